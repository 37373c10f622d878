#!/usr/bin/python3
"""SciPy peer of the start-up benchmark (tests/bench/bench_startup.c).

The small fit the benchmark times end to end, in one Python process with
Debian's system python3: read measurements/examples/enzyme_kinetics/
enzyme.csv, fit Michaelis-Menten v = vmax s / (km + s) with
scipy.optimize.curve_fit (sigma 5 relative: the covariance scaled by the residual variance, as
phytocal's standard errors; bounds >= 0, start
vmax 150, km 0.1 as in enzyme.yaml), and write a report: parameters, standard
errors, 95% t intervals, RMSE, R^2, AICc, and the straight-line baseline's
R^2 and AICc, as report.md and result.json in OUTDIR.  No plots (Debian's
python3 here has no matplotlib); phytocal's run also draws four PNGs.

    /usr/bin/python3 tests/bench/startup_peer.py CSV OUTDIR

Prints the report's numbers so that a run can be compared with phytocal's.
"""
import json
import math
import sys

import numpy as np
import scipy.optimize
import scipy.stats


def aicc(rss, n, p):
    # Gaussian maximum likelihood with the noise variance estimated (RSS/n),
    # k = p + 1 estimated quantities: AICc = -2 lnL + 2k + 2k(k+1)/(n-k-1),
    # as phytocal's report (Burnham & Anderson 2002, eq. 2.14)
    k = p + 1
    lnl = -0.5 * n * (math.log(2 * math.pi * rss / n) + 1)
    return -2 * lnl + 2 * k + 2 * k * (k + 1) / (n - k - 1)


def main():
    csv, out = sys.argv[1], sys.argv[2]
    data = np.loadtxt(csv, delimiter=",", comments="#", skiprows=3)
    s, v = data[:, 0], data[:, 1]
    sigma = 5.0
    n = len(s)

    def mm(x, vmax, km):
        return vmax * x / (km + x)

    p, cov = scipy.optimize.curve_fit(mm, s, v, p0=[150, 0.1], sigma=np.full(n, sigma),
                                      absolute_sigma=False, bounds=([0, 0], [np.inf, np.inf]))
    se = np.sqrt(np.diag(cov))
    t = scipy.stats.t.ppf(0.975, n - 2)
    r = v - mm(s, *p)
    rss = float(r @ r)
    r2 = 1 - rss / float(((v - v.mean()) ** 2).sum())
    line = np.polyfit(s, v, 1)
    rl = v - np.polyval(line, s)
    r2_line = 1 - float(rl @ rl) / float(((v - v.mean()) ** 2).sum())
    result = {
        "parameters": {name: {"value": float(p[i]), "stderr": float(se[i]),
                              "ci95": [float(p[i] - t * se[i]), float(p[i] + t * se[i])]}
                       for i, name in enumerate(["vmax", "km"])},
        "n": n, "rmse": math.sqrt(rss / n), "r2": r2,
        "aicc": aicc(rss, n, 2),
        "baseline": {"r2": r2_line, "aicc": aicc(float(rl @ rl), n, 2)},
    }
    with open(f"{out}/result.json", "w") as f:
        json.dump(result, f, indent=1)
    with open(f"{out}/report.md", "w") as f:
        f.write("# enzyme-kinetics (SciPy curve_fit)\n\n| parameter | value | std. error | 95% interval |\n"
                "|---|---|---|---|\n")
        for name, q in result["parameters"].items():
            f.write(f"| {name} | {q['value']:.6g} | {q['stderr']:.6g} | "
                    f"[{q['ci95'][0]:.6g}, {q['ci95'][1]:.6g}] |\n")
        f.write(f"\nn={n} RMSE={result['rmse']:.6g} R²={r2:.6g} AICc={result['aicc']:.5g}; "
                f"baseline line R²={r2_line:.6g} AICc={result['baseline']['aicc']:.6g}\n")
    print(f"vmax {p[0]:.6g} +- {se[0]:.6g}, km {p[1]:.6g} +- {se[1]:.6g}, R2 {r2:.6g}")


if __name__ == "__main__":
    main()
