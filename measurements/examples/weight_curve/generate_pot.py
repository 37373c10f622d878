#!/usr/bin/env python3
"""Generates the potted-seedling example (synthetic, project-authored).

pot_balance.csv: the bundled seedling (seedling.csv, made by generate.py) in
a covered pot on a logging balance for 4 days, weighed every 10 minutes, with
ISO 8601 local timestamps (Europe/Berlin, summer: UTC+2).  Lights are on from
07:00 to 23:00 local time; by night the leaves lose a tenth of the day's
rate.  The pot's soil is a water store joined to the plant's root segment.
The columns PAR (umol m-2 s-1, 600 by day, 0 by night) and VPD (kPa) are
what a climate logger would write beside the balance.

The model is the wilting paper's water model with the authors' current
conductances (conductance: reference_2024: weight = the mean of
1e6 pi r^4 / (8 * 0.9 L), pressure 11.538 theta / V, r and L in cm), plus the
soil node of model/water_balance.h:
    theta' = S(t) theta, S = K R D^-1 - g(t) D_l,   W = sum theta,
    soil: pressure K theta_s / C, exchange q = k (theta_s / C - theta_0 / V_0)
written here independently of phytocal with SciPy: the state is carried
from weighing to weighing by scipy.linalg.expm(S * 600 s), one matrix for
the day and one for the night (the lights switch on the 10-minute grid).
The reference conductances keep the system only moderately stiff (fastest
rate 5.9e4 1/s), so expm's backward error (~1e-16 of the norm) moves W by
about 1e-6 relative over the 4 days, far below the noise; the physical
default (5.9e8 1/s) would not allow that.  Plant and soil start in
equilibrium (the same relative fill).  Gaussian noise of sd 0.02 g (the
balance), fixed seed.

True values: delta = 4.0e-3 s-1 cm-2, night_factor 0.10, total water at the
start 160 g, dry mass (pot, soil, plant) 310 g, capacity C = 150 g,
conductance k = 2.0e-4 g/s.

Run with Debian's system python3 (needs python3-numpy, python3-scipy):
    /usr/bin/python3 measurements/examples/weight_curve/generate_pot.py
The file it writes is committed; re-running reproduces it exactly.
"""
import csv
import datetime as dt
import math
import os
import random

HERE = os.path.dirname(os.path.abspath(__file__))

TRUE = dict(delta=4.0e-3, night_factor=0.10, water=160.0, dry=310.0, capacity=150.0,
            conductance=2.0e-4)
NOISE_SD = 0.02
STEP_MIN = 10.0
DAYS = 4.0
START_LOCAL = dt.datetime(2024, 6, 10, 9, 0, 0)   # 09:00 local, summer time
UTC_OFFSET_H = 2.0                                 # Europe/Berlin in June
DAY_START_H, DAY_END_H = 7.0, 23.0


def read_graph(path):
    """seedling.csv (phytocal native format, metres)."""
    rows = []
    with open(path) as f:
        lines = [l for l in f if not l.startswith('#')]
    for r in csv.DictReader(lines):
        rows.append(r)
    ids = {int(r['id']): i for i, r in enumerate(rows)}
    segs = []
    for r in rows:
        head = [float(r['x_head']), float(r['y_head']), float(r['z_head'])]
        tail = [float(r['x_tail']), float(r['y_tail']), float(r['z_tail'])]
        segs.append(dict(parent=ids[int(r['parent'])] if int(r['parent']) >= 0 else -1,
                         radius=float(r['radius']), length=float(r['length']),
                         leaf=int(r['leaf'])))
    return segs


def system(segs, p):
    """S without loss (K R D^-1, the soil node appended) and the loss area."""
    import numpy as np
    n = len(segs)
    r = np.array([s['radius'] for s in segs]) * 100.0          # cm
    h = np.array([s['length'] for s in segs]) * 100.0
    V = math.pi * r * r * h
    g = 1e6 * math.pi * r ** 4 / (8.0 * 0.9 * h)              # the authors' FlowRes
    K = 11.538249539485484                                    # their PRESS_CONST
    N = n + 1
    cap = np.append(V, p['capacity'])                         # theta / (pressure / K)
    A = np.zeros((N, N))                                      # flux = w (P_j - P_i)
    root = [i for i, s in enumerate(segs) if s['parent'] < 0][0]
    edges = [(i, s['parent'], 0.5 * (g[i] + g[s['parent']]))
             for i, s in enumerate(segs) if s['parent'] >= 0]
    edges.append((n, root, p['conductance'] / K))             # soil - root
    for i, j, w in edges:
        for a, b in ((i, j), (j, i)):
            A[a, b] += w * K / cap[b]
            A[a, a] -= w * K / cap[a]
    area = np.append(r * h * np.array([s['leaf'] for s in segs]), 0.0)
    return A, area, cap


def light(hour):
    return DAY_START_H <= hour < DAY_END_H


def main():
    import numpy as np
    from scipy.linalg import expm
    segs = read_graph(os.path.join(HERE, 'seedling.csv'))
    A, area, cap = system(segs, TRUE)
    theta = TRUE['water'] * cap / cap.sum()                    # equilibrium start
    step = STEP_MIN * 60.0
    times = np.arange(0.0, DAYS * 86400.0 + 1.0, step)
    E = {g: expm((A - np.diag(g * TRUE['delta'] * area)) * step)
         for g in (1.0, TRUE['night_factor'])}
    W = np.empty(len(times))
    for i, t in enumerate(times):
        W[i] = theta.sum()
        stamp = START_LOCAL + dt.timedelta(seconds=float(t))
        g = 1.0 if light(stamp.hour + stamp.minute / 60.0) else TRUE['night_factor']
        theta = E[g] @ theta
    rng = random.Random(20241125)
    path = os.path.join(HERE, 'pot_balance.csv')
    with open(path, 'w', newline='') as f:
        f.write('# SYNTHETIC potted seedling on a logging balance, made by generate_pot.py\n')
        f.write('# (true values in its docstring); local time Europe/Berlin (UTC+2 in June);\n')
        i24, i96 = int(round(24 * 60 / STEP_MIN)), len(times) - 1
        f.write(f'# noiseless water W(24 h) = {W[i24]:.10f} g, W(96 h) = {W[i96]:.10f} g\n')
        wr = csv.writer(f, lineterminator='\n')
        wr.writerow(['timestamp', 'mass_g', 'PAR', 'VPD'])
        for t, w in zip(times, W):
            stamp = START_LOCAL + dt.timedelta(seconds=float(t))
            hour = stamp.hour + stamp.minute / 60.0
            day = light(hour)
            par = 600.0 if day else 0.0
            vpd = 1.2 + 0.6 * math.sin(2 * math.pi * (hour - 9.0) / 24.0) if day else 0.4
            mass = TRUE['dry'] + w + rng.gauss(0.0, NOISE_SD)
            wr.writerow([stamp.strftime('%Y-%m-%dT%H:%M:%S'), f'{mass:.3f}', f'{par:.0f}',
                         f'{vpd:.3f}'])
    print(f'wrote {path}: {len(times)} weighings, water {W[0]:.3f} -> {W[-1]:.3f} g')


if __name__ == '__main__':
    main()
