"""The parametric leaflet surface of a size-23 three-leaflet valve in its nearly closed,
stress-free state (model and choices: docs/valve-scene.md, "Valve geometry").

Frame: z is the valve axis (flow from z < 0 to z > 0), the stent is the cylinder r = R, the
lowest attachment point (leaflet base) lies at z = 0. Leaflet k is centred on the azimuth
theta_k = k * 120 deg; the planes through the axis at theta_k +- 60 deg are the coaptation
(commissure) planes between neighbours. Leaflet 0 is built here and rotated for the others.

Leaflet 0 is parametrised by s in [-1, 1] (circumferential, s = 0 on its bisecting plane
y = 0, s = +-1 at the commissures) and v in [0, 1] (radial, attachment -> free edge):
  attachment A(s): on the cylinder at azimuth s*Phi, height (Hc - h_tab)(1 - cos(pi s / 2))
                   (a U-shaped suture line from the base up to the commissure tabs);
  free edge F(s):  two straight segments from the free-edge midpoint M (on the bisector, at
                   height Hm) to the commissure tops C+- (on the cylinder, at height Hc),
                   each at distance gap/2 from its coaptation plane;
  r(s, v):         the quadratic Bezier curve A -> Q -> F with Q = (1 - beta)(A + F)/2
                   + beta*K, K = F's top-view position at A's height: beta = 0 gives a
                   ruled surface, beta -> 1 a deep belly whose free-edge region hangs
                   vertically (the coaptation zone) and leaves the stent horizontally.
At s = +-1 A and F lie one above the other on the commissure post: the leaflet is sutured
along a tab of height h_tab, which keeps every grid column of finite length.
Rounded commissure: where the free edge meets the tab (at C+-, an 85 deg corner) a fillet of
radius rho, built in the surface's tangent plane at C+- and mapped onto the surface, replaces the
corner: the free edge leaves its straight line at T2 (distance d = rho / tan(alpha / 2) from C+-)
and curves down into the tab, which it meets tangentially at T1 (d below C+-). The surface is not
changed, only trimmed: the leaflet is the part of r(s, v) below the trimmed edge v <= v_top(s).
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

LEAFLET_COUNT = 3
SECTOR_HALF_ANGLE = math.pi / LEAFLET_COUNT  # 60 deg: half the angular span of a leaflet


@dataclass(frozen=True)
class ValveParameters:
    """Dimensions of the generic size-23 valve (metres)."""
    annulus_radius: float = 11.5e-3        # stent inner radius R (size 23)
    commissure_height: float = 12.0e-3     # Hc: commissure tops above the leaflet base
    tab_height: float = 5.0e-3             # h_tab: suture length along each commissure post (see docs: sets the stable step)
    free_edge_centre_height: float = 11.0e-3  # Hm: height of the free-edge midpoints
    belly: float = 0.5                     # beta in [0, 1): depth of the leaflet belly
    coaptation_gap: float = 0.5e-3         # gap between neighbouring free edges (nearly closed)
    thickness: float = 0.25e-3             # leaflet thickness
    commissure_fillet_radius: float = 0.0     # rho: rounds the free edge into the tab (0 = sharp corner; 2 mm measured, not yet robust: docs/valve-scene.md)

    def validate(self) -> None:
        checks = [
            ("annulus_radius", self.annulus_radius > 0, "> 0"),
            ("commissure_height", self.commissure_height > self.tab_height, "> tab_height"),
            ("tab_height", self.tab_height > 0, "> 0"),
            ("free_edge_centre_height", 0 < self.free_edge_centre_height <= self.commissure_height + 0.5 * self.annulus_radius, "in (0, Hc + R/2]"),
            ("belly", 0 <= self.belly < 1, "in [0, 1)"),
            ("coaptation_gap", 0 <= self.coaptation_gap < 0.2 * self.annulus_radius, "in [0, R/5)"),
            ("thickness", 0 < self.thickness < 0.1 * self.annulus_radius, "in (0, R/10)"),
        ]
        for name, ok, allowed in checks:
            if not ok:
                raise ValueError(f"valve parameter '{name}' = {getattr(self, name)!r}: allowed {allowed}")
        largest = self.largest_fillet_radius
        if not 0 <= self.commissure_fillet_radius <= largest:
            raise ValueError(f"valve parameter 'commissure_fillet_radius' = {self.commissure_fillet_radius!r}: allowed "
                             f"[0, {largest:.4g}] (the fillet's tangent points must stay on the upper half of the tab "
                             "and the outer half of the free edge)")

    @property
    def commissure_corner_angle(self) -> float:
        """alpha: the sharp corner's angle at C+ between the tab (downward) and the free edge."""
        edge = self.free_edge_midpoint - self.commissure_top(+1.0)
        return math.acos(-edge[2] / float(np.linalg.norm(edge)))

    @property
    def largest_fillet_radius(self) -> float:
        edge = float(np.linalg.norm(self.free_edge_midpoint - self.commissure_top(+1.0)))
        return 0.5 * min(self.tab_height, edge) * math.tan(0.5 * self.commissure_corner_angle)

    @property
    def leaflet_half_angle(self) -> float:
        """Phi: azimuth of leaflet 0's commissure tabs, inset so they sit gap/2 from the plane."""
        return SECTOR_HALF_ANGLE - math.asin(0.5 * self.coaptation_gap / self.annulus_radius)

    @property
    def free_edge_midpoint(self) -> np.ndarray:
        """M: on the bisector, gap/2 from both coaptation planes."""
        offset = 0.5 * self.coaptation_gap / math.sin(SECTOR_HALF_ANGLE)
        return np.array([offset, 0.0, self.free_edge_centre_height])

    def commissure_top(self, side: float) -> np.ndarray:
        """C+ (side = +1) or C- (side = -1) of leaflet 0."""
        phi = side * self.leaflet_half_angle
        R = self.annulus_radius
        return np.array([R * math.cos(phi), R * math.sin(phi), self.commissure_height])


def attachment_point(p: ValveParameters, s: np.ndarray) -> np.ndarray:
    """A(s) on the stent cylinder, shape (..., 3)."""
    s = np.asarray(s, dtype=float)
    phi = s * p.leaflet_half_angle
    z = (p.commissure_height - p.tab_height) * (1.0 - np.cos(0.5 * math.pi * s))
    R = p.annulus_radius
    return np.stack([R * np.cos(phi), R * np.sin(phi), z], axis=-1)


def free_edge_point(p: ValveParameters, s: np.ndarray) -> np.ndarray:
    """F(s): straight from M (s = 0) to the commissure top C+- (s = +-1)."""
    s = np.asarray(s, dtype=float)
    m = p.free_edge_midpoint
    c_plus, c_minus = p.commissure_top(+1.0), p.commissure_top(-1.0)
    target = np.where((s >= 0)[..., None], c_plus, c_minus)
    return m + np.abs(s)[..., None] * (target - m)


def belly_control_point(p: ValveParameters, a: np.ndarray, f: np.ndarray) -> np.ndarray:
    corner = np.concatenate([f[..., :2], a[..., 2:3]], axis=-1)
    return (1.0 - p.belly) * 0.5 * (a + f) + p.belly * corner


def leaflet_point(p: ValveParameters, s, v) -> np.ndarray:
    """r(s, v) of leaflet 0, broadcasting s and v."""
    s, v = np.broadcast_arrays(np.asarray(s, dtype=float), np.asarray(v, dtype=float))
    a = attachment_point(p, s)
    f = free_edge_point(p, s)
    q = belly_control_point(p, a, f)
    v = v[..., None]
    return (1 - v) ** 2 * a + 2 * v * (1 - v) * q + v ** 2 * f


def rotation_about_axis(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def leaflet_rotation(k: int) -> np.ndarray:
    """Maps leaflet 0 onto leaflet k."""
    return rotation_about_axis(2.0 * math.pi * k / LEAFLET_COUNT)


def leaflet_surface_area(p: ValveParameters, order: int = 48) -> float:
    """Area of one leaflet by Gauss-Legendre quadrature of |r_s x r_v| over the trimmed domain
    0 <= v <= v_top(s), on each half (the free edge has a corner at s = 0) and, with a rounded
    commissure, separately inside and outside the fillet's s-range (v_top has a kink at T2)."""
    nodes, weights = np.polynomial.legendre.leggauss(order)
    fillet = commissure_fillet(p)
    pieces = [(0.0, fillet.s_free_end)] + ([(fillet.s_free_end, 1.0)] if fillet.radius > 0 else [])
    area = 0.0
    for s_lo, s_hi in pieces:
        s = 0.5 * (s_hi - s_lo) * nodes + 0.5 * (s_hi + s_lo)
        top = np.array([fillet.free_edge_v(x) for x in s])
        xi = 0.5 * nodes + 0.5
        S, XI = np.meshgrid(s, xi, indexing="ij")
        V = top[:, None] * XI
        h = 1e-6
        r_s = (leaflet_point(p, S + h, V) - leaflet_point(p, S - h, V)) / (2 * h)
        r_v = (leaflet_point(p, S, V + h) - leaflet_point(p, S, V - h)) / (2 * h)
        jac = np.linalg.norm(np.cross(r_s, r_v), axis=-1) * top[:, None]
        w = np.outer(weights * 0.5 * (s_hi - s_lo), weights * 0.5)
        area += 2.0 * float((w * jac).sum())      # the two halves are mirror images
    return area


@dataclass(frozen=True)
class CommissureFillet:
    """The rounded commissure of leaflet 0 in parameter space (s >= 0; mirrored for s < 0).
    The arc runs from T1 on the tab (s = 1, v = v_tab_end) to T2 on the straight free edge
    (s = s_free_end, v = 1), sampled uniformly in its angle phi in [0, sweep]: (arc_s, arc_v)."""
    radius: float
    tangent_distance: float      # d: |C T1| = |C T2|
    sweep: float                 # pi - alpha: the arc's angle
    s_free_end: float            # s of T2
    v_tab_end: float             # v of T1 on the tab column s = 1
    arc_s: np.ndarray
    arc_v: np.ndarray

    @property
    def arc_length(self) -> float:
        return self.radius * self.sweep

    def arc_point(self, arc_length_from_t1) -> tuple[np.ndarray, np.ndarray]:
        """(s, v) of the arc points at the given lengths from T1."""
        phi = np.linspace(0.0, self.sweep, len(self.arc_s))
        angle = np.asarray(arc_length_from_t1, dtype=float) / self.radius
        return np.interp(angle, phi, self.arc_s), np.interp(angle, phi, self.arc_v)

    def free_edge_v(self, s_abs: float) -> float:
        """v of the trimmed free edge at |s| (1 outside the fillet; the tangent point on the tab at s = 1)."""
        if self.radius == 0.0 or s_abs <= self.s_free_end:
            return 1.0
        order = np.argsort(self.arc_s)
        return float(np.interp(min(s_abs, 1.0), self.arc_s[order], self.arc_v[order]))


def tab_v_at_height(p: ValveParameters, z):
    """v on the tab column s = 1 (a vertical segment, z increasing with v) at height(s) z."""
    z = np.atleast_1d(np.asarray(z, dtype=float))
    lo, hi = np.zeros_like(z), np.ones_like(z)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        below = leaflet_point(p, np.ones_like(mid), mid)[..., 2] < z
        lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
    return 0.5 * (lo + hi)


@functools.lru_cache(maxsize=16)
def commissure_fillet(p: ValveParameters, samples: int = 401) -> CommissureFillet:
    """The fillet of radius p.commissure_fillet_radius at C+: a circular arc tangent to the tab
    and to the straight free edge in the tangent plane there (spanned by the two), each arc point
    mapped onto the surface as the point r(s, v) whose projection on that plane it is (Newton)."""
    rho = p.commissure_fillet_radius
    alpha = p.commissure_corner_angle
    if rho == 0.0:
        return CommissureFillet(0.0, 0.0, math.pi - alpha, 1.0, 1.0, np.array([1.0, 1.0]), np.array([1.0, 1.0]))
    corner = p.commissure_top(+1.0)
    down = np.array([0.0, 0.0, -1.0])
    along = p.free_edge_midpoint - corner
    edge_length = float(np.linalg.norm(along))
    along /= edge_length
    d = rho / math.tan(0.5 * alpha)
    bisector = (down + along) / np.linalg.norm(down + along)
    centre = corner + rho / math.sin(0.5 * alpha) * bisector
    t1, t2 = corner + d * down, corner + d * along
    u = (t1 - centre) / rho
    w = t2 - centre
    w = w - (w @ u) * u
    w /= np.linalg.norm(w)
    sweep = math.pi - alpha
    phi = np.linspace(0.0, sweep, samples)
    arc = centre + rho * (np.cos(phi)[:, None] * u + np.sin(phi)[:, None] * w)
    # orthonormal basis of the tangent plane at the corner (the surface's r_v and r_s span it)
    b = along - (along @ down) * down
    basis = np.stack([down, b / np.linalg.norm(b)])

    def chart(s, v):
        return basis @ (leaflet_point(p, s, v) - corner)

    v_t1 = float(tab_v_at_height(p, corner[2] - d)[0])
    s_t2 = 1.0 - d / edge_length
    out_s, out_v = np.empty(samples), np.empty(samples)
    s, v = 1.0, v_t1
    h = 1e-7
    for k, point in enumerate(arc):
        target = basis @ (point - corner)
        for _ in range(30):
            residual = chart(s, v) - target
            if np.linalg.norm(residual) < 1e-13:
                break
            jac = np.column_stack([(chart(s + h, v) - chart(s - h, v)) / (2 * h),
                                   (chart(s, v + h) - chart(s, v - h)) / (2 * h)])
            s, v = np.array([s, v]) - np.linalg.solve(jac, residual)
        else:
            raise RuntimeError(f"commissure fillet (radius {rho!r} m): the arc point {k} does not map onto the leaflet surface")
        out_s[k], out_v[k] = s, v
    out_s[0], out_v[0] = 1.0, v_t1          # the tangent points exactly
    out_s[-1], out_v[-1] = s_t2, 1.0
    return CommissureFillet(rho, d, sweep, s_t2, v_t1, out_s, out_v)
