//! Exact checks with parry: whether one component, in one direction, meets the scene;
//! and the refinement of a rasterized cone's boundary with them.

use super::cubemap::{Cell, CubeMap};
use super::probe::{Component, End};
use super::scene::Scene;
use crate::geometry::{P3, V3};
use parry3d_f64::math::Isometry;
use parry3d_f64::na::{Translation3, UnitQuaternion};
use parry3d_f64::shape::{Capsule, Cylinder};

/// Whether `comp`, its axis from `from` along the unit direction `d`, meets the scene:
/// an exact ray for the bare half-line, a capsule or cylinder test otherwise. The ram's
/// infinite end is cut well past the scene.
pub fn component_hits(scene: &Scene, from: &P3, d: &V3, comp: &Component) -> bool {
    if scene.mesh().is_none() {
        return false;
    }
    let b = comp.b.min(comp.a + 4.0 * scene.size + 10.0);
    if comp.radius == 0.0 {
        return scene
            .cast_ray(&(from + d * comp.a), d, b - comp.a)
            .is_some_and(|t| t > 1e-9);
    }
    let id = Isometry::identity();
    let axis = [from + d * comp.a, from + d * b, from + d * b];
    match comp.end {
        End::Round => {
            let cap = Capsule::new(axis[0], axis[1], comp.radius);
            scene.meets_axis((&cap, &id), &axis[0], &axis[1], comp.radius, false)
        }
        End::Flat => {
            let half = (b - comp.a) / 2.0;
            let cyl = Cylinder::new(half, comp.radius);
            let rot = UnitQuaternion::rotation_between(&V3::y(), d).unwrap_or_else(|| {
                UnitQuaternion::from_axis_angle(&V3::x_axis(), std::f64::consts::PI)
            });
            let centre = from + d * (comp.a + half);
            let pos = Isometry::from_parts(Translation3::from(centre.coords), rot);
            scene.meets_axis((&cyl, &pos), &axis[0], &axis[1], comp.radius, true)
        }
    }
}

/// Refines a component's blocked map at its boundary: blocked pixels next to free ones
/// are tested exactly at their centres and freed when clear, and the test spreads to
/// their blocked neighbours, until the free region stops growing; a sparse lattice of
/// blocked pixels seeds the search too. Preferred directions
/// are tested exactly. Afterwards the pixels reached are exact at their centres; the
/// rest stay as the rasterizer left them.
pub fn refine(scene: &Scene, from: &P3, comp: &Component, blocked: &mut CubeMap) {
    let mut queue: Vec<super::Pixel> = Vec::new();
    let mut seen = blocked.empty_like();
    for cell in blocked.not().cells() {
        if let Cell::Pixel(p) = cell {
            for q in blocked.neighbours(p) {
                if blocked.get(Cell::Pixel(q)) && !seen.get(Cell::Pixel(q)) {
                    seen.set(Cell::Pixel(q), true);
                    queue.push(q);
                }
            }
        }
    }
    // Seeds inside blocked regions too, every fourth pixel each way, so free pockets the
    // rasterizer closed completely are found.
    for cell in blocked.cells() {
        if let Cell::Pixel(p) = cell {
            if p.i % 4 == 2 && p.j % 4 == 2 && !seen.get(cell) {
                seen.set(cell, true);
                queue.push(p);
            }
        }
    }
    queue.sort();
    while let Some(p) = queue.pop() {
        let d = blocked.direction(Cell::Pixel(p));
        if component_hits(scene, from, &d, comp) {
            continue;
        }
        blocked.set(Cell::Pixel(p), false);
        let mut next = blocked.neighbours(p);
        next.sort();
        for q in next {
            if blocked.get(Cell::Pixel(q)) && !seen.get(Cell::Pixel(q)) {
                seen.set(Cell::Pixel(q), true);
                queue.push(q);
            }
        }
    }
    for k in 0..blocked.preferred_len() {
        if blocked.get(Cell::Preferred(k)) {
            let d = blocked.preferred(k);
            blocked.set(Cell::Preferred(k), component_hits(scene, from, &d, comp));
        }
    }
}
