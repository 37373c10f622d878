#!/usr/bin/env bash
# `phytocal profile` and `phytocal mcmc` under Open MPI (fit/study_dist.h,
# fit/mpi/): with `mpirun -np 2` the profile of the pressure-volume leaves
# (three parameters, shared out one per message) writes a result.json
# identical byte for byte to the one-process run's (report.md too, but for
# its provenance's command line and times) and prints its table
# once; a failure on every rank (a missing config, a bad option) ends the
# job with its message once.  `mcmc --method dram` with -np 2 (its chains
# shared out, one per message) equals one process, report.md's count of
# model evaluations included; a DRAM run stopped under MPI after 2 chains
# and resumed under MPI equals the uninterrupted one.  `mcmc --method
# stretch` (every rank runs the ensemble and evaluates its block of each
# half's proposals, one all-gather per half-step) with -np 2 and -np 3
# equals one process, report.md's count of model evaluations included, and
# every rank evaluated (PHC_STUDY_MPI_TIMES=1 prints each rank's count); a
# bad --chains under mpirun and a stretch run with one rank exit 2 with one
# message.
# Skips (77) only when mpirun is absent (CI installs Open MPI through
# scripts/setup).
#
#   bash test_profile_mcmc_mpi.sh PATH/TO/phytocal
#
# Prints "ok - <case>" / "not ok - <case>: <why>", then "N passed, M failed".

source "$(dirname "${BASH_SOURCE[0]}")/../cli_cases.sh" "$@"
if ! command -v mpirun >/dev/null 2>&1; then
    echo "skip: mpirun not found (Debian: openmpi-bin; scripts/setup installs it)"
    exit 77
fi
PV_DIR="$SCRIPT_DIR/../../measurements/examples/pressure_volume"
cp "$PV_DIR"/pv_leaves.yaml "$SCRIPT_DIR"/../../measurements/examples/enzyme_kinetics/enzyme.{yaml,csv} .
for f in $(grep -o '[A-Za-z0-9_./-]*\.csv' pv_leaves.yaml); do cp "$PV_DIR/$f" . 2>/dev/null; done
# Open MPI refuses root without these; --oversubscribe lets 2 ranks start
# on a machine with fewer cores.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
MPIRUN=(timeout 300 mpirun --oversubscribe)
run() { "$@" >"$T/stdout" 2>"$T/stderr"; RC=$?; [ "$RC" -ne 124 ] || why "hung (killed after 300 s)"; }

# ---- profile: 2 ranks = one process -------------------------------------------
run "$PHC" profile pv_leaves.yaml -o one
[ "$RC" -eq 0 ] || why "one process: exit $RC"
sed '/^results/d' "$T/stdout" > one.txt
run "${MPIRUN[@]}" -np 2 "$PHC" profile pv_leaves.yaml -o many
[ "$RC" -eq 0 ] || why "mpirun -np 2: exit $RC"
cmp -s one/result.json many/result.json || why "result.json differs from the one-process run's"
prov() { grep -v -E '^- (command|started)' "$1"; } # the provenance's command line and times differ
diff -q <(prov one/report.md) <(prov many/report.md) >/dev/null || why "report.md differs from the one-process run's"
diff -q one.txt <(sed '/^results/d' "$T/stdout") >/dev/null || why "the printed table differs"
n=$(grep -c 'parameters profiled' "$T/stdout")
[ "$n" = 1 ] || why "the summary was printed $n times"
n=$(grep -c '^writing' "$T/stderr")
[ "$n" = 1 ] || why "progress printed by $n ranks"
# the master traces only the profiles it kept: with three parameters and a
# worker two messages ahead, the worker traced two, the master one
n=$(grep -o 'profile [0-9]/3' "$T/stderr" | sort -u | wc -l)
[ "$n" -lt 3 ] || why "the master's progress shows all 3 profiles: did the worker take part?"
finish "profile with mpirun -np 2: result.json and report.md identical to one process, printed once"

# ---- profile: a failure on every rank is reported once and ends the job --------
for bad in "missing.yaml" "pv_leaves.yaml --level 1.5"; do
    rm -rf bad
    run "${MPIRUN[@]}" -np 2 "$PHC" profile $bad -o bad
    [ "$RC" -ne 0 ] && [ "$RC" -ne 124 ] || why "exit $RC, expected a failure"
    key=${bad##* }
    n=$(grep -cF -- "$key" "$T/stderr") # fixed string: "1.5" as a regex matched MPI job ids such as [[11859,1],0]
    [ "$n" = 1 ] || why "the message naming $key appears $n times, expected once"
    [ ! -e bad ] || why "a directory was written"
    finish "profile $bad with mpirun -np 2: one message, no hang, no directory"
done

# rank_count R LINE: rank R's count in "mcmc stretch: model evaluations by rank: 0: N (...), 1: M (...); ..."
rank_count() { local re=" $1: ([0-9]+) \\("; [[ $2 =~ $re ]] && echo "${BASH_REMATCH[1]}"; }

# ---- mcmc: DRAM's chains on 2 ranks, the stretch ensemble's proposals on 2 ranks = one process ----
for method in dram stretch; do
    rm -rf one many
    run "$PHC" mcmc enzyme.yaml -o one --method $method --samples 1000 --chains 6 --seed 3
    [ "$RC" -eq 0 ] || why "one process: exit $RC"
    sed '/^results/d' "$T/stdout" > one.txt
    PHC_STUDY_MPI_TIMES=1 run "${MPIRUN[@]}" -np 2 "$PHC" mcmc enzyme.yaml -o many --method $method \
        --samples 1000 --chains 6 --seed 3
    [ "$RC" -eq 0 ] || why "mpirun -np 2: exit $RC"
    cmp -s one/result.json many/result.json || why "result.json differs from the one-process run's"
    diff -q <(prov one/report.md) <(prov many/report.md) >/dev/null || why "report.md differs"
    cmp -s one/mcmc_pairs.png many/mcmc_pairs.png || why "mcmc_pairs.png differs"
    diff -q one.txt <(sed '/^results/d' "$T/stdout") >/dev/null || why "the printed summary differs"
    n=$(grep -c '^results' "$T/stdout")
    [ "$n" = 1 ] || why "the summary was printed $n times"
    [ ! -e many.ledger ] || why "the ledger stayed beside the finished run"
    if [ $method = stretch ]; then
        # "mcmc stretch: model evaluations by rank: 0: N (...), 1: M (...); ..."
        line=$(grep -F 'mcmc stretch: model evaluations by rank:' "$T/stderr")
        echo "# $line"
        n0=$(rank_count 0 "$line")
        n1=$(rank_count 1 "$line")
        [ "${n0:-0}" -gt 0 ] && [ "${n1:-0}" -gt 0 ] || why "not every rank evaluated (rank 0: '$n0', rank 1: '$n1')"
    fi
    finish "mcmc --method $method with mpirun -np 2: result.json, report.md and plots identical to one process"
done

# ---- stretch on 3 ranks (one proposal each per half of 6 walkers) = one process ----
rm -rf many
PHC_STUDY_MPI_TIMES=1 run "${MPIRUN[@]}" -np 3 "$PHC" mcmc enzyme.yaml -o many --method stretch --samples 1000 \
    --chains 6 --seed 3 -q
[ "$RC" -eq 0 ] || why "mpirun -np 3: exit $RC"
cmp -s one/result.json many/result.json || why "result.json differs from the one-process run's"
diff -q <(prov one/report.md) <(prov many/report.md) >/dev/null || why "report.md differs"
line=$(grep -F 'mcmc stretch: model evaluations by rank:' "$T/stderr")
echo "# $line"
for r in 0 1 2; do
    k=$(rank_count $r "$line")
    [ "${k:-0}" -gt 0 ] || why "rank $r evaluated '$k' proposals"
done
finish "mcmc --method stretch with mpirun -np 3: result.json and report.md identical to one process"

# ---- stretch: bad input under mpirun: one message, exit 2, no hang ----------
rm -rf bad
run "${MPIRUN[@]}" -np 2 "$PHC" mcmc enzyme.yaml -o bad --method stretch --chains 5
[ "$RC" -eq 2 ] || why "exit $RC, expected 2"
n=$(grep -cF -- "--chains 5: the stretch-move ensemble needs an even number" "$T/stderr")
[ "$n" = 1 ] || why "the message appears $n times, expected once"
[ ! -e bad ] || why "a directory was written"
finish "mcmc --method stretch --chains 5 with mpirun -np 2: exit 2, one message, no directory"
run "${MPIRUN[@]}" -np 1 "$PHC" mcmc enzyme.yaml -o bad --method stretch
[ "$RC" -eq 2 ] || why "exit $RC, expected 2"
n=$(grep -cF -- "the MPI launcher started 1 rank" "$T/stderr")
[ "$n" = 1 ] || why "the message appears $n times, expected once"
[ ! -e bad ] || why "a directory was written"
finish "mcmc --method stretch with mpirun -np 1: exit 2, 'the MPI launcher started 1 rank'"


# ---- DRAM stopped under MPI after 2 chains, resumed under MPI = uninterrupted --
rm -rf one part part.ledger
run "$PHC" mcmc enzyme.yaml -o one --samples 1000 --chains 6 --seed 3 -q
PHYTOCAL_STOP_AFTER=2 run "${MPIRUN[@]}" -np 2 "$PHC" mcmc enzyme.yaml -o part --samples 1000 --chains 6 \
    --seed 3 -q
[ "$RC" -ne 0 ] && [ "$RC" -ne 124 ] || why "the stopped run exited $RC"
grep -qF "stopped after 2 new chains" "$T/stderr" || why "no stop message"
n=$(grep -c '^[0-9]' part.ledger 2>/dev/null)
[ "$n" = 2 ] || why "ledger holds $n chains, expected 2 (the master records; chains in flight are dropped)"
[ ! -e part ] || why "the stopped run wrote its directory"
run "${MPIRUN[@]}" -np 2 "$PHC" mcmc enzyme.yaml -o part --samples 1000 --chains 6 --seed 3 -q --resume
[ "$RC" -eq 0 ] || why "resume: exit $RC"
grep -q "chains taken from the ledger (--resume): 2\." part/report.md || why "resume did not reuse the 2 chains"
cmp -s one/result.json part/result.json || why "result.json differs from the uninterrupted run's"
[ ! -e part.ledger ] || why "the ledger stayed beside the finished run"
finish "DRAM stopped after 2 chains under mpirun -np 2, resumed under mpirun = uninterrupted"

echo "$PASSED passed, $FAILED failed"
[ "$FAILED" -eq 0 ]
