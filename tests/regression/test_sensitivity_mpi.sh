#!/usr/bin/env bash
# `phytocal sensitivity` under Open MPI (fit/study_dist.h, fit/mpi/): the
# weight-curve seedling study with `mpirun -np 2` (Sobol) and `-np 3`
# (Morris) writes a result.json identical byte for byte to the one-process
# run's, a ledger with the same records, and prints its summary once; a
# study stopped under MPI and resumed under MPI equals the uninterrupted
# one; `phytocal version` does not load libmpi.  Skips (77) only when
# mpirun is absent (CI installs Open MPI through scripts/setup).
#
#   bash test_sensitivity_mpi.sh PATH/TO/phytocal
#
# Prints "ok - <case>" / "not ok - <case>: <why>", then "N passed, M failed".

source "$(dirname "${BASH_SOURCE[0]}")/../cli_cases.sh" "$@"
if ! command -v mpirun >/dev/null 2>&1; then
    echo "skip: mpirun not found (Debian: openmpi-bin; scripts/setup installs it)"
    exit 77
fi
SEED_DIR="$SCRIPT_DIR/../../measurements/examples/weight_curve"
cp "$SEED_DIR/seedling.csv" "$SEED_DIR/balance.csv" "$SEED_DIR/seedling_sensitivity.yaml" .
# Open MPI refuses root without these; --oversubscribe lets 2 or 3 ranks
# start on a machine with fewer cores.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
MPIRUN=(timeout 300 mpirun --oversubscribe)
run() { "$@" >"$T/stdout" 2>"$T/stderr"; RC=$?; [ "$RC" -ne 124 ] || why "hung (killed after 300 s)"; }
records() { grep '^[0-9]' "$1" | sort; }

# ---- the module is loaded only under mpirun ---------------------------------
n=$(LD_DEBUG=libs "$PHC" version 2>&1 | grep -c -E 'libmpi|open-pal|phytocal_mpi')
[ "$n" = 0 ] || why "phytocal version loaded $n MPI objects"
run mpirun -np 2 env LD_DEBUG=libs "$PHC" sensitivity missing.yaml
n=$(grep -c -E 'calling init: .*phytocal_mpi\.so' "$T/stderr")
[ "$n" = 2 ] || why "under mpirun -np 2 the module was loaded $n times, expected 2"
finish "phytocal version loads no MPI library; mpirun loads phytocal_mpi.so in each rank"

# ---- 2 ranks (Sobol) and 3 ranks (Morris) = one process ----------------------
for case in "sobol 2 128" "morris 3 40"; do
    set -- $case
    method=$1 np=$2 samples=$3
    rm -rf one many
    run "$PHC" sensitivity seedling_sensitivity.yaml -o one --method "$method" --samples "$samples"
    [ "$RC" -eq 0 ] || why "one process: exit $RC"
    sed '/^results/d' "$T/stdout" > one.txt
    run "${MPIRUN[@]}" -np "$np" "$PHC" sensitivity seedling_sensitivity.yaml -o many --method "$method" \
        --samples "$samples"
    [ "$RC" -eq 0 ] || why "mpirun -np $np: exit $RC"
    cmp -s one/result.json many/result.json || why "result.json differs from the one-process run's"
    diff -q <(records one/ledger.tsv) <(records many/ledger.tsv) >/dev/null || why "the ledgers' records differ"
    diff -q one.txt <(sed '/^results/d' "$T/stdout") >/dev/null || why "the printed summary differs"
    n=$(grep -c 'study:' "$T/stdout")
    [ "$n" = 1 ] || why "the summary was printed $n times"
    n=$(grep -c '^estimating' "$T/stderr")
    [ "$n" = 1 ] || why "progress printed by $n ranks"
    [ ! -e many.ledger ] || why "the ledger stayed beside the finished run"
    # the master records results as they arrive: rows out of order show that
    # the workers evaluated some
    grep '^[0-9]' many/ledger.tsv | cut -f1 | sort -n -C && why "the ledger is in row order: did a worker take part?"
    finish "$method with mpirun -np $np: result.json identical to one process, printed once"
done

# ---- stopped under MPI, resumed under MPI = uninterrupted ---------------------
rm -rf part part.ledger
PHYTOCAL_STOP_AFTER=100 run "${MPIRUN[@]}" -np 2 "$PHC" sensitivity seedling_sensitivity.yaml -o part \
    --samples 128 -q
[ "$RC" -ne 0 ] && [ "$RC" -ne 124 ] || why "the stopped run exited $RC"
grep -qF "stopped after 100 new evaluations" "$T/stderr" || why "no stop message"
n=$(grep -c '^[0-9]' part.ledger 2>/dev/null)
[ "$n" = 100 ] || why "ledger holds $n records, expected 100 (the master records, workers' results in flight are dropped)"
[ ! -e part ] || why "the stopped run wrote its directory"
rm -rf one
run "$PHC" sensitivity seedling_sensitivity.yaml -o one --samples 128 -q
run "${MPIRUN[@]}" -np 2 "$PHC" sensitivity seedling_sensitivity.yaml -o part --samples 128 --resume
[ "$RC" -eq 0 ] || why "resume: exit $RC"
grep -q "(540 computed, 100 from the ledger, 0 failed)" "$T/stdout" || why "resume did not reuse the 100"
cmp -s one/result.json part/result.json || why "result.json differs from the uninterrupted run's"
finish "stopped after 100 evaluations under mpirun -np 2, resumed under mpirun = uninterrupted"

echo "$PASSED passed, $FAILED failed"
[ "$FAILED" -eq 0 ]
