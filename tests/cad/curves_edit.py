"""Text edits of OpenCASCADE's STEP files for the curve kinds OpenCASCADE does not
write (`make.py` calls them): composite curves of trimmed segments, and offset curves.
Each edit keeps the geometry exact, so OpenCASCADE's reading of the unedited solid is
the expectation (ISO 10303-42 composite_curve, trimmed_curve, offset_curve_3d)."""

import math
import re


def entities(text):
    """Instance number → (type, parameter text) of every simple instance."""
    out = {}
    for m in re.finditer(r"^#(\d+) = (\w+)\((.*?)\);$", text, re.M | re.S):
        out[int(m.group(1))] = (m.group(2), m.group(3))
    return out


def refs(params):
    return [int(r) for r in re.findall(r"#(\d+)", params)]


def numbers(params):
    return [float(x) for x in re.findall(r"[-+]?\d+\.?\d*(?:E[-+]?\d+)?", params)]


def sub(a, b):
    return [x - y for x, y in zip(a, b)]


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def unit(a):
    n = math.sqrt(dot(a, a))
    return [x / n for x in a]


class Adder:
    """New instances appended at the end of the DATA section."""

    def __init__(self, first):
        self.next = first
        self.lines = []

    def add(self, s):
        self.next += 1
        self.lines.append(f"#{self.next} = {s};")
        return f"#{self.next}"

    def point(self, p):
        return self.add("CARTESIAN_POINT('',(" + ",".join(repr(float(x)) for x in p) + "))")

    def direction(self, d):
        return self.add("DIRECTION('',(" + ",".join(repr(float(x)) for x in d) + "))")

    def finish(self, text):
        return text.replace("ENDSEC;\nEND-ISO", "\n".join(self.lines) + "\nENDSEC;\nEND-ISO", 1)


class Basis:
    """A LINE or CIRCLE instance as a parametrised curve (ISO 10303-42 § 4.4)."""

    def __init__(self, ents, cid):
        kind, params = ents[cid]
        self.kind = kind
        r = refs(params)
        if kind == "LINE":
            self.p = numbers(ents[r[0]][1])
            _, vec = ents[r[1]]
            vr = refs(vec)
            self.d = unit(numbers(ents[vr[0]][1]))
            self.mag = numbers(vec.split(",")[-1])[0]
        elif kind == "CIRCLE":
            a = refs(ents[r[0]][1])
            self.o = numbers(ents[a[0]][1])
            self.z = unit(numbers(ents[a[1]][1]))
            x = numbers(ents[a[2]][1])
            self.x = unit(sub(x, [dot(x, self.z) * c for c in self.z]))
            self.y = cross(self.z, self.x)
            self.r = numbers(params.split(",")[-1])[0]
        else:
            raise ValueError(kind)

    def param(self, q):
        if self.kind == "LINE":
            return dot(sub(q, self.p), self.d) / self.mag
        w = sub(q, self.o)
        return math.atan2(dot(w, self.y), dot(w, self.x))

    def at(self, t):
        if self.kind == "LINE":
            return [p + t * self.mag * d for p, d in zip(self.p, self.d)]
        c, s = math.cos(t), math.sin(t)
        return [o + self.r * (c * x + s * y) for o, x, y in zip(self.o, self.x, self.y)]

    def span(self, a, b, closed):
        """The parameters from point a to point b along the curve's sense."""
        ta, tb = self.param(a), self.param(b)
        if self.kind == "CIRCLE":
            d = (tb - ta) % (2 * math.pi)
            tb = ta + (2 * math.pi if closed or d < 1e-12 else d)
        return ta, tb


def edge_curves(ents):
    """(3D curve's wrapper id, 3D curve id, start point, end point, closed) of every
    EDGE_CURVE: start and end along the curve's own sense."""
    out = []
    for i, (t, a) in sorted(ents.items()):
        if t != "EDGE_CURVE":
            continue
        v1, v2, c = refs(a)[:3]
        same = a.strip().endswith(".T.")
        pts = [numbers(ents[refs(ents[v][1])[0]][1]) for v in (v1, v2)]
        if not same:
            pts.reverse()
        wrapper = c
        inner = refs(ents[c][1])[0] if ents[c][0] in ("SURFACE_CURVE", "SEAM_CURVE") else c
        out.append((wrapper, inner, pts[0], pts[1], v1 == v2))
    return out


def param(x):
    return f"PARAMETER_VALUE({x!r})"


def composite(text):
    """Every edge's curve a COMPOSITE_CURVE of two stretches of its line or circle,
    split at the middle parameter and written three ways in turn: both trimmed by
    parameter; the second trimmed by points (master CARTESIAN); the second trimmed
    against the basis's sense by both point and parameter and run with
    `same_sense = .F.`. Every fourth edge's first segment is itself a one-segment
    composite."""
    ents = entities(text)
    new = Adder(700000)
    replace = {}
    for k, (wrapper, inner, a, b, closed) in enumerate(edge_curves(ents)):
        basis = Basis(ents, inner)
        t0, t1 = basis.span(a, b, closed)
        tm = 0.5 * (t0 + t1)
        first = new.add(f"TRIMMED_CURVE('',#{inner},({param(t0)}),({param(tm)}),.T.,.PARAMETER.)")
        if k % 4 == 3:
            seg = new.add(f"COMPOSITE_CURVE_SEGMENT(.CONTINUOUS.,.T.,{first})")
            first = new.add(f"COMPOSITE_CURVE('',({seg}),.F.)")
        s1 = new.add(f"COMPOSITE_CURVE_SEGMENT(.CONTINUOUS.,.T.,{first})")
        if k % 3 == 0:
            second = new.add(f"TRIMMED_CURVE('',#{inner},({param(tm)}),({param(t1)}),.T.,.PARAMETER.)")
            s2 = new.add(f"COMPOSITE_CURVE_SEGMENT(.CONTINUOUS.,.T.,{second})")
        elif k % 3 == 1:
            pm, p1 = new.point(basis.at(tm)), new.point(basis.at(t1))
            second = new.add(f"TRIMMED_CURVE('',#{inner},({pm}),({p1}),.T.,.CARTESIAN.)")
            s2 = new.add(f"COMPOSITE_CURVE_SEGMENT(.CONTINUOUS.,.T.,{second})")
        else:
            pm, p1 = new.point(basis.at(tm)), new.point(basis.at(t1))
            second = new.add(f"TRIMMED_CURVE('',#{inner},({p1},{param(t1)}),({pm},{param(tm)}),.F.,.UNSPECIFIED.)")
            s2 = new.add(f"COMPOSITE_CURVE_SEGMENT(.CONTINUOUS.,.F.,{second})")
        replace[wrapper] = new.add(f"COMPOSITE_CURVE('',({s1},{s2}),.F.)")

    def swap(m):
        i = int(m.group(1))
        if i not in replace:
            return m.group(0)
        return f"#{i} = {m.group(2)}('',{replace[i]},"

    text = re.sub(r"^#(\d+) = (SURFACE_CURVE|SEAM_CURVE)\('',#\d+,", swap, text, flags=re.M)
    return new.finish(text)


def offset_curves(basis, distance, d_ref):
    """An edit that writes every 3D B-spline curve of the file (the approximated offset
    OpenCASCADE writes for the exact one) as OFFSET_CURVE_3D of `basis` (an OpenCASCADE
    B-spline in the plane z = 0) moved to that curve's height, by `distance` along
    `d_ref × T` (ISO 10303-42 offset_curve_3d)."""

    def edit(text):
        new = Adder(700000)
        made = {}

        def offset_at(z):
            if z not in made:
                b = basis
                poles = ",".join(new.point((b.Pole(i).X(), b.Pole(i).Y(), b.Pole(i).Z() + z)) for i in range(1, b.NbPoles() + 1))
                mults = ",".join(str(b.Multiplicity(i)) for i in range(1, b.NbKnots() + 1))
                knots = ",".join(repr(b.Knot(i)) for i in range(1, b.NbKnots() + 1))
                bs = new.add(f"B_SPLINE_CURVE_WITH_KNOTS('',{b.Degree()},({poles}),.UNSPECIFIED.,.F.,.F.,({mults}),({knots}),.UNSPECIFIED.)")
                made[z] = (bs, new.direction(d_ref))
            bs, d = made[z]
            return f"OFFSET_CURVE_3D('',{bs},{distance!r},.F.,{d})"

        def swap(m):
            pts = re.findall(r"#(\d+)", m.group(3))
            zs = {round(numbers(ents[int(p)][1])[2], 9) for p in pts if len(numbers(ents[int(p)][1])) == 3}
            if len(zs) != 1 or len(numbers(ents[int(pts[0])][1])) != 3:
                return m.group(0)
            return f"#{m.group(1)} = {offset_at(zs.pop())};"

        ents = entities(text)
        text = re.sub(
            r"^#(\d+) = (B_SPLINE_CURVE_WITH_KNOTS)\('',\d+,(\([^)]*\)),.*?\);$",
            swap,
            text,
            flags=re.M | re.S,
        )
        return new.finish(text)

    return edit
