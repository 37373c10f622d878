#!/usr/bin/env bash
# OpenMP's waiting threads (fit/cli/main.c, wait_passively): a command of
# `phytocal` sets OMP_WAIT_POLICY=PASSIVE and runs itself again, unless the
# user chose a policy (OMP_WAIT_POLICY or GOMP_SPINCOUNT), because spinning
# threads lose to other programs' load (README "Speed").  libgomp prints its
# settings with OMP_DISPLAY_ENV=verbose when it loads, so a re-run shows two
# blocks, the second with GOMP_SPINCOUNT '0'.  Checked:
#   - no policy set: two blocks, the last one spins 0; the command's own
#     message once; its exit code kept (2: a config that does not open);
#   - OMP_WAIT_POLICY=active or GOMP_SPINCOUNT=1000 from the user: one
#     block, theirs;
#   - `phytocal version` and `--help` never run again (one block).
#   bash test_openmp_wait.sh PATH/TO/phytocal [SHARED_DATA]
set -u
PHC=${1:?usage: test_openmp_wait.sh PATH/TO/phytocal [SHARED_DATA]}
T=$(mktemp -d "${TMPDIR:-/tmp}/phc_omp_wait.XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT
FAILED=0
check() { # name, condition result (0 = pass)
    if [ "$2" -eq 0 ]; then echo "ok - $1"; else echo "FAIL - $1"; FAILED=1; fi
}
run() { # out-file, env assignments..., -- args...
    local out=$1; shift
    local envs=()
    while [ "$1" != "--" ]; do envs+=("$1"); shift; done
    shift
    env -u OMP_WAIT_POLICY -u GOMP_SPINCOUNT "${envs[@]}" OMP_DISPLAY_ENV=verbose "$PHC" "$@" >"$out" 2>&1
}
blocks() { grep -c "OPENMP DISPLAY ENVIRONMENT BEGIN" "$1"; }
spin() { grep "GOMP_SPINCOUNT" "$1" | tail -n 1 | sed "s/.*= '\(.*\)'.*/\1/"; }

run "$T/default" -- fit "$T/none.yaml"
RC=$?
echo "no policy set: exit $RC, $(blocks "$T/default") blocks, last GOMP_SPINCOUNT $(spin "$T/default"), message lines $(grep -c 'cannot open' "$T/default")"
check "no policy: two blocks" $([ "$(blocks "$T/default")" -eq 2 ]; echo $?)
check "no policy: the second spins 0 (passive)" $([ "$(spin "$T/default")" = 0 ]; echo $?)
check "no policy: the message once" $([ "$(grep -c 'cannot open' "$T/default")" -eq 1 ]; echo $?)
check "no policy: exit code 2 kept" $([ "$RC" -eq 2 ]; echo $?)

run "$T/active" OMP_WAIT_POLICY=active -- fit "$T/none.yaml"
echo "OMP_WAIT_POLICY=active: $(blocks "$T/active") block(s), $(grep 'OMP_WAIT_POLICY' "$T/active" | tail -n 1 | tr -s ' ')"
check "user's OMP_WAIT_POLICY: one block, ACTIVE" \
    $([ "$(blocks "$T/active")" -eq 1 ] && grep -q "OMP_WAIT_POLICY = 'ACTIVE'" "$T/active"; echo $?)

run "$T/spin" GOMP_SPINCOUNT=1000 -- fit "$T/none.yaml"
echo "GOMP_SPINCOUNT=1000: $(blocks "$T/spin") block(s), GOMP_SPINCOUNT $(spin "$T/spin")"
check "user's GOMP_SPINCOUNT: one block, 1000" $([ "$(blocks "$T/spin")" -eq 1 ] && [ "$(spin "$T/spin")" = 1000 ]; echo $?)

run "$T/version" -- version
run "$T/help" -- --help
echo "version: $(blocks "$T/version") block(s); --help: $(blocks "$T/help") block(s)"
check "version and --help run once" $([ "$(blocks "$T/version")" -eq 1 ] && [ "$(blocks "$T/help")" -eq 1 ]; echo $?)

[ "$FAILED" -eq 0 ] && echo "test_openmp_wait: pass" || echo "test_openmp_wait: FAILED"
exit "$FAILED"
