#!/usr/bin/env python3
"""Generates the bundled soil-probe example (synthetic, project-authored).

A 1 m x 1 m plot, 3 m deep, of a uniform sandy clay loam (Rhizomorph Fig. 7:
capacity c = 75, permeability p = 0.033 m/h), initially at a fill level of
w/c = 4e-4 (w = 0.03 m3/m3).  A sprinkler waters the central 0.4 m x 0.4 m
patch at 5 mm/h for the first 3 hours.  Six soil-moisture probes, placed by
GPS (latitude and longitude strings) around a georeferenced corner at
43.6481 N, 79.3832 W, read the volumetric water content every hour for 36 h.

1. probes.csv:   id, lat, lon, depth (m), sigma (m3/m3)
2. readings.csv: time (h), probe, theta (m3/m3): the model of Rhizomorph §6
   (eqs. 25-31) as phytocal discretises it (model/soil.h: finite volumes,
   harmonic-mean face permeability, Lax-Wendroff gravity, absorbing bottom in
   the authors' i^2 form) computed by an implementation independent of
   phytocal's (NumPy array slicing), trilinearly interpolated at the probes,
   plus Gaussian noise of sd 0.002 m3/m3 with a fixed seed.

Run with Debian's system python3 (needs python3-numpy):
    /usr/bin/python3 measurements/examples/soil_probe/generate.py
The files it writes are committed; re-running reproduces them exactly.
"""
import math
import os

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))

NX, NY, NZ, DX = 10, 10, 30, 0.1          # voxels, m
C_TRUE, P_TRUE = 75.0, 0.033              # capacity, permeability (m/h)
FILL0 = 4e-4                              # initial w/c
F_DIFF, F_GRAV = 1.0, 1.0
DT = 0.05                                 # h
RAIN = dict(start=0.0, end=3.0, rate=0.005, x0=0.3, x1=0.7, y0=0.3, y1=0.7)
ABSORB_WIDTH = 5
HOURS = 36
NOISE_SD = 0.002
LAT0, LON0 = 43.6481, -79.3832            # the grid's west-south corner
# probe id, x (east, m), y (north, m), depth (m)
PROBES = [("P1", 0.50, 0.50, 0.10), ("P2", 0.50, 0.50, 0.30), ("P3", 0.50, 0.50, 0.55),
          ("P4", 0.50, 0.50, 0.90), ("P5", 0.20, 0.45, 0.30), ("P6", 0.85, 0.80, 0.20)]


def harmonic(a, b):
    s = a + b
    return np.where((a > 0) & (b > 0), 2 * a * b / np.where(s > 0, s, 1), 0.0)


def step(w, p, ic, h):
    """One forward-Euler step of the conservative scheme, blocking walls."""
    lvl = w * ic
    dw = np.zeros_like(w)
    for axis in range(3):              # w[k, j, i]: axis 0 = z, 1 = y, 2 = x
        lo = [slice(None)] * 3
        hi = [slice(None)] * 3
        lo[axis] = slice(0, -1)
        hi[axis] = slice(1, None)
        lo, hi = tuple(lo), tuple(hi)
        kf = harmonic(p[lo], p[hi])
        flux = F_DIFF * kf * (lvl[hi] - lvl[lo]) / DX**2   # into lo from hi
        dw[lo] += flux
        dw[hi] -= flux
    # gravity, Lax-Wendroff on q = f_grav p w through z faces (from k+1 down to k)
    q = F_GRAV * p * w
    kz = harmonic(p[:-1], p[1:])
    g = np.where(kz > 0, 0.5 * (q[1:] + q[:-1]) - h * F_GRAV / (2 * DX) * kz * (q[:-1] - q[1:]), 0.0)
    dw[:-1] += g / DX
    dw[1:] -= g / DX
    return w + h * dw


def rain(w, t, h):
    lo, hi = max(t, RAIN["start"]), min(t + h, RAIN["end"])
    if hi <= lo:
        return
    dw = RAIN["rate"] * (hi - lo) / DX
    xc = (np.arange(NX) + 0.5) * DX
    yc = (np.arange(NY) + 0.5) * DX
    inside = ((yc[:, None] >= RAIN["y0"]) & (yc[:, None] < RAIN["y1"]) &
              (xc[None, :] >= RAIN["x0"]) & (xc[None, :] < RAIN["x1"]))
    w[NZ - 1][inside] += dw


def absorb_factors(h):
    f = np.ones(NZ)
    for i in range(ABSORB_WIDTH):      # bottom face only, k = i
        a = 1.0 - math.exp(-(i * i) / (0.2 * ABSORB_WIDTH**2))
        f[i] *= a ** (h / DT)
    return f


def sample(w, x, y, z):
    pos = []
    for v, n in ((z, NZ), (y, NY), (x, NX)):
        fi = min(max(v / DX - 0.5, 0.0), n - 1.0)
        i0 = int(math.floor(fi))
        i1 = min(i0 + 1, n - 1)
        pos.append((i0, i1, fi - i0))
    (k0, k1, tz), (j0, j1, ty), (i0, i1, tx) = pos
    val = 0.0
    for kk, wz in ((k0, 1 - tz), (k1, tz)):
        for jj, wy in ((j0, 1 - ty), (j1, ty)):
            for ii, wx in ((i0, 1 - tx), (i1, tx)):
                val += wz * wy * wx * w[kk, jj, ii]
    return val


def latlon(east, north):
    """WGS84 offsets from the corner (exact to ~1e-7 relative at 1 m)."""
    a, f = 6378137.0, 1 / 298.257223563
    e2 = f * (2 - f)
    phi = math.radians(LAT0)
    s2 = math.sin(phi) ** 2
    m = a * (1 - e2) / (1 - e2 * s2) ** 1.5          # meridian radius
    n = a / math.sqrt(1 - e2 * s2)                   # prime vertical radius
    return LAT0 + math.degrees(north / m), LON0 + math.degrees(east / (n * math.cos(phi)))


def dms(value, pos, neg):
    return "%.9f %s" % (abs(value), pos if value >= 0 else neg)


def main():
    p = np.full((NZ, NY, NX), P_TRUE)
    ic = np.full((NZ, NY, NX), 1.0 / C_TRUE)
    w = np.full((NZ, NY, NX), FILL0 * C_TRUE)
    damp = absorb_factors(DT)[:, None, None]
    rng = np.random.default_rng(20261121)
    rows = []
    t = 0.0
    steps_per_hour = int(round(1.0 / DT))
    for hour in range(HOURS + 1):
        if hour > 0:
            for _ in range(steps_per_hour):
                w = step(w, p, ic, DT)
                rain(w, t, DT)
                w *= damp
                t += DT
        if hour == 0:
            continue
        for pid, x, y, depth in PROBES:
            rows.append((hour, pid, sample(w, x, y, NZ * DX - depth)))
    with open(os.path.join(HERE, "probes.csv"), "w") as f:
        f.write("# Six soil-moisture probes placed by GPS (WGS84); depth below the surface (m);\n")
        f.write("# sigma: the probe's standard deviation (m3/m3).  Written by generate.py.\n")
        f.write("id,lat,lon,depth,sigma\n")
        for pid, x, y, depth in PROBES:
            lat, lon = latlon(x, y)
            f.write('%s,%s,%s,%.2f,%.3f\n' % (pid, dms(lat, "N", "S"), dms(lon, "E", "W"), depth, NOISE_SD))
    with open(os.path.join(HERE, "readings.csv"), "w") as f:
        f.write("# Hourly probe readings, volumetric water content (m3/m3), sprinkler on for t in [0, 3) h.\n")
        f.write("# Written by generate.py (true p = %g m/h, c = %g, noise sd %g).\n" % (P_TRUE, C_TRUE, NOISE_SD))
        f.write("time_h,probe,theta\n")
        for hour, pid, val in rows:
            f.write("%d,%s,%.5f\n" % (hour, pid, val + rng.normal(0.0, NOISE_SD)))
    print("wrote %d readings of %d probes" % (len(rows), len(PROBES)))


if __name__ == "__main__":
    main()
