#!/usr/bin/python3
"""Dam-break surge front against Martin & Moyce (1952), as measured and with the fitted delay.

Reads the front samples the dam-break tests write when VALVEFSI_DAM_BREAK_FRONT_DIR is set
(dam_break_front_dp<dp>.csv: T, Z and the fitted delay in the header) and the measured points
(tests/fluid_sph/data), and draws Z(T) and Z(T - delay) for every resolution found.

  mkdir -p /tmp/front
  VALVEFSI_DAM_BREAK_FRONT_DIR=/tmp/front build/tests/fluid_sph/fluid_dam_break_test
  VALVEFSI_DAM_BREAK_FRONT_DIR=/tmp/front build/tests/fluid_sph/fluid_dam_break_validation
  /usr/bin/python3 fluid_sph/scripts/plot_dam_break_front.py /tmp/front docs/figures/fluid-dam-break-front.png
"""
import re
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

ROOT = Path(__file__).resolve().parents[2]
MEASURED = ROOT / "tests" / "fluid_sph" / "data" / "dam-break-front-martin-moyce-1952.csv"


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    folder, output = Path(sys.argv[1]), Path(sys.argv[2])
    files = sorted(folder.glob("dam_break_front_dp*.csv"), key=lambda f: -float(f.stem.split("dp")[1]))
    if not files:
        sys.exit(f"{folder}: no dam_break_front_dp*.csv (run the dam-break tests with VALVEFSI_DAM_BREAK_FRONT_DIR={folder})")
    mm = np.loadtxt(MEASURED, delimiter=",", comments="#", skiprows=6)
    mm = mm[mm[:, 1] < 4.0]
    fig, axes = plt.subplots(1, 2, figsize=(10, 4), sharey=True)
    for f in files:
        header = f.read_text().splitlines()[0]
        delay = float(re.search(r"fitted delay ([0-9.eE+-]+)", header).group(1))
        dp = float(f.stem.split("dp")[1])
        data = np.loadtxt(f, delimiter=",", comments="#", skiprows=2)
        axes[0].plot(data[:, 0], data[:, 1], label=f"SPH dp = {dp:g} m")
        axes[1].plot(data[:, 0] + delay, data[:, 1], label=f"dp = {dp:g} m, delay {delay:.3f}")
    for ax, title in zip(axes, ["as computed (release at T = 0)", "shifted by the fitted start-up delay"]):
        ax.plot(mm[:, 0], mm[:, 1], "ko", label="Martin & Moyce 1952")
        ax.axhline(4.0, color="grey", lw=0.8, ls=":")
        ax.set_xlim(0, 3.2)
        ax.set_ylim(0.9, 4.2)
        ax.set_xlabel("T = t (2g/a)^1/2")
        ax.set_title(title)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    axes[0].set_ylabel("Z = z / a (front)")
    fig.tight_layout()
    fig.savefig(output, dpi=110)
    print(f"wrote {output}")


if __name__ == "__main__":
    main()
