#!/usr/bin/python3
"""Potential-flow added mass of a thin disk (radius a) moving normal to itself (along x) in the
middle of a closed cubic box of side L, as the ratio to the unbounded value (8/3) rho a^3: the
box's correction to the SPH disk test (thin_wall_3d --scene disk, docs/thin-leaflet.md).

Finite volumes on a uniform grid of one octant (x, y, z >= 0): the potential is odd in x (zero
on the plane x = 0 beyond the disk) and even in y and z (no flux through y = 0, z = 0); the
disk lies on the plane x = 0, where a face carries the disk's normal velocity U on the part of
its area inside the circle and the odd symmetry's zero potential on the rest; the box's faces
carry no flux. The added mass is twice the kinetic energy over U^2, eight octants. The disk's
edge singularity makes the error first order in h; the script prints each grid and a
Richardson extrapolation of the last three, for the box and (--reference) a larger box, whose
ratio is the correction with most of the discretisation error cancelled.
"""
import argparse
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla


def disk_face_fraction(y_lo, z_lo, h, a, sides=0, sub=8):
    """Fraction of the square face [y_lo, y_lo + h] x [z_lo, z_lo + h] inside the circle r < a,
    or (sides > 0) inside the regular polygon inscribed in it with a vertex on the +y axis, as
    the SPH scene's meshes are (sub x sub sample points)."""
    s = (np.arange(sub) + 0.5) / sub * h
    yy = y_lo[..., None, None] + s[:, None]
    zz = z_lo[..., None, None] + s[None, :]
    if sides <= 0:
        return ((yy ** 2 + zz ** 2) < a * a).mean(axis=(-1, -2))
    # Inside the polygon: the projection on the normal of the point's sector's side is below
    # the apothem a cos(pi / n).
    sector = 2.0 * np.pi / sides
    angle = np.mod(np.arctan2(zz, yy), sector) - 0.5 * sector
    r = np.hypot(yy, zz)
    return (r * np.cos(angle) < a * np.cos(0.5 * sector)).mean(axis=(-1, -2))


def added_mass_ratio(a, L, cells_per_a, sides=0):
    h = a / cells_per_a
    n = int(round(L / 2 / h))  # cells per octant edge
    shape = (n, n, n)  # index order (i: x, j: y, k: z)
    idx = np.arange(n ** 3).reshape(shape)
    rows, cols, vals = [], [], []
    diag = np.zeros(shape)
    # Interior faces along each axis: coupling -1 off the diagonal, +1 on it (negative Laplacian).
    for axis in range(3):
        lo = [slice(None)] * 3
        hi = [slice(None)] * 3
        lo[axis] = slice(0, n - 1)
        hi[axis] = slice(1, n)
        p, q = idx[tuple(lo)].ravel(), idx[tuple(hi)].ravel()
        rows += [p, q]
        cols += [q, p]
        vals += [-np.ones(p.size), -np.ones(p.size)]
        diag[tuple(lo)] += 1.0
        diag[tuple(hi)] += 1.0
    # The plane x = 0: fraction f of each face is the disk (flux U), 1 - f the odd symmetry's
    # phi = 0 at h/2 from the cell centre (coefficient 2).
    y_lo = np.arange(n)[:, None] * h * np.ones((1, n))
    z_lo = np.arange(n)[None, :] * h * np.ones((n, 1))
    f = disk_face_fraction(y_lo, z_lo, h, a, sides)
    diag[0] += 2.0 * (1.0 - f)
    U = 1.0
    rhs = np.zeros(shape)
    # Outward flux balance per cell over h: sum (phi_nb - phi) - 2 (1 - f) phi - f U h = 0.
    rhs[0] = -f * U * h
    rows.append(idx.ravel())
    cols.append(idx.ravel())
    vals.append(diag.ravel())
    A = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n ** 3, n ** 3))
    inv_diag = 1.0 / A.diagonal()
    M = spla.LinearOperator(A.shape, lambda v: v * inv_diag)  # Jacobi
    phi, info = spla.cg(A, rhs.ravel(), tol=1e-10, maxiter=50000, M=M)
    if info != 0:
        raise SystemExit(f"cg did not converge ({info}) at a/h = {cells_per_a}, L = {L}")
    phi = phi.reshape(shape)
    # Energy integral of |grad phi|^2 over the octant: interior faces (d phi)^2 h, plane faces
    # off the disk 2 phi^2 h (gradient phi / (h/2) over a half cell); h^2 area x h.
    energy = sum((np.diff(phi, axis=ax) ** 2).sum() for ax in range(3)) * h
    energy += (2.0 * (1.0 - f) * phi[0] ** 2).sum() * h
    # The Green identity on the discrete system (phi^T A phi = phi^T rhs) gives the same number
    # from the disk's faces alone: a check on the solve.
    green = -(f * phi[0]).sum() * U * h * h
    m_total = 8.0 * green / (U * U)  # rho = 1
    return m_total / (8.0 / 3.0 * a ** 3), 8.0 * energy / (8.0 / 3.0 * a ** 3)


def richardson(values):
    r1, r2, r3 = values[-3:]
    order = np.log(abs((r2 - r1) / (r3 - r2))) / np.log(2)
    return order, r3 + (r3 - r2) / (2 ** order - 1)


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--a", type=float, default=0.05)
    ap.add_argument("--L", type=float, default=0.3, help="box side (m)")
    ap.add_argument("--reference", type=float, default=0.0, help="a larger box side (m) for the ratio")
    ap.add_argument("--sides", type=int, default=0, help="a regular polygon inscribed in the circle (the mesh's rim) instead")
    ap.add_argument("--cells", type=int, nargs="+", default=[4, 8, 16], help="cells per a (each twice the last for Richardson)")
    a = ap.parse_args()
    for L in [a.L] + ([a.reference] if a.reference > 0 else []):
        ratios = []
        for c in a.cells:
            green, energy = added_mass_ratio(a.a, L, c, a.sides)
            ratios.append(green)
            print(f"sides {a.sides or 'circle'}, L/a = {L / a.a:.1f}, a/h = {c:3d}: m / ((8/3) rho a^3) = {green:.5f} (energy form {energy:.5f})", flush=True)
        if len(ratios) >= 3:
            order, extrap = richardson(ratios)
            print(f"L/a = {L / a.a:.1f}: observed order {order:.2f}; extrapolated {extrap:.5f}")


if __name__ == "__main__":
    main()
