//! Reading the curves made of other curves (their geometry is `composite.rs`'s):
//! `COMPOSITE_CURVE` and its subtypes `COMPOSITE_CURVE_ON_SURFACE`, `BOUNDARY_CURVE`
//! and `OUTER_BOUNDARY_CURVE`, whose `COMPOSITE_CURVE_SEGMENT(transition, same_sense,
//! parent_curve)`s each take a stretch of their parent, and `OFFSET_CURVE_3D(name,
//! basis_curve, distance, self_intersect, ref_direction)` (ISO 10303-42 § 4.4).
//!
//! An edge bounds its curve by its vertices, so a `TRIMMED_CURVE` that is an edge's
//! geometry is read as its basis (`brep.rs`); a composite's segments have no vertices,
//! and there the trims are read: `trim_1` and `trim_2` each a parameter value, a point
//! or both (`master_representation` says which one rules when both are given), the
//! stretch running from `trim_1` to `trim_2` along the basis's sense when
//! `sense_agreement` is true and against it when false, once round at most on a closed
//! basis. A circle's or ellipse's parameter is an angle in the file's plane angle unit.
//! A segment's parent that is not trimmed is bounded by itself: a B-spline's knots, a
//! polyline's points, a composite's own range, a circle's or ellipse's whole turn.

use super::brep::Reader;
use super::composite::{Composite, OffsetCurve, Segment};
use super::p21::{Instance, Param, Record};
use super::{Curve, StepError};

/// How far apart two segments of a composite may end and start (mm): ten times the
/// loosest modelling tolerance CAD systems write, far below any segment a misread
/// sense would put elsewhere.
const JOIN_MM: f64 = 1e-2;

impl Reader<'_> {
    /// The curve made of curves that instance `id` is, or `None` when it is another kind.
    pub(super) fn compound(&self, id: u64, inst: &Instance) -> Option<Result<Curve, StepError>> {
        if let Some(r) = [
            "COMPOSITE_CURVE",
            "COMPOSITE_CURVE_ON_SURFACE",
            "BOUNDARY_CURVE",
            "OUTER_BOUNDARY_CURVE",
        ]
        .iter()
        .find_map(|k| inst.record(k))
        {
            return Some(self.composite(id, inst, r));
        }
        let r = inst.record("OFFSET_CURVE_3D")?;
        Some(self.offset_curve(id, inst, r))
    }

    fn composite(&self, id: u64, inst: &Instance, r: &Record) -> Result<Curve, StepError> {
        let mut segments = Vec::new();
        for p in self.list(id, r, 1)? {
            let sid = self.ref_of(id, p)?;
            let s = self.inst(sid, Some(id))?;
            let rec = s
                .record("COMPOSITE_CURVE_SEGMENT")
                .or(s.record("REPARAMETRISED_COMPOSITE_CURVE_SEGMENT"))
                .ok_or_else(|| self.bad(sid, "a composite curve's segment was expected"))?;
            let same_sense = self.boolean(sid, rec, 1)?;
            let parent = self.reference(sid, rec, 2)?;
            let (curve, from, to) = self
                .trail
                .follow(id, inst.line, || self.stretch(parent, sid))?;
            let (from, to) = if same_sense { (from, to) } else { (to, from) };
            segments.push(Segment { curve, from, to });
        }
        for (k, w) in segments.windows(2).enumerate() {
            let gap = (w[0].curve.eval(w[0].to) - w[1].curve.eval(w[1].from)).norm();
            if gap.is_nan() || gap > JOIN_MM {
                return Err(self.bad(
                    id,
                    format!(
                        "its segment {} ends {gap:.3} mm from where segment {} starts",
                        k + 1,
                        k + 2
                    ),
                ));
            }
        }
        Composite::new(segments)
            .map(|c| Curve::Composite(std::sync::Arc::new(c)))
            .ok_or_else(|| self.bad(id, "a composite curve needs segments of finite length"))
    }

    /// The stretch of curve `pid` a composite's segment takes: the curve and the
    /// parameters it runs from and to.
    fn stretch(&self, pid: u64, from: u64) -> Result<(Curve, f64, f64), StepError> {
        let inst = self.inst(pid, Some(from))?;
        if let Some(r) = inst.record("TRIMMED_CURVE") {
            return self.trimmed(pid, inst, r);
        }
        for wrapper in ["SURFACE_CURVE", "SEAM_CURVE", "INTERSECTION_CURVE"] {
            if let Some(r) = inst.record(wrapper) {
                let inner = self.reference(pid, r, 1)?;
                return self
                    .trail
                    .follow(pid, inst.line, || self.stretch(inner, pid));
            }
        }
        if let Some(r) = inst.record("OFFSET_CURVE_3D") {
            // The offset of a stretch is the stretch of the offset: same parameters.
            let inner = self.reference(pid, r, 1)?;
            let (_, a, b) = self
                .trail
                .follow(pid, inst.line, || self.stretch(inner, pid))?;
            return Ok((self.curve(pid, from)?, a, b));
        }
        let c = self.curve(pid, from)?;
        let (a, b) = match &c {
            Curve::BSpline(_) | Curve::Polyline(_) | Curve::Composite(_) => c.range(),
            Curve::Circle(..) | Curve::Ellipse(..) => (0.0, std::f64::consts::TAU),
            _ => {
                return Err(self.bad(
                    pid,
                    "a composite curve's segment lies on an unbounded curve, untrimmed",
                ))
            }
        };
        Ok((c, a, b))
    }

    /// A `TRIMMED_CURVE(name, basis, trim_1, trim_2, sense_agreement,
    /// master_representation)` as its basis and the parameters it runs from and to.
    fn trimmed(
        &self,
        pid: u64,
        inst: &Instance,
        r: &Record,
    ) -> Result<(Curve, f64, f64), StepError> {
        let basis_id = self.reference(pid, r, 1)?;
        let basis = self
            .trail
            .follow(pid, inst.line, || self.curve(basis_id, pid))?;
        let master = r.params.get(5).and_then(Param::enumeration);
        let t1 = self.trim(pid, r, 2, &basis, master)?;
        let t2 = self.trim(pid, r, 3, &basis, master)?;
        let forward = self.boolean(pid, r, 4)?;
        let t2 = match basis.period() {
            Some(per) => wind(t1, t2, per, forward),
            None => t2,
        };
        if !(t1.is_finite() && t2.is_finite()) {
            return Err(self.bad(pid, "its trims are not finite numbers"));
        }
        Ok((basis, t1, t2))
    }

    /// One trim of a trimmed curve as a parameter of its basis: the point's when the
    /// file prefers it or gives no parameter, else the parameter value (an angle for a
    /// circle or ellipse, in the file's unit).
    fn trim(
        &self,
        pid: u64,
        r: &Record,
        i: usize,
        basis: &Curve,
        master: Option<&str>,
    ) -> Result<f64, StepError> {
        let mut point = None;
        let mut value = None;
        for item in self.list(pid, r, i)? {
            match item {
                Param::Ref(p) => point = Some(self.point(*p, pid)?),
                other => value = other.real().or(value),
            }
        }
        match (point, value) {
            (Some(p), v) if v.is_none() || master == Some("CARTESIAN") => Ok(basis.param(&p)),
            (_, Some(v)) => match basis {
                Curve::Composite(_) if self.angle != 1.0 => Err(StepError::Unsupported {
                    id: pid,
                    line: self.f.instances.get(&pid).map_or(0, |i| i.line),
                    what: "composite curve trimmed by parameter in a plane angle unit other than the radian".into(),
                }),
                _ if angular(basis) => Ok(v * self.angle),
                _ => Ok(v),
            },
            _ => Err(self.bad(pid, "a trim is neither a point nor a parameter value")),
        }
    }

    fn offset_curve(&self, id: u64, inst: &Instance, r: &Record) -> Result<Curve, StepError> {
        let basis_id = self.reference(id, r, 1)?;
        let basis = self
            .trail
            .follow(id, inst.line, || self.curve(basis_id, id))?;
        if matches!(basis, Curve::Polyline(_)) {
            return Err(StepError::Unsupported {
                id,
                line: inst.line,
                what: "offset of a polyline".into(),
            });
        }
        let distance = self.real(id, r, 2)? * self.unit;
        if !distance.is_finite() {
            return Err(self.bad(id, format!("an offset cannot be {distance} mm")));
        }
        let v = self.direction(self.reference(id, r, 4)?, id)?;
        OffsetCurve::curve(basis, distance, v).ok_or_else(|| {
            self.bad(
                id,
                "its offset is undefined: the reference direction is zero or along a line, or the circle shrinks to nothing",
            )
        })
    }
}

/// Whether a curve's parameter is an angle (a circle's, an ellipse's, an offset's of one).
fn angular(c: &Curve) -> bool {
    match c {
        Curve::Circle(..) | Curve::Ellipse(..) => true,
        Curve::Offset(o) => angular(&o.basis),
        _ => false,
    }
}

/// `t2` moved by whole periods so that the stretch from `t1` runs `forward` (or back)
/// for more than nothing and at most once round: equal trims on a closed curve are
/// the whole of it.
fn wind(t1: f64, t2: f64, per: f64, forward: bool) -> f64 {
    let dir = if forward { 1.0 } else { -1.0 };
    let d = (t2 - t1) * dir;
    let d = d - ((d / per).ceil() - 1.0) * per;
    t1 + dir * d
}

#[cfg(test)]
mod tests {
    use super::wind;
    use std::f64::consts::{PI, TAU};

    #[test]
    fn trims_on_a_closed_curve_go_round_once_at_most() {
        assert!((wind(0.0, TAU, TAU, true) - TAU).abs() < 1e-12);
        assert!((wind(1.5 * PI, 0.5 * PI, TAU, true) - 2.5 * PI).abs() < 1e-12);
        assert!((wind(0.5 * PI, 1.5 * PI, TAU, false) - -0.5 * PI).abs() < 1e-12);
        assert!((wind(1.0, 1.0, TAU, true) - (1.0 + TAU)).abs() < 1e-12);
        assert!((wind(0.0, 1.0, TAU, true) - 1.0).abs() < 1e-12);
    }
}
