"""Kinematic metrics of a valve run, from arrays (node positions over time, triangles), as the
reference reports them (definitions: docs/valve-scene.md, "Analysis").

- free-edge midpoint radial position, mean over the leaflets (reference Fig. 5a);
- geometric orifice area (GOA): the part of the annulus disk not covered by the top-view
  projection of any leaflet triangle (reference Fig. 5b), by rasterisation;
- leaflet profiles in a leaflet's bisecting plane (reference Fig. 6);
- RVOT, RVCT, ET from the radial-position curve (reference Table 3).
A 1/6 sector stands for the full valve: its GOA is measured inside its 60 deg wedge and
multiplied by 6; its single free-edge midpoint is the mean by symmetry.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

DEFAULT_PIXELS_ACROSS = 1000   # raster resolution over the annulus diameter


def hexahedron_face_triangles(hexahedra: np.ndarray) -> np.ndarray:
    """The ventricular and aortic faces of bricks (nodes 0-3, 4-7) as triangles, for the GOA
    and profiles of a hexahedron run."""
    h = np.asarray(hexahedra)
    faces = [h[:, [0, 1, 2]], h[:, [0, 2, 3]], h[:, [4, 5, 6]], h[:, [4, 6, 7]]]
    return np.concatenate(faces)


def free_edge_radial_position(nodes: np.ndarray, midpoint_ids) -> np.ndarray:
    """Mean distance from the valve axis of the free-edge midpoints; nodes [..., N, 3]."""
    x = np.asarray(nodes)[..., np.asarray(midpoint_ids), :]
    return np.hypot(x[..., 0], x[..., 1]).mean(axis=-1)


def _covered_pixels(xy: np.ndarray, triangles: np.ndarray, origin: float, h: float, n: int) -> np.ndarray:
    """Boolean [n, n] (row = y, column = x): pixel centres inside the projection of any
    triangle. Each triangle adds +1/-1 at the ends of its x-interval on every pixel row it
    spans; a running sum along the rows then counts covering triangles per pixel."""
    p = xy[triangles]                                   # [T, 3, 2]
    ymin, ymax = p[:, :, 1].min(axis=1), p[:, :, 1].max(axis=1)
    j0 = np.maximum(np.ceil((ymin - origin) / h - 0.5).astype(np.int64), 0)
    j1 = np.minimum(np.floor((ymax - origin) / h - 0.5).astype(np.int64), n - 1)
    rows = np.maximum(j1 - j0 + 1, 0)
    tri = np.repeat(np.arange(len(triangles)), rows)
    j = j0[tri] + (np.arange(rows.sum()) - np.repeat(np.cumsum(rows) - rows, rows))
    y = origin + (j + 0.5) * h
    crossings = []
    for a, b in ((0, 1), (1, 2), (2, 0)):
        # each edge in a canonical direction (lower node id first), so that the two triangles
        # sharing it compute bit-identical crossings and leave no pixel between them
        ia, ib = triangles[tri, a], triangles[tri, b]
        pa, pb = xy[np.minimum(ia, ib)], xy[np.maximum(ia, ib)]
        spans = ((pa[:, 1] <= y) & (y < pb[:, 1])) | ((pb[:, 1] <= y) & (y < pa[:, 1]))
        dy = np.where(spans, pb[:, 1] - pa[:, 1], 1.0)
        crossings.append(np.where(spans, pa[:, 0] + (y - pa[:, 1]) * (pb[:, 0] - pa[:, 0]) / dy, np.nan))
    crossings = np.stack(crossings, axis=1)
    valid = np.isfinite(crossings).sum(axis=1) >= 2
    crossings, j = crossings[valid], j[valid]
    x0, x1 = np.nanmin(crossings, axis=1), np.nanmax(crossings, axis=1)
    i0 = np.maximum(np.ceil((x0 - origin) / h - 0.5).astype(np.int64), 0)
    i1 = np.minimum(np.floor((x1 - origin) / h - 0.5).astype(np.int64), n - 1)
    keep = i1 >= i0
    diff = np.zeros((n, n + 1), dtype=np.int32)
    np.add.at(diff, (j[keep], i0[keep]), 1)
    np.add.at(diff, (j[keep], i1[keep] + 1), -1)
    return np.cumsum(diff[:, :n], axis=1) > 0


def geometric_orifice_area(nodes: np.ndarray, triangles: np.ndarray, annulus_radius: float,
                           wedge_deg: tuple[float, float] | None = None,
                           pixels_across: int = DEFAULT_PIXELS_ACROSS) -> float:
    """GOA (m^2): area of the annulus disk r < R not covered by any triangle seen along z.
    With wedge_deg = (a, b) only the wedge a <= azimuth <= b is measured and the result is
    scaled by 360 / (b - a) (a sector run standing for the full valve).
    Pixel-centre sampling with h = 2R / pixels_across: the error is a few boundary pixels,
    about 1e-3 of a 1 cm^2 opening at the default (measured in tests/scene/test_analysis.py)."""
    R = float(annulus_radius)
    n = int(pixels_across)
    h = 2.0 * R / n
    centres = -R + (np.arange(n) + 0.5) * h
    X, Y = np.meshgrid(centres, centres)                # [row = y, column = x]
    inside = X * X + Y * Y < R * R
    scale = 1.0
    if wedge_deg is not None:
        a, b = (math.radians(w) for w in wedge_deg)
        phi = np.mod(np.arctan2(Y, X) - a, 2 * math.pi)
        inside &= phi <= (b - a)
        scale = 2 * math.pi / (b - a)
    xy = np.asarray(nodes)[:, :2]
    open_pixels = inside & ~_covered_pixels(xy, np.asarray(triangles), -R, h, n)
    return scale * h * h * float(open_pixels.sum())


def bisection_profile(nodes: np.ndarray, triangles: np.ndarray, azimuth_deg: float) -> np.ndarray:
    """The leaflet's cut by the half-plane through the axis at the given azimuth, as an
    ordered polyline [(radial coordinate, z)], from the lower end (the attachment base)
    to the other (the free edge). Pass the triangles of one leaflet."""
    a = math.radians(azimuth_deg)
    direction = np.array([math.cos(a), math.sin(a), 0.0])
    normal = np.array([-math.sin(a), math.cos(a), 0.0])
    nodes = np.asarray(nodes)
    d = nodes @ normal
    tol = 1e-12 * max(1.0, float(np.abs(nodes).max()))
    side = np.where(np.abs(d) <= tol, 0, np.sign(d)).astype(int)
    points: dict = {}
    segments = set()

    def point_id(u: int, w: int):
        if side[u] == 0:
            key = ("v", u)
            points[key] = nodes[u]
        else:
            key = ("e", min(u, w), max(u, w))
            t = d[u] / (d[u] - d[w])
            points[key] = nodes[u] + t * (nodes[w] - nodes[u])
        return key

    for tri in np.asarray(triangles):
        ends = []
        for u, w in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])):
            if side[u] == 0:
                ends.append(point_id(u, w))
            elif side[u] * side[w] < 0:
                ends.append(point_id(u, w))
        ends = list(dict.fromkeys(ends))
        if len(ends) == 2:
            segments.add(tuple(sorted(ends)))
    if not segments:
        return np.empty((0, 2))
    neighbours: dict = {}
    for u, w in segments:
        neighbours.setdefault(u, []).append(w)
        neighbours.setdefault(w, []).append(u)
    ends = [k for k, v in neighbours.items() if len(v) == 1] or list(neighbours)
    start = min(ends, key=lambda k: points[k][2])
    order, previous, current = [start], None, start
    while True:
        following = [k for k in neighbours[current] if k != previous]
        if not following or following[0] == start:
            break
        previous, current = current, following[0]
        order.append(current)
    xyz = np.array([points[k] for k in order])
    return np.stack([xyz @ direction, xyz[:, 2]], axis=1)


VALVE_EVENTS_SMOOTHING_S = 1.0e-3   # Gaussian sigma: removes the FE-only flutter (periods 1-3 ms)


@dataclass(frozen=True)
class ValveEvents:
    """Times (s) from the free-edge radial-position curve (definitions: valve_events)."""
    opening_start: float   # the steepest-rise tangent leaves the closed level
    opening_end: float     # ... and reaches the open level
    closing_start: float   # the steepest-fall tangent leaves the open level
    closing_end: float     # ... and reaches the closed level
    rvot: float            # rapid valve opening time = (r_open - r_closed) / steepest rise
    rvct: float            # rapid valve closing time = (r_open - r_closed) / steepest fall
    et: float              # ejection time = closing_end - opening_start
    r_closed: float = float("nan")   # the cycle's closed and open levels (m)
    r_open: float = float("nan")


def _crossings(t: np.ndarray, r: np.ndarray, level: float, upward: bool) -> np.ndarray:
    if upward:
        idx = np.flatnonzero((r[:-1] < level) & (r[1:] >= level))
    else:
        idx = np.flatnonzero((r[:-1] >= level) & (r[1:] < level))
    frac = (level - r[idx]) / (r[idx + 1] - r[idx])
    return t[idx] + frac * (t[idx + 1] - t[idx])


def smoothed(t: np.ndarray, r: np.ndarray, sigma: float) -> tuple[np.ndarray, np.ndarray]:
    """r(t) resampled (linearly) on a uniform grid no coarser than sigma / 5 and convolved with a
    Gaussian of standard deviation sigma (the ends continued by their values); returns (t, r)."""
    spacing = float(np.median(np.diff(t)))
    if sigma > 0:
        spacing = min(spacing, sigma / 5.0)
    grid = np.linspace(t[0], t[-1], int(round((t[-1] - t[0]) / spacing)) + 1)
    values = np.interp(grid, t, r)
    if sigma <= 0:
        return grid, values
    half = int(math.ceil(4.0 * sigma / (grid[1] - grid[0])))
    kernel = np.exp(-0.5 * (np.arange(-half, half + 1) * (grid[1] - grid[0]) / sigma) ** 2)
    padded = np.concatenate([np.full(half, values[0]), values, np.full(half, values[-1])])
    return grid, np.convolve(padded, kernel / kernel.sum(), mode="valid")


def valve_events(t, radial_position, smoothing_s: float = VALVE_EVENTS_SMOOTHING_S,
                 allow_open_end: bool = False) -> ValveEvents:
    """RVOT, RVCT, ET over one cycle of the free-edge radial position r(t) (docs/valve-scene.md,
    "Analysis"; the reference: "from the high positive/negative slope of the radial displacement
    curve", after Leyh et al. 1999).
    1. r is smoothed by a Gaussian of sigma = smoothing_s (the undamped FE-only leaflet flutters
       by +-1-2 mm at 1-3 ms periods; a step becomes a ramp of 2.5 sigma under the definition).
    2. The cycle's own levels: r_closed and r_open, the medians of the smoothed samples below and
       above the middle of its range (a cycle that starts ajar, an overshoot, rebounds and
       flutter do not move them); dr = r_open - r_closed.
    3. The opening is around the first upward crossing of r_closed + dr/2, the closing around the
       last downward one; each phase is bracketed by the 10 % and 90 % levels around it, and in
       it the steepest slope g of the smoothed curve is found.
    4. The tangent at the steepest point leaves one level and reaches the other: RVOT = dr / g
       (rise), RVCT = dr / |g| (fall); ET runs from the opening tangent's foot on r_closed to the
       closing tangent's foot on r_closed. On a piecewise-linear history these are its corners.
    allow_open_end: a history that ends before the valve closes (a run still going, or stopped)
    gives the opening's events and NaN for the closing's (closing start and end, RVCT, ET);
    r_open is then the median of what the open plateau has shown so far."""
    t = np.asarray(t, dtype=float)
    r = np.asarray(radial_position, dtype=float)
    if t.ndim != 1 or t.shape != r.shape or len(t) < 3 or np.any(np.diff(t) <= 0):
        raise ValueError("valve_events: t and radial_position must be 1-D, equally long (>= 3) and t increasing")
    if not r.max() > r.min():
        raise ValueError("valve_events: the radial position never changes; the valve did not open")
    ts, rs = smoothed(t, r, smoothing_s)
    middle = 0.5 * (rs.min() + rs.max())
    r_closed, r_open = float(np.median(rs[rs < middle])), float(np.median(rs[rs >= middle]))
    span = r_open - r_closed
    half, low, high = r_closed + 0.5 * span, r_closed + 0.1 * span, r_closed + 0.9 * span
    slope = np.gradient(rs, ts)
    ups = _crossings(ts, rs, half, True)
    if len(ups) == 0:
        raise ValueError("valve_events: r(t) never rises through half of its range (starts open?)")
    downs = _crossings(ts, rs, half, False)
    downs = downs[downs > ups[0]]
    if len(downs) == 0 and not allow_open_end:
        raise ValueError("valve_events: r(t) does not open and close within the samples given")
    rise_at = ups[0]

    def bracket(centre, before_level, before_up, after_level, after_up):
        before = _crossings(ts, rs, before_level, before_up)
        before = before[before < centre]
        after = _crossings(ts, rs, after_level, after_up)
        after = after[after > centre]
        lo = before[-1] if len(before) else ts[0]
        hi = after[0] if len(after) else ts[-1]
        return (ts >= lo) & (ts <= hi)

    rising = bracket(rise_at, low, True, high, True)
    k = int(np.flatnonzero(rising)[np.argmax(slope[rising])])
    g_up = float(slope[k])
    opening_start = ts[k] - (rs[k] - r_closed) / g_up
    opening_end = ts[k] + (r_open - rs[k]) / g_up
    if len(downs) == 0:
        if not g_up > 0:
            raise ValueError("valve_events: no rising slope found around the opening")
        nan = float("nan")
        return ValveEvents(float(opening_start), float(opening_end), nan, nan, span / g_up, nan, nan, r_closed, r_open)
    fall_at = downs[-1]
    falling = bracket(fall_at, high, False, low, False)
    k = int(np.flatnonzero(falling)[np.argmin(slope[falling])])
    g_down = -float(slope[k])
    if not (g_up > 0 and g_down > 0):
        raise ValueError("valve_events: no rising or falling slope found around the opening or closing")
    closing_start = ts[k] - (r_open - rs[k]) / g_down
    closing_end = ts[k] + (rs[k] - r_closed) / g_down
    return ValveEvents(float(opening_start), float(opening_end), float(closing_start), float(closing_end),
                       span / g_up, span / g_down, float(closing_end - opening_start), r_closed, r_open)


def kinematics(times, node_history, triangles, midpoint_ids, annulus_radius, sector: bool = False,
               pixels_across: int = DEFAULT_PIXELS_ACROSS) -> dict:
    """Time series of the free-edge radial position and GOA, and the valve events, for
    node_history [steps, N, 3]. A sector mesh is leaflet 0's half between azimuth 0 and 60 deg."""
    times = np.asarray(times, dtype=float)
    radial = free_edge_radial_position(node_history, midpoint_ids)
    wedge = (0.0, 60.0) if sector else None
    goa = np.array([geometric_orifice_area(x, triangles, annulus_radius, wedge, pixels_across) for x in node_history])
    result = {"time_s": times, "free_edge_radial_position_m": radial, "goa_m2": goa}
    try:
        result["events"] = valve_events(times, radial)
    except ValueError as error:
        result["events"] = None
        result["events_error"] = str(error)
    return result


@dataclass(frozen=True)
class FieldPeak:
    """Largest value of a per-element field and where it sits on the undeformed leaflet."""
    value: float
    element: int
    reference_centroid: np.ndarray   # (m)
    region: str                      # "commissure", "attachment", "free edge" or "belly"


def peak_with_location(values, reference_nodes, elements, node_sets, near: float = 1.0e-3,
                       commissure_radius: float = 2.0e-3) -> FieldPeak:
    """The maximum of a per-element field (e.g. max-principal stress or log strain) and the
    leaflet region of its element, judged on the reference (undeformed) mesh: within
    `commissure_radius` of a commissure top (the highest attachment nodes) -> "commissure";
    else within `near` of the attachment line -> "attachment"; of the free edge -> "free
    edge"; otherwise "belly"."""
    values = np.asarray(values, dtype=float)
    e = int(np.argmax(values))
    nodes = np.asarray(reference_nodes)
    centroid = nodes[np.asarray(elements)[e]].mean(axis=0)
    attachment = nodes[node_sets["attachment"]]
    free_edge = nodes[node_sets["free_edge"]]
    z_top = attachment[:, 2].max()
    commissure_tops = attachment[attachment[:, 2] >= z_top - 1e-9]

    def distance(points):
        return float(np.min(np.linalg.norm(points - centroid, axis=1)))

    if distance(commissure_tops) <= commissure_radius:
        region = "commissure"
    elif distance(attachment) <= near:
        region = "attachment"
    elif distance(free_edge) <= near:
        region = "free edge"
    else:
        region = "belly"
    return FieldPeak(float(values[e]), e, centroid, region)


ROBUST_PEAK_FRACTION = 0.01   # the robust peak is the value exceeded on 1 % of the leaflet area


def triangle_areas(reference_nodes, triangles) -> np.ndarray:
    """Areas of the triangles on the reference (undeformed) mesh (m^2)."""
    p = np.asarray(reference_nodes, dtype=float)[np.asarray(triangles)]
    return 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)


def area_percentile(values, areas, fraction: float = ROBUST_PEAK_FRACTION) -> float:
    """The value the field reaches on the top `fraction` of the leaflet's reference area:
    elements sorted by value (largest first), element k covering the area fraction
    (A_(k-1), A_k], the value of the element whose interval holds `fraction`. Unlike the
    maximum, one element (a mesh corner, a flutter spike) cannot move it unless it carries more
    than `fraction` of the area, and splitting elements does not change it."""
    values = np.asarray(values, dtype=float)
    areas = np.asarray(areas, dtype=float)
    if values.shape != areas.shape or values.size == 0:
        raise ValueError(f"area_percentile: {values.size} values for {areas.size} areas (need equal, > 0)")
    order = np.argsort(values, kind="stable")[::-1]
    covered = np.cumsum(areas[order]) / areas.sum()   # A_k
    k = int(np.searchsorted(covered, min(max(fraction, 0.0), 1.0) * (1 - 1e-12)))
    return float(values[order][min(k, values.size - 1)])


def robust_peak(snapshots, areas, fraction: float = ROBUST_PEAK_FRACTION) -> tuple[float, int]:
    """The largest over snapshots of area_percentile (the value exceeded on `fraction` of the
    leaflet area at that instant); returns (value, snapshot index)."""
    per_snapshot = [area_percentile(values, areas, fraction) for values in snapshots]
    if not per_snapshot:
        raise ValueError("robust_peak: no snapshots")
    k = int(np.argmax(per_snapshot))
    return per_snapshot[k], k
