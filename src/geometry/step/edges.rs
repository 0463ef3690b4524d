//! Edges cut into polylines to a chord tolerance, once each, before any face is
//! meshed: the two faces that share an edge share its points, and the mesh closes.
//!
//! A line is its two vertices; a circle or ellipse is cut into equal angles; every other
//! curve is cut between its vertices' parameters by halving where it strays from the
//! chord or turns too much, first at its knots, corners or joints (a B-spline's knots,
//! a composite's joints), where it may bend sharply. An edge of a ruled face (QIF's
//! `Ruled23`) is cut further wherever that face's normal turns along it by more than
//! the angle limit: a twisted ruled surface turns along its straight lines, and the
//! face's triangles cannot split a bound segment (OpenCASCADE's mesher cuts every edge
//! so; the other surfaces' edges are left as they were, which keeps the meshes of the
//! parts already read).

use super::brep::{Bound, Brep, Edge};
use super::curve::Curve;
use super::geom::Surf;
use crate::geometry::weld::MAX_TRIANGLES;
use crate::geometry::{P3, V3};
use rayon::prelude::*;
use std::f64::consts::TAU;

/// How fine the mesh is.
#[derive(Debug, Clone, Copy)]
pub struct Resolution {
    /// Largest distance between a triangle and the surface (mm).
    pub chord_mm: f64,
    /// Largest turn of the normal across a triangle or an edge segment (radians).
    pub angle_rad: f64,
}

/// How many faces or edges are meshed side by side before the totals are checked: the
/// check falls at the same place for any thread count.
pub(super) const BATCH: usize = 64;

/// Why a part is not meshed: it needs too many triangles at this resolution.
pub(super) fn too_large(res: Resolution) -> String {
    format!(
        "meshing it to a {} mm chord takes more than {MAX_TRIANGLES} triangles",
        res.chord_mm
    )
}

/// The segment count for an arc of `sweep` radians on radius `r`.
fn arc_segments(sweep: f64, r: f64, res: Resolution) -> usize {
    let chord_step = if res.chord_mm < r {
        2.0 * (1.0 - res.chord_mm / r).acos()
    } else {
        res.angle_rad
    };
    let step = chord_step.min(res.angle_rad).max(1e-3);
    ((sweep.abs() / step).ceil() as usize).max(1)
}

/// An edge as a polyline from its start vertex to its end vertex.
fn edge_points(e: &Edge, res: Resolution) -> Vec<P3> {
    let closed = (e.start - e.end).norm() < 1e-9;
    let mut pts = match &e.curve {
        Curve::Line(..) => vec![e.start, e.end],
        Curve::Polyline(p) => {
            let mut p = p.to_vec();
            if !e.same_sense {
                p.reverse();
            }
            p
        }
        Curve::Circle(_, r) | Curve::Ellipse(_, r, _) => {
            let r = match &e.curve {
                Curve::Ellipse(_, a, b) => a.max(*b),
                _ => *r,
            };
            let t0 = e.curve.param(&e.start);
            let mut t1 = e.curve.param(&e.end);
            if e.same_sense {
                while t1 <= t0 + 1e-9 {
                    t1 += TAU;
                }
                if !closed && t1 - t0 > TAU - 1e-9 {
                    t1 -= TAU;
                }
            } else {
                while t1 >= t0 - 1e-9 {
                    t1 -= TAU;
                }
                if !closed && t0 - t1 > TAU - 1e-9 {
                    t1 += TAU;
                }
            }
            let n = arc_segments(t1 - t0, r, res);
            (0..=n)
                .map(|k| e.curve.eval(t0 + (t1 - t0) * k as f64 / n as f64))
                .collect()
        }
        Curve::Parabola(..) | Curve::Hyperbola(..) => {
            let (ts, te) = (e.curve.param(&e.start), e.curve.param(&e.end));
            let (lo, hi) = (ts.min(te), ts.max(te));
            let mut params = vec![lo];
            refine_curve(&|t| e.curve.eval(t), lo, hi, res, 0, &mut params);
            let mut p: Vec<P3> = params.iter().map(|&t| e.curve.eval(t)).collect();
            if ts > te {
                p.reverse();
            }
            p
        }
        c @ (Curve::Composite(_) | Curve::Offset(_)) => traced(e, c, res),
        Curve::BSpline(c) => {
            let (a, b) = c.knots.range();
            let near = |p: &P3, t: f64| (c.eval(t) - p).norm() < 1e-6;
            let (ts, te) = if closed && near(&e.start, a) && near(&e.start, b) {
                if e.same_sense {
                    (a, b)
                } else {
                    (b, a)
                }
            } else {
                let find = |p: &P3| {
                    if near(p, a) {
                        a
                    } else if near(p, b) {
                        b
                    } else {
                        e.curve.param(p)
                    }
                };
                (find(&e.start), find(&e.end))
            };
            let (lo, hi) = (ts.min(te), ts.max(te));
            let mut knots: Vec<f64> = c.knots.breaks();
            knots.retain(|k| *k > lo && *k < hi);
            let mut stops = vec![lo];
            stops.extend(knots);
            stops.push(hi);
            let mut params = vec![lo];
            for w in stops.windows(2) {
                refine_curve(&|t| c.eval(t), w[0], w[1], res, 0, &mut params);
            }
            let mut p: Vec<P3> = params.iter().map(|&t| c.eval(t)).collect();
            if ts > te {
                p.reverse();
            }
            p
        }
    };
    // The ends are the vertices exactly, so that edges meeting there share a point.
    if let Some(first) = pts.first_mut() {
        *first = e.start;
    }
    if let Some(last) = pts.last_mut() {
        *last = e.end;
    }
    if pts.len() < 2 {
        pts = vec![e.start, e.end];
    }
    pts
}

/// Appends the parameters after `a` up to `b`, splitting where the curve leaves the
/// chord by more than the tolerance or turns by more than the angle limit.
pub(super) fn refine_curve(
    f: &dyn Fn(f64) -> P3,
    a: f64,
    b: f64,
    res: Resolution,
    depth: usize,
    out: &mut Vec<f64>,
) {
    split_curve(f, (a, f(a)), (b, f(b)), res, depth, out);
}

/// [`refine_curve`] with the ends' points known, so that each split evaluates the
/// curve only at its new parameters.
fn split_curve(
    f: &dyn Fn(f64) -> P3,
    (a, pa): (f64, P3),
    (b, pb): (f64, P3),
    res: Resolution,
    depth: usize,
    out: &mut Vec<f64>,
) {
    let m = 0.5 * (a + b);
    let pm = f(m);
    let chord = pb - pa;
    // The curve's distance from the chord at a quarter, the middle and three quarters
    // (a span of a B-spline can bend twice).
    let from_chord = |p: P3| {
        if chord.norm() > 1e-12 {
            (p - pa).cross(&chord).norm() / chord.norm()
        } else {
            (p - pa).norm()
        }
    };
    let off = [pm, f(a + (b - a) * 0.25), f(a + (b - a) * 0.75)]
        .into_iter()
        .map(from_chord)
        .fold(0.0, f64::max);
    let turn = (pm - pa).angle(&(pb - pm));
    // Depth and count limits keep a corrupt curve from taking the memory.
    if depth < 14 && out.len() < 100_000 && (off > res.chord_mm || turn > res.angle_rad) {
        split_curve(f, (a, pa), (m, pm), res, depth + 1, out);
        split_curve(f, (m, pm), (b, pb), res, depth + 1, out);
    } else {
        out.push(b);
    }
}

/// Edges cut into polylines, as tessellation cuts them; an error when they take more
/// than [`MAX_TRIANGLES`] points in all (more than the largest mesh has triangles).
pub(crate) fn edge_polylines(b: &Brep, res: Resolution) -> Result<Vec<Vec<P3>>, String> {
    // The ruled faces each edge bounds: their normals may turn along a straight edge.
    let mut ruled: Vec<Vec<&Surf>> = vec![Vec::new(); b.edges.len()];
    for f in b
        .faces
        .iter()
        .filter(|f| matches!(f.surface, Surf::Ruled(_)))
    {
        for (e, _) in f.bounds.iter().flat_map(Bound::edges) {
            ruled[*e].push(&f.surface);
        }
    }
    let mut out: Vec<Vec<P3>> = Vec::with_capacity(b.edges.len());
    let mut points = 0usize;
    for (k, batch) in b.edges.chunks(BATCH).enumerate() {
        let cut: Vec<Vec<P3>> = batch
            .par_iter()
            .enumerate()
            .map(|(i, e)| {
                let pts = edge_points(e, res);
                match ruled[k * BATCH + i].as_slice() {
                    [] => pts,
                    faces => turned(e, pts, faces, res),
                }
            })
            .collect();
        points += cut.iter().map(Vec::len).sum::<usize>();
        if points > MAX_TRIANGLES {
            return Err(too_large(res));
        }
        out.extend(cut);
    }
    Ok(out)
}

/// Each ruled face's normal at a point of an edge (`None` where it is undefined).
type Normals = Vec<Option<V3>>;

fn normals_at(faces: &[&Surf], p: &P3) -> Normals {
    faces
        .iter()
        .map(|s| {
            let (u, v) = s.param(p, None);
            s.normal(&s.eval(u, v), u, v)
        })
        .collect()
}

/// An edge's points with more between any two where the normal of a ruled face it
/// bounds turns by more than the angle limit: a twisted ruled surface turns along its
/// straight lines, and a bound segment is what the face's triangles cannot split.
fn turned(e: &Edge, pts: Vec<P3>, faces: &[&Surf], res: Resolution) -> Vec<P3> {
    let mut out = vec![pts[0]];
    let mut prev = normals_at(faces, &pts[0]);
    for &p in &pts[1..] {
        let np = normals_at(faces, &p);
        let a = *out.last().unwrap_or(&p);
        split_turn(e, faces, res, (a, &prev), (p, &np), 0, &mut out);
        prev = np;
    }
    out
}

/// Appends the points after `a` up to `b`, halving along the edge's curve while the
/// faces' normals at the two ends differ by more than the angle limit.
fn split_turn(
    e: &Edge,
    faces: &[&Surf],
    res: Resolution,
    (a, na): (P3, &[Option<V3>]),
    (b, nb): (P3, &[Option<V3>]),
    depth: usize,
    out: &mut Vec<P3>,
) {
    let turns = na
        .iter()
        .zip(nb)
        .any(|(x, y)| matches!((x, y), (Some(x), Some(y)) if x.angle(y) > res.angle_rad));
    if depth < 10 && turns {
        let m = P3::from((a.coords + b.coords) / 2.0);
        let m = e.curve.eval(e.curve.param(&m));
        let nm = normals_at(faces, &m);
        split_turn(e, faces, res, (a, na), (m, &nm), depth + 1, out);
        split_turn(e, faces, res, (m, &nm), (b, nb), depth + 1, out);
    } else {
        out.push(b);
    }
}

/// An edge on a curve known by evaluation only (a composite, an offset): from its
/// start vertex's parameter to its end's (on a closed curve, along the edge's sense
/// and once round for a closed edge), cut between the curve's breaks.
fn traced(e: &Edge, c: &Curve, res: Resolution) -> Vec<P3> {
    let (a, b) = c.range();
    let near = |p: &P3, t: f64| (c.eval(t) - p).norm() < 1e-6;
    let find = |p: &P3| {
        if near(p, a) {
            a
        } else if near(p, b) {
            b
        } else {
            c.param(p)
        }
    };
    let period = c.period();
    let (ts, te) = match period {
        Some(per) => {
            let ts = c.param(&e.start);
            let dir = if e.same_sense { 1.0 } else { -1.0 };
            let d = if (e.start - e.end).norm() < 1e-9 {
                per
            } else {
                let d = (c.param(&e.end) - ts) * dir;
                d - ((d / per).ceil() - 1.0) * per
            };
            (ts, ts + dir * d)
        }
        None => (find(&e.start), find(&e.end)),
    };
    // Along a closed curve the parameter runs on past its range's end.
    let at = |t: f64| match period {
        Some(per) => c.eval(a + (t - a).rem_euclid(per)),
        None => c.eval(t),
    };
    let (lo, hi) = (ts.min(te), ts.max(te));
    let mut stops = vec![lo];
    let shifts: Vec<f64> = match period {
        Some(per) => {
            let k = ((lo - a) / per).floor() as i64;
            (k..=k + 2).map(|i| i as f64 * per).collect()
        }
        None => vec![0.0],
    };
    let mut inner: Vec<f64> = shifts
        .iter()
        .flat_map(|s| c.breaks().into_iter().map(move |k| k + s))
        .filter(|k| *k > lo && *k < hi)
        .collect();
    inner.sort_by(f64::total_cmp);
    inner.dedup();
    stops.extend(inner);
    stops.push(hi);
    let mut params = vec![lo];
    for w in stops.windows(2) {
        refine_curve(&at, w[0], w[1], res, 0, &mut params);
    }
    let mut p: Vec<P3> = params.iter().map(|&t| at(t)).collect();
    if ts > te {
        p.reverse();
    }
    p
}
