"""Reads and writes the leaflet mesh file (`*.mesh.h5`, format "valvefsi-mesh" version 1),
the contract between the valve generator and solid_fe (layout: docs/valve-scene.md)."""
from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np

from .valve_mesh import ValveMesh

FORMAT_NAME = "valvefsi-mesh"
FORMAT_VERSION = 1


def write_mesh(mesh: ValveMesh, path: Path) -> None:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with h5py.File(path, "w") as f:
        g = f.create_group("mesh")
        g.attrs["format"] = FORMAT_NAME
        g.attrs["version"] = np.int64(FORMAT_VERSION)
        for key, value in mesh.description.items():
            g.attrs[key] = value
        g.create_dataset("nodes", data=np.asarray(mesh.nodes, dtype=np.float64))
        if mesh.triangles is not None:
            g.create_dataset("triangles", data=np.asarray(mesh.triangles, dtype=np.int64))
            g.create_dataset("triangle_thickness", data=np.asarray(mesh.triangle_thickness, dtype=np.float64))
            axes = g.create_group("triangle_axes")
            axes.create_dataset("circumferential", data=mesh.triangle_circumferential)
            axes.create_dataset("radial", data=mesh.triangle_radial)
        if mesh.hexahedra is not None:
            g.create_dataset("hexahedra", data=np.asarray(mesh.hexahedra, dtype=np.int64))
            axes = g.create_group("hexahedron_axes")
            axes.create_dataset("circumferential", data=mesh.hexahedron_circumferential)
            axes.create_dataset("radial", data=mesh.hexahedron_radial)
        node_sets = g.create_group("node_sets")
        for name, ids in mesh.node_sets.items():
            node_sets.create_dataset(name, data=np.asarray(ids, dtype=np.int64))
        element_sets = g.create_group("element_sets")
        for name, (element_type, ids) in mesh.element_sets.items():
            d = element_sets.create_dataset(name, data=np.asarray(ids, dtype=np.int64))
            d.attrs["element_type"] = element_type
        for group_name, planes in (("symmetry_planes", mesh.symmetry_planes), ("contact_planes", mesh.contact_planes)):
            planes_group = g.create_group(group_name)
            for name, (point, normal) in planes.items():
                plane = planes_group.create_group(name)
                plane.attrs["point"] = np.asarray(point, dtype=np.float64)
                plane.attrs["normal"] = np.asarray(normal, dtype=np.float64)


def read_mesh(path: Path) -> ValveMesh:
    path = Path(path)
    with h5py.File(path, "r") as f:
        if "mesh" not in f:
            raise ValueError(f"{path}: no group '/mesh' (not a {FORMAT_NAME} file)")
        g = f["mesh"]
        fmt = g.attrs.get("format")
        if isinstance(fmt, bytes):
            fmt = fmt.decode()
        if fmt != FORMAT_NAME or int(g.attrs.get("version", -1)) != FORMAT_VERSION:
            raise ValueError(f"{path}: /mesh attributes format={fmt!r} version={g.attrs.get('version')!r}: "
                             f"expected format='{FORMAT_NAME}' version={FORMAT_VERSION}")

        def optional(name):
            return g[name][()] if name in g else None

        mesh = ValveMesh(nodes=g["nodes"][()])
        mesh.triangles = optional("triangles")
        mesh.triangle_thickness = optional("triangle_thickness")
        mesh.triangle_circumferential = optional("triangle_axes/circumferential")
        mesh.triangle_radial = optional("triangle_axes/radial")
        mesh.hexahedra = optional("hexahedra")
        mesh.hexahedron_circumferential = optional("hexahedron_axes/circumferential")
        mesh.hexahedron_radial = optional("hexahedron_axes/radial")
        mesh.node_sets = {name: d[()] for name, d in g.get("node_sets", {}).items()}
        for name, d in g.get("element_sets", {}).items():
            element_type = d.attrs["element_type"]
            mesh.element_sets[name] = (element_type.decode() if isinstance(element_type, bytes) else element_type, d[()])
        for group_name in ("symmetry_planes", "contact_planes"):
            target = getattr(mesh, group_name)
            for name, plane in g.get(group_name, {}).items():
                target[name] = (np.asarray(plane.attrs["point"]), np.asarray(plane.attrs["normal"]))
        mesh.description = {k: (v.decode() if isinstance(v, bytes) else v) for k, v in g.attrs.items()
                            if k not in ("format", "version")}
    return mesh
