#!/usr/bin/env bash
# A fit of phototropism toward where the light is (seek_light; README
# "Phototropism toward where the light is"): `phytocal fit` of
# measurements/examples/climbing/seek_light.yaml (eta and r, 8 seeds) to the
# model's own traces of overhang.yaml (eta 0.08 1/s, r 0.3 1/s, seed 101),
# from the example's starts (eta 0.11, r 0.2: 37.5% and 33% off) and from
# starts on the other side (eta 0.05, r 0.4: 37.5% and 33% off).  Checked:
# every fit converges (exit 0, status converged) and each parameter's 95%
# interval covers the truth.
#   bash test_seek_light_fit.sh PATH/TO/phytocal [SHARED_DATA]
set -u
PHC=${1:?usage: test_seek_light_fit.sh PATH/TO/phytocal [SHARED_DATA]}
case "$PHC" in /*) ;; *) PHC="$PWD/$PHC" ;; esac
SRC=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
EX="$SRC/measurements/examples/climbing"
T=$(mktemp -d "${TMPDIR:-/tmp}/phc_seek_fit.XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT
cp "$EX/seek_light.yaml" "$EX/overhang.yaml" "$EX/overhang.obj" "$EX/seek_light_traces.csv" "$T/"
sed 's/value: 0.11,/value: 0.05,/; s/value: 0.2, lower/value: 0.4, lower/' "$T/seek_light.yaml" >"$T/below.yaml"
FAILED=0
for cfg in seek_light below; do
    "$PHC" fit "$T/$cfg.yaml" -o "$T/run_$cfg" >"$T/out_$cfg" 2>"$T/err_$cfg"
    RC=$?
    if ! /usr/bin/python3 - "$T/run_$cfg/result.json" "$cfg" "$RC" <<'PY'
import json, sys
path, cfg, rc = sys.argv[1], sys.argv[2], int(sys.argv[3])
truth = {"phototropism": 0.08, "growth_rate": 0.3}
try:
    r = json.load(open(path))
except (OSError, ValueError) as e:
    print(f"not ok - {cfg}: exit {rc}, no result.json ({e})")
    sys.exit(1)
ok = rc == 0 and r.get("status") == "converged"
parts = []
for name, t in truth.items():
    p = r["parameters"][name]
    lo, hi = p["ci95"]
    covers = lo <= t <= hi
    ok &= covers
    parts.append(f"{name} {p['value']:.4g} [{lo:.4g}, {hi:.4g}] from {p['start']:g} "
                 f"({'covers' if covers else 'MISSES'} {t:g})")
print(f"{'ok' if ok else 'not ok'} - {cfg}: exit {rc}, {r.get('status')}; " + "; ".join(parts))
sys.exit(0 if ok else 1)
PY
    then
        head -c 300 "$T/err_$cfg"
        FAILED=1
    fi
done
exit $FAILED
