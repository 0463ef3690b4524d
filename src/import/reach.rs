//! How long a thin stylus an imported part's small holes need: the rack's Ø1 mm tip
//! must reach the bottom of every small hole with the probe's body (the TP20 module,
//! Ø13.2 mm) still clear of the part. A Ø2.5 mm hole 2.4 mm deep in the ceiling of a
//! 17 mm cavity (NIST FTC 10) is out of the 10 mm stylus's reach however short it is;
//! Renishaw's stylus guidance asks for a stylus "long enough to reach all features",
//! the shortest that does (a longer one bends more).
//!
//! The measure is a ray test, as [`crate::geometry::recess_depth`]'s: from the hole's
//! deepest point up its axis out of its open end, the body fits at the first height
//! where eight rays across the axis all run the body's radius (with a margin) without
//! meeting the part.

use crate::geometry::{across, RawMesh, Surface, P3, V3};
use parry3d_f64::math::{Point, Vector};
use parry3d_f64::query::{Ray, RayCast};
use parry3d_f64::shape::TriMesh;

/// Holes narrower than this (mm) are the thin stylus's (the rack's other tips are Ø2
/// and Ø3 mm).
pub(super) const SMALL_HOLE: f64 = 6.0;

/// The probe body's radius and the clearance kept from it (mm): the TP20 module is
/// Ø13.2 mm and the planner keeps a 1 mm motion margin.
const BODY_CLEAR: f64 = 6.6 + 1.0;

/// Heights tried up a hole's axis (mm), and how far (past that, no stylus of the rack
/// reaches anyway).
const STEP: f64 = 1.0;
const MAX_REACH: f64 = 80.0;

/// Directions across the axis whose rays must all run clear.
const RAYS: usize = 8;

/// The longest reach (mm, deepest point of the hole to where the body fits) over the
/// part's small holes: concave cylinders narrower than [`SMALL_HOLE`] whose faces on
/// one axis run all round it (a fillet is a concave cylinder too, a quarter of one).
/// 0 when it has none or the mesh gives no ray test.
pub(super) fn small_hole_reach(mesh: &RawMesh) -> f64 {
    let Ok(trimesh) = TriMesh::new(mesh.vertices.clone(), mesh.triangles.clone()) else {
        return 0.0;
    };
    let own = mesh.triangles_of_groups();
    // The small concave cylinders, the halves of one hole together.
    let mut holes: Vec<(P3, V3, Vec<usize>)> = Vec::new();
    for (k, surface) in mesh.exact.iter().enumerate() {
        let Surface::Cylinder {
            origin,
            axis,
            radius,
            convex: false,
        } = surface
        else {
            continue;
        };
        if 2.0 * radius >= SMALL_HOLE || own[k].is_empty() {
            continue;
        }
        match holes
            .iter_mut()
            .find(|(o, d, _)| same_axis(o, d, origin, axis))
        {
            Some(hole) => hole.2.push(k),
            None => holes.push((*origin, *axis, vec![k])),
        }
    }
    let mut reach: f64 = 0.0;
    for (origin, axis, faces) in &holes {
        let tris: Vec<u32> = faces.iter().flat_map(|&k| own[k].iter().copied()).collect();
        if !all_round(mesh, &tris, origin, axis) {
            continue;
        }
        let Some((lo, hi)) = extent(mesh, &tris, origin, axis) else {
            continue;
        };
        let (a, b) = (origin + axis * lo, origin + axis * hi);
        // Out of either end; a blind hole's bottom end is closed.
        let from_hi = hole_reach(&trimesh, &a, axis, hi - lo);
        let from_lo = hole_reach(&trimesh, &b, &-axis, hi - lo);
        if let Some(r) = [from_hi, from_lo].into_iter().flatten().reduce(f64::min) {
            reach = reach.max(r);
        }
    }
    reach
}

/// Whether the triangles' vertices run all round the axis: every one of 8 sectors of
/// 45° holds one (a hole; a fillet covers a quarter). The sectors are wider than the
/// meshes' angular step (STEP faces are meshed at 0.5 rad at most).
fn all_round(mesh: &RawMesh, tris: &[u32], origin: &P3, axis: &V3) -> bool {
    let (u, v) = across(axis);
    let mut sectors = [false; 8];
    for &t in tris {
        for i in mesh.triangles[t as usize] {
            let d = mesh.vertices[i as usize] - origin;
            let angle = d.dot(&v).atan2(d.dot(&u)).to_degrees().rem_euclid(360.0);
            sectors[((angle / 45.0) as usize).min(7)] = true;
        }
    }
    sectors.iter().all(|&s| s)
}

/// The face's extent along its axis: the least and greatest axial coordinate of its
/// vertices about `origin`.
fn extent(mesh: &RawMesh, tris: &[u32], origin: &P3, axis: &V3) -> Option<(f64, f64)> {
    let (lo, hi) = tris
        .iter()
        .flat_map(|&t| mesh.triangles[t as usize])
        .map(|i| (mesh.vertices[i as usize] - origin).dot(axis))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
            (l.min(x), h.max(x))
        });
    (lo <= hi).then_some((lo, hi))
}

/// Whether the line through `b` along `e` is the line through `a` along `d` (within
/// 10 µm and 1e-6 in direction).
fn same_axis(a: &P3, d: &V3, b: &P3, e: &V3) -> bool {
    let off = b - a;
    d.cross(e).norm() < 1e-6 && (off - d * off.dot(d)).norm() < 1e-2
}

/// How far up `dir` from `deep` (the hole's far end on its axis) the body first fits,
/// the hole `length` long; `None` when the end `dir` leaves by is closed (the axis
/// meets the part within the hole's length) or nothing fits within [`MAX_REACH`].
fn hole_reach(mesh: &TriMesh, deep: &P3, dir: &V3, length: f64) -> Option<f64> {
    let start = deep + dir * 1e-3;
    let axial = Ray::new(Point::from(start.coords), Vector::from(*dir));
    if mesh.intersects_local_ray(&axial, length + 0.5) {
        return None;
    }
    let (u, v) = across(dir);
    let clear = |h: f64| {
        let o = deep + dir * h;
        (0..RAYS).all(|k| {
            let a = std::f64::consts::TAU * k as f64 / RAYS as f64;
            let d = u * a.cos() + v * a.sin();
            let ray = Ray::new(Point::from(o.coords), Vector::from(d));
            !mesh.intersects_local_ray(&ray, BODY_CLEAR)
        })
    };
    let mut h = length.max(STEP);
    while h <= MAX_REACH {
        if clear(h) {
            return Some(h);
        }
        h += STEP;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The wall of a cylinder about z of radius `r` from `z0` to `z1`, as triangles
    /// appended to `m` in group `group`; with `floor`, a disc closes it at `z0`.
    fn wall(m: &mut RawMesh, r: f64, (z0, z1): (f64, f64), group: u32, floor: bool) {
        let n = 32u32;
        let base = m.vertices.len() as u32;
        for i in 0..n {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            m.vertices.push(P3::new(r * a.cos(), r * a.sin(), z0));
            m.vertices.push(P3::new(r * a.cos(), r * a.sin(), z1));
        }
        for i in 0..n {
            let (a, b) = (base + 2 * i, base + 2 * ((i + 1) % n));
            m.triangles.push([a, b, b + 1]);
            m.triangles.push([a, b + 1, a + 1]);
            m.tri_group.extend([group, group]);
        }
        if floor {
            let c = m.vertices.len() as u32;
            m.vertices.push(P3::new(0.0, 0.0, z0));
            for i in 0..n {
                m.triangles
                    .push([c, base + 2 * ((i + 1) % n), base + 2 * i]);
                m.tri_group.push(group + 1);
            }
        }
    }

    /// A Ø2.5 mm hole 3 mm deep in the floor of a Ø12 mm pocket 17 mm deep (NIST FTC
    /// 10's holes in its cavity's ceiling): the body fits only above the pocket's rim,
    /// 20 mm over the hole's bottom.
    #[test]
    fn a_hole_in_a_narrow_pocket_needs_the_pocket_s_depth() {
        let mut m = RawMesh::default();
        wall(&mut m, 1.25, (0.0, 3.0), 0, true);
        wall(&mut m, 6.0, (3.0, 20.0), 2, false);
        m.exact = vec![
            Surface::Cylinder {
                origin: P3::origin(),
                axis: V3::z(),
                radius: 1.25,
                convex: false,
            },
            Surface::Plane {
                origin: P3::origin(),
                normal: V3::z(),
            },
            Surface::Cylinder {
                origin: P3::origin(),
                axis: V3::z(),
                radius: 6.0,
                convex: false,
            },
        ];
        let reach = small_hole_reach(&m);
        assert!((20.0..=21.5).contains(&reach), "reach {reach}");
        // In a wide pocket the body stands just above the hole.
        let mut wide = m.clone();
        for v in &mut wide.vertices[64 + 1..] {
            let (x, y) = (v.x * 3.0, v.y * 3.0);
            (v.x, v.y) = (x, y);
        }
        let reach = small_hole_reach(&wide);
        assert!((3.0..=4.0).contains(&reach), "reach {reach}");
    }
}
