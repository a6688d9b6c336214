"""Structured leaflet meshes of the parametric valve: a quad grid per leaflet (columns along
the circumferential parameter s, rows from the attachment to the free edge, uniform in arc
length except for a longer top row at a sharp commissure, COMMISSURE_TOP_ROW), written as
triangles (each quad split) and hexahedra (quads extruded +-t/2 along the node normals), with
node sets, element sets, material axes and, for the 1/6 sector, its symmetry and contact planes.

The sector is cut out of the full valve's leaflet 0 (columns s >= 0) after the node normals
were computed on the whole leaflet, so it is exactly the corresponding part of the full mesh.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .valve_geometry import (LEAFLET_COUNT, SECTOR_HALF_ANGLE, ValveParameters, commissure_fillet,
                             leaflet_point, leaflet_rotation, tab_v_at_height)

# Quad cells per leaflet (circumferential over the whole leaflet, radial). The medium full
# valve has 3 * 48 * 28 * 2 = 8064 triangles (the reference used 7896 bricks).
RESOLUTIONS = {"coarse": (24, 14), "medium": (48, 28), "fine": (96, 56)}
VARIANTS = ("full", "sector")
# The sharp commissure's top row: (factor, columns) of leaflet_grid. The corner element between
# the tab top and the free edge carries the corner's stress singularity and, under the closed
# valve's load, set a 0.23 us stable step (MHGO coarse sector, element 335); its height is the
# tab's row spacing h_tab / nv. Twice that, blended out over two columns, lifts the closed
# load's smallest step to 0.64 us (docs/valve-scene.md, "The commissure's top row").
COMMISSURE_TOP_ROW = (2.0, 2)
ELEMENT_FAMILIES = ("both", "triangles", "hexahedra")


@dataclass
class ValveMesh:
    nodes: np.ndarray                                   # [N, 3] (m)
    triangles: np.ndarray | None = None                 # [T, 3]
    triangle_thickness: np.ndarray | None = None        # [T]
    triangle_circumferential: np.ndarray | None = None  # [T, 3]
    triangle_radial: np.ndarray | None = None           # [T, 3]
    hexahedra: np.ndarray | None = None                 # [H, 8]
    hexahedron_circumferential: np.ndarray | None = None
    hexahedron_radial: np.ndarray | None = None
    node_sets: dict = field(default_factory=dict)       # name -> int64 [k]
    element_sets: dict = field(default_factory=dict)    # name -> (element_type, int64 [k])
    symmetry_planes: dict = field(default_factory=dict)  # name -> (point, normal)
    contact_planes: dict = field(default_factory=dict)   # name -> (point, normal toward the leaflet)
    description: dict = field(default_factory=dict)     # provenance attributes


def row_fractions(nv: int, top_row_factor: float) -> np.ndarray:
    """Row positions along a column as fractions of its length, [nv + 1]: the top row
    `top_row_factor` times the uniform spacing 1 / nv, the other rows uniform and shorter."""
    if not (top_row_factor == 1.0 or 1.0 < top_row_factor < nv):
        raise ValueError(f"commissure top-row factor {top_row_factor!r}: allowed [1, cells_radial = {nv})")
    if nv == 1:
        return np.array([0.0, 1.0])
    rest = (1.0 - top_row_factor / nv) / (nv - 1)
    return np.append(np.arange(nv) * rest, 1.0)


def leaflet_grid(p: ValveParameters, cells_circumferential: int, cells_radial: int,
                 commissure_top_row: tuple[float, int] = (1.0, 1)) -> np.ndarray:
    """Nodes of leaflet 0, shape [nu + 1, nv + 1, 3]; rows uniform in arc length per column,
    except near the commissures: `commissure_top_row` = (factor, columns) makes the top row of
    each tab column `factor` times its uniform spacing, and of the next columns a factor falling
    linearly to 1 over `columns` columns (the column `columns` away from a tab and the rest are
    uniform, bit for bit); then, with a rounded commissure, the corner patches moved onto the
    trimmed surface."""
    nu, nv = cells_circumferential, cells_radial
    factor, blend_columns = commissure_top_row
    if blend_columns < 1:
        raise ValueError(f"commissure top-row blend {blend_columns!r} columns: allowed >= 1")
    if factor != 1.0 and p.commissure_fillet_radius > 0:
        raise ValueError(f"commissure top-row factor {factor!r} with a rounded commissure "
                         f"(commissure_fillet_radius = {p.commissure_fillet_radius!r}): allowed 1 (its patch assumes uniform rows)")
    s = np.linspace(-1.0, 1.0, nu + 1)
    v_dense = np.linspace(0.0, 1.0, 801)
    grid_v = np.empty((nu + 1, nv + 1))
    for i, s_i in enumerate(s):
        dense = leaflet_point(p, s_i, v_dense)
        arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(dense, axis=0), axis=1))])
        columns_from_tab = min(i, nu - i)
        weight = max(0.0, 1.0 - columns_from_tab / blend_columns)
        targets = (row_fractions(nv, 1.0 + (factor - 1.0) * weight) * arc[-1] if weight > 0 and factor != 1.0
                   else np.linspace(0.0, arc[-1], nv + 1))
        grid_v[i] = np.interp(targets, arc, v_dense)
    grid_s = np.repeat(s[:, None], nv + 1, axis=1)
    if p.commissure_fillet_radius > 0:
        # the right half (s >= 0) rounded, the left half its exact mirror image
        right = slice(nu // 2, nu + 1)
        rounded_s, rounded_v = _rounded_corner_parameters(p, grid_s[right], grid_v[right], nv)
        moved = ((rounded_s != grid_s[right]) | (rounded_v != grid_v[right]))[:0:-1]
        grid_s[right], grid_v[right] = rounded_s, rounded_v
        left_s, left_v = grid_s[:nu // 2], grid_v[:nu // 2]
        left_s[moved], left_v[moved] = -rounded_s[:0:-1][moved], rounded_v[:0:-1][moved]
    return leaflet_point(p, grid_s, grid_v)


def _smoothstep(x: np.ndarray, start: float) -> np.ndarray:
    t = np.clip((x - start) / (1.0 - start), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def _rounded_corner_parameters(p: ValveParameters, sigma: np.ndarray, grid_v: np.ndarray, nv: int):
    """(s, v) of the grid nodes (|s| = sigma, rows nu = j / nv) with the commissure corner
    rounded. The grid's corner node moves from C to G, the fillet's midpoint. The tab side's
    last 2d (B..T1..C) becomes the path up the tab to T1 and along the arc to G, the free-edge
    side's last 2d (..T2..C) the straight edge to T2 and the arc to G, each uniform in length;
    the interior follows by a blend of the two boundary displacements (a Coons patch with
    smoothstep weights) that vanishes outside the corner patch (the last 2d of rows and
    columns), then Laplace smoothing; every node farther than 4.5d from C keeps its place."""
    f = commissure_fillet(p)
    d, half_arc = f.tangent_distance, 0.5 * f.arc_length
    corner, midpoint = p.commissure_top(+1.0), p.free_edge_midpoint
    edge_length = float(np.linalg.norm(midpoint - corner))
    sigma_start = 1.0 - 2.0 * d / edge_length        # where the free-edge side starts to move
    nu_start = 1.0 - 2.0 * d / p.tab_height           # where the tab side starts to move
    path = d + half_arc                                # each side's new length (was 2d)
    g_s, g_v = (float(x[0]) for x in f.arc_point([half_arc]))

    def top_side(sig):                                 # free edge: (sigma, 1) -> new (s, v)
        ell = np.clip((sig - sigma_start) / (1.0 - sigma_start), 0.0, 1.0) * path
        arc_s, arc_v = f.arc_point(f.arc_length - (ell - d))
        straight = ell <= d
        return (np.where(straight, sigma_start + ell / edge_length, arc_s), np.where(straight, 1.0, arc_v))

    def tab_side(nu):                                  # tab: row nu of column s = 1 -> new (s, v)
        ell = np.clip((nu - nu_start) / (1.0 - nu_start), 0.0, 1.0) * path
        arc_s, arc_v = f.arc_point(ell - d)
        straight = ell <= d
        on_tab = tab_v_at_height(p, corner[2] - 2.0 * d + np.minimum(ell, d))
        return np.where(straight, 1.0, arc_s), np.where(straight, on_tab, arc_v)

    nu = np.broadcast_to(np.arange(nv + 1) / nv, sigma.shape)
    tab_v_original = tab_v_at_height(p, corner[2] - p.tab_height * (1.0 - nu))
    top_s, top_v = top_side(sigma)
    side_s, side_v = tab_side(nu)
    w_sigma, w_nu = _smoothstep(sigma, sigma_start), _smoothstep(nu, nu_start)
    moved = (sigma > sigma_start) & (nu > nu_start)
    new_s = sigma + w_nu * (top_s - sigma) + w_sigma * (side_s - 1.0) - w_sigma * w_nu * (g_s - 1.0)
    new_v = grid_v + w_nu * (top_v - 1.0) + w_sigma * (side_v - tab_v_original) - w_sigma * w_nu * (g_v - 1.0)
    new_s, new_v = np.where(moved, new_s, sigma), np.where(moved, new_v, grid_v)
    return _smooth_corner_patch(p, new_s, new_v, moved)


def _smooth_corner_patch(p: ValveParameters, s: np.ndarray, v: np.ndarray, moved: np.ndarray, sweeps: int = 400):
    """Laplace smoothing of the corner patch's interior nodes (each to the mean of its four grid
    neighbours) in the tangent plane at the commissure, where the patch is nearly flat; the
    blend alone leaves the rows squeezed against the arc. Boundary nodes (the trimmed edge, the
    tab) and everything outside the patch stay; the smoothed points are mapped back onto the
    surface by Newton on the same chart."""
    corner = p.commissure_top(+1.0)
    down = np.array([0.0, 0.0, -1.0])
    along = p.free_edge_midpoint - corner
    b = along - (along @ down) * down
    basis = np.stack([down, b / np.linalg.norm(b)])

    def chart(s_, v_):
        return (leaflet_point(p, s_, v_) - corner) @ basis.T

    interior = moved.copy()   # s >= 0 only: the last column is the tab, the last row the free edge
    interior[-1, :] = False
    interior[:, -1] = False
    if not interior.any():
        return s, v
    x = chart(s, v)
    for _ in range(sweeps):
        mean = 0.25 * (np.roll(x, 1, 0) + np.roll(x, -1, 0) + np.roll(x, 1, 1) + np.roll(x, -1, 1))
        x = np.where(interior[..., None], mean, x)
    ss, vv = s[interior], v[interior]
    target = x[interior]
    h = 1e-7
    for _ in range(30):
        residual = chart(ss, vv) - target
        if np.abs(residual).max() < 1e-13:
            break
        j_s = (chart(ss + h, vv) - chart(ss - h, vv)) / (2 * h)
        j_v = (chart(ss, vv + h) - chart(ss, vv - h)) / (2 * h)
        det = j_s[:, 0] * j_v[:, 1] - j_s[:, 1] * j_v[:, 0]
        ss = ss - (residual[:, 0] * j_v[:, 1] - residual[:, 1] * j_v[:, 0]) / det
        vv = vv - (j_s[:, 0] * residual[:, 1] - j_s[:, 1] * residual[:, 0]) / det
    else:
        raise RuntimeError("rounded commissure: the smoothed corner patch does not map back onto the leaflet surface")
    s, v = s.copy(), v.copy()
    s[interior], v[interior] = ss, vv
    return s, v


def quad_split(i: int, nu: int, flipped: bool = False):
    """Local corner pairs of the two triangles of quad column i, mirror-symmetric about the
    bisector: the left half splits along (i,j)-(i+1,j+1), the right half along (i+1,j)-(i,j+1);
    `flipped` takes the other diagonal (a rounded commissure's corner patch, see
    corner_patch_flips). Corners are (di, dj) offsets, counter-clockwise in (s, v), i.e. seen
    from the outflow side."""
    if (i < nu // 2) != flipped:
        return (((0, 0), (1, 0), (1, 1)), ((0, 0), (1, 1), (0, 1)))
    return (((0, 0), (1, 0), (0, 1)), ((1, 0), (1, 1), (0, 1)))


def _smallest_angle(a, b, c) -> float:
    angles = []
    for p, q, r in ((a, b, c), (b, c, a), (c, a, b)):
        u, w = q - p, r - p
        angles.append(math.acos(max(-1.0, min(1.0, float(u @ w / (np.linalg.norm(u) * np.linalg.norm(w)))))))
    return min(angles)


def corner_patch_flips(p: ValveParameters, grid: np.ndarray) -> frozenset:
    """Quads (i, j) of a rounded commissure's corner patches that split along their other
    diagonal: the one whose two triangles have the larger smallest angle (the patch's cells
    turn around the fillet, where the fixed diagonal direction leaves slivers). Chosen on the
    right half, mirrored to the left; quads away from the commissure keep the fixed split."""
    if p.commissure_fillet_radius <= 0:
        return frozenset()
    nu, nv = grid.shape[0] - 1, grid.shape[1] - 1
    corner = p.commissure_top(+1.0)
    reach = 3.0 * commissure_fillet(p).tangent_distance
    flips = set()
    for i in range(nu // 2, nu):
        for j in range(nv):
            a, b, c, d = grid[i, j], grid[i + 1, j], grid[i + 1, j + 1], grid[i, j + 1]
            if min(np.linalg.norm(x - corner) for x in (a, b, c, d)) > reach:
                continue
            along_ac = min(_smallest_angle(a, b, c), _smallest_angle(a, c, d))
            along_bd = min(_smallest_angle(a, b, d), _smallest_angle(b, c, d))
            if along_ac > along_bd:          # the right half's default is b-d
                flips.update({(i, j), (nu - 1 - i, j)})
    return frozenset(flips)


def _triangle_normals(points: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """Area-weighted (unnormalised, length = 2 * area) normals."""
    a, b, c = points[tris[:, 0]], points[tris[:, 1]], points[tris[:, 2]]
    return np.cross(b - a, c - a)


def _local_triangles(nu: int, nv: int, columns: range, flips: frozenset = frozenset()):
    """Triangles of leaflet-local grid indices (flattened over the kept columns)."""
    first = columns.start
    width = nv + 1
    tris, quad_of_tri = [], []
    for i in columns[:-1]:
        for j in range(nv):
            for corners in quad_split(i, nu, (i, j) in flips):
                tris.append([(i + di - first) * width + (j + dj) for di, dj in corners])
                quad_of_tri.append((i - first) * nv + j)
    return np.array(tris, dtype=np.int64), np.array(quad_of_tri, dtype=np.int64)


def _local_quads(nv: int, columns: range) -> np.ndarray:
    first, width = columns.start, nv + 1
    quads = []
    for i in columns[:-1]:
        for j in range(nv):
            c = (i - first) * width + j
            quads.append([c, c + width, c + width + 1, c + 1])  # (i,j) (i+1,j) (i+1,j+1) (i,j+1)
    return np.array(quads, dtype=np.int64)


def _node_normals(grid: np.ndarray, nu: int, nv: int, flips: frozenset = frozenset()) -> np.ndarray:
    """Unit normals at the grid nodes of the whole leaflet (area-weighted triangle normals)."""
    points = grid.reshape(-1, 3)
    tris, _ = _local_triangles(nu, nv, range(0, nu + 1), flips)
    normals = _triangle_normals(points, tris)
    accumulated = np.zeros_like(points)
    for corner in range(3):
        np.add.at(accumulated, tris[:, corner], normals)
    return (accumulated / np.linalg.norm(accumulated, axis=1)[:, None]).reshape(grid.shape)


def _in_plane_axes(circumferential_hint: np.ndarray, normal: np.ndarray):
    """Circumferential: the hint projected on the element plane; radial = normal x circumferential."""
    n = normal / np.linalg.norm(normal, axis=1)[:, None]
    c = circumferential_hint - np.sum(circumferential_hint * n, axis=1)[:, None] * n
    c /= np.linalg.norm(c, axis=1)[:, None]
    r = np.cross(n, c)
    return c, r / np.linalg.norm(r, axis=1)[:, None]


def build_valve_mesh(variant: str = "full", resolution: str = "medium", elements: str = "both",
                     params: ValveParameters | None = None,
                     cells: tuple[int, int] | None = None,
                     commissure_top_row: tuple[float, int] | None = None) -> ValveMesh:
    """The valve mesh. `cells` = (circumferential per leaflet, even; radial) overrides `resolution`;
    `commissure_top_row` (factor, columns) overrides COMMISSURE_TOP_ROW (see leaflet_grid)."""
    p = params or ValveParameters()
    p.validate()
    if variant not in VARIANTS:
        raise ValueError(f"variant '{variant}': allowed {', '.join(VARIANTS)}")
    if elements not in ELEMENT_FAMILIES:
        raise ValueError(f"elements '{elements}': allowed {', '.join(ELEMENT_FAMILIES)}")
    if cells is None:
        if resolution not in RESOLUTIONS:
            raise ValueError(f"resolution '{resolution}': allowed {', '.join(RESOLUTIONS)}")
        cells = RESOLUTIONS[resolution]
    nu, nv = cells
    if nu < 2 or nu % 2 or nv < 1:
        raise ValueError(f"cells {cells}: circumferential count must be even and >= 2, radial >= 1")

    if commissure_top_row is None:
        # the rounded commissure re-spaces its own corner patch (on uniform rows); grids too short
        # for the factor stay uniform
        graded = p.commissure_fillet_radius == 0 and nv > 2 * COMMISSURE_TOP_ROW[0]
        commissure_top_row = COMMISSURE_TOP_ROW if graded else (1.0, 1)
    grid0 = leaflet_grid(p, nu, nv, commissure_top_row)
    flips = corner_patch_flips(p, grid0)
    normals0 = _node_normals(grid0, nu, nv, flips)
    columns = range(0, nu + 1) if variant == "full" else range(nu // 2, nu + 1)
    leaflets = range(LEAFLET_COUNT) if variant == "full" else range(1)
    kept_grid = grid0[columns.start:].reshape(-1, 3)
    kept_normals = normals0[columns.start:].reshape(-1, 3)
    width = nv + 1
    per_leaflet = len(columns) * width

    local_i = np.repeat(np.arange(columns.start, nu + 1), width)
    local_j = np.tile(np.arange(width), len(columns))
    # the tab columns are sutured where they lie on the stent; a rounded commissure's arc above
    # the tab (up to the grid corner) is free edge
    on_stent = np.hypot(kept_grid[:, 0], kept_grid[:, 1]) >= p.annulus_radius * (1.0 - 1e-12)
    tab_column = (local_i == 0) | (local_i == nu)
    is_attachment = (local_j == 0) | (tab_column & on_stent)
    is_free_edge = (local_j == nv) | (tab_column & ~on_stent)
    midpoint_local = int(np.flatnonzero((local_i == nu // 2) & is_free_edge)[0])

    mid = np.concatenate([kept_grid @ leaflet_rotation(k).T for k in leaflets])
    nrm = np.concatenate([kept_normals @ leaflet_rotation(k).T for k in leaflets])
    with_triangles = elements in ("both", "triangles")
    with_hexahedra = elements in ("both", "hexahedra")
    layers = {}  # node layer -> offset of its first node
    blocks = []
    if with_triangles:
        layers["mid"] = 0
        blocks.append(mid)
    if with_hexahedra:
        half = 0.5 * p.thickness
        layers["ventricular"] = sum(len(b) for b in blocks)
        blocks.append(mid - half * nrm)
        layers["aortic"] = sum(len(b) for b in blocks)
        blocks.append(mid + half * nrm)
    mesh = ValveMesh(nodes=np.concatenate(blocks))

    tri_local, tri_quad = _local_triangles(nu, nv, columns, flips)
    quad_local = _local_quads(nv, columns)
    quad_count = len(quad_local)
    tris, tri_c, tri_r, hexes, hex_c, hex_r = [], [], [], [], [], []
    for n_k, k in enumerate(leaflets):
        base = n_k * per_leaflet
        points = mid[base:base + per_leaflet]
        # circumferential hint per quad: mean of its two s-direction edges
        q = quad_local
        hint = 0.5 * (points[q[:, 1]] - points[q[:, 0]] + points[q[:, 2]] - points[q[:, 3]])
        if with_triangles:
            tri_normal = _triangle_normals(points, tri_local)
            c, r = _in_plane_axes(hint[tri_quad], tri_normal)
            tris.append(tri_local + base + layers["mid"])
            tri_c.append(c)
            tri_r.append(r)
        if with_hexahedra:
            radial_hint = 0.5 * (points[q[:, 3]] - points[q[:, 0]] + points[q[:, 2]] - points[q[:, 1]])
            c, r = _in_plane_axes(hint, np.cross(hint, radial_hint))
            hexes.append(np.concatenate([quad_local + base + layers["ventricular"],
                                         quad_local + base + layers["aortic"]], axis=1))
            hex_c.append(c)
            hex_r.append(r)

    if with_triangles:
        mesh.triangles = np.concatenate(tris)
        mesh.triangle_thickness = np.full(len(mesh.triangles), p.thickness)
        mesh.triangle_circumferential = np.concatenate(tri_c)
        mesh.triangle_radial = np.concatenate(tri_r)
        per = len(tri_local)
        for n_k, k in enumerate(leaflets):
            mesh.element_sets[f"leaflet_{k}_triangles"] = ("triangle", np.arange(n_k * per, (n_k + 1) * per, dtype=np.int64))
    if with_hexahedra:
        mesh.hexahedra = np.concatenate(hexes)
        mesh.hexahedron_circumferential = np.concatenate(hex_c)
        mesh.hexahedron_radial = np.concatenate(hex_r)
        for n_k, k in enumerate(leaflets):
            mesh.element_sets[f"leaflet_{k}_hexahedra"] = ("hexahedron", np.arange(n_k * quad_count, (n_k + 1) * quad_count, dtype=np.int64))

    def in_layers(local_mask: np.ndarray, layer_names) -> np.ndarray:
        ids = [layers[name] + n_k * per_leaflet + np.flatnonzero(local_mask)
               for name in layer_names for n_k in range(len(leaflets))]
        return np.sort(np.concatenate(ids)).astype(np.int64)

    all_layers = list(layers)
    everywhere = np.ones(per_leaflet, dtype=bool)
    mesh.node_sets["attachment"] = in_layers(is_attachment, all_layers)
    mesh.node_sets["free_edge"] = in_layers(is_free_edge, all_layers)
    marker_layer = "mid" if with_triangles else "aortic"
    mesh.node_sets["free_edge_midpoints"] = np.array(
        [layers[marker_layer] + n_k * per_leaflet + midpoint_local for n_k in range(len(leaflets))], dtype=np.int64)
    if with_triangles:
        mesh.node_sets["triangle_nodes"] = in_layers(everywhere, ["mid"])
    if with_hexahedra:
        mesh.node_sets["hexahedron_nodes"] = in_layers(everywhere, ["ventricular", "aortic"])
    for n_k, k in enumerate(leaflets):
        mesh.node_sets[f"leaflet_{k}"] = np.sort(np.concatenate(
            [layers[name] + n_k * per_leaflet + np.arange(per_leaflet) for name in all_layers])).astype(np.int64)

    if variant == "sector":
        # Leaflet 0 between its bisecting plane (y = 0: the leaflet continues across it as
        # its own mirror image -> symmetry plane) and the coaptation plane at +60 deg (the
        # neighbour is this half's mirror image there, but the leaflet is not continuous
        # across it -> rigid contact plane, not a constraint).
        on_bisector = local_i == nu // 2
        mesh.symmetry_planes["leaflet_bisector"] = (np.zeros(3), np.array([0.0, 1.0, 0.0]))
        mesh.node_sets["symmetry_leaflet_bisector"] = in_layers(on_bisector, all_layers)
        normal = np.array([math.sin(SECTOR_HALF_ANGLE), -math.cos(SECTOR_HALF_ANGLE), 0.0])
        mesh.contact_planes["coaptation"] = (np.zeros(3), normal)

    mesh.description = {
        "generator": "valve_scene.generate",
        "variant": variant,
        "resolution": resolution if cells == RESOLUTIONS.get(resolution) else f"{nu}x{nv}",
        "cells_circumferential_per_leaflet": nu,
        "cells_radial": nv,
        "leaflet_count_in_file": len(leaflets),
        "full_valve_fraction": 1.0 if variant == "full" else 1.0 / (2 * LEAFLET_COUNT),
        "commissure_top_row_factor": float(commissure_top_row[0]),
        "commissure_top_row_columns": int(commissure_top_row[1]),
        **{f"param_{name}": value for name, value in p.__dict__.items()},
    }
    return mesh
