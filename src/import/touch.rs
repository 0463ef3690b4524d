//! Faces no ball of the rack can touch: a concave blend or corner tighter than the
//! smallest ball (NIST FTC 07's R0.43 mm fillets against the rack's Ø1 mm tip), a slot
//! narrower than it. A ball larger than a concave surface's radius rests on the
//! surface's neighbours, never on the surface, so points "on" it measure the walls
//! beside it: such a face is not a CMM's to measure (a radius gauge, an optical
//! comparator or a section is), and the importer leaves it out of the features it
//! writes, saying so in the spec.
//!
//! A concave cylinder or sphere of a radius under the ball's is untouchable by its
//! geometry. On other faces (a freeform corner blend) the test is the planner's own tip fit (`access::tip_fits`: the mesh at least 0.9 of
//! the radius from the ball's centre, the mesh's chordal error allowed) at the centroids
//! of up to [`SAMPLES`] of the face's triangles off its boundary (where it has such),
//! the ball standing on each along its outward normal. A face where it fits at under
//! half of them is untouchable: those that pass lie towards where the blend meets its
//! walls (NIST FTC 07's R0.43 corner blends pass at 29–33 % of them, the planner's
//! points on them at 1 or 2 of 16).

use crate::geometry::{RawMesh, Surface, P3};
use parry3d_f64::math::{Isometry, Point};
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::TriMesh;
use std::collections::BTreeSet;

/// The radius (mm) of the rack's smallest ball: every imported rack carries a Ø1 mm
/// tip (`write::rack`).
pub(super) const SMALLEST_BALL: f64 = 0.5;

/// Triangles of a face the ball is stood on.
const SAMPLES: usize = 24;

/// The share of the face's samples the ball must fit at.
const LEAST_SHARE: f64 = 0.5;

/// Of `faces` (0-based groups of the mesh), those a ball of radius `r` fits at under
/// [`LEAST_SHARE`] of their samples. Empty when the mesh gives no distance test.
pub(super) fn untouchable(mesh: &RawMesh, faces: &BTreeSet<usize>, r: f64) -> BTreeSet<usize> {
    let Ok(trimesh) = TriMesh::new(mesh.vertices.clone(), mesh.triangles.clone()) else {
        return BTreeSet::new();
    };
    // Per vertex the face it belongs to, or usize::MAX where faces meet.
    let mut face_of = vec![None::<usize>; mesh.vertices.len()];
    for (t, &g) in mesh.tri_group.iter().enumerate() {
        for i in mesh.triangles[t] {
            let v = &mut face_of[i as usize];
            *v = match *v {
                None => Some(g as usize),
                Some(h) if h == g as usize => Some(h),
                Some(_) => Some(usize::MAX),
            };
        }
    }
    // The triangles of each face, those off its boundary where it has some.
    let own = mesh.triangles_of_groups();
    let inner = |f: usize, tris: &[u32]| -> Vec<u32> {
        tris.iter()
            .copied()
            .filter(|&t| {
                mesh.triangles[t as usize]
                    .iter()
                    .all(|&i| face_of[i as usize] == Some(f))
            })
            .collect()
    };
    faces
        .iter()
        .copied()
        .filter(|&f| {
            let all = own.get(f).map_or(&[][..], Vec::as_slice);
            let off_edges = inner(f, all);
            let tris = if off_edges.is_empty() {
                all
            } else {
                &off_edges[..]
            };
            let tighter = match mesh.exact.get(f) {
                Some(
                    Surface::Cylinder {
                        radius,
                        convex: false,
                        ..
                    }
                    | Surface::Sphere {
                        radius,
                        convex: false,
                        ..
                    },
                ) => *radius < r,
                _ => false,
            };
            !tris.is_empty() && (tighter || fit_share(mesh, &trimesh, tris, r) < LEAST_SHARE)
        })
        .collect()
}

/// The share of up to [`SAMPLES`] of `tris` (spread evenly by index) at whose centroid
/// the ball of radius `r` stands clear of the mesh.
fn fit_share(mesh: &RawMesh, trimesh: &TriMesh, tris: &[u32], r: f64) -> f64 {
    let step = tris.len().div_ceil(SAMPLES).max(1);
    let picked: Vec<u32> = tris.iter().copied().step_by(step).collect();
    let fits = picked
        .iter()
        .filter(|&&t| {
            let [a, b, c] = mesh.triangles[t as usize].map(|i| mesh.vertices[i as usize]);
            let Some(n) = (b - a).cross(&(c - a)).try_normalize(1e-12) else {
                return false;
            };
            let centre: P3 = P3::from((a.coords + b.coords + c.coords) / 3.0) + n * r;
            let d = trimesh.distance_to_point(
                &Isometry::identity(),
                &Point::from(centre.coords),
                false,
            );
            d >= crate::access::pose::TIP_CLEARANCE * r
        })
        .count();
    fits as f64 / picked.len().max(1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::V3;

    /// An L of two 10 mm walls meeting in a concave quarter-round fillet of radius
    /// `rho`, swept 10 mm along z: group 0 the floor, 1 the wall, 2 the fillet.
    fn corner(rho: f64) -> RawMesh {
        let mut m = RawMesh::default();
        let quad = |m: &mut RawMesh, p: [P3; 4], g: u32| {
            let base = m.vertices.len() as u32;
            m.vertices.extend(p);
            m.triangles.push([base, base + 1, base + 2]);
            m.triangles.push([base, base + 2, base + 3]);
            m.tri_group.extend([g, g]);
        };
        // Floor y = 0 from x = rho to 10, facing +y; wall x = 0 from y = rho to 10,
        // facing +x; the fillet about the axis (rho, rho) between them.
        quad(
            &mut m,
            [
                P3::new(rho, 0.0, 0.0),
                P3::new(rho, 0.0, 10.0),
                P3::new(10.0, 0.0, 10.0),
                P3::new(10.0, 0.0, 0.0),
            ],
            0,
        );
        quad(
            &mut m,
            [
                P3::new(0.0, rho, 0.0),
                P3::new(0.0, 10.0, 0.0),
                P3::new(0.0, 10.0, 10.0),
                P3::new(0.0, rho, 10.0),
            ],
            1,
        );
        let n = 8;
        for i in 0..n {
            let arc = |k: usize| {
                let a = std::f64::consts::PI + std::f64::consts::FRAC_PI_2 * k as f64 / n as f64;
                (rho + rho * a.cos(), rho + rho * a.sin())
            };
            let ((x0, y0), (x1, y1)) = (arc(i), arc(i + 1));
            quad(
                &mut m,
                [
                    P3::new(x0, y0, 0.0),
                    P3::new(x0, y0, 10.0),
                    P3::new(x1, y1, 10.0),
                    P3::new(x1, y1, 0.0),
                ],
                2,
            );
        }
        m.exact = vec![
            Surface::Plane {
                origin: P3::origin(),
                normal: V3::y(),
            };
            3
        ];
        m
    }

    #[test]
    fn a_fillet_tighter_than_the_ball_is_untouchable_and_its_walls_are_not() {
        let all: BTreeSet<usize> = [0, 1, 2].into();
        // R0.3 against a Ø1 ball: the ball stands on the walls, not the fillet; the
        // mesh alone tells (the fillet is no exact cylinder here).
        assert_eq!(untouchable(&corner(0.3), &all, 0.5), [2].into());
        // R2 takes the ball.
        assert!(untouchable(&corner(2.0), &all, 0.5).is_empty());
        // R0.43 as an exact concave cylinder: tighter than the ball by its radius.
        let mut exact = corner(0.43);
        exact.exact[2] = Surface::Cylinder {
            origin: P3::new(0.43, 0.43, 0.0),
            axis: V3::z(),
            radius: 0.43,
            convex: false,
        };
        assert_eq!(untouchable(&exact, &all, 0.5), [2].into());
    }
}
