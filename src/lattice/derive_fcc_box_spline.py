#!/usr/bin/env python3
"""Derives the polynomial pieces of the six-direction box spline on the FCC
lattice in exact rational arithmetic and writes src/lattice/FccBoxSplinePieces.h.

The box spline (de Boor, Hoellig & Riemenschneider, "Box Splines", 1993,
ch. I) of the six FCC nearest-neighbour directions

    Xi = {(1,1,0), (1,-1,0), (1,0,1), (1,0,-1), (0,1,1), (0,1,-1)}

is the density of sum_i t_i xi_i with t_i uniform on [0,1]. Split Xi into two
bases A = {(1,1,0), (1,-1,0), (1,0,1)} and B = {(1,0,-1), (0,1,1), (0,1,-1)}
(|det A| = |det B| = 2): M_Xi = M_A * M_B, M_A = chi(A[0,1)^3) / 2, so with
y = A s

    K(x) = 2 M_Xi(x + c) = vol{ s in [0,1]^3 : 0 <= B^-1 (x + c - A s) <= 1 }

where c = (sum xi) / 2 centres it and the factor 2 (the FCC lattice's
determinant) makes its FCC shifts a partition of unity (Kim, Entezari &
Peters, "Box spline reconstruction on the face-centered cubic lattice", IEEE
TVCG 14(6) 2008: the 6-direction box spline, cubic, C1, approximation order 3).

Its knot planes are x, y, z in Z and x +- y +- z odd: the unit cube with an
even lower corner splits into four corner tetrahedra at its even corners and
one central tetrahedron; a cube with an odd lower corner is the point
reflection of an even one (Kim, "GPU isosurface raycasting of FCC datasets",
Graphical Models 75(2) 2013; summarised in Sarfaraz & Shaban 2015, 4.2). A
lattice symmetry maps every corner tetrahedron onto the one at the origin, so
two reference pieces remain:

    corner:  v in [0,1]^3, x + y + z <= 1
    central: v in [0,1]^3, x+y+z >= 1, x+y-z <= 1, x-y+z <= 1, -x+y+z <= 1

For each piece and each FCC point j whose shifted spline is not zero there,
K(v - j) restricted to the piece is a cubic; this script finds it by exact
interpolation at 20 unisolvent points (the cubic's Bernstein-Bezier domain
points, shrunk towards the centroid) and checks it at 12 more random points
of the piece, so a piece that is not one polynomial fails loudly. Volumes are
computed by clipping the unit cube with Fractions: no rounding anywhere.
(Kim & Peters, "Fast and stable evaluation of box-splines via the BB-form",
Numerical Algorithms 2009, tabulate the pieces in the same spirit.)

Usage: src/lattice/derive_fcc_box_spline.py [--check]
"""

import math
import os
import random
import subprocess
import sys
from fractions import Fraction as F

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "FccBoxSplinePieces.h")

A = [(1, 1, 0), (1, -1, 0), (1, 0, 1)]
B = [(1, 0, -1), (0, 1, 1), (0, 1, -1)]
CENTRE = tuple(F(sum(d[a] for d in A + B), 2) for a in range(3))

# Monomials x^a y^b z^c of total degree <= 3, by degree then lexicographic.
MONOMIALS = [(a, b, c) for deg in range(4) for a in range(deg, -1, -1)
             for b in range(deg - a, -1, -1) for c in [deg - a - b]]


def cols(vs):
    """Matrix with the vectors vs as columns (rows list)."""
    return [[F(vs[c][r]) for c in range(3)] for r in range(3)]


def det3(m):
    return (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
            m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
            m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))


def inv3(m):
    d = det3(m)
    r = [[None] * 3 for _ in range(3)]
    for i in range(3):
        for j in range(3):
            a = [[m[x][y] for y in range(3) if y != i] for x in range(3) if x != j]
            r[i][j] = (a[0][0] * a[1][1] - a[0][1] * a[1][0]) * (-1) ** (i + j) / d
    return r


def matvec(m, v):
    return tuple(sum(m[r][c] * v[c] for c in range(3)) for r in range(3))


def matmul(a, b):
    return [[sum(a[r][k] * b[k][c] for k in range(3)) for c in range(3)] for r in range(3)]


MA, MB = cols(A), cols(B)
assert abs(det3(MA)) == 2 and abs(det3(MB)) == 2
MB_INV = inv3(MB)
C = matmul(MB_INV, MA)  # B^-1 A


def sub(p, q):
    return tuple(a - b for a, b in zip(p, q))


def dot(p, q):
    return sum(a * b for a, b in zip(p, q))


def cross(p, q):
    return (p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0])


def unit_cube():
    v = [tuple(F(b) for b in (x, y, z)) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
    idx = lambda x, y, z: 4 * x + 2 * y + z
    faces = [[(0, 0, 0), (0, 1, 0), (0, 1, 1), (0, 0, 1)], [(1, 0, 0), (1, 0, 1), (1, 1, 1), (1, 1, 0)],
             [(0, 0, 0), (0, 0, 1), (1, 0, 1), (1, 0, 0)], [(0, 1, 0), (1, 1, 0), (1, 1, 1), (0, 1, 1)],
             [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], [(0, 0, 1), (0, 1, 1), (1, 1, 1), (1, 0, 1)]]
    return [[v[idx(*c)] for c in f] for f in faces]


def clip(faces, n, d):
    """Keeps the part of a convex polyhedron (faces as vertex cycles) where n.s <= d."""
    out, on_plane = [], set()
    for face in faces:
        poly = []
        for i, p in enumerate(face):
            q = face[(i + 1) % len(face)]
            dp, dq = dot(n, p) - d, dot(n, q) - d
            if dp <= 0:
                poly.append(p)
                if dp == 0:
                    on_plane.add(p)
            if (dp < 0 < dq) or (dq < 0 < dp):
                t = dp / (dp - dq)
                x = tuple(a + t * (b - a) for a, b in zip(p, q))
                poly.append(x)
                on_plane.add(x)
        if len(poly) >= 3:
            out.append(poly)
    if len(on_plane) >= 3:
        pts = list(on_plane)
        g = tuple(sum(p[a] for p in pts) / len(pts) for a in range(3))
        e1 = sub(pts[0], g)
        e2 = cross(n, e1)
        # Floats only order the cap's corners; the volume stays exact.
        pts.sort(key=lambda p: math.atan2(float(dot(sub(p, g), e2)), float(dot(sub(p, g), e1))))
        out.append(pts)
    return out


def volume(faces):
    verts = {p for f in faces for p in f}
    if len(verts) < 4:
        return F(0)
    g = tuple(sum(p[a] for p in verts) / len(verts) for a in range(3))
    vol = F(0)
    for f in faces:
        for i in range(1, len(f) - 1):
            vol += abs(dot(sub(f[0], g), cross(sub(f[i], g), sub(f[i + 1], g))))
    return vol / 6


def kernel(x):
    """K(x): the centred, FCC-normalised six-direction box spline, exactly."""
    b = matvec(MB_INV, tuple(xa + ca for xa, ca in zip(x, CENTRE)))
    faces = unit_cube()
    for r in range(3):
        row = tuple(C[r])
        faces = clip(faces, row, b[r])  # (B^-1 A s)_r <= b_r
        faces = clip(faces, tuple(-a for a in row), 1 - b[r])  # (B^-1 A s)_r >= b_r - 1
        if not faces:
            return F(0)
    return volume(faces)


CORNER = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
CENTRAL = [(1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 1)]


def lerp_tet(tet, w):
    return tuple(sum(F(w[i]) * tet[i][a] for i in range(4)) for a in range(3))


def fit_points(tet):
    g = lerp_tet(tet, [F(1, 4)] * 4)
    pts = []
    for i in range(4):
        for j in range(4 - i):
            for k in range(4 - i - j):
                p = lerp_tet(tet, [F(i, 3), F(j, 3), F(k, 3), F(3 - i - j - k, 3)])
                pts.append(tuple(ga + (pa - ga) / 2 for ga, pa in zip(g, p)))
    return pts


def check_points(tet, rng, n=12):
    pts = []
    for _ in range(n):
        w = [F(rng.randint(1, 97)) for _ in range(4)]
        s = sum(w)
        pts.append(lerp_tet(tet, [x / s for x in w]))
    return pts


def mono(p, e):
    return p[0] ** e[0] * p[1] ** e[1] * p[2] ** e[2]


def solve(m, rhs):
    n = len(m)
    a = [row[:] + [r] for row, r in zip(m, rhs)]
    for c in range(n):
        piv = next(r for r in range(c, n) if a[r][c] != 0)
        a[c], a[piv] = a[piv], a[c]
        for r in range(n):
            if r != c and a[r][c] != 0:
                f = a[r][c] / a[c][c]
                a[r] = [x - f * y for x, y in zip(a[r], a[c])]
    return [a[r][n] / a[r][r] for r in range(n)]


def pieces(tet, rng):
    fit = fit_points(tet)
    chk = check_points(tet, rng)
    vander = [[mono(p, e) for e in MONOMIALS] for p in fit]
    result = []
    for i in range(-3, 4):
        for j in range(-3, 4):
            for k in range(-3, 4):
                if (i + j + k) % 2:
                    continue
                lat = (i, j, k)
                vals = [kernel(sub(p, lat)) for p in fit]
                if all(v == 0 for v in vals):
                    coef = [F(0)] * len(MONOMIALS)
                else:
                    coef = solve(vander, vals)
                for p in chk:
                    exact = kernel(sub(p, lat))
                    poly = sum(c * mono(p, e) for c, e in zip(coef, MONOMIALS))
                    if exact != poly:
                        sys.exit(f"K(. - {lat}) is not one cubic on {tet}: {exact} != {poly}")
                if any(c != 0 for c in coef):
                    result.append((lat, coef))
    return result


def emit(name, tet, piece_list, den):
    lines = [f"// {name}: tetrahedron {tet}; {len(piece_list)} lattice points.",
             f"inline constexpr BoxSplinePiece k{name}Piece = {{{{"]
    for lat, coef in piece_list:
        nums = [c * den for c in coef]
        assert all(x.denominator == 1 for x in nums)
        nums = ", ".join(str(x.numerator) for x in nums)
        lines.append(f"    {{{{{lat[0]}, {lat[1]}, {lat[2]}}}, {{{nums}}}}},")
    lines.append("}};")
    return "\n".join(lines)


def main():
    rng = random.Random(17)
    # Sanity of the kernel itself: partition of unity at a generic point.
    x = (F(3, 10), F(1, 7), F(2, 11))
    total = sum(kernel(sub(x, (i, j, k))) for i in range(-3, 4) for j in range(-3, 4)
                for k in range(-3, 4) if (i + j + k) % 2 == 0)
    assert total == 1, total
    corner = pieces(CORNER, rng)
    central = pieces(CENTRAL, rng)
    den = 1
    for _, coef in corner + central:
        for c in coef:
            den = den * c.denominator // math.gcd(den, c.denominator)
    mono_names = ", ".join("x" * a + "y" * b + "z" * c or "1" for a, b, c in MONOMIALS)
    text = f"""#pragma once
// GENERATED by src/lattice/derive_fcc_box_spline.py -- do not edit; rerun it.
//
// The centred six-direction box spline K on the FCC lattice (FCC shifts sum
// to 1), restricted to the two reference tetrahedra of the unit cube with an
// even lower corner: for each lattice point j whose shift is not zero there,
// K(v - j) = (1 / {den}) * sum_m coefficient[m] * monomial_m(v), v in the
// cube's local coordinates. Monomials, in order: {mono_names}.
// Derived exactly (rational arithmetic) from the box spline's definition as
// a convolution of two parallelepiped indicators; see the script.
#include <array>

namespace tessera::lattice::detail {{

inline constexpr int kPieceDenominator = {den};
inline constexpr int kPieceMonomials = {len(MONOMIALS)};
inline constexpr int kPieceStencil = {len(corner)};
// Exponents (of x, y, z) of the monomials.
inline constexpr std::array<std::array<int, 3>, kPieceMonomials> kPieceExponents = {{{{
    {", ".join("{%d, %d, %d}" % e for e in MONOMIALS)}}}}};

struct BoxSplineTerm {{
  std::array<int, 3> lattice;
  std::array<int, kPieceMonomials> coefficient;
}};
using BoxSplinePiece = std::array<BoxSplineTerm, kPieceStencil>;

{emit("Corner", CORNER, corner, den)}

{emit("Central", CENTRAL, central, den)}

}}  // namespace tessera::lattice::detail
"""
    assert len(corner) == len(central)
    # The repository's .clang-format decides the layout, so the file is
    # already formatted and --check compares like with like.
    text = subprocess.run(["clang-format", "--assume-filename=" + OUT], input=text, text=True,
                          check=True, capture_output=True, cwd=HERE).stdout
    if "--check" in sys.argv:
        with open(OUT) as f:
            if f.read() != text:
                sys.exit(f"{OUT} differs from what this script derives")
        print("up to date")
        return
    with open(OUT, "w") as f:
        f.write(text)
    print(f"wrote {OUT}: {len(corner)} + {len(central)} terms, denominator {den}")


if __name__ == "__main__":
    main()
