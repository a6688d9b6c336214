"""A first look at one FE-only run: free-edge radial position and geometric orifice area over
time (PNG), the 10-90 % opening time, the peak max-principal log strain, and the solver's energy
balance error. Used by scripts/run-default.sh.

    cd scripts && /usr/bin/python3 -m valve_scene.quick_look RUN_DIR --variant sector --resolution coarse
"""
from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from .analysis import geometric_orifice_area
from .solid_results import SolidFields, read_series
from .valve_mesh import build_valve_mesh


def opening_time_10_90(t: np.ndarray, radial: np.ndarray) -> float:
    """Time from 10 % to 90 % of the rise from the initial to the largest radial position (s)."""
    r0, r1 = radial[0], radial.max()
    low, high = r0 + 0.1 * (r1 - r0), r0 + 0.9 * (r1 - r0)
    return float(t[np.argmax(radial >= high)] - t[np.argmax(radial >= low)])


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dir", type=Path)
    parser.add_argument("--variant", choices=("full", "sector"), default="sector")
    parser.add_argument("--resolution", choices=("coarse", "medium", "fine"), default="coarse")
    args = parser.parse_args(argv)

    series = read_series(args.run_dir)
    radial = np.hypot(series.midpoint_positions[..., 0], series.midpoint_positions[..., 1]).mean(axis=1)
    mesh = build_valve_mesh(args.variant, args.resolution, "triangles")
    annulus_radius = float(mesh.description["param_annulus_radius"])
    fields = SolidFields(args.run_dir)
    wedge = (0.0, 60.0) if args.variant == "sector" else None
    goa = [geometric_orifice_area(fields.snapshot(k)["position"], fields.triangles, annulus_radius, wedge,
                                  pixels_across=400) for k in range(len(fields.times))]
    strain = max(float(np.max(fields.snapshot(k).get("max_principal_log_strain", [np.nan])))
                 for k in range(len(fields.times)))

    fig, (ax_r, ax_a) = plt.subplots(2, 1, sharex=True, figsize=(7, 6))
    ax_r.plot(series.time * 1e3, radial * 1e3)
    ax_r.set_ylabel("free-edge midpoint radius (mm)")
    ax_a.plot(fields.times * 1e3, np.array(goa) * 1e4)
    ax_a.set_ylabel("geometric orifice area (cm²)")
    ax_a.set_xlabel("time (ms)")
    ax_r.set_title(f"FE-only {args.variant} valve ({args.resolution})")
    for ax in (ax_r, ax_a):
        ax.grid(alpha=0.3)
    figure = args.run_dir / "kinematics.png"
    fig.tight_layout()
    fig.savefig(figure, dpi=110)

    print(f"quick_look: 10-90 % opening time {opening_time_10_90(series.time, radial) * 1e3:.1f} ms "
          f"(reference FE-only: 5-6 ms); free-edge radius {radial[0] * 1e3:.2f} -> {radial.max() * 1e3:.2f} mm; "
          f"largest GOA {max(goa) * 1e4:.2f} cm² of {np.pi * annulus_radius ** 2 * 1e4:.2f} cm²; "
          f"peak max-principal log strain {strain:.3f} (reference FE-MHGO opening: 0.22); "
          f"largest energy balance error {np.nanmax(np.abs(series.energy_balance_error)):.2e}")
    print(f"quick_look: plot in {figure}")


if __name__ == "__main__":
    main()
