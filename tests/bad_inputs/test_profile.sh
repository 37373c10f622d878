#!/usr/bin/env bash
# `phytocal profile`: bad input exits 2 (usage errors 1) naming the option or
# the config and why, and leaves nothing behind; a good run writes its run
# directory; a non-identifiable product (y = a*b*x) is reported as such.
#
#   bash test_profile.sh PATH/TO/phytocal
#
# Prints "ok - <case>" / "not ok - <case>: <why>", then "N passed, M failed".

source "$(dirname "${BASH_SOURCE[0]}")/../cli_cases.sh" "$@"
EXAMPLE_DIR="$SCRIPT_DIR/../../measurements/examples/enzyme_kinetics"
cp "$EXAMPLE_DIR/enzyme.csv" "$EXAMPLE_DIR/enzyme.yaml" .

bad_case() { # name, expected exit, expected message part, args...
    local name=$1 code=$2 expect=$3
    shift 3
    rm -rf out
    run profile "$@"
    [ "$RC" -eq "$code" ] || why "exit $RC, expected $code"
    grep -qF -- "$expect" "$T/stderr" || why "message lacks '$expect'"
    [ ! -e out ] || why "left out/ behind"
    ls out.tmp-* >/dev/null 2>&1 && why "left a temporary directory"
    finish "$name"
}

sed 's/^  vmax: {value: 150, lower: 0/  vmax: {value: 150, lower: 0, fixed: true/; s/^  km:   {value: 0.1, lower: 0/  km:   {value: 0.1, lower: 0, fixed: true/' \
    enzyme.yaml > fixed.yaml

bad_case "unknown option" 1 "--bogus" enzyme.yaml -o out --bogus
bad_case "--points without a value" 1 "--points needs a value" enzyme.yaml -o out --points
bad_case "--points 2 (< 3)" 2 "--points: expected a whole number from 3" enzyme.yaml -o out --points 2
bad_case "--points not a number" 2 "found 'many'" enzyme.yaml -o out --points many
bad_case "--level outside (0, 1)" 2 "--level: expected a number between 0 and 1, found '1.5'" enzyme.yaml -o out --level 1.5
bad_case "no free parameter" 2 "fixed.yaml: every parameter is fixed" fixed.yaml -o out
bad_case "missing config" 2 "nope.yaml" nope.yaml -o out

# ---- good runs ---------------------------------------------------------------
rm -rf out
run profile enzyme.yaml -o out --points 6 --quiet
[ "$RC" -eq 0 ] || why "exit $RC"
for f in result.json report.md profile_vmax.png profile_km.png phytocal-run.json; do
    [ -s "out/$f" ] || why "no out/$f"
done
grep -q '"lower_end": "crossed"' out/result.json || why "no crossed end in result.json"
[ ! -s "$T/stdout" ] || why "--quiet printed to stdout"
finish "enzyme profile writes its run directory"

run profile enzyme.yaml -o out
[ "$RC" -eq 2 ] || why "exit $RC, expected 2 for an existing run directory without --force"
run profile enzyme.yaml -o out --force --quiet
[ "$RC" -eq 0 ] || why "--force: exit $RC"
finish "run directory rules (refused without --force, replaced with it)"

grep -v '^#' enzyme.csv | awk 'NR == 1 { print "x,y"; next } { print }' > lin.csv
cat > product.yaml <<'YAML'
name: product
parameters:
  a: {value: 1, lower: 0.5, upper: 2}
  b: {value: 100, lower: 1, upper: 1000}
datasets:
  - kind: curve
    name: d
    file: lin.csv
    x: x
    y: y
    expression: "a * b * x"
YAML
rm -rf out
run profile product.yaml -o out
[ "$RC" -eq 0 ] || [ "$RC" -eq 3 ] || why "exit $RC"
grep -q "a: practically non-identifiable" out/report.md || why "a is not called practically non-identifiable"
grep -q '"upper_end": "at_bound"' out/result.json || why "no side open to the bound"
finish "y = a*b*x: a flat profile open to its bounds"

echo "$PASSED passed, $FAILED failed"
[ "$FAILED" -eq 0 ]
