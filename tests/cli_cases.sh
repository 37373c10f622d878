# tests/cli_cases.sh: what the command-line test scripts share.  A script
# sources it first thing, with its own arguments:
#
#   source "$(dirname "${BASH_SOURCE[0]}")/../cli_cases.sh" "$@"
#
# It checks the first argument (the phytocal command, made absolute as PHC),
# sets SCRIPT_DIR (the sourcing script's folder), makes a scratch folder T
# (removed on exit) and enters it, and defines the case helpers:
#   run ARGS...    runs "$PHC" ARGS with a timeout (PHC_CASE_TIMEOUT, 600 s);
#                  stdout and stderr into $T/stdout and $T/stderr, exit in RC
#   why TEXT       records a reason the case failed
#   finish NAME    prints "ok - NAME" or "not ok - NAME: reasons [...]" and
#                  counts it (a sanitizer report on stderr fails the case)
#   want_rc N, err_has TEXT, out_has TEXT: the usual checks (file_has FILE
#                  TEXT reads the file in the shell: no subprocess per check)
# The script ends with: echo "$PASSED passed, $FAILED failed"; [ "$FAILED" -eq 0 ]
set -u
PHC=${1:-}
if [ -z "$PHC" ]; then
    echo "usage: bash $(basename "${BASH_SOURCE[1]}") PATH/TO/phytocal [SHARED_DATA_DIR]" >&2
    exit 2
fi
case "$PHC" in /*) ;; *) PHC="$PWD/$PHC" ;; esac
SCRIPT_DIR=$(cd "$(dirname "${BASH_SOURCE[1]}")" && pwd)

T=$(mktemp -d "${TMPDIR:-/tmp}/phc_$(basename "${BASH_SOURCE[1]}" .sh).XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT
cd "$T" || exit 1

PASSED=0
FAILED=0
WHY=""
RC=0
why() { WHY="${WHY:+$WHY; }$1"; }
# file_has FILE TEXT: FILE contains TEXT (read by the shell: a case costs
# no subprocess beyond phytocal itself)
file_has() {
    [ -f "$1" ] || return 1
    local -a lines
    mapfile -t lines <"$1"
    local IFS=$'\n'
    case "${lines[*]}" in *"$2"*) return 0 ;; esac
    return 1
}
finish() {
    if file_has "$T/stderr" AddressSanitizer || file_has "$T/stderr" 'runtime error' ||
        file_has "$T/stderr" LeakSanitizer; then
        why "sanitizer report on stderr"
    fi
    if [ -z "$WHY" ]; then
        PASSED=$((PASSED + 1))
        echo "ok - $1"
    else
        FAILED=$((FAILED + 1))
        echo "not ok - $1: $WHY [rc=$RC stderr: $(head -c 600 "$T/stderr" | tr '\n' '|')]"
    fi
    WHY=""
}
run() {
    timeout "${PHC_CASE_TIMEOUT:-600}" "$PHC" "$@" >"$T/stdout" 2>"$T/stderr"
    RC=$?
}
want_rc() { [ "$RC" -eq "$1" ] || why "exit code $RC, expected $1"; }
err_has() { file_has "$T/stderr" "$1" || why "stderr lacks '$1'"; }
out_has() { file_has "$T/stdout" "$1" || why "stdout lacks '$1'"; }
