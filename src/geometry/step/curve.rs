//! The exact curves of a STEP or QIF B-rep, and the frames and knot vectors curves and
//! surfaces share: evaluation, and the inverse from a point to its parameter (ISO
//! 10303-42 § 4.4 parametrisations; angles are radians, lengths millimetres).

use super::composite::{Composite, OffsetCurve};
use crate::geometry::{P3, V3};
use std::f64::consts::TAU;
use std::sync::Arc;

/// A right-handed orthonormal frame (STEP's `AXIS2_PLACEMENT_3D`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Origin.
    pub o: P3,
    /// Reference direction.
    pub x: V3,
    /// `z × x`.
    pub y: V3,
    /// Axis.
    pub z: V3,
}

impl Frame {
    /// The frame from an origin, an axis and a reference direction (either may be
    /// missing: STEP's defaults apply).
    pub fn new(o: P3, axis: Option<V3>, reference: Option<V3>) -> Option<Frame> {
        let z = axis.unwrap_or(V3::z()).try_normalize(1e-12)?;
        let guess = reference.unwrap_or(if z.x.abs() < 0.9 { V3::x() } else { V3::y() });
        let x = (guess - z * guess.dot(&z)).try_normalize(1e-12)?;
        Some(Frame {
            o,
            x,
            y: z.cross(&x),
            z,
        })
    }

    /// Local coordinates of `p`.
    pub(crate) fn local(&self, p: &P3) -> V3 {
        let d = p - self.o;
        V3::new(d.dot(&self.x), d.dot(&self.y), d.dot(&self.z))
    }

    pub(crate) fn at(&self, x: f64, y: f64, z: f64) -> P3 {
        self.o + self.x * x + self.y * y + self.z * z
    }
}

/// The highest B-spline degree read (CAD systems write up to 9 or so).
pub(crate) const MAX_DEGREE: usize = 15;

/// A non-uniform rational B-spline in any number of parameters' worth of control points:
/// one knot vector and degree per direction (used for curves and surfaces).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Knots {
    /// Degree.
    pub degree: usize,
    /// The full knot vector (multiplicities expanded).
    pub knots: Vec<f64>,
}

impl Knots {
    /// The knot vector from STEP's distinct knots and multiplicities; `None` when it
    /// does not fit `n` control points of this degree.
    ///
    /// The multiplicities are summed and checked against the `n + degree + 1` knots
    /// the control points already read call for before anything is allocated from
    /// them: a file's counts never size memory by themselves (a multiplicity of 10¹²
    /// is refused, not expanded).
    pub fn new(degree: usize, mults: &[i64], values: &[f64], n: usize) -> Option<Knots> {
        if mults.len() != values.len() || degree == 0 || degree > MAX_DEGREE {
            return None;
        }
        let want = n.checked_add(degree + 1)?;
        let mut total = 0usize;
        for m in mults {
            let m = usize::try_from(*m).ok().filter(|m| *m >= 1)?;
            total = total.checked_add(m).filter(|t| *t <= want)?;
        }
        if total != want {
            return None;
        }
        let mut knots = Vec::with_capacity(want);
        for (m, v) in mults.iter().zip(values) {
            knots.extend(std::iter::repeat_n(*v, *m as usize));
        }
        Knots::checked(degree, knots)
    }

    /// A knot vector given in full (QIF writes it so): `None` unless it is
    /// non-decreasing (no NaN), of a degree inspc evaluates, and long enough for the
    /// `degree + 1` control points the degree needs at least (the caller checks it
    /// against its own points).
    pub fn checked(degree: usize, knots: Vec<f64>) -> Option<Knots> {
        if degree == 0 || degree > MAX_DEGREE || knots.len() < 2 * (degree + 1) {
            return None;
        }
        if knots.iter().any(|k| k.is_nan()) || knots.windows(2).any(|w| w[1] < w[0]) {
            return None;
        }
        Some(Knots { degree, knots })
    }

    /// The parameter range.
    pub fn range(&self) -> (f64, f64) {
        let n = self.knots.len() - self.degree - 1;
        (self.knots[self.degree], self.knots[n])
    }

    /// The span index `k` with `knots[k] ≤ t < knots[k+1]`, clamped to the range.
    fn span(&self, t: f64) -> usize {
        let n = self.knots.len() - self.degree - 1;
        let p = self.degree;
        if t >= self.knots[n] {
            let mut k = n - 1;
            while k > p && self.knots[k] >= self.knots[k + 1] {
                k -= 1;
            }
            return k;
        }
        let mut k = p;
        while k + 1 < n && self.knots[k + 1] <= t {
            k += 1;
        }
        k
    }

    /// The distinct knots inside the range, with the ends.
    pub(crate) fn breaks(&self) -> Vec<f64> {
        let (a, b) = self.range();
        let mut out: Vec<f64> = self
            .knots
            .iter()
            .copied()
            .filter(|k| *k >= a && *k <= b)
            .collect();
        out.dedup();
        out
    }

    /// The basis functions' non-zero values at `t`: (first index, values; the first
    /// `degree + 1` are used).
    pub(super) fn basis(&self, t: f64) -> (usize, [f64; MAX_DEGREE + 1]) {
        let p = self.degree;
        let k = self.span(t);
        let (a, b) = self.range();
        let t = t.clamp(a, b);
        let u = &self.knots;
        let mut n = [0.0; MAX_DEGREE + 1];
        let mut left = [0.0; MAX_DEGREE + 1];
        let mut right = [0.0; MAX_DEGREE + 1];
        n[0] = 1.0;
        for j in 1..=p {
            left[j] = t - u[k + 1 - j];
            right[j] = u[k + j] - t;
            let mut saved = 0.0;
            for r in 0..j {
                let den = right[r + 1] + left[j - r];
                let temp = if den.abs() > 0.0 { n[r] / den } else { 0.0 };
                n[r] = saved + right[r + 1] * temp;
                saved = left[j - r] * temp;
            }
            n[j] = saved;
        }
        (k - p, n)
    }
}

/// A B-spline curve.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct BSplineCurve {
    /// Knots and degree.
    pub knots: Knots,
    /// Control points.
    pub points: Vec<P3>,
    /// Weights (all 1 for a non-rational curve).
    pub weights: Vec<f64>,
}

impl BSplineCurve {
    /// The point at `t`.
    pub fn eval(&self, t: f64) -> P3 {
        let (first, n) = self.knots.basis(t);
        let mut sum = V3::zeros();
        let mut w = 0.0;
        for (j, b) in n[..=self.knots.degree].iter().enumerate() {
            let i = first + j;
            sum += self.points[i].coords * (b * self.weights[i]);
            w += b * self.weights[i];
        }
        P3::from(sum / w)
    }
}

/// An edge's curve (ISO 10303-42 § 4.4 parametrisations).
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Curve {
    /// A straight line: a point and the vector one unit of parameter moves along it.
    Line(P3, V3),
    /// A circle in the frame's xy plane, parametrised by angle from x.
    Circle(Frame, f64),
    /// An ellipse: semi-axes along x and y.
    Ellipse(Frame, f64, f64),
    /// A parabola with this focal distance: `C + f·(t²·x + 2t·y)`.
    Parabola(Frame, f64),
    /// One branch of a hyperbola with these semi-axes: `C + a·cosh t·x + b·sinh t·y`.
    Hyperbola(Frame, f64, f64),
    /// A B-spline curve (shared: every edge on it holds the one read).
    BSpline(Arc<BSplineCurve>),
    /// A polyline through these points (shared likewise), parametrised from 0 at the
    /// first point by one per segment (ISO 10303-42 `polyline`).
    Polyline(Arc<[P3]>),
    /// Stretches of other curves joined end to end (shared; `composite.rs`).
    Composite(Arc<Composite>),
    /// A curve at a constant distance from another (shared; `composite.rs`).
    Offset(Arc<OffsetCurve>),
}

impl Curve {
    /// The point at parameter `t`.
    pub fn eval(&self, t: f64) -> P3 {
        match self {
            Curve::Line(o, d) => o + d * t,
            Curve::Circle(f, r) => f.at(r * t.cos(), r * t.sin(), 0.0),
            Curve::Ellipse(f, a, b) => f.at(a * t.cos(), b * t.sin(), 0.0),
            Curve::Parabola(f, focal) => f.at(focal * t * t, 2.0 * focal * t, 0.0),
            Curve::Hyperbola(f, a, b) => f.at(a * t.cosh(), b * t.sinh(), 0.0),
            Curve::BSpline(c) => c.eval(t),
            Curve::Polyline(p) => polyline_at(p, t),
            Curve::Composite(c) => c.eval(t),
            Curve::Offset(o) => o.eval(t),
        }
    }

    /// The parameter of (the point of the curve nearest) `p`.
    pub fn param(&self, p: &P3) -> f64 {
        match self {
            Curve::Line(o, d) => (p - o).dot(d) / d.norm_squared().max(1e-300),
            Curve::Circle(f, _) => {
                let l = f.local(p);
                l.y.atan2(l.x)
            }
            Curve::Ellipse(f, a, b) => {
                let l = f.local(p);
                (l.y / b).atan2(l.x / a)
            }
            Curve::Parabola(f, focal) => f.local(p).y / (2.0 * focal),
            Curve::Hyperbola(f, _, b) => (f.local(p).y / b).asinh(),
            Curve::BSpline(c) => nearest_param(|t| c.eval(t), c.knots.range(), p),
            Curve::Polyline(pts) => polyline_param(pts, p),
            // The nearest of each segment's nearest points.
            Curve::Composite(c) => c
                .spans()
                .into_iter()
                .map(|span| nearest_param(|t| c.eval(t), span, p))
                .min_by(|a, b| {
                    (c.eval(*a) - p)
                        .norm_squared()
                        .total_cmp(&(c.eval(*b) - p).norm_squared())
                })
                .unwrap_or(0.0),
            Curve::Offset(o) => nearest_param(|t| o.eval(t), o.basis.range(), p),
        }
    }

    /// The span of parameters the curve is defined over: a B-spline's knots, one turn
    /// of a closed conic, a bounded stretch of the open ones (searches stay in it).
    pub fn range(&self) -> (f64, f64) {
        match self {
            Curve::BSpline(c) => c.knots.range(),
            Curve::Circle(..) | Curve::Ellipse(..) => (-std::f64::consts::PI, std::f64::consts::PI),
            Curve::Hyperbola(..) => (-30.0, 30.0),
            Curve::Line(..) | Curve::Parabola(..) => (-1e6, 1e6),
            Curve::Polyline(p) => (0.0, p.len().saturating_sub(1) as f64),
            Curve::Composite(c) => c.range(),
            Curve::Offset(o) => o.basis.range(),
        }
    }

    /// The parameters inside the range where the curve may bend sharply (a B-spline's
    /// knots, a polyline's corners, a composite's joints) with the range's ends; none
    /// for a smooth curve.
    pub(crate) fn breaks(&self) -> Vec<f64> {
        match self {
            Curve::BSpline(c) => c.knots.breaks(),
            Curve::Polyline(p) => (0..p.len()).map(|k| k as f64).collect(),
            Curve::Composite(c) => c.breaks(),
            Curve::Offset(o) => o.basis.breaks(),
            _ => vec![],
        }
    }

    /// The period of the parameter, for a curve that closes on itself.
    pub fn period(&self) -> Option<f64> {
        match self {
            Curve::Circle(..) | Curve::Ellipse(..) => Some(TAU),
            Curve::Composite(c) => c.period(),
            Curve::BSpline(_) => {
                let (a, b) = self.range();
                let span = (self.eval(b) - self.eval(a)).norm();
                (span < 1e-9 * (1.0 + self.eval(a).coords.norm())).then_some(b - a)
            }
            Curve::Offset(o) => o.period,
            _ => None,
        }
    }

    /// The frame whose xy plane holds a conic.
    pub fn plane(&self) -> Option<&Frame> {
        match self {
            Curve::Circle(f, _)
            | Curve::Ellipse(f, ..)
            | Curve::Parabola(f, _)
            | Curve::Hyperbola(f, ..) => Some(f),
            _ => None,
        }
    }
}

/// A polyline's point at `t`: the `⌊t⌋`-th segment at `t − ⌊t⌋` (the ends clamp).
fn polyline_at(p: &[P3], t: f64) -> P3 {
    let Some(last) = p.len().checked_sub(1) else {
        return P3::origin();
    };
    if last == 0 || t.is_nan() {
        return p[0];
    }
    let t = t.clamp(0.0, last as f64);
    let i = (t.floor() as usize).min(last - 1);
    p[i] + (p[i + 1] - p[i]) * (t - i as f64)
}

/// The parameter of the point of a polyline nearest `q`.
fn polyline_param(p: &[P3], q: &P3) -> f64 {
    let mut best = (0.0, f64::INFINITY);
    for (i, w) in p.windows(2).enumerate() {
        let d = w[1] - w[0];
        let s = ((q - w[0]).dot(&d) / d.norm_squared().max(1e-300)).clamp(0.0, 1.0);
        let dist = (w[0] + d * s - q).norm_squared();
        if dist < best.1 {
            best = (i as f64 + s, dist);
        }
    }
    best.0
}

/// The parameter in `range` whose point is nearest `p`: a dense scan, then golden-section
/// refinement around the best sample (and around the other end too when the best is an
/// end: on a closed curve both ends are the same point, and the nearest parameter may
/// lie just inside either).
pub(crate) fn nearest_param(f: impl Fn(f64) -> P3, (a, b): (f64, f64), p: &P3) -> f64 {
    const N: usize = 64;
    let d = |t: f64| (f(t) - p).norm_squared();
    let step = (b - a) / N as f64;
    let (mut best, mut bd) = (0, f64::INFINITY);
    for i in 0..=N {
        let dt = d(a + step * i as f64);
        if dt < bd {
            bd = dt;
            best = i;
        }
    }
    let golden = |k: usize| {
        let t = a + step * k as f64;
        let (mut lo, mut hi) = ((t - step).max(a), (t + step).min(b));
        let g = 0.5 * (5f64.sqrt() - 1.0);
        for _ in 0..60 {
            let m1 = hi - g * (hi - lo);
            let m2 = lo + g * (hi - lo);
            if d(m1) < d(m2) {
                hi = m2;
            } else {
                lo = m1;
            }
        }
        0.5 * (lo + hi)
    };
    let t = golden(best);
    let other = match best {
        0 => N,
        k if k == N => 0,
        _ => return t,
    };
    let t2 = golden(other);
    if d(t2) < d(t) {
        t2
    } else {
        t
    }
}

/// `a` shifted by whole periods to lie within half a period of `near`.
pub(crate) fn unwrap_near(a: f64, near: f64, period: f64) -> f64 {
    a + ((near - a) / period).round() * period
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rational_quadratic_is_a_circle() {
        // A quarter circle of radius 2 as a rational quadratic B-spline.
        let w = std::f64::consts::FRAC_1_SQRT_2;
        let c = BSplineCurve {
            knots: Knots::new(2, &[3, 3], &[0.0, 1.0], 3).unwrap(),
            points: vec![
                P3::new(2.0, 0.0, 0.0),
                P3::new(2.0, 2.0, 0.0),
                P3::new(0.0, 2.0, 0.0),
            ],
            weights: vec![1.0, w, 1.0],
        };
        for i in 0..=10 {
            let p = c.eval(i as f64 / 10.0);
            assert!((p.coords.norm() - 2.0).abs() < 1e-12);
        }
        let t = Curve::BSpline(Arc::new(c.clone())).param(&c.eval(0.37));
        assert!((t - 0.37).abs() < 1e-7);
    }
}
