//! Fixtures made from a mesh (`fixture X { kind mesh, mesh "nest.stl", up +z }`): the mesh
//! read in the part's frame and checked against the part — it must touch the part (its
//! locating faces, which it covers) and must not cut into it.
//!
//! A fixture that cuts into the part is `insp::geometry::fixture_overlaps_part`, one
//! that touches no face `insp::geometry::fixture_misses_part`; its locating faces are
//! those with at least [`MIN_CONTACT_MM2`] (1 mm²) within [`CONTACT_MM`] (0.05 mm) of
//! it. The planner offers that one pose (`plan::poses`).

use super::errors::{self, GeometryError};
use super::{FaceId, PartGeometry, RawMesh, P3};
use crate::diag::Diagnostics;
use crate::model::{Fixture, FixtureId, FixtureKind};
use crate::source::World;
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::TriMesh;
use rayon::prelude::*;

/// How near a part face must come to the fixture to rest on it (mm).
pub(crate) const CONTACT_MM: f64 = 0.05;

/// The least area of a face touching the fixture for it to be a locating face (mm²).
pub(crate) const MIN_CONTACT_MM2: f64 = 1.0;

/// The size of the pieces a face's triangles are cut into to find its contact (mm).
const SAMPLE_MM: f64 = 2.0;

/// How deep the part may sink into the fixture, or the fixture into the part, before
/// they overlap (mm): meshes exported from one assembly meet to about this.
pub(crate) const OVERLAP_MM: f64 = 0.05;

/// A mesh fixture placed with its part.
#[derive(Debug, Clone)]
pub struct FixtureMesh {
    /// The fixture.
    pub fixture: FixtureId,
    /// Vertices (mm, part frame).
    pub vertices: Vec<P3>,
    /// Triangles.
    pub triangles: Vec<[u32; 3]>,
    /// The part's faces it touches: they rest on it and are not inspected in its setup.
    pub locating: Vec<FaceId>,
}

/// Reads mesh fixture `f` and places it with part geometry `g`: `None`, with a
/// diagnostic, when the file cannot be read, when the fixture cuts into the part or
/// when it touches no face of it.
pub fn place_fixture(
    g: &PartGeometry,
    part: &str,
    id: FixtureId,
    f: &Fixture,
    world: &dyn World,
    diags: &mut Diagnostics,
) -> Option<FixtureMesh> {
    let FixtureKind::Mesh {
        path,
        unit_mm,
        span,
        ..
    } = &f.kind
    else {
        return None;
    };
    let raw = super::read_reported(world, path, *unit_mm, super::step::RESOLUTION, *span, diags)?;
    let Ok(fixture_mesh) = TriMesh::new(raw.vertices.clone(), raw.triangles.clone()) else {
        diags.push(GeometryError::MeshCorrupt {
            span: *span,
            path: errors::shown_path(path),
            reason: "its triangles do not make a mesh".into(),
        });
        return None;
    };
    let Ok(part_mesh) = TriMesh::new(g.vertices.clone(), g.triangles.clone()) else {
        return None;
    };
    let sunk = sunk_depth(g, &raw, &fixture_mesh, &part_mesh);
    if sunk > OVERLAP_MM {
        diags.push(GeometryError::FixtureOverlapsPart {
            span: *span,
            fixture: f.name.clone(),
            part: part.into(),
            depth: crate::model::fmt_num((sunk * 1e3).round() / 1e3),
        });
        return None;
    }
    let locating = locating_faces(g, &raw.vertices, &fixture_mesh);
    if locating.is_empty() {
        let gap = g
            .vertices
            .par_iter()
            .map(|p| fixture_mesh.distance_to_local_point(p, false))
            .reduce(|| f64::INFINITY, f64::min);
        diags.push(GeometryError::FixtureMissesPart {
            span: *span,
            fixture: f.name.clone(),
            part: part.into(),
            gap: crate::model::fmt_num((gap * 1e3).round() / 1e3),
        });
        return None;
    }
    Some(FixtureMesh {
        fixture: id,
        vertices: raw.vertices,
        triangles: raw.triangles,
        locating,
    })
}

/// How deep the part and the fixture sink into each other: the deepest vertex of
/// either inside the other solid (0 when none is).
fn sunk_depth(g: &PartGeometry, raw: &RawMesh, fixture_mesh: &TriMesh, part_mesh: &TriMesh) -> f64 {
    // How deep each mesh's vertices lie inside the other solid (0 outside).
    let depth = |points: &[P3], mesh: &TriMesh, inside: &(dyn Fn(&P3) -> bool + Sync)| {
        points
            .par_iter()
            .map(|p| {
                if inside(p) {
                    mesh.distance_to_local_point(p, false)
                } else {
                    0.0
                }
            })
            .reduce(|| 0.0, f64::max)
    };
    let in_fixture = |p: &P3| super::query::winding_number(&raw.vertices, &raw.triangles, p) > 0.5;
    let in_part = |p: &P3| g.winding_number(p) > 0.5;
    depth(&g.vertices, fixture_mesh, &in_fixture).max(depth(&raw.vertices, part_mesh, &in_part))
}

/// The locating faces: those with at least [`MIN_CONTACT_MM2`] of their area within
/// [`CONTACT_MM`] of the fixture (`fixture_vertices`, `fixture_mesh`).
fn locating_faces(
    g: &PartGeometry,
    fixture_vertices: &[P3],
    fixture_mesh: &TriMesh,
) -> Vec<FaceId> {
    let near = bounds(fixture_vertices);
    (0..g.faces.len())
        .into_par_iter()
        .filter(|&k| {
            g.faces[k]
                .triangles
                .iter()
                .map(|&t| contact_area(g, t, fixture_mesh, near))
                .sum::<f64>()
                >= MIN_CONTACT_MM2
        })
        .map(FaceId)
        .collect()
}

/// The area of triangle `t` within [`CONTACT_MM`] of the fixture (`fixture_mesh`,
/// bounded by `(flo, fhi)`): the triangle cut into pieces of about [`SAMPLE_MM`], each
/// piece counted by its centre.
fn contact_area(g: &PartGeometry, t: u32, fixture_mesh: &TriMesh, (flo, fhi): (P3, P3)) -> f64 {
    let near_box =
        |p: &P3| (0..3).all(|i| p[i] >= flo[i] - CONTACT_MM && p[i] <= fhi[i] + CONTACT_MM);
    let [a, b, c] = g.triangles[t as usize].map(|i| g.vertices[i as usize]);
    let (tlo, thi) = bounds(&[a, b, c]);
    if (0..3).any(|i| thi[i] < flo[i] - CONTACT_MM || tlo[i] > fhi[i] + CONTACT_MM) {
        return 0.0;
    }
    let longest = [(b - a).norm(), (c - b).norm(), (a - c).norm()]
        .into_iter()
        .fold(0.0, f64::max);
    let n = ((longest / SAMPLE_MM).ceil() as usize).clamp(1, 64);
    let area = (b - a).cross(&(c - a)).norm() / 2.0 / (n * n) as f64;
    let (u, v) = ((b - a) / n as f64, (c - a) / n as f64);
    let mut touching = 0;
    for i in 0..n {
        for j in 0..n - i {
            // The centres of the piece (i, j) and, inside the strip, its mirror.
            let corner = a + u * i as f64 + v * j as f64;
            let mut centres = vec![corner + (u + v) / 3.0];
            if i + j + 1 < n {
                centres.push(corner + (u + v) * (2.0 / 3.0));
            }
            touching += centres
                .iter()
                .filter(|p| {
                    near_box(p) && fixture_mesh.distance_to_local_point(p, false) <= CONTACT_MM
                })
                .count();
        }
    }
    touching as f64 * area
}

/// The bounding box of points.
fn bounds(points: &[P3]) -> (P3, P3) {
    points.iter().fold(
        (
            P3::from([f64::INFINITY; 3]),
            P3::from([f64::NEG_INFINITY; 3]),
        ),
        |(lo, hi), p| (lo.inf(p), hi.sup(p)),
    )
}
