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
"""
from __future__ import annotations

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
    """Area of one leaflet by Gauss-Legendre quadrature of |r_s x r_v| on each half (the
    free edge has a corner at s = 0, so each half is smooth)."""
    nodes, weights = np.polynomial.legendre.leggauss(order)
    area = 0.0
    for s_lo, s_hi in ((-1.0, 0.0), (0.0, 1.0)):
        s = 0.5 * (s_hi - s_lo) * nodes + 0.5 * (s_hi + s_lo)
        v = 0.5 * nodes + 0.5
        S, V = np.meshgrid(s, v, indexing="ij")
        h = 1e-6
        r_s = (leaflet_point(p, S + h, V) - leaflet_point(p, S - h, V)) / (2 * h)
        r_v = (leaflet_point(p, S, V + h) - leaflet_point(p, S, V - h)) / (2 * h)
        jac = np.linalg.norm(np.cross(r_s, r_v), axis=-1)
        w = np.outer(weights * 0.5 * (s_hi - s_lo), weights * 0.5)
        area += float((w * jac).sum())
    return area
