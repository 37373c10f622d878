#!/usr/bin/env bash
# Bad-input tests of the phytocal command line (DESIGN.md §3-4, tests/bad_inputs).
#
#   bash test_bad_inputs.sh PATH/TO/phytocal [SHARED_DATA_DIR]
#
# Every malformed input must give: exit code 2; exactly one line on stderr,
# starting with "phytocal: ", that names the file and the line (or key) of the
# problem; no crash (no signal, no sanitizer report); no output directory and
# no temporary directory left behind.  Usage errors exit 1.  A positive
# control (the bundled enzyme example) checks that the harness itself is sound.
#
# PHC_TEST_VERBOSE=1 also prints each case's exit code and stderr.
# Prints "ok - <case>" / "not ok - <case>: <why>" per case, then
# "N passed, M failed"; exits 1 if any case failed.

set -u

PHC=${1:-}
if [ -z "$PHC" ]; then
    echo "usage: bash test_bad_inputs.sh PATH/TO/phytocal [SHARED_DATA_DIR]" >&2
    exit 2
fi
case "$PHC" in /*) ;; *) PHC="$PWD/$PHC" ;; esac
if [ ! -x "$PHC" ]; then
    echo "not ok - setup: $PHC is not an executable" >&2
    echo "0 passed, 1 failed"
    exit 1
fi
# The shared data folder is not needed: every input is written here.

SCRIPT_DIR=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
EXAMPLE_DIR="$SCRIPT_DIR/../../measurements/examples/enzyme_kinetics"

T=$(mktemp -d "${TMPDIR:-/tmp}/phc_bad_inputs.XXXXXX") || exit 1
# PHC_BAD_INPUTS_KEEP=DIR: copy the case files into DIR before they are
# removed (scripts/fuzz builds its seed corpora from them).
trap 'chmod -R u+rwx "$T" 2>/dev/null
      if [ -n "${PHC_BAD_INPUTS_KEEP:-}" ]; then cp -R "$T/cases/." "$PHC_BAD_INPUTS_KEEP/"; fi
      rm -rf "$T"' EXIT
cd "$T" || exit 1
mkdir -p cases
C="$T/cases"

# A generous limit: a hang is a failure, not a stuck CI job.
TIMEOUT=120
if command -v timeout >/dev/null 2>&1; then
    RUN=(timeout "$TIMEOUT")
else
    RUN=()
fi

PASSED=0
FAILED=0
FAIL_LIST=()

pass() { PASSED=$((PASSED + 1)); echo "ok - $1"; }
failc() {
    FAILED=$((FAILED + 1))
    FAIL_LIST+=("$1")
    echo "not ok - $1: $2"
}

# Runs phytocal with the given arguments; sets RC and ERR (stderr); stdout is in $T/stdout.
run_phc() {
    "${RUN[@]}" "$PHC" "$@" >"$T/stdout" 2>"$T/stderr"
    RC=$?
    # read without a subprocess: 313 cases x a few forks cost tens of
    # seconds on this machine
    mapfile -t ERR_LINES <"$T/stderr"
    local IFS=$'\n'
    ERR="${ERR_LINES[*]}"
}

# Appends to WHY the problems common to every error case.
# $1 expected exit code; remaining: substrings stderr must contain.
WHY=""
add_why() { WHY="${WHY:+$WHY; }$1"; }

check_error_output() {
    local want_rc=$1
    shift
    if [ "$RC" -ge 128 ] || [ "$RC" -eq 124 ]; then
        add_why "crashed or hung (exit code $RC)"
    elif [ "$RC" -ne "$want_rc" ]; then
        add_why "exit code $RC, expected $want_rc"
    fi
    case "$ERR" in
    *AddressSanitizer* | *"runtime error"* | *LeakSanitizer*) add_why "sanitizer report on stderr" ;;
    esac
    local nlines=${#ERR_LINES[@]}
    if [ "$nlines" -ne 1 ]; then
        add_why "stderr has $nlines lines, expected exactly 1"
    fi
    case "$ERR" in
    "phytocal: "*) ;;
    *) add_why "stderr does not start with 'phytocal: '" ;;
    esac
    local s
    for s in "$@"; do
        case "$ERR" in
        *"$s"*) ;;
        *) add_why "stderr lacks '$s'" ;;
        esac
    done
}

# No output directory, no temporary or set-aside directory next to it.
check_no_output() {
    local out=$1
    if [ -e "$out" ]; then
        add_why "output directory $(basename "$out") was created"
    fi
    local -a left=()
    local had_nullglob=0
    shopt -q nullglob && had_nullglob=1
    shopt -s nullglob
    left=("$out".tmp-* "$out".old*)
    [ "$had_nullglob" -eq 1 ] || shopt -u nullglob
    if [ "${#left[@]}" -gt 0 ]; then
        add_why "left behind: ${left[*]##*/}"
    fi
    if [ -e "$T/runs" ]; then
        add_why "a default runs/ directory was created"
        rm -rf "$T/runs"
    fi
}

report_case() {
    local name=$1
    if [ -n "${PHC_TEST_VERBOSE:-}" ]; then
        echo "# rc=$RC stderr: $(head -c 400 "$T/stderr" | tr '\n' '|')"
    fi
    if [ -z "$WHY" ]; then
        pass "$name"
    else
        failc "$name" "$WHY [rc=$RC stderr: $(head -c 400 "$T/stderr" | tr '\n' '|')]"
    fi
    WHY=""
}

# fit_case NAME CONFIG SUBSTRING...: `phytocal fit CONFIG -o OUT` must fail
# with exit code 2, one line naming the file and line/key, and no output.
# FIT_OPTS holds extra options (--quiet where the error comes after the fit
# has started, so progress lines do not count as error lines).
FIT_OPTS=()
fit_case() {
    local name=$1 config=$2
    shift 2
    local out="$T/out_${name//[^A-Za-z0-9_]/_}"
    WHY=""
    run_phc fit "$config" -o "$out" ${FIT_OPTS[@]+"${FIT_OPTS[@]}"}
    check_error_output 2 "$@"
    check_no_output "$out"
    report_case "$name"
}

# ----------------------------------------------------------------------------
# Shared valid pieces.
cat >"$C/data.csv" <<'EOF'
x,y
1,2.1
2,3.9
3,6.2
4,8.0
5,9.9
6,12.1
EOF

# write_config FILE [PARAMETERS_BLOCK] [DATASET_BLOCK] [EXTRA]: a config with
# the given parameter and data-set blocks (defaults: a valid straight line).
PARAMS_OK='parameters:
  a: {value: 1, lower: 0, upper: 10}
  b: {value: 0.5}'
dataset_block() { # $1 csv file, $2 expression, $3 extra data-set lines
    printf '  - kind: curve\n    file: %s\n    x: x\n    y: y\n    expression: "%s"\n%s' "$1" "$2" "${3:-}"
}
write_config() {
    local file=$1 params=${2:-$PARAMS_OK} ds=${3:-}
    [ -n "$ds" ] || ds=$(dataset_block data.csv "a*x + b")
    printf 'name: t\n%s\ndatasets:\n%s\n' "$params" "$ds" >"$file"
}

# Sanity: the valid base config fits (otherwise every case below is moot).
write_config "$C/base.yaml"
WHY=""
run_phc fit "$C/base.yaml" -o "$T/out_base" --quiet
if [ "$RC" -ne 0 ]; then
    add_why "exit code $RC, expected 0"
fi
[ -f "$T/out_base/result.json" ] || add_why "no result.json"
report_case "control: valid base config fits"
rm -rf "$T/out_base"

# ---- malformed YAML ----------------------------------------------------------
cat >"$C/indent.yaml" <<'EOF'
name: t
parameters:
  a: {value: 1}
   b: {value: 2}
datasets:
  - kind: curve
    file: data.csv
    x: x
    y: y
    expression: "a*x + b"
EOF
fit_case "yaml: bad indentation" "$C/indent.yaml" "indent.yaml:4"

cat >"$C/bracket.yaml" <<'EOF'
name: t
parameters:
  a: {value: 1, lower: 0
  b: {value: 2}
datasets:
  - kind: curve
    file: data.csv
    x: x
    y: y
    expression: "a*x + b"
EOF
fit_case "yaml: unclosed bracket" "$C/bracket.yaml" "bracket.yaml:"

cat >"$C/bracket2.yaml" <<'EOF'
name: t
parameters:
  a: {value: 1}
  b: {value: 2}
datasets: [
EOF
fit_case "yaml: unclosed flow sequence at end of file" "$C/bracket2.yaml" "bracket2.yaml:"

printf 'name: t\nparameters:\n\ta: {value: 1}\n' >"$C/tab.yaml"
fit_case "yaml: tab indentation" "$C/tab.yaml" "tab.yaml:3"

printf 'just a scalar\n' >"$C/scalar.yaml"
fit_case "yaml: config is a bare scalar" "$C/scalar.yaml" "scalar.yaml:1"

: >"$C/empty.yaml"
fit_case "yaml: empty config file" "$C/empty.yaml" "empty.yaml"

printf -- '- a\n- b\n' >"$C/seq.yaml"
fit_case "yaml: config is a sequence" "$C/seq.yaml" "seq.yaml:1"

cat >"$C/dupkey.yaml" <<'EOF'
name: t
parameters:
  a: {value: 1, value: 2}
  b: {value: 2}
datasets:
  - kind: curve
    file: data.csv
    x: x
    y: y
    expression: "a*x + b"
EOF
fit_case "yaml: duplicate key" "$C/dupkey.yaml" "dupkey.yaml:3" "value"

# ---- unknown keys, with suggestions -----------------------------------------
{
    printf 'name: t\nparamters:\n  a: {value: 1}\n  b: {value: 2}\ndatasets:\n'
    dataset_block data.csv "a*x + b"
} >"$C/topkey.yaml"
fit_case "unknown top-level key 'paramters'" "$C/topkey.yaml" "topkey.yaml:2" "paramters" "did you mean 'parameters'"

write_config "$C/lowr.yaml" 'parameters:
  a: {value: 1, lowr: 0}
  b: {value: 0.5}'
fit_case "unknown parameter key 'lowr'" "$C/lowr.yaml" "lowr.yaml:3" "lowr" "did you mean 'lower'"

write_config "$C/dskey.yaml" "$PARAMS_OK" "$(dataset_block data.csv "a*x + b" '    sigmaa: 1
')"
fit_case "unknown data-set key 'sigmaa'" "$C/dskey.yaml" "dskey.yaml:11" "sigmaa" "did you mean 'sigma'"

write_config "$C/dskey2.yaml" "$PARAMS_OK" '  - kind: curve
    file: data.csv
    x: x
    y: y
    expresion: "a*x + b"'
fit_case "unknown data-set key 'expresion'" "$C/dskey2.yaml" "dskey2.yaml:10" "did you mean 'expression'"

write_config "$C/kind.yaml" "$PARAMS_OK" '  - kind: curv
    file: data.csv
    x: x
    y: y
    expression: "a*x + b"'
fit_case "unknown data-set kind 'curv'" "$C/kind.yaml" "kind.yaml:6" "curv" "did you mean 'curve'"

write_config "$C/solverkey.yaml"
printf 'solver:\n  max_iteration: 10\n' >>"$C/solverkey.yaml"
fit_case "unknown solver key 'max_iteration'" "$C/solverkey.yaml" "solverkey.yaml:" "did you mean 'max_iterations'"

write_config "$C/nokind.yaml" "$PARAMS_OK" '  - file: data.csv
    x: x
    y: y
    expression: "a*x + b"'
fit_case "data set without 'kind'" "$C/nokind.yaml" "nokind.yaml:6" "kind"

write_config "$C/noexpr.yaml" "$PARAMS_OK" '  - kind: curve
    file: data.csv
    x: x
    y: y'
fit_case "curve data set without 'expression'" "$C/noexpr.yaml" "noexpr.yaml:6" "expression"

write_config "$C/nocol.yaml" "$PARAMS_OK" '  - kind: curve
    file: data.csv
    x: x
    y: yy
    expression: "a*x + b"'
fit_case "y column not in the CSV" "$C/nocol.yaml" "nocol.yaml:9" "yy"

write_config "$C/valnum.yaml" 'parameters:
  a: {value: abc}
  b: {value: 0.5}'
fit_case "parameter value not a number" "$C/valnum.yaml" "valnum.yaml:3" "abc"

# ---- missing and unreadable files -------------------------------------------
write_config "$C/missing.yaml" "$PARAMS_OK" "$(dataset_block nope.csv "a*x + b")"
# A file that cannot be read names the config line and key that named it.
fit_case "missing CSV file" "$C/missing.yaml" "missing.yaml:7" "key 'file'" "nope.csv" "No such file"

mkdir -p "$C/adir.csv"
write_config "$C/dirfile.yaml" "$PARAMS_OK" "$(dataset_block adir.csv "a*x + b")"
fit_case "directory given as the CSV file" "$C/dirfile.yaml" "dirfile.yaml:7" "key 'file'" "adir.csv"

fit_case "missing config file" "$C/no_such_config.yaml" "no_such_config.yaml"

mkdir -p "$C/dirconfig.yaml"
fit_case "directory given as the config file" "$C/dirconfig.yaml" "dirconfig.yaml"

if [ "$(id -u)" -ne 0 ]; then
    cp "$C/data.csv" "$C/noread.csv"
    chmod 000 "$C/noread.csv"
    write_config "$C/noread.yaml" "$PARAMS_OK" "$(dataset_block noread.csv "a*x + b")"
    fit_case "CSV file without read permission" "$C/noread.yaml" "noread.yaml:7" "key 'file'" "noread.csv"
fi

# ---- CSV contents -------------------------------------------------------------
# csv_case NAME ROW3 EXPECT...: data.csv with its 3rd data row (file line 4)
# replaced by ROW3.
csv_case() {
    local name=$1 file=$2 row=$3
    shift 3
    printf 'x,y\n1,2.1\n2,3.9\n%s\n4,8.0\n5,9.9\n6,12.1\n' "$row" >"$C/$file.csv"
    write_config "$C/$file.yaml" "$PARAMS_OK" "$(dataset_block "$file.csv" "a*x + b")"
    fit_case "$name" "$C/$file.yaml" "$file.csv:4:" "$@"
}
csv_case "CSV: empty cell" cell_empty "3,"
csv_case "CSV: empty cell in the first column" cell_empty1 ",6.2"
csv_case "CSV: non-numeric cell 'n/a'" cell_na "3,n/a" "n/a"
csv_case "CSV: 'nan'" cell_nan "3,nan" "nan"
csv_case "CSV: 'NaN'" cell_nan2 "3,NaN" "NaN"
csv_case "CSV: 'inf'" cell_inf "3,inf" "inf"
csv_case "CSV: '-Infinity'" cell_ninf "3,-Infinity" "Infinity"
csv_case "CSV: overflowing number 1e999" cell_huge "3,1e999" "1e999"
csv_case "CSV: trailing garbage '6.2abc'" cell_garbage "3,6.2abc" "6.2abc"
csv_case "CSV: ragged row (too many cells)" ragged_long "3,6.2,7"
csv_case "CSV: ragged row (too few cells)" ragged_short "3"

printf 'x,y\n' >"$C/header_only.csv"
write_config "$C/header_only.yaml" "$PARAMS_OK" "$(dataset_block header_only.csv "a*x + b")"
fit_case "CSV: header only, no rows" "$C/header_only.yaml" "header_only.csv"

: >"$C/empty_csv.csv"
write_config "$C/empty_csv.yaml" "$PARAMS_OK" "$(dataset_block empty_csv.csv "a*x + b")"
fit_case "CSV: empty file" "$C/empty_csv.yaml" "empty_csv.csv"

# ---- expressions ----------------------------------------------------------------
write_config "$C/expr_syntax.yaml" "$PARAMS_OK" "$(dataset_block data.csv "a*x + * b")"
# the second '*' is character 7 of the expression
fit_case "expression: syntax error (position)" "$C/expr_syntax.yaml" "expr_syntax.yaml:10" "character 7"

# 9,970 nested parentheses (a fuzzing find: it overflowed the stack), under a
# 2 MiB stack as a small embedding program would have: refused with a message
DEEP=$(printf '%.0s(' $(seq 9970))a*x$(printf '%.0s)' $(seq 9970))
write_config "$C/expr_deep.yaml" "$PARAMS_OK" "$(dataset_block data.csv "$DEEP + b")"
RUN_SAVED=("${RUN[@]}")
if command -v prlimit >/dev/null 2>&1; then RUN=(prlimit --stack=2097152 "${RUN_SAVED[@]}"); fi
fit_case "expression: 9970 nested parentheses" "$C/expr_deep.yaml" "expr_deep.yaml:10" "nested more than 200 levels deep" "(19947 characters)"
RUN=("${RUN_SAVED[@]}")
# a long expression with an error at its end: the message keeps the reason
LONG="$(printf 'a*x + %.0s' $(seq 400))b + * 2"
write_config "$C/expr_long.yaml" "$PARAMS_OK" "$(dataset_block data.csv "$LONG")"
fit_case "expression: long, error at the end" "$C/expr_long.yaml" "expr_long.yaml:10" "(2407 characters)" "character 2405"

write_config "$C/expr_paren.yaml" "$PARAMS_OK" "$(dataset_block data.csv "a*(x + b")"
fit_case "expression: unbalanced parenthesis" "$C/expr_paren.yaml" "expr_paren.yaml:10" "character "

write_config "$C/expr_name.yaml" "$PARAMS_OK" "$(dataset_block data.csv "a*x + b + zeta")"
fit_case "expression: unknown name" "$C/expr_name.yaml" "expr_name.yaml:10" "zeta" "character 11"

# muparser alone says 'Unexpected parenthesis': name the function, its
# character (5) and the functions there are
write_config "$C/expr_fun.yaml" "$PARAMS_OK" "$(dataset_block data.csv "a * expp(x) + b")"
fit_case "expression: unknown function" "$C/expr_fun.yaml" "expr_fun.yaml:10" "unknown function 'expp' at character 5" \
    "did you mean 'exp'?" "known functions: exp log"

write_config "$C/expr_pfun.yaml" "$PARAMS_OK" "$(dataset_block data.csv "a(x) + b")"
fit_case "expression: a parameter used as a function" "$C/expr_pfun.yaml" "expr_pfun.yaml:10" \
    "'a' at character 1 is a parameter, not a function"

write_config "$C/expr_ambig.yaml" 'parameters:
  a: {value: 1}
  x: {value: 0.5}' "$(dataset_block data.csv "a*x")"
fit_case "expression: name is both a parameter and a column" "$C/expr_ambig.yaml" "expr_ambig.yaml:10" "'x'"

# The model cannot be evaluated at the start values: b/(x-3) divides by zero
# on the row x = 3 (nonfinite.csv line 4).  The message must still say where:
# the config or the CSV file, not only an internal residual-block number.
cp "$C/data.csv" "$C/nonfinite.csv"
write_config "$C/nonfinite.yaml" "$PARAMS_OK" "$(dataset_block nonfinite.csv "a*x + b/(x - 3)")"
FIT_OPTS=(--quiet)
fit_case "model not finite at the start values" "$C/nonfinite.yaml" "nonfinite."
FIT_OPTS=()

write_config "$C/expr_empty.yaml" "$PARAMS_OK" "$(dataset_block data.csv "")"
fit_case "expression: empty" "$C/expr_empty.yaml" "expr_empty.yaml:" "expression"

# ---- parameters and bounds ------------------------------------------------------
write_config "$C/bounds.yaml" 'parameters:
  a: {value: 1, lower: 5, upper: 2}
  b: {value: 0.5}'
fit_case "lower > upper" "$C/bounds.yaml" "bounds.yaml:3" "lower"

write_config "$C/start.yaml" 'parameters:
  a: {value: 20, lower: 0, upper: 10}
  b: {value: 0.5}'
fit_case "start outside its bounds" "$C/start.yaml" "start.yaml:3" "20"

write_config "$C/start2.yaml" 'parameters:
  a: {value: -1, lower: 0}
  b: {value: 0.5}'
fit_case "start below its lower bound" "$C/start2.yaml" "start2.yaml:3"

# 1e308 is finite, but the multi-start box (10 times the start) is not
write_config "$C/huge.yaml" 'parameters:
  a: {value: 1e308, lower: 0}
  b: {value: 0.5}'
fit_case "start value 1e308" "$C/huge.yaml" "huge.yaml:3" "parameter 'a'" "1e+308" "too large"

write_config "$C/hugebound.yaml" 'parameters:
  a: {value: 1}
  b: {value: 0.5, lower: -1e305}'
fit_case "lower bound -1e305" "$C/hugebound.yaml" "hugebound.yaml:4" "parameter 'b'" "lower bound -1e+305"

write_config "$C/tinyscale.yaml" 'parameters:
  a: {value: 1, scale: 1e-305}
  b: {value: 0.5}'
fit_case "start value over its scale overflows" "$C/tinyscale.yaml" "tinyscale.yaml:3" "parameter 'a'" "scale 1e-305"

write_config "$C/unused.yaml" 'parameters:
  a: {value: 1, lower: 0, upper: 10}
  b: {value: 0.5}
  c: {value: 3}'
fit_case "parameter not used by any data set" "$C/unused.yaml" "unused.yaml" "'c'"

printf 'name: t\n%s\ndatasets: []\n' "$PARAMS_OK" >"$C/nodatasets.yaml"
fit_case "empty datasets list" "$C/nodatasets.yaml" "nodatasets.yaml:5" "datasets"

printf 'name: t\n%s\n' "$PARAMS_OK" >"$C/nodatasetkey.yaml"
fit_case "no datasets key" "$C/nodatasetkey.yaml" "nodatasetkey.yaml" "datasets"

write_config "$C/bind.yaml" "$PARAMS_OK" "$(dataset_block data.csv "a*x + b" '    parameters: {a: zz}
')"
fit_case "data set binds a slot to an unknown parameter" "$C/bind.yaml" "bind.yaml:11" "'zz'"

write_config "$C/allfixed.yaml" 'parameters:
  a: {value: 1, fixed: true}
  b: {value: 0.5, fixed: true}'
fit_case "every parameter fixed" "$C/allfixed.yaml" "allfixed.yaml" "fixed"

write_config "$C/dupname.yaml" "$PARAMS_OK" "$(dataset_block data.csv "a*x + b" '    name: same
')
$(dataset_block data.csv "a*x + b" '    name: same
')"
fit_case "two data sets with the same name" "$C/dupname.yaml" "dupname.yaml:" "'same'"

# ---- sigma -----------------------------------------------------------------------
write_config "$C/sigma0.yaml" "$PARAMS_OK" "$(dataset_block data.csv "a*x + b" '    sigma: 0
')"
fit_case "sigma 0" "$C/sigma0.yaml" "sigma0.yaml:11" "sigma"

write_config "$C/sigmaneg.yaml" "$PARAMS_OK" "$(dataset_block data.csv "a*x + b" '    sigma: -0.5
')"
fit_case "sigma negative" "$C/sigmaneg.yaml" "sigmaneg.yaml:11" "sigma"

printf 'x,y,s\n1,2.1,0.1\n2,3.9,0.1\n3,6.2,0\n4,8.0,0.1\n5,9.9,0.1\n6,12.1,0.1\n' >"$C/sigcol.csv"
write_config "$C/sigcol.yaml" "$PARAMS_OK" "$(dataset_block sigcol.csv "a*x + b" '    sigma: s
')"
fit_case "sigma column with a zero" "$C/sigcol.yaml" "sigcol.csv:4:" "'s'"

printf 'x,y,s\n1,2.1,0.1\n2,3.9,0.1\n3,6.2,0.1\n4,8.0,-0.1\n5,9.9,0.1\n6,12.1,0.1\n' >"$C/sigcolneg.csv"
write_config "$C/sigcolneg.yaml" "$PARAMS_OK" "$(dataset_block sigcolneg.csv "a*x + b" '    sigma: s
')"
fit_case "sigma column with a negative value" "$C/sigcolneg.yaml" "sigcolneg.csv:5:" "'s'"

# ---- too few points --------------------------------------------------------------
printf 'x,y\n1,2.1\n' >"$C/few.csv"
write_config "$C/few.yaml" "$PARAMS_OK" "$(dataset_block few.csv "a*x + b")"
fit_case "fewer points than free parameters" "$C/few.yaml" "few.yaml"

# ---- loss and solver values --------------------------------------------------------
write_config "$C/loss.yaml" "$PARAMS_OK" "$(dataset_block data.csv "a*x + b" '    loss: hubber
')"
fit_case "unknown loss 'hubber'" "$C/loss.yaml" "loss.yaml:11" "did you mean 'huber'"

write_config "$C/starts.yaml"
printf 'solver:\n  starts: -3\n' >>"$C/starts.yaml"
fit_case "solver starts negative" "$C/starts.yaml" "starts.yaml:12" "starts"

write_config "$C/level.yaml"
printf 'report:\n  level: 2\n' >>"$C/level.yaml"
fit_case "report level outside (0, 1)" "$C/level.yaml" "level.yaml:12" "level"

write_config "$C/lscale.yaml" "$PARAMS_OK" "$(dataset_block data.csv "a*x + b" '    loss: huber
    loss_scale: -1
')"
fit_case "negative loss_scale" "$C/lscale.yaml" "lscale.yaml:" "loss_scale"

write_config "$C/sigmacol.yaml" "$PARAMS_OK" "$(dataset_block data.csv "a*x + b" '    sigma: nosuchcol
')"
fit_case "sigma names a column that does not exist" "$C/sigmacol.yaml" "sigmacol.yaml:11" "nosuchcol"

# ---- existing output directory ------------------------------------------------------
write_config "$C/exists.yaml"
EXIST="$T/out_exists"
mkdir -p "$EXIST"
echo "earlier run" >"$EXIST/marker.txt"
WHY=""
run_phc fit "$C/exists.yaml" -o "$EXIST"
check_error_output 2 "out_exists" "--force"
if [ "$(cat "$EXIST/marker.txt" 2>/dev/null)" != "earlier run" ]; then
    add_why "the existing directory's marker file did not survive"
fi
if [ "$(ls -A "$EXIST" | wc -l)" -ne 1 ]; then
    add_why "the existing directory was modified: $(ls -A "$EXIST" | tr '\n' ' ')"
fi
left=$(ls -d "$EXIST".tmp-* "$EXIST".old* 2>/dev/null | head -3)
[ -z "$left" ] || add_why "left behind: $left"
report_case "existing output directory without --force"

echo "a file" >"$T/out_isfile"
WHY=""
run_phc fit "$C/exists.yaml" -o "$T/out_isfile" --force
check_error_output 2 "out_isfile"
[ "$(cat "$T/out_isfile")" = "a file" ] || add_why "the existing file was modified"
left=$(ls -d "$T"/out_isfile.tmp-* "$T"/out_isfile.old* 2>/dev/null | head -3)
[ -z "$left" ] || add_why "left behind: $left"
report_case "output path is an existing file (with --force)"

# The output's parent is a file: fails when the run directory is created, after
# the fit (hence --quiet); nothing may be left behind.
echo "a file" >"$T/parent_file"
WHY=""
run_phc fit "$C/exists.yaml" -o "$T/parent_file/out" --quiet
check_error_output 2 "parent_file"
[ "$(cat "$T/parent_file")" = "a file" ] || add_why "the file was modified"
left=$(ls -d "$T"/parent_file.tmp-* "$T"/parent_file/out* 2>/dev/null | head -3)
[ -z "$left" ] || add_why "left behind: $left"
report_case "output directory under an existing file"

# ---- report on bad files -------------------------------------------------------------
report_case_run() { # NAME FILE SUBSTRING...
    local name=$1 file=$2
    shift 2
    WHY=""
    run_phc report "$file"
    check_error_output 2 "$@"
    report_case "$name"
}
report_case_run "report: missing file" "$T/nowhere/result.json" "nowhere/result.json"

printf '{\n  "status": "converged",\n  "iterations": 3,,\n  "cost": 1\n}\n' >"$C/malformed.json"
report_case_run "report: malformed JSON (line:col)" "$C/malformed.json" "malformed.json:3:"

printf '{\n  "status": "converged",\n  "iterations": 3\n' >"$C/truncated.json"
report_case_run "report: truncated JSON" "$C/truncated.json" "truncated.json:"

printf '{\n  "status": "converged",\n  "iterations": 3,\n  "cost": 1.5\n}\n' >"$C/fields.json"
# result.json without "parameters", "datasets", ... : the missing field is named
report_case_run "report: JSON missing fields" "$C/fields.json" "fields.json:" "expected"

printf '[1, 2, 3]\n' >"$C/array.json"
report_case_run "report: JSON that is not an object" "$C/array.json" "array.json"

: >"$C/empty.json"
report_case_run "report: empty file" "$C/empty.json" "empty.json"

mkdir -p "$C/dir.json"
# Not "invalid JSON near end of file": say that it is a directory.
report_case_run "report: a directory" "$C/dir.json" "dir.json" "directory"

# ---- usage errors: exit 1 ---------------------------------------------------------
usage_case() { # NAME ARGS...
    local name=$1
    shift
    WHY=""
    run_phc "$@"
    if [ "$RC" -ge 128 ] || [ "$RC" -eq 124 ]; then
        add_why "crashed or hung (exit code $RC)"
    elif [ "$RC" -ne 1 ]; then
        add_why "exit code $RC, expected 1"
    fi
    if grep -q -e 'AddressSanitizer' -e 'runtime error' "$T/stderr"; then
        add_why "sanitizer report on stderr"
    fi
    [ -n "$ERR" ] || add_why "nothing on stderr"
    case "$ERR" in *usage*) ;; *) add_why "stderr shows no usage" ;; esac
    [ ! -e "$T/runs" ] || { add_why "a runs/ directory was created"; rm -rf "$T/runs"; }
    report_case "$name"
}
usage_case "usage: no arguments"
usage_case "usage: unknown command" frobnicate
usage_case "usage: unknown option" fit "$C/base.yaml" --bogus
usage_case "usage: fit without a config" fit
usage_case "usage: -o without a directory" fit "$C/base.yaml" -o
usage_case "usage: report with an unknown option" report "$C/fields.json" --force
usage_case "usage: two config files" fit "$C/base.yaml" "$C/base.yaml"

# ---- positive control: the bundled enzyme example -------------------------------------
GOOD="$T/out_enzyme"
WHY=""
if [ ! -f "$EXAMPLE_DIR/enzyme.yaml" ]; then
    add_why "example $EXAMPLE_DIR/enzyme.yaml not found"
    RC=0
    : >"$T/stderr"
else
    run_phc fit "$EXAMPLE_DIR/enzyme.yaml" -o "$GOOD"
    [ "$RC" -eq 0 ] || add_why "exit code $RC, expected 0"
    [ -s "$GOOD/result.json" ] || add_why "no result.json"
    [ -s "$GOOD/report.md" ] || add_why "no report.md"
    npng=$(ls "$GOOD"/*.png 2>/dev/null | wc -l)
    [ "$npng" -eq 4 ] || add_why "$npng PNG files, expected 4"
    left=$(ls -d "$GOOD".tmp-* "$GOOD".old* 2>/dev/null | head -3)
    [ -z "$left" ] || add_why "left behind: $left"
fi
report_case "control: enzyme example fits, writes result.json, report.md, 4 PNGs"

WHY=""
if [ -d "$GOOD" ]; then
    # a file phytocal wrote, changed since: --force replaces it (files
    # phytocal did not write are refused: tests/bad_inputs/test_run_dirs.sh)
    echo "stale" >"$GOOD/report.md"
    run_phc fit "$EXAMPLE_DIR/enzyme.yaml" -o "$GOOD" --force --quiet
    [ "$RC" -eq 0 ] || add_why "exit code $RC, expected 0"
    ! grep -qx "stale" "$GOOD/report.md" || add_why "the earlier run was not replaced (stale report.md still there)"
    [ -s "$GOOD/result.json" ] || add_why "no result.json after --force"
    npng=$(ls "$GOOD"/*.png 2>/dev/null | wc -l)
    [ "$npng" -eq 4 ] || add_why "$npng PNG files after --force, expected 4"
    left=$(ls -d "$GOOD".tmp-* "$GOOD".old* 2>/dev/null | head -3)
    [ -z "$left" ] || add_why "left behind: $left"
else
    add_why "no earlier run to replace"
fi
report_case "control: --force replaces the earlier run"

WHY=""
run_phc report "$GOOD/result.json"
[ "$RC" -eq 0 ] || add_why "report exit code $RC, expected 0"
verdict=$(grep -i '^verdict:' "$T/stdout" | head -1)
[ -n "$verdict" ] || add_why "no 'verdict:' line in the report output"
run_phc report "$GOOD/result.json" --strict
strict_rc=$RC
case "$verdict" in
*"no problems"*)
    [ "$strict_rc" -eq 0 ] || add_why "verdict '$verdict' but --strict exits $strict_rc (expected 0)" ;;
"")
    ;;
*)
    [ "$strict_rc" -eq 3 ] || add_why "verdict '$verdict' but --strict exits $strict_rc (expected 3)" ;;
esac
if [ "$strict_rc" -ne 0 ] && [ "$strict_rc" -ne 3 ]; then
    add_why "--strict exit code $strict_rc, expected 0 or 3"
fi
report_case "control: report exits 0 and --strict agrees with the verdict"

# ---- pv_curve ---------------------------------------------------------------
# Pressure-volume data sets (fit/costs/pv_curve.h): each case exits 2 with one
# stderr line naming the file and line (or the config key).
PV_PARAMS='parameters:
  kappa: {value: 20, lower: 0}
  chi0:  {value: 0.85}
  e_min: {value: 0, fixed: true}
  e_max: {value: 5, lower: 0}'
pv_csv() { # FILE [ROW3]: two leaves of 6 points; ROW3 replaces leaf A's 3rd point (line 4)
    local row3=${2:-A,-0.95,1.5305,0.352,1.604}
    printf 'leaf,psi,fresh,dry,sat\nA,-0.40,1.6025,0.352,1.604\nA,-0.67,1.5681,0.352,1.604\n%s\nA,-1.28,1.4725,0.352,1.604\nA,-1.46,1.4102,0.352,1.604\nA,-1.64,1.3514,0.352,1.604\nB,-0.45,1.3692,0.291,1.377\nB,-0.71,1.3420,0.291,1.377\nB,-0.91,1.3172,0.291,1.377\nB,-1.29,1.2591,0.291,1.377\nB,-1.48,1.2091,0.291,1.377\nB,-1.64,1.1547,0.291,1.377\n' "$row3" >"$C/$1"
}
pv_config() { # FILE CSV EXTRA_LINES (dry/saturated/leaf keys)
    printf 'name: t\n%s\ndatasets:\n  - kind: pv_curve\n    file: %s\n    psi: psi\n    fresh_mass: fresh\n    group: leaf\n%s' \
        "$PV_PARAMS" "$2" "$3" >"$C/$1"
}
pv_csv pv_ok.csv
pv_config pv_nodry.yaml pv_ok.csv '    saturated_mass: sat
    leaf: A
'
fit_case "pv_curve: missing dry mass" "$C/pv_nodry.yaml" "pv_nodry.yaml:8" "dry_mass"
pv_config pv_nosat.yaml pv_ok.csv '    dry_mass: dry
    leaf: A
'
fit_case "pv_curve: missing saturated mass" "$C/pv_nosat.yaml" "pv_nosat.yaml:8" "saturated_mass"
pv_csv pv_pos.csv A,0.95,1.5305,0.352,1.604
pv_config pv_pos.yaml pv_pos.csv '    dry_mass: dry
    saturated_mass: sat
    leaf: A
'
fit_case "pv_curve: positive water potential" "$C/pv_pos.yaml" "pv_pos.csv:4:" "negative"
pv_csv pv_text.csv A,-0.95,n/a,0.352,1.604
pv_config pv_text.yaml pv_text.csv '    dry_mass: dry
    saturated_mass: sat
    leaf: A
'
fit_case "pv_curve: non-numeric mass" "$C/pv_text.yaml" "pv_text.csv:4:" "n/a"
pv_config pv_tlp.yaml pv_ok.csv '    dry_mass: dry
    saturated_mass: sat
    leaf: A
    tlp: guessed
'
fit_case "pv_curve: unknown tlp convention" "$C/pv_tlp.yaml" "pv_tlp.yaml:16" "'guessed'" "fitted, measured"
pv_config pv_conv.yaml pv_ok.csv '    dry_mass: dry
    saturated_mass: sat
    leaf: A
    convention: pvldcurve
'
fit_case "pv_curve: unknown convention" "$C/pv_conv.yaml" "pv_conv.yaml:16" "'pvldcurve'" "photosynthesis"
pv_config pv_area.yaml pv_ok.csv '    dry_mass: dry
    saturated_mass: sat
    leaf: A
    leaf_area: 0
'
fit_case "pv_curve: leaf area not positive" "$C/pv_area.yaml" "pv_area.yaml:16" "'leaf_area'" "positive"
pv_config pv_group.yaml pv_ok.csv '    dry_mass: dry
    saturated_mass: sat
    leaf: L9
'
fit_case "pv_curve: unknown leaf id" "$C/pv_group.yaml" "pv_group.yaml:15" "'L9'"
printf 'leaf,psi,fresh,dry,sat\nA,-0.40,1.6025,0.352,1.604\n' >"$C/pv_one.csv"
pv_config pv_one.yaml pv_one.csv '    dry_mass: dry
    saturated_mass: sat
    leaf: A
'
fit_case "pv_curve: a single point" "$C/pv_one.yaml" "pv_one.csv:2:" "1 point"
pv_config pv_each.yaml pv_ok.csv '    dry_mass: dry
    saturated_mass: sat
'
fit_case "pv_curve: several leaves, none chosen" "$C/pv_each.yaml" "pv_each.yaml:" "leaf"
pv_config pv_unit.yaml pv_ok.csv '    dry_mass: dry
    saturated_mass: sat
    leaf: A
    psi_unit: psi
'
fit_case "pv_curve: unknown potential unit" "$C/pv_unit.yaml" "pv_unit.yaml:16" "psi_unit"
pv_config pv_nofile.yaml pv_none.csv '    dry_mass: dry
    saturated_mass: sat
    leaf: A
'
fit_case "pv_curve: missing data file" "$C/pv_nofile.yaml" "pv_nofile.yaml:9" "key 'file'" "pv_none.csv" "No such file"
# ---- end pv_curve -------------------------------------------------------------

# ---- weight_curve and plant graphs -----------------------------------------
# Balance curves (fit/costs/weight_curve.h) and every malformed plant-graph
# file of tests/bad_inputs/plant_graphs/ (read through `plant:`): each case
# exits 2 with one stderr line naming the file and line (or the key).
GRAPH_DIR="$SCRIPT_DIR/plant_graphs"
WC_PARAMS='parameters:
  delta: {value: 1.0e-3, lower: 0}
  initial_water: {value: 3, lower: 0}
  dry_mass: {value: 1, lower: 0}'
printf 't,m\n0,4.0\n1,3.9\n2,3.8\n3,3.7\n' >"$C/wc_ok.csv"
wc_config() { # FILE CSV EXTRA_LINES (must include plant: or leaf_area:)
    printf 'name: t\n%s\ndatasets:\n  - kind: weight_curve\n    file: %s\n    time: {column: t, unit: h}\n    mass: {column: m, unit: g}\n%s' \
        "$WC_PARAMS" "$2" "$3" >"$C/$1"
}
if [ -d "$GRAPH_DIR" ]; then
    while IFS='|' read -r gfile gwant; do
        case "$gfile" in '#'* | '') continue ;; esac
        wc_config "wcg_${gfile}.yaml" wc_ok.csv "    plant: $GRAPH_DIR/$gfile
"
        fit_case "plant graph: $gfile" "$C/wcg_${gfile}.yaml" "$gwant"
    done <"$GRAPH_DIR/expected.txt"
fi
printf 't,m\n0,4.0\n1,3.9\n1,3.8\n3,3.7\n' >"$C/wc_time.csv"
wc_config wc_time.yaml wc_time.csv '    leaf_area: 100
'
fit_case "weight_curve: time not increasing" "$C/wc_time.yaml" "wc_time.csv:4:" "not after"
printf 't,m\n0,4.0\n' >"$C/wc_one.csv"
wc_config wc_one.yaml wc_one.csv '    leaf_area: 100
'
fit_case "weight_curve: a single weighing" "$C/wc_one.yaml" "wc_one.csv" "at least 2"
wc_config wc_dry.yaml wc_ok.csv '    leaf_area: 100
    dry_mass: 3.8
'
fit_case "weight_curve: mass below the dry mass" "$C/wc_dry.yaml" "wc_ok.csv:5:" "below the measured dry mass"
printf 't,m\n0,4.0\n1,3.9\n2,5.8\n3,5.7\n' >"$C/wc_jump.csv"
wc_config wc_jump.yaml wc_jump.csv '    leaf_area: 100
'
fit_case "weight_curve: irrigation jump" "$C/wc_jump.yaml" "wc_jump.csv:4:" "jumps: split"
wc_config wc_unit.yaml wc_ok.csv '    leaf_area: 100
' && sed -i 's/unit: h}/unit: hourz}/' "$C/wc_unit.yaml"
fit_case "weight_curve: unknown time unit" "$C/wc_unit.yaml" "wc_unit.yaml:" "hourz"
wc_config wc_munit.yaml wc_ok.csv '    leaf_area: 100
' && sed -i 's/unit: g}/unit: s}/' "$C/wc_munit.yaml"
fit_case "weight_curve: mass in a time unit" "$C/wc_munit.yaml" "wc_munit.yaml:" "cannot be converted to 'g'"
wc_config wc_both.yaml wc_ok.csv '    leaf_area: 100
    plant: x.csv
'
fit_case "weight_curve: plant and leaf_area" "$C/wc_both.yaml" "wc_both.yaml:" "either 'plant'"
wc_config wc_col.yaml wc_ok.csv '    leaf_area: 100
' && sed -i 's/column: m,/column: mass,/' "$C/wc_col.yaml"
fit_case "weight_curve: unknown mass column" "$C/wc_col.yaml" "wc_col.yaml:" "'mass'"
printf 't,m\n0,4.0\n1,n/a\n2,3.8\n' >"$C/wc_text.csv"
wc_config wc_text.yaml wc_text.csv '    leaf_area: 100
'
fit_case "weight_curve: non-numeric mass" "$C/wc_text.yaml" "wc_text.csv:3:" "n/a"
wc_config wc_sel.yaml wc_ok.csv '    leaf_area: 100
    select: {plant: 3}
'
fit_case "weight_curve: select names no column" "$C/wc_sel.yaml" "wc_sel.yaml:" "'plant'"
wc_config wc_nofile.yaml wc_none.csv '    leaf_area: 100
'
fit_case "weight_curve: missing data file" "$C/wc_nofile.yaml" "wc_nofile.yaml:8" "key 'file'" "wc_none.csv" "No such file"
wc_config wc_noplant.yaml wc_ok.csv '    plant: no_graph.csv
'
fit_case "weight_curve: missing plant graph" "$C/wc_noplant.yaml" "wc_noplant.yaml:11" "key 'plant'" "no_graph.csv" "No such file"
wc_config wc_selnone.yaml wc_ok.csv '    leaf_area: 100
    select: {t: 99}
'
fit_case "weight_curve: select keeps no row" "$C/wc_selnone.yaml" "wc_selnone.yaml:12" "key 'select'" "wc_ok.csv"
# Balance-logger files: date and time columns through a strptime format and a time zone
# (measurements/logger_time.h); the time key is on line 9.
wcl_config() { # FILE CSV TIME_SPEC
    printf 'name: t\n%s\ndatasets:\n  - kind: weight_curve\n    file: %s\n    time: %s\n    mass: Weight\n    leaf_area: 100\n' \
        "$WC_PARAMS" "$2" "$3" >"$C/$1"
}
WCL_DMY='{columns: [Date, Time], format: "%d/%m/%Y %H:%M:%S"'
printf 'Date,Time,Weight\n30/01/2024,10:00:00,4.0\n31/02/2024,10:10:00,3.9\n' >"$C/wcl_date.csv"
wcl_config wcl_date.yaml wcl_date.csv "$WCL_DMY}"
fit_case "weight_curve: date not matching the format" "$C/wcl_date.yaml" "wcl_date.csv:3:" \
    "columns 'Date' and 'Time'" "'31/02/2024 10:10:00'" "format '%d/%m/%Y %H:%M:%S'"
printf 'Date,Time,Weight\n24.10.2024,10:00:00,4.0\n' >"$C/wcl_sep.csv"
wcl_config wcl_sep.yaml wcl_sep.csv "$WCL_DMY}"
fit_case "weight_curve: date with the wrong separators" "$C/wcl_sep.yaml" "wcl_sep.csv:2:" "'24.10.2024 10:00:00'" "does not match the format"
printf 'Date,Time,Weight\n27/10/2024,02:30:00,4.0\n27/10/2024,02:50:00,3.9\n27/10/2024,02:10:00,3.8\n' >"$C/wcl_dst.csv"
wcl_config wcl_tz.yaml wcl_dst.csv "$WCL_DMY, timezone: Europe/Berln}"
fit_case "weight_curve: unknown time zone" "$C/wcl_tz.yaml" "wcl_tz.yaml:9" "key 'timezone'" "'Europe/Berln'"
wcl_config wcl_tzdots.yaml wcl_dst.csv "$WCL_DMY, timezone: ../zoneinfo/UTC}"
fit_case "weight_curve: time zone outside the database" "$C/wcl_tzdots.yaml" "wcl_tzdots.yaml:9" "key 'timezone'"
wcl_config wcl_dst.yaml wcl_dst.csv "$WCL_DMY}"
fit_case "weight_curve: clock steps back without timezone" "$C/wcl_dst.yaml" "wcl_dst.csv:4:" "line 3" "daylight saving" "timezone:"
wcl_config wcl_col.yaml wcl_dst.csv '{columns: [Date, Tim], timezone: Europe/Berlin}'
fit_case "weight_curve: columns names no column" "$C/wcl_col.yaml" "wcl_col.yaml:9" "'Tim'" "'Time'"
wcl_config wcl_unit.yaml wcl_dst.csv "$WCL_DMY, unit: h}"
fit_case "weight_curve: unit with timestamps" "$C/wcl_unit.yaml" "wcl_unit.yaml:9" "'unit' is for numeric times"
# Day and night, covariates and the pot (fit/costs/weight_drivers.h): the
# extra keys start on line 12, after leaf_area on line 11.
wc_config wc_day.yaml wc_ok.csv '    leaf_area: 100
    day: {start: "23:00", end: "07:00", clock: "09:00", night_factor: 0.1}
'
fit_case "weight_curve: day starting after it ends" "$C/wc_day.yaml" "wc_day.yaml:12" "start (23:00) must be before end (07:00)"
wc_config wc_dayclock.yaml wc_ok.csv '    leaf_area: 100
    day: {start: "07:00", end: "23:00", night_factor: 0.1}
'
fit_case "weight_curve: day on a numeric time without clock" "$C/wc_dayclock.yaml" "wc_dayclock.yaml:12" "clock: \"HH:MM\"" "first weighing"
wc_config wc_dayfmt.yaml wc_ok.csv '    leaf_area: 100
    day: {start: "7h", end: "23:00", clock: "09:00", night_factor: 0.1}
'
fit_case "weight_curve: day start not a clock time" "$C/wc_dayfmt.yaml" "wc_dayfmt.yaml:12" "'7h' is not a clock time"
wc_config wc_night.yaml wc_ok.csv '    leaf_area: 100
    day: {start: "07:00", end: "23:00", clock: "09:00", night_factor: -0.5}
'
fit_case "weight_curve: negative night_factor" "$C/wc_night.yaml" "wc_night.yaml:12" "night_factor must be >= 0"
printf 't,m,PAR\n0,4.0,600\n1,3.9,\n2,3.8,0\n' >"$C/wc_cov.csv"
wc_config wc_cov.yaml wc_cov.csv '    leaf_area: 100
    covariates: {columns: [PAR], law: linear}
'
fit_case "weight_curve: covariate with a gap" "$C/wc_cov.yaml" "wc_cov.csv:3:" "column 'PAR'" "needs a number at every kept weighing"
wc_config wc_covcol.yaml wc_cov.csv '    leaf_area: 100
    covariates: {columns: [PAT]}
'
fit_case "weight_curve: covariate column missing" "$C/wc_covcol.yaml" "wc_covcol.yaml:12" "'PAT'" "'PAR'"
wc_config wc_covlaw.yaml wc_cov.csv '    leaf_area: 100
    covariates: {columns: [PAR], law: exponential}
'
fit_case "weight_curve: unknown covariate law" "$C/wc_covlaw.yaml" "wc_covlaw.yaml:12" "law 'exponential'"
wc_config wc_pot.yaml wc_ok.csv '    leaf_area: 100
    pot: {capacity: 0, conductance: 0.01}
'
fit_case "weight_curve: pot capacity 0" "$C/wc_pot.yaml" "wc_pot.yaml:12" "capacity must be > 0 g"
wc_config wc_potk.yaml wc_ok.csv '    leaf_area: 100
    pot: {capacity: 100, conductance: -1}
'
fit_case "weight_curve: negative pot conductance" "$C/wc_potk.yaml" "wc_potk.yaml:12" "conductance must be >= 0"
# ---- end weight_curve ------------------------------------------------------

# ---- soil_probe and infiltration -------------------------------------------
# Soil-moisture probes and infiltration fronts against the Rhizomorph soil
# (fit/costs/soil_probe.h, fit/costs/infiltration.h, fit/costs/soil_setup.h).
printf 'id,x,y,depth\nP1,0.02,0.02,0.1\nP2,0.02,0.02,0.3\n' >"$C/probes_ok.csv"
printf 'time_h,probe,theta\n1,P1,0.03\n1,P2,0.03\n2,P1,0.02\n' >"$C/sp_ok.csv"
# sp_config FILE READINGS PROBES SOIL_EXTRA [DATASET_EXTRA]
sp_config() {
    printf 'name: t\nparameters:\n  p: {value: 0.05, lower: 1e-6}\n  c: {value: 50, lower: 1e-3}\ndatasets:\n  - kind: soil_probe\n    file: %s\n    time: {column: time_h, unit: h}\n    probe: probe\n    value: theta\n    sigma: 0.002\n    probes: {file: %s}\n%s    soil:\n      grid: {nx: 1, ny: 1, nz: 20, dx: 0.05}\n      dt: 0.05\n%s' \
        "$2" "$3" "${5:-}" "$4" >"$C/$1"
}
LAYER_OK='      layers: [{soil: silt, fill: 0.001}]
'
sp_config sp_good.yaml sp_ok.csv probes_ok.csv "$LAYER_OK"
run_phc fit "$C/sp_good.yaml" -o "$T/sp_good_out" --quiet
if [ "$RC" -eq 0 ]; then pass "soil_probe: positive control fits"; else failc "soil_probe: positive control fits" "exit $RC: $ERR"; fi
rm -rf "$T/sp_good_out"
printf 'time_h,probe,theta\n1,P1,0.03\n1,P9,0.03\n' >"$C/sp_unknown.csv"
sp_config sp_unknown.yaml sp_unknown.csv probes_ok.csv "$LAYER_OK"
fit_case "soil_probe: unknown probe id" "$C/sp_unknown.yaml" "sp_unknown.csv:3:" "probe 'P9'"
printf 'time_h,probe,theta\n2,P1,0.03\n3,P2,0.03\n1,P1,0.02\n' >"$C/sp_order.csv"
sp_config sp_order.yaml sp_order.csv probes_ok.csv "$LAYER_OK"
fit_case "soil_probe: times out of order" "$C/sp_order.yaml" "sp_order.csv:4:" "time order"
printf 'time_h,probe,theta\n1,P1,wet\n' >"$C/sp_text.csv"
sp_config sp_text.yaml sp_text.csv probes_ok.csv "$LAYER_OK"
fit_case "soil_probe: non-numeric reading" "$C/sp_text.yaml" "sp_text.csv:2:" "'wet'"
printf 'id,x,y,depth\nP1,0.02,0.02,0.1\nP2,3.5,0.02,0.3\n' >"$C/probes_out.csv"
sp_config sp_out.yaml sp_ok.csv probes_out.csv "$LAYER_OK"
fit_case "soil_probe: probe outside the grid" "$C/sp_out.yaml" "probes_out.csv:3:" "probe 'P2'" "outside the soil grid"
printf 'id,x,y,depth\nP1,0.5,0.5,0.1\nP2,0.5,0.5,-0.3\n' >"$C/probes_neg.csv"
sp_config sp_neg.yaml sp_ok.csv probes_neg.csv "$LAYER_OK"
fit_case "soil_probe: negative probe depth" "$C/sp_neg.yaml" "probes_neg.csv:3:" "depth must be >= 0"
printf 'id,x,y,depth\nP1,0.5,0.5,0.1\nP1,0.5,0.5,0.3\n' >"$C/probes_dup.csv"
sp_config sp_dup.yaml sp_ok.csv probes_dup.csv "$LAYER_OK"
fit_case "soil_probe: duplicate probe id" "$C/sp_dup.yaml" "probes_dup.csv:3:" "listed twice"
printf 'id,lat,lon,depth\nP1,43.6481 N,79.3832 W,0.1\nP2,43.6481 E,79.3832 W,0.3\n' >"$C/probes_lat.csv"
sp_config sp_lat.yaml sp_ok.csv probes_lat.csv "$LAYER_OK
      geo_origin: {lat: \"43.6481 N\", lon: \"79.3832 W\"}
"
sed -i 's|probes: {file: probes_lat.csv}|probes: {file: probes_lat.csv, lat: lat, lon: lon}|' "$C/sp_lat.yaml"
fit_case "soil_probe: unparseable latitude" "$C/sp_lat.yaml" "probes_lat.csv:3:" "as a latitude"
printf 'id,lat,lon,depth\nP1,43.6481 N,79.3832 W,0.1\nP2,43.6491 N,79.3832 W,0.3\n' >"$C/probes_far.csv"
sp_config sp_far.yaml sp_ok.csv probes_far.csv "$LAYER_OK
      geo_origin: {lat: \"43.6481 N\", lon: \"79.3832 W\"}
"
sed -i 's|probes: {file: probes_far.csv}|probes: {file: probes_far.csv, lat: lat, lon: lon}|' "$C/sp_far.yaml"
fit_case "soil_probe: GPS probe 111 m off the grid" "$C/sp_far.yaml" "probes_far.csv:3:" "probe 'P2'" "outside the soil grid"
sp_config sp_nogeo.yaml sp_ok.csv probes_lat.csv "$LAYER_OK"
sed -i 's|probes: {file: probes_lat.csv}|probes: {file: probes_lat.csv, lat: lat, lon: lon}|' "$C/sp_nogeo.yaml"
fit_case "soil_probe: latitudes without geo_origin" "$C/sp_nogeo.yaml" "probes_lat.csv" "no geo_origin"
sp_config sp_c0.yaml sp_ok.csv probes_ok.csv '      layers: [{c: 0, p: 0.03, fill: 0.001}]
'
fit_case "soil: zero capacity" "$C/sp_c0.yaml" "sp_c0.yaml:" "soil layer 1" "c > 0"
sp_config sp_pneg.yaml sp_ok.csv probes_ok.csv '      layers: [{c: 10, p: 0.03, thickness: 0.5}, {c: 10, p: -0.1}]
'
fit_case "soil: negative permeability" "$C/sp_pneg.yaml" "sp_pneg.yaml:" "soil layer 2" "p >= 0"
sp_config sp_nan.yaml sp_ok.csv probes_ok.csv '      layers: [{c: .nan, p: 0.03}]
'
fit_case "soil: NaN capacity" "$C/sp_nan.yaml" "sp_nan.yaml:" "'c'"
sp_config sp_peat.yaml sp_ok.csv probes_ok.csv '      layers: [{soil: peat}]
'
fit_case "soil: unknown soil type" "$C/sp_peat.yaml" "sp_peat.yaml:" "unknown soil 'peat'" "silt_loam"
sp_config sp_dt.yaml sp_ok.csv probes_ok.csv '      layers: [{soil: sandy_loam, fill: 0.001}]
      substep: false
' && sed -i 's/dt: 0.05/dt: 0.5/' "$C/sp_dt.yaml"
fit_case "soil: time step over the stability limit, no sub-stepping" "$C/sp_dt.yaml" "sp_dt.yaml:" "stability limit" "substep"
sp_config sp_abs.yaml sp_ok.csv probes_ok.csv "$LAYER_OK      boundaries: {sides: absorb}
"
fit_case "soil: absorbing layers wider than the grid" "$C/sp_abs.yaml" "sp_abs.yaml:" "absorbs over 5 layers"
sp_config sp_per.yaml sp_ok.csv probes_ok.csv "$LAYER_OK      boundaries: {x_min: periodic}
"
fit_case "soil: one periodic face" "$C/sp_per.yaml" "sp_per.yaml:" "come in pairs"
sp_config sp_src.yaml sp_ok.csv probes_ok.csv "$LAYER_OK      sources: [{x: 0.02, y: 0.02, depth: 2.5, water_rate: 1e-4}]
"
fit_case "soil: source below the grid" "$C/sp_src.yaml" "sp_src.yaml:" "source 1" "outside the soil grid"
sp_config sp_grid.yaml sp_ok.csv probes_ok.csv "$LAYER_OK" && sed -i 's/nz: 20, //' "$C/sp_grid.yaml"
fit_case "soil: grid without nz" "$C/sp_grid.yaml" "sp_grid.yaml:" "'nz'"
sp_config sp_q.yaml sp_ok.csv probes_ok.csv "$LAYER_OK" '    quantity: suction
'
fit_case "soil_probe: unknown quantity" "$C/sp_q.yaml" "sp_q.yaml:" "not one of water, fill"
sp_config sp_ts.yaml sp_ok.csv probes_ok.csv "$LAYER_OK" && sed -i 's/unit: h}/unit: "hours since 2026-05-01"}/' "$C/sp_ts.yaml"
fit_case "soil_probe: timestamps without start" "$C/sp_ts.yaml" "sp_ts.yaml:" "give \`start:\`"
sp_config sp_nofile.yaml sp_none.csv probes_ok.csv "$LAYER_OK"
fit_case "soil_probe: missing readings file" "$C/sp_nofile.yaml" "sp_nofile.yaml:7" "key 'file'" "sp_none.csv" "No such file"
sp_config sp_noprobes.yaml sp_ok.csv probes_none.csv "$LAYER_OK"
fit_case "soil_probe: missing probe table" "$C/sp_noprobes.yaml" "sp_noprobes.yaml:12" "probes: key 'file'" "probes_none.csv"
# infiltration
inf_config() {
    printf 'name: t\nparameters:\n  p: {value: 0.05, lower: 1e-6}\n  c: {value: 50, lower: 1e-3}\ndatasets:\n  - kind: infiltration\n    file: %s\n    time: {column: t, unit: h}\n    depth: {column: d, unit: m}\n    sigma: 0.01\n    soil:\n      grid: {nx: 1, ny: 1, nz: 40, dx: 0.05}\n%s' \
        "$2" "$3" >"$C/$1"
}
RAIN_OK='      layers: [{soil: silt, fill: 0.0001}]
      rain: [{start: 0, end: 2, rate: 0.01}]
'
printf 't,d\n1,0.05\n2,0.1\n4,0.2\n' >"$C/inf_ok.csv"
inf_config inf_norain.yaml inf_ok.csv '      layers: [{soil: silt, fill: 0.0001}]
'
fit_case "infiltration: no rain" "$C/inf_norain.yaml" "inf_norain.yaml:" "nothing infiltrates"
printf 't,d\n1,0.05\n2,-0.1\n' >"$C/inf_neg.csv"
inf_config inf_neg.yaml inf_neg.csv "$RAIN_OK"
fit_case "infiltration: negative depth" "$C/inf_neg.yaml" "inf_neg.csv:3:" "depth must be >= 0"
printf 't,d\n2,0.05\n1,0.1\n' >"$C/inf_order.csv"
inf_config inf_order.yaml inf_order.csv "$RAIN_OK"
fit_case "infiltration: times out of order" "$C/inf_order.yaml" "inf_order.csv:3:" "increasing"
inf_config inf_frac.yaml inf_ok.csv "$RAIN_OK" && printf '    fraction: 1.5\n' >>"$C/inf_frac.yaml"
fit_case "infiltration: fraction above 1" "$C/inf_frac.yaml" "inf_frac.yaml:" "fraction"
inf_config inf_rain.yaml inf_ok.csv '      layers: [{soil: silt, fill: 0.0001}]
      rain: [{start: 2, end: 1, rate: 0.01}]
'
fit_case "infiltration: rain ending before it starts" "$C/inf_rain.yaml" "inf_rain.yaml:" "rain 1"
inf_config inf_nofile.yaml inf_none.csv "$RAIN_OK"
fit_case "infiltration: missing data file" "$C/inf_nofile.yaml" "inf_nofile.yaml:7" "key 'file'" "inf_none.csv"
# ---- end soil ----------------------------------------------------------------

# ---- leaf photos (leaf_photos data sets, measurements/photo_*_bridge.cc) ------
# leaf_png FILE W H [LEAVES] [COLOUR]: green elliptical leaves with a darker
# midrib on white paper, written with the Python standard library only.
leaf_png() {
    /usr/bin/python3 - "$@" <<'PY'
import sys, zlib, struct
path, w, h = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
leaves = int(sys.argv[4]) if len(sys.argv) > 4 else 1
col = sys.argv[5] if len(sys.argv) > 5 else "green"
base = {"green": (60, 140, 50), "yellow": (200, 190, 60), "white": (255, 255, 255)}[col]
rows = []
for y in range(h):
    row = bytearray([0])
    for x in range(w):
        c = (255, 255, 255)
        for k in range(leaves):
            cx = (k + 0.5) * w / leaves
            u, v = (x - cx) / (0.4 * w / leaves), (y - h / 2) / (0.4 * h)
            if u * u + v * v < 1:
                c = base
                if abs(x - cx) < 1.5 and col != "white":
                    c = tuple(int(0.7 * q) for q in base)
        row += bytes(c)
    rows.append(bytes(row))
raw = zlib.compress(b"".join(rows))
def chunk(t, d):
    return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
with open(path, "wb") as f:
    f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) +
            chunk(b"IDAT", raw) + chunk(b"IEND", b""))
PY
}
leaf_png "$C/leaf_a.png" 120 80
leaf_png "$C/leaf_b.png" 120 80
leaf_png "$C/leaf_old.png" 120 80 1 yellow
leaf_png "$C/blank.png" 120 80 1 white
leaf_png "$C/veins_small.png" 60 40
head -c 300 "$C/leaf_a.png" >"$C/leaf_cut.png"
echo "not an image" >"$C/leaf_text.png"
# lp_config NAME CSV [EXTRA LINES]: a pixels-mode data set over leaf photos
lp_config() {
    printf 'name: t\nparameters:\n  stomata_scale: {value: 0.1, lower: 0}\ndatasets:\n  - kind: leaf_photos\n    file: %s\n    image: {column: image}\n    stage: {column: day}\n    reference: {image: leaf_old.png}\n    model_size: 32\n%s' \
        "$2" "${3:-}" >"$C/$1"
}
printf 'day,image\n0,leaf_a.png\n2,leaf_b.png\n' >"$C/lp_ok.csv"
lp_config lp_ok.yaml lp_ok.csv
WHY=""
run_phc simulate "$C/lp_ok.yaml" -o "$T/out_lp_ok"
if [ "$RC" -eq 0 ]; then pass "leaf_photos: the valid base simulates"; else failc "leaf_photos: the valid base simulates" "exit $RC: $ERR"; fi
printf 'day,image\n0,leaf_a.png\n2,leaf_cut.png\n' >"$C/lp_cut.csv"
lp_config lp_cut.yaml lp_cut.csv
fit_case "leaf_photos: truncated PNG" "$C/lp_cut.yaml" "lp_cut.csv:3" "leaf_cut.png" "truncated"
printf 'day,image\n0,leaf_a.png\n2,leaf_text.png\n' >"$C/lp_text.csv"
lp_config lp_text.yaml lp_text.csv
fit_case "leaf_photos: a text file as a photo" "$C/lp_text.yaml" "lp_text.csv:3" "leaf_text.png"
printf 'day,image\n0,leaf_a.png\n2,nowhere.png\n' >"$C/lp_missing.csv"
lp_config lp_missing.yaml lp_missing.csv
fit_case "leaf_photos: missing photo" "$C/lp_missing.yaml" "lp_missing.csv:3" "nowhere.png"
printf 'day,image\n0,leaf_a.png\n2,blank.png\n' >"$C/lp_blank.csv"
lp_config lp_blank.yaml lp_blank.csv
fit_case "leaf_photos: no leaf in the photo" "$C/lp_blank.yaml" "lp_blank.csv:3" "blank.png" "no leaf found"
printf 'day,image,leaf\n0,leaf_a.png,1\n2,leaf_b.png,3\n' >"$C/lp_num.csv"
lp_config lp_num.yaml lp_num.csv '    leaf: leaf
'
fit_case "leaf_photos: leaf number beyond the leaves found" "$C/lp_num.yaml" "lp_num.csv:3" "leaf 3 requested, 1 leaf found"
lp_config lp_veins.yaml lp_ok.csv '    veins: veins_small.png
'
fit_case "leaf_photos: vein map of another size" "$C/lp_veins.yaml" "veins_small.png" "60" "120"
printf 'day,image\n0,leaf_a.png\n3,leaf_b.png\n2,leaf_b.png\n' >"$C/lp_order.csv"
lp_config lp_order.yaml lp_order.csv
fit_case "leaf_photos: stages out of order" "$C/lp_order.yaml" "lp_order.csv:4" "out of order"
printf 'day,image\n0,leaf_a.png\n,leaf_b.png\n' >"$C/lp_nostage.csv"
lp_config lp_nostage.yaml lp_nostage.csv
fit_case "leaf_photos: missing stage" "$C/lp_nostage.yaml" "lp_nostage.csv:3" "'day'"
lp_config lp_before.yaml lp_ok.csv '    initial: "3"
    id: day
'
fit_case "leaf_photos: initial id not a row" "$C/lp_before.yaml" "lp_before.yaml:" "no row has id '3'"
lp_config lp_resid.yaml lp_ok.csv '    residual: pixel
'
fit_case "leaf_photos: unknown residual" "$C/lp_resid.yaml" "lp_resid.yaml:" "not one of pixels, histogram"
printf 'name: t\nparameters:\n  other: {value: 1}\ndatasets:\n  - kind: leaf_photos\n    file: lp_ok.csv\n    image: {column: image}\n    stage: {column: day}\n    reference: {image: leaf_old.png}\n' >"$C/lp_noslot.yaml"
fit_case "leaf_photos: no parameter to fit" "$C/lp_noslot.yaml" "lp_noslot.yaml:" "no parameter to fit"
lp_config lp_ref.yaml lp_ok.csv && sed -i 's/leaf_old.png/blank.png/' "$C/lp_ref.yaml"
fit_case "leaf_photos: reference photo without a leaf" "$C/lp_ref.yaml" "lp_ref.yaml:" "blank.png" "no leaf found"
# A photo named by the config is the config's fault (line 7, image:), not the
# table's first row; a photo named in the table gives the row and column.
printf 'day\n0\n2\n' >"$C/lp_days.csv"
lp_config lp_cfgimg.yaml lp_days.csv && sed -i 's/image: {column: image}/image: nowhere.png/' "$C/lp_cfgimg.yaml"
fit_case "leaf_photos: config image missing" "$C/lp_cfgimg.yaml" "lp_cfgimg.yaml:7" "key 'image'" "nowhere.png" "No such file"
lp_config lp_cfgtext.yaml lp_days.csv && sed -i 's/image: {column: image}/image: leaf_text.png/' "$C/lp_cfgtext.yaml"
fit_case "leaf_photos: config image not an image" "$C/lp_cfgtext.yaml" "lp_cfgtext.yaml:7" "key 'image'" "leaf_text.png"
fit_case "leaf_photos: table image missing (row and column)" "$C/lp_missing.yaml" "lp_missing.csv:3" "column 'image'" "nowhere.png"
lp_config lp_refmiss.yaml lp_ok.csv && sed -i 's/leaf_old.png/no_ref.png/' "$C/lp_refmiss.yaml"
fit_case "leaf_photos: reference image missing" "$C/lp_refmiss.yaml" "lp_refmiss.yaml:9" "reference: key 'image'" "no_ref.png" "No such file"
lp_config lp_veinmiss.yaml lp_ok.csv '    veins: no_veins.png
'
fit_case "leaf_photos: vein map missing" "$C/lp_veinmiss.yaml" "lp_veinmiss.yaml:11" "key 'veins'" "no_veins.png" "No such file"
lp_config lp_nofile.yaml lp_none.csv
fit_case "leaf_photos: missing table" "$C/lp_nofile.yaml" "lp_nofile.yaml:6" "key 'file'" "lp_none.csv" "No such file"
# ---- end leaf photos -----------------------------------------------------------

# ---- root_shoot (harvested plants against the shoot-root growth model) ------
# fit/costs/root_shoot.h: a small harvest table (or a BAAD study folder), a
# tiny soil pot and 30 simulated days, so that every case is fast.
RS_SHARED=${2:-}
case "$RS_SHARED" in /* | "") ;; *) RS_SHARED="$OLDPWD/$RS_SHARED" ;; esac
printf 'd_mm,root_g,shoot_g,age_m,light\n1.0,0.05,0.10,1,L\n1.5,0.08,0.15,2,L\n2.0,0.12,0.22,3,H\n' >"$C/rs_ok.csv"
RS_TABLE='    diameter: {column: d_mm, unit: mm}
    root_mass: {column: root_g, unit: g}
    shoot_mass: {column: shoot_g, unit: g}
    age: {column: age_m, unit: month}
'
RS_SOIL='    soil:
      grid: {nx: 4, ny: 4, nz: 4, dx: 0.05}
      dt: 1
      layers:
        - {c: 10, p: 0.0015, water: 3}
'
# rs_config FILE SOURCE [EXTRA]: SOURCE is the data lines (file/baad and
# columns), EXTRA further data-set lines (default: sigma 0.3, 30 days).
rs_config() {
    printf 'name: t\nparameters:\n  phi_rg: {value: 0.6, lower: 0.05, upper: 0.95}\ndatasets:\n  - kind: root_shoot\n%s%s%s' \
        "$2" "${3-    sigma: 0.3
    days: 30
}" "$RS_SOIL" >"$C/$1"
}
# rs_table_config FILE CSV [EXTRA]: a table data set with the usual columns.
rs_table_config() {
    rs_config "$1" "    file: $2
$RS_TABLE" "${3:-}    sigma: 0.3
    days: 30
"
}
rs_table_config rs_good.yaml rs_ok.csv
WHY=""
run_phc fit "$C/rs_good.yaml" -o "$T/rs_good_out" --quiet
[ "$RC" -eq 0 ] || add_why "exit code $RC, expected 0 (stderr: $(head -c 300 "$T/stderr" | tr '\n' '|'))"
[ -f "$T/rs_good_out/result.json" ] || add_why "no result.json"
report_case "root_shoot: positive control fits"
rm -rf "$T/rs_good_out"
# 1. growth presets
rs_table_config rs_preset.yaml rs_ok.csv '    preset: birch
'
fit_case "root_shoot: unknown preset" "$C/rs_preset.yaml" "rs_preset.yaml:" "'preset'" "birch" "oak" "cherry" "apple" "poplar" "maple"
# 2-4. impossible plants in the table
printf 'd_mm,root_g,shoot_g,age_m\n1.0,0.05,0.10,1\n0,0.08,0.15,2\n' >"$C/rs_d0.csv"
rs_table_config rs_d0.yaml rs_d0.csv
fit_case "root_shoot: zero basal diameter" "$C/rs_d0.yaml" "rs_d0.csv:3:" "basal diameter must be a positive number"
printf 'd_mm,root_g,shoot_g,age_m\n1.0,0.05,0.10,1\n1.5,0.08,0.15,2\n2.0,-0.12,0.22,3\n' >"$C/rs_rneg.csv"
rs_table_config rs_rneg.yaml rs_rneg.csv
fit_case "root_shoot: negative root mass" "$C/rs_rneg.yaml" "rs_rneg.csv:4:" "root mass must be a positive number" "-0.12"
printf 'd_mm,root_g,shoot_g,age_m\n1.0,0.05,0,1\n1.5,0.08,0.15,2\n' >"$C/rs_s0.csv"
rs_table_config rs_s0.yaml rs_s0.csv
fit_case "root_shoot: zero shoot mass" "$C/rs_s0.yaml" "rs_s0.csv:2:" "shoot mass must be a positive number"
# 5. cells that are not numbers
printf 'd_mm,root_g,shoot_g,age_m\n1.0,0.05,0.10,1\n,0.08,0.15,2\n' >"$C/rs_empty.csv"
rs_table_config rs_empty.yaml rs_empty.csv
fit_case "root_shoot: empty diameter cell" "$C/rs_empty.yaml" "rs_empty.csv:3" "'d_mm'"
printf 'd_mm,root_g,shoot_g,age_m\n1.0,0.05,0.10,1\nn/a,0.08,0.15,2\n' >"$C/rs_text.csv"
rs_table_config rs_text.yaml rs_text.csv
fit_case "root_shoot: text in the diameter column" "$C/rs_text.yaml" "rs_text.csv:3" "'d_mm'" "'n/a'"
# 6. a column that is not in the table
rs_config rs_col.yaml "    file: rs_ok.csv
$(printf '%s' "$RS_TABLE" | sed 's/column: d_mm/column: d_m/')
"
fit_case "root_shoot: unknown diameter column" "$C/rs_col.yaml" "rs_col.yaml:" "'d_m'" "d_mm"
# 7. no shoot mass at all; leaf mass without stem mass
rs_config rs_noshoot.yaml "    file: rs_ok.csv
$(printf '%s' "$RS_TABLE" | grep -v shoot_mass)
"
fit_case "root_shoot: no shoot mass" "$C/rs_noshoot.yaml" "rs_noshoot.yaml:" "'shoot_mass'" "'leaf_mass'" "'stem_mass'"
rs_config rs_leafonly.yaml "    file: rs_ok.csv
$(printf '%s' "$RS_TABLE" | sed 's/shoot_mass: {column: shoot_g/leaf_mass: {column: shoot_g/')
"
fit_case "root_shoot: leaf mass without stem mass" "$C/rs_leafonly.yaml" "rs_leafonly.yaml:" "'shoot_mass'" "'stem_mass'"
# 8. exactly one of file and baad
mkdir -p "$C/rs_study"
rs_config rs_both.yaml "    file: rs_ok.csv
    baad: rs_study
    species: Quercus rubra
$RS_TABLE"
fit_case "root_shoot: both file and baad" "$C/rs_both.yaml" "rs_both.yaml:" "exactly one of 'file'" "'baad'"
rs_config rs_neither.yaml "$RS_TABLE"
fit_case "root_shoot: neither file nor baad" "$C/rs_neither.yaml" "rs_neither.yaml:" "exactly one of 'file'" "'baad'"
# 9. the plant outside the pot
rs_table_config rs_plant.yaml rs_ok.csv '    plant: {x: 5, y: 0.1}
'
fit_case "root_shoot: plant seeded outside the soil grid" "$C/rs_plant.yaml" "rs_plant.yaml:" "plant" "outside the soil grid" "x = 5"
# 10. growth parameters
rs_table_config rs_gname.yaml rs_ok.csv '    growth: {phi_rgg: 1}
'
fit_case "root_shoot: unknown growth parameter" "$C/rs_gname.yaml" "rs_gname.yaml:" "unknown growth parameter 'phi_rgg'"
rs_table_config rs_grange.yaml rs_ok.csv '    growth: {phi_rg: 1.5}
'
fit_case "root_shoot: growth parameter out of range" "$C/rs_grange.yaml" "rs_grange.yaml:" "phi_rg" "1.5"
# 11. model options
rs_table_config rs_mode.yaml rs_ok.csv '    mode: smooth
'
fit_case "root_shoot: unknown mode" "$C/rs_mode.yaml" "rs_mode.yaml:" "'mode'" "'smooth'" "stochastic"
rs_table_config rs_uptake.yaml rs_ok.csv '    uptake: chemical
'
fit_case "root_shoot: unknown uptake" "$C/rs_uptake.yaml" "rs_uptake.yaml:" "'uptake'" "'chemical'" "'physical' or 'none'"
rs_config rs_step.yaml "    file: rs_ok.csv
$RS_TABLE" '    sigma: 0.3
    days: 30
    step: 40
'
fit_case "root_shoot: step longer than days" "$C/rs_step.yaml" "rs_step.yaml:" "step <= days" "step 40 d" "days 30 d"
rs_config rs_sigma.yaml "    file: rs_ok.csv
$RS_TABLE" '    sigma: 0
    days: 30
'
fit_case "root_shoot: zero sigma" "$C/rs_sigma.yaml" "rs_sigma.yaml:" "'sigma'" "> 0"
# 12. BAAD study folders
rs_config rs_nobaad.yaml '    baad: no_such_study
    species: Quercus rubra
'
fit_case "root_shoot: BAAD folder does not exist" "$C/rs_nobaad.yaml" "rs_nobaad.yaml:" "'baad'" "no_such_study"
if [ -n "$RS_SHARED" ] && [ -f "$RS_SHARED/baad/Baltzer2007/data.csv" ]; then
    RS_STUDY=$(cd "$RS_SHARED/baad/Baltzer2007" && pwd)
    rs_config rs_species.yaml "    baad: $RS_STUDY
    species: Quercus rubrum
"
    fit_case "root_shoot: species not in the BAAD study" "$C/rs_species.yaml" "rs_species.yaml:" "'Quercus rubrum'" "Baltzer2007" "Quercus rubra" "Acer rubrum"
    rs_config rs_bsel.yaml "    baad: $RS_STUDY
    species: Quercus rubra
    select: {column: Shade, equals: L}
"
    fit_case "root_shoot: BAAD select column does not exist" "$C/rs_bsel.yaml" "rs_bsel.yaml:" "select" "'Shade'" "data.csv"
else
    echo "# skip - root_shoot BAAD study cases: no shared data folder (second argument)"
fi
# A tiny BAAD tree (config/ beside the study folders, as in the database):
# a study folder without dataMatchColumns.csv, and a unit_in that BAAD's
# variableConversion.csv does not convert.
mkdir -p "$C/rs_baad/config" "$C/rs_baad/NoMatch2020" "$C/rs_baad/BadConv2020"
printf 'variable,units,group,type\nspecies,NA,species,character\nd.ba,m,tree,numeric\nm.rt,kg,tree,numeric\nm.so,kg,tree,numeric\n' \
    >"$C/rs_baad/config/variableDefinitions.csv"
printf 'unit_in,unit_out,conversion\ng,kg,x/1000\nmm,m,x/1000\nm2/kg,kg/m2,1/x\n' >"$C/rs_baad/config/variableConversion.csv"
printf 'sp,d,root,shoot\nQuercus rubra,2.0,0.05,0.10\nQuercus rubra,2.5,0.08,0.15\n' >"$C/rs_baad/NoMatch2020/data.csv"
cp "$C/rs_baad/NoMatch2020/data.csv" "$C/rs_baad/BadConv2020/data.csv"
printf 'var_in,unit_in,var_out\nsp,NA,species\nd,furlong,d.ba\nroot,g,m.rt\nshoot,g,m.so\n' \
    >"$C/rs_baad/BadConv2020/dataMatchColumns.csv"
rs_config rs_nomatch.yaml '    baad: rs_baad/NoMatch2020
    species: Quercus rubra
'
fit_case "root_shoot: BAAD study folder without dataMatchColumns.csv" "$C/rs_nomatch.yaml" "rs_nomatch.yaml:" \
    "rs_baad/NoMatch2020" "no dataMatchColumns.csv"
rs_config rs_badconv.yaml '    baad: rs_baad/BadConv2020
    species: Quercus rubra
'
fit_case "root_shoot: BAAD unit conversion BAAD does not define" "$C/rs_badconv.yaml" \
    "BadConv2020/dataMatchColumns.csv:3:" "no conversion from 'furlong' to 'm'" "variableConversion.csv"
rs_table_config rs_tsel.yaml rs_ok.csv '    select: {column: shade, equals: L}
'
fit_case "root_shoot: table select column does not exist" "$C/rs_tsel.yaml" "rs_tsel.yaml:" "'shade'" "light"
# 13. a filter that keeps nothing
rs_table_config rs_none.yaml rs_ok.csv '    select: {column: light, equals: M}
'
fit_case "root_shoot: select matches no rows" "$C/rs_none.yaml" "rs_ok.csv" "select: no row of" "light = 'M'"
rs_table_config rs_nofile.yaml rs_none.csv
fit_case "root_shoot: missing table" "$C/rs_nofile.yaml" "rs_nofile.yaml:6" "key 'file'" "rs_none.csv" "No such file"
# ---- end root_shoot --------------------------------------------------------

# ---- fuzzing finds (tests/fuzz, scripts/fuzz) --------------------------------
# Inputs the libFuzzer harnesses found mishandled, each with the exact message
# (after "phytocal: ") and nothing on stdout.
# fuzz_case NAME CONFIG MESSAGE: fit_case, then stderr is exactly
# "phytocal: MESSAGE" and stdout is empty.
fuzz_case() {
    local name=$1 config=$2 want=$3
    local out="$T/out_${name//[^A-Za-z0-9_]/_}"
    WHY=""
    run_phc fit "$config" -o "$out"
    check_error_output 2
    check_no_output "$out"
    if [ "$ERR" != "phytocal: $want" ]; then
        add_why "stderr is not exactly 'phytocal: $want'"
    fi
    if [ -s "$T/stdout" ]; then
        add_why "stdout is not empty ($(head -c 80 "$T/stdout" | od -c | head -2 | tr '\n' ' '))"
    fi
    report_case "$name"
}
# A quoted CSV header with a line break, named in a "did you mean": the
# message was two lines; control characters in messages are now escaped
# (model/status.c).
printf 'x,"y\nz"\n1,2.1\n2,3.9\n3,6.2\n4,8.0\n' >"$C/hdr_nl.csv"
write_config "$C/hdr_nl.yaml" "$PARAMS_OK" "$(dataset_block hdr_nl.csv "a*x + b" | sed 's/    y: y/    y: yz/')"
fuzz_case "fuzz: column name with a line break" "$C/hdr_nl.yaml" \
    "$C/hdr_nl.yaml:9: y 'yz' is not a column of $C/hdr_nl.csv; did you mean 'y\\nz'?"
# The same in the one message written without phc_error_set (found by
# reading the code after the case above, fit/costs/curve.c): sigma text.
write_config "$C/sigma_nl.yaml" "$PARAMS_OK" "$(dataset_block data.csv "a*x + b" '    sigma: "s\nt"
')"
fuzz_case "fuzz: sigma text with a line break" "$C/sigma_nl.yaml" \
    "$C/sigma_nl.yaml:11: key 'sigma': expected a positive number or a column of $C/data.csv, found 's\\nt'"
# A unit with a line break ("h\n"): UDUNITS-2 printed the line break on
# stdout and accepted "h"; now it is not a unit (measurements/units.c).
wc_config wc_unit_nl.yaml wc_ok.csv '    leaf_area: 100
' && sed -i 's/unit: h}/unit: "h\\n"}/' "$C/wc_unit_nl.yaml"
fuzz_case "fuzz: time unit with a line break" "$C/wc_unit_nl.yaml" \
    "$C/wc_unit_nl.yaml:9: time unit: 'h\\n' is not a unit UDUNITS-2 knows"
# A TreeQSM cylinder shorter than the rounding of its start point: its tail
# fell on its start (a zero-length segment); the plant_graphs case list has
# the file (treeqsm_length_lost_in_rounding.txt, measurements/plant_io.c).

# ---- shape_series (issue 19) -----------------------------------------------
printf 'Time (s),Flower 1 Angle (deg),Flower 2 Angle (deg)\n10,30,120\n20,29,119\n30,28,118\n40,27,117\n' >"$C/ss_ok.csv"
printf 'Time (s),Flower 1 Angle (deg),Flower 2 Angle (deg)\n10,30,120\n20,29,119\n15,28,118\n40,27,117\n' >"$C/ss_back.csv"
printf 'Time (s),Flower 1 Angle (deg),Flower 2 Angle (deg)\n10,30,120\n20,nan,119\n30,28,118\n40,27,117\n' >"$C/ss_nan.csv"
# ss_config FILE CSV SERIES_ITEM [EXTRA_DATASET_LINES]: the series item is on line 12
ss_config() {
    printf 'name: t\nparameters:\n  kappa: {value: 10}\n  chi0: {value: 0.8}\n  e_max: {value: 1e6}\n  delta: {value: 1e-4}\ndatasets:\n  - kind: shape_series\n    file: %s\n    time: {column: "Time (s)", unit: s}\n    series:\n      - %s\n%s' \
        "$2" "$3" "${4:-}" >"$C/$1"
}
SS_F1='{id: flower1, column: "Flower 1 Angle (deg)", unit: deg, length: 0.04, radius: 0.001, tip_mass: 0.001}'
ss_config ss_good.yaml ss_ok.csv "$SS_F1"
WHY=""
run_phc simulate "$C/ss_good.yaml" -o "$T/out_ss_good"
[ "$RC" -eq 0 ] || add_why "exit code $RC, expected 0"
ls "$T/out_ss_good"/*flower1_frames.png >/dev/null 2>&1 || add_why "no side views written"
ls "$T/out_ss_good"/*flower1_frame00.vtk >/dev/null 2>&1 || add_why "no VTK frame written"
report_case "shape_series: control: a valid config simulates"
rm -rf "$T/out_ss_good"
ss_config ss_col.yaml ss_ok.csv '{id: flower1, column: "Flower 9 Angle (deg)", unit: deg, length: 0.04, radius: 0.001, tip_mass: 0.001}'
fit_case "shape_series: unknown column" "$C/ss_col.yaml" "ss_col.yaml:12" "Flower 9 Angle (deg)"
ss_config ss_unit.yaml ss_ok.csv '{id: flower1, column: "Flower 1 Angle (deg)", unit: gradians, length: 0.04, radius: 0.001, tip_mass: 0.001}'
fit_case "shape_series: unknown angle unit" "$C/ss_unit.yaml" "ss_unit.yaml:12" "gradians"
ss_config ss_back.yaml ss_back.csv "$SS_F1"
fit_case "shape_series: time runs backwards" "$C/ss_back.yaml" "ss_back.csv:4" "Time (s)" "not after"
ss_config ss_nan.yaml ss_nan.csv "$SS_F1"
fit_case "shape_series: NaN angle" "$C/ss_nan.yaml" "ss_nan.csv:3" "Flower 1 Angle (deg)"
ss_config ss_radius.yaml ss_ok.csv '{id: flower1, column: "Flower 1 Angle (deg)", unit: deg, length: 0.04, radius: 0, tip_mass: 0.001}'
fit_case "shape_series: zero radius" "$C/ss_radius.yaml" "ss_radius.yaml:12" "'radius'" "positive"
ss_config ss_length.yaml ss_ok.csv '{id: flower1, column: "Flower 1 Angle (deg)", unit: deg, length: -0.04, radius: 0.001, tip_mass: 0.001}'
fit_case "shape_series: negative length" "$C/ss_length.yaml" "ss_length.yaml:12" "'length'" "positive"
ss_config ss_emin.yaml ss_ok.csv "$SS_F1" '    e_min: -5
'
fit_case "shape_series: negative modulus" "$C/ss_emin.yaml" "ss_emin.yaml:13" "'e_min'" "positive"
ss_config ss_key.yaml ss_ok.csv '{id: flower1, column: "Flower 1 Angle (deg)", unit: deg, length: 0.04, radius: 0.001, tip_mass: 0.001, segmnts: 4}'
fit_case "shape_series: unknown stalk key" "$C/ss_key.yaml" "ss_key.yaml:12" "segmnts" "segments"
ss_config ss_series.yaml ss_ok.csv "$SS_F1" '      - {id: flower1, column: "Flower 2 Angle (deg)", unit: deg, length: 0.04, radius: 0.001, tip_mass: 0.001}
'
fit_case "shape_series: duplicate series id" "$C/ss_series.yaml" "ss_series.yaml:13" "flower1"
printf '# unit: m\nid,parent,radius,length,x_head,y_head,z_head,x_tail,y_tail,z_tail,leaf,fixed\n0,-1,0.001,0.01,0,0,0,0.01,0,0,0,1\n1,0,0.001,0.01,0.01,0,0,0.02,0,0,0,0\n2,1,0.001,0.01,0.02,0,0,0.03,0,0,0,0\n' >"$C/ss_plant.csv"
printf 'name: t\nparameters:\n  kappa: {value: 10}\n  chi0: {value: 0.8}\n  e_max: {value: 1e8}\n  delta: {value: 1e-4}\ndatasets:\n  - kind: shape_series\n    file: ss_ok.csv\n    time: {column: "Time (s)", unit: s}\n    plant: ss_plant.csv\n    series:\n      - {id: flower1, column: "Flower 1 Angle (deg)", unit: deg, tip_mass: 0.001, segment: %s}\n' 2 >"$C/ss_pgood.yaml"
sed 's/segment: 2}/segment: 7}/' "$C/ss_pgood.yaml" >"$C/ss_pseg.yaml"
WHY=""
run_phc simulate "$C/ss_pgood.yaml" -o "$T/out_ss_pgood"
[ "$RC" -eq 0 ] || add_why "exit code $RC, expected 0"
ls "$T/out_ss_pgood"/*flower1_frame00.vtk >/dev/null 2>&1 || add_why "no VTK frame written"
report_case "shape_series: control: a plant graph with a segment per series simulates"
rm -rf "$T/out_ss_pgood"
fit_case "shape_series: unknown segment" "$C/ss_pseg.yaml" "ss_pseg.yaml:13" "flower1" "no segment 7"
# dynamics: particles (the particle keys on lines 13 and 14)
ss_config ss_pgood_particles.yaml ss_ok.csv "$SS_F1" '    dynamics: particles
    frames: 2
'
WHY=""
run_phc simulate "$C/ss_pgood_particles.yaml" -o "$T/out_ss_particles"
[ "$RC" -eq 0 ] || add_why "exit code $RC, expected 0"
ls "$T/out_ss_particles"/*flower1_frames.png >/dev/null 2>&1 || add_why "no side views written"
ls "$T/out_ss_particles"/*flower1_frame01.vtk >/dev/null 2>&1 || add_why "no VTK frame written"
ls "$T/out_ss_particles"/*flower1_frame01.csv >/dev/null 2>&1 || add_why "no native graph written"
report_case "shape_series: control: dynamics: particles simulates"
rm -rf "$T/out_ss_particles"
ss_config ss_dyn.yaml ss_ok.csv "$SS_F1" '    dynamics: springs
'
fit_case "shape_series: unknown dynamics" "$C/ss_dyn.yaml" "ss_dyn.yaml:13" "'dynamics'" "springs" "rods, particles"
ss_config ss_prods.yaml ss_ok.csv "$SS_F1" '    particle_iterations: 8
'
fit_case "shape_series: particle key with rods" "$C/ss_prods.yaml" "ss_prods.yaml:13" "particle_iterations" \
    "only with"
ss_config ss_pdt.yaml ss_ok.csv "$SS_F1" '    dynamics: particles
    particle_time_step: 0
'
fit_case "shape_series: particle time step zero" "$C/ss_pdt.yaml" "ss_pdt.yaml:14" "'particle_time_step'"
ss_config ss_pdamp.yaml ss_ok.csv "$SS_F1" '    dynamics: particles
    particle_damping: 1
'
fit_case "shape_series: particle damping 1" "$C/ss_pdamp.yaml" "ss_pdamp.yaml:14" "'particle_damping'"
ss_config ss_piter.yaml ss_ok.csv "$SS_F1" '    dynamics: particles
    particle_iterations: 0
'
fit_case "shape_series: particle iterations 0" "$C/ss_piter.yaml" "ss_piter.yaml:14" "'particle_iterations'"
ss_config ss_pweight.yaml ss_ok.csv "$SS_F1" '    dynamics: particles
    parent_weight: 0.5
'
fit_case "shape_series: parent weight below 1" "$C/ss_pweight.yaml" "ss_pweight.yaml:14" "'parent_weight'"
ss_config ss_psteps.yaml ss_ok.csv "$SS_F1" '    dynamics: particles
    particle_steps: 5
'
fit_case "shape_series: particles not at rest within the step cap" "$C/ss_psteps.yaml" "ss_ok.csv:2" \
    "not finite at the start values"
# ---- end shape_series ------------------------------------------------------
# ---- shape_series with water: plant (the water model drives the moduli) ----
sed 's/,0,0$/,1,0/' "$C/ss_plant.csv" >"$C/ss_leafplant.csv" # leaf segments lose water
sed -e 's/ss_plant.csv/ss_leafplant.csv/' -e 's/^    plant:/    water: plant\n    plant:/' "$C/ss_pgood.yaml" >"$C/ss_wgood.yaml"
WHY=""
run_phc simulate "$C/ss_wgood.yaml" -o "$T/out_ss_wgood"
[ "$RC" -eq 0 ] || add_why "exit code $RC, expected 0"
ls "$T/out_ss_wgood"/*flower1_frame00.vtk >/dev/null 2>&1 || add_why "no VTK frame written"
report_case "shape_series: control: water: plant simulates"
rm -rf "$T/out_ss_wgood"
ss_config ss_wnoplant.yaml ss_ok.csv "$SS_F1" '    water: plant
'
fit_case "shape_series: water: plant without a plant" "$C/ss_wnoplant.yaml" "ss_wnoplant.yaml:13" "'water'" "plant"
ss_config ss_wbad.yaml ss_ok.csv "$SS_F1" '    water: soil
'
fit_case "shape_series: unknown water driver" "$C/ss_wbad.yaml" "ss_wbad.yaml:13" "'soil'" "compartment, plant"
ss_config ss_wvisc.yaml ss_ok.csv "$SS_F1" '    viscosity: 1.0
'
fit_case "shape_series: viscosity without the water model" "$C/ss_wvisc.yaml" "ss_wvisc.yaml:13" "'viscosity'" "water: plant"
sed 's/^    water: plant/    water: plant\n    water_step: -1/' "$C/ss_wgood.yaml" >"$C/ss_wstep.yaml"
fit_case "shape_series: negative water step" "$C/ss_wstep.yaml" "ss_wstep.yaml:12" "'water_step'" "positive"

# ---- phytocal grow (climbing plants) -----------------------------------------
# grow_case NAME CONFIG SUBSTRING...: `phytocal grow CONFIG -o OUT` must fail
# with exit code 2, one line naming the file and line/key, and no output.
grow_case() {
    local name=$1 config=$2
    shift 2
    local out="$T/out_${name//[^A-Za-z0-9_]/_}"
    WHY=""
    run_phc grow "$config" -o "$out"
    check_error_output 2 "$@"
    check_no_output "$out"
    report_case "$name"
}
printf 'v -0.5 0 0\nv 0.5 0 0\nv -0.5 0 1\nv 0.5 0 1\nf 1 3 2\nf 2 3 4\n' >"$C/gr_wall.obj"
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nzero one two?\n' >"$C/gr_noheader.ply"
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\nzero one two?\n' >"$C/gr_junk.ply"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\n' >"$C/gr_points.obj"
gr_config() { # FILE MESH POSITION EXTRA_LINES
    printf 'name: g\nsupport: %s\nduration: 2\nplant:\n  position: %s\n%s' "$2" "$3" "${4:-}" >"$C/$1"
}
gr_config gr_good.yaml gr_wall.obj '[0, 0.03, 0]'
WHY=""
run_phc grow "$C/gr_good.yaml" -o "$T/out_gr_good" --quiet
[ "$RC" -eq 0 ] || add_why "exit code $RC, expected 0"
for f in result.json growth.csv frame_0000.vtk plant_side.png plant_front.png support.vtk phytocal-run.json; do
    [ -f "$T/out_gr_good/$f" ] || add_why "no $f written"
done
report_case "grow: control: a seed before a wall grows"
run_phc grow "$C/gr_good.yaml" -o "$T/out_gr_good" --quiet
WHY=""
[ "$RC" -eq 2 ] || add_why "exit code $RC, expected 2 (the run directory exists)"
run_phc grow "$C/gr_good.yaml" -o "$T/out_gr_good" --quiet --force
[ "$RC" -eq 0 ] || add_why "with --force: exit code $RC, expected 0"
report_case "grow: control: an earlier run is replaced only with --force"
rm -rf "$T/out_gr_good"
gr_config gr_noheader.yaml gr_noheader.ply '[0, 0.03, 0]'
grow_case "grow: PLY mesh without end_header" "$C/gr_noheader.yaml" "gr_noheader.yaml:2" "support" "end_header"
gr_config gr_junk.yaml gr_junk.ply '[0, 0.03, 0]'
grow_case "grow: PLY mesh that does not parse" "$C/gr_junk.yaml" "gr_junk.yaml:2" "support" "assimp"
gr_config gr_points.yaml gr_points.obj '[0, 0.03, 0]'
grow_case "grow: OBJ mesh without triangles" "$C/gr_points.yaml" "gr_points.yaml:2" "no triangles"
gr_config gr_nomesh.yaml gr_none.obj '[0, 0.03, 0]'
grow_case "grow: missing mesh file" "$C/gr_nomesh.yaml" "gr_nomesh.yaml:2" "gr_none.obj"
gr_config gr_inside.yaml gr_wall.obj '[0, -0.05, 0.3]'
grow_case "grow: seed inside (behind) the support" "$C/gr_inside.yaml" "gr_inside.yaml:5" "plant.position" "behind"
gr_config gr_bp.yaml gr_wall.obj '[0, 0.03, 0]' 'branching:
  probability: 1.5
'
grow_case "grow: branching probability above 1" "$C/gr_bp.yaml" "gr_bp.yaml:7" "branching.probability" "[0, 1]"
gr_config gr_bpneg.yaml gr_wall.obj '[0, 0.03, 0]' 'branching:
  probability: -0.1
'
grow_case "grow: branching probability below 0" "$C/gr_bpneg.yaml" "gr_bpneg.yaml:7" "branching.probability"
gr_config gr_var.yaml gr_wall.obj '[0, 0.03, 0]' 'branching:
  variance: 1.2
'
grow_case "grow: direction variance over 1" "$C/gr_var.yaml" "gr_var.yaml:7" "branching.variance" "90 degrees"
gr_config gr_ks.yaml gr_wall.obj '[0, 0.03, 0]' 'anchors:
  strength: 2
'
grow_case "grow: anchor strength over 1" "$C/gr_ks.yaml" "gr_ks.yaml:7" "anchors.strength"
gr_config gr_typo.yaml gr_wall.obj '[0, 0.03, 0]' 'branching:
  probabilty: 0.5
'
grow_case "grow: misspelt key" "$C/gr_typo.yaml" "gr_typo.yaml:7" "did you mean 'probability'"
gr_config gr_nopos.yaml gr_wall.obj '[0, 0.03, 0]'
sed -i 's/position:/direction:/' "$C/gr_nopos.yaml"
grow_case "grow: no seed position" "$C/gr_nopos.yaml" "gr_nopos.yaml:5" "position"
gr_config gr_vec.yaml gr_wall.obj '[0, 0.03]'
grow_case "grow: position of two numbers" "$C/gr_vec.yaml" "gr_vec.yaml:5" "three numbers"
gr_config gr_dt.yaml gr_wall.obj '[0, 0.03, 0]' 'time_step: 8
'
grow_case "grow: time step too long for the growth rate" "$C/gr_dt.yaml" "gr_dt.yaml:6" "time_step"
gr_config gr_rel.yaml gr_wall.obj '[0, 0.03, 0]' 'anchors:
  attach_distance: 0.03
'
grow_case "grow: release distance not above attach distance" "$C/gr_rel.yaml" "gr_rel.yaml:7" "release_distance"
gr_config gr_leafang.yaml gr_wall.obj '[0, 0.03, 0]' 'leaves:
  angle: 400
'
grow_case "grow: leaf divergence angle over 360 degrees" "$C/gr_leafang.yaml" "gr_leafang.yaml:7" "leaves.angle" "[0, 360]"
gr_config gr_leafsize.yaml gr_wall.obj '[0, 0.03, 0]' 'leaves:
  size: 0
'
grow_case "grow: leaf size zero" "$C/gr_leafsize.yaml" "gr_leafsize.yaml:7" "leaves.size" "(0, inf)"
gr_config gr_leafstep.yaml gr_wall.obj '[0, 0.03, 0]' 'leaves:
  step: 1.5
'
grow_case "grow: leaf step not an integer" "$C/gr_leafstep.yaml" "gr_leafstep.yaml:7" "leaves.step"
gr_config gr_camb.yaml gr_wall.obj '[0, 0.03, 0]' 'cambium:
  rate: -1
'
grow_case "grow: negative cambium rate" "$C/gr_camb.yaml" "gr_camb.yaml:7" "cambium.rate"
gr_config gr_break.yaml gr_wall.obj '[0, 0.03, 0]' 'dynamics:
  break_threshold: -0.1
'
grow_case "grow: negative break threshold" "$C/gr_break.yaml" "gr_break.yaml:7" "dynamics.break_threshold" "[0, inf)"
gr_config gr_breaktext.yaml gr_wall.obj '[0, 0.03, 0]' 'dynamics:
  break_threshold: strong
'
grow_case "grow: break threshold not a number" "$C/gr_breaktext.yaml" "gr_breaktext.yaml:7" "dynamics.break_threshold"
gr_config gr_fall.yaml gr_wall.obj '[0, 0.03, 0]' 'dynamics:
  fall_time: -1
'
grow_case "grow: negative fall time" "$C/gr_fall.yaml" "gr_fall.yaml:7" "dynamics.fall_time" "[0, inf)"
gr_config gr_resprout.yaml gr_wall.obj '[0, 0.03, 0]' 'dynamics:
  resprout_delay: -2
'
grow_case "grow: negative resprout delay" "$C/gr_resprout.yaml" "gr_resprout.yaml:7" "dynamics.resprout_delay" "[0, inf)"
gr_config gr_resprouttext.yaml gr_wall.obj '[0, 0.03, 0]' 'dynamics:
  resprout_delay: soon
'
grow_case "grow: resprout delay not a number" "$C/gr_resprouttext.yaml" "gr_resprouttext.yaml:7" "dynamics.resprout_delay"
gr_config gr_shadow.yaml gr_wall.obj '[0, 0.03, 0]' 'light:
  supports_cast_shadows: maybe
'
grow_case "grow: shadows neither true nor false" "$C/gr_shadow.yaml" "gr_shadow.yaml:7" "supports_cast_shadows"
gr_config gr_amb.yaml gr_wall.obj '[0, 0.03, 0]' 'light:
  ambient: 1.5
'
grow_case "grow: ambient light share over 1" "$C/gr_amb.yaml" "gr_amb.yaml:7" "light.ambient" "[0, 1]"
gr_config gr_collide.yaml gr_wall.obj '[0, 0.03, 0]' 'dynamics:
  collide: sometimes
'
grow_case "grow: collide neither true nor false" "$C/gr_collide.yaml" "gr_collide.yaml:7" "dynamics.collide" "expected a boolean"
gr_config gr_collide_ends.yaml gr_wall.obj '[0, 0.03, 0]' 'dynamics:
  collide_ends: 2
'
grow_case "grow: collide_ends neither true nor false" "$C/gr_collide_ends.yaml" "gr_collide_ends.yaml:7" "dynamics.collide_ends" "expected a boolean"
gr_config gr_collide_segments.yaml gr_wall.obj '[0, 0.03, 0]' 'dynamics:
  collide_segments: maybe
'
grow_case "grow: collide_segments neither true nor false" "$C/gr_collide_segments.yaml" "gr_collide_segments.yaml:7" "dynamics.collide_segments" "expected a boolean"
gr_config gr_bending.yaml gr_wall.obj '[0, 0.03, 0]' 'dynamics:
  bending: springy
'
grow_case "grow: bending neither own_weight nor beam" "$C/gr_bending.yaml" "gr_bending.yaml:7" "dynamics.bending" "'springy'" "own_weight or beam"
gr_config gr_beam_modulus.yaml gr_wall.obj '[0, 0.03, 0]' 'dynamics:
  bending: beam
  beam_modulus: 0
'
grow_case "grow: beam modulus zero" "$C/gr_beam_modulus.yaml" "gr_beam_modulus.yaml:8" "dynamics.beam_modulus" "(0, inf) Pa"
gr_config gr_break_stress.yaml gr_wall.obj '[0, 0.03, 0]' 'dynamics:
  bending: beam
  break_stress: -1e6
'
grow_case "grow: negative break stress" "$C/gr_break_stress.yaml" "gr_break_stress.yaml:8" "dynamics.break_stress" "[0, inf) Pa"
gr_config gr_break_stress_nan.yaml gr_wall.obj '[0, 0.03, 0]' 'dynamics:
  bending: beam
  break_stress: .nan
'
grow_case "grow: break stress not a number" "$C/gr_break_stress_nan.yaml" "gr_break_stress_nan.yaml:8" "dynamics.break_stress"
gr_config gr_break_stress_own.yaml gr_wall.obj '[0, 0.03, 0]' 'dynamics:
  bending: own_weight
  break_stress: 1e6
'
grow_case "grow: break stress with the own-weight pass" "$C/gr_break_stress_own.yaml" "gr_break_stress_own.yaml:8" "dynamics.break_stress" "bending: beam" "own_weight"
gr_config gr_break_both.yaml gr_wall.obj '[0, 0.03, 0]' 'dynamics:
  bending: beam
  break_threshold: 0.05
  break_stress: 1e6
'
grow_case "grow: break stress and break threshold both" "$C/gr_break_both.yaml" "gr_break_both.yaml:9" "dynamics.break_stress" "dynamics.break_threshold" "give one"
gr_config gr_carry_own.yaml gr_wall.obj '[0, 0.03, 0]' 'dynamics:
  anchors_carry_moment: true
'
grow_case "grow: anchors carry moment with the own-weight pass" "$C/gr_carry_own.yaml" "gr_carry_own.yaml:7" "dynamics.anchors_carry_moment" "bending: beam"
# ---- end grow ----------------------------------------------------------------

# ---- shoot_traces (traced shoots of a climbing plant) ------------------------
gr_config st_plant.yaml gr_wall.obj '[0, 0.03, 0]'
st_config() { # FILE TRACES [EXTRA_LINES]
    printf 'name: st\nparameters:\n  branch_probability: {value: 0.3, lower: 0, upper: 1}\ndatasets:\n  - kind: shoot_traces\n    file: %s\n    plant: st_plant.yaml\n    seeds: 2\n%s' "$2" "${3:-}" >"$C/$1"
}
printf 'time,shoot,x,y,z,parent\n0,a,0,0.03,0,\n1,a,0,0.03,0.01,\n1,b,0,0.03,0.005,c\n2,b,0.01,0.03,0.01,c\n' >"$C/st_parent.csv"
st_config st_parent.yaml st_parent.csv
fit_case "shoot_traces: unknown parent shoot" "$C/st_parent.yaml" "st_parent.csv:4" "column 'parent'" "'c'"
printf 'time,shoot,x,y,z\n0,a,0,0.03,0\n2,a,0,0.03,0.01\n1,a,0,0.03,0.02\n' >"$C/st_back.csv"
st_config st_back.yaml st_back.csv
fit_case "shoot_traces: time going backwards within a shoot" "$C/st_back.yaml" "st_back.csv:4" "column 'time'" "backwards"
printf 'time,shoot,x,y,z\n0,a,0,0.03,0\n1,a,0,n/a,0.01\n' >"$C/st_text.csv"
st_config st_text.yaml st_text.csv
fit_case "shoot_traces: non-numeric cell" "$C/st_text.yaml" "st_text.csv:3" "column 'y'" "n/a"
printf 'time,shoot,x,y,z\n0,a,0,0.03,0\n1,a,0,0.03,0.01\n1,b,0,0.03,0.01\n' >"$C/st_one.csv"
st_config st_one.yaml st_one.csv
fit_case "shoot_traces: a shoot with one point" "$C/st_one.yaml" "st_one.csv:4" "at least 2"
printf 'time,shoot,x,y,z\n0,a,0,0.03,0\n1,a,0,0.03,0.01\n' >"$C/st_ok.csv"
st_config st_late.yaml st_ok.csv '    times: [0.5, 3]
'
fit_case "shoot_traces: observation time after the traces" "$C/st_late.yaml" "st_late.yaml:5" "3 s"
st_config st_seeds.yaml st_ok.csv '    seeds: 0
'
sed -i '0,/    seeds: 2/{/    seeds: 2/d}' "$C/st_seeds.yaml"
fit_case "shoot_traces: zero seeds" "$C/st_seeds.yaml" "st_seeds.yaml:8" "'seeds'"
# ---- end shoot_traces --------------------------------------------------------

# ----------------------------------------------------------------------------
echo "$PASSED passed, $FAILED failed"
[ "$FAILED" -eq 0 ]
