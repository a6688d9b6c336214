#!/usr/bin/python3
"""Fits the thin_wall_2d plate scene's force to F = alpha w^2 X + beta w V + const over whole
periods after the first and prints alpha and beta against the added mass m = rho pi (b/2)^2
(times the box's potential-flow ratio, see plate_added_mass.py).

For harmonic motion X'' = -w^2 X, so an ideal added mass m gives F = -m X'' = m w^2 X:
alpha / m is the in-phase (inertia) coefficient, beta / m the part in phase with the velocity
(damping: viscous and vortex-shedding drag, numerical dissipation)."""
import argparse
import numpy as np


def fit(csv, b, period, rho=1000.0, box_ratio=1.0, skip_periods=1.0):
    data = np.genfromtxt(csv, delimiter=",", names=True)
    t, f, x, v = data["time"], data["force_x"], data["wall_x"], data["wall_vx"]
    w = 2 * np.pi / period
    n_periods = np.floor((t[-1] - skip_periods * period) / period + 1e-6)
    keep = (t >= skip_periods * period) & (t <= (skip_periods + n_periods) * period)
    M = np.column_stack([w * w * x[keep], w * v[keep], np.ones(keep.sum())])
    (alpha, beta, mean), *_ = np.linalg.lstsq(M, f[keep], rcond=None)
    m = rho * np.pi * (b / 2) ** 2 * box_ratio
    amplitude = np.max(np.abs(x[keep])) * w * w * m
    residual = f[keep] - M @ np.array([alpha, beta, mean])
    return alpha / m, beta / m, np.sqrt(np.mean(residual ** 2)) / amplitude, data


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("csv", nargs="+")
    ap.add_argument("--b", type=float, default=0.1)
    ap.add_argument("--period", type=float, default=0.5)
    ap.add_argument("--box-ratio", type=float, default=1.0)
    a = ap.parse_args()
    for csv in a.csv:
        cin, cout, noise, data = fit(csv, a.b, a.period, box_ratio=a.box_ratio)
        print(f"{csv}: in-phase {cin:.3f}, velocity-phase {cout:.3f}, residual rms {noise:.3f} of m A w^2; "
              f"corrections {int(data['corrections'][-1])} leaks {int(data['leaks'][-1])}")


if __name__ == "__main__":
    main()
