"""The rounded commissure measured with solid_fe: the closed valve's stable step and peak stress
on a sharp and a rounded mesh (docs/valve-scene.md, "Rounded commissure").

    cd scripts && /usr/bin/python3 -m valve_scene.commissure_check --out /work/runs/commissure \
        [--radii 0 1e-3] [--resolution coarse] [--material MHGO] [--build-dir ../build] \
        [--commissure-top-row 1 1]   # the sharp corner with uniform rows (before session 12)

Each radius gets the sector mesh and a closing case (the solid's owner's refinement check,
docs/solid_fe.md): aortic 80 mmHg ramped in over 5 ms against 0 ventricular, mass damping
1000/s so the closed state settles, 10 ms, FE-only; then an opening case (the real waveform's
first 10 ms, undamped). Printed per run: the stable step (median over the last 2 ms) and the
element setting it, the closed max-principal stress (element maximum, 99th area percentile,
median) at 5 and 10 ms, the steps taken and the wall time.
"""
from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np

from .analysis import area_percentile, triangle_areas
from .mesh_io import write_mesh
from .solid_results import SolidFields
from .valve_geometry import ValveParameters
from .valve_mesh import build_valve_mesh
from .write_cases import CaseSpec, case_text
from . import waveform

REPO = Path(__file__).resolve().parents[2]
CLOSING_PRESSURE_MMHG = 80.0
CLOSING_RAMP_S = 0.005
CLOSING_DAMPING_PER_S = 1000.0
RUN_END_S = 0.010


def closing_waveform() -> str:
    return ("waveform {\n"
            "  # constant: the aortic pressure closes the valve, ramped in\n"
            f"  period_s: 1\n  time_s: [0, 0.5]\n  ventricular_pressure_mmHg: [0, 0]\n"
            f"  aortic_pressure_mmHg: [{CLOSING_PRESSURE_MMHG:g}, {CLOSING_PRESSURE_MMHG:g}]\n"
            f"  ramp_time: {CLOSING_RAMP_S:g}\n}}\n")


def check_case(spec: CaseSpec, mesh_path: Path, closing: bool) -> str:
    text = case_text(spec)
    if closing:
        text = text.replace(waveform.waveform_textproto(), closing_waveform())
        # the cycle cases carry their own (lighter) mass damping since session 6: replace it
        damping = f"mass_damping_per_s: {CLOSING_DAMPING_PER_S:g}"
        if re.search(r"mass_damping_per_s: \S+", text):
            text = re.sub(r"mass_damping_per_s: \S+", damping, text, count=1)
        else:
            text = text.replace("  density: ", f"  {damping}\n  density: ", 1)
    text = re.sub(r"end_time: [0-9.]+", f"end_time: {RUN_END_S:g}", text, count=1)
    text = re.sub(r"snapshot_interval: [0-9.]+", "snapshot_interval: 0.001", text, count=1)
    return text.replace(f'mesh_file: "meshes/{spec.mesh_name}"', f'mesh_file: "{mesh_path}"')


def run(case_file: Path, out: Path, build_dir: Path) -> float:
    cmd = [sys.executable, str(REPO / "scripts" / "run_case.py"), str(case_file), "--output", str(out),
           "--fe-only", "--build-dir", str(build_dir)]
    start = time.monotonic()
    with open(out.with_suffix(".log"), "w") as log:
        result = subprocess.run(cmd, stdout=log, stderr=subprocess.STDOUT, cwd=REPO)
    if result.returncode != 0:
        raise RuntimeError(f"{case_file.name}: run_case.py exited with {result.returncode}; see {out.with_suffix('.log')}")
    return time.monotonic() - start


def summarise(out: Path, wall: float) -> dict:
    with h5py.File(out / "solid_series.h5", "r") as f:
        t = f["time"][()]
        dt = f["time_step"][()]
        critical = f["time_step_source/critical_element"][()]
        steps = int(f["step"][()][-1])
        energy = float(np.nanmax(np.abs(f["energy/relative_balance_error"][()])))
    late = t >= t[-1] - 0.002
    values, counts = np.unique(critical[late].astype(int), return_counts=True)
    fields = SolidFields(out)
    areas = triangle_areas(fields.reference_nodes, fields.triangles)
    stress = {}
    for when in (0.005, 0.010):
        snap = fields.snapshot(fields.nearest(when))["max_principal_stress"]
        stress[f"{when * 1e3:g} ms"] = {"max_MPa": float(snap.max() * 1e-6), "element": int(np.argmax(snap)),
                                        "p99_MPa": float(area_percentile(snap, areas) * 1e-6),
                                        "median_MPa": float(np.median(snap) * 1e-6)}
    return {"stable_step_us": float(np.median(dt[late]) * 1e6), "stable_step_min_us": float(dt[late].min() * 1e6),
            "critical_elements": {int(v): int(c) for v, c in zip(values, counts)}, "steps": steps,
            "wall_s": wall, "max_energy_error": energy, "stress": stress}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--radii", nargs="+", type=float, default=[0.0, ValveParameters().commissure_fillet_radius])
    parser.add_argument("--resolution", default="coarse")
    parser.add_argument("--material", default="MHGO", choices=("MHGO", "Ogden"))
    parser.add_argument("--build-dir", type=Path, default=REPO / "build")
    parser.add_argument("--phases", nargs="+", choices=("closing", "opening"), default=["closing", "opening"])
    parser.add_argument("--commissure-top-row", nargs=2, type=float, metavar=("FACTOR", "COLUMNS"),
                        help="the sharp corner's top row (valve_mesh.COMMISSURE_TOP_ROW by default; 1 1 = uniform rows)")
    args = parser.parse_args(argv)
    top_row = None if args.commissure_top_row is None else (args.commissure_top_row[0], int(args.commissure_top_row[1]))
    tag = "" if top_row is None else f"-top-row-{top_row[0]:g}x{top_row[1]}"
    args.out.mkdir(parents=True, exist_ok=True)
    spec = CaseSpec("FE", args.material, "sector", args.resolution)
    results = {}
    for rho in args.radii:
        params = ValveParameters(commissure_fillet_radius=rho)
        mesh_path = args.out / f"valve-sector-{args.resolution}-fillet-{rho * 1e3:g}mm{tag}.mesh.h5"
        write_mesh(build_valve_mesh("sector", args.resolution, "triangles", params, commissure_top_row=top_row), mesh_path)
        for closing in [phase == "closing" for phase in args.phases]:
            name = f"{spec.name}-fillet-{rho * 1e3:g}mm{tag}-{'closing' if closing else 'opening'}"
            case_file = args.out / f"{name}.textproto"
            case_file.write_text(check_case(spec, mesh_path, closing))
            wall = run(case_file, args.out / name, args.build_dir)
            results[name] = summarise(args.out / name, wall)
            print(name, json.dumps(results[name]), flush=True)
    (args.out / "summary.json").write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
