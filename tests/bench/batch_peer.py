"""SciPy peer of the batch benchmark (tests/bench/bench_batch.c).

    /usr/bin/python3 batch_peer.py NAME=CSV [NAME=CSV ...]

Fits each NIST problem NAME to the CSV written by nist_write_case (header
x,y; starting values Start 1 from the .dat file given as NAME's third field:
NAME=CSV=DAT) with scipy.optimize.least_squares (TRF, 2-point Jacobian,
x_scale='jac', tolerances 1e-15, as nist_peers.py), then the covariance
from the Jacobian at the optimum, and prints one line per fit.  One call
with one argument is "a Python process per fit"; one call with all is "all
in one process".  The models are nist_peers.py's.
"""
import os
import sys

import numpy as np
from scipy.optimize import least_squares

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from nist_peers import MODELS, TOL, load_dat  # noqa: E402


def fit(name, csv_path, dat_path):
    data = np.loadtxt(csv_path, delimiter=",", skiprows=1, ndmin=2)
    x, y = data[:, 0], data[:, -1]
    x0 = np.asarray(load_dat(dat_path).starts[0], dtype=float)
    model = MODELS[name]
    res = least_squares(lambda b: model(b, x) - y, x0, method="trf", jac="2-point", x_scale="jac",
                        ftol=TOL, xtol=TOL, gtol=TOL, max_nfev=10000)
    dof = max(len(y) - len(x0), 1)
    s2 = 2 * res.cost / dof
    try:
        cov = np.linalg.inv(res.jac.T @ res.jac) * s2
        se = np.sqrt(np.diag(cov))
    except np.linalg.LinAlgError:
        se = np.full(len(x0), np.nan)
    print("%s cost %.10g b %s se %s" % (name, res.cost, " ".join("%.8g" % v for v in res.x),
                                        " ".join("%.3g" % v for v in se)))


def main():
    for arg in sys.argv[1:]:
        name, csv_path, dat_path = arg.split("=", 2)
        fit(name, csv_path, dat_path)


if __name__ == "__main__":
    main()
