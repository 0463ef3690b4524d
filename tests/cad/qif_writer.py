"""A QIF 3 MBD writer for the fixtures: an OpenCASCADE solid's B-rep as QIF's
GeometrySet and TopologySet (Geometry.xsd, Topology.xsd of ../shared/qif3-schema),
with no PMI. Not run by CI; `make.py` calls it.

Conventions the schema leaves open, as inspc's reader reads them (src/geometry/qif):
a conic arc's `A` and `B` are its diameters (twice the semi-axes; for a parabola A is
twice the focal distance), as the schema's text says; NURBS control points go
u-fastest unless `v_fastest`; loops run counter-clockwise in the surface's parameters
(a reversed face's wires are written backwards).
"""

import math

from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepTools import BRepTools_WireExplorer
from OCP.GeomAbs import GeomAbs_CurveType, GeomAbs_SurfaceType
from OCP.GeomAdaptor import GeomAdaptor_Curve
from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED, TopAbs_WIRE
from OCP.TopExp import TopExp, TopExp_Explorer
from OCP.TopoDS import TopoDS
from OCP.TopTools import TopTools_IndexedMapOfShape


def bounded(c):
    """A curve's parameter range, an unbounded one (a line, a conic) cut to [0, 1]."""
    first, last = c.FirstParameter(), c.LastParameter()
    if abs(first) > 1e100 or abs(last) > 1e100:
        return 0.0, 1.0
    return first, last


def axis(ax):
    return f"<Axis><AxisPoint>{pnt(ax.Location())}</AxisPoint><Direction>{pnt(ax.Direction())}</Direction></Axis>"


def sweep(ax):
    return f"<Sweep><DirBeg>{pnt(ax.XDirection())}</DirBeg><DomainAngle>0 {fmt(2 * math.pi)}</DomainAngle></Sweep>"


def lat_long(ax):
    return (f"<LatitudeLongitudeSweep><DirMeridianPrime>{pnt(ax.XDirection())}</DirMeridianPrime>"
            f"<DomainLatitude>{fmt(-math.pi / 2, math.pi / 2)}</DomainLatitude><DomainLongitude>0 {fmt(2 * math.pi)}</DomainLongitude></LatitudeLongitudeSweep>")


def fmt(*xs):
    return " ".join(repr(float(x)) for x in xs)


def pnt(p):
    return fmt(p.X(), p.Y(), p.Z())


class Writer:
    def __init__(self, v_fastest=False, splines=False, ruled=False):
        """`splines`: non-rational B-splines written as Spline13/Spline23 (`qif_splines.py`,
        every other one normalised); `ruled`: a surface of degree 1 with two rows of poles
        as Ruled23."""
        self.next = 0
        self.v_fastest = v_fastest
        self.splines = splines
        self.ruled = ruled
        self.points, self.curves, self.surfaces = [], [], []
        self.vertices, self.edges, self.loops, self.faces = [], [], [], []

    def id(self):
        self.next += 1
        return self.next

    def curve_core(self, a, first, last):
        """The core element of a 3D curve (an OCC curve adaptor) over [first, last]."""
        t = a.GetType()
        dom = f'domain="{fmt(first, last)}"'
        if t == GeomAbs_CurveType.GeomAbs_Line:
            return f"<Segment13Core domain=\"0 1\"><StartPoint>{pnt(a.Value(first))}</StartPoint><EndPoint>{pnt(a.Value(last))}</EndPoint></Segment13Core>", "Segment13"
        if t == GeomAbs_CurveType.GeomAbs_Circle:
            ci = a.Circle()
            ax = ci.Position()
            return (f"<ArcCircular13Core {dom}><Radius>{fmt(ci.Radius())}</Radius><Center>{pnt(ci.Location())}</Center>"
                    f"<DirBeg>{pnt(ax.XDirection())}</DirBeg><Normal>{pnt(ax.Direction())}</Normal></ArcCircular13Core>", "ArcCircular13")
        conic = {
            GeomAbs_CurveType.GeomAbs_Ellipse: ("ELLIPSE", lambda: a.Ellipse(), lambda g: (g.MajorRadius(), g.MinorRadius())),
            GeomAbs_CurveType.GeomAbs_Hyperbola: ("HYPERBOLA", lambda: a.Hyperbola(), lambda g: (g.MajorRadius(), g.MinorRadius())),
            GeomAbs_CurveType.GeomAbs_Parabola: ("PARABOLA", lambda: a.Parabola(), lambda g: (g.Focal(), g.Focal())),
        }
        if t in conic:
            form, get, radii = conic[t]
            g = get()
            ax = g.Position()
            ra, rb = radii(g)
            if form == "PARABOLA":
                # OpenCASCADE's parameter U is ISO 10303-42's t = U / 2f (the reader's).
                first, last = first / (2 * ra), last / (2 * ra)
                dom = f'domain="{fmt(first, last)}"'
            return (f'<ArcConic13Core {dom} form="{form}"><A>{fmt(2 * ra)}</A><B>{fmt(2 * rb)}</B><Center>{pnt(g.Location())}</Center>'
                    f"<DirBeg>{pnt(ax.XDirection())}</DirBeg><Normal>{pnt(ax.Direction())}</Normal></ArcConic13Core>", "ArcConic13")
        if t == GeomAbs_CurveType.GeomAbs_BSplineCurve:
            b = a.BSpline()
            if b.IsPeriodic():
                # QIF's knot vector is the full one, poles + order long.
                b = b.Copy()
                b.SetNotPeriodic()
            if self.splines and not b.IsRational():
                from qif_splines import spline13_core

                return spline13_core(b, first, last, normalized=self.next % 2 == 0)
            knots = []
            for i in range(1, b.NbKnots() + 1):
                knots += [b.Knot(i)] * b.Multiplicity(i)
            cps = " ".join(pnt(b.Pole(i)) for i in range(1, b.NbPoles() + 1))
            w = " ".join(fmt(b.Weight(i)) for i in range(1, b.NbPoles() + 1))
            n = b.NbPoles()
            return (f'<Nurbs13Core {dom}><Order>{b.Degree() + 1}</Order><Knots count="{len(knots)}">{fmt(*knots)}</Knots>'
                    f'<CPs count="{n}">{cps}</CPs><Weights count="{n}">{w}</Weights></Nurbs13Core>', "Nurbs13")
        raise ValueError(f"curve type {t}")

    def surface_core(self, s):
        """The core element of a surface (an OCC Geom_Surface)."""
        from OCP.GeomAdaptor import GeomAdaptor_Surface

        a = GeomAdaptor_Surface(s)
        t = a.GetType()
        if t == GeomAbs_SurfaceType.GeomAbs_Plane:
            ax = a.Plane().Position()
            return (f'<Plane23Core domainU="-1e3 1e3" domainV="-1e3 1e3"><Origin>{pnt(ax.Location())}</Origin>'
                    f"<DirU>{pnt(ax.XDirection())}</DirU><DirV>{pnt(ax.YDirection())}</DirV></Plane23Core>", "Plane23")
        if t == GeomAbs_SurfaceType.GeomAbs_Cylinder:
            c = a.Cylinder()
            ax = c.Position()
            return (f"<Cylinder23Core><Diameter>{fmt(2 * c.Radius())}</Diameter><Length>1000.0</Length>{axis(ax)}{sweep(ax)}</Cylinder23Core>", "Cylinder23")
        if t == GeomAbs_SurfaceType.GeomAbs_Torus:
            c = a.Torus()
            ax = c.Position()
            return (f"<Torus23Core><DiameterMinor>{fmt(2 * c.MinorRadius())}</DiameterMinor><DiameterMajor>{fmt(2 * c.MajorRadius())}</DiameterMajor>"
                    f"{axis(ax)}{lat_long(ax)}</Torus23Core>", "Torus23")
        if t == GeomAbs_SurfaceType.GeomAbs_Sphere:
            c = a.Sphere()
            ax = c.Position()
            return (f"<Sphere23Core><Diameter>{fmt(2 * c.Radius())}</Diameter><Location>{pnt(ax.Location())}</Location>"
                    f"{lat_long(ax)}</Sphere23Core>", "Sphere23")
        if t == GeomAbs_SurfaceType.GeomAbs_Cone:
            c = a.Cone()
            ax = c.Position()
            # A stretch 10 mm long from the reference radius: the reader takes the
            # semi-angle from the two diameters.
            r, top = c.RefRadius(), c.RefRadius() + 10 * math.tan(c.SemiAngle())
            return (f"<Cone23Core><DiameterBottom>{fmt(2 * r)}</DiameterBottom><DiameterTop>{fmt(2 * top)}</DiameterTop><Length>10.0</Length>"
                    f"{axis(ax)}{sweep(ax)}</Cone23Core>", "Cone23")
        if t == GeomAbs_SurfaceType.GeomAbs_BSplineSurface:
            b = a.BSpline()
            if b.IsUPeriodic() or b.IsVPeriodic():
                # QIF's knot vectors are the full ones, poles + order long.
                b = b.Copy()
                if b.IsUPeriodic():
                    b.SetUNotPeriodic()
                if b.IsVPeriodic():
                    b.SetVNotPeriodic()
            if self.ruled:
                from qif_splines import ruled_core

                core = ruled_core(b, self.curve_core)
                if core:
                    return core
            if self.splines and not (b.IsURational() or b.IsVRational()):
                from qif_splines import spline23_core

                return spline23_core(b, self.v_fastest, normalized=self.next % 2 == 1)
            nu, nv = b.NbUPoles(), b.NbVPoles()

            def knots(n, k, m):
                out = []
                for i in range(1, n + 1):
                    out += [k(i)] * m(i)
                return out

            ku = knots(b.NbUKnots(), b.UKnot, b.UMultiplicity)
            kv = knots(b.NbVKnots(), b.VKnot, b.VMultiplicity)
            order = [(i, j) for i in range(1, nu + 1) for j in range(1, nv + 1)] if self.v_fastest else [
                (i, j) for j in range(1, nv + 1) for i in range(1, nu + 1)]
            cps = " ".join(pnt(b.Pole(i, j)) for i, j in order)
            w = " ".join(fmt(b.Weight(i, j)) for i, j in order)
            return (f'<Nurbs23Core><OrderU>{b.UDegree() + 1}</OrderU><OrderV>{b.VDegree() + 1}</OrderV><KnotsU count="{len(ku)}">{fmt(*ku)}</KnotsU>'
                    f'<KnotsV count="{len(kv)}">{fmt(*kv)}</KnotsV><CPs count="{nu * nv}">{cps}</CPs><Weights count="{nu * nv}">{w}</Weights></Nurbs23Core>', "Nurbs23")
        if t == GeomAbs_SurfaceType.GeomAbs_SurfaceOfExtrusion:
            c = a.BasisCurve()
            first, last = bounded(c)
            core, _ = self.curve_core(c, first, last)
            d = a.Direction()
            start = c.Value(first)
            end = (start.X() + d.X(), start.Y() + d.Y(), start.Z() + d.Z())
            return f"<Extrude23Core><TerminationPoint>{fmt(*end)}</TerminationPoint><Curve>{core}</Curve></Extrude23Core>", "Extrude23"
        if t == GeomAbs_SurfaceType.GeomAbs_SurfaceOfRevolution:
            c = a.BasisCurve()
            core, _ = self.curve_core(c, *bounded(c))
            ax = a.AxeOfRevolution()
            return f'<Revolution23Core angle="0 {fmt(2 * math.pi)}">{axis(ax)}<Generatrix>{core}</Generatrix></Revolution23Core>', "Revolution23"
        if t == GeomAbs_SurfaceType.GeomAbs_OffsetSurface:
            from OCP.Geom import Geom_OffsetSurface

            off = Geom_OffsetSurface.DownCast(s) if hasattr(Geom_OffsetSurface, "DownCast") else s
            base_core, _ = self.surface_core(off.BasisSurface())
            return f"<Offset23Core><Distance>{fmt(off.Offset())}</Distance><Surface>{base_core}</Surface></Offset23Core>", "Offset23"
        raise ValueError(f"surface type {t}")

    def write(self, shape):
        from OCP.BRepLib import BRepLib

        BRepLib.BuildCurves3d_s(shape)
        vmap, emap = TopTools_IndexedMapOfShape(), TopTools_IndexedMapOfShape()
        from OCP.TopAbs import TopAbs_EDGE, TopAbs_VERTEX

        TopExp.MapShapes_s(shape, TopAbs_VERTEX, vmap)
        TopExp.MapShapes_s(shape, TopAbs_EDGE, emap)
        vid, eid = {}, {}
        for i in range(1, vmap.Extent() + 1):
            p = BRep_Tool.Pnt_s(TopoDS.Vertex_s(vmap.FindKey(i)))
            pid, v = self.id(), self.id()
            self.points.append(f'<Point id="{pid}"><XYZ>{pnt(p)}</XYZ></Point>')
            self.vertices.append(f'<Vertex id="{v}"><Point><Id>{pid}</Id></Point></Vertex>')
            vid[i] = v
        for i in range(1, emap.Extent() + 1):
            e = TopoDS.Edge_s(emap.FindKey(i))
            if BRep_Tool.Degenerated_s(e):
                # A pole's edge has no curve: the loop passes through the pole's vertex.
                continue
            from OCP.BRepAdaptor import BRepAdaptor_Curve

            a = BRepAdaptor_Curve(e)
            core, name = self.curve_core(a, a.FirstParameter(), a.LastParameter())
            cid, ed = self.id(), self.id()
            self.curves.append(f'<{name} id="{cid}">{core}</{name}>')
            from OCP.TopoDS import TopoDS_Vertex

            v0, v1 = TopoDS_Vertex(), TopoDS_Vertex()
            TopExp.Vertices_s(e, v0, v1)
            self.edges.append(f'<Edge id="{ed}"><Curve><Id>{cid}</Id></Curve><VertexBeg><Id>{vid[vmap.FindIndex(v0)]}</Id></VertexBeg>'
                              f"<VertexEnd><Id>{vid[vmap.FindIndex(v1)]}</Id></VertexEnd></Edge>")
            eid[i] = ed
        face_ids = []
        ex = TopExp_Explorer(shape, TopAbs_FACE)
        while ex.More():
            f = TopoDS.Face_s(ex.Current())
            reversed_face = f.Orientation() == TopAbs_REVERSED
            core, name = self.surface_core(BRep_Tool.Surface_s(f))
            sid = self.id()
            self.surfaces.append(f'<{name} id="{sid}">{core}</{name}>')
            loop_ids = []
            wx = TopExp_Explorer(f, TopAbs_WIRE)
            while wx.More():
                w = TopoDS.Wire_s(wx.Current())
                co = []
                it = BRepTools_WireExplorer(w, f)
                while it.More():
                    e = it.Current()
                    if BRep_Tool.Degenerated_s(e):
                        it.Next()
                        continue
                    # The edge's own orientation in the wire (the explorer's Orientation()
                    # is composed with the face's).
                    co.append((eid[emap.FindIndex(e)], e.Orientation() == TopAbs_REVERSED))
                    it.Next()
                if reversed_face:
                    co = [(e, not t) for e, t in reversed(co)]
                lid = self.id()
                turned = ' turned="true"'
                coedges = "".join(
                    f"<CoEdge><EdgeOriented{turned if t else ''}><Id>{e}</Id></EdgeOriented></CoEdge>" for e, t in co)
                self.loops.append(f'<Loop id="{lid}"><CoEdges n="{len(co)}">{coedges}</CoEdges></Loop>')
                loop_ids.append(lid)
                wx.Next()
            fid = self.id()
            ids = "".join(f"<Id>{l}</Id>" for l in loop_ids)
            self.faces.append(f'<Face id="{fid}"><Surface><Id>{sid}</Id></Surface><LoopIds n="{len(loop_ids)}">{ids}</LoopIds></Face>')
            face_ids.append(fid)
            ex.Next()
        body = self.id()
        fids = "".join(f"<Id>{f}</Id>" for f in face_ids)
        n = lambda xs: "\n".join(xs)
        return f"""<?xml version="1.0" encoding="utf-8"?>
<QIFDocument xmlns="http://qifstandards.org/xsd/qif3" versionQIF="3.0.0" idMax="{self.next + 1}">
<QPId>d5d1c1e2-0a7e-4b7a-9c1f-1d2c3b4a5e6f</QPId>
<FileUnits><PrimaryUnits><LinearUnit><SIUnitName>meter</SIUnitName><UnitName>mm</UnitName><UnitConversion><Factor>0.001</Factor></UnitConversion></LinearUnit></PrimaryUnits></FileUnits>
<Product><GeometrySet>
<PointSet n="{len(self.points)}">{n(self.points)}</PointSet>
<Curve13Set n="{len(self.curves)}">{n(self.curves)}</Curve13Set>
<SurfaceSet n="{len(self.surfaces)}">{n(self.surfaces)}</SurfaceSet>
</GeometrySet>
<TopologySet>
<VertexSet n="{len(self.vertices)}">{n(self.vertices)}</VertexSet>
<EdgeSet n="{len(self.edges)}">{n(self.edges)}</EdgeSet>
<LoopSet n="{len(self.loops)}">{n(self.loops)}</LoopSet>
<FaceSet n="{len(self.faces)}">{n(self.faces)}</FaceSet>
<BodySet n="1"><Body id="{body}" form="SOLID"><FaceIds n="{len(face_ids)}">{fids}</FaceIds></Body></BodySet>
</TopologySet></Product>
</QIFDocument>
"""
