"""Peer for tests/realdata/test_profile_nist.c: lmfit's conf_interval (F-test,
the profile-likelihood interval of Venzon & Moolgavkar) on a NIST problem.

    python3 profile_lmfit.py DATA.csv "EXPRESSION" b1=START b2=START ...

DATA.csv has columns x,y; EXPRESSION is a phytocal curve expression in x and
the parameters (only exp and the arithmetic operators are translated).
Prints one line per parameter: NAME BEST LOWER95 UPPER95 (exit 77 when lmfit
is not installed)."""
import sys

try:
    import numpy as np
    import lmfit
except ImportError as e:  # the C test skips with this message
    print(f"lmfit not available: {e}", file=sys.stderr)
    sys.exit(77)

path, expr = sys.argv[1], sys.argv[2]
starts = dict(a.split("=") for a in sys.argv[3:])
data = np.genfromtxt(path, delimiter=",", names=True)
x, y = data["x"], data["y"]
code = compile(expr.replace("^", "**"), "expression", "eval")

params = lmfit.Parameters()
for name, v in starts.items():
    params.add(name, value=float(v))


def residual(p):
    env = {"x": x, "exp": np.exp}
    env.update({k: p[k].value for k in starts})
    return y - eval(code, {"__builtins__": {}}, env)


mini = lmfit.Minimizer(residual, params, xtol=1e-14, ftol=1e-14, gtol=1e-14)
result = mini.minimize(method="leastsq")
ci = lmfit.conf_interval(mini, result, sigmas=[0.95])
for name in starts:
    lo = [v for p, v in ci[name] if abs(p - 0.95) < 1e-12 and v < result.params[name].value]
    hi = [v for p, v in ci[name] if abs(p - 0.95) < 1e-12 and v > result.params[name].value]
    print(f"{name} {result.params[name].value:.17g} {lo[0]:.17g} {hi[0]:.17g}")
