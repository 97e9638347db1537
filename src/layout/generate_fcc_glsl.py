#!/usr/bin/env python3
"""Writes src/layout/fcc_pieces.glsl, the GLSL ES 3.00 twin of the box
spline's two reference pieces, from src/lattice/FccBoxSplinePieces.h (the
exact tables derive_fcc_box_spline.py derives).

The header gives, per piece, 16 lattice offsets and for each a cubic in
monomial form (178 and 220 non-zero terms). The GPU evaluates each piece in
Bernstein-Bezier form on its tetrahedron instead: a cubic on a tetrahedron
is sum_alpha d_alpha lambda^alpha over its 20 barycentric monomials, and
d_alpha = sum_k beta_k,alpha c_k needs only 119 (corner) and 88 (central)
non-zero beta: about half the multiply-adds, plus ~40 for the monomials
(Kim & Peters, "Fast and stable evaluation of box-splines via the BB-form",
Numerical Algorithms 2009, for BB-form box-spline evaluation). All
conversions are exact (Fractions); only the final literals are rounded to
float.

Usage: src/layout/generate_fcc_glsl.py [--check]   (--check: fail if stale)
"""

import os
import re
import sys
from fractions import Fraction as F
from itertools import combinations, product

HERE = os.path.dirname(os.path.abspath(__file__))
TABLES = os.path.join(HERE, "..", "lattice", "FccBoxSplinePieces.h")
OUT = os.path.join(HERE, "fcc_pieces.glsl")

MONOMIALS = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1), (2, 0, 0), (1, 1, 0), (1, 0, 1),
             (0, 2, 0), (0, 1, 1), (0, 0, 2), (3, 0, 0), (2, 1, 0), (2, 0, 1), (1, 2, 0),
             (1, 1, 1), (1, 0, 2), (0, 3, 0), (0, 2, 1), (0, 1, 2), (0, 0, 3)]
ALPHAS = [a for a in product(range(3, -1, -1), repeat=4) if sum(a) == 3]

# x, y, z as linear forms in the barycentric coordinates (l0, l1, l2, l3).
# Corner tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1).
CORNER_XYZ = [(0, 1, 0, 0), (0, 0, 1, 0), (0, 0, 0, 1)]
# Central tetrahedron (1,0,0), (0,1,0), (0,0,1), (1,1,1).
CENTRAL_XYZ = [(1, 0, 0, 1), (0, 1, 0, 1), (0, 0, 1, 1)]
# GLSL for the barycentric coordinates from the local position l.
CORNER_BARY = ["1.0 - l.x - l.y - l.z", "l.x", "l.y", "l.z"]
CENTRAL_BARY = ["l.x - t", "l.y - t", "l.z - t", "t"]  # t = (x + y + z - 1) / 2


def read_pieces():
    text = open(TABLES).read()
    denominator = int(re.search(r"kPieceDenominator = (\d+)", text).group(1))
    pieces = {}
    for name in ("kCornerPiece", "kCentralPiece"):
        body = text.split(name + " = ")[1].split("}};")[0]
        rows = re.findall(r"\{\{(-?\d+), (-?\d+), (-?\d+)\}, \{([^}]*)\}\}", body)
        pieces[name] = [((int(a), int(b), int(c)), [F(int(x), denominator) for x in co.split(",")])
                        for a, b, c, co in rows]
        assert len(pieces[name]) == 16, name
    return pieces


def poly_mul(p, q):
    out = {}
    for ea, ca in p.items():
        for eb, cb in q.items():
            e = tuple(x + y for x, y in zip(ea, eb))
            out[e] = out.get(e, 0) + ca * cb
    return out


def bb_form(coefficients, xyz):
    """Monomial cubic in x, y, z -> {alpha: d_alpha}, homogeneous in lambda."""
    one = {(1, 0, 0, 0): F(1), (0, 1, 0, 0): F(1), (0, 0, 1, 0): F(1), (0, 0, 0, 1): F(1)}
    lin = [{tuple(1 if i == j else 0 for i in range(4)): F(1) for j in range(4) if form[j]}
           for form in xyz]
    out = {}
    for c, (a, b, cc) in zip(coefficients, MONOMIALS):
        if c == 0:
            continue
        term = {(0, 0, 0, 0): c}
        for axis, power in enumerate((a, b, cc)):
            for _ in range(power):
                term = poly_mul(term, lin[axis])
        for _ in range(3 - a - b - cc):  # homogenise: multiply by l0 + l1 + l2 + l3 = 1
            term = poly_mul(term, one)
        for e, v in term.items():
            out[e] = out.get(e, 0) + v
    return out


def cube_cover(points):
    """The fewest unit cubes [q, q + 1]^3 whose FCC corners hold `points`
    (5 for both pieces), and for each point its cube and channel: a cube's
    four FCC corners q + o are told apart by o.x + 2 o.y (o.z follows from
    the parity), the channel FccLayout's cube texture stores them in."""
    wanted = set(points)

    def corners_of(q):
        return frozenset(tuple(q[a] + o[a] for a in range(3)) for o in product((0, 1), repeat=3)
                         if sum(q[a] + o[a] for a in range(3)) % 2 == 0)

    # Cubes holding at least two wanted points (16 points in 5 cubes of 4
    # need no cube holding one), the fullest first.
    cubes = [q for q in product(range(-2, 3), repeat=3) if len(corners_of(q) & wanted) >= 2]
    cubes.sort(key=lambda q: -len(corners_of(q) & wanted))
    held = {q: corners_of(q) & wanted for q in cubes}
    for k in range(1, 8):
        for combo in combinations(cubes, k):
            if sum(len(held[q]) for q in combo) < len(wanted):
                continue
            if wanted <= set().union(*(held[q] for q in combo)):
                where = []
                for p in points:
                    j = next(i for i, q in enumerate(combo) if p in corners_of(q))
                    o = [p[a] - combo[j][a] for a in range(3)]
                    where.append((j, o[0] + 2 * o[1]))
                return list(combo), where
    raise AssertionError("no cube cover")


def literal(f):
    v = float(f)
    return repr(v) if "." in repr(v) or "e" in repr(v) else repr(v) + ".0"


def piece_glsl(name, glsl_name, rows, xyz, bary, comment):
    lines = [f"// {comment}",
             f"float {glsl_name}(ivec3 b, ivec3 s, vec3 l) {{"]
    # Packed storage: one fetch per lattice point.
    lines.append("#ifndef FCC_CUBES")
    for k, (off, _) in enumerate(rows):
        lines.append(f"  float c{k} = fccPoint(b + s * ivec3({off[0]}, {off[1]}, {off[2]}));")
    # Cube storage: the 16 points are the FCC corners of 5 unit cubes, one
    # RGBA fetch each (fccCube reflects the cube and orders its channels).
    lines.append("#else")
    cubes, where = cube_cover([off for off, _ in rows])
    for j, q in enumerate(cubes):
        lines.append(f"  vec4 t{j} = fccCube(b, s, ivec3({q[0]}, {q[1]}, {q[2]}));")
    for k, (j, ch) in enumerate(where):
        lines.append(f"  float c{k} = t{j}.{'rgba'[ch]};")
    lines.append("#endif")
    beta = {}
    for k, (_, co) in enumerate(rows):
        for alpha, v in bb_form(co, xyz).items():
            if v != 0:
                beta.setdefault(alpha, []).append((k, v))
    if glsl_name.endswith("Central"):
        lines.append("  float t = 0.5 * (l.x + l.y + l.z - 1.0);")
    # The benchmark's cost split (FccLayout::Evaluation::FetchesOnly).
    lines.append("#ifdef FCC_FETCHES_ONLY")
    lines.append("  return 0.0625 * (" + " + ".join(f"c{k}" for k in range(16)) + ");")
    lines.append("#endif")
    for i, expr in enumerate(bary):
        lines.append(f"  float l{i} = {expr};")
    for i in range(4):
        lines.append(f"  float q{i} = l{i} * l{i};")
    terms = []
    for alpha in ALPHAS:
        if alpha not in beta:
            continue
        # Terms sharing a coefficient are summed first: fewer multiplies.
        by_value = {}
        for k, v in sorted(beta[alpha]):
            by_value.setdefault(v, []).append(f"c{k}")
        groups = [(f"{literal(v)} * " + (ks[0] if len(ks) == 1 else "(" + " + ".join(ks) + ")"))
                  for v, ks in sorted(by_value.items(), key=lambda kv: -abs(kv[0]))]
        name_a = "d" + "".join(map(str, alpha))
        lines.append(f"  float {name_a} = " + "\n      + ".join(groups) + ";")
        factors = []
        for i, p in enumerate(alpha):
            factors += {0: [], 1: [f"l{i}"], 2: [f"q{i}"], 3: [f"q{i}", f"l{i}"]}[p]
        terms.append(f"{name_a} * " + " * ".join(factors))
    lines.append("  return " + "\n      + ".join(terms) + ";")
    lines.append("}")
    count = sum(len(v) for v in beta.values())
    return lines, count


def generate():
    pieces = read_pieces()
    corner, n_corner = piece_glsl(
        "kCornerPiece", "fccCorner", pieces["kCornerPiece"], CORNER_XYZ, CORNER_BARY,
        "Corner tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1): l0 = 1 - x - y - z.")
    central, n_central = piece_glsl(
        "kCentralPiece", "fccCentral", pieces["kCentralPiece"], CENTRAL_XYZ, CENTRAL_BARY,
        "Central tetrahedron (1,0,0), (0,1,0), (0,0,1), (1,1,1): l3 = (x + y + z - 1) / 2.")
    head = [
        "// GENERATED by src/layout/generate_fcc_glsl.py from src/lattice/FccBoxSplinePieces.h",
        "// -- do not edit; rerun it. The box spline's two reference pieces in Bernstein-Bezier",
        f"// form ({n_corner} and {n_central} non-zero coefficient terms): piece(b, s, l) is the",
        "// spline at local position l of the reference tetrahedron, its 16 lattice points",
        "// being b + s * offset (lattice/FccBoxSpline.h: locateBoxSpline). Needs fccPoint().",
    ]
    return "\n".join(head + [""] + corner + [""] + central) + "\n"


def main():
    text = generate()
    if "--check" in sys.argv:
        if open(OUT).read() != text:
            sys.exit(f"{OUT} is stale: rerun {sys.argv[0]}")
        return
    with open(OUT, "w") as f:
        f.write(text)
    print("wrote", OUT)


if __name__ == "__main__":
    main()
