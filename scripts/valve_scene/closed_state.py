"""The closed valve, full against sector (issue 4, docs/fe-only-study.md "Full valve against
sector: the closed stress gap"): at one instant of two FE-only runs, where the top 1 % of the
leaflet area by stress lies, how far leaflets fold past their coaptation planes, and the
membrane fibre strain that the MHGO exponential turns into stress.

    cd scripts && /usr/bin/python3 -m valve_scene.closed_state FULL_RUN SECTOR_RUN --time 0.15 \\
        --full-mesh ../cases/meshes/valve-full-coarse.mesh.h5 --sector-mesh ../cases/meshes/valve-sector-coarse.mesh.h5 [--png ../docs/figures/closed-full-vs-sector.png]
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

import h5py
import numpy as np

from .analysis import area_percentile, triangle_areas
from .solid_results import SolidFields
from .valve_geometry import LEAFLET_COUNT, SECTOR_HALF_ANGLE

TOP_AREA_FRACTION = 0.01   # the p99's area: the elements that carry the top 1 % of the leaflet area


def coaptation_normal() -> np.ndarray:
    """Unit normal of the sector's coaptation plane (through the axis at 60 degrees), toward leaflet 0's half."""
    return np.array([math.sin(SECTOR_HALF_ANGLE), -math.cos(SECTOR_HALF_ANGLE), 0.0])


def to_sector_frame(points: np.ndarray, reference: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Maps points of the full valve onto leaflet 0's half between azimuth 0 and 60 degrees: each
    is rotated back by its leaflet's 120-degree turn and, on the leaflet's y < 0 half, mirrored in
    y = 0. Leaflet and half are those of `reference` (the same points in the stress-free mesh;
    default the points themselves). Returns (mapped points, leaflet index)."""
    reference = points if reference is None else reference
    turn = 2.0 * math.pi / LEAFLET_COUNT
    leaflet = np.round(np.arctan2(reference[:, 1], reference[:, 0]) / turn).astype(int)
    angle = -leaflet * turn
    c, s = np.cos(angle), np.sin(angle)
    y_ref = reference[:, 0] * s + reference[:, 1] * c
    x = points[:, 0] * c - points[:, 1] * s
    y = (points[:, 0] * s + points[:, 1] * c) * np.where(y_ref >= 0.0, 1.0, -1.0)
    return np.stack([x, y, points[:, 2]], axis=1), leaflet % LEAFLET_COUNT


def membrane_fibre_log_strain(reference: np.ndarray, current: np.ndarray, triangles: np.ndarray,
                              circumferential: np.ndarray, radial: np.ndarray, fibre_angle_deg: float) -> np.ndarray:
    """Largest log strain of the two fibre families at +-angle from the circumferential axis,
    from each triangle's constant in-plane deformation (mid-surface: no bending)."""
    E = np.stack([reference[triangles[:, 1]] - reference[triangles[:, 0]],
                  reference[triangles[:, 2]] - reference[triangles[:, 0]]], axis=-1)
    e = np.stack([current[triangles[:, 1]] - current[triangles[:, 0]],
                  current[triangles[:, 2]] - current[triangles[:, 0]]], axis=-1)
    metric = np.einsum("tij,tik->tjk", E, E)
    theta = math.radians(fibre_angle_deg)
    strain = np.full(len(triangles), -np.inf)
    for sign in (1.0, -1.0):
        fibre = math.cos(theta) * circumferential + sign * math.sin(theta) * radial
        w = np.linalg.solve(metric, np.einsum("tij,ti->tj", E, fibre)[..., None])[..., 0]   # fibre = E w
        stretched = np.einsum("tij,tj->ti", e, w)
        strain = np.maximum(strain, 0.5 * np.log(np.einsum("ti,ti->t", stretched, stretched)))
    return strain


def mhgo_fibre_stress(fibre_log_strain, k1_Pa: float, k2: float) -> np.ndarray:
    """The fibre term's Cauchy stress along a fibre, 2 k1 (I4 - 1) exp(k2 (I4 - 1)^2) I4
    (I4 = stretch^2, incompressible, fibres in tension only): what the exponential does to strain."""
    i4 = np.exp(2.0 * np.asarray(fibre_log_strain, dtype=float))
    d = np.maximum(i4 - 1.0, 0.0)
    return 2.0 * k1_Pa * d * np.exp(k2 * d * d) * i4


def top_area_elements(values: np.ndarray, areas: np.ndarray, fraction: float = TOP_AREA_FRACTION) -> np.ndarray:
    """Indices of the largest values that together cover `fraction` of the area."""
    order = np.argsort(values)[::-1]
    covered = np.cumsum(areas[order])
    return order[:int(np.searchsorted(covered, fraction * areas.sum())) + 1]


def neighbour_stress_ratio(stress: np.ndarray, triangles: np.ndarray, floor_Pa: float = 1e3) -> float:
    """Median ratio of the stresses of two triangles sharing an edge (>= 1): ~1 for a smooth
    field, large when the field is speckled element by element (vibration at the mesh scale)."""
    first = {}
    pairs = []
    for e, t in enumerate(triangles):
        for a, b in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
            key = (min(a, b), max(a, b))
            if key in first:
                pairs.append((first[key], e))
            else:
                first[key] = e
    pairs = np.array(pairs)
    s = np.maximum(stress, floor_Pa)
    return float(np.exp(np.median(np.abs(np.log(s[pairs[:, 0]] / s[pairs[:, 1]])))))


def closed_state(run_dir: Path, mesh_file: Path, time: float, fibre_angle_deg: float, full: bool) -> dict:
    fields = SolidFields(run_dir)
    snap = fields.snapshot(fields.nearest(time))
    ref, tri = fields.reference_nodes, fields.triangles
    with h5py.File(mesh_file, "r") as f:
        c, r = f["mesh/triangle_axes/circumferential"][()], f["mesh/triangle_axes/radial"][()]
    if len(c) != len(tri):
        raise ValueError(f"{mesh_file}: {len(c)} triangle axes, but {run_dir} has {len(tri)} triangles (not this run's mesh)")
    areas = triangle_areas(ref, tri)
    stress = snap["max_principal_stress"]
    mapped, _ = to_sector_frame(snap["position"], ref) if full else (snap["position"], None)
    beyond = -(mapped @ coaptation_normal())   # > 0: past the coaptation plane, into the neighbour's half
    fibre = membrane_fibre_log_strain(ref, snap["position"], tri, c, r, fibre_angle_deg)
    top = top_area_elements(stress, areas)
    with h5py.File(fields.path, "r") as f:
        velocity = f["snapshots"][fields.names[fields.nearest(time)]]["velocity"][()]
    with h5py.File(Path(run_dir) / "solid_series.h5", "r") as f:
        i = int(np.argmin(np.abs(f["time"][()] - time)))
        scale = 1.0 if full else 2.0 * LEAFLET_COUNT   # the sector's energies are a sixth of the valve's
        energies = {k: float(f[f"energy/{k}"][i]) * scale for k in ("kinetic", "strain_energy", "external_work")}
    centroids = (to_sector_frame(ref, ref)[0] if full else ref)[tri].mean(axis=1)
    return {"time": float(fields.times[fields.nearest(time)]),
            "stress_p99_MPa": area_percentile(stress, areas) / 1e6,
            "stress_median_MPa": float(np.median(stress)) / 1e6,
            "strain_p99": area_percentile(snap["max_principal_log_strain"], areas),
            "fibre_strain_p99": area_percentile(fibre, areas),
            "nodes_past_plane": int(np.sum(beyond > 0.0)),
            "largest_past_plane_mm": float(max(beyond.max(), 0.0)) * 1e3,
            "kinetic_mJ": energies["kinetic"] * 1e3, "strain_energy_mJ": energies["strain_energy"] * 1e3,
            "external_work_mJ": energies["external_work"] * 1e3,
            "node_speed_rms": float(np.sqrt(np.mean(np.sum(velocity ** 2, axis=1)))),
            "neighbour_stress_ratio": neighbour_stress_ratio(stress, tri),
            "top_azimuth_deg": np.degrees(np.arctan2(centroids[top, 1], centroids[top, 0])),
            "top_z_mm": centroids[top, 2] * 1e3}


def _sector_copies(points: np.ndarray) -> list[np.ndarray]:
    """The sector's six images making the full valve: three turns, each with its mirror in y = 0."""
    copies = []
    for k in range(LEAFLET_COUNT):
        a = k * 2.0 * math.pi / LEAFLET_COUNT
        for mirror in (1.0, -1.0):
            x, y = points[..., 0], mirror * points[..., 1]
            copies.append(np.stack([x * math.cos(a) - y * math.sin(a), x * math.sin(a) + y * math.cos(a)], axis=-1))
    return copies


def plot_top_views(full_run: Path, sector_run: Path, time: float, path: Path) -> None:
    """Top views (seen from the aorta) of the two closed valves coloured by element stress, the
    elements of the top 1 % of the area outlined."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import PolyCollection
    from matplotlib.colors import LogNorm
    fig, axes = plt.subplots(1, 2, figsize=(11, 5.2))
    norm = LogNorm(vmin=0.05, vmax=50.0)
    for ax, run, full in ((axes[0], full_run, True), (axes[1], sector_run, False)):
        fields = SolidFields(run)
        snap = fields.snapshot(fields.nearest(time))
        tri, stress = fields.triangles, snap["max_principal_stress"] / 1e6
        areas = triangle_areas(fields.reference_nodes, tri)
        top = top_area_elements(stress, areas)
        polys = [snap["position"][tri][:, :, :2]] if full else _sector_copies(snap["position"][tri])
        for copy in polys:
            ax.add_collection(PolyCollection(copy * 1e3, array=np.clip(stress, 0.05, None), cmap="viridis", norm=norm,
                                             edgecolors="none"))
            ax.add_collection(PolyCollection(copy[top] * 1e3, facecolors="none", edgecolors="r", linewidths=0.8))
        ax.set_xlim(-12.5, 12.5)
        ax.set_ylim(-12.5, 12.5)
        ax.set_aspect("equal")
        ax.set_xlabel("x (mm)")
        ax.set_title(f"{'full valve' if full else 'sector x 6'}, t = {fields.times[fields.nearest(time)]:.3f} s of the run: "
                     f"p99 {area_percentile(stress, areas):.1f} MPa", fontsize=9)
    axes[0].set_ylabel("y (mm)")
    fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap="viridis"), ax=axes, label="max principal stress (MPa); red: top 1 % of area")
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("full_run", type=Path)
    parser.add_argument("sector_run", type=Path)
    parser.add_argument("--time", type=float, nargs="+", default=[0.15], help="run times compared (s)")
    parser.add_argument("--full-mesh", type=Path, required=True)
    parser.add_argument("--sector-mesh", type=Path, required=True)
    parser.add_argument("--fibre-angle-deg", type=float, default=43.11)
    parser.add_argument("--png", type=Path, help="top views of the two closed valves at the last --time")
    args = parser.parse_args(argv)
    if args.png:
        plot_top_views(args.full_run, args.sector_run, args.time[-1], args.png)
    print("| run | t (s) | stress p99 (MPa) | median | log strain p99 | membrane fibre strain p99 | nodes past the plane | largest (mm) | "
          "kinetic / strain energy / external work (mJ, valve) | node speed rms (m/s) | neighbour stress ratio | top-1 % area: azimuth (deg), z (mm) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for t in args.time:
        for name, run, mesh, full in (("full", args.full_run, args.full_mesh, True), ("sector", args.sector_run, args.sector_mesh, False)):
            s = closed_state(run, mesh, t, args.fibre_angle_deg, full)
            print(f"| {name} | {s['time']:.3f} | {s['stress_p99_MPa']:.2f} | {s['stress_median_MPa']:.2f} | {s['strain_p99']:.3f} | "
                  f"{s['fibre_strain_p99']:.4f} | {s['nodes_past_plane']} | {s['largest_past_plane_mm']:.2f} | "
                  f"{s['kinetic_mJ']:.2f} / {s['strain_energy_mJ']:.2f} / {s['external_work_mJ']:.2f} | {s['node_speed_rms']:.2f} | "
                  f"{s['neighbour_stress_ratio']:.2f} | "
                  f"{np.median(s['top_azimuth_deg']):.0f} ({s['top_azimuth_deg'].min():.0f}-{s['top_azimuth_deg'].max():.0f}), "
                  f"{np.median(s['top_z_mm']):.1f} ({s['top_z_mm'].min():.1f}-{s['top_z_mm'].max():.1f}) |")


if __name__ == "__main__":
    main()
