#!/usr/bin/env bash
# Batch fits (issue 16): `phytocal fit CONFIG --each COLUMN -o DIR` and
# `phytocal fit A.yaml B.yaml -o DIR` write one run directory per fit and a
# summary whose numbers are exactly those of the same fit run alone.
#
#   bash test_batch.sh PATH/TO/phytocal [SHARED_DATA_DIR]
#
# Cases:
#  1. --each run over measurements/examples/enzyme_kinetics/enzyme_runs.yaml:
#     twelve run directories (result.json, report.md, plots, manifest), the
#     batch's own manifest, summary.tsv with twelve rows; for runs r01 and r07
#     a single `phytocal fit` of a config whose table holds only that run's
#     rows gives a result.json whose cost, parameters, standard errors, R²
#     and n_obs equal the summary row's numbers exactly (17 digits read back)
#     and the batch's own result.json of that run;
#  2. --each leaf over the pressure-volume example (kind pv_curve): two
#     leaves, each the same as a single fit of its rows;
#  3. two configs in one call (enzyme.yaml, pv_leaves.yaml): DIR/enzyme/ and
#     DIR/pv_leaves/ equal to the single fits of the two configs;
#  4. `phytocal report --check` passes on the batch directory and on a
#     fit's directory inside it;
#  5. --each plant over a weight_curve table holding the seedling's balance
#     twice (plants p1, p2, times starting at 0 for each): both rows equal
#     the seedling example fitted alone.
# Each case prints "ok - <case>" or "not ok - <case>: <why>"; exit 1 if any failed.
source "$(dirname "${BASH_SOURCE[0]}")/../cli_cases.sh" "$@"
EX="$SCRIPT_DIR/../../measurements/examples"
PY=python3
[ -x /usr/bin/python3 ] && PY=/usr/bin/python3

# compare SUMMARY ROW_FIT RESULT_JSON: every number of the row against result.json
compare() {
    "$PY" - "$@" <<'PYEOF' || why "$(cat "$T/cmp.txt")"
import csv, json, math, sys
summary, fit, result = sys.argv[1:4]
rows = list(csv.DictReader(open(summary, newline=""), delimiter="\t"))
row = [r for r in rows if r["fit"] == fit]
bad = []
if len(row) != 1:
    bad.append("%d rows named %s" % (len(row), fit))
else:
    row = row[0]
    res = json.load(open(result))
    def same(label, cell, value):
        if value is None:
            ok = cell == ""
        else:
            ok = cell != "" and float(cell) == value
        if not ok:
            bad.append("%s: summary %r, result.json %r" % (label, cell, value))
    same("cost", row["cost"], res["cost"])
    same("n_obs", row["n_obs"], res["n_observations"])
    if row["status"] != res["status"]:
        bad.append("status %s vs %s" % (row["status"], res["status"]))
    for name, p in res["parameters"].items():
        same(name, row[name], p["value"])
        same(name + "_se", row[name + "_se"], None if p["fixed"] else p["stderr"])
    for ds in res["datasets"]:
        same("r2_" + ds["name"], row["r2_" + ds["name"]], ds["goodness"]["r2"])
open(sys.argv[4], "w").write("; ".join(bad[:4]))
sys.exit(1 if bad else 0)
PYEOF
}
cmp_row() { compare "$1" "$2" "$3" "$T/cmp.txt"; }

# single_group SRC_DIR CONFIG CSV COLUMN VALUE OUT: a config whose table holds only the group's rows
single_group() {
    local src=$1 cfg=$2 csv=$3 col=$4 val=$5 out=$6
    rm -rf "$T/single_$val" "$out"
    mkdir -p "$T/single_$val"
    cp "$src/$cfg" "$T/single_$val/"
    "$PY" - "$src/$csv" "$T/single_$val/$csv" "$col" "$val" <<'PYEOF'
import sys
src, dst, col, val = sys.argv[1:5]
lines = open(src).read().splitlines(True)
out, idx = [], None
for ln in lines:
    if ln.lstrip().startswith("#") or not ln.strip():
        out.append(ln)
        continue
    cells = ln.rstrip("\r\n").split(",")
    if idx is None:
        idx = cells.index(col)
        out.append(ln)
    elif cells[idx] == val:
        out.append(ln)
open(dst, "w").write("".join(out))
PYEOF
    run fit "$T/single_$val/$cfg" -o "$out" -q
}

# 1. --each over a curve table
run fit "$EX/enzyme_kinetics/enzyme_runs.yaml" --each run -o "$T/runs"
[ "$RC" -eq 0 ] || why "exit $RC"
for k in 01 02 03 04 05 06 07 08 09 10 11 12; do
    for f in result.json report.md assay_fit.png phytocal-run.json; do
        [ -f "$T/runs/r$k/$f" ] || why "runs/r$k/$f missing"
    done
done
[ -f "$T/runs/phytocal-run.json" ] && [ -f "$T/runs/summary.md" ] || why "batch manifest or summary.md missing"
[ "$(tail -n +2 "$T/runs/summary.tsv" | wc -l)" -eq 12 ] || why "summary.tsv has not 12 rows"
grep -qF "12 of 12 fits converged" "$T/stdout" || why "stdout lacks the count"
for g in r01 r07; do
    single_group "$EX/enzyme_kinetics" enzyme_runs.yaml enzyme_runs.csv run "$g" "$T/alone_$g"
    [ "$RC" -eq 0 ] || why "single fit of $g: exit $RC"
    cmp_row "$T/runs/summary.tsv" "$g" "$T/alone_$g/result.json"
    cmp_row "$T/runs/summary.tsv" "$g" "$T/runs/$g/result.json"
done
finish "--each run: twelve fits, rows equal to the single fits"

# 2. --each over a pv_curve table
run fit "$EX/pressure_volume/pv_leaves.yaml" --each leaf -o "$T/leaves" -q
[ "$RC" -eq 0 ] || why "exit $RC"
head -1 "$T/leaves/summary.tsv" | grep -q "^fit	leaf	config" || why "no leaf column in the header"
for g in A B; do
    [ -f "$T/leaves/$g/moduli_pv_curve.png" ] || why "leaves/$g/moduli_pv_curve.png missing"
    single_group "$EX/pressure_volume" pv_leaves.yaml pv_leaves.csv leaf "$g" "$T/leaf_$g"
    [ "$RC" -eq 0 ] || why "single fit of leaf $g: exit $RC"
    cmp_row "$T/leaves/summary.tsv" "$g" "$T/leaf_$g/result.json"
done
finish "--each leaf (pv_curve): rows equal to the single fits"

# 3. several configs in one call
run fit "$EX/enzyme_kinetics/enzyme.yaml" "$EX/pressure_volume/pv_leaves.yaml" -o "$T/two" -q
[ "$RC" -eq 0 ] || why "exit $RC"
run fit "$EX/enzyme_kinetics/enzyme.yaml" -o "$T/one_enzyme" -q
run fit "$EX/pressure_volume/pv_leaves.yaml" -o "$T/one_pv" -q
cmp_row "$T/two/summary.tsv" enzyme "$T/one_enzyme/result.json"
cmp_row "$T/two/summary.tsv" pv_leaves "$T/one_pv/result.json"
finish "two configs: DIR/enzyme and DIR/pv_leaves equal to the single fits"

# 5. --each over a weight_curve table: the seedling's balance twice, as plants p1 and p2
#    (each plant's times start at 0 again: the rows of all plants together are no weight curve)
mkdir -p "$T/wc"
cp "$EX/weight_curve/seedling.yaml" "$EX/weight_curve/seedling.csv" "$T/wc/"
{
    grep '^#' "$EX/weight_curve/balance.csv"
    echo "plant,$(grep -v '^#' "$EX/weight_curve/balance.csv" | head -1)"
    for p in p1 p2; do grep -v '^#' "$EX/weight_curve/balance.csv" | tail -n +2 | sed "s/^/$p,/"; done
} >"$T/wc/balance.csv"
run fit "$T/wc/seedling.yaml" --each plant -o "$T/plants" -q
[ "$RC" -eq 0 ] || why "exit $RC"
run fit "$EX/weight_curve/seedling.yaml" -o "$T/seedling_alone" -q
[ "$RC" -eq 0 ] || why "single seedling fit: exit $RC"
cmp_row "$T/plants/summary.tsv" p1 "$T/seedling_alone/result.json"
cmp_row "$T/plants/summary.tsv" p2 "$T/seedling_alone/result.json"
finish "--each plant (weight_curve): each plant equal to the seedling fit alone"

# 4. the manifests hold
run report --check "$T/runs"
[ "$RC" -eq 0 ] || why "report --check DIR: exit $RC"
run report --check "$T/runs/r05"
[ "$RC" -eq 0 ] || why "report --check DIR/r05: exit $RC"
finish "report --check on the batch and on one of its fits"

echo "$PASSED passed, $FAILED failed"
[ "$FAILED" -eq 0 ]
