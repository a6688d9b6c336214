#!/usr/bin/python3
"""Compares the SPH fluid pressure round the oscillating plate with potential flow.

Input: the per-particle fit written by `thin_wall_2d --scene plate --field-output f.csv`
(p_i = alpha_i w^2 X + beta_i w V + c_i, at the particle's mean position). Potential flow
gives p = -rho dphi/dt = rho w^2 X phi_U (phi_U: potential per unit plate velocity, from
plate_added_mass.py's finite volumes), so alpha / rho should equal phi_U up to a constant.
Prints the scale s of the least-squares fit alpha/rho = s phi_U + c over bands of distance
from the plate (s = 1: potential flow), and the jump across the plate along it.
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plate_added_mass import potential_field  # noqa: E402


def scale_fit(alpha, phi):
    A = np.column_stack([phi, np.ones_like(phi)])
    (s, c), *_ = np.linalg.lstsq(A, alpha, rcond=None)
    return s


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("field_csv")
    ap.add_argument("--dp", type=float, required=True)
    ap.add_argument("--b", type=float, default=0.1)
    ap.add_argument("--L", type=float, default=0.4)
    ap.add_argument("--H", type=float, default=0.4)
    ap.add_argument("--rho", type=float, default=1000.0)
    ap.add_argument("--fv-cells", type=int, default=80, help="finite-volume cells per b")
    a = ap.parse_args()
    d = np.genfromtxt(a.field_csv, delimiter=",", names=True)
    phi, xc, yc = potential_field(a.b, a.L, a.H, a.fv_cells)
    h = a.b / a.fv_cells
    i = np.clip(np.floor((d["x"] + a.L / 2) / h).astype(int), 0, len(xc) - 1)
    j = np.clip(np.floor((d["y"] + a.H / 2) / h).astype(int), 0, len(yc) - 1)
    pot = phi[j, i]
    alpha = d["alpha"] / a.rho
    half = a.b / 2
    # Distance to the plate segment x = 0, |y| <= b/2.
    dist = np.hypot(d["x"], np.maximum(np.abs(d["y"]) - half, 0.0))
    print(f"all particles: alpha/rho = s phi_U + c with s = {scale_fit(alpha, pot):.3f} ({len(alpha)} particles)")
    edges = [0, 1, 2, 3, 5, 8, 12, 20, 40]
    for lo, hi in zip(edges[:-1], edges[1:]):
        m = (dist >= lo * a.dp) & (dist < hi * a.dp)
        if m.sum() > 5:
            print(f"  distance {lo:2d}-{hi:2d} dp: s = {scale_fit(alpha[m], pot[m]):.3f} ({m.sum()} particles)")
    for name, m in (("beside the plate (|y| < b/2)", np.abs(d["y"]) < half), ("beyond the tips (|y| > b/2)", np.abs(d["y"]) >= half)):
        for lo, hi in ((0, 3), (3, 40)):
            mm = m & (dist >= lo * a.dp) & (dist < hi * a.dp)
            print(f"  {name}, {lo}-{hi} dp: s = {scale_fit(alpha[mm], pot[mm]):.3f} ({mm.sum()} particles)")
    if "vx_per_V" in d.dtype.names:
        gy, gx = np.gradient(phi, h)
        u = np.stack([gx[j, i], gy[j, i]], axis=1)
        v = np.stack([d["vx_per_V"], d["vy_per_V"]], axis=1)
        print("velocity in phase with the plate's, SPH against grad phi_U: scale s (v = s u), by distance")
        for lo, hi in zip(edges[:-1], edges[1:]):
            m = (dist >= lo * a.dp) & (dist < hi * a.dp)
            if m.sum() > 5:
                s_v = (v[m] * u[m]).sum() / (u[m] * u[m]).sum()
                print(f"  distance {lo:2d}-{hi:2d} dp: s = {s_v:.3f}, |v| mean {np.linalg.norm(v[m], axis=1).mean():.3f}, "
                      f"|u| mean {np.linalg.norm(u[m], axis=1).mean():.3f}")
        # Flux per unit plate speed through the plate's line beyond its tips: the two particle
        # columns beside it (|x| < dp, |y| > b/2) averaged; continuity says b.
        m = (np.abs(d["x"]) < a.dp) & (np.abs(d["y"]) > half)
        print(f"flux round the tips per unit plate speed: SPH {v[m, 0].sum() * a.dp / 2:.4f} m, potential "
              f"{u[m, 0].sum() * a.dp / 2:.4f} m (plate width {a.b} m)")
        # The same through the plate itself (|y| < b/2): the plate's own sweep, b.
        m = (np.abs(d["x"]) < a.dp) & (np.abs(d["y"]) < half)
        print(f"flux through the plate's span per unit plate speed: SPH {v[m, 0].sum() * a.dp / 2:.4f} m, potential "
              f"{u[m, 0].sum() * a.dp / 2:.4f} m")
        for xc in (2, 5, 10):
            m = (np.abs(np.abs(d["x"]) - xc * a.dp) < a.dp / 2) & (np.abs(d["y"]) < 4 * half)
            vv = np.abs(v[m, 0]).sum() * a.dp / 2
            uu = np.abs(u[m, 0]).sum() * a.dp / 2
            print(f"  |v_x| integrated over lines x = +-{xc} dp: SPH {vv:.4f}, potential {uu:.4f}")
    print("first column each side (|x| < dp): y/a, jump SPH (left - right), potential, ratio")
    left = (d["x"] < 0) & (d["x"] > -a.dp)
    right = (d["x"] > 0) & (d["x"] < a.dp)
    cst = np.mean(alpha - pot)  # common constant (irrelevant to the jump)
    for y0 in np.arange(-half - 2 * a.dp, half + 2 * a.dp, a.dp):
        ml = left & (d["y"] >= y0) & (d["y"] < y0 + a.dp)
        mr = right & (d["y"] >= y0) & (d["y"] < y0 + a.dp)
        if ml.any() and mr.any():
            js = alpha[ml].mean() - alpha[mr].mean()
            jp = pot[ml].mean() - pot[mr].mean()
            print(f"{(y0 + a.dp / 2) / half:+6.2f} {js:9.5f} {jp:9.5f} {js / jp:7.3f}")
    del cst


if __name__ == "__main__":
    main()
