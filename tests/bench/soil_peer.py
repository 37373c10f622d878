#!/usr/bin/python3
"""NumPy peer of the soil benchmark (tests/bench/bench_soil.c).

The same explicit water step as `transport` in model/soil.c (soil.h), for
the benchmark's soil only (water, no nutrients, all six faces BLOCK),
written with vectorised NumPy slicing and run with Debian's system python3:

    /usr/bin/python3 tests/bench/soil_peer.py N STEPS [--repeat R]

The grid is N^3 voxels of DX = 0.01 m, array axes (k, j, i) so that the
flat C-order index is i + N (j + N k) as in soil.h.  The initial state is
the one bench_soil.c builds:
  * two layers by the depth of the voxel centre below the top of the box,
    ((N - 1 - k) + 0.5) DX < (N / 2) DX: silt_loam (c 100, p 0.5 m/h) above,
    clay (c 10, p 0.0015 m/h) below (phc_soil_preset values);
  * w = c (0.3 + 0.2 m / 16), m = (7 i + 13 j + 29 k) mod 17;
  * f_diff = f_grav = 1, h = 0.5 * the stability limit (computed here with
    the formula of phc_soil_stable_dt, printed so the C side can compare).
One step (soil.h "Discretisation"):
  face permeability k_f = 2 a b / (a + b) (0 when a or b is 0, and 0 across
  the box faces); l = w / c (as w * (1/c));
  diffusion through each face F = k_f (l_neighbour - l_self);
  gravity on z faces, Lax-Wendroff on q = f_grav p w:
      G = (q_up + q_low)/2 - (h f_grav k_f / (2 dx)) (q_low - q_up)   (k_f > 0)
  w_new = w + h f_diff / dx^2 (sum of F over the six faces)
            + h / dx (G_top - G_bottom).
The face sums are taken in the C kernel's order (+x, -x, +y, -y, +z, -z)
so the two results agree to round-off.

Prints `name: value unit` lines (prefix numpy_): voxel updates per second
(best of R timings of STEPS steps, each from the initial state), the step h,
and two checksums of the final state: sum(w * wt) and sum((w - w0) * wt)
with wt = 1 + (q mod 97) + k (q the flat index), summed with math.fsum.
"""
import argparse
import math
import sys
import time

import numpy as np

DX = 0.01
SILT_LOAM = (100.0, 0.5)  # capacity, permeability (m/h): model/soil.c presets
CLAY = (10.0, 0.0015)
F_DIFF = 1.0
F_GRAV = 1.0


def harmonic(a, b):
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where((a > 0) & (b > 0), 2 * a * b / (a + b), 0.0)


def build(N):
    k = np.arange(N).reshape(N, 1, 1)
    j = np.arange(N).reshape(1, N, 1)
    i = np.arange(N).reshape(1, 1, N)
    depth = ((N - 1 - k) + 0.5) * DX
    top = np.broadcast_to(depth < (N // 2) * DX, (N, N, N))
    c = np.where(top, SILT_LOAM[0], CLAY[0])
    p = np.where(top, SILT_LOAM[1], CLAY[1])
    m = (7 * i + 13 * j + 29 * k) % 17
    fill = 0.3 + 0.2 * m / 16.0
    w = c * fill
    return c, p, np.ascontiguousarray(w)


def faces(p):
    """Interior face permeabilities, padded with a zero face at both box
    walls: Kx[k, j, i] is the face between voxels i-1 and i (i = 0..N)."""
    N = p.shape[0]
    Kx = np.zeros((N, N, N + 1))
    Ky = np.zeros((N, N + 1, N))
    Kz = np.zeros((N + 1, N, N))
    Kx[:, :, 1:-1] = harmonic(p[:, :, :-1], p[:, :, 1:])
    Ky[:, 1:-1, :] = harmonic(p[:, :-1, :], p[:, 1:, :])
    Kz[1:-1, :, :] = harmonic(p[:-1, :, :], p[1:, :, :])
    return Kx, Ky, Kz


def stable_dt(c, p, Kx, Ky, Kz):
    s = Kx[:, :, 1:] + Kx[:, :, :-1]
    s += Ky[:, 1:, :]
    s += Ky[:, :-1, :]
    s += Kz[1:, :, :]
    s += Kz[:-1, :, :]
    bb = F_DIFF * s / (c * (DX * DX))
    g = F_GRAV * p / DX
    a = g * g
    with np.errstate(divide="ignore"):
        h = 2.0 / (bb + np.sqrt(bb * bb + 4 * a))
    return float(np.min(h[p > 0]))


class Stepper:
    def __init__(self, c, p, Kx, Ky, Kz, h):
        N = c.shape[0]
        self.ic = 1.0 / c
        self.ap = F_GRAV * p
        self.kx = Kx[:, :, 1:-1]
        self.ky = Ky[:, 1:-1, :]
        self.kz = Kz[1:-1, :, :]
        self.zmask = self.kz > 0
        self.cd = h * F_DIFF / (DX * DX)
        self.cg = h / DX
        self.lwk = (h * F_GRAV / (2 * DX)) * self.kz
        self.Fx = np.zeros((N, N, N + 1))
        self.Fy = np.zeros((N, N + 1, N))
        self.Fz = np.zeros((N + 1, N, N))
        self.Gz = np.zeros((N + 1, N, N))

    def step(self, w):
        Fx, Fy, Fz, Gz = self.Fx, self.Fy, self.Fz, self.Gz
        l = w * self.ic
        np.multiply(self.kx, l[:, :, 1:] - l[:, :, :-1], out=Fx[:, :, 1:-1])
        np.multiply(self.ky, l[:, 1:, :] - l[:, :-1, :], out=Fy[:, 1:-1, :])
        np.multiply(self.kz, l[1:, :, :] - l[:-1, :, :], out=Fz[1:-1, :, :])
        # sum over faces in the C order: +x, -x, +y, -y, +z, -z
        s = Fx[:, :, 1:] - Fx[:, :, :-1]
        s += Fy[:, 1:, :]
        s -= Fy[:, :-1, :]
        s += Fz[1:, :, :]
        s -= Fz[:-1, :, :]
        q = self.ap * w
        qlow, qup = q[:-1, :, :], q[1:, :, :]
        g = 0.5 * (qup + qlow) - self.lwk * (qlow - qup)
        Gz[1:-1, :, :] = np.where(self.zmask, g, 0.0)
        s *= self.cd
        grav = Gz[1:, :, :] - Gz[:-1, :, :]
        grav *= self.cg
        out = w + s
        out += grav
        return out


def checksums(w, w0):
    N = w.shape[0]
    q = np.arange(w.size)
    k = q // (N * N)
    wt = (1 + (q % 97) + k).astype(np.float64)
    return math.fsum((w.ravel() * wt).tolist()), math.fsum(((w - w0).ravel() * wt).tolist())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("N", type=int)
    ap.add_argument("steps", type=int)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    N, steps = a.N, a.steps
    c, p, w0 = build(N)
    Kx, Ky, Kz = faces(p)
    h = 0.5 * stable_dt(c, p, Kx, Ky, Kz)
    st = Stepper(c, p, Kx, Ky, Kz, h)
    best = math.inf
    for _ in range(a.repeat):
        w = w0.copy()
        t0 = time.perf_counter()
        for _ in range(steps):
            w = st.step(w)
        best = min(best, time.perf_counter() - t0)
    cs, dcs = checksums(w, w0)
    print(f"numpy_version: {np.__version__} (python {sys.version.split()[0]})")
    print(f"numpy_vups_{N}: {N ** 3 * steps / best:.6e} voxel/s (best of {a.repeat}, {steps} steps)")
    print(f"numpy_h_{N}: {h:.17g} h")
    print(f"numpy_checksum_{N}: {cs:.17g} 1")
    print(f"numpy_delta_checksum_{N}: {dcs:.17g} 1")
    return 0


if __name__ == "__main__":
    sys.exit(main())
