"""The flow sections' volume against the particles that crossed them.

A flow section (fluid.probes.flow_planes) integrates sum u V over a slab: it sees the particles'
velocities. A particle's mass crosses the plane only by moving, and particle shifting moves
particles without velocity, so over a span the particles that crossed a plane (the change of the
count on its upstream side, times dp^D) and the section's volume differ by what the shift carried
(lost particles and compression aside). docs/fsi-2d.md, "Session 19", measured it over a 2D
diastole for each fluid.shifting_speed.

    python -m valve_scene.section_budget RUN_DIR [--plane NAME=POSITION ...] [--symmetry-factor 6]

Planes: --plane NAME=POSITION (m along the axis: x in 2D, z in 3D), by default the valve scenes'
sections below. Volumes per metre of depth in 2D (mm^2), in mL in 3D (times the symmetry factor).
"""
from __future__ import annotations

import argparse
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import hemodynamics

# The valve scenes' flow sections (valve2d.py, tube_case.py): name -> position along the axis (m).
DEFAULT_PLANES_2D = {"x_m23mm": -0.023, "x_m3mm": -0.003, "x_p30mm": 0.030, "x_p69mm": 0.069}
DEFAULT_PLANES_3D = {"upstream_tap": -0.023, "leaflet_base": 0.0, "commissure_tops": 0.012, "downstream_30mm": 0.030}


@dataclass
class SectionBudget:
    plane: str
    position: float            # m along the axis
    times: np.ndarray          # s, the particle snapshots'
    section_volume: np.ndarray  # the section's integral of its flow rate since times[0] (m^D per depth in 2D)
    crossed_volume: np.ndarray  # particles that crossed it downstream since times[0], times dp^D

    @property
    def drift(self) -> np.ndarray:
        """What the particles carried that the section did not see."""
        return self.crossed_volume - self.section_volume


def section_budgets(run_dir: Path, planes: dict[str, float], dimension: int, spacing: float | None = None,
                    start: float = -math.inf, end: float = math.inf) -> list[SectionBudget]:
    import h5py
    run_dir = Path(run_dir)
    spacing = spacing or hemodynamics.particle_spacing_of(run_dir)
    if not spacing:
        raise ValueError(f"{run_dir}: the particle spacing is unknown (no fluid.log states 'dp = ... m'; pass --spacing)")
    probes = run_dir / "fluid_probes.h5"
    if not probes.is_file():
        raise FileNotFoundError(f"{probes}: no probe series")
    with h5py.File(probes, "r") as f:
        t = f["time"][()]
        missing = [name for name in planes if f"flow_rate/{name}" not in f]
        if missing:
            raise KeyError(f"{probes}: no flow section(s) {', '.join(missing)} (found: {', '.join(f['flow_rate'])})")
        rates = {name: f[f"flow_rate/{name}"][()] for name in planes}
    axis = 0 if dimension == 2 else 2   # x in 2D (the channel), z in 3D (the tube)
    snapshots = [s for s in hemodynamics.particle_snapshots(run_dir) if start <= s[0] <= end]
    if len(snapshots) < 2:
        raise ValueError(f"{run_dir}: {len(snapshots)} particle snapshot(s) in the span, at least 2 needed")
    times, upstream = [], {name: [] for name in planes}
    for time, path, group in snapshots:
        with h5py.File(path, "r") as f:
            kind = f[group]["kind"][()].reshape(-1)
            coordinate = f[group]["position"][()][kind == hemodynamics.PARTICLE_FLUID][:, axis]
        times.append(time)
        for name, position in planes.items():
            upstream[name].append(np.count_nonzero(coordinate < position))
    times = np.array(times)
    out = []
    for name, position in planes.items():
        sections = np.array([hemodynamics.integral(t, rates[name], times[0], b) for b in times])
        crossed = -(np.array(upstream[name], float) - upstream[name][0]) * spacing ** dimension
        out.append(SectionBudget(name, position, times, sections, crossed))
    return out


def table(budgets: list[SectionBudget], dimension: int, symmetry_factor: float = 1.0, rows: int = 6) -> str:
    scale, unit = (1e6, "mm²") if dimension == 2 else (1e6 * symmetry_factor, "mL")
    lines = [f"| section (position) | t (ms) | section's volume ({unit}) | particles crossed ({unit}) | drift ({unit}) |",
             "|---|---|---|---|---|"]
    for b in budgets:
        picks = sorted(set(np.linspace(1, len(b.times) - 1, min(rows, len(b.times) - 1)).round().astype(int)))
        for k in picks:
            section, crossed, drift = (round(float(v) * scale, 6) + 0.0 for v in (b.section_volume[k], b.crossed_volume[k], b.drift[k]))
            lines.append(f"| {b.plane} ({b.position * 1e3:g} mm) | {b.times[k] * 1e3:.0f} | {section:.3g} | {crossed:.3g} | {drift:+.3g} |")
    return "\n".join(lines)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("run_dir", type=Path)
    parser.add_argument("--dimension", type=int, choices=(2, 3), default=None, help="default: 3 if the run is a 3D one")
    parser.add_argument("--plane", action="append", default=[], metavar="NAME=POSITION_M")
    parser.add_argument("--symmetry-factor", type=float, default=1.0)
    parser.add_argument("--spacing", type=float, default=None, help="particle spacing (m); default: fluid.log's")
    parser.add_argument("--start", type=float, default=-math.inf, help="s")
    parser.add_argument("--end", type=float, default=math.inf, help="s")
    args = parser.parse_args(argv)
    dimension = args.dimension
    if dimension is None:
        log = (args.run_dir / "fluid.log").read_text(errors="replace") if (args.run_dir / "fluid.log").is_file() else ""
        dimension = 2 if "(2D)" in log else 3
    planes = {}
    for item in args.plane:
        name, _, position = item.partition("=")
        try:
            planes[name] = float(position)
        except ValueError:
            parser.error(f"--plane {item!r}: expected NAME=POSITION_M, e.g. x_m3mm=-0.003")
    planes = planes or (DEFAULT_PLANES_2D if dimension == 2 else DEFAULT_PLANES_3D)
    print(table(section_budgets(args.run_dir, planes, dimension, args.spacing, args.start, args.end), dimension,
                args.symmetry_factor))


if __name__ == "__main__":
    main()
