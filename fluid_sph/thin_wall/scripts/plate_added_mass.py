#!/usr/bin/python3
"""Potential-flow added mass of a thin plate (width b) moving normal to itself in the middle
of a closed rectangular box (L along the motion, H along the plate), per unit depth.

Finite volumes on a uniform grid with the plate on a line of cell faces: faces on the plate
carry the plate's normal velocity U on both sides, box faces carry none. The added mass is
twice the kinetic energy over U^2: m = rho * sum over faces of (grad phi)^2 * area.
Printed as the ratio to the unbounded value rho pi (b/2)^2, for a sequence of grids
(Richardson-extrapolated), so the box's correction to the SPH test is known exactly.
"""
import argparse
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla


def added_mass_ratio(b, L, H, cells_per_b):
    return solve(b, L, H, cells_per_b)[0]


def potential_field(b, L, H, cells_per_b):
    """Velocity potential per unit plate velocity at the cell centres (ny x nx, mean zero),
    plate at x = 0 moving towards +x; cell centre coordinates x, y."""
    phi = solve(b, L, H, cells_per_b)[1]
    h = b / cells_per_b
    x = (np.arange(phi.shape[1]) + 0.5) * h - L / 2
    y = (np.arange(phi.shape[0]) + 0.5) * h - H / 2
    return phi - phi.mean(), x, y


def solve(b, L, H, cells_per_b):
    h = b / cells_per_b
    nx = int(round(L / h))
    ny = int(round(H / h))
    assert nx % 2 == 0 and ny % 2 == 0 and cells_per_b % 2 == 0
    idx = lambda i, j: j * nx + i
    n = nx * ny
    rows, cols, vals = [], [], []
    rhs = np.zeros(n)
    ip = nx // 2  # plate on the face between columns ip-1 and ip (x = 0)
    jlo, jhi = ny // 2 - cells_per_b // 2, ny // 2 + cells_per_b // 2  # plate spans rows [jlo, jhi)
    U = 1.0
    for j in range(ny):
        for i in range(nx):
            k = idx(i, j)
            diag = 0.0
            for di, dj in ((1, 0), (-1, 0), (0, 1), (0, -1)):
                ii, jj = i + di, j + dj
                if ii < 0 or ii >= nx or jj < 0 or jj >= ny:
                    continue  # box wall: no flux
                on_plate = dj == 0 and jlo <= j < jhi and ((di == 1 and i == ip - 1) or (di == -1 and i == ip))
                if on_plate:
                    # Outflow through the face = U h (left cell) or -U h (right cell), in units of h.
                    rhs[k] -= U * h * (1 if di == 1 else -1)
                    continue
                rows.append(k); cols.append(idx(ii, jj)); vals.append(1.0)
                diag -= 1.0
            rows.append(k); cols.append(k); vals.append(diag)
    A = sp.csr_matrix((vals, (rows, cols)), shape=(n, n))
    # Pure Neumann: pin one value (the system is compatible, net plate flux is zero).
    A = A.tolil(); A[0, :] = 0; A[0, 0] = 1; rhs[0] = 0; A = A.tocsr()
    phi = spla.spsolve(A, rhs).reshape(ny, nx)
    # Energy: sum over interior faces not on the plate of (delta phi)^2 (grad^2 * h^2 area-weighted).
    dx = np.diff(phi, axis=1)  # faces between columns
    mask = np.ones_like(dx, dtype=bool)
    mask[jlo:jhi, ip - 1] = False
    dy = np.diff(phi, axis=0)
    energy2 = (dx[mask] ** 2).sum() + (dy ** 2).sum()  # = integral |grad phi|^2 (h^2 cancels)
    return energy2 / (U * U) / (np.pi * (b / 2) ** 2), phi


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--b", type=float, default=0.1)
    ap.add_argument("--L", type=float, default=0.4)
    ap.add_argument("--H", type=float, default=0.4)
    ap.add_argument("--cells", type=int, nargs="+", default=[20, 40, 80])
    a = ap.parse_args()
    ratios = [added_mass_ratio(a.b, a.L, a.H, c) for c in a.cells]
    for c, r in zip(a.cells, ratios):
        print(f"b/h = {c:4d}: m / (rho pi b^2/4) = {r:.5f}")
    if len(ratios) >= 3:
        r1, r2, r3 = ratios[-3:]
        order = np.log((r2 - r1) / (r3 - r2)) / np.log(2)
        extrap = r3 + (r3 - r2) / (2 ** order - 1)
        print(f"observed order {order:.2f}; extrapolated {extrap:.5f}")


if __name__ == "__main__":
    main()
