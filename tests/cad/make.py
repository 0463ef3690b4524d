"""Makes the STEP fixtures of `tests/suite/cad_kinds.rs` with OpenCASCADE (OCP).

Not run by CI: the files it writes are checked in. Re-run it by hand after changing a
part here (`pip install cadquery-ocp==7.7.2`, then `python3 tests/cad/make.py` from the
repository root). Each part is one solid whose faces use one surface or curve kind that
real exporters write; beside each `NAME.stp` goes `NAME.json`, OpenCASCADE's own reading
of the solid (every face's surface type and area, the volume, the bounding box, in
millimetres), which the test compares inspc's reading with.

Some kinds OpenCASCADE never writes by itself (a cylinder face with no seam edge, a
plane angle in degrees); those parts are written by OpenCASCADE and then edited as text,
and the edit is described beside the part.

Every file comes out byte-identical from run to run but `offset.stp`, whose faces
OpenCASCADE's offset algorithm orders differently each time (the same solid): keep the
checked-in one unless the part changes.
"""

import json
import math
import os
import re

from curves_edit import entities, numbers
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Surface
from OCP.BRepAlgoAPI import BRepAlgoAPI_Cut
from OCP.BRepBndLib import BRepBndLib
from OCP.BRepBuilderAPI import (
    BRepBuilderAPI_MakeEdge,
    BRepBuilderAPI_MakeFace,
    BRepBuilderAPI_MakeWire,
    BRepBuilderAPI_NurbsConvert,
)
from OCP.BRepGProp import BRepGProp
from OCP.BRepOffsetAPI import BRepOffsetAPI_MakeOffsetShape
from OCP.BRepPrimAPI import (
    BRepPrimAPI_MakeBox,
    BRepPrimAPI_MakeCone,
    BRepPrimAPI_MakeCylinder,
    BRepPrimAPI_MakePrism,
    BRepPrimAPI_MakeRevol,
    BRepPrimAPI_MakeSphere,
)
from OCP.Bnd import Bnd_Box
from OCP.GC import GC_MakeArcOfHyperbola, GC_MakeArcOfParabola, GC_MakeSegment
from OCP.GeomAbs import GeomAbs_CurveType, GeomAbs_SurfaceType
from OCP.GeomAPI import GeomAPI_Interpolate
from OCP.GProp import GProp_GProps
from OCP.Interface import Interface_Static
from OCP.STEPControl import STEPControl_AsIs, STEPControl_Writer
from OCP.TColgp import TColgp_HArray1OfPnt
from OCP.TopAbs import TopAbs_FACE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS
from OCP.BRep import BRep_Tool
from OCP.GeomLib import GeomLib_IsPlanarSurface
from OCP.gp import gp_Ax1, gp_Ax2, gp_Dir, gp_Hypr, gp_Parab, gp_Pnt, gp_Vec

HERE = os.path.dirname(os.path.abspath(__file__))

KIND = {
    GeomAbs_SurfaceType.GeomAbs_Plane: "plane",
    GeomAbs_SurfaceType.GeomAbs_Cylinder: "cylinder",
    GeomAbs_SurfaceType.GeomAbs_Cone: "cone",
    GeomAbs_SurfaceType.GeomAbs_Sphere: "sphere",
    GeomAbs_SurfaceType.GeomAbs_Torus: "torus",
    GeomAbs_SurfaceType.GeomAbs_BezierSurface: "freeform",
    GeomAbs_SurfaceType.GeomAbs_BSplineSurface: "freeform",
    GeomAbs_SurfaceType.GeomAbs_SurfaceOfRevolution: "freeform",
    GeomAbs_SurfaceType.GeomAbs_SurfaceOfExtrusion: "freeform",
    GeomAbs_SurfaceType.GeomAbs_OffsetSurface: "freeform",
}


def interpolate(points, periodic):
    arr = TColgp_HArray1OfPnt(1, len(points))
    for i, p in enumerate(points):
        arr.SetValue(i + 1, gp_Pnt(*p))
    it = GeomAPI_Interpolate(arr, periodic, 1e-6)
    it.Perform()
    return it.Curve()


def wire(*edges):
    w = BRepBuilderAPI_MakeWire()
    for e in edges:
        w.Add(e)
    return w.Wire()


def segment(a, b):
    return BRepBuilderAPI_MakeEdge(GC_MakeSegment(gp_Pnt(*a), gp_Pnt(*b)).Value()).Edge()


def profile_face(edges):
    return BRepBuilderAPI_MakeFace(wire(*edges)).Face()


def reading(shape, unit_mm):
    """OpenCASCADE's reading of the solid, in millimetres."""
    faces = []
    ex = TopExp_Explorer(shape, TopAbs_FACE)
    while ex.More():
        f = TopoDS.Face_s(ex.Current())
        props = GProp_GProps()
        BRepGProp.SurfaceProperties_s(f, props)
        kind = KIND[BRepAdaptor_Surface(f).GetType()]
        # A B-spline whose poles lie on one plane is that plane (OpenCASCADE's own
        # test, `GeomLib_IsPlanarSurface`, at inspc's 1e-6 mm).
        if kind == "freeform" and GeomLib_IsPlanarSurface(BRep_Tool.Surface_s(f), 1e-6).IsPlanar():
            kind = "plane"
        faces.append({"kind": kind, "area": round(props.Mass() * unit_mm**2, 6)})
        ex.Next()
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props)
    box = Bnd_Box()
    box.SetGap(0.0)
    BRepBndLib.AddOptimal_s(shape, box, False, False)
    lo, hi = box.CornerMin(), box.CornerMax()
    return {
        "faces": faces,
        "volume": round(props.Mass() * unit_mm**3, 6),
        "box": [
            [round(c * unit_mm, 6) for c in (lo.X(), lo.Y(), lo.Z())],
            [round(c * unit_mm, 6) for c in (hi.X(), hi.Y(), hi.Z())],
        ],
    }


def write(name, shape, unit="MM", unit_mm=1.0, edit=None, what="", qif=None, step_shape=None, qif_kinds=None):
    """Writes NAME.stp and NAME.json, and NAME.qif when `qif` says how (`"u"` or
    `"v"`: which NURBS index runs fastest, `qif_writer.py`; `qif_kinds` the writer's
    other options). `step_shape`, when given,
    is what OpenCASCADE writes for `edit` to make exact (a curve it cannot write,
    approximated); the expectation is always `shape`'s."""
    Interface_Static.SetCVal_s("write.step.unit", unit)
    Interface_Static.SetCVal_s("write.step.schema", "AP214IS")
    path = os.path.join(HERE, name + ".stp")
    w = STEPControl_Writer()
    w.Transfer(shape if step_shape is None else step_shape, STEPControl_AsIs)
    w.Write(path)
    text = open(path).read()
    # The header's time stamp would change the file at every run.
    text = re.sub(r"FILE_NAME\('[^']*','[^']*'", f"FILE_NAME('{name}.stp','2026-11-27T00:00:00'", text)
    # Nor would the writer's product counter.
    text = re.sub(r"Open CASCADE STEP translator ([\d.]+) \d+", r"Open CASCADE STEP translator \1", text)
    if edit:
        text = edit(text)
    open(path, "w").write(text)
    if qif:
        from qif_writer import Writer

        with open(os.path.join(HERE, name + ".qif"), "w") as f:
            f.write(Writer(v_fastest=qif == "v", **(qif_kinds or {})).write(shape))
    expected = reading(shape, unit_mm)
    expected["what"] = what
    with open(os.path.join(HERE, name + ".json"), "w") as f:
        json.dump(expected, f, indent=1)
        f.write("\n")


def blob_prism():
    c = interpolate([(30, 0, 0), (20, 18, 0), (0, 25, 0), (-22, 15, 0), (-28, -5, 0), (-10, -22, 0), (15, -20, 0)], True)
    f = BRepBuilderAPI_MakeFace(wire(BRepBuilderAPI_MakeEdge(c).Edge())).Face()
    return BRepPrimAPI_MakePrism(f, gp_Vec(0, 0, 20)).Shape()


def oblique_prism():
    """A circle swept along a slanted vector: an oblique cylinder, not a cylinder."""
    from OCP.gp import gp_Circ

    e = BRepBuilderAPI_MakeEdge(gp_Circ(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 12)).Edge()
    f = BRepBuilderAPI_MakeFace(wire(e)).Face()
    return BRepPrimAPI_MakePrism(f, gp_Vec(8, 0, 25)).Shape()


def ellipse_prism():
    from OCP.gp import gp_Elips

    e = BRepBuilderAPI_MakeEdge(gp_Elips(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 20, 11)).Edge()
    f = BRepBuilderAPI_MakeFace(wire(e)).Face()
    return BRepPrimAPI_MakePrism(f, gp_Vec(0, 0, 15)).Shape()


def vase(angle=2 * math.pi):
    """A ring whose outside is a B-spline revolved about z."""
    c = interpolate([(20, 0, 0), (26, 0, 10), (22, 0, 22), (28, 0, 35)], False)
    outer = BRepBuilderAPI_MakeEdge(c).Edge()
    f = profile_face([segment((10, 0, 0), (20, 0, 0)), outer, segment((28, 0, 35), (10, 0, 35)), segment((10, 0, 35), (10, 0, 0))])
    return BRepPrimAPI_MakeRevol(f, gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), angle).Shape()


def dome():
    """A B-spline revolved from the axis: the surface closes at a pole."""
    c = interpolate([(0, 0, 30), (12, 0, 27), (22, 0, 15), (25, 0, 0)], False)
    f = profile_face([BRepBuilderAPI_MakeEdge(c).Edge(), segment((25, 0, 0), (0, 0, 0)), segment((0, 0, 0), (0, 0, 30))])
    return BRepPrimAPI_MakeRevol(f, gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 2 * math.pi).Shape()


def conics():
    """A plate bounded by a parabola and a hyperbola arc, extruded."""
    parab = gp_Parab(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1), gp_Dir(0, 1, 0)), 4.0)
    # Points of y² = 4 f x with x along the parabola's axis (here +y): (t, t²/16).
    p_arc = GC_MakeArcOfParabola(parab, gp_Pnt(-16, 16, 0), gp_Pnt(16, 16, 0), True).Value()
    hyp = gp_Hypr(gp_Ax2(gp_Pnt(0, 60, 0), gp_Dir(0, 0, 1), gp_Dir(0, -1, 0)), 10.0, 12.0)
    h_arc = GC_MakeArcOfHyperbola(hyp, -1.0, 1.0, True).Value()
    a, b = h_arc.StartPoint(), h_arc.EndPoint()
    pa, pb = p_arc.StartPoint(), p_arc.EndPoint()
    e1 = BRepBuilderAPI_MakeEdge(p_arc).Edge()
    e3 = BRepBuilderAPI_MakeEdge(h_arc).Edge()
    # Join the ends: each hyperbola end to the nearer parabola end.
    ends = sorted([(a.X(), a), (b.X(), b)], key=lambda t: t[0])
    pends = sorted([(pa.X(), pa), (pb.X(), pb)], key=lambda t: t[0])
    s_left = segment(xyz(pends[0][1]), xyz(ends[0][1]))
    s_right = segment(xyz(pends[1][1]), xyz(ends[1][1]))
    f = profile_face([e1, s_right, e3, s_left])
    return BRepPrimAPI_MakePrism(f, gp_Vec(0, 0, 10)).Shape()


def xyz(p):
    return (p.X(), p.Y(), p.Z())


def nurbs_cap():
    """A box with a spherical pocket, every face converted to rational B-splines."""
    box = BRepPrimAPI_MakeBox(60, 40, 20).Shape()
    ball = BRepPrimAPI_MakeSphere(gp_Pnt(30, 20, 28), 15).Shape()
    cut = BRepAlgoAPI_Cut(box, ball).Shape()
    return BRepBuilderAPI_NurbsConvert(cut, True).Shape()


def offset_ellipse_prism():
    """The elliptic prism grown 3 mm: its side an offset of a swept ellipse."""
    mk = BRepOffsetAPI_MakeOffsetShape()
    mk.PerformByJoin(ellipse_prism(), 3.0, 1e-6)
    return mk.Shape()


def offset_vase():
    """The vase grown 2 mm: its B-spline side becomes an offset surface."""
    mk = BRepOffsetAPI_MakeOffsetShape()
    mk.PerformByJoin(vase(), 2.0, 1e-6)
    return mk.Shape()


def cylinder_block():
    box = BRepPrimAPI_MakeBox(50, 40, 20).Shape()
    hole = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(25, 20, -1), gp_Dir(0, 0, 1)), 8, 22).Shape()
    return BRepAlgoAPI_Cut(box, hole).Shape()


def cone_block():
    box = BRepPrimAPI_MakeBox(50, 40, 20).Shape()
    cone = BRepPrimAPI_MakeCone(gp_Ax2(gp_Pnt(25, 20, -1), gp_Dir(0, 0, 1)), 12, 5, 22).Shape()
    return BRepAlgoAPI_Cut(box, cone).Shape()


def without_seam(text):
    """The bore's cylinder face bounded by its two circles alone, with no seam edge
    (a band that goes once round, as some exporters write full cylinders)."""
    lines = text.split("\n")
    ents = {}
    for l in lines:
        m = re.match(r"#(\d+) = (\w+)\((.*)\);$", l)
        if m:
            ents[int(m.group(1))] = (m.group(2), m.group(3))
    seams = {i for i, (t, a) in ents.items() if t == "SEAM_CURVE"}
    seam_edges = {i for i, (t, a) in ents.items() if t == "EDGE_CURVE" and int(re.findall(r"#(\d+)", a)[2]) in seams}
    seam_oriented = {i for i, (t, a) in ents.items() if t == "ORIENTED_EDGE" and int(re.findall(r"#(\d+)", a)[0]) in seam_edges}
    out = []
    for l in lines:
        m = re.match(r"#(\d+) = EDGE_LOOP\('',\((.*)\)\);$", l)
        if m:
            refs = [int(r) for r in re.findall(r"#(\d+)", m.group(2))]
            if any(r in seam_oriented for r in refs):
                keep = [r for r in refs if r not in seam_oriented]
                # Each circle closes on its own vertex: one loop per circle.
                first, rest = keep[0], keep[1:]
                l = f"#{m.group(1)} = EDGE_LOOP('',(#{first}));"
                for r in rest:
                    nid = 900000 + r
                    out.append(f"#{nid} = EDGE_LOOP('',(#{r}));")
                    sense = next(a.split(",")[-1] for t, a in ents.values() if t in ("FACE_BOUND", "FACE_OUTER_BOUND") and re.findall(r"#(\d+)", a)[0] == m.group(1))
                    out.append(f"#{nid + 50000} = FACE_BOUND('',#{nid},{sense});")
                    extra_bounds.setdefault(int(m.group(1)), []).append(nid + 50000)
        out.append(l)
    text = "\n".join(out)
    for loop, bounds in extra_bounds.items():
        # The loop's own bound is listed by a face: add the new bounds beside it.
        bound = next(i for i, (t, a) in ents.items() if t in ("FACE_BOUND", "FACE_OUTER_BOUND") and re.findall(r"#(\d+)", a)[0] == str(loop))
        face = next(i for i, (t, a) in ents.items() if t == "ADVANCED_FACE" and f"#{bound}" in re.findall(r"#\d+", a.split(")")[0]))
        text = re.sub(rf"(#{face} = ADVANCED_FACE\('',\()([^)]*)\)", lambda m: m.group(1) + m.group(2) + "," + ",".join(f"#{b}" for b in bounds) + ")", text)
    return text


extra_bounds = {}


def disguised_far(text):
    """`disguised`, with the cone's line given by a point beyond its apex, on the other
    nappe from the face (ISO 10303-42 lets the line's point lie anywhere on it)."""
    return disguised(text, far_cone=True)


def disguised(text, far_cone=False):
    """Every analytic surface written as the swept or offset surface it also is, the
    way CATIA V5 and other exporters write them: a plane as a line swept along the
    plane (every other one as an offset of a parallel plane), a cylinder as a circle
    swept along its axis (every other one swept the other way, so that the face's
    sense must flip), a cone as a line revolved, a sphere and a torus as a circle
    revolved (ISO 10303-42 surface_of_linear_extrusion, surface_of_revolution,
    offset_surface)."""
    ents = entities(text)
    new = []
    next_id = [800000]

    def add(s):
        next_id[0] += 1
        new.append(f"#{next_id[0]} = {s};")
        return f"#{next_id[0]}"

    def vec3(v):
        return "(" + ",".join(repr(float(x)) for x in v) + ")"

    def placement(ref):
        _, a = ents[int(ref[1:])]
        refs = re.findall(r"#\d+", a)
        p = numbers(ents[int(refs[0][1:])][1])
        z = numbers(ents[int(refs[1][1:])][1])
        x = numbers(ents[int(refs[2][1:])][1])
        y = [z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0]]
        return p, x, y, z

    def point(v):
        return add(f"CARTESIAN_POINT('',{vec3(v)})")

    def direction(v):
        return add(f"DIRECTION('',{vec3(v)})")

    def at(p, *terms):
        out = list(p)
        for k, v in terms:
            out = [o + k * c for o, c in zip(out, v)]
        return out

    count = {"PLANE": 0, "CYLINDRICAL_SURFACE": 0}
    # Surfaces whose swept form's natural normal points the other way: their faces'
    # sense flags flip with them, so that the solid stays the same.
    flipped = set()

    def replace(m):
        sid, kind, params = m.group(1), m.group(2), m.group(3)
        ref = re.findall(r"#\d+", params)[0]
        p, x, y, z = placement(ref)
        vals = numbers(params.split(ref, 1)[1])
        if kind == "PLANE":
            count[kind] += 1
            if count[kind] % 2 == 0:
                d = 3.0
                frame = add(f"AXIS2_PLACEMENT_3D('',{point(at(p, (-d, z)))},{direction(z)},{direction(x)})")
                base = add(f"PLANE('',{frame})")
                return f"#{sid} = OFFSET_SURFACE('',{base},{d!r},.F.);"
            along_x = add(f"VECTOR('',{direction(x)},1.)")
            line = add(f"LINE('',{point(p)},{along_x})")
            along_y = add(f"VECTOR('',{direction(y)},1.)")
            return f"#{sid} = SURFACE_OF_LINEAR_EXTRUSION('',{line},{along_y});"
        if kind == "CYLINDRICAL_SURFACE":
            count[kind] += 1
            sign = 1.0 if count[kind] % 2 else -1.0
            if sign < 0:
                flipped.add(sid)
            circle = add(f"CIRCLE('',{ref},{vals[0]!r})")
            along = add(f"VECTOR('',{direction([sign * c for c in z])},1.)")
            return f"#{sid} = SURFACE_OF_LINEAR_EXTRUSION('',{circle},{along});"
        axis = add(f"AXIS1_PLACEMENT('',{point(p)},{direction(z)})")
        if kind == "CONICAL_SURFACE":
            r, semi = vals[0], vals[1]
            d = [math.sin(semi) * a + math.cos(semi) * b for a, b in zip(x, z)]
            slope = add(f"VECTOR('',{direction(d)},1.)")
            start = at(p, (r, x))
            if far_cone:
                apex = at(start, (-r / math.sin(semi), d))
                start = [2 * a - s0 for a, s0 in zip(apex, start)]
            line = add(f"LINE('',{point(start)},{slope})")
            return f"#{sid} = SURFACE_OF_REVOLUTION('',{line},{axis});"
        if kind == "SPHERICAL_SURFACE":
            # The circle turns against the revolution: S_u × S_v points out.
            frame = add(f"AXIS2_PLACEMENT_3D('',{point(p)},{direction([-c for c in y])},{direction(x)})")
            circle = add(f"CIRCLE('',{frame},{vals[0]!r})")
            return f"#{sid} = SURFACE_OF_REVOLUTION('',{circle},{axis});"
        if kind == "TOROIDAL_SURFACE":
            big, small = vals[0], vals[1]
            # The circle turns with the revolution: S_u × S_v points in.
            flipped.add(sid)
            frame = add(f"AXIS2_PLACEMENT_3D('',{point(at(p, (big, x)))},{direction(y)},{direction(x)})")
            circle = add(f"CIRCLE('',{frame},{small!r})")
            return f"#{sid} = SURFACE_OF_REVOLUTION('',{circle},{axis});"
        return m.group(0)

    text = re.sub(
        r"^#(\d+) = (PLANE|CYLINDRICAL_SURFACE|CONICAL_SURFACE|SPHERICAL_SURFACE|TOROIDAL_SURFACE)\((.*?)\);$",
        replace,
        text,
        flags=re.M | re.S,
    )
    def sense(m):
        flip = {".T.": ".F.", ".F.": ".T."}
        return m.group(1) + (flip[m.group(3)] if m.group(2) in flipped else m.group(3)) + ");"

    text = re.sub(r"(ADVANCED_FACE\('',\([^)]*\),#(\d+),)(\.[TF]\.)\);", sense, text)
    return text.replace("ENDSEC;\nEND-ISO", "\n".join(new) + "\nENDSEC;\nEND-ISO", 1)


def spline_prism(mults, knots):
    """A plate whose curved side is a cubic B-spline with the given knots, extruded."""
    from OCP.Geom import Geom_BSplineCurve
    from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal
    from OCP.TColgp import TColgp_Array1OfPnt

    pts = [(0, 0), (10, 12), (25, 8), (40, 18), (55, 5), (70, 10), (80, 0)]
    poles = TColgp_Array1OfPnt(1, len(pts))
    for i, (x, y) in enumerate(pts):
        poles.SetValue(i + 1, gp_Pnt(x, y + 20, 0))
    k = TColStd_Array1OfReal(1, len(knots))
    m = TColStd_Array1OfInteger(1, len(mults))
    for i, (kv, mv) in enumerate(zip(knots, mults)):
        k.SetValue(i + 1, kv)
        m.SetValue(i + 1, mv)
    curve = Geom_BSplineCurve(poles, k, m, 3)
    a, b = curve.StartPoint(), curve.EndPoint()
    edges = [
        BRepBuilderAPI_MakeEdge(curve).Edge(),
        segment(xyz(b), (xyz(b)[0], 0, 0)),
        segment((xyz(b)[0], 0, 0), (xyz(a)[0], 0, 0)),
        segment((xyz(a)[0], 0, 0), xyz(a)),
    ]
    return BRepPrimAPI_MakePrism(profile_face(edges), gp_Vec(0, 0, 12)).Shape()


def implied_knots(kind):
    """B-splines whose knots their subtype implies (ISO 10303-42 uniform_curve,
    quasi_uniform_curve, bezier_curve, bezier_surface): every simple B-spline instance
    whose knots are that pattern loses them and takes the subtype's name. A Bézier
    piece's shape does not depend on its knots' spacing, so degree-1 lines and planes
    of any length qualify; a quasi-uniform or uniform curve's knots must be 0, 1, 2, …
    as the subtype implies."""

    def edit(text):
        def curve(m):
            name, deg, pts, flags, mults, knots = m.groups()
            mults = [int(x) for x in mults.split(",")]
            knots = [float(x) for x in knots.split(",")]
            d = int(deg)
            steps = [b - a for a, b in zip(knots, knots[1:])]
            unit = all(abs(x - 1.0) < 1e-12 for x in steps)
            if kind == "BEZIER" and mults[0] == mults[-1] == d + 1 and all(x == d for x in mults[1:-1]):
                new = "BEZIER_CURVE"
            elif kind == "QUASI_UNIFORM" and unit and knots[0] == 0 and mults[0] == mults[-1] == d + 1 and all(x == 1 for x in mults[1:-1]):
                new = "QUASI_UNIFORM_CURVE"
            elif kind == "UNIFORM" and unit and knots[0] == -d and all(x == 1 for x in mults):
                new = "UNIFORM_CURVE"
            else:
                return m.group(0)
            return f"{new}({name},{deg},{pts},{flags});"

        def surface(m):
            name, du, dv, pts, flags, mu, mv, ku, kv = m.groups()
            ok = all(
                [int(x) for x in ms.split(",")] == [int(d) + 1, int(d) + 1]
                for ms, d in ((mu, du), (mv, dv))
            )
            if kind != "BEZIER" or not ok:
                return m.group(0)
            return f"BEZIER_SURFACE({name},{du},{dv},{pts},{flags});"

        text = re.sub(
            r"B_SPLINE_CURVE_WITH_KNOTS\(('[^']*'),(\d+),(\([^)]*\)),(\.\w+\.,\.\w+\.,\.\w+\.),\s*\(([^)]*)\),\s*\(([^)]*)\),\s*\.\w+\.\);",
            curve,
            text,
        )
        return re.sub(
            r"B_SPLINE_SURFACE_WITH_KNOTS\(('[^']*'),(\d+),(\d+),(\((?:\s*,?\s*\([^)]*\))*\s*\)),(\.\w+\.,\.\w+\.,\.\w+\.,\.\w+\.),\s*\(([^)]*)\),\s*\(([^)]*)\),\s*\(([^)]*)\),\s*\(([^)]*)\),\s*\.\w+\.\);",
            surface,
            text,
        )

    return edit


def analytic_block():
    """A block with a bore, a countersink, a spherical pocket and a filleted boss."""
    from OCP.BRepAlgoAPI import BRepAlgoAPI_Fuse
    from OCP.BRepFilletAPI import BRepFilletAPI_MakeFillet
    from OCP.TopAbs import TopAbs_EDGE

    box = BRepPrimAPI_MakeBox(80, 50, 30).Shape()
    bore = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(20, 25, -1), gp_Dir(0, 0, 1)), 6, 32).Shape()
    sink = BRepPrimAPI_MakeCone(gp_Ax2(gp_Pnt(20, 25, 24), gp_Dir(0, 0, 1)), 6, 12, 6.01).Shape()
    ball = BRepPrimAPI_MakeSphere(gp_Pnt(55, 25, 38), 12).Shape()
    boss = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(62, 12, 30), gp_Dir(0, 0, 1)), 7, 8).Shape()
    body = BRepAlgoAPI_Cut(BRepAlgoAPI_Cut(BRepAlgoAPI_Cut(box, bore).Shape(), sink).Shape(), ball).Shape()
    body = BRepAlgoAPI_Fuse(body, boss).Shape()
    fillet = BRepFilletAPI_MakeFillet(body)
    ex = TopExp_Explorer(body, TopAbs_EDGE)
    while ex.More():
        e = TopoDS.Edge_s(ex.Current())
        c = BRepAdaptor_Curve(e)
        if c.GetType() == GeomAbs_CurveType.GeomAbs_Circle:
            circ = c.Circle()
            if abs(circ.Radius() - 7) < 1e-6 and abs(circ.Location().Z() - 38) < 1e-6:
                fillet.Add(2.0, e)
        ex.Next()
    return fillet.Shape()


def degrees(text):
    """The plane angle unit declared as a degree (a conversion-based unit), and the
    cone's semi-angle written in it."""
    text = re.sub(
        r"#(\d+) = \( NAMED_UNIT\(\*\) PLANE_ANGLE_UNIT\(\) SI_UNIT\(\$,\.RADIAN\.\) \);",
        lambda m: f"#{m.group(1)} = ( CONVERSION_BASED_UNIT('DEGREE',#990001) NAMED_UNIT(#990003) PLANE_ANGLE_UNIT() );\n"
        "#990001 = PLANE_ANGLE_MEASURE_WITH_UNIT(PLANE_ANGLE_MEASURE(0.0174532925199433),#990002);\n"
        "#990002 = ( NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.) );\n"
        "#990003 = DIMENSIONAL_EXPONENTS(0.,0.,0.,0.,0.,0.,0.);",
        text,
    )

    def cone(m):
        return f"{m.group(1)}{float(m.group(2)) * 180 / math.pi!r}{m.group(3)}"

    return re.sub(r"(CONICAL_SURFACE\('',#\d+,[-0-9.E+]+,)([-0-9.E+]+)(\))", cone, text)


def d_plate():
    """A plate with a round end and a bore: lines, a half circle, full circles."""
    from OCP.GC import GC_MakeArcOfCircle

    arc = GC_MakeArcOfCircle(gp_Pnt(40, 0, 0), gp_Pnt(55, 15, 0), gp_Pnt(40, 30, 0)).Value()
    edges = [segment((0, 0, 0), (40, 0, 0)), BRepBuilderAPI_MakeEdge(arc).Edge(), segment((40, 30, 0), (0, 30, 0)), segment((0, 30, 0), (0, 0, 0))]
    plate = BRepPrimAPI_MakePrism(profile_face(edges), gp_Vec(0, 0, 12)).Shape()
    bore = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(18, 15, -1), gp_Dir(0, 0, 1)), 6, 14).Shape()
    return BRepAlgoAPI_Cut(plate, bore).Shape()


def offset_blob():
    """The blob's B-spline (made not periodic) and its offset 3 mm inward, the way
    STEP's OFFSET_CURVE_3D with distance 3 and reference +z puts it: OpenCASCADE's offset
    by -3 along T x V is the standard's by 3 along V x T."""
    from OCP.Geom import Geom_OffsetCurve

    c = interpolate([(30, 0, 0), (20, 18, 0), (0, 25, 0), (-22, 15, 0), (-28, -5, 0), (-10, -22, 0), (15, -20, 0)], True)
    c.SetNotPeriodic()
    return c, Geom_OffsetCurve(c, -3.0, gp_Dir(0, 0, 1))


def offset_prism(exact):
    """The offset blob swept 20 mm along z: exactly, or (for the file OpenCASCADE can
    write, whose curves the edit replaces) with the offset approximated."""
    from OCP.GeomAbs import GeomAbs_Shape
    from OCP.GeomConvert import GeomConvert_ApproxCurve

    _, off = offset_blob()
    curve = off if exact else GeomConvert_ApproxCurve(off, 1e-7, GeomAbs_Shape.GeomAbs_C2, 200, 9).Curve()
    f = BRepBuilderAPI_MakeFace(wire(BRepBuilderAPI_MakeEdge(curve).Edge())).Face()
    return BRepPrimAPI_MakePrism(f, gp_Vec(0, 0, 20)).Shape()


def ruled_loft():
    """A solid ruled between the blob's B-spline at z = 0 and a copy of it shrunk to 0.6
    and turned 20° at z = 25 (the same knots, so corresponding points share a parameter)."""
    from OCP.BRepOffsetAPI import BRepOffsetAPI_ThruSections
    from OCP.gp import gp_Trsf

    c = interpolate([(30, 0, 0), (20, 18, 0), (0, 25, 0), (-22, 15, 0), (-28, -5, 0), (-10, -22, 0), (15, -20, 0)], True)
    top = c.Copy()
    t = gp_Trsf()
    t.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), math.radians(20))
    s = gp_Trsf()
    s.SetScale(gp_Pnt(0, 0, 0), 0.6)
    m = gp_Trsf()
    m.SetTranslation(gp_Vec(0, 0, 25))
    top.Transform(m.Multiplied(t.Multiplied(s)))
    loft = BRepOffsetAPI_ThruSections(True, True)
    loft.AddWire(wire(BRepBuilderAPI_MakeEdge(c).Edge()))
    loft.AddWire(wire(BRepBuilderAPI_MakeEdge(top).Edge()))
    loft.Build()
    return loft.Shape()


def thin_ring():
    """A ring whose bore is 0.95 mm off its axis: its wall is 0.05 mm thin on one side,
    less than the 0.1 mm chord parts are meshed to, so that the chords of its two sides
    cross in the end faces' parameters (a sliver wall)."""
    outer = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 21, 10).Shape()
    bore = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(0, 0.95, -1), gp_Dir(0, 0, 1)), 20, 12).Shape()
    return BRepAlgoAPI_Cut(outer, bore).Shape()


def main():
    import sys

    from curves_edit import composite, offset_curves

    only = set(sys.argv[1:])
    if only:
        # Only the named parts (the others' files stay as they are).
        global write
        all_write = write
        write = lambda name, *a, **k: all_write(name, *a, **k) if name in only else None
    basis, _ = offset_blob()
    write("composite", d_plate(), edit=composite, what="every edge's curve a composite of two trimmed stretches (COMPOSITE_CURVE, TRIMMED_CURVE)")
    write("spline", BRepBuilderAPI_NurbsConvert(spline_prism([4, 1, 1, 1, 4], [0, 1, 2, 3, 4]), True).Shape(), qif="v", qif_kinds={"splines": True},
          what="the quasi-uniform spline plate with every face and edge a B-spline, written to QIF as polynomial pieces (Spline13, Spline23)")
    write("ruled", ruled_loft(), qif="u", qif_kinds={"ruled": True}, what="a loft ruled between a B-spline and its smaller copy (QIF Ruled23)")
    write("thin_wall", thin_ring(), what="a ring with a wall 0.05 mm thin: its end faces' bounds cross at the 0.1 mm chord")
    write("offset_curve", offset_prism(True), edit=offset_curves(basis, 3.0, (0.0, 0.0, 1.0)), step_shape=offset_prism(False), what="a B-spline's offset swept along z (OFFSET_CURVE_3D)")
    write("extrusion_bspline", blob_prism(), what="a closed B-spline swept along z (SURFACE_OF_LINEAR_EXTRUSION, seam)", qif="u")
    write("extrusion_ellipse", ellipse_prism(), what="an ellipse swept along its normal", qif="u")
    write("extrusion_oblique", oblique_prism(), what="a circle swept along a slanted vector")
    write("revolution_bspline", vase(), what="a B-spline revolved once round (SURFACE_OF_REVOLUTION, seam)", qif="u")
    write("revolution_partial", vase(2 * math.pi / 3), what="a B-spline revolved through 120 degrees")
    write("revolution_pole", dome(), what="a B-spline revolved from the axis: a pole", qif="u")
    write("conics", conics(), what="a plate bounded by a parabola and a hyperbola, extruded", qif="u")
    write("nurbs", nurbs_cap(), what="a block with a spherical pocket, every face a rational B-spline", qif="v")
    write("offset", offset_vase(), what="the revolved vase grown 2 mm (OFFSET_SURFACE)", qif="u")
    write("seamless_cylinder", cylinder_block(), edit=without_seam, what="a bore whose cylinder face has no seam edge")
    write("disguised", analytic_block(), edit=disguised, what="planes, cylinders, a cone, a sphere and a torus written as swept and offset surfaces")
    write("bezier", nurbs_cap(), edit=implied_knots("BEZIER"), what="the NURBS block with its lines and planes as Bezier curves and surfaces")
    write("quasi_uniform", spline_prism([4, 1, 1, 1, 4], [0, 1, 2, 3, 4]), edit=implied_knots("QUASI_UNIFORM"), what="a quasi-uniform cubic B-spline, knots implied")
    write("uniform", spline_prism([1] * 11, [float(k) for k in range(-3, 8)]), edit=implied_knots("UNIFORM"), what="a uniform cubic B-spline, knots implied")
    write("disguised_far", analytic_block(), edit=disguised_far, what="the disguised block with its cone's line given beyond the apex")
    write("offset_ellipse", offset_ellipse_prism(), what="an offset of an extruded ellipse (OFFSET_SURFACE of SURFACE_OF_LINEAR_EXTRUSION)")
    write("unit_inch", cylinder_block(), unit="INCH", unit_mm=1.0, what="lengths in inches")
    write("unit_metre", cylinder_block(), unit="M", unit_mm=1.0, what="lengths in metres")
    write("unit_degree", cone_block(), edit=degrees, what="plane angles in degrees (a conversion-based unit)")


if __name__ == "__main__":
    main()
