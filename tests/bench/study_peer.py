#!/usr/bin/python3
"""NumPy and emcee peers of the study benchmark (tests/bench/bench_study.c),
run with Debian's system python3.

    /usr/bin/python3 tests/bench/study_peer.py saltelli BASE N K R SEED [--repeat T]
    /usr/bin/python3 tests/bench/study_peer.py emcee CSV VAR0 N0 B1 B2 WALKERS STEPS

saltelli: the Sobol study of the Ishigami function (a = 7, b = 0.1) that
`phytocal sensitivity` runs in the bench, written as a NumPy user would:
  - BASE is the raw file the bench writes: the N x 2K unit-cube base points
    of the design (float64, row-major; A = the first K columns, B = the
    last K), the same points phytocal evaluates (GSL's Sobol sequence).
    Reading it is not timed.
  - timed: the N (K + 2) design points as arrays (A, B and the K matrices
    A_B^i), the factors on [-pi, pi], the model vectorised over all points
    (f = sin x1 + 7 sin^2 x2 + 0.1 x3^4 sin x1), the same two outputs as
    phytocal (the cost 3 x 0.5 f^2 of the three observations y = 0 with
    sigma 1 the bench's config has, and the mean prediction f), and for each output the first-order (Saltelli
    2010) and total (Jansen 1999) estimators with f centred on the mean over
    A and B, and R bootstrap resamples of the base samples (NumPy's
    default_rng(SEED), chunks of 100 resamples vectorised) with the
    percentile 95% interval (np.quantile, linear: the same rule as GSL's
    gsl_stats_quantile_from_sorted_data).
  Prints the best and the median of T timings in CPU seconds
  (time.process_time: this process, all its threads), the model
  evaluations and the point estimates (S1 and ST per factor and output, to
  compare with phytocal's; the intervals come from other random numbers).

emcee: emcee's EnsembleSampler (stretch move, a = 2) on NIST Misra1a's
marginal posterior of (b1, b2) with flat priors, s2 integrated out:
  log p = -(n0 + n)/2 log(n0 var0 + SS(b)),  SS = sum (y - b1 (1 - exp(-b2 x)))^2
(the posterior phytocal's stretch sampler draws (b1, b2) from while it
samples s2 from its full conditional; tests/realdata/test_mcmc_nist.c checks
the two agree), WALKERS walkers x STEPS steps from the fit's values
(perturbed by 1e-3 relative), seeded.  Times run_mcmc alone (seconds, wall
and CPU) and prints the number of log-posterior calls it made.
"""
import sys
import time

import numpy as np


def saltelli(args):
    base_path, n, k, R, seed = args[0], int(args[1]), int(args[2]), int(args[3]), int(args[4])
    repeat = int(args[args.index("--repeat") + 1]) if "--repeat" in args else 3
    base = np.fromfile(base_path, dtype=np.float64).reshape(n, 2 * k)
    lo, hi = -np.pi, np.pi

    def study():
        A, B = base[:, :k], base[:, k:]
        # the design: A, B and A_B^i (A with column i from B), M = N (k + 2) points
        X = np.empty((k + 2, n, k))
        X[0], X[1] = A, B
        for i in range(k):
            X[2 + i] = A
            X[2 + i, :, i] = B[:, i]
        P = lo + (hi - lo) * X
        f = np.sin(P[..., 0]) + 7.0 * np.sin(P[..., 1]) ** 2 + 0.1 * P[..., 2] ** 4 * np.sin(P[..., 0])
        # phytocal's five outputs of this config: the cost, the data set's mean
        # prediction, and its series (the prediction at each of the three
        # observations: f, the expression does not depend on x)
        outputs = {"cost": 1.5 * f * f, "mean": f, "y@1": f, "y@2": f, "y@3": f}
        series = ["y@1", "y@2", "y@3"]

        def est(a, b, ab):
            # a, b: (..., m); ab: (k, ..., m); the numerators and the variance
            mean = (a.sum(-1) + b.sum(-1)) / (2 * a.shape[-1])
            a = a - mean[..., None]
            b = b - mean[..., None]
            ab = ab - mean[..., None]
            var = ((a * a).sum(-1) + (b * b).sum(-1)) / (2 * a.shape[-1])
            return (b * (ab - a)).mean(-1), ((a - ab) ** 2).mean(-1) / 2, var

        rng = np.random.default_rng(seed)
        point = {name: est(Y[0], Y[1], Y[2:]) for name, Y in outputs.items()}
        boot = {name: ([], [], []) for name in outputs}
        for c in range(0, R, 100):
            # the resamples of this chunk, shared by all outputs (as phytocal's)
            idx = rng.integers(0, n, size=(min(100, R - c), n))
            for name, Y in outputs.items():
                for lst, v in zip(boot[name], est(Y[0][idx], Y[1][idx], Y[2:][:, idx])):
                    lst.append(v)
        res = {}
        for name in outputs:
            n1, nt, var = point[name]
            b1, bt, bv = (np.concatenate(v, axis=-1) for v in boot[name])
            res[name] = (n1 / var, nt / var, np.quantile(b1 / bv, [0.025, 0.975], axis=1),
                         np.quantile(bt / bv, [0.025, 0.975], axis=1))
        # the series summary: sum_t V_t S_t / sum_t V_t on the same resamples
        n1 = sum(point[t][0] for t in series)
        nt = sum(point[t][1] for t in series)
        var = sum(point[t][2] for t in series)
        b1 = sum(np.concatenate(boot[t][0], axis=-1) for t in series)
        bt = sum(np.concatenate(boot[t][1], axis=-1) for t in series)
        bv = sum(np.concatenate(boot[t][2], axis=-1) for t in series)
        res["summary"] = (n1 / var, nt / var, np.quantile(b1 / bv, [0.025, 0.975], axis=1),
                          np.quantile(bt / bv, [0.025, 0.975], axis=1))
        return res

    times, walls = [], []
    for _ in range(repeat):
        w0, t0 = time.perf_counter(), time.process_time()
        res = study()
        times.append(time.process_time() - t0)
        walls.append(time.perf_counter() - w0)
    best = min(range(repeat), key=lambda r: times[r])
    print(f"numpy_saltelli_time: {times[best]:.6f} s (best of {repeat}; median {sorted(times)[repeat // 2]:.6f})")
    print(f"numpy_saltelli_wall: {walls[best]:.6f} s (wall of the best run; best wall {min(walls):.6f})")
    print(f"numpy_saltelli_evaluations: {n * (k + 2)}")
    for name, (s1, st, ci1, cit) in res.items():
        for i in range(k):
            print(f"numpy_S1_{name}_{i + 1}: {s1[i]:.17g} [{ci1[0, i]:.6f}, {ci1[1, i]:.6f}]")
            print(f"numpy_ST_{name}_{i + 1}: {st[i]:.17g} [{cit[0, i]:.6f}, {cit[1, i]:.6f}]")


def run_emcee(args):
    import emcee

    csv, var0, n0, b1, b2, nw, steps = args[0], float(args[1]), float(args[2]), float(args[3]), float(args[4]), \
        int(args[5]), int(args[6])
    x, y = np.loadtxt(csv, delimiter=",", skiprows=1, unpack=True)
    n = len(y)
    calls = [0]

    def logp(b):
        calls[0] += 1
        ss = np.sum((y - b[0] * (1 - np.exp(-b[1] * x))) ** 2)
        return -0.5 * (n0 + n) * np.log(n0 * var0 + ss)

    rng = np.random.default_rng(42)
    p0 = np.array([b1, b2]) * (1 + 1e-3 * rng.standard_normal((nw, 2)))
    s = emcee.EnsembleSampler(nw, 2, logp)
    s.random_state = np.random.RandomState(42).get_state()
    w0, c0 = time.perf_counter(), time.process_time()
    s.run_mcmc(p0, steps, progress=False)
    wall, cpu = time.perf_counter() - w0, time.process_time() - c0
    flat = s.get_chain(discard=steps // 2).reshape(-1, 2)
    print(f"emcee_time: {wall:.6f} s (wall; CPU {cpu:.6f} s)")
    print(f"emcee_log_posterior_calls: {calls[0]}")
    print(f"emcee_acceptance: {np.mean(s.acceptance_fraction):.3f}")
    print(f"emcee_b1_median: {np.median(flat[:, 0]):.8g}")
    print(f"emcee_b2_median: {np.median(flat[:, 1]):.8g}")


if __name__ == "__main__":
    if len(sys.argv) < 2 or sys.argv[1] not in ("saltelli", "emcee"):
        sys.exit(__doc__)
    (saltelli if sys.argv[1] == "saltelli" else run_emcee)(sys.argv[2:])
