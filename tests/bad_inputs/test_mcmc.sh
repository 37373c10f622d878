#!/usr/bin/env bash
# `phytocal mcmc`: bad input exits 1 (usage) or 2 (bad input) with the
# reason and leaves nothing behind; a good run writes its directory, and the
# same seed gives the same result.json byte for byte (another seed does not).
#
#   bash test_mcmc.sh PATH/TO/phytocal
#
# Prints "ok - <case>" / "not ok - <case>: <why>", then "N passed, M failed".

source "$(dirname "${BASH_SOURCE[0]}")/../cli_cases.sh" "$@"
EXAMPLE_DIR="$SCRIPT_DIR/../../measurements/examples/enzyme_kinetics"
cp "$EXAMPLE_DIR/enzyme.csv" .

config() { # $1 = vmax line, $2 = km line
    cat <<YAML
name: enzyme-mcmc
parameters:
$1
$2
datasets:
  - kind: curve
    name: assay
    file: enzyme.csv
    x: substrate_mM
    y: rate_umol_min
    expression: "vmax * substrate_mM / (km + substrate_mM)"
    sigma: 5
YAML
}
GOOD_V='  vmax: {value: 150, lower: 0, upper: 400, unit: "umol min-1"}'
GOOD_K='  km:   {value: 0.1, lower: 0, prior: {dist: log-normal, meanlog: -2.3, sdlog: 0.5}, unit: mM}'
config "$GOOD_V" "$GOOD_K" > good.yaml

bad_case() { # name, expected exit, config, expected message part, extra args...
    local name=$1 code=$2 cfg=$3 expect=$4
    shift 4
    rm -rf out
    run mcmc "$cfg" -o out "$@"
    [ "$RC" -eq "$code" ] || why "exit $RC, expected $code"
    grep -qF -- "$expect" "$T/stderr" || why "message lacks '$expect'"
    [ ! -e out ] || why "left out/ behind"
    ls out.tmp-* >/dev/null 2>&1 && why "left a temporary directory"
    finish "$name"
}
bad_case "samples too small" 2 good.yaml "--samples 50 is too small: at least 100" --samples 50
bad_case "one chain" 2 good.yaml "--chains 1 is too small: at least 2" --chains 1
bad_case "stretch with fewer than 2 d walkers" 2 good.yaml \
    "--chains 2: the stretch-move ensemble needs an even number of at least 2 d = 4 walkers" --method stretch --chains 2
bad_case "stretch with an odd number of walkers" 2 good.yaml "needs an even number" --method stretch --chains 5
bad_case "unknown method" 2 good.yaml "--method: unknown method 'gibbs'; expected dram or stretch" --method gibbs
bad_case "samples not a number" 2 good.yaml "--samples: expected a whole number" --samples many
bad_case "option without its value" 1 good.yaml "--seed needs a value" --seed
config "$GOOD_V" '  km:   {value: 0.1, lower: 0, prior: {dist: normal, mean: 0.1, sd: -1}}' > badprior.yaml
bad_case "prior with a negative sd" 2 badprior.yaml "badprior.yaml:4: parameter 'km': prior normal"
config '  vmax: {value: 150, fixed: true}' '  km:   {value: 0.1, fixed: true}' > fixed.yaml
bad_case "every parameter fixed" 2 fixed.yaml "every parameter is fixed"

# ---- a good run; the same seed gives the same result -------------------------
rm -rf a b c
run mcmc good.yaml -o a --samples 2000 --seed 7 -q
[ "$RC" -eq 0 ] || why "exit $RC"
for f in result.json report.md mcmc_trace.png mcmc_pairs.png phytocal-run.json; do
    [ -s "a/$f" ] || why "no a/$f"
done
grep -q '"method": "dram"' a/result.json || why "result.json lacks the method"
grep -q "IMPROPER" a/report.md && why "report calls a bounded prior improper"
finish "good run writes its directory"
run mcmc good.yaml -o b --samples 2000 --seed 7 -q
cmp -s a/result.json b/result.json || why "same seed, different result.json"
run mcmc good.yaml -o c --samples 2000 --seed 8 -q
cmp -s a/result.json c/result.json && why "another seed gave the same result.json"
finish "same seed, same chains; another seed, other chains"

config '  vmax: {value: 150, lower: 0}' "$GOOD_K" > improper.yaml
rm -rf d
run mcmc improper.yaml -o d --samples 1000 --method stretch
[ "$RC" -eq 0 ] || why "exit $RC"
grep -q "vmax: flat and IMPROPER" d/report.md || why "report does not say the prior of vmax is improper"
grep -q '"dist": "flat-improper"' d/result.json || why "result.json does not say flat-improper"
finish "an open bound without a prior: flat improper prior, said in the report"

# ---- an interrupted DRAM run resumed equals an uninterrupted one ----------------
rm -rf full part part.ledger
run mcmc good.yaml -o full --samples 1000 -q
[ "$RC" -eq 0 ] || why "uninterrupted run: exit $RC"
PHYTOCAL_STOP_AFTER=3 "$PHC" mcmc good.yaml -o part --samples 1000 -q >"$T/stdout" 2>"$T/stderr"
RC=$?
[ "$RC" -ne 0 ] || why "the stopped run exited 0"
[ -f part.ledger ] || why "no ledger after the stop"
[ ! -e part ] || why "the stopped run wrote its directory"
n_before=$(grep -c '^[0-9]' part.ledger 2>/dev/null)
[ "$n_before" = 3 ] || why "ledger holds $n_before chains, expected 3"
run mcmc good.yaml -o part --samples 1000 -q --resume
[ "$RC" -eq 0 ] || why "resume: exit $RC"
cmp -s full/result.json part/result.json || why "resumed result.json differs from the uninterrupted one"
grep -q "chains taken from the ledger (--resume): 3" part/report.md || why "report does not count 3 chains from the ledger"
[ ! -e part.ledger ] || why "the ledger was left behind after the run"
finish "an interrupted DRAM run resumed gives the same result.json"

rm -rf part part.ledger
PHYTOCAL_STOP_AFTER=1 "$PHC" mcmc good.yaml -o part --samples 1000 -q >/dev/null 2>&1
run mcmc good.yaml -o part --samples 1000 --seed 2 -q --resume
[ "$RC" -eq 2 ] || why "exit $RC, expected 2"
grep -qF "the ledger is from another study: sampler is" "$T/stderr" || why "message does not say what differs"
[ ! -e part ] || why "wrote part/"
finish "a ledger of another run is refused, saying what differs"
run mcmc good.yaml -o part --samples 1000 -q
[ "$RC" -eq 2 ] || why "exit $RC, expected 2"
grep -qF "an unfinished study's ledger is here" "$T/stderr" || why "message does not name the ledger"
[ -f part.ledger ] || why "the unfinished ledger is gone"
finish "a fresh run does not overwrite an unfinished ledger without --force"
rm -rf part part.ledger
bad_case "stretch cannot resume" 2 good.yaml "--resume: only --method dram resumes" --method stretch --resume

echo "$PASSED passed, $FAILED failed"
[ "$FAILED" -eq 0 ]
