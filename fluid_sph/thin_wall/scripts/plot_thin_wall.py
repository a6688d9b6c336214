#!/usr/bin/python3
"""Plots for docs/thin-leaflet.md from thin_wall_2d CSV output:
  gap:   water levels either side of the wall over time (from particle counts)
  plate: force on the oscillating plate against the potential-flow added-mass force
Usage: plot_thin_wall.py gap OUT.png RUN.csv [RUN.csv ...]
       plot_thin_wall.py plate OUT.png --box-ratio R RUN.csv [RUN.csv ...]"""
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


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("kind", choices=["gap", "plate"])
    ap.add_argument("out")
    ap.add_argument("csv", nargs="+")
    ap.add_argument("--box-ratio", type=float, default=1.0)
    ap.add_argument("--b", type=float, default=0.1)
    ap.add_argument("--period", type=float, default=0.5)
    a = ap.parse_args()
    gap(a) if a.kind == "gap" else plate(a)


if __name__ == "__main__":
    main()
