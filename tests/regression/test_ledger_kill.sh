#!/usr/bin/env bash
# The run ledger's promise under SIGKILL (fit/run_ledger.h): records go out
# in batches (64 records, 64 KiB, or 50 ms after the last write), so a
# study killed with SIGKILL halfway keeps every record but those of its
# last unwritten batch; the ledger it leaves parses (a cut last line is
# dropped), and `--resume` finishes with a result.json identical to an
# uninterrupted run's, recomputing only what the ledger lacks.
#
#   bash test_ledger_kill.sh PATH/TO/phytocal
#
# Prints "ok - <case>" / "not ok - <case>: <why>", then "N passed, M failed".

source "$(dirname "${BASH_SOURCE[0]}")/../cli_cases.sh" "$@"
SEED_DIR="$SCRIPT_DIR/../../measurements/examples/weight_curve"
cp "$SEED_DIR/seedling.csv" "$SEED_DIR/balance.csv" "$SEED_DIR/seedling_sensitivity.yaml" .

records() { local n; n=$(grep -c '^[0-9]' "$1" 2>/dev/null); echo "${n:-0}"; }

run sensitivity seedling_sensitivity.yaml -o one --samples 256 -q
[ "$RC" -eq 0 ] || why "uninterrupted run: exit $RC"
total=$(records one/ledger.tsv)

# killed while evaluating: wait until the ledger holds records, then SIGKILL
"$PHC" sensitivity seedling_sensitivity.yaml -o part --samples 256 -q >/dev/null 2>&1 &
pid=$!
for _ in $(seq 1 600); do
    [ "$(records part.ledger)" -gt 100 ] && break
    sleep 0.05
done
kill -KILL "$pid" 2>/dev/null
wait "$pid" 2>/dev/null
kept=$(records part.ledger)
[ ! -e part ] || why "the killed run wrote its directory (it finished before the kill: make the study longer)"
[ "$kept" -gt 0 ] && [ "$kept" -lt "$total" ] || why "the killed run's ledger holds $kept of $total records"
run sensitivity seedling_sensitivity.yaml -o part --samples 256 --resume
[ "$RC" -eq 0 ] || why "resume: exit $RC"
grep -q "($((total - kept)) computed, $kept from the ledger, 0 failed)" "$T/stdout" ||
    why "resume did not take the $kept records the ledger held: $(grep computed "$T/stdout")"
cmp -s one/result.json part/result.json || why "result.json differs from the uninterrupted run's"
finish "SIGKILL after $kept of $total records: the ledger parses, --resume recomputes $((total - kept)), same result.json"

echo "$PASSED passed, $FAILED failed"
[ "$FAILED" -eq 0 ]
