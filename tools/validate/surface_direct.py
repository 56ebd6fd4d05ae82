#!/usr/bin/env python3
"""Direct solve of the minimum-curvature-with-tension system (Smith & Wessel 1990).

An iterative gridder (aeromag's `MinCurvature`, GMT `surface`) stops at a
convergence limit; this script solves the same finite-difference equations
exactly (SciPy sparse LU, float64), so two iterative grids can be scored
against the solution they both approximate.

Equations (unit node spacing, tension T), on the nodes of the region plus two
rows of ghost nodes on each side:
- node without data: (1-T)(20 z0 - 8 S1 + 2 S2 + S3) - T(S1 - 4 z0) = 0;
- node with a data point at offset (dx, dy) (the block mean nearest to it):
  the same with the node's Laplacian replaced by the estimate exact for
  quadratics through the data and four nodes on the far side (Briggs 1974);
  within 0.05 node of the node the data value is taken at the node;
- edges: (1-T) d2z/dn2 + T dz/dn = 0, d(lap z)/dn = 0; corners d2z/dxdy = 0.
A least-squares plane is removed from the data and added back.

Usage: surface_direct.py BLOCKMEANS.xyz WEST SOUTH CELL NX NY TENSION > GRID.xyz
(BLOCKMEANS: `x y z`, at most one point per node, e.g. from `gmt blockmean`;
NX, NY: nodes; output `x y z` per node, rows from the south).
"""
import sys

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spl


def laplacian_weights(dx, dy):
    """Nodes (offsets) and weights of the Laplacian estimate at a data node."""
    sx = 1 if dx >= 0 else -1
    sy = 1 if dy >= 0 else -1
    nodes = [(-sx, 0), (0, -sy), (sx, -sy), (-sx, sy)]
    m = np.array([[a, b, a * a / 2, b * b / 2, a * b] for a, b in nodes + [(dx, dy)]]).T
    return nodes, np.linalg.solve(m, np.array([0, 0, 1, 1, 0.0]))


def main():
    path, west, south, cell, nx, ny, t = sys.argv[1:8]
    west, south, cell, t = float(west), float(south), float(cell), float(t)
    nx, ny = int(nx), int(ny)
    pts = np.loadtxt(path, ndmin=2)
    u, v, z = (pts[:, 0] - west) / cell, (pts[:, 1] - south) / cell, pts[:, 2]
    plane = np.linalg.lstsq(np.c_[np.ones_like(u), u, v], z, rcond=None)[0]
    data = {}
    for uu, vv, zz in zip(u, v, z):
        i, j = int(np.floor(uu + 0.5)), int(np.floor(vv + 0.5))
        if 0 <= i < nx and 0 <= j < ny:
            if (i, j) in data:
                sys.exit(f"two points at node ({i}, {j}): give block means")
            data[(i, j)] = (uu - i, vv - j, zz)

    unknown = {}
    rows, rhs = [], []

    def equation(terms, value=0.0):
        for node, _ in terms:
            unknown.setdefault(node, len(unknown))
        rows.append(terms)
        rhs.append(value)

    loose = 1.0 - t
    for i in range(nx):
        for j in range(ny):
            around = [((i + a, j + b), 4 * loose) for a, b in [(1, 0), (-1, 0), (0, 1), (0, -1)]]
            around += [((i + a, j + b), -2 * loose) for a, b in [(1, 1), (-1, 1), (1, -1), (-1, -1)]]
            around += [((i + a, j + b), -loose) for a, b in [(2, 0), (-2, 0), (0, 2), (0, -2)]]
            if (i, j) not in data:
                near = [((i + a, j + b), 4 - 3 * t) for a, b in [(1, 0), (-1, 0), (0, 1), (0, -1)]]
                equation(around + near + [((i, j), -(20 - 16 * t))])
                continue
            dx, dy, zz = data[(i, j)]
            if abs(dx) < 0.05 and abs(dy) < 0.05:
                equation([((i, j), 1.0)], zz - (plane[0] + plane[1] * i + plane[2] * j))
                continue
            zr = zz - (plane[0] + plane[1] * (i + dx) + plane[2] * (j + dy))
            nodes, w = laplacian_weights(dx, dy)
            terms = around + [((i + a, j + b), (4 - 3 * t) * c) for (a, b), c in zip(nodes, w[:4])]
            terms.append(((i, j), -(4 * loose + (4 - 3 * t) * w.sum())))
            equation(terms, -(4 - 3 * t) * w[4] * zr)

    c0, c1 = 4 * loose / (2 - t), (3 * t - 2) / (2 - t)
    mx, my = nx - 1, ny - 1
    for i in range(nx):  # first ghost rows
        equation([((i, -1), 1), ((i, 0), -c0), ((i, 1), -c1)])
        equation([((i, my + 1), 1), ((i, my), -c0), ((i, my - 1), -c1)])
    for j in range(ny):
        equation([((-1, j), 1), ((0, j), -c0), ((1, j), -c1)])
        equation([((mx + 1, j), 1), ((mx, j), -c0), ((mx - 1, j), -c1)])
    for ci, cj, si, sj in [(0, 0, -1, -1), (0, my, -1, 1), (mx, 0, 1, -1), (mx, my, 1, 1)]:
        equation([((ci + si, cj + sj), 1), ((ci - si, cj + sj), -1), ((ci + si, cj - sj), -1), ((ci - si, cj - sj), 1)])
    for i in range(nx):  # second ghost rows: the Laplacian continues across the edge
        for j, s in [(0, -1), (my, 1)]:
            equation([((i, j + 2 * s), 1), ((i, j - 2 * s), -1), ((i - 1, j - s), -1), ((i + 1, j - s), -1),
                      ((i - 1, j + s), 1), ((i + 1, j + s), 1), ((i, j + s), -4), ((i, j - s), 4)])
    for j in range(ny):
        for i, s in [(0, -1), (mx, 1)]:
            equation([((i + 2 * s, j), 1), ((i - 2 * s, j), -1), ((i - s, j + 1), -1), ((i - s, j - 1), -1),
                      ((i + s, j + 1), 1), ((i + s, j - 1), 1), ((i + s, j), -4), ((i - s, j), 4)])

    r, c, val = [], [], []
    for k, terms in enumerate(rows):
        for node, coef in terms:
            r.append(k)
            c.append(unknown[node])
            val.append(coef)
    a = sp.csc_matrix((val, (r, c)), shape=(len(rows), len(unknown)))
    sol = spl.spsolve(a, np.array(rhs))
    residual = np.abs(a @ sol - np.array(rhs)).max()
    print(f"{len(unknown)} unknowns, largest equation residual {residual:.2e}", file=sys.stderr)
    for j in range(ny):
        for i in range(nx):
            zz = sol[unknown[(i, j)]] + plane[0] + plane[1] * i + plane[2] * j
            print(f"{west + i * cell:.6f} {south + j * cell:.6f} {zz:.9f}")


if __name__ == "__main__":
    main()
