#!/usr/bin/python3
"""Plots for docs/thin-leaflet.md from thin_wall_2d CSV output:
  gap:   water levels either side of the wall over time (from particle counts)
  plate: force on the oscillating plate against the potential-flow added-mass force
  profile: the in-phase load along the plate per marker (from --marker-output) against the
           potential-flow jump 2 rho sqrt(a^2 - y^2)
Usage: plot_thin_wall.py gap OUT.png RUN.csv [RUN.csv ...]
       plot_thin_wall.py plate OUT.png --box-ratio R RUN.csv [RUN.csv ...]
       plot_thin_wall.py profile OUT.png --box-ratio R RUN.csv MARKERS.csv"""
import argparse
import os
import numpy as np
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt


def gap(args):
    fig, ax = plt.subplots(figsize=(7, 4))
    for path in args.csv:
        d = np.genfromtxt(path, delimiter=",", names=True)
        n = d["left_count"] + d["right_count"]
        # Each side is 0.5 m wide; the fluid's total area is (1.0 + 0.5) * 0.5 m^2.
        area = 0.75
        label = os.path.splitext(os.path.basename(path))[0]
        ax.plot(d["time"], d["left_count"] / n * area / 0.5, label=f"{label}: left")
        ax.plot(d["time"], d["right_count"] / n * area / 0.5, "--", label=f"{label}: right")
    ax.axhline(0.75, color="k", lw=0.5)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("water level (m)")
    ax.set_title("Gap of 0.1 m under a thin wall: levels 1.0 / 0.5 m equalise")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)


def plate(args):
    fig, ax = plt.subplots(figsize=(7, 4))
    for path in args.csv:
        d = np.genfromtxt(path, delimiter=",", names=True)
        w = 2 * np.pi / args.period
        m = 1000.0 * np.pi * (args.b / 2) ** 2 * args.box_ratio
        label = os.path.splitext(os.path.basename(path))[0]
        ax.plot(d["time"], d["force_x"], lw=0.6, label=f"{label}: SPH")
    ax.plot(d["time"], m * w * w * d["wall_x"], "k", lw=1.5, label="potential flow m w^2 X (box-corrected)")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("force on plate (N/m)")
    ax.set_title("Plate oscillating normal to itself")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)


def profile(args):
    run, markers = args.csv[0], args.csv[1]
    d = np.genfromtxt(run, delimiter=",", names=True)
    with open(markers) as f:
        s = np.array([float(h[1:]) for h in f.readline().strip().split(",")[1:]])
    mk = np.genfromtxt(markers, delimiter=",", skip_header=1)
    t, forces = mk[:, 0], mk[:, 1:]
    w = 2 * np.pi / args.period
    keep = t >= args.period
    x = np.interp(t, d["time"], d["wall_x"])
    v = np.interp(t, d["time"], d["wall_vx"])
    M = np.column_stack([w * w * x[keep], w * v[keep], np.ones(keep.sum())])
    coef, *_ = np.linalg.lstsq(M, forces[keep], rcond=None)
    a = args.b / 2
    ds = s[1] - s[0]
    y = (s - a) / a
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.plot(y, coef[0] / ds, "o-", label="SPH (in-phase fit per marker)")
    yy = np.linspace(-1, 1, 201)
    ax.plot(yy, 1000.0 * 2 * a * np.sqrt(1 - yy * yy) * args.box_ratio, "k", label="potential flow (box-corrected)")
    ax.set_xlabel("y / a  (a = b/2)")
    ax.set_ylabel("added mass per length (kg/m^2)")
    ax.set_title("Where the plate load is too large")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    print(f"total {coef[0].sum():.3f} kg/m, potential {1000.0 * np.pi * a * a * args.box_ratio:.3f} kg/m")


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("kind", choices=["gap", "plate", "profile"])
    ap.add_argument("out")
    ap.add_argument("csv", nargs="+")
    ap.add_argument("--box-ratio", type=float, default=1.0)
    ap.add_argument("--b", type=float, default=0.1)
    ap.add_argument("--period", type=float, default=0.5)
    a = ap.parse_args()
    {"gap": gap, "plate": plate, "profile": profile}[a.kind](a)


if __name__ == "__main__":
    main()
