//! QIF 3's piecewise polynomial curves and surfaces (Geometry.xsd `Spline13CoreType`,
//! `Spline23CoreType`) read as the B-splines they are, so that they evaluate, project
//! and mesh exactly as NURBS do.
//!
//! The schema: `Knots` are the breakpoints; `Orders` the order (degree + 1) of each
//! polynomial segment between two breakpoints; `Coefficients` each segment's
//! coefficients, as many per segment as its order (a surface's patch has
//! order-in-u × order-in-v of them); `normalized` says whether the curve is normalised.
//! It gives no formula, so the usual piecewise polynomial form (IGES 5.3 entity 112's,
//! which this element carries over) is read: segment i is `Σ_k a_k s^k`, coefficients in
//! increasing powers, with `s = t − t_i` on `[t_i, t_{i+1}]`, or with `s` running from 0
//! to 1 over the segment (`(t − t_i) / (t_{i+1} − t_i)`) when normalised. Each segment
//! is then an exact Bézier piece (power to Bernstein basis, raised to the highest
//! order), and the pieces share their end points in a B-spline whose inner knots repeat
//! to the degree.
//!
//! **Decision: a reading that does not hold together is malformed, not guessed.** The
//! segments of a spline meet end to end (it is one curve): under the wrong reading of
//! the parameter they do not, and the file is refused. A surface's patches must meet
//! along their edges, and the face's vertices lie on it; the schema does not say
//! which index runs fastest, either over the patches or over a patch's coefficients,
//! and the one order of the four under which both hold is taken (as for `Nurbs23`).

use super::doc::{domain, malformed, Doc};
use super::xml::Node;
use super::QifError;
use crate::geometry::step::curve::{BSplineCurve, Curve, Knots, MAX_DEGREE};
use crate::geometry::step::geom::{BSplineSurface, Surf};
use crate::geometry::{P3, V3};
use std::sync::Arc;

/// How far apart two polynomial pieces may end and start (mm).
const JOIN_MM: f64 = 1e-3;

/// A `Spline13Core` as a B-spline curve, and where it starts (its domain's start).
pub(super) fn spline13(d: &Doc, c: &Node) -> Result<(Curve, Option<P3>), QifError> {
    let breaks = breakpoints(c, "Knots")?;
    let orders = orders(c, "Orders", breaks.len())?;
    let coefs = coefficients(d, c, orders.iter().sum())?;
    let degree = degree_of(c, &orders)?;
    let normalized = is_normalized(c);
    let mut points: Vec<P3> = Vec::new();
    let mut at = 0;
    for (i, &o) in orders.iter().enumerate() {
        let h = breaks[i + 1] - breaks[i];
        let a: Vec<V3> = (0..o)
            .map(|k| coefs[at + k] * if normalized { 1.0 } else { h.powi(k as i32) })
            .collect();
        at += o;
        let piece = bernstein(&a, degree);
        if let Some(last) = points.last() {
            let gap = (last - piece[0]).norm();
            if gap.is_nan() || gap > JOIN_MM {
                return Err(malformed(
                    c,
                    &format!(
                        "its segments {i} and {} do not meet ({gap:.3} mm apart)",
                        i + 1
                    ),
                ));
            }
            points.extend(&piece[1..]);
        } else {
            points.extend(piece);
        }
    }
    let knots = Knots::checked(degree, piece_knots(&breaks, degree))
        .ok_or_else(|| malformed(c, "its knots are not ascending"))?;
    let curve = BSplineCurve {
        knots,
        weights: vec![1.0; points.len()],
        points,
    };
    let t0 = domain(c).map_or(breaks[0], |dm| dm.0);
    let start = curve.eval(t0);
    Ok((Curve::BSpline(Arc::new(curve)), Some(start)))
}

/// A `Spline23Core` as a B-spline surface: the order of patches and coefficients under
/// which the patches meet and `vertices` (the face's) lie on it.
pub(super) fn spline23(d: &Doc, c: &Node, vertices: &[P3], on: f64) -> Result<Surf, QifError> {
    let (bu, bv) = (breakpoints(c, "KnotsU")?, breakpoints(c, "KnotsV")?);
    let (ou, ov) = (
        orders(c, "OrdersU", bu.len())?,
        orders(c, "OrdersV", bv.len())?,
    );
    let total: usize = ou.iter().flat_map(|a| ov.iter().map(move |b| a * b)).sum();
    let coefs = coefficients(d, c, total)?;
    let (p, q) = (degree_of(c, &ou)?, degree_of(c, &ov)?);
    let (u, v) = match (
        Knots::checked(p, piece_knots(&bu, p)),
        Knots::checked(q, piece_knots(&bv, q)),
    ) {
        (Some(u), Some(v)) => (u, v),
        _ => return Err(malformed(c, "its knots are not ascending")),
    };
    let grid = Grid {
        bu: &bu,
        bv: &bv,
        ou: &ou,
        ov: &ov,
        p,
        q,
        normalized: is_normalized(c),
    };
    for patches_u_fastest in [true, false] {
        for coefs_u_fastest in [true, false] {
            let Some(points) = grid.points(&coefs, patches_u_fastest, coefs_u_fastest) else {
                continue;
            };
            let (nu, nv) = (points.len(), points[0].len());
            let same = |a: &P3, b: &P3| (a - b).norm() < 1e-9 * (1.0 + a.coords.norm());
            let closed = [
                (0..nv).all(|j| same(&points[0][j], &points[nu - 1][j])),
                (0..nu).all(|i| same(&points[i][0], &points[i][nv - 1])),
            ];
            let s = Surf::BSpline(Arc::new(BSplineSurface {
                u: u.clone(),
                v: v.clone(),
                weights: vec![vec![1.0; nv]; nu],
                points,
                closed,
            }));
            let fits = vertices.iter().all(|x| {
                let (a, b) = s.param(x, None);
                (s.eval(a, b) - x).norm() <= on
            });
            if fits {
                return Ok(s);
            }
        }
    }
    Err(malformed(
        c,
        "its patches do not meet, or its face's vertices lie off it, with the patches and coefficients taken in any order",
    ))
}

/// The shape of a spline surface's patches.
struct Grid<'a> {
    bu: &'a [f64],
    bv: &'a [f64],
    ou: &'a [usize],
    ov: &'a [usize],
    p: usize,
    q: usize,
    normalized: bool,
}

impl Grid<'_> {
    /// The B-spline's control points with the patches (and within each patch the
    /// coefficients) taken u-fastest or v-fastest; `None` when the patches do not meet.
    fn points(&self, coefs: &[V3], patches_u: bool, coefs_u: bool) -> Option<Vec<Vec<P3>>> {
        let (mu, mv) = (self.ou.len(), self.ov.len());
        let (nu, nv) = (mu * self.p + 1, mv * self.q + 1);
        let mut grid: Vec<Vec<Option<P3>>> = vec![vec![None; nv]; nu];
        let order: Vec<(usize, usize)> = if patches_u {
            (0..mv).flat_map(|j| (0..mu).map(move |i| (i, j))).collect()
        } else {
            (0..mu).flat_map(|i| (0..mv).map(move |j| (i, j))).collect()
        };
        let mut at = 0;
        for (i, j) in order {
            let (oi, oj) = (self.ou[i], self.ov[j]);
            let (hu, hv) = (self.bu[i + 1] - self.bu[i], self.bv[j + 1] - self.bv[j]);
            // Coefficients a[k][l] of s^k r^l, scaled to the patch's unit square.
            let mut a = vec![vec![V3::zeros(); oj]; oi];
            for n in 0..oi * oj {
                let (k, l) = if coefs_u {
                    (n % oi, n / oi)
                } else {
                    (n / oj, n % oj)
                };
                let scale = if self.normalized {
                    1.0
                } else {
                    hu.powi(k as i32) * hv.powi(l as i32)
                };
                a[k][l] = coefs[at + n] * scale;
            }
            at += oi * oj;
            // Power to Bernstein along v for each power of s, then along u.
            let rows: Vec<Vec<V3>> = a.iter().map(|r| bernstein_v(r, self.q)).collect();
            for jj in 0..=self.q {
                let column: Vec<V3> = rows.iter().map(|r| r[jj]).collect();
                for (ii, b) in bernstein_v(&column, self.p).into_iter().enumerate() {
                    let cell = &mut grid[i * self.p + ii][j * self.q + jj];
                    let b = P3::from(b);
                    match cell {
                        Some(prev)
                            if (*prev - b).norm().is_nan() || (*prev - b).norm() > JOIN_MM =>
                        {
                            return None
                        }
                        _ => *cell = Some(b),
                    }
                }
            }
        }
        grid.into_iter()
            .map(|row| row.into_iter().collect::<Option<Vec<P3>>>())
            .collect()
    }
}

/// Whether `normalized` is set.
fn is_normalized(c: &Node) -> bool {
    matches!(c.attr("normalized"), Some("true" | "1"))
}

/// Strictly ascending breakpoints, at least two.
fn breakpoints(c: &Node, name: &str) -> Result<Vec<f64>, QifError> {
    let k = c
        .child(name)
        .and_then(|k| k.numbers())
        .ok_or_else(|| malformed(c, &format!("its <{name}> are not numbers")))?;
    if k.len() < 2 || k.windows(2).any(|w| w[1] <= w[0]) || k.iter().any(|x| !x.is_finite()) {
        return Err(malformed(
            c,
            &format!("its <{name}> are not two or more ascending breakpoints"),
        ));
    }
    Ok(k)
}

/// One order per interval between `breaks` breakpoints, each from 1 to the highest
/// order read.
fn orders(c: &Node, name: &str, breaks: usize) -> Result<Vec<usize>, QifError> {
    let o = c
        .child(name)
        .and_then(|k| k.numbers())
        .ok_or_else(|| malformed(c, &format!("its <{name}> are not numbers")))?;
    let max = (MAX_DEGREE + 1) as f64;
    if o.len() + 1 != breaks
        || o.iter()
            .any(|x| x.fract() != 0.0 || !(1.0..=max).contains(x))
    {
        return Err(malformed(
            c,
            &format!("its <{name}> are not one order from 1 to {max} per segment"),
        ));
    }
    Ok(o.into_iter().map(|x| x as usize).collect())
}

/// The highest order's degree (1 at least: a spline of constants is a point).
fn degree_of(c: &Node, orders: &[usize]) -> Result<usize, QifError> {
    match orders.iter().max() {
        Some(&o) if o >= 2 => Ok(o - 1),
        _ => Err(malformed(c, "its polynomials are all constants")),
    }
}

/// The `Coefficients` as vectors in millimetres, exactly `n` of them.
fn coefficients(d: &Doc, c: &Node, n: usize) -> Result<Vec<V3>, QifError> {
    let v = c
        .child("Coefficients")
        .and_then(|k| k.numbers())
        .filter(|v| v.len() == 3 * n && v.iter().all(|x| x.is_finite()))
        .ok_or_else(|| {
            malformed(
                c,
                &format!("its <Coefficients> are not {n} x y z triples, the sum of its orders"),
            )
        })?;
    Ok(v.chunks(3)
        .map(|p| V3::new(p[0], p[1], p[2]) * d.unit)
        .collect())
}

/// The full knot vector of Bézier pieces of this degree between `breaks`: the ends
/// `degree + 1` times, the inner breakpoints `degree` times.
fn piece_knots(breaks: &[f64], degree: usize) -> Vec<f64> {
    let mut k = Vec::new();
    for (i, b) in breaks.iter().enumerate() {
        let m = if i == 0 || i + 1 == breaks.len() {
            degree + 1
        } else {
            degree
        };
        k.extend(std::iter::repeat_n(*b, m));
    }
    k
}

/// A polynomial `Σ a_k s^k` on `0 ≤ s ≤ 1` as the `degree + 1` Bézier points of that
/// degree: `b_i = Σ_{k ≤ i} C(i, k) / C(degree, k) · a_k` (a lower order is the same
/// polynomial with zero coefficients above it).
fn bernstein_v(a: &[V3], degree: usize) -> Vec<V3> {
    (0..=degree)
        .map(|i| {
            (0..=i.min(a.len() - 1))
                .map(|k| a[k] * (binomial(i, k) / binomial(degree, k)))
                .sum()
        })
        .collect()
}

/// [`bernstein_v`] for a curve's piece, as points.
fn bernstein(a: &[V3], degree: usize) -> Vec<P3> {
    bernstein_v(a, degree).into_iter().map(P3::from).collect()
}

fn binomial(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |acc, j| acc * (n - j) as f64 / (j + 1) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_power_polynomial_is_its_bezier_piece() {
        // p(s) = (1, 2, 0) + (3, 0, 0) s + (0, 0, 6) s² + (0, 4, 0) s³, raised to degree 4.
        let a = [
            V3::new(1.0, 2.0, 0.0),
            V3::new(3.0, 0.0, 0.0),
            V3::new(0.0, 0.0, 6.0),
            V3::new(0.0, 4.0, 0.0),
        ];
        let b = bernstein(&a, 4);
        let c = BSplineCurve {
            knots: Knots::checked(4, piece_knots(&[0.0, 1.0], 4)).unwrap(),
            weights: vec![1.0; 5],
            points: b,
        };
        for k in 0..=10 {
            let s = k as f64 / 10.0;
            let want: V3 = a
                .iter()
                .enumerate()
                .map(|(i, x)| x * s.powi(i as i32))
                .sum();
            assert!((c.eval(s).coords - want).norm() < 1e-12, "{s}");
        }
    }
}
