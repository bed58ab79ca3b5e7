#!/usr/bin/env python3
"""Writes a dense, curly groom as an artist's tool would export it, with
Pixar's own library.

    pip install usd-core        # the committed file was written by usd-core 26.11
    python3 tools/usd_dense_groom.py                       # tests/data/usd/dense_curly.usdc, 1,500 strands
    python3 tools/usd_dense_groom.py 20000 /tmp/dense.usdc  # the README's 20,000 strands (6 MB)

STRANDS (default 1,500) linear curves of 24 points on the upper part of a 9 cm head sphere
centred at (0, 0, 1.6) m — metersPerUnit 1, Z up, as Blender writes — each
growing out from its root, bending down under a soft "gravity" to 22-30 cm,
wound into a helix of 3 mm radius and 4-6 turns around its own path. Widths
per vertex from 80 um at the root to 20 um at the tip; displayColor per curve,
browns of varying lightness; primvars:st per curve, the root's direction
from the head's centre (u around Z, v from the bottom up). No guide marks:
vkhair chooses the guides.
Deterministic (a fixed seed). Beside it, HEAD.obj: the head sphere as an OBJ
in vkhair's frame (meters, Y up: centre (0, 1.6, 0)), for --obj.
"""

import math
import os
import random
import sys

from pxr import Gf, Sdf, Usd, UsdGeom, Vt

OUT = sys.argv[2] if len(sys.argv) > 2 else os.path.join(os.path.dirname(__file__), "..", "tests", "data", "usd", "dense_curly.usdc")
STRANDS = int(sys.argv[1]) if len(sys.argv) > 1 else 1_500
POINTS = 24
CENTER = (0.0, 0.0, 1.6)
RADIUS = 0.09


def strand(rng, k):
    # Golden-angle spiral over the cap above 20 degrees below the equator.
    z = 1.0 - (k + 0.5) / STRANDS * 1.34
    r = math.sqrt(max(0.0, 1.0 - z * z))
    a = k * 2.399963
    n = (r * math.cos(a), r * math.sin(a), z)
    root = [CENTER[i] + RADIUS * n[i] for i in range(3)]
    length = rng.uniform(0.22, 0.30)
    turns = rng.uniform(4.0, 6.0)
    phase = rng.uniform(0.0, 2.0 * math.pi)
    path = [root]
    d = n
    step = length / (POINTS - 1)
    for _ in range(POINTS - 1):
        # Bend towards -Z a little at every point.
        d = (d[0], d[1], d[2] - 0.35)
        m = math.sqrt(sum(c * c for c in d))
        d = tuple(c / m for c in d)
        p = path[-1]
        path.append([p[i] + step * d[i] for i in range(3)])
    # A frame around the root-to-tip line for the helix.
    axis = [path[-1][i] - root[i] for i in range(3)]
    m = math.sqrt(sum(c * c for c in axis))
    axis = [c / m for c in axis]
    helper = (1.0, 0.0, 0.0) if abs(axis[0]) < 0.9 else (0.0, 1.0, 0.0)
    u = [axis[1] * helper[2] - axis[2] * helper[1], axis[2] * helper[0] - axis[0] * helper[2], axis[0] * helper[1] - axis[1] * helper[0]]
    m = math.sqrt(sum(c * c for c in u))
    u = [c / m for c in u]
    v = [axis[1] * u[2] - axis[2] * u[1], axis[2] * u[0] - axis[0] * u[2], axis[0] * u[1] - axis[1] * u[0]]
    out = []
    for i, p in enumerate(path):
        t = i / (POINTS - 1)
        rad = 0.003 * min(1.0, 4.0 * t)
        ang = phase + turns * 2.0 * math.pi * t
        out.append(Gf.Vec3f(*[p[j] + rad * (math.cos(ang) * u[j] + math.sin(ang) * v[j]) for j in range(3)]))
    uv = Gf.Vec2f((a / (2.0 * math.pi)) % 1.0, 0.5 * (z + 1.0))
    return out, uv


def write_head(path, rings=24, segments=32):
    # Y up (Z up turned the way vkhair turns it: (x, y, z) -> (x, z, -y)).
    c = (CENTER[0], CENTER[2], -CENTER[1])
    lines = []
    for i in range(rings + 1):
        th = math.pi * i / rings
        for j in range(segments):
            ph = 2.0 * math.pi * j / segments
            n = (math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph))
            lines.append("v %.6f %.6f %.6f" % tuple(c[k] + RADIUS * 0.97 * n[k] for k in range(3)))
    for i in range(rings):
        for j in range(segments):
            a = i * segments + j + 1
            b = i * segments + (j + 1) % segments + 1
            lines.append("f %d %d %d" % (a, a + segments, b))
            lines.append("f %d %d %d" % (b, a + segments, b + segments))
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def main():
    rng = random.Random(20261125)
    if os.path.exists(OUT):
        os.remove(OUT)
    stage = Usd.Stage.CreateNew(OUT)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    root = UsdGeom.Xform.Define(stage, "/hair")
    stage.SetDefaultPrim(root.GetPrim())
    curves = UsdGeom.BasisCurves.Define(stage, "/hair/curly")
    curves.CreateTypeAttr(UsdGeom.Tokens.linear)
    points, widths, colors, uvs = [], [], [], []
    for k in range(STRANDS):
        pts, uv = strand(rng, k)
        points.extend(pts)
        uvs.append(uv)
        widths.extend(8e-5 - 6e-5 * i / (POINTS - 1) for i in range(POINTS))
        light = rng.uniform(0.6, 1.0)
        colors.append(Gf.Vec3f(0.28 * light, 0.16 * light, 0.08 * light))
    curves.CreateCurveVertexCountsAttr(Vt.IntArray([POINTS] * STRANDS))
    curves.CreatePointsAttr(Vt.Vec3fArray(points))
    curves.CreateWidthsAttr(Vt.FloatArray(widths))
    curves.SetWidthsInterpolation(UsdGeom.Tokens.vertex)
    curves.CreateDisplayColorPrimvar(UsdGeom.Tokens.uniform).Set(Vt.Vec3fArray(colors))
    st = UsdGeom.PrimvarsAPI(curves).CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray, UsdGeom.Tokens.uniform)
    st.Set(Vt.Vec2fArray(uvs))
    stage.GetRootLayer().Save()
    write_head(os.path.splitext(OUT)[0] + "_head.obj")
    print("wrote", OUT, os.path.getsize(OUT), "bytes with usd-core", ".".join(map(str, Usd.GetVersion())))


if __name__ == "__main__":
    main()
