"""Writes the parametric size-23 valve as a leaflet mesh file.

    cd scripts && /usr/bin/python3 -m valve_scene.generate --variant full|sector \
        --resolution coarse|medium|fine --out X.mesh.h5 [--elements both|triangles|hexahedra] [--png X.png]
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

from .mesh_io import write_mesh
from .valve_geometry import ValveParameters
from .valve_mesh import ELEMENT_FAMILIES, RESOLUTIONS, VARIANTS, ValveMesh, build_valve_mesh


def plot_mesh(mesh: ValveMesh, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import PolyCollection
    if mesh.triangles is None:
        raise ValueError("the preview draws triangles; generate with --elements both|triangles")
    x = mesh.nodes * 1e3
    tris = mesh.triangles
    fig = plt.figure(figsize=(11, 5))
    top = fig.add_subplot(1, 2, 1)
    top.add_collection(PolyCollection(x[tris][:, :, :2], facecolor="tab:orange", edgecolor="k", linewidths=0.15, alpha=0.6))
    phi = np.linspace(0, 2 * math.pi, 361)
    R = mesh.description.get("param_annulus_radius", 11.5e-3) * 1e3
    top.plot(R * np.cos(phi), R * np.sin(phi), "k-", lw=0.8)
    for name in ("free_edge_midpoints",):
        ids = mesh.node_sets[name]
        top.plot(x[ids, 0], x[ids, 1], "ro", ms=4)
    top.set_aspect("equal")
    top.set_xlim(-R * 1.1, R * 1.1)
    top.set_ylim(-R * 1.1, R * 1.1)
    top.set_title("top view (from the aorta), mm")
    side = fig.add_subplot(1, 2, 2, projection="3d")
    side.plot_trisurf(x[:, 0], x[:, 1], x[:, 2], triangles=tris, color="tab:orange", edgecolor="k", linewidth=0.1, alpha=0.8)
    att = mesh.node_sets["attachment"]
    side.scatter(x[att, 0], x[att, 1], x[att, 2], s=2, c="b")
    side.set_box_aspect((1, 1, 0.6))
    side.view_init(elev=20, azim=-60)
    side.set_title(f"{mesh.description.get('variant')} valve, {len(tris)} triangles")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description="Write the parametric size-23 TAV leaflet mesh (valvefsi-mesh HDF5).")
    parser.add_argument("--variant", choices=VARIANTS, default="full")
    parser.add_argument("--resolution", choices=list(RESOLUTIONS), default="medium")
    parser.add_argument("--elements", choices=ELEMENT_FAMILIES, default="both",
                        help="element families to write (default both: triangles on the mid-surface and hexahedra)")
    parser.add_argument("--out", type=Path, required=True, help="output file, e.g. valve.mesh.h5")
    parser.add_argument("--png", type=Path, help="optional preview plot")
    args = parser.parse_args(argv)
    mesh = build_valve_mesh(args.variant, args.resolution, args.elements, ValveParameters())
    write_mesh(mesh, args.out)
    if args.png:
        plot_mesh(mesh, args.png)
    counts = [f"{len(mesh.nodes)} nodes"]
    if mesh.triangles is not None:
        counts.append(f"{len(mesh.triangles)} triangles")
    if mesh.hexahedra is not None:
        counts.append(f"{len(mesh.hexahedra)} hexahedra")
    print(f"{args.out}: {args.variant} valve, {args.resolution}: " + ", ".join(counts))


if __name__ == "__main__":
    main()
