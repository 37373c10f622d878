#!/usr/bin/env bash
# Run directories never lose the user's data (issue 13), provenance can be
# checked, and help, version and progress behave as the README says.
#
#   bash test_run_dirs.sh PATH/TO/phytocal [SHARED_DATA_DIR]
#
# Each case prints "ok - <case>" or "not ok - <case>: <why>"; the last line
# is "N passed, M failed"; exit 1 if any failed.  Runs in the sanitizer build
# too (label bad_inputs): any sanitizer report fails the case.

source "$(dirname "${BASH_SOURCE[0]}")/../cli_cases.sh" "$@"
EXAMPLE_DIR="$SCRIPT_DIR/../../measurements/examples/enzyme_kinetics"
exists() { [ -e "$1" ] || why "$1 is gone"; }
no_leftovers() {
    local left
    left=$(ls -d "$1".tmp-* "$1".old-* 2>/dev/null | head -3 | tr '\n' ' ')
    [ -z "$left" ] || why "left behind: $left"
}
sha() { sha256sum "$1" | cut -d' ' -f1; }

fresh_example() {
    rm -rf "$T/ex"
    mkdir -p "$T/ex"
    cp "$EXAMPLE_DIR/enzyme.yaml" "$EXAMPLE_DIR/enzyme.csv" "$T/ex/"
}

# 1. a new run directory carries a manifest that lists what was written
fresh_example
run fit ex/enzyme.yaml -o run1 --quiet
want_rc 0
exists run1/phytocal-run.json
grep -q '"path": "result.json"' run1/phytocal-run.json || why "manifest does not list result.json"
grep -q '"sha256"' run1/phytocal-run.json || why "manifest has no SHA-256"
[ ! -s "$T/stdout" ] && [ ! -s "$T/stderr" ] || why "--quiet printed something"
no_leftovers run1
finish "fit writes a manifest; --quiet prints nothing"

# 2. without --force an existing directory is refused, untouched
before=$(sha run1/result.json)
run fit ex/enzyme.yaml -o run1 --quiet
want_rc 2
err_has "run1: output directory exists"
[ "$(sha run1/result.json)" = "$before" ] || why "result.json changed"
finish "existing run directory without --force"

# 3. --force replaces phytocal's own run directory
run fit ex/enzyme.yaml -o run1 --force --quiet
want_rc 0
exists run1/result.json
no_leftovers run1
finish "--force replaces a run directory that holds only phytocal's files"

# 4. a file and a folder of the user's in the run directory: refused, kept
echo "my notes" >run1/my_notes.txt
mkdir -p run1/photos && echo jpeg >run1/photos/leaf1.jpg
before=$(sha run1/result.json)
run fit ex/enzyme.yaml -o run1 --force --quiet
want_rc 2
err_has "phytocal did not write"
err_has "my_notes.txt"
err_has "photos/"
exists run1/my_notes.txt
exists run1/photos/leaf1.jpg
[ "$(sha run1/result.json)" = "$before" ] || why "the earlier run changed"
no_leftovers run1
finish "--force refuses a run directory holding the user's files"
rm -rf run1/my_notes.txt run1/photos

# 5. -o equal to the config's folder
run fit ex/enzyme.yaml -o ex --force --quiet
want_rc 2
err_has "ex: holds the config 'ex/enzyme.yaml'"
exists ex/enzyme.yaml
exists ex/enzyme.csv
no_leftovers ex
finish "-o equal to the config's folder is refused with --force"

# 6. a data folder without a manifest given as -o
mkdir -p data && echo "t,m" >data/raw_balance.csv
run fit ex/enzyme.yaml -o data --force --quiet
want_rc 2
err_has "not a phytocal run directory"
exists data/raw_balance.csv
no_leftovers data
finish "-o a data folder (no manifest) is refused with --force"

# 7. the run's data file inside a phytocal run directory (listed by a forged
#    manifest, as if a previous run had written it): never removed
mkdir -p forged
cp ex/enzyme.csv forged/enzyme.csv
printf '{"phytocal_run_directory": 1, "files": [{"path": "enzyme.csv", "sha256": "%s"}], "directories": []}\n' \
    "$(sha forged/enzyme.csv)" >forged/phytocal-run.json
sed 's#file: enzyme.csv#file: ../forged/enzyme.csv#' ex/enzyme.yaml >ex/forged_input.yaml
run fit ex/forged_input.yaml -o forged --force --quiet
want_rc 2
err_has "an input of this run"
exists forged/enzyme.csv
finish "a run directory holding the run's data file is refused"

# 8. a manifest that names paths outside its directory is not ours
mkdir -p evil
printf '{"phytocal_run_directory": 1, "files": ["../ex/enzyme.csv"], "directories": []}\n' >evil/phytocal-run.json
run fit ex/enzyme.yaml -o evil --force --quiet
want_rc 2
err_has "invalid path"
exists ex/enzyme.csv
finish "a manifest with '..' paths is refused"

# 9. name: is a name, not a path
for bad in '../../../../data' 'a/b' '.hidden'; do
    sed "s#^name: .*#name: \"$bad\"#" ex/enzyme.yaml >ex/badname.yaml
    run fit ex/badname.yaml --quiet
    want_rc 2
    err_has "badname.yaml:"
    err_has "is not a plain name"
    [ ! -e runs ] || why "runs/ was created"
    finish "name '$bad' is refused at load with its line"
done

# 10. report --check: inputs and outputs against the manifest
run fit ex/enzyme.yaml -o run2 --quiet
run report --check run2
want_rc 0
out_has "check: all"
out_has "config"
finish "report --check passes on an untouched run"
echo "# changed" >>ex/enzyme.yaml
run report --check run2/result.json
want_rc 3
out_has "CHANGED   config"
finish "report --check finds a changed config"
fresh_example
rm run2/report.md
run report --check run2
want_rc 3
out_has "MISSING   output     report.md"
finish "report --check finds a missing output"
run report --check ex
want_rc 2
err_has "phytocal-run.json"
finish "report --check on a directory without a manifest"

# 11. provenance in result.json and report.md
run fit ex/enzyme.yaml -o run3 --quiet
for key in '"provenance"' '"command_line"' '"sha256"' '"started"' '"finished"' '"host_processors"'; do
    grep -q "$key" run3/result.json || why "result.json lacks $key"
done
grep -q '^## Provenance' run3/report.md || why "report.md has no Provenance section"
grep -q 'enzyme.yaml' run3/report.md || why "report.md does not name the config"
finish "provenance in result.json and report.md"
run report run3/result.json
want_rc 0
out_has "vmax"
finish "report reads a result.json with provenance"

# 12. help and version
run --help
want_rc 0
out_has "exit codes"
out_has "phytocal fit"
finish "phytocal --help"
for cmd in fit simulate report; do
    run "$cmd" --help
    want_rc 0
    out_has "usage: phytocal $cmd"
    out_has "exit codes"
    finish "phytocal $cmd --help"
    run help "$cmd"
    want_rc 0
    out_has "usage: phytocal $cmd"
    finish "phytocal help $cmd"
done
run --version
want_rc 0
out_has "phytocal "
out_has "Ceres Solver"
finish "phytocal --version"
run help no_such_thing
want_rc 1
err_has "no_such_thing"
finish "help on an unknown topic is a usage error"
run fit ex/enzyme.yaml --frobnicate
want_rc 1
err_has "unknown option '--frobnicate'"
finish "unknown option names itself"

# 12b. a trailing slash names the same folder
run fit ex/enzyme.yaml -o run1/ --force --quiet
want_rc 0
exists run1/result.json
[ -z "$(ls -A run1 | grep -e '^\.tmp' -e '^run1')" ] || why "a temporary folder landed inside run1/"
no_leftovers run1
finish "-o DIR/ (trailing slash) replaces DIR itself"

# 13. progress: plain lines when stderr is not a terminal
run fit ex/enzyme.yaml -o run4
want_rc 0
err_has "start 1/"
err_has "uncertainty"
out_has "results: run4/"
finish "progress lines on stderr when not a terminal"

echo "$PASSED passed, $FAILED failed"
[ "$FAILED" -eq 0 ]
