#!/usr/bin/python3
"""SciPy peer of the leaf benchmark (tests/bench/bench_leaf.c).

The same step as phc_leaf_step (model/leaf.h; Silva et al. §3, eqs. 1-7),
written with NumPy and scipy.linalg.solve_banded and run with Debian's
system python3:

    /usr/bin/python3 tests/bench/leaf_peer.py N STEPS MAPS [--repeat R]

MAPS is the raw file bench_leaf.c writes: the mask (N^2 uint8), then the
venation beta, the stomata O and the inflow I (N^2 float64 each), element
order x + N y (array axes [y, x]).  Parameters: s_beta 50, s_O 0.1,
s_I 0.05, h = dt = 0.1 (phc_leaf_params_default); y = 1 on the leaf.

One step:
  1. transpiration  y <- max(y - h s_O O, 0)
  2. inflow         y <- y + h s_I I
  3. columns, then rows: for every run of consecutive leaf pixels of every
     column (then row), the tridiagonal system
        -a_{i-1} y'_{i-1} + (1 + a_{i-1} + a_i) y'_i - a_i y'_{i+1} = y_i,
        a = h s_beta (beta_a + beta_b) / 2 for the faces inside the run,
     solved with one scipy.linalg.solve_banded call (LAPACK gbsv) per run.
     The band matrices are built once, outside the timings.
A batched variant solves all the runs of a half-step in one solve_banded
call (the runs concatenated, with zero coupling between them, pixels off
the leaf as identity rows): the same systems, fewer Python calls.

Prints `name: value unit` lines (prefix scipy_): milliseconds per step (best
of R timings of STEPS steps, each from y = 1, and the median), and the
checksum sum(y wt), wt = 1 + (i mod 97) + row (i the flat index), after
STEPS steps, summed with math.fsum, for both variants.
"""
import argparse
import math
import statistics
import sys
import time

import numpy as np
import scipy
from scipy.linalg import solve_banded

S_BETA, S_O, S_I, DT = 50.0, 0.1, 0.05, 0.1


def read_maps(path, N):
    n = N * N
    raw = np.fromfile(path, dtype=np.uint8)
    if raw.size != n + 3 * 8 * n:
        raise SystemExit(f"{path}: {raw.size} bytes, expected {n + 24 * n}")
    mask = raw[:n].reshape(N, N).astype(bool)
    rest = np.frombuffer(raw[n:].tobytes(), dtype="<f8")
    beta, O, I = (rest[k * n:(k + 1) * n].reshape(N, N).copy() for k in range(3))
    return mask, beta, O, I


def runs(line):
    """[(s, e)] of the runs of True in a 1-D boolean array."""
    d = np.diff(np.concatenate(([0], line.astype(np.int8), [0])))
    return list(zip(np.flatnonzero(d == 1).tolist(), np.flatnonzero(d == -1).tolist()))


def band(beta_run, h):
    """(3, n) band of one run's system, solve_banded layout."""
    a = h * (S_BETA * (0.5 * (beta_run[:-1] + beta_run[1:])))
    n = beta_run.size
    ab = np.zeros((3, n))
    ab[0, 1:] = -a
    ab[2, :-1] = -a
    d = np.ones(n)
    d[:-1] += a
    d[1:] += a
    ab[1] = d
    return ab


def systems(mask, beta, h, axis):
    """[(line, s, e, ab)] for every run of every column (axis 0: y varies)
    or row (axis 1: x varies)."""
    out = []
    N = mask.shape[0]
    for j in range(N):
        m = mask[:, j] if axis == 0 else mask[j, :]
        b = beta[:, j] if axis == 0 else beta[j, :]
        for s, e in runs(m):
            out.append((j, s, e, band(b[s:e], h)))
    return out


def batched_band(mask, beta, h):
    """One band for all the rows of (mask, beta) concatenated (row-major):
    zero coupling across row ends and across the mask border."""
    both = mask[:, :-1] & mask[:, 1:]
    a = np.zeros(mask.shape)
    a[:, :-1] = np.where(both, h * (S_BETA * (0.5 * (beta[:, :-1] + beta[:, 1:]))), 0.0)
    a = a.ravel()  # a[i]: face between i and i + 1 (0 at row ends)
    n = a.size
    ab = np.zeros((3, n))
    ab[0, 1:] = -a[:-1]
    ab[2, :-1] = -a[:-1]
    d = np.ones(n)
    d += a
    d[1:] += a[:-1]
    ab[1] = d
    return ab


def step_runs(y, O, I, h, cols, rows):
    y = np.maximum(y - (h * S_O) * O, 0.0) + (h * S_I) * I
    for x, s, e, ab in cols:
        y[s:e, x] = solve_banded((1, 1), ab, y[s:e, x], check_finite=False)
    for r, s, e, ab in rows:
        y[r, s:e] = solve_banded((1, 1), ab, y[r, s:e], check_finite=False)
    return y


def step_batched(y, O, I, h, abc, abr):
    y = np.maximum(y - (h * S_O) * O, 0.0) + (h * S_I) * I
    yt = solve_banded((1, 1), abc, y.T.ravel(), overwrite_b=True, check_finite=False)
    y = np.ascontiguousarray(yt.reshape(y.shape).T)
    return solve_banded((1, 1), abr, y.ravel(), overwrite_b=True, check_finite=False).reshape(y.shape)


def checksum(y):
    N = y.shape[1]
    i = np.arange(y.size)
    wt = (1 + (i % 97) + i // N).astype(np.float64)
    return math.fsum((y.ravel() * wt).tolist())


def timed(fn, y0, steps, repeat):
    times = []
    y = None
    for _ in range(repeat):
        y = y0.copy()
        t0 = time.perf_counter()
        for _ in range(steps):
            y = fn(y)
        times.append((time.perf_counter() - t0) / steps * 1e3)
    return min(times), statistics.median(times), y


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("N", type=int)
    ap.add_argument("steps", type=int)
    ap.add_argument("maps")
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    N, steps = a.N, a.steps
    mask, beta, O, I = read_maps(a.maps, N)
    O = np.where(mask, O, 0.0)
    I = np.where(mask, I, 0.0)
    y0 = np.where(mask, 1.0, 0.0)
    h = DT
    cols = systems(mask, beta, h, 0)
    rows = systems(mask, beta, h, 1)
    print(f"scipy_version: {scipy.__version__} (numpy {np.__version__}, python {sys.version.split()[0]})")
    print(f"scipy_runs_{N}: {len(cols)} column runs, {len(rows)} row runs (one solve_banded call each)")
    best, med, y = timed(lambda v: step_runs(v, O, I, h, cols, rows), y0, steps, a.repeat)
    print(f"scipy_ms_per_step_{N}: {best:.3f} ms (best of {a.repeat} timings of {steps} steps; "
          f"median {med:.3f} ms)")
    print(f"scipy_checksum_{N}: {checksum(y):.17g} 1")
    abc = batched_band(mask.T.copy(), beta.T.copy(), h)
    abr = batched_band(mask, beta, h)
    best, med, y = timed(lambda v: step_batched(v, O, I, h, abc, abr), y0, steps, a.repeat)
    print(f"scipy_batched_ms_per_step_{N}: {best:.3f} ms (best of {a.repeat} timings of {steps} steps; "
          f"median {med:.3f} ms)")
    print(f"scipy_batched_checksum_{N}: {checksum(y):.17g} 1")
    return 0


if __name__ == "__main__":
    sys.exit(main())
