#!/usr/bin/env python3
"""Writes the USD groom fixtures in tests/data/usd/ with Pixar's own library.

    pip install usd-core        # the committed files were written by usd-core 26.11
    python3 tools/usd_fixtures.py

Every value is chosen here and stated in tests/usd.rs, which reads the files
back through vkhair: nothing in the files is computed by vkhair.

- small_cm_zup.usda / small_cm_zup.usdc: the same stage twice (text and
  binary). Centimetres (metersPerUnit 0.01), Z up. Under an Xform translated
  by (0, 0, 100) cm:
  - /groom/linear: BasisCurves, linear, 3 curves of 2, 3 and 4 points along +X
    at y = 0, 10, 20 cm, z = 0; widths per vertex (0.2 cm at the root falling
    by 0.05 cm a point); displayColor per curve (red, green, blue);
    primvars:st per curve (0.1, 0.2), (0.3, 0.4), (0.5, 0.6);
    primvars:groom_guide per curve (1, 0, 1).
  - /groom/cubic: BasisCurves, cubic bspline, 1 curve of 5 points straight up
    +Z from (0, 50, 0) cm, 2 cm apart; widths constant 0.1 cm; displayColor
    constant (0.5, 0.5, 0.5); no st (so the groom has no root UVs).
  - /groom/mesh: a Mesh (not curves: skipped).
- periodic.usda: one periodic cubic curve (a loop, refused as a strand).
- no_points.usda: a BasisCurves prim without points.
- counts_mismatch.usda: curveVertexCounts sum 5, 4 points.
- nan.usda: one linear curve with a NaN point.
- animated.usda: one linear curve whose points are time samples only, at
  times 5 (x = 0) and 10 (x = 1): the first sample is read.
- rotated.usda: meters, Y up; /a translates (1, 2, 3), rotates XYZ (30, 45,
  60) degrees and scales (2, 2, 2); /a/b rotates 90 degrees about Y then
  translates (0, 1, 0); /a/b/c is a linear curve through (0, 0, 0) and
  (0.1, 0.2, 0.3). The script prints the points usd-core's
  ComputeLocalToWorldTransform gives them (the values tests/usd.rs states).
"""

import math
import os

from pxr import Gf, Sdf, Usd, UsdGeom, Vt

OUT = os.path.join(os.path.dirname(__file__), "..", "tests", "data", "usd")


def small(path):
    stage = Usd.Stage.CreateNew(path)
    UsdGeom.SetStageMetersPerUnit(stage, 0.01)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    root = UsdGeom.Xform.Define(stage, "/groom")
    root.AddTranslateOp().Set(Gf.Vec3d(0, 0, 100))
    stage.SetDefaultPrim(root.GetPrim())

    lin = UsdGeom.BasisCurves.Define(stage, "/groom/linear")
    lin.CreateTypeAttr(UsdGeom.Tokens.linear)
    counts = [2, 3, 4]
    points, widths = [], []
    for c, n in enumerate(counts):
        for i in range(n):
            points.append(Gf.Vec3f(i * 1.0, c * 10.0, 0.0))
            widths.append(0.2 - 0.05 * i)
    lin.CreateCurveVertexCountsAttr(Vt.IntArray(counts))
    lin.CreatePointsAttr(Vt.Vec3fArray(points))
    lin.CreateWidthsAttr(Vt.FloatArray(widths))
    lin.SetWidthsInterpolation(UsdGeom.Tokens.vertex)
    color = lin.CreateDisplayColorPrimvar(UsdGeom.Tokens.uniform)
    color.Set(Vt.Vec3fArray([Gf.Vec3f(1, 0, 0), Gf.Vec3f(0, 1, 0), Gf.Vec3f(0, 0, 1)]))
    pv = UsdGeom.PrimvarsAPI(lin)
    st = pv.CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray, UsdGeom.Tokens.uniform)
    st.Set(Vt.Vec2fArray([Gf.Vec2f(0.1, 0.2), Gf.Vec2f(0.3, 0.4), Gf.Vec2f(0.5, 0.6)]))
    guide = pv.CreatePrimvar("groom_guide", Sdf.ValueTypeNames.IntArray, UsdGeom.Tokens.uniform)
    guide.Set(Vt.IntArray([1, 0, 1]))

    cub = UsdGeom.BasisCurves.Define(stage, "/groom/cubic")
    cub.CreateTypeAttr(UsdGeom.Tokens.cubic)
    cub.CreateBasisAttr(UsdGeom.Tokens.bspline)
    cub.CreateCurveVertexCountsAttr(Vt.IntArray([5]))
    cub.CreatePointsAttr(Vt.Vec3fArray([Gf.Vec3f(0, 50, 2.0 * i) for i in range(5)]))
    cub.CreateWidthsAttr(Vt.FloatArray([0.1]))
    cub.SetWidthsInterpolation(UsdGeom.Tokens.constant)
    cub.CreateDisplayColorPrimvar(UsdGeom.Tokens.constant).Set(Vt.Vec3fArray([Gf.Vec3f(0.5, 0.5, 0.5)]))

    mesh = UsdGeom.Mesh.Define(stage, "/groom/mesh")
    mesh.CreatePointsAttr(Vt.Vec3fArray([Gf.Vec3f(0, 0, 0), Gf.Vec3f(1, 0, 0), Gf.Vec3f(0, 1, 0)]))
    mesh.CreateFaceVertexCountsAttr(Vt.IntArray([3]))
    mesh.CreateFaceVertexIndicesAttr(Vt.IntArray([0, 1, 2]))
    stage.GetRootLayer().Save()


def one_curve(path, points, counts=None, wrap=None, curve_type="linear"):
    stage = Usd.Stage.CreateNew(path)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    curves = UsdGeom.BasisCurves.Define(stage, "/hair")
    curves.CreateTypeAttr(curve_type)
    if curve_type == "cubic":
        curves.CreateBasisAttr(UsdGeom.Tokens.bspline)
    if wrap:
        curves.CreateWrapAttr(wrap)
    curves.CreateCurveVertexCountsAttr(Vt.IntArray(counts or [len(points)]))
    if points is not None:
        curves.CreatePointsAttr(Vt.Vec3fArray([Gf.Vec3f(*p) for p in points]))
    stage.GetRootLayer().Save()


def animated(path):
    stage = Usd.Stage.CreateNew(path)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    curves = UsdGeom.BasisCurves.Define(stage, "/hair")
    curves.CreateTypeAttr(UsdGeom.Tokens.linear)
    curves.CreateCurveVertexCountsAttr(Vt.IntArray([3]))
    points = curves.CreatePointsAttr()
    for time, x in ((5.0, 0.0), (10.0, 1.0)):
        points.Set(Vt.Vec3fArray([Gf.Vec3f(x, -0.1 * i, 0.0) for i in range(3)]), Usd.TimeCode(time))
    stage.GetRootLayer().Save()


def rotated(path):
    stage = Usd.Stage.CreateNew(path)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    a = UsdGeom.Xform.Define(stage, "/a")
    a.AddTranslateOp().Set(Gf.Vec3d(1, 2, 3))
    a.AddRotateXYZOp().Set(Gf.Vec3f(30, 45, 60))
    a.AddScaleOp().Set(Gf.Vec3f(2, 2, 2))
    b = UsdGeom.Xform.Define(stage, "/a/b")
    b.AddRotateYOp().Set(90.0)
    b.AddTranslateOp().Set(Gf.Vec3d(0, 1, 0))
    c = UsdGeom.BasisCurves.Define(stage, "/a/b/c")
    c.CreateTypeAttr(UsdGeom.Tokens.linear)
    c.CreateCurveVertexCountsAttr(Vt.IntArray([2]))
    pts = [Gf.Vec3f(0, 0, 0), Gf.Vec3f(0.1, 0.2, 0.3)]
    c.CreatePointsAttr(Vt.Vec3fArray(pts))
    stage.GetRootLayer().Save()
    m = UsdGeom.Xformable(c).ComputeLocalToWorldTransform(Usd.TimeCode.Default())
    print("rotated.usda world points:", [tuple(round(v, 7) for v in m.Transform(Gf.Vec3d(p))) for p in pts])


def main():
    os.makedirs(OUT, exist_ok=True)
    written = ["small_cm_zup.usda", "small_cm_zup.usdc", "periodic.usda", "no_points.usda",
               "counts_mismatch.usda", "nan.usda", "animated.usda", "rotated.usda"]
    for name in written:
        if os.path.exists(os.path.join(OUT, name)):
            os.remove(os.path.join(OUT, name))
    small(os.path.join(OUT, "small_cm_zup.usda"))
    small(os.path.join(OUT, "small_cm_zup.usdc"))
    loop = [(math.cos(a), math.sin(a), 0.0) for a in (k * math.pi / 3 for k in range(6))]
    one_curve(os.path.join(OUT, "periodic.usda"), loop, wrap="periodic", curve_type="cubic")
    one_curve(os.path.join(OUT, "no_points.usda"), None, counts=[2])
    one_curve(os.path.join(OUT, "counts_mismatch.usda"), [(0, 0, 0), (0, 1, 0), (0, 2, 0), (0, 3, 0)], counts=[2, 3])
    one_curve(os.path.join(OUT, "nan.usda"), [(0, 0, 0), (0, float("nan"), 0), (0, 2, 0)])
    animated(os.path.join(OUT, "animated.usda"))
    rotated(os.path.join(OUT, "rotated.usda"))
    print("wrote", written, "with usd-core", ".".join(map(str, Usd.GetVersion())))


if __name__ == "__main__":
    main()
