#!/usr/bin/python3
"""Fits the thin_wall_3d disk scene's force (CSV of `thin_wall_3d --scene disk --output`) to
F = alpha w^2 X + beta w V + const over a time window and prints alpha and beta against the
potential-flow added mass of a disk, (8/3) rho a^3 (docs/thin-leaflet.md, "3D").

For harmonic motion X'' = -w^2 X, an ideal added mass m gives F = -m X'' = m w^2 X: alpha / m
is the in-phase (inertia) coefficient, beta / m the part in phase with the velocity. A run of
the quarter disk (--quarter) reports the quarter's force: --symmetry 4 scales it to the disk."""
import argparse
import numpy as np


def fit(csv, radius, period, start, end, symmetry=1.0, rho=1000.0):
    # invalid_raise=False: a run still writing ends in a partial line, which is skipped
    data = np.genfromtxt(csv, delimiter=",", names=True, invalid_raise=False)
    t, f, x, v = data["time"], symmetry * data["fx"], data["X"], data["V"]
    w = 2 * np.pi / period
    keep = (t >= start * period - 1e-9) & (t <= end * period + 1e-9)
    if keep.sum() < 10:
        raise SystemExit(f"{csv}: only {keep.sum()} samples in [{start}, {end}] periods (the run ends at t = {t[-1]} s)")
    M = np.column_stack([w * w * x[keep], w * v[keep], np.ones(keep.sum())])
    (alpha, beta, mean), *_ = np.linalg.lstsq(M, f[keep], rcond=None)
    m = 8.0 / 3.0 * rho * radius ** 3
    amplitude = np.max(np.abs(x[keep])) * w * w * m
    residual = f[keep] - M @ np.array([alpha, beta, mean])
    return alpha / m, beta / m, np.sqrt(np.mean(residual ** 2)) / amplitude, data


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("csv", nargs="+")
    ap.add_argument("--radius", type=float, default=0.05, help="disk radius a (m)")
    ap.add_argument("--period", type=float, default=0.5, help="s")
    ap.add_argument("--start", type=float, default=1.0, help="fit window start (periods)")
    ap.add_argument("--end", type=float, default=2.0, help="fit window end (periods)")
    ap.add_argument("--symmetry", type=float, default=1.0, help="force factor (4 for --quarter runs)")
    a = ap.parse_args()
    for csv in a.csv:
        cin, cout, noise, data = fit(csv, a.radius, a.period, a.start, a.end, a.symmetry)
        print(f"{csv}: periods {a.start}-{a.end}: in-phase {cin:.3f}, velocity-phase {cout:.3f}, residual rms {noise:.3f} "
              f"of m A w^2; corrections {int(data['corrections'][-1])} leaks {int(data['leaks'][-1])} "
              f"lost {int(data['lost'][-1])}; {int(data['steps'][-1])} steps, {data['wall_s'][-1]:.0f} s wall")


if __name__ == "__main__":
    main()
