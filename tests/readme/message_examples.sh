#!/usr/bin/env bash
# Examples of phytocal's messages for bad input, for the README (its block is
# checked against this script's output by check_readme.py).  Each case is the
# bundled enzyme example with one defect, run in a scratch folder.
#
#   bash tests/readme/message_examples.sh build/phytocal
set -u
PHC=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
EXAMPLE=$(cd "$(dirname "${BASH_SOURCE[0]}")/../../measurements/examples/enzyme_kinetics" && pwd)
T=$(mktemp -d "${TMPDIR:-/tmp}/phc_messages.XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT
cd "$T" || exit 1
cp "$EXAMPLE/enzyme.yaml" fit.yaml
cp "$EXAMPLE/enzyme.csv" enzyme.csv
show() { "$PHC" "$@" 2>&1 >/dev/null | head -1; }

# a value that is not a number in the data
sed '5s/,.*/,n\/a/' enzyme.csv >bad.csv
sed 's/file: enzyme.csv/file: bad.csv/' fit.yaml >bad_value.yaml
show fit bad_value.yaml -o out
# a misspelt key
sed 's/lower: 0/lowr: 0/' fit.yaml >typo.yaml
show fit typo.yaml -o out
# an expression with an unknown function
sed 's/expression: .*/expression: "vmax * substrate_mM \/ (km + sqr(substrate_mM))"/' fit.yaml >func.yaml
show fit func.yaml -o out
# a missing data file
sed 's/file: enzyme.csv/file: enzyme_2024.csv/' fit.yaml >missing.yaml
show fit missing.yaml -o out
# a run name that is a path
sed 's/^name: .*/name: "..\/..\/data"/' fit.yaml >name.yaml
show fit name.yaml
# an earlier run, and a folder of the user's
"$PHC" fit fit.yaml -o out --quiet
show fit fit.yaml -o out
echo "notes" >out/my_notes.txt
show fit fit.yaml -o out --force
show fit fit.yaml -o . --force
