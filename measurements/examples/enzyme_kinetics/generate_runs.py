"""Writes enzyme_runs.csv: SYNTHETIC Michaelis-Menten initial rates of twelve
enzyme preparations (runs r01..r12), duplicate assays at the seven substrate
concentrations of enzyme.csv, for `phytocal fit enzyme_runs.yaml --each run`.

Each run draws its own Vmax (umol/min) and Km (mM) around 210 and 0.065; the
rates get Gaussian noise of sd 5 umol/min (pipetting and plate reader, the
sigma of enzyme_runs.yaml).  Seed 20261126.  Not measured data.

    /usr/bin/python3 generate_runs.py > enzyme_runs.csv

With an argument N, N runs instead of twelve (r001..rN, three digits or
more; the first twelve runs draw the same numbers as r01..r12): the larger
tables of the batch benchmark (tests/bench/bench_batch.c).

    /usr/bin/python3 generate_runs.py 240 > plate.csv
"""
import sys

import numpy as np

n_runs = int(sys.argv[1]) if len(sys.argv) > 1 else 12
width = 2 if n_runs < 100 else len(str(n_runs))
count = "twelve" if n_runs == 12 else str(n_runs)
rng = np.random.default_rng(20261126)
substrate = [0.02, 0.04, 0.06, 0.11, 0.22, 0.56, 1.10]
print(f"# SYNTHETIC Michaelis-Menten initial rates of {count} enzyme preparations, made by")
print("# generate_runs.py (seed 20261126): Vmax ~ 210 umol/min, Km ~ 0.065 mM per run,")
print("# duplicate assays, Gaussian noise sd 5 umol/min.  Not measured data.")
print("run,substrate_mM,rate_umol_min")
for k in range(1, n_runs + 1):
    vmax = 210.0 * np.exp(rng.normal(0.0, 0.15))
    km = 0.065 * np.exp(rng.normal(0.0, 0.25))
    for s in substrate:
        for _ in range(2):
            rate = vmax * s / (km + s) + rng.normal(0.0, 5.0)
            print(f"r{k:0{width}d},{s:.2f},{rate:.1f}")
