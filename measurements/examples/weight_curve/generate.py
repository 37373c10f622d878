#!/usr/bin/env python3
"""Generates the bundled weight-curve example (synthetic, project-authored).

1. seedling.csv: a tomato-like seedling as a phytocal native plant graph
   (metres): a stem of 12 segments, 4 leaves, each a petiole of 3 segments and
   a blade of a midrib of 6 segments with a pair of side veins on every midrib
   segment (3 segments each).  Blade segments are leaf segments.
2. balance.csv: the seedling's mass on a balance every 5 minutes for 48 hours
   (577 weighings), computed from the wilting paper's water model in
   phytocal's default physical setting (conductance: poiseuille) by an
   implementation independent of phytocal's (NumPy's symmetric eigensolver),
   plus Gaussian noise of sd 0.01 g (the balance), with a fixed seed:
       mass(t) = dry_mass + W(t),  W(t) = 1^T exp(S t) theta0
   true values: delta = 2.0e-3 s-1 cm-2, initial water 12 g, dry mass 2.5 g.

Run with Debian's system python3 (needs python3-numpy):
    /usr/bin/python3 measurements/examples/weight_curve/generate.py
The files it writes are committed; re-running reproduces them exactly.
"""
import math
import os
import random

HERE = os.path.dirname(os.path.abspath(__file__))

TRUE_DELTA = 2.0e-3    # s-1 cm-2
TRUE_WATER = 12.0      # g
TRUE_DRY = 2.5         # g
NOISE_SD = 0.01        # g
STEP_MIN = 5.0         # minutes between weighings
HOURS = 48.0


def seedling():
    """Segments as dicts: parent, radius (m), head, tail (m), leaf flag."""
    segs = []

    def add(parent, head, direction, length, radius, leaf):
        norm = math.sqrt(sum(c * c for c in direction))
        tail = tuple(h + length * c / norm for h, c in zip(head, direction))
        segs.append(dict(parent=parent, radius=radius, head=head, tail=tail, leaf=leaf))
        return len(segs) - 1

    # stem: 12 segments of 2 cm, radius tapering 2.0 mm -> 1.0 mm
    stem = []
    head = (0.0, 0.0, 0.0)
    parent = -1
    for i in range(12):
        r = 0.0020 - 0.0010 * i / 11
        parent = add(parent, head, (0, 0, 1), 0.02, r, 0)
        head = segs[parent]['tail']
        stem.append(parent)
    # four leaves at stem segments 3, 6, 9, 11, rotating by 90 degrees
    for k, node in enumerate((3, 6, 9, 11)):
        ang = k * math.pi / 2
        out = (math.cos(ang), math.sin(ang), 0.6)
        p = stem[node]
        head = segs[p]['tail']
        for _ in range(3):                      # petiole, 1.5 cm each
            p = add(p, head, out, 0.015, 0.0008, 0)
            head = segs[p]['tail']
        for m in range(6):                      # midrib, 1.2 cm each
            p = add(p, head, out, 0.012, 0.0006 - 0.00005 * m, 1)
            mid_tail = segs[p]['tail']
            for side in (-1, 1):                # a pair of side veins
                sd = (out[0] - side * out[1], out[1] + side * out[0], 0.2)
                q, h = p, segs[p]['head']
                for _ in range(3):
                    q = add(q, h, sd, 0.006, 0.0003, 1)
                    h = segs[q]['tail']
            head = mid_tail
    return segs


def write_graph(segs, path):
    with open(path, 'w') as f:
        f.write('# unit: m\n')
        f.write('# project-authored tomato-like seedling for the weight-curve example '
                '(measurements/examples/weight_curve/generate.py)\n')
        f.write('id,parent,radius,length,x_head,y_head,z_head,x_tail,y_tail,z_tail,leaf,fixed\n')
        for i, s in enumerate(segs):
            length = math.dist(s['head'], s['tail'])
            f.write('%d,%d,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%d,%d\n' % (
                i, s['parent'], s['radius'], length, *s['head'], *s['tail'], s['leaf'],
                1 if s['parent'] < 0 else 0))


def water_matrix(segs, delta, mu_mpas=0.89):
    """The wilting paper's water model in phytocal's physical default
    (model/water.h, PHC_WATER_POISEUILLE), written independently with NumPy:
    cm, g, s; Poiseuille half pipes in series; pressure K*theta/V with
    K = R T / M_w at 298.15 K in Ba cm^3/g; leaf loss l = delta * r * h.
    theta' = S theta with S = K R D^-1 - D_l (D = diag V).  Returns the
    symmetric transport part T = K D^-1/2 R D^-1/2, the loss l and V."""
    import numpy as np
    n = len(segs)
    r = np.array([s['radius'] for s in segs]) * 100.0
    h = np.array([math.dist(s['head'], s['tail']) for s in segs]) * 100.0
    leaf = np.array([s['leaf'] for s in segs], dtype=float)
    V = math.pi * r * r * h
    mu = mu_mpas * 1e-2                                   # poise
    g = math.pi * r ** 4 / (8.0 * mu * h)                 # cm^3/(s Ba) per segment
    K = 8.314462618 * 298.15 / 18.01528 * 1e7             # Ba cm^3 / g
    R = np.zeros((n, n))
    for i, s in enumerate(segs):
        j = s['parent']
        if j < 0:
            continue
        w = 2.0 * g[i] * g[j] / (g[i] + g[j])             # half pipes in series
        R[i, j] += w
        R[j, i] += w
        R[i, i] -= w
        R[j, j] -= w
    sq = np.sqrt(V)
    T = K * R / np.outer(sq, sq)
    return T, delta * r * h * leaf, V


def unit_response(T, ell, V, times_s):
    """W(t)/W(0) at the given times from theta(0) proportional to V.

    In the symmetric form phi = D^-1/2 theta, phi' = (T - D_l) phi.  T is
    huge (pressure equalises within microseconds) and exactly singular along
    v = sqrt(V)/|sqrt(V)|, so a dense eigensolver would lose the slow
    eigenvalue in round-off (its absolute error is ~1e-16 |T|).  Deflate
    instead: in an orthonormal basis (Householder H, H e1 = v) the first row
    and column of H T H are exactly zero, leaving
        H (T - D_l) H = [[a, b^T], [b, M]],  a = -v^T D_l v,
    and the slow eigenvalue solves lam = a - b^T (M - lam)^-1 b (fixed-point
    steps, each an accurate solve since M - lam is far from singular).
    theta(0) is along v, so the fast modes carry a weight of order
    |b|^2/|M|^2 (~1e-20) and decay within microseconds:
        W(t)/W(0) = exp(lam t) / (1 + |(M - lam)^-1 b|^2).
    Independent of phytocal's BDF6 and eigen evaluators."""
    import numpy as np
    n = len(V)
    sq = np.sqrt(V)
    v = sq / np.linalg.norm(sq)
    u = v.copy()
    u[0] -= 1.0
    H = np.eye(n) - 2.0 * np.outer(u, u) / (u @ u)
    B = H @ T @ H
    B[0, :] = 0.0
    B[:, 0] = 0.0
    B -= H @ np.diag(ell) @ H
    a, b, M = B[0, 0], B[1:, 0], B[1:, 1:]
    lam = a
    for _ in range(5):
        z = np.linalg.solve(M - lam * np.eye(n - 1), b)
        lam = a - b @ z
    weight = 1.0 / (1.0 + z @ z)
    return weight * np.exp(lam * np.asarray(times_s))


def main():
    import numpy as np
    segs = seedling()
    write_graph(segs, os.path.join(HERE, 'seedling.csv'))
    T, ell, V = water_matrix(segs, TRUE_DELTA)
    # weighings every 5 min for 48 h; an irrigation of 6 g right after 24 h
    n = int(HOURS * 60 / STEP_MIN) + 1
    t_h = np.arange(n) * STEP_MIN / 60.0
    cut = int(24 * 60 / STEP_MIN)                  # last weighing before watering
    u = unit_response(T, ell, V, np.arange(n) * STEP_MIN * 60.0)
    water = TRUE_WATER * u[:cut + 1]
    w_after = water[-1] + 6.0                      # watered to this much
    u2 = u[:n - cut - 1]                           # the same response, restarted
    water = np.concatenate([water, w_after * u2])
    rng = random.Random(20261121)
    with open(os.path.join(HERE, 'balance.csv'), 'w') as f:
        f.write('# SYNTHETIC balance curve of seedling.csv, made by generate.py: wilting-paper water\n')
        f.write('# model (physical default), delta = %g s-1 cm-2, initial water %g g, dry mass %g g,\n'
                % (TRUE_DELTA, TRUE_WATER, TRUE_DRY))
        f.write('# watered with 6 g after 24 h, Gaussian balance noise sd %g g (seed 20261121)\n' % NOISE_SD)
        f.write('time_h,mass_g\n')
        for t, w in zip(t_h, water):
            f.write('%.4f,%.4f\n' % (t, TRUE_DRY + w + rng.gauss(0.0, NOISE_SD)))
    print('wrote seedling.csv (%d segments, %d leaf) and balance.csv (%d weighings); '
          'water left at 24 h: %.3f g of %.3f' % (len(segs), sum(s['leaf'] for s in segs), n,
                                                   water[cut], TRUE_WATER))


if __name__ == '__main__':
    main()
