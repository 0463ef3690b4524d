//! Least-squares fits of measured points, as a CMM's software fits them: a plane by its
//! covariance's smallest eigenvector, a cylinder, cone and sphere by Levenberg–Marquardt
//! on the geometric distances, started from the nominal (which the program states) and
//! parametrised about it so a handful of points converges in a few steps. Points on one
//! circle fix no axis direction: the direction (and a cone's angle) then stay nominal.

use super::{P3, V3};
use nalgebra::{DMatrix, DVector, Matrix3, SymmetricEigen};

/// A fitted (or nominal) shape, in whatever frame its points are. Directions are unit
/// vectors; `p` is a point of the plane or axis.
#[allow(missing_docs)]
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// A point on the plane and its unit normal.
    Plane { p: P3, n: V3 },
    /// A point on the axis, the unit axis, the radius.
    Cylinder { p: P3, a: V3, r: f64 },
    /// The apex, the unit axis into the cone, the half angle (radians).
    Cone { apex: P3, a: V3, half: f64 },
    /// Centre and radius.
    Sphere { c: P3, r: f64 },
    /// One point and its vector.
    Point { p: P3, n: V3 },
    /// A line on a face (the 3-2-1 secondary): a point, its unit direction, and the
    /// face's normal across it (the side its touches came from).
    Line { p: P3, d: V3, n: V3 },
    /// Two opposed planes: the centre plane's point and normal, and the width.
    Parpln { p: P3, n: V3, width: f64 },
    /// No analytic shape (a free-form surface): the points are the feature.
    Surface,
}

impl Shape {
    /// A face's analytic surface as a shape, with whether the solid is outside it (a
    /// shaft rather than a hole); `None` for a free-form face.
    pub fn of_surface(s: &crate::geometry::Surface) -> Option<(Shape, bool)> {
        use crate::geometry::Surface;
        Some(match s {
            Surface::Plane { origin, normal } => (
                Shape::Plane {
                    p: *origin,
                    n: *normal,
                },
                true,
            ),
            Surface::Cylinder {
                origin,
                axis,
                radius,
                convex,
            } => (
                Shape::Cylinder {
                    p: *origin,
                    a: *axis,
                    r: *radius,
                },
                *convex,
            ),
            Surface::Cone {
                apex,
                axis,
                half_angle,
                convex,
            } => (
                Shape::Cone {
                    apex: *apex,
                    a: *axis,
                    half: *half_angle,
                },
                *convex,
            ),
            Surface::Sphere {
                center,
                radius,
                convex,
            } => (
                Shape::Sphere {
                    c: *center,
                    r: *radius,
                },
                *convex,
            ),
            Surface::Freeform => return None,
        })
    }

    /// Whether two shapes are one surface, to `tol` (mm; and `tol` per mm for
    /// directions): a plane's normal and offset, a cylinder's axis line and radius, a
    /// cone's apex, axis and angle, a sphere's centre and radius. A feature's nominal
    /// as a program writes it (four decimals) is its face's surface by this test.
    pub fn same_surface(&self, o: &Shape, tol: f64) -> bool {
        let parallel = |a: &V3, b: &V3| a.dot(b).abs() > 1.0 - tol * tol;
        let off_line = |p: &P3, a: &V3, q: &P3| {
            let d = q - p;
            (d - a * d.dot(a)).norm()
        };
        match (self, o) {
            (Shape::Plane { p, n }, Shape::Plane { p: q, n: m }) => {
                parallel(n, m) && (q - p).dot(n).abs() < tol
            }
            (Shape::Cylinder { p, a, r }, Shape::Cylinder { p: q, a: b, r: s }) => {
                parallel(a, b) && off_line(p, a, q) < tol && (r - s).abs() < tol
            }
            (
                Shape::Cone { apex, a, half },
                Shape::Cone {
                    apex: q,
                    a: b,
                    half: h,
                },
            ) => a.dot(b) > 1.0 - tol * tol && (apex - q).norm() < tol && (half - h).abs() < tol,
            (Shape::Sphere { c, r }, Shape::Sphere { c: d, r: s }) => {
                (c - d).norm() < tol && (r - s).abs() < tol
            }
            _ => false,
        }
    }

    /// The shape moved by a rigid motion.
    pub fn moved(&self, m: &nalgebra::Isometry3<f64>) -> Shape {
        match self {
            Shape::Plane { p, n } => Shape::Plane { p: m * p, n: m * n },
            Shape::Cylinder { p, a, r } => Shape::Cylinder {
                p: m * p,
                a: m * a,
                r: *r,
            },
            Shape::Cone { apex, a, half } => Shape::Cone {
                apex: m * apex,
                a: m * a,
                half: *half,
            },
            Shape::Sphere { c, r } => Shape::Sphere { c: m * c, r: *r },
            Shape::Point { p, n } => Shape::Point { p: m * p, n: m * n },
            Shape::Line { p, d, n } => Shape::Line {
                p: m * p,
                d: m * d,
                n: m * n,
            },
            Shape::Parpln { p, n, width } => Shape::Parpln {
                p: m * p,
                n: m * n,
                width: *width,
            },
            Shape::Surface => Shape::Surface,
        }
    }

    /// Its direction: a plane's normal, an axis, a line's run; none for spheres and
    /// surfaces.
    pub fn direction(&self) -> Option<V3> {
        match self {
            Shape::Line { d, .. } => Some(*d),
            Shape::Plane { n, .. } | Shape::Point { n, .. } | Shape::Parpln { n, .. } => Some(*n),
            Shape::Cylinder { a, .. } | Shape::Cone { a, .. } => Some(*a),
            _ => None,
        }
    }

    /// Its location: a point of the plane or axis, the apex, the centre.
    pub fn location(&self) -> Option<P3> {
        match self {
            Shape::Plane { p, .. }
            | Shape::Point { p, .. }
            | Shape::Line { p, .. }
            | Shape::Parpln { p, .. }
            | Shape::Cylinder { p, .. } => Some(*p),
            Shape::Cone { apex, .. } => Some(*apex),
            Shape::Sphere { c, .. } => Some(*c),
            Shape::Surface => None,
        }
    }

    /// Its size: a diameter, a width; none otherwise.
    pub fn size(&self) -> Option<f64> {
        match self {
            Shape::Cylinder { r, .. } | Shape::Sphere { r, .. } => Some(2.0 * r),
            Shape::Parpln { width, .. } => Some(*width),
            _ => None,
        }
    }

    /// Signed distance of `q` from the shape, positive on the side the normal or the
    /// radius points to (outside a cylinder, cone or sphere; above a plane).
    pub fn signed(&self, q: &P3) -> f64 {
        match self {
            Shape::Plane { p, n } | Shape::Point { p, n } | Shape::Line { p, n, .. } => {
                (q - p).dot(n)
            }
            Shape::Cylinder { p, a, r } => {
                let d = q - p;
                (d - a * d.dot(a)).norm() - r
            }
            Shape::Cone { apex, a, half } => {
                let d = q - apex;
                let h = d.dot(a);
                let rr = (d - a * h).norm();
                rr * half.cos() - h * half.sin()
            }
            Shape::Sphere { c, r } => (q - c).norm() - r,
            Shape::Parpln { p, n, width } => (q - p).dot(n).abs() - width / 2.0,
            Shape::Surface => 0.0,
        }
    }

    /// The direction the signed distance grows in at `q` (up to sign, the surface's
    /// normal there); `None` for a free-form surface or on an axis.
    pub fn normal_at(&self, q: &P3) -> Option<V3> {
        match self {
            Shape::Plane { n, .. }
            | Shape::Point { n, .. }
            | Shape::Line { n, .. }
            | Shape::Parpln { n, .. } => Some(*n),
            Shape::Cylinder { p, a, .. } => {
                let d = q - p;
                (d - a * d.dot(a)).try_normalize(1e-9)
            }
            Shape::Cone { apex, a, half } => {
                let d = q - apex;
                let radial = (d - a * d.dot(a)).try_normalize(1e-9)?;
                Some(radial * half.cos() - a * half.sin())
            }
            Shape::Sphere { c, .. } => (q - c).try_normalize(1e-9),
            Shape::Surface => None,
        }
    }

    /// The shape offset by `d` along its outward sense (`convex`: the radius grows
    /// outward; a hole's inward). A plane moves along its normal.
    pub fn offset(&self, d: f64, convex: bool) -> Shape {
        let s = if convex { d } else { -d };
        match self {
            Shape::Plane { p, n } => Shape::Plane {
                p: p + n * d,
                n: *n,
            },
            Shape::Cylinder { p, a, r } => Shape::Cylinder {
                p: *p,
                a: *a,
                r: r + s,
            },
            Shape::Sphere { c, r } => Shape::Sphere { c: *c, r: r + s },
            Shape::Cone { apex, a, half } => Shape::Cone {
                apex: apex - a * (s / half.sin().max(1e-9)),
                a: *a,
                half: *half,
            },
            other => other.clone(),
        }
    }
}

/// Two unit vectors across `a`.
pub fn across(a: &V3) -> (V3, V3) {
    let helper = if a.x.abs() < 0.9 { V3::x() } else { V3::y() };
    let u = helper.cross(a).normalize();
    (u, a.cross(&u))
}

/// A pattern of parallel bores or pins as one axis: the members' mean direction,
/// through the centroid of their axes (each taken where it crosses the plane across
/// the first), the mean radius; `None` unless every member is a cylinder.
pub fn pattern(members: &[Shape]) -> Option<Shape> {
    let cyl: Vec<(P3, V3, f64)> = members
        .iter()
        .map(|m| match m {
            Shape::Cylinder { p, a, r } => Some((*p, *a, *r)),
            _ => None,
        })
        .collect::<Option<_>>()?;
    let (p0, a0, _) = *cyl.first()?;
    let a = cyl
        .iter()
        .fold(V3::zeros(), |s, (_, a, _)| {
            s + if a.dot(&a0) < 0.0 { -a } else { *a }
        })
        .try_normalize(1e-9)?;
    let n = cyl.len() as f64;
    let c = cyl.iter().fold(V3::zeros(), |s, (p, _, _)| {
        s + (p - a * (p - p0).dot(&a)).coords
    }) / n;
    let r = cyl.iter().map(|x| x.2).sum::<f64>() / n;
    Some(Shape::Cylinder {
        p: P3::from(c),
        a,
        r,
    })
}

/// The least-squares plane; its normal on the side of `near`.
pub fn plane(points: &[P3], near: &V3) -> Option<Shape> {
    if points.len() < 3 {
        return None;
    }
    let c = points.iter().fold(V3::zeros(), |s, q| s + q.coords) / points.len() as f64;
    let m = points.iter().fold(Matrix3::zeros(), |s, q| {
        let d = q.coords - c;
        s + d * d.transpose()
    });
    let e = SymmetricEigen::new(m);
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&a, &b| e.eigenvalues[a].total_cmp(&e.eigenvalues[b]));
    // Collinear points leave two small eigenvalues: no plane.
    if e.eigenvalues[idx[1]] <= 1e-12 * e.eigenvalues[idx[2]].max(1e-300) {
        return None;
    }
    let mut n: V3 = e.eigenvectors.column(idx[0]).into_owned().normalize();
    if n.dot(near) < 0.0 {
        n = -n;
    }
    Some(Shape::Plane { p: P3::from(c), n })
}

/// Whether the points spread along `a` (more than one circle).
fn spread_along(points: &[P3], a: &V3) -> bool {
    let (lo, hi) = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), q| {
            let t = q.coords.dot(a);
            (l.min(t), h.max(t))
        });
    hi - lo > 1e-3
}

/// Levenberg–Marquardt on `residuals(x, out)` from `x`, numeric Jacobian.
fn lm(x: &mut DVector<f64>, n: usize, residuals: &dyn Fn(&DVector<f64>, &mut DVector<f64>)) {
    let m = x.len();
    let mut r = DVector::zeros(n);
    let mut r2 = DVector::zeros(n);
    residuals(x, &mut r);
    let mut cost = r.norm_squared();
    let mut lambda = 1e-3;
    for _ in 0..100 {
        let mut j = DMatrix::zeros(n, m);
        for k in 0..m {
            let h = 1e-7 * x[k].abs().max(1.0);
            let mut xk = x.clone();
            xk[k] += h;
            residuals(&xk, &mut r2);
            for i in 0..n {
                j[(i, k)] = (r2[i] - r[i]) / h;
            }
        }
        let jt = j.transpose();
        let jtj = &jt * &j;
        let g = &jt * &r;
        let mut improved = false;
        for _ in 0..12 {
            let mut a = jtj.clone();
            for k in 0..m {
                a[(k, k)] += lambda * (jtj[(k, k)].max(1e-12));
            }
            let Some(step) = a.lu().solve(&(-&g)) else {
                lambda *= 10.0;
                continue;
            };
            let xn = &*x + &step;
            residuals(&xn, &mut r2);
            let c2 = r2.norm_squared();
            if c2.is_finite() && c2 <= cost {
                let small = step.norm() < 1e-12 * (1.0 + x.norm());
                *x = xn;
                std::mem::swap(&mut r, &mut r2);
                let done = small || cost - c2 <= 1e-15 * (1.0 + cost);
                cost = c2;
                lambda = (lambda / 10.0).max(1e-12);
                improved = !done;
                break;
            }
            lambda *= 10.0;
        }
        if !improved {
            break;
        }
    }
}

/// Where a circle (`D` = 2) or sphere (`D` = 3) fit starts, as an offset of the centre
/// from the nominal's and a radius: the points' own algebraic (Kåsa) circle or sphere,
/// |x|² + D·x + G = 0 solved by least squares, where it fits them better than the
/// nominal does; else the nominal. A part placed millimetres off puts a small bore's
/// nominal outside it, where the descent runs away; points at two places round a
/// circle (a fillet touched at two angles) leave the algebraic one undetermined.
fn start<const D: usize>(pts: &[[f64; D]], nominal_r: f64) -> ([f64; D], f64) {
    let nominal = ([0.0; D], nominal_r);
    let cost = |(c, r): &([f64; D], f64)| -> f64 {
        pts.iter()
            .map(|q| {
                let d: f64 = (0..D).map(|k| (q[k] - c[k]).powi(2)).sum();
                (d.sqrt() - r).powi(2)
            })
            .sum()
    };
    if pts.len() <= D {
        return nominal;
    }
    let mut a = DMatrix::zeros(pts.len(), D + 1);
    let mut b = DVector::zeros(pts.len());
    for (i, q) in pts.iter().enumerate() {
        for k in 0..D {
            a[(i, k)] = q[k];
        }
        a[(i, D)] = 1.0;
        b[i] = -q.iter().map(|x| x * x).sum::<f64>();
    }
    let svd = a.svd(true, true);
    let s = &svd.singular_values;
    if s.min() <= 1e-4 * s.max() {
        return nominal;
    }
    let Ok(sol) = svd.solve(&b, 1e-12) else {
        return nominal;
    };
    let c: [f64; D] = std::array::from_fn(|k| -sol[k] / 2.0);
    let rr = c.iter().map(|x| x * x).sum::<f64>() - sol[D];
    if !(rr > 0.0 && rr.is_finite()) {
        return nominal;
    }
    let own = (c, rr.sqrt());
    if cost(&own) + 1e-9 * (pts.len() as f64) < cost(&nominal) {
        own
    } else {
        nominal
    }
}

/// The least-squares cylinder started from `guess`.
pub fn cylinder(points: &[P3], guess: &Shape) -> Option<Shape> {
    let Shape::Cylinder { p, a, r } = guess else {
        return None;
    };
    // About the points' centroid along the axis, for conditioning.
    let mean = points.iter().fold(V3::zeros(), |s, q| s + q.coords) / points.len().max(1) as f64;
    let p0 = p + a * (mean - p.coords).dot(a);
    let (u, v) = across(a);
    let tilt = spread_along(points, a) && points.len() >= 5;
    if points.len() < 3 {
        return None;
    }
    let shape = |x: &DVector<f64>| -> (P3, V3, f64) {
        let o = p0 + u * x[0] + v * x[1];
        let ax = if tilt {
            (a + u * x[3] + v * x[4]).normalize()
        } else {
            *a
        };
        (o, ax, x[2])
    };
    let flat: Vec<[f64; 2]> = points
        .iter()
        .map(|q| {
            let d = q - p0;
            [d.dot(&u), d.dot(&v)]
        })
        .collect();
    let ([x0, y0], r0) = start(&flat, *r);
    let mut x = DVector::from_vec(if tilt {
        vec![x0, y0, r0, 0.0, 0.0]
    } else {
        vec![x0, y0, r0]
    });
    lm(&mut x, points.len(), &|x, out| {
        let (o, ax, rr) = shape(x);
        for (i, q) in points.iter().enumerate() {
            let d = q - o;
            out[i] = (d - ax * d.dot(&ax)).norm() - rr;
        }
    });
    let (o, ax, rr) = shape(&x);
    (rr.is_finite() && rr > 0.0).then_some(Shape::Cylinder { p: o, a: ax, r: rr })
}

/// The line through surface points touched along `n` on a face: their mean and
/// their principal direction, turned the way `guess` runs; at least two points apart.
pub fn line(points: &[P3], n: &V3, guess: &V3) -> Option<Shape> {
    let (first, last) = (points.first()?, points.last()?);
    let d = (last - first).try_normalize(1e-6)?;
    let d = if d.dot(guess) < 0.0 { -d } else { d };
    let mean = points.iter().fold(V3::zeros(), |s, q| s + q.coords) / points.len() as f64;
    // The face's normal square to the line.
    let n = (n - d * n.dot(&d)).try_normalize(1e-9)?;
    Some(Shape::Line {
        p: P3::from(mean),
        d,
        n,
    })
}

/// The least-squares circle of points about `guess`'s axis (a cylinder whose point is
/// the nominal centre): the axis kept, the centre and radius fitted in the plane square
/// to it, at the points' mean height along it. Three points off a line determine it.
pub fn circle(points: &[P3], guess: &Shape) -> Option<Shape> {
    let Shape::Cylinder { a, .. } = guess else {
        return None;
    };
    let (u, v) = across(a);
    let flat: Vec<[f64; 2]> = points
        .iter()
        .map(|q| [q.coords.dot(&u), q.coords.dot(&v)])
        .collect();
    if points.len() < 3 || collinear(&flat) {
        return None;
    }
    // The cylinder fit holds the axis when the points do not spread along it; flattened
    // onto one plane, they never do.
    let mean = points.iter().fold(V3::zeros(), |s, q| s + q.coords) / points.len() as f64;
    let h = mean.dot(a);
    let on_plane: Vec<P3> = points
        .iter()
        .map(|q| q - a * (q.coords.dot(a) - h))
        .collect();
    cylinder(&on_plane, guess)
}

/// Whether 2D points lie on one line (to a micrometre over their spread).
fn collinear(pts: &[[f64; 2]]) -> bool {
    let n = pts.len() as f64;
    let (mx, my) = pts
        .iter()
        .fold((0.0, 0.0), |s, p| (s.0 + p[0] / n, s.1 + p[1] / n));
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for p in pts {
        let (dx, dy) = (p[0] - mx, p[1] - my);
        sxx += dx * dx;
        sxy += dx * dy;
        syy += dy * dy;
    }
    // The smaller eigenvalue of the scatter: the spread across the best line.
    let tr = sxx + syy;
    let det = sxx * syy - sxy * sxy;
    let small = tr / 2.0 - ((tr * tr / 4.0 - det).max(0.0)).sqrt();
    small / n < 1e-12 || small <= 1e-12 * tr
}

/// The least-squares cone started from `guess`.
pub fn cone(points: &[P3], guess: &Shape) -> Option<Shape> {
    let Shape::Cone { apex, a, half } = guess else {
        return None;
    };
    if points.len() < 3 {
        return None;
    }
    let (u, v) = across(a);
    let tilt = spread_along(points, a) && points.len() >= 6;
    let shape = |x: &DVector<f64>| -> (P3, V3, f64) {
        let ap = apex + u * x[0] + v * x[1] + a * x[2];
        if tilt {
            ((ap), (a + u * x[3] + v * x[4]).normalize(), *half + x[5])
        } else {
            (ap, *a, *half)
        }
    };
    let mut x = DVector::from_vec(if tilt { vec![0.0; 6] } else { vec![0.0; 3] });
    lm(&mut x, points.len(), &|x, out| {
        let (ap, ax, h) = shape(x);
        for (i, q) in points.iter().enumerate() {
            let d = q - ap;
            let t = d.dot(&ax);
            let rr = (d - ax * t).norm();
            out[i] = rr * h.cos() - t * h.sin();
        }
    });
    let (ap, ax, h) = shape(&x);
    (h.is_finite() && h > 0.0 && h < std::f64::consts::FRAC_PI_2).then_some(Shape::Cone {
        apex: ap,
        a: ax,
        half: h,
    })
}

/// The least-squares sphere started from `guess`.
pub fn sphere(points: &[P3], guess: &Shape) -> Option<Shape> {
    let Shape::Sphere { c, r } = guess else {
        return None;
    };
    if points.len() < 4 {
        return None;
    }
    let around: Vec<[f64; 3]> = points.iter().map(|q| (q - c).into()).collect();
    let ([cx, cy, cz], r0) = start(&around, *r);
    let mut x = DVector::from_vec(vec![cx, cy, cz, r0]);
    lm(&mut x, points.len(), &|x, out| {
        let cc = c + V3::new(x[0], x[1], x[2]);
        for (i, q) in points.iter().enumerate() {
            out[i] = (q - cc).norm() - x[3];
        }
    });
    let cc = c + V3::new(x[0], x[1], x[2]);
    (x[3].is_finite() && x[3] > 0.0).then_some(Shape::Sphere { c: cc, r: x[3] })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cylinder_is_found_from_a_nominal_off_by_a_little() {
        let truth = (
            P3::new(1.0, 2.0, 0.0),
            V3::new(0.01, 0.0, 1.0).normalize(),
            5.0,
        );
        let (u, v) = across(&truth.1);
        let mut pts = Vec::new();
        for h in [0.0, 10.0] {
            for k in 0..4 {
                let t = k as f64 * std::f64::consts::FRAC_PI_2 + 0.3;
                pts.push(truth.0 + truth.1 * h + (u * t.cos() + v * t.sin()) * truth.2);
            }
        }
        let guess = Shape::Cylinder {
            p: P3::origin(),
            a: V3::z(),
            r: 5.2,
        };
        let Some(Shape::Cylinder { p, a, r }) = cylinder(&pts, &guess) else {
            panic!("no fit");
        };
        assert!((r - 5.0).abs() < 1e-9, "{r}");
        assert!(a.dot(&truth.1).abs() > 1.0 - 1e-12);
        assert!((p - truth.0).cross(&truth.1).norm() < 1e-9);
    }

    #[test]
    fn a_sphere_and_a_plane_fit_their_points() {
        let c = P3::new(3.0, -1.0, 2.0);
        let pts: Vec<P3> = [
            (1.0, 0.0, 0.0),
            (0.0, 1.0, 0.0),
            (0.0, 0.0, 1.0),
            (-0.6, 0.0, 0.8),
            (0.0, -0.6, 0.8),
        ]
        .iter()
        .map(|&(x, y, z)| c + V3::new(x, y, z) * 7.0)
        .collect();
        let Some(Shape::Sphere { c: cc, r }) = sphere(
            &pts,
            &Shape::Sphere {
                c: P3::new(3.5, -1.0, 2.0),
                r: 6.0,
            },
        ) else {
            panic!("no fit");
        };
        assert!((cc - c).norm() < 1e-9 && (r - 7.0).abs() < 1e-9);
        let flat = [
            P3::new(0.0, 0.0, 1.0),
            P3::new(1.0, 0.0, 1.0),
            P3::new(0.0, 1.0, 1.0),
        ];
        let Some(Shape::Plane { n, .. }) = plane(&flat, &V3::z()) else {
            panic!("no plane");
        };
        assert!((n - V3::z()).norm() < 1e-12);
    }
}
