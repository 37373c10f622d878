#!/usr/bin/env bash
# Batch fits (`phytocal fit A.yaml B.yaml -o DIR`, `phytocal fit CONFIG
# --each COLUMN -o DIR`) given bad inputs: each case says what is refused or
# how a failure is reported, and that the other fits are still done.
#
#   bash test_batch.sh PATH/TO/phytocal [SHARED_DATA_DIR]
#
# Each case prints "ok - <case>" or "not ok - <case>: <why>"; exit 1 if any failed.
source "$(dirname "${BASH_SOURCE[0]}")/../cli_cases.sh" "$@"
export LC_ALL=C
EX="$SCRIPT_DIR/../../measurements/examples"
no_leftovers() {
    local left
    left=$(ls -d "$1".tmp-* "$1".old-* 2>/dev/null | head -3 | tr '\n' ' ')
    [ -z "$left" ] || why "left behind: $left"
}

# a small curve example with a group column whose values need escaping
mkdir -p ex
cp "$EX/enzyme_kinetics/enzyme.yaml" "$EX/enzyme_kinetics/enzyme.csv" ex/
{
    echo "plate,substrate_mM,rate_umol_min"
    tail -n +4 ex/enzyme.csv | sed 's/^/a\/b,/'
    tail -n +4 ex/enzyme.csv | sed 's/^/..,/'
    tail -n +4 ex/enzyme.csv | sed 's/^/plate 3,/'
} >ex/plates.csv
sed 's/file: enzyme.csv/file: plates.csv/' ex/enzyme.yaml >ex/plates.yaml

# --each COLUMN that the table does not have
run fit ex/plates.yaml --each leaf -o out1
want_rc 2
err_has "plates.csv: --each: no column 'leaf'"
err_has "columns: plate, substrate_mM, rate_umol_min"
[ ! -e out1 ] || why "out1 was created"
finish "--each with a missing column: exit 2 naming the file and the column"

# group values that are not plain names are escaped (%XX), never paths
run fit ex/plates.yaml --each plate -o out2 -q
want_rc 0
for d in "a%2Fb" "%2E." "plate%203"; do
    [ -f "out2/$d/result.json" ] || why "out2/$d/result.json missing"
done
[ "$(ls out2 | tr '\n' ' ')" = "%2E. a%2Fb phytocal-run.json plate%203 summary.md summary.tsv " ] ||
    why "out2 holds $(ls out2 | tr '\n' ' ')"
grep -q "^a/b	a/b	" out2/summary.tsv || why "summary.tsv does not give the value a/b as it is"
finish "unsafe group values: escaped folder names, values kept in the summary"

# two configs with the same stem are refused before anything is fitted
mkdir -p other
cp ex/enzyme.yaml ex/enzyme.csv other/
run fit ex/enzyme.yaml other/enzyme.yaml -o out3
want_rc 2
err_has "have the same stem 'enzyme'"
err_has "nothing was fitted"
[ ! -e out3 ] || why "out3 was created"
no_leftovers out3
finish "clashing config stems: exit 2, nothing written"

# a failing config among good ones: the others are fitted, the worst exit code
printf 'name: broken\nparameters:\n  a: 1\ndatasets:\n  - kind: curve\n    file: nowhere.csv\n    x: x\n    y: y\n    expression: "a * x"\n' >ex/broken.yaml
grep -v -e '^solver:' -e '^  starts: 8' ex/enzyme.yaml >ex/stalls.yaml
printf 'solver:\n  max_iterations: 1\n  starts: 1\n' >>ex/stalls.yaml
run fit ex/enzyme.yaml ex/broken.yaml ex/plates.yaml -o out4
want_rc 2
out_has "enzyme: converged"
out_has "plates: converged"
out_has "broken: error (exit 2: "
err_has "1 of 3 fits did not succeed (exit 2"
[ -f out4/enzyme/result.json ] && [ -f out4/plates/result.json ] || why "the good fits were not written"
[ ! -e out4/broken ] || why "out4/broken written"
grep -q "^broken	.*	error	2	" out4/summary.tsv || why "summary.tsv lacks the failed row"
grep -qF "broken (error, exit 2): " out4/summary.md || why "summary.md does not name the failure"
finish "a config that fails to load: the others fitted, exit 2, named in the summary"

# a fit that does not converge beside a config that fails: exit 3 is the worst
run fit ex/stalls.yaml ex/broken.yaml -o out5
grep -q "^stalls	.*	not_converged	3	" out5/summary.tsv || why "stalls is not not_converged/3 in summary.tsv"
want_rc 3
[ -f out5/stalls/result.json ] || why "the unconverged fit was not written for inspection"
finish "not converged + bad input: exit 3 (the worst), both in the summary"

# a kind that cannot be split into groups
run fit "$EX/soil_probe/soil_probe.yaml" --each probe -o out6
want_rc 2
err_has "cannot be split into groups of rows"
err_has "kind 'soil_probe'"
[ ! -e out6 ] || why "out6 was created"
finish "--each on a kind that is not one table: exit 2 naming the kind"

# usage: no -o, --each with two configs
run fit ex/enzyme.yaml ex/plates.yaml
want_rc 1
err_has "needs -o DIR"
run fit ex/enzyme.yaml ex/plates.yaml --each plate -o out7
want_rc 1
err_has "give one config"
finish "batch usage errors: exit 1"

# run-directory safety as for one fit
run fit ex/plates.yaml --each plate -o out2 -q
want_rc 2
err_has "output directory exists"
echo "mine" >out2/notes.txt
run fit ex/plates.yaml --each plate -o out2 -q --force
want_rc 2
[ "$(cat out2/notes.txt 2>/dev/null)" = "mine" ] || why "the user's file was touched"
rm out2/notes.txt
run fit ex/plates.yaml --each plate -o out2 -q --force
want_rc 0
no_leftovers out2
run fit ex/plates.yaml --each plate -o ex -q --force
want_rc 2
[ -f ex/plates.csv ] || why "the data were removed"
finish "existing DIR: refused, --force only over a batch of phytocal's own, never the data"

echo "$PASSED passed, $FAILED failed"
[ "$FAILED" -eq 0 ]
