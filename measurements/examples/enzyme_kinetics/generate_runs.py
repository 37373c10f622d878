"""Writes enzyme_runs.csv: SYNTHETIC Michaelis-Menten initial rates of twelve
enzyme preparations (runs r01..r12), duplicate assays at the seven substrate
concentrations of enzyme.csv, for `phytocal fit enzyme_runs.yaml --each run`.

Each run draws its own Vmax (umol/min) and Km (mM) around 210 and 0.065; the
rates get Gaussian noise of sd 5 umol/min (pipetting and plate reader, the
sigma of enzyme_runs.yaml).  Seed 20261126.  Not measured data.

    /usr/bin/python3 generate_runs.py > enzyme_runs.csv
"""
import numpy as np

rng = np.random.default_rng(20261126)
substrate = [0.02, 0.04, 0.06, 0.11, 0.22, 0.56, 1.10]
print("# SYNTHETIC Michaelis-Menten initial rates of twelve enzyme preparations, made by")
print("# generate_runs.py (seed 20261126): Vmax ~ 210 umol/min, Km ~ 0.065 mM per run,")
print("# duplicate assays, Gaussian noise sd 5 umol/min.  Not measured data.")
print("run,substrate_mM,rate_umol_min")
for k in range(1, 13):
    vmax = 210.0 * np.exp(rng.normal(0.0, 0.15))
    km = 0.065 * np.exp(rng.normal(0.0, 0.25))
    for s in substrate:
        for _ in range(2):
            rate = vmax * s / (km + s) + rng.normal(0.0, 5.0)
            print(f"r{k:02d},{s:.2f},{rate:.1f}")
