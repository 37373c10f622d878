#!/usr/bin/env bash
# `phytocal fit --plots all|none` (issue 16: many small fits without 2000
# PNG files): which files a run directory gets, what its manifest and report
# say about them, and that the numbers do not depend on the plots.
#
#   bash test_fit_plots.sh PATH/TO/phytocal [SHARED_DATA_DIR]
#
# Cases:
#  1. a single fit of the enzyme example with --plots none: the directory
#     holds exactly result.json, report.md and phytocal-run.json; the
#     manifest lists exactly result.json and report.md; report.md links no
#     picture and says that none was drawn; `report --check` passes; its
#     result.json has the same cost and parameters as the default run;
#  2. the default (and --plots all, the same): the four plots of the data
#     set exist, the manifest lists every file of the directory, every
#     picture report.md links exists;
#  3. --each leaf over the pressure-volume example (pv_curve, a kind that
#     adds its own picture) with --plots none: no PNG anywhere below DIR,
#     DIR's manifest lists exactly the files below it, `report --check`
#     passes on DIR and on a leaf's folder, and summary.tsv has the same
#     bytes as that of the batch with plots;
#  4. bad values: `--plots some` (single and batch) is exit 2 naming the
#     option and the value, and writes nothing; `--plots` without a value is
#     a usage error (exit 1).
# Each case prints "ok - <case>" or "not ok - <case>: <why>"; exit 1 if any failed.
source "$(dirname "${BASH_SOURCE[0]}")/../cli_cases.sh" "$@"
EX="$SCRIPT_DIR/../../measurements/examples"
PY=python3
[ -x /usr/bin/python3 ] && PY=/usr/bin/python3

# manifest_is DIR: the manifest lists exactly the files below DIR (itself
# aside), each with the SHA-256 of its bytes; extra arguments: file names
# that must be the whole list
manifest_is() {
    "$PY" - "$@" >"$T/why.txt" <<'PYEOF' || why "$(cat "$T/why.txt")"
import hashlib, json, os, sys
d = sys.argv[1]
want = set(sys.argv[2:])
m = json.load(open(os.path.join(d, "phytocal-run.json")))
listed = {f["path"]: f["sha256"] for f in m["files"]}
found = set()
for root, dirs, files in os.walk(d):
    for f in files:
        rel = os.path.relpath(os.path.join(root, f), d)
        if rel != "phytocal-run.json":
            found.add(rel)
bad = []
if set(listed) != found:
    bad.append("manifest %s, on disk %s" % (sorted(set(listed) - found)[:3], sorted(found - set(listed))[:3]))
if want and set(listed) != want:
    bad.append("manifest lists %s, expected %s" % (sorted(listed), sorted(want)))
for rel, sha in listed.items():
    p = os.path.join(d, rel)
    if os.path.exists(p) and hashlib.sha256(open(p, "rb").read()).hexdigest() != sha:
        bad.append("%s: SHA-256 differs" % rel)
print("; ".join(bad[:3]))
sys.exit(1 if bad else 0)
PYEOF
}

# links_exist DIR: every picture report.md links is a file of DIR; prints the count
links_exist() {
    "$PY" - "$1" >"$T/why.txt" <<'PYEOF' || why "$(cat "$T/why.txt")"
import os, re, sys
d = sys.argv[1]
links = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", open(os.path.join(d, "report.md")).read())
missing = [l for l in links if not os.path.isfile(os.path.join(d, l))]
print("links to missing files: %s" % missing[:3] if missing else len(links))
sys.exit(1 if missing or not links else 0)
PYEOF
}

# same_numbers A B: result.json A and B have the same cost and parameters
same_numbers() {
    "$PY" - "$1" "$2" >"$T/why.txt" <<'PYEOF' || why "$(cat "$T/why.txt")"
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
bad = [k for k in ("cost", "status") if a[k] != b[k]]
bad += [n for n in a["parameters"] if a["parameters"][n] != b["parameters"][n]]
print("differ: %s" % bad if bad else "")
sys.exit(1 if bad else 0)
PYEOF
}

# 1. a single fit without plots
run fit "$EX/enzyme_kinetics/enzyme.yaml" -o "$T/none" --plots none
want_rc 0
out_has "results: $T/none/ (result.json, report.md)"
[ "$(cd "$T/none" && ls | tr '\n' ' ')" = "phytocal-run.json report.md result.json " ] ||
    why "files: $(cd "$T/none" && ls | tr '\n' ' ')"
manifest_is "$T/none" result.json report.md
file_has "$T/none/report.md" "No plots were drawn for this run (\`--plots none\`)." || why "report.md does not say so"
file_has "$T/none/report.md" "](" && why "report.md links something"
run report --check "$T/none"
want_rc 0
run fit "$EX/enzyme_kinetics/enzyme.yaml" -o "$T/all" -q
want_rc 0
same_numbers "$T/none/result.json" "$T/all/result.json"
finish "--plots none: result.json, report.md and the manifest only; the same numbers"

# 2. the default draws the plots; --plots all is the default
for f in assay_fit.png assay_residuals.png assay_qq.png assay_acf.png; do
    [ -s "$T/all/$f" ] || why "$f missing"
done
manifest_is "$T/all"
links_exist "$T/all"
file_has "$T/all/report.md" "No plots were drawn" && why "report.md says no plots were drawn"
run fit "$EX/enzyme_kinetics/enzyme.yaml" -o "$T/all2" -q --plots all
want_rc 0
[ "$(cd "$T/all" && ls | tr '\n' ' ')" = "$(cd "$T/all2" && ls | tr '\n' ' ')" ] || why "--plots all wrote other files"
finish "default and --plots all: the plots, all listed and linked"

# 3. a batch without plots, of a kind that adds its own picture
run fit "$EX/pressure_volume/pv_leaves.yaml" --each leaf -o "$T/leaves_none" --plots none -q
want_rc 0
[ -z "$(find "$T/leaves_none" -name '*.png')" ] || why "PNG files: $(find "$T/leaves_none" -name '*.png' | head -3)"
[ "$(cd "$T/leaves_none/A" && ls | tr '\n' ' ')" = "phytocal-run.json report.md result.json " ] ||
    why "leaf A: $(cd "$T/leaves_none/A" && ls | tr '\n' ' ')"
manifest_is "$T/leaves_none"
manifest_is "$T/leaves_none/B" result.json report.md
run report --check "$T/leaves_none"
want_rc 0
run report --check "$T/leaves_none/A"
want_rc 0
run fit "$EX/pressure_volume/pv_leaves.yaml" --each leaf -o "$T/leaves_all" -q
want_rc 0
[ -s "$T/leaves_all/A/moduli_pv_curve.png" ] || why "the batch with plots lacks A/moduli_pv_curve.png"
cmp -s "$T/leaves_none/summary.tsv" "$T/leaves_all/summary.tsv" || why "summary.tsv differs with and without plots"
finish "--each with --plots none: no PNG, manifests exact, the same summary as with plots"

# 4. bad values
run fit "$EX/enzyme_kinetics/enzyme.yaml" -o "$T/bad" --plots some
want_rc 2
err_has "--plots: expected all or none, found 'some'"
[ -e "$T/bad" ] && why "$T/bad was written"
run fit "$EX/enzyme_kinetics/enzyme_runs.yaml" --each run -o "$T/bad_batch" --plots NONE
want_rc 2
err_has "--plots: expected all or none, found 'NONE'"
[ -e "$T/bad_batch" ] && why "$T/bad_batch was written"
run fit "$EX/enzyme_kinetics/enzyme.yaml" -o "$T/bad2" --plots
want_rc 1
err_has "--plots needs a value"
run fit "$EX/enzyme_kinetics/enzyme.yaml" "$EX/pressure_volume/pv_leaves.yaml" -o "$T/bad3" --plots
want_rc 1
err_has "--plots needs a value (all or none)"
finish "bad --plots values: exit 2 naming the option and the value, nothing written"

echo "$PASSED passed, $FAILED failed"
[ "$FAILED" -eq 0 ]
