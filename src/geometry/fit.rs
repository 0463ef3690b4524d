//! Least-squares surface fits for mesh faces.
//!
//! Planes: centroid and the covariance's smallest eigenvector. Cylinders and cones: the
//! axis direction is the direction the (centred) triangle normals do not vary in; every
//! normal line of a cylinder or cone meets the axis, so the axis point is the
//! least-squares intersection of the normals projected across the axis; the radius
//! along the axis is then a straight line (constant for a cylinder). Spheres: the
//! algebraic fit `|p|² = 2 c·p + k`.

use super::{Surface, P3, V3};
use nalgebra::{Matrix3, Matrix4, SymmetricEigen, Vector4};

/// A fitted surface and the RMS distance of the points to it (mm).
#[derive(Debug, Clone)]
pub struct Fit {
    /// The surface.
    pub surface: Surface,
    /// RMS residual (mm).
    pub rms: f64,
}

/// Points and area-weighted normals of a patch.
pub struct Patch<'a> {
    /// Distinct vertices of the patch.
    pub points: &'a [P3],
    /// (unit normal, area, centroid) per triangle.
    pub normals: &'a [(V3, f64, P3)],
}

fn rms(points: &[P3], s: &Surface) -> f64 {
    let sum: f64 = points
        .iter()
        .map(|p| s.distance(p).unwrap_or(0.0).powi(2))
        .sum();
    (sum / points.len().max(1) as f64).sqrt()
}

fn smallest_eigenvector(m: Matrix3<f64>) -> V3 {
    let e = SymmetricEigen::new(m);
    let (mut k, mut best) = (0, f64::INFINITY);
    for i in 0..3 {
        if e.eigenvalues[i] < best {
            best = e.eigenvalues[i];
            k = i;
        }
    }
    e.eigenvectors.column(k).into_owned().normalize()
}

fn mean_normal(p: &Patch) -> V3 {
    p.normals
        .iter()
        .fold(V3::zeros(), |s, (n, a, _)| s + n * *a)
}

/// The best plane, its normal oriented like the triangles'.
pub fn plane(p: &Patch) -> Fit {
    let c = p.points.iter().fold(V3::zeros(), |s, q| s + q.coords) / p.points.len().max(1) as f64;
    let m = p.points.iter().fold(Matrix3::zeros(), |s, q| {
        let d = q.coords - c;
        s + d * d.transpose()
    });
    let mut n = smallest_eigenvector(m);
    if n.dot(&mean_normal(p)) < 0.0 {
        n = -n;
    }
    let surface = Surface::Plane {
        origin: P3::from(c),
        normal: n,
    };
    Fit {
        rms: rms(p.points, &surface),
        surface,
    }
}

/// The best cylinder or cone (whichever the radius along the axis says), or `None` when
/// the normals do not determine an axis.
pub(crate) fn cylinder_or_cone(p: &Patch) -> Option<Fit> {
    let wsum: f64 = p.normals.iter().map(|(_, a, _)| a).sum();
    if wsum <= 0.0 {
        return None;
    }
    let nbar = mean_normal(p) / wsum;
    let m = p.normals.iter().fold(Matrix3::zeros(), |s, (n, a, _)| {
        let d = n - nbar;
        s + d * d.transpose() * *a
    });
    // A narrow patch (a few facets) leaves two small eigenvalues: the axis is then the
    // direction across the normals' spread and their mean.
    let e = SymmetricEigen::new(m);
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&a, &b| e.eigenvalues[a].total_cmp(&e.eigenvalues[b]));
    let largest: V3 = e.eigenvectors.column(idx[2]).into_owned();
    let axis = if e.eigenvalues[idx[1]] < 0.05 * e.eigenvalues[idx[2]] {
        largest.cross(&nbar).try_normalize(1e-9)?
    } else {
        e.eigenvectors.column(idx[0]).into_owned().normalize()
    };
    // Axis point: least-squares intersection of the normal lines, across the axis.
    let (u, v) = {
        let helper = if axis.x.abs() < 0.9 { V3::x() } else { V3::y() };
        let u = helper.cross(&axis).normalize();
        (u, axis.cross(&u))
    };
    let mut a = nalgebra::Matrix2::zeros();
    let mut b = nalgebra::Vector2::zeros();
    for (n, w, g) in p.normals {
        let d = nalgebra::Vector2::new(n.dot(&u), n.dot(&v));
        let len = d.norm();
        if len < 1e-6 {
            continue;
        }
        let d = d / len;
        let q = nalgebra::Vector2::new(g.coords.dot(&u), g.coords.dot(&v));
        let perp = nalgebra::Matrix2::identity() - d * d.transpose();
        a += perp * *w;
        b += perp * q * *w;
    }
    let c2 = a.try_inverse()? * b;
    let origin = P3::from(u * c2.x + v * c2.y);
    // Radius as a straight line in the height along the axis.
    let (mut sh, mut sr, mut shh, mut shr) = (0.0, 0.0, 0.0, 0.0);
    let n = p.points.len() as f64;
    for q in p.points {
        let d = q - origin;
        let h = d.dot(&axis);
        let r = (d - axis * h).norm();
        sh += h;
        sr += r;
        shh += h * h;
        shr += h * r;
    }
    let var = shh - sh * sh / n;
    let slope = if var > 1e-12 {
        (shr - sh * sr / n) / var
    } else {
        0.0
    };
    let r0 = (sr - slope * sh) / n;
    let convex = p
        .normals
        .iter()
        .map(|(nn, w, g)| {
            let d = g - origin;
            (d - axis * d.dot(&axis)).normalize().dot(nn) * w
        })
        .sum::<f64>()
        > 0.0;
    let surface = if slope.abs() < (0.25f64).to_radians().tan() {
        Surface::Cylinder {
            origin,
            axis,
            radius: sr / n,
            convex,
        }
    } else {
        let h_apex = -r0 / slope;
        let apex = origin + axis * h_apex;
        let dir = if slope > 0.0 { axis } else { -axis };
        Surface::Cone {
            apex,
            axis: dir,
            half_angle: slope.abs().atan(),
            convex,
        }
    };
    if !surface_finite(&surface) {
        return None;
    }
    Some(Fit {
        rms: rms(p.points, &surface),
        surface,
    })
}

/// The best sphere.
pub fn sphere(p: &Patch) -> Option<Fit> {
    // Centred first: far from the origin the normal equations lose all precision.
    let mean =
        p.points.iter().fold(V3::zeros(), |s, q| s + q.coords) / p.points.len().max(1) as f64;
    let mut ata = Matrix4::zeros();
    let mut atb = Vector4::zeros();
    for q in p.points {
        let q = q.coords - mean;
        let row = Vector4::new(2.0 * q.x, 2.0 * q.y, 2.0 * q.z, 1.0);
        ata += row * row.transpose();
        atb += row * q.norm_squared();
    }
    let x = ata.try_inverse()? * atb;
    let local = V3::new(x[0], x[1], x[2]);
    let r2 = x[3] + local.norm_squared();
    let center = P3::from(local + mean);
    if r2 <= 0.0 {
        return None;
    }
    let convex = p
        .normals
        .iter()
        .map(|(n, w, g)| (g - center).normalize().dot(n) * w)
        .sum::<f64>()
        > 0.0;
    let surface = Surface::Sphere {
        center,
        radius: r2.sqrt(),
        convex,
    };
    if !surface_finite(&surface) {
        return None;
    }
    Some(Fit {
        rms: rms(p.points, &surface),
        surface,
    })
}

fn surface_finite(s: &Surface) -> bool {
    match s {
        Surface::Cylinder { origin, radius, .. } => {
            origin.coords.iter().all(|c| c.is_finite()) && radius.is_finite() && *radius < 1e7
        }
        Surface::Cone {
            apex, half_angle, ..
        } => apex.coords.iter().all(|c| c.is_finite()) && half_angle.is_finite(),
        Surface::Sphere { center, radius, .. } => {
            center.coords.iter().all(|c| c.is_finite()) && radius.is_finite() && *radius < 1e7
        }
        _ => true,
    }
}

/// Whether the triangles' normals agree with the surface's at their centroids (within
/// `max_deg`, for 95 % of the area: slivers have no reliable normal), which rules out
/// fits that pass through the vertices with the wrong shape.
fn normals_agree(p: &Patch, s: &Surface, max_deg: f64) -> bool {
    let cos = max_deg.to_radians().cos();
    let total: f64 = p.normals.iter().map(|(_, a, _)| a).sum();
    let agreeing: f64 = p
        .normals
        .iter()
        .filter(|(n, _, g)| s.normal_at(g).is_some_and(|sn| sn.dot(n) >= cos))
        .map(|(_, a, _)| a)
        .sum();
    agreeing >= 0.95 * total
}

/// How far a planar face's facet normals may turn from the plane's (degrees).
pub(crate) const PLANE_NORMAL_DEG: f64 = 10.0;

/// The best analytic surface for a patch, or free-form when none is within `tol` (mm).
/// The simplest surface that fits wins: plane, then cylinder or cone, then sphere (a
/// cylinder tessellated with one row of facets also lies on a sphere). A plane must
/// also agree with its facets' normals within [`PLANE_NORMAL_DEG`]: a small fillet (R0.5
/// in two facets) lies within the tolerance of a plane but turns through 90°.
pub fn best(p: &Patch, tol: f64) -> Fit {
    let pl = plane(p);
    if pl.rms <= tol && normals_agree(p, &pl.surface, PLANE_NORMAL_DEG) {
        return pl;
    }
    for f in [cylinder_or_cone(p), sphere(p)].into_iter().flatten() {
        if f.rms <= tol && normals_agree(p, &f.surface, 35.0) {
            return f;
        }
    }
    Fit {
        surface: Surface::Freeform,
        rms: pl.rms,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A quarter-round fillet of radius `r` along x, `n` facets across, 10 mm long.
    fn fillet(r: f64, n: usize) -> (Vec<P3>, Vec<(V3, f64, P3)>) {
        let at = |k: usize, x: f64| {
            let t = std::f64::consts::FRAC_PI_2 * k as f64 / n as f64;
            P3::new(x, r * t.cos(), r * t.sin())
        };
        let mut pts = Vec::new();
        let mut normals = Vec::new();
        for k in 0..=n {
            pts.push(at(k, 0.0));
            pts.push(at(k, 10.0));
        }
        for k in 0..n {
            let (a, b, c) = (at(k, 0.0), at(k + 1, 0.0), at(k, 10.0));
            let nrm = (b - a).cross(&(c - a));
            let t = std::f64::consts::FRAC_PI_2 * (k as f64 + 0.5) / n as f64;
            let out = V3::new(0.0, t.cos(), t.sin());
            let nrm = if nrm.dot(&out) < 0.0 { -nrm } else { nrm };
            normals.push((
                nrm.normalize(),
                nrm.norm(),
                P3::from((a.coords + b.coords + c.coords) / 3.0),
            ));
        }
        (pts, normals)
    }

    #[test]
    fn a_small_fillet_is_not_a_plane() {
        // Within a 0.06 mm fit tolerance of its chord plane, but its facets turn 90°.
        let (points, normals) = fillet(0.5, 2);
        let fit = best(
            &Patch {
                points: &points,
                normals: &normals,
            },
            0.1,
        );
        assert!(
            !matches!(fit.surface, Surface::Plane { .. }),
            "{:?}",
            fit.surface
        );
    }
}
