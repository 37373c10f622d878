#!/usr/bin/python3
"""Peer numbers for the NIST StRD nonlinear regression benchmark.

Fits the 22 NIST problems in DATA_DIR (*.dat, NIST's own files) from both
NIST starting points with two Python peers and prints, as `name: value unit`
lines on stdout:

    scipy_solved: S of 44 (min parameter LRE >= 4)
    scipy_average_lre: L digits
    scipy_total_time: T s
    lmfit_...   (the same three)

Run with Debian's system Python, which has SciPy 1.10 and lmfit 1.1
(not the pyenv python on PATH):

    /usr/bin/python3 tests/bench/nist_peers.py ../shared/data/nist [--repeat R] [--table]

Peers and settings (one configuration each, stated here so the numbers mean
something):

  scipy  scipy.optimize.least_squares(fun, x0, method='trf', jac='2-point',
         x_scale='jac', ftol=1e-15, xtol=1e-15, gtol=1e-15); other arguments
         default (max_nfev = 100*n for trf).  Trust-region reflective with
         Jacobian scaling is the default method plus the scaling a user
         would add for badly scaled problems such as Misra1a or Nelson.
  lmfit  lmfit.minimize(residual, params, method='leastsq', ftol=1e-15,
         xtol=1e-15, gtol=1e-15): MINPACK Levenberg-Marquardt with
         forward-difference Jacobian (lmfit's default method), and lmfit's
         default post-fit work (covariance, statistics).  Parameters have no
         bounds.  nan_policy is lmfit's default ('raise').

  Tolerances: both peers use 1e-15 instead of their defaults (1e-8 for
  least_squares, 1.5e-8 for MINPACK via lmfit) because the score is digits of
  agreement with 11-digit certified values; default tolerances stop at about
  as many digits as the tolerance allows.  MINPACK may report that 1e-15 is
  "too small"; the fit still returns its best point, which is what is scored.

Score: for each fit, the smallest log relative error over the parameters,
LRE = -log10(|b - b_cert| / |b_cert|), clipped to [0, 11] as in Ceres
examples/nist.cc.  A fit that raises (lmfit's default nan_policy raises
when the residual becomes NaN) counts as LRE 0, is left out of total_time and
is counted in <peer>_errors.  "Solved" means that
minimum LRE >= 4 (Ceres's kMinNumMatchingDigits).  average_lre is the mean of
the 44 minimum LREs.

Time: time.perf_counter() around the fit call only (building the residual
closure and, for lmfit, the Parameters object is outside the timing);
each fit is repeated R times (default 3) and the MINIMUM is kept;
total_time is the sum of these minima over the 44 fits.  Single thread is not
enforced; these problems are too small for BLAS threading to matter.

Nelson models log(y): the residual is log(y) - f(x1, x2), matching the `y`
column that tests/nist_problem.h writes for phytocal.
"""

import argparse
import math
import os
import re
import sys
import time
import warnings

import numpy as np


# ---- .dat parsing -------------------------------------------------------------

class Problem:
    pass


def load_dat(path):
    """Reads a NIST StRD nonlinear regression .dat file."""
    p = Problem()
    p.name = os.path.splitext(os.path.basename(path))[0]
    with open(path, "r") as f:
        lines = [ln.rstrip("\r\n") for ln in f]
    data_first, data_last = 61, len(lines)
    for ln in lines[:20]:
        m = re.match(r"\s*Data\s*\(lines\s+(\d+)\s+to\s+(\d+)\)", ln)
        if m:
            data_first, data_last = int(m.group(1)), int(m.group(2))
    starts, cert, sd = [[], []], [], []
    rss = None
    n_declared = None
    response_log = False
    for i, ln in enumerate(lines[:data_first - 1], start=1):
        s = ln.strip()
        m = re.match(r"b(\d+)\s*=\s*(.*)$", s)
        if m:
            if int(m.group(1)) != len(cert) + 1:
                raise ValueError("%s:%d: expected b%d" % (path, i, len(cert) + 1))
            v = [float(t) for t in m.group(2).split()]
            if len(v) != 4:
                raise ValueError("%s:%d: expected 4 numbers" % (path, i))
            starts[0].append(v[0])
            starts[1].append(v[1])
            cert.append(v[2])
            sd.append(v[3])
        elif s.startswith("Residual Sum of Squares:"):
            rss = float(s.split(":", 1)[1])
        elif s.startswith("Number of Observations:"):
            n_declared = int(s.split(":", 1)[1])
        elif s.startswith("log[y]"):
            response_log = True
    rows = []
    for i in range(data_first, data_last + 1):
        s = lines[i - 1].strip() if i - 1 < len(lines) else ""
        if s:
            rows.append([float(t) for t in s.split()])
    if not cert or rss is None or not rows:
        raise ValueError("%s: not a NIST StRD nonlinear regression file" % path)
    if n_declared is not None and n_declared != len(rows):
        raise ValueError("%s: %d observations declared, %d read" % (path, n_declared, len(rows)))
    data = np.array(rows, dtype=float)
    p.k = len(cert)
    p.starts = [np.array(starts[0]), np.array(starts[1])]
    p.certified = np.array(cert)
    p.certified_sd = np.array(sd)
    p.certified_rss = rss
    p.y = data[:, 0]
    p.response = np.log(p.y) if response_log else p.y
    p.x = data[:, 1] if data.shape[1] == 2 else data[:, 1:]  # Nelson: (n, 2)
    p.n = len(rows)
    return p


# ---- the 22 models (same as tests/nist_problem.h) -----------------------------

def _gauss(b, x):
    return (b[0] * np.exp(-b[1] * x) + b[2] * np.exp(-((x - b[3]) ** 2) / b[4] ** 2)
            + b[5] * np.exp(-((x - b[6]) ** 2) / b[7] ** 2))


def _lanczos(b, x):
    return b[0] * np.exp(-b[1] * x) + b[2] * np.exp(-b[3] * x) + b[4] * np.exp(-b[5] * x)


def _enso(b, x):
    w = 2 * np.pi * x
    return (b[0] + b[1] * np.cos(w / 12) + b[2] * np.sin(w / 12)
            + b[4] * np.cos(w / b[3]) + b[5] * np.sin(w / b[3])
            + b[7] * np.cos(w / b[6]) + b[8] * np.sin(w / b[6]))


MODELS = {
    "BoxBOD": lambda b, x: b[0] * (1 - np.exp(-b[1] * x)),
    "Chwirut1": lambda b, x: np.exp(-b[0] * x) / (b[1] + b[2] * x),
    "Chwirut2": lambda b, x: np.exp(-b[0] * x) / (b[1] + b[2] * x),
    "DanWood": lambda b, x: b[0] * x ** b[1],
    "ENSO": _enso,
    "Gauss1": _gauss,
    "Gauss2": _gauss,
    "Gauss3": _gauss,
    "Hahn1": lambda b, x: ((b[0] + b[1] * x + b[2] * x ** 2 + b[3] * x ** 3)
                           / (1 + b[4] * x + b[5] * x ** 2 + b[6] * x ** 3)),
    "Kirby2": lambda b, x: (b[0] + b[1] * x + b[2] * x ** 2) / (1 + b[3] * x + b[4] * x ** 2),
    "Lanczos1": _lanczos,
    "Lanczos2": _lanczos,
    "Lanczos3": _lanczos,
    "MGH09": lambda b, x: b[0] * (x ** 2 + x * b[1]) / (x ** 2 + x * b[2] + b[3]),
    "MGH17": lambda b, x: b[0] + b[1] * np.exp(-x * b[3]) + b[2] * np.exp(-x * b[4]),
    "Misra1a": lambda b, x: b[0] * (1 - np.exp(-b[1] * x)),
    "Misra1b": lambda b, x: b[0] * (1 - (1 + b[1] * x / 2) ** (-2)),
    "Misra1c": lambda b, x: b[0] * (1 - (1 + 2 * b[1] * x) ** (-0.5)),
    "Misra1d": lambda b, x: b[0] * b[1] * x * ((1 + b[1] * x) ** (-1)),
    "Nelson": lambda b, x: b[0] - b[1] * x[:, 0] * np.exp(-b[2] * x[:, 1]),
    "Rat42": lambda b, x: b[0] / (1 + np.exp(b[1] - b[2] * x)),
    "Roszman1": lambda b, x: b[0] - b[1] * x - np.arctan(b[2] / (x - b[3])) / np.pi,
}


# ---- scoring ------------------------------------------------------------------

def lre(computed, certified):
    """Log relative error, clipped to [0, 11] (Ceres examples/nist.cc)."""
    err = abs(computed - certified)
    if certified != 0:
        err /= abs(certified)
    if not math.isfinite(err):
        return 0.0
    if err == 0:
        return 11.0
    return min(11.0, max(0.0, -math.log10(err)))


def min_lre(b, certified):
    if b is None:
        return 0.0
    return min(lre(float(v), float(c)) for v, c in zip(b, certified))


# ---- peers --------------------------------------------------------------------

TOL = 1e-15


def fit_scipy(p, x0):
    from scipy.optimize import least_squares
    f, x, r = MODELS[p.name], p.x, p.response

    def fun(b):
        return f(b, x) - r

    t0 = time.perf_counter()
    res = least_squares(fun, x0, method="trf", jac="2-point", x_scale="jac",
                        ftol=TOL, xtol=TOL, gtol=TOL)
    t = time.perf_counter() - t0
    # nfev excludes the k evaluations of each 2-point Jacobian; count them
    return res.x, t, res.nfev + res.njev * len(x0)


def fit_lmfit(p, x0):
    import lmfit
    f, x, r, k = MODELS[p.name], p.x, p.response, p.k
    names = ["b%d" % (j + 1) for j in range(k)]

    def residual(params):
        b = [params[nm].value for nm in names]
        return f(b, x) - r

    params = lmfit.Parameters()
    for nm, v in zip(names, x0):
        params.add(nm, value=float(v))
    t0 = time.perf_counter()
    res = lmfit.minimize(residual, params, method="leastsq",
                         ftol=TOL, xtol=TOL, gtol=TOL)
    t = time.perf_counter() - t0
    # MINPACK's nfev includes the forward-difference Jacobian evaluations
    return np.array([res.params[nm].value for nm in names]), t, res.nfev


PEERS = [("scipy", fit_scipy), ("lmfit", fit_lmfit)]


def run_fit(fit, p, x0, repeat):
    best_t, b, nfev, error = math.inf, None, 0, None
    for _ in range(repeat):
        try:
            with np.errstate(all="ignore"), warnings.catch_warnings():
                warnings.simplefilter("ignore")
                b, t, nfev = fit(p, x0.copy())
        except Exception as e:  # a fit that raises scores LRE 0
            b, t, error = None, math.inf, "%s: %s" % (type(e).__name__, e)
            break
        best_t = min(best_t, t)
    return b, best_t, nfev, error


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("data_dir", help="directory with NIST's *.dat files")
    ap.add_argument("--repeat", type=int, default=3,
                    help="repetitions per fit; the minimum time is kept (default 3)")
    ap.add_argument("--table", action="store_true",
                    help="print a per-problem table to stderr")
    args = ap.parse_args()
    if args.repeat < 1:
        ap.error("--repeat must be >= 1")

    paths = sorted(os.path.join(args.data_dir, f) for f in os.listdir(args.data_dir)
                   if f.endswith(".dat"))
    problems = []
    for path in paths:
        p = load_dat(path)
        if p.name not in MODELS:
            print("%s: no model for %s, skipped" % (path, p.name), file=sys.stderr)
            continue
        problems.append(p)
    if not problems:
        sys.exit("%s: no NIST .dat files" % args.data_dir)

    totals = {name: {"solved": 0, "lre": 0.0, "time": 0.0, "fits": 0, "errors": 0}
              for name, _ in PEERS}
    if args.table:
        import scipy
        import lmfit
        print("# scipy %s, lmfit %s, numpy %s; evals = residual evaluations including "
              "finite-difference Jacobians" % (scipy.__version__, lmfit.__version__,
                                               np.__version__), file=sys.stderr)
        print("%-9s %5s  %-6s %7s %10s %6s  %s" % ("problem", "start", "peer", "minLRE",
                                                   "time_s", "evals", "note"),
              file=sys.stderr)
    for p in problems:
        for start in (1, 2):
            x0 = p.starts[start - 1]
            for name, fit in PEERS:
                b, t, nfev, error = run_fit(fit, p, x0, args.repeat)
                score = min_lre(b, p.certified)
                tot = totals[name]
                tot["fits"] += 1
                tot["lre"] += score
                tot["solved"] += score >= 4
                if error:
                    tot["errors"] += 1
                else:
                    tot["time"] += t
                if args.table:
                    print("%-9s %5d  %-6s %7.2f %10.6f %6s  %s" % (
                        p.name, start, name, score, t if not error else float("nan"),
                        nfev if not error else "-", error or ""), file=sys.stderr)

    for name, _ in PEERS:
        tot = totals[name]
        print("%s_solved: %d of %d (min parameter LRE >= 4)" % (name, tot["solved"], tot["fits"]))
        print("%s_average_lre: %.2f digits" % (name, tot["lre"] / tot["fits"]))
        print("%s_total_time: %.3f s" % (name, tot["time"]))
        if tot["errors"]:
            print("%s_errors: %d fits (scored LRE 0, not timed)" % (name, tot["errors"]))


if __name__ == "__main__":
    main()
