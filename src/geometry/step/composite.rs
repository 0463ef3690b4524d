//! Curves made of other curves: composite curves and offset curves (ISO 10303-42
//! § 4.4, `composite_curve`, `composite_curve_segment`, `offset_curve_3d`), evaluated
//! exactly through the curves they are made of.
//!
//! - A composite curve joins its segments end to end, in order. Each segment runs along
//!   a stretch of its parent curve, with the parent's sense or against it
//!   (`same_sense = .F.`). The parametrisation is the standard's accumulation of
//!   parametric ranges: the first segment takes T in `[0, l₁]`, the i-th
//!   `[Σ_{k<i} l_k, Σ_{k≤i} l_k]`, `l_k` the parametric length of the k-th stretch, and
//!   within a segment `t = t₀ + (T − Σ_{k<i} l_k)` along the parent's sense, or
//!   `t = t₁ − (T − Σ_{k<i} l_k)` against it. Angles are radians here whatever the
//!   file's angle unit (the reader converts trims), so a composite's parameters are
//!   its own, not the file's; edges are bounded by their vertices either way.
//! - An offset curve lies at a constant distance from its basis along `V × T`, V the
//!   fixed reference direction and T the basis's unit tangent:
//!   `C(t) = B(t) + d·(V × T(t)) / |V × T(t)|`, with the basis's parametrisation
//!   (OpenCASCADE's `StepToGeom` reads the same curve as its own offset along `T × V`
//!   by `−d`).

use super::Curve;
use crate::geometry::{P3, V3};

/// A stretch of a parent curve: from parameter `from` to `to` (`to < from` runs against
/// the parent's sense).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Segment {
    /// The parent curve.
    pub curve: Curve,
    /// The parameter the stretch starts at.
    pub from: f64,
    /// The parameter it ends at.
    pub to: f64,
}

impl Segment {
    /// Its parametric length.
    fn length(&self) -> f64 {
        (self.to - self.from).abs()
    }

    /// The parent's parameter `s` into the stretch (`0 ≤ s ≤ length`).
    fn at(&self, s: f64) -> f64 {
        if self.to >= self.from {
            self.from + s
        } else {
            self.from - s
        }
    }
}

/// Segments joined end to end.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Composite {
    segments: Vec<Segment>,
    /// Where each segment ends in the composite's parameter.
    ends: Vec<f64>,
    /// Whether it ends where it starts: its parameter then runs on round it.
    closed: bool,
}

impl Composite {
    /// The composite of `segments`, each already turned the way it runs; `None` when
    /// there is none or a parametric length is not a finite number.
    pub(crate) fn new(segments: Vec<Segment>) -> Option<Composite> {
        let mut ends = Vec::with_capacity(segments.len());
        let mut total = 0.0;
        for s in &segments {
            let l = s.length();
            if !l.is_finite() {
                return None;
            }
            total += l;
            ends.push(total);
        }
        if !(total > 0.0 && total.is_finite()) {
            return None;
        }
        let mut c = Composite {
            segments,
            ends,
            closed: false,
        };
        let (a, b) = (c.eval(0.0), c.eval(total));
        c.closed = (a - b).norm() < 1e-9 * (1.0 + a.coords.norm());
        Some(c)
    }

    /// The period of the parameter, for a composite that closes.
    pub(crate) fn period(&self) -> Option<f64> {
        self.closed.then(|| self.range().1)
    }

    /// The parameter range `(0, Σ l_k)`.
    pub(crate) fn range(&self) -> (f64, f64) {
        (0.0, self.ends.last().copied().unwrap_or(0.0))
    }

    /// The segment holding `t` (the range's ends clamp), and where it starts.
    fn locate(&self, t: f64) -> (&Segment, f64) {
        let i = self
            .ends
            .iter()
            .position(|e| t <= *e)
            .unwrap_or(self.ends.len() - 1);
        let start = if i == 0 { 0.0 } else { self.ends[i - 1] };
        (&self.segments[i], start)
    }

    /// The point at `t` (taken round the period of a closed composite).
    pub(crate) fn eval(&self, t: f64) -> P3 {
        let t = match self.period() {
            Some(per) => t.rem_euclid(per),
            None => t,
        };
        let (s, start) = self.locate(t);
        s.curve.eval(s.at((t - start).clamp(0.0, s.length())))
    }

    /// The parameters where the curve may bend sharply: the segments' joints and the
    /// knots of B-spline parents, with the range's ends, ascending.
    pub(crate) fn breaks(&self) -> Vec<f64> {
        let mut out = vec![0.0];
        let mut start = 0.0;
        for (s, end) in self.segments.iter().zip(&self.ends) {
            let (lo, hi) = (s.from.min(s.to), s.from.max(s.to));
            for k in s.curve.breaks() {
                if k > lo && k < hi {
                    out.push(start + (k - s.from).abs());
                }
            }
            out.push(*end);
            start = *end;
        }
        out.sort_by(f64::total_cmp);
        out.dedup();
        out
    }

    /// Each segment's parameter range in the composite's parameter.
    pub(crate) fn spans(&self) -> Vec<(f64, f64)> {
        let starts = std::iter::once(0.0).chain(self.ends.iter().copied());
        starts.zip(self.ends.iter().copied()).collect()
    }
}

/// A curve at a constant distance from a basis curve.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct OffsetCurve {
    /// The basis curve.
    pub basis: Curve,
    /// The distance along `V × T` (mm, may be negative).
    pub distance: f64,
    /// The unit reference direction V.
    pub reference: V3,
    /// The basis's period, if it closes: the parameter runs on round it.
    pub period: Option<f64>,
}

impl OffsetCurve {
    /// The offset of `basis` by `distance` along `reference × T`: a line or a circle
    /// in a plane square to the reference when the basis is one (exactly: a line's
    /// tangent is fixed, a circle's offset in its plane is concentric), else the
    /// general offset. `None` when the offset is undefined: the reference along a
    /// line, or a circle shrunk to nothing.
    pub(crate) fn curve(basis: Curve, distance: f64, reference: V3) -> Option<Curve> {
        let v = reference.try_normalize(1e-12)?;
        match &basis {
            Curve::Line(o, d) => {
                let n = v.cross(d).try_normalize(1e-9)?;
                Some(Curve::Line(o + n * distance, *d))
            }
            // V × T for a circle turning about +z with V = ±z points to or from the
            // centre: the radius shrinks by d·(V·z).
            Curve::Circle(f, r) if v.cross(&f.z).norm() < 1e-12 => {
                let r2 = r - distance * v.dot(&f.z).signum();
                (r2 > 0.0).then_some(Curve::Circle(*f, r2))
            }
            _ => Some(Curve::Offset(std::sync::Arc::new(OffsetCurve {
                period: basis.period(),
                basis,
                distance,
                reference: v,
            }))),
        }
    }

    /// The point at `t`; where `V × T` vanishes (the tangent along V), the basis's.
    pub(crate) fn eval(&self, t: f64) -> P3 {
        let t = match self.period {
            Some(per) => {
                let a = self.basis.range().0;
                a + (t - a).rem_euclid(per)
            }
            None => t,
        };
        let p = self.basis.eval(t);
        match self
            .reference
            .cross(&tangent(&self.basis, t))
            .try_normalize(1e-12)
        {
            Some(n) => p + n * self.distance,
            None => p,
        }
    }
}

/// The direction of `c` at `t` (not normalised), by central differences that stay in
/// the range of a bounded curve.
pub(crate) fn tangent(c: &Curve, t: f64) -> V3 {
    let (a, b) = c.range();
    let h = 1e-6 * (b - a).abs().clamp(1e-3, 1e3);
    let (lo, hi) = if c.period().is_some() {
        (t - h, t + h)
    } else {
        ((t - h).max(a), (t + h).min(b))
    };
    c.eval(hi) - c.eval(lo)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::step::curve::Frame;

    fn circle() -> Curve {
        Curve::Circle(Frame::new(P3::origin(), None, None).unwrap(), 10.0)
    }

    #[test]
    fn segments_join_in_order_and_turn_back() {
        // The circle's quarter from 90° back to 0°, against its sense, from (0,10,0) to
        // (10,0,0); then a line on to (10,5,0).
        let half_pi = std::f64::consts::FRAC_PI_2;
        let line = Curve::Line(P3::new(10.0, 0.0, 0.0), V3::new(0.0, 1.0, 0.0));
        let c = Composite::new(vec![
            Segment {
                curve: circle(),
                from: half_pi,
                to: 0.0,
            },
            Segment {
                curve: line,
                from: 0.0,
                to: 5.0,
            },
        ])
        .unwrap();
        let (a, b) = c.range();
        assert!(a == 0.0 && (b - (half_pi + 5.0)).abs() < 1e-12);
        assert!((c.eval(0.0) - P3::new(0.0, 10.0, 0.0)).norm() < 1e-12);
        assert!((c.eval(half_pi) - P3::new(10.0, 0.0, 0.0)).norm() < 1e-12);
        assert!((c.eval(b) - P3::new(10.0, 5.0, 0.0)).norm() < 1e-12);
        for t in [0.3, 2.0, 4.5] {
            let curve = Curve::Composite(std::sync::Arc::new(c.clone()));
            assert!((curve.param(&c.eval(t)) - t).abs() < 1e-7, "{t}");
        }
        assert_eq!(c.breaks(), vec![0.0, half_pi, b]);
    }

    #[test]
    fn an_offset_goes_along_the_reference_cross_the_tangent() {
        // A circle about +z offset by 2 with V = +z: V × T points to the centre.
        let c = OffsetCurve::curve(circle(), 2.0, V3::z()).unwrap();
        assert_eq!(
            c,
            Curve::Circle(Frame::new(P3::origin(), None, None).unwrap(), 8.0)
        );
        // A line along x offset with V = z: z × x = y.
        let l = Curve::Line(P3::origin(), V3::x());
        let o = OffsetCurve::curve(l, 3.0, V3::z()).unwrap();
        assert!((o.eval(1.0) - P3::new(1.0, 3.0, 0.0)).norm() < 1e-12);
        // An ellipse's general offset stays at the distance from it.
        let f = Frame::new(P3::origin(), None, None).unwrap();
        let e = OffsetCurve::curve(Curve::Ellipse(f, 10.0, 5.0), 1.0, V3::z()).unwrap();
        assert!(matches!(e, Curve::Offset(_)));
        let p = e.eval(0.0);
        assert!((p - P3::new(9.0, 0.0, 0.0)).norm() < 1e-6);
        assert!((e.param(&p) - 0.0).abs() < 1e-6);
    }
}
