"""QIF 3 piecewise polynomial and ruled elements for `qif_writer.py`: an OpenCASCADE
B-spline as `Spline13Core` / `Spline23Core` (Geometry.xsd; each knot span's polynomial
in increasing powers of `t - t_i`, or of `(t - t_i) / (t_{i+1} - t_i)` when
`normalized`), and a surface of degree 1 with two rows of poles in one direction as
`Ruled23Core` between its two boundary curves. Not run by CI."""

import math


def fmt(*xs):
    return " ".join(repr(float(x)) for x in xs)


def taylor_shift(d, h):
    """Coefficients about a span's start from Taylor coefficients `d` about its middle
    (`d[m]` the m-th derivative / m!): a_j = sum_{m>=j} C(m, j) d_m (-h/2)^(m-j)."""
    n = len(d)
    return [sum(math.comb(m, j) * d[m] * (-h / 2) ** (m - j) for m in range(j, n)) for j in range(n)]


def spans(knots):
    return [(a, b) for a, b in zip(knots, knots[1:]) if b > a]


def curve_knots(b):
    return [b.Knot(i) for i in range(1, b.NbKnots() + 1)]


def spline13_core(b, first, last, normalized):
    """A non-rational B-spline curve (OpenCASCADE's `Geom_BSplineCurve`) as Spline13Core."""
    p = b.Degree()
    breaks, coefs = [], []
    for a, z in spans(curve_knots(b)):
        h, mid = z - a, 0.5 * (a + z)
        per_axis = []
        for axis in range(3):
            d = [b.Value(mid).Coord(axis + 1)] + [b.DN(mid, m).Coord(axis + 1) / math.factorial(m) for m in range(1, p + 1)]
            c = taylor_shift(d, h)
            per_axis.append([cj * (h ** j if normalized else 1.0) for j, cj in enumerate(c)])
        coefs += [fmt(*(per_axis[k][j] for k in range(3))) for j in range(p + 1)]
        breaks.append(a)
    breaks.append(spans(curve_knots(b))[-1][1])
    n = len(breaks) - 1
    norm = ' normalized="true"' if normalized else ""
    return (f'<Spline13Core domain="{fmt(first, last)}"{norm}><Knots count="{len(breaks)}">{fmt(*breaks)}</Knots>'
            f'<Orders count="{n}">{" ".join([str(p + 1)] * n)}</Orders><Coefficients count="{len(coefs)}">{" ".join(coefs)}</Coefficients></Spline13Core>', "Spline13")


def spline23_core(b, v_fastest, normalized):
    """A non-rational B-spline surface as Spline23Core: patches and, within a patch,
    coefficients u-fastest (or v-fastest)."""
    p, q = b.UDegree(), b.VDegree()
    us = spans([b.UKnot(i) for i in range(1, b.NbUKnots() + 1)])
    vs = spans([b.VKnot(i) for i in range(1, b.NbVKnots() + 1)])
    patches = [(i, j) for i in range(len(us)) for j in range(len(vs))] if v_fastest else [
        (i, j) for j in range(len(vs)) for i in range(len(us))]
    out = []
    for i, j in patches:
        (u0, u1), (v0, v1) = us[i], vs[j]
        hu, hv = u1 - u0, v1 - v0
        mu, mv = 0.5 * (u0 + u1), 0.5 * (v0 + v1)
        a = {}
        for axis in range(3):
            d = [[(b.Value(mu, mv) if m == n == 0 else b.DN(mu, mv, m, n)).Coord(axis + 1) / (math.factorial(m) * math.factorial(n))
                  for n in range(q + 1)] for m in range(p + 1)]
            for k in range(p + 1):
                for l in range(q + 1):
                    v = sum(math.comb(m, k) * math.comb(n, l) * d[m][n] * (-hu / 2) ** (m - k) * (-hv / 2) ** (n - l)
                            for m in range(k, p + 1) for n in range(l, q + 1))
                    a[(k, l, axis)] = v * (hu ** k * hv ** l if normalized else 1.0)
        order = [(k, l) for k in range(p + 1) for l in range(q + 1)] if v_fastest else [
            (k, l) for l in range(q + 1) for k in range(p + 1)]
        out += [fmt(*(a[(k, l, ax)] for ax in range(3))) for k, l in order]
    bu = [x for x, _ in us] + [us[-1][1]]
    bv = [x for x, _ in vs] + [vs[-1][1]]
    norm = ' normalized="true"' if normalized else ""
    return (f'<Spline23Core{norm}><KnotsU count="{len(bu)}">{fmt(*bu)}</KnotsU><KnotsV count="{len(bv)}">{fmt(*bv)}</KnotsV>'
            f'<OrdersU count="{len(us)}">{" ".join([str(p + 1)] * len(us))}</OrdersU><OrdersV count="{len(vs)}">{" ".join([str(q + 1)] * len(vs))}</OrdersV>'
            f'<Coefficients count="{len(out)}">{" ".join(out)}</Coefficients></Spline23Core>', "Spline23")


def ruled_core(b, curve_core):
    """A B-spline surface of degree 1 with two poles along u or v as Ruled23Core between
    its boundary curves (`curve_core(adaptor, first, last)` writes each), or None."""
    from OCP.GeomAdaptor import GeomAdaptor_Curve

    if b.IsURational() or b.IsVRational():
        return None
    if b.VDegree() == 1 and b.NbVPoles() == 2:
        (v0, v1), iso = b.Bounds()[2:], b.VIso
        ends = b.Bounds()[:2]
    elif b.UDegree() == 1 and b.NbUPoles() == 2:
        (v0, v1), iso = b.Bounds()[:2], b.UIso
        ends = b.Bounds()[2:]
    else:
        return None
    cores = [curve_core(GeomAdaptor_Curve(iso(v)), *ends)[0] for v in (v0, v1)]
    return f"<Ruled23Core><Curve>{cores[0]}</Curve><Curve>{cores[1]}</Curve></Ruled23Core>", "Ruled23"
