"""Writes a leaflet mesh (*.mesh.h5, docs/mesh-format.md) as the plain-text surface that
`thin_wall_3d --case CASE --surface FILE` reads: node count, "x y z thickness" per node
(thickness: mean of the incident triangles'), triangle count, "a b c" per triangle.

Usage: /usr/bin/python3 dump_surface.py MESH.h5 OUT.txt
"""
import sys

import h5py
import numpy as np


def main():
    mesh, out = sys.argv[1], sys.argv[2]
    with h5py.File(mesh) as f:
        nodes = f["mesh/nodes"][:]
        triangles = f["mesh/triangles"][:]
        thickness = f["mesh/triangle_thickness"][:]
    node_t = np.zeros(len(nodes))
    count = np.zeros(len(nodes))
    for tri, t in zip(triangles, thickness):
        node_t[tri] += t
        count[tri] += 1
    node_t /= np.maximum(count, 1)
    with open(out, "w") as f:
        f.write(f"{len(nodes)}\n")
        for x, t in zip(nodes, node_t):
            f.write(f"{x[0]:.17g} {x[1]:.17g} {x[2]:.17g} {t:.17g}\n")
        f.write(f"{len(triangles)}\n")
        for tri in triangles:
            f.write(f"{tri[0]} {tri[1]} {tri[2]}\n")


if __name__ == "__main__":
    main()
