//! A QIF document's curves (Geometry.xsd's `…13Core` elements) as the STEP reader's.

use super::doc::{domain, frame, malformed, num, positive, vec3, Doc, MAX_SAMPLES};
use super::xml::Node;
use super::QifError;
use crate::geometry::step::curve::{BSplineCurve, Curve, Frame, Knots, MAX_DEGREE};
use crate::geometry::P3;
use std::f64::consts::TAU;

/// A curve from its core element (`ArcCircular13Core`, …), and where it starts.
pub(super) fn curve_core(d: &Doc, c: &Node, owner: &Node) -> Result<(Curve, Option<P3>), QifError> {
    let unsupported = || QifError::Unsupported {
        id: owner.id(),
        line: c.line,
        what: format!("curve {}", c.name.trim_end_matches("Core")),
    };
    match c.name.as_str() {
        "Segment13Core" => {
            let (a, b) = (d.point(c, "StartPoint")?, d.point(c, "EndPoint")?);
            Ok((Curve::Line(a, b - a), Some(a)))
        }
        "ArcCircular13Core" => {
            let r = d.length(c, "Radius")?;
            positive(c, r, "its radius")?;
            let f = arc_frame(d, c)?;
            let t0 = domain(c).map_or(0.0, |dm| dm.0);
            let curve = Curve::Circle(f, r);
            let start = curve.eval(t0);
            Ok((curve, Some(start)))
        }
        "ArcConic13Core" => {
            let curve = conic(d, c)?;
            let start = curve.eval(domain(c).map_or(0.0, |dm| dm.0));
            Ok((curve, Some(start)))
        }
        "Nurbs13Core" if c.child("CPsBinary").is_some() => Err(QifError::Unsupported {
            id: owner.id(),
            line: c.line,
            what: "NURBS curve with binary control points (CPsBinary)".into(),
        }),
        "Nurbs13Core" => {
            let order = num(c, "Order")?;
            let knots = c
                .child("Knots")
                .and_then(|k| k.numbers())
                .ok_or_else(|| malformed(c, "its <Knots> are not numbers"))?;
            let cps = c
                .child("CPs")
                .and_then(|k| k.numbers())
                .ok_or_else(|| malformed(c, "its <CPs> are not numbers"))?;
            if cps.len() % 3 != 0 || cps.is_empty() {
                return Err(malformed(c, "its <CPs> are not x y z triples"));
            }
            let points: Vec<P3> = cps
                .chunks(3)
                .map(|p| P3::new(p[0], p[1], p[2]) * d.unit)
                .collect();
            let weights = match c.child("Weights") {
                Some(w) => w
                    .numbers()
                    .filter(|w| w.len() == points.len() && w.iter().all(|x| *x > 0.0))
                    .ok_or_else(|| {
                        malformed(
                            c,
                            "its <Weights> are not one positive number per control point",
                        )
                    })?,
                None => vec![1.0; points.len()],
            };
            // The order is checked before it sizes anything: a whole number no
            // higher than the highest degree read, plus one.
            let max_order = (MAX_DEGREE + 1) as f64;
            let fits = order.fract() == 0.0 && (2.0..=max_order).contains(&order);
            let knots = Some(knots)
                .filter(|k| fits && k.len() == points.len() + order as usize)
                .and_then(|k| Knots::checked(order as usize - 1, k))
                .ok_or_else(|| {
                    malformed(c, "its order, knots and control points do not fit together")
                })?;
            let curve = BSplineCurve {
                knots,
                points,
                weights,
            };
            // The curve starts where its domain does (the knots' range when it says none).
            let t0 = domain(c).map_or(curve.knots.range().0, |d| d.0);
            let start = curve.eval(t0);
            Ok((Curve::BSpline(std::sync::Arc::new(curve)), Some(start)))
        }
        "Spline13Core" => super::splines::spline13(d, c),
        "Polyline13Core" => {
            let v = c
                .child("Points")
                .and_then(|p| p.numbers())
                .filter(|v| v.len() >= 6 && v.len() % 3 == 0)
                .ok_or_else(|| malformed(c, "its <Points> are not x y z triples"))?;
            let pts: Vec<P3> = v
                .chunks(3)
                .map(|p| P3::new(p[0], p[1], p[2]) * d.unit)
                .collect();
            let start = pts[0];
            Ok((Curve::Polyline(pts.into()), Some(start)))
        }
        "Aggregate13Core" => {
            let mut pts: Vec<P3> = Vec::new();
            let subs = c
                .child("SubCurves")
                .ok_or_else(|| malformed(c, "it has no <SubCurves>"))?;
            for sc in subs.all("SubCurve") {
                let inner = sc
                    .children
                    .iter()
                    .find(|k| k.name.ends_with("Core"))
                    .ok_or_else(|| malformed(sc, "it has no curve"))?;
                let (curve, _) = curve_core(d, inner, owner)?;
                let mut p = sample(&curve, inner, d)?;
                if sc.attr("turned") == Some("true") {
                    p.reverse();
                }
                if pts.last().is_some_and(|l| (l - p[0]).norm() < 1e-9) {
                    pts.pop();
                }
                pts.extend(p);
            }
            if pts.len() < 2 {
                return Err(malformed(c, "its sub-curves are empty"));
            }
            let start = pts[0];
            Ok((Curve::Polyline(pts.into()), Some(start)))
        }
        _ => Err(unsupported()),
    }
}

/// The plane and start of a circular or conic arc: centred at `Center`, square to
/// `Normal`, starting along `DirBeg` (Geometry.xsd, `ArcCircular13CoreType`,
/// `ArcConic13CoreType`).
fn arc_frame(d: &Doc, c: &Node) -> Result<Frame, QifError> {
    frame(
        c,
        d.point(c, "Center")?,
        vec3(c, "Normal")?,
        Some(vec3(c, "DirBeg")?),
    )
}

/// A conic arc's curve. QIF 3's schema (Geometry.xsd, `ArcConic13CoreType`) names `A`
/// and `B` the conic's "major" and "minor diameter", as its circles, cylinders and tori
/// give diameters, and puts the conic in the plane of `Normal` starting along `DirBeg`;
/// it gives no formula, so ISO 10303-42's parametrisations are taken with the
/// semi-axes (for a parabola the focal distance) `A/2` and `B/2`. The edge's vertices
/// must then lie on the curve (`brep.rs::edge` checks): a reading that disagrees with the
/// file's own topology stops instead of meshing a wrong face.
fn conic(d: &Doc, c: &Node) -> Result<Curve, QifError> {
    let a = d.length(c, "A")? / 2.0;
    positive(c, a, "its A")?;
    let f = arc_frame(d, c)?;
    match c.attr("form") {
        Some("PARABOLA") => Ok(Curve::Parabola(f, a)),
        Some(form @ ("ELLIPSE" | "HYPERBOLA")) => {
            let b = d.length(c, "B")? / 2.0;
            positive(c, b, "its B")?;
            Ok(if form == "ELLIPSE" {
                Curve::Ellipse(f, a, b)
            } else {
                Curve::Hyperbola(f, a, b)
            })
        }
        _ => Err(malformed(
            c,
            "its form is not PARABOLA, ELLIPSE or HYPERBOLA",
        )),
    }
}

/// A sub-curve of an aggregate as points along its domain, fine enough for any chord
/// tolerance the tessellator is asked for (a 0.02 rad step on arcs, 32 points a span on
/// B-splines).
///
/// Every point is charged to the document's [`Doc::samples`] before it is made: an
/// arc's domain is at most a turn, and all aggregates together take at most
/// [`MAX_SAMPLES`] points, so their cost follows the file's size.
fn sample(curve: &Curve, c: &Node, d: &Doc) -> Result<Vec<P3>, QifError> {
    let count = match curve {
        Curve::Line(..) => 2,
        Curve::Polyline(p) => p.len(),
        Curve::Parabola(..) | Curve::Hyperbola(..) => 65,
        Curve::Circle(..) | Curve::Ellipse(..) => {
            let (a, b) = domain(c).ok_or_else(|| malformed(c, "it has no domain"))?;
            let sweep = (b - a).abs();
            if sweep.is_nan() || sweep > TAU + 1e-9 {
                return Err(malformed(c, "its domain spans more than a full turn"));
            }
            ((b - a).abs() / 0.02).ceil().max(1.0) as usize + 1
        }
        Curve::BSpline(s) => 32 * s.knots.breaks().len() + 1,
        Curve::Composite(_) | Curve::Offset(_) => 32 * curve.breaks().len().max(2) + 1,
    };
    match d.samples.get().checked_sub(count) {
        Some(left) => d.samples.set(left),
        None => {
            return Err(malformed(
                c,
                &format!("the aggregate curves need more than {MAX_SAMPLES} points in all"),
            ))
        }
    }
    Ok(match curve {
        Curve::Line(a, d) => vec![*a, a + d],
        Curve::Polyline(p) => p.to_vec(),
        Curve::Circle(..) | Curve::Ellipse(..) | Curve::Parabola(..) | Curve::Hyperbola(..) => {
            let (a, b) = domain(c).ok_or_else(|| malformed(c, "it has no domain"))?;
            let n = count - 1;
            (0..=n)
                .map(|k| curve.eval(a + (b - a) * k as f64 / n as f64))
                .collect()
        }
        Curve::BSpline(s) => {
            let br = s.knots.breaks();
            let mut out = vec![s.eval(br[0])];
            for w in br.windows(2) {
                for k in 1..=32 {
                    out.push(s.eval(w[0] + (w[1] - w[0]) * k as f64 / 32.0));
                }
            }
            out
        }
        Curve::Composite(_) | Curve::Offset(_) => {
            let (a, b) = curve.range();
            (0..count)
                .map(|k| curve.eval(a + (b - a) * k as f64 / (count - 1) as f64))
                .collect()
        }
    })
}
