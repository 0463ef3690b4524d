//! STEP parts (AP203, AP214, AP242): the B-rep of the file's solid, each face with its
//! exact surface, tessellated to a stated chord tolerance.
//!
//! `p21.rs` reads the exchange file's instances, `brep.rs` the faces, edges and units,
//! `geom.rs` evaluates the curves and surfaces, `tess.rs` meshes them, `pmi.rs` reads the
//! semantic PMI, `error.rs` says why a file could not be read. [`read`] is the entry
//! point: bytes in, a [`CadPart`] out whose mesh's groups are the faces (`face_<n>`,
//! numbered from 1 in shell order, as the reference meshes of `../shared/parts/` name
//! them) with their exact surfaces beside.
//!
//! **Architecture Invariant:** a face that cannot be meshed is an error naming its
//! instance number, never a silently missing face: a hole in the mesh would let the
//! accessibility analysis see through the part.
//!
//! **Architecture Invariant:** a file costs in proportion to its size, whatever it
//! holds: references are followed once each on a trail (`refs.rs`; a circle is
//! `step_cycle`), nesting and counts are checked before they size anything, and the
//! mesh stops at 2,000,000 triangles (`mesh_too_large`). The QIF reader keeps the same.
//!
//! **Decision: our own reader and tessellator, with spade for the triangulation.** The
//! candidate stack (truck-stepio + truck-meshalgo) rejects the empty lists `()` most
//! AP242 files hold (ruststep#256), fails on some faces and panics on small spheres;
//! patching a fork of three crates costs more than the subset we need. `p21.rs` parses
//! any Part 21 file (simple and complex instances, every parameter kind). `brep.rs`
//! reads solids (`MANIFOLD_SOLID_BREP`, `BREP_WITH_VOIDS`), then sheet bodies, in file
//! order, each shell's faces in list order (the NIST reference meshes number faces this
//! way, except CTC 02's, which follow OpenCASCADE's order), with lengths and angles
//! through the units of the representation that holds the solid (FTC 08 is in inches,
//! CTC 01's cones in degrees); the spec's `units` do not apply to a STEP file, which
//! states its own. Sheet bodies beside a solid are construction geometry (FTC 08's QIF
//! keeps the same face in a hidden body): they keep their numbers after the solid's
//! faces, so PMI links to them are recognised and reported, but they are not meshed —
//! no probe touches them and no move avoids them. Sheet bodies alone are the part.
//! Surfaces: plane, cylinder, cone, sphere, torus (also degenerate), B-spline
//! (rational, closed; knots given or implied), linear extrusion, revolution, offset
//! (`swept.rs`; read analytic where they are one, `canon.rs`), rectangular trimmed;
//! curves: line, circle, ellipse, parabola, hyperbola, B-spline, polyline, composite
//! curves of trimmed or bounded segments and offset curves (`composite.rs`, read by
//! `compound.rs`), and the trimmed, surface and seam wrappers. Edges are cut once each
//! (`edges.rs`); a face whose triangulation fails falls back to a coarser one that keeps
//! the mesh closed (`tess.rs`, `fallback.rs`). Resolution ([`RESOLUTION`]): 0.1 mm chord
//! and 0.5 rad, the reference meshes' own.

pub(super) mod brep;
pub(super) mod canon;
pub(super) mod composite;
mod compound;
pub(super) mod curve;
pub(super) mod edges;
pub(in crate::geometry) mod error;
mod fallback;
pub(super) mod geom;
mod p21;
pub mod pmi;
mod refs;
pub(super) mod swept;
pub(super) mod tess;

/// The curve type, for the files of this folder that `curve.rs` imports.
pub(crate) use curve::Curve;
pub use edges::Resolution;
pub use error::StepError;
pub(crate) use p21::Name;

use super::weld::{weld, RawMesh};
use super::{Surface, P3, V3};
use crate::geometry::errors::MeshError;
use std::collections::{BTreeSet, HashMap};

/// The resolution parts are meshed at: the reference meshes' (OpenCASCADE, linear
/// deflection [`crate::model::DEFAULT_CHORD_MM`], angular 0.5 rad), so that a STEP part
/// plans as its mesh did.
pub const RESOLUTION: Resolution = Resolution {
    chord_mm: crate::model::DEFAULT_CHORD_MM,
    angle_rad: 0.5,
};

/// A CAD part (STEP or QIF) read and meshed.
#[derive(Debug, Clone)]
pub struct CadPart {
    /// The mesh, one group per face.
    pub mesh: RawMesh,
    /// Each face's instance number (STEP) or id (QIF).
    pub face_ids: Vec<u64>,
    /// The file's length unit as named, and its size in millimetres.
    pub unit: (String, f64),
    /// Faces of sheet (open-shell) bodies beside a solid: construction geometry, last
    /// in `face_ids` and left out of the mesh (no material a probe could touch or hit).
    /// 0 when the file has sheet bodies only: those are the part.
    pub sheet_faces: usize,
    /// The semantic PMI, linked to the faces' 0-based indices.
    pub pmi: pmi::Pmi,
}

impl CadPart {
    /// The faces of the part: those of `face_ids` before the sheet faces left out.
    pub fn solid_faces(&self) -> usize {
        self.face_ids.len() - self.sheet_faces
    }
}

/// Reads a STEP file's solid and meshes it.
pub fn read(bytes: &[u8], res: Resolution) -> Result<CadPart, MeshError> {
    let file = p21::parse(bytes).map_err(|e| {
        MeshError::Step(StepError::Syntax {
            line: e.line,
            message: e.message,
        })
    })?;
    let mut b = brep::read(&file).map_err(MeshError::Step)?;
    check_extent(&b)?;
    // The PMI may name sheet faces: it is read against every face, the mesh made of the
    // solid's.
    let face_ids: Vec<u64> = b.faces.iter().map(|f| f.id).collect();
    let pmi_edges = edge_faces(&b);
    let sheet_faces = if b.sheet_faces < b.faces.len() {
        b.sheet_faces
    } else {
        0
    };
    // The PMI links faces and edges, not the mesh: it is read (and a circle of its
    // references found) before the faces are meshed.
    let mut pmi = pmi::read(&file, &face_ids, &pmi_edges, b.unit_mm).map_err(MeshError::Step)?;
    b.faces.truncate(b.faces.len() - sheet_faces);
    let mesh = mesh_brep(&b, res, crate::model::CadKind::Step).map_err(|e| match e {
        MeshFailure::Faces(list) => MeshError::Step(StepError::Faces(list)),
        MeshFailure::Mesh(e) => e,
    })?;
    locate_targets(&mut pmi, &mesh);
    Ok(CadPart {
        pmi,
        mesh,
        face_ids,
        unit: (b.unit_name, b.unit_mm),
        sheet_faces,
    })
}

/// Refuses a B-rep larger than any CMM measures ([`crate::model::MAX_LENGTH_MM`], the
/// bound the spec's own lengths have) before anything is meshed: meshing works to an
/// absolute chord, so its cost grows with the part's size, and a part 100 km across is a
/// file whose length unit is wrong (a prefix off by 10⁵), not a part to inspect.
pub(super) fn check_extent(b: &brep::Brep) -> Result<(), MeshError> {
    let span_mm = extent(b);
    if span_mm > crate::model::MAX_LENGTH_MM {
        return Err(MeshError::Extent {
            span_mm,
            unit: b.unit_name.clone(),
        });
    }
    Ok(())
}

/// The diagonal of a box holding every edge of the B-rep (its vertices, a circle's or
/// ellipse's whole round, a B-spline's control points, a polyline's points) and every
/// sphere or torus a face lies on (mm); infinite when a coordinate is not finite, 0 for
/// a B-rep without edges.
fn extent(b: &brep::Brep) -> f64 {
    let (mut lo, mut hi) = (
        P3::from(V3::repeat(f64::INFINITY)),
        P3::from(V3::repeat(f64::NEG_INFINITY)),
    );
    let mut add = |p: &P3, r: f64| {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k] - r);
            hi[k] = hi[k].max(p[k] + r);
        }
    };
    for e in &b.edges {
        add(&e.start, 0.0);
        add(&e.end, 0.0);
        match &e.curve {
            curve::Curve::Circle(f, r) => add(&f.o, r.abs()),
            curve::Curve::Ellipse(f, a, c) => add(&f.o, a.abs().max(c.abs())),
            curve::Curve::BSpline(c) => c.points.iter().for_each(|p| add(p, 0.0)),
            curve::Curve::Polyline(pts) => pts.iter().for_each(|p| add(p, 0.0)),
            c @ (curve::Curve::Composite(_) | curve::Curve::Offset(_)) => {
                let (a, z) = c.range();
                (0..=64).for_each(|k| add(&c.eval(a + (z - a) * k as f64 / 64.0), 0.0));
            }
            curve::Curve::Line(..) | curve::Curve::Parabola(..) | curve::Curve::Hyperbola(..) => {}
        }
    }
    for f in &b.faces {
        match &f.surface {
            geom::Surf::Sphere(fr, r) => add(&fr.o, r.abs()),
            geom::Surf::Torus(fr, big, small) => add(&fr.o, big.abs() + small.abs()),
            _ => {}
        }
    }
    let d = hi - lo;
    if d.iter().any(|x| x.is_nan()) {
        return f64::INFINITY;
    }
    // Nothing added (a face without edges): no extent to speak of.
    if d.iter().any(|&x| x < 0.0) {
        return 0.0;
    }
    d.norm()
}

/// Why a B-rep could not be meshed.
pub(super) enum MeshFailure {
    /// Faces that could not be tessellated: (1-based face number, id, why).
    Faces(Vec<(usize, u64, String)>),
    /// The welded mesh is not a mesh.
    Mesh(MeshError),
}

/// Tessellates a B-rep and welds it: one group per face (`face_<n>`), each with its
/// exact surface and its id in the file (of `kind`).
pub(super) fn mesh_brep(
    b: &brep::Brep,
    res: Resolution,
    kind: crate::model::CadKind,
) -> Result<RawMesh, MeshFailure> {
    let (soup, failures) =
        tess::tessellate(b, res).map_err(|e| MeshFailure::Mesh(MeshError::TooLarge(e)))?;
    if !failures.is_empty() {
        return Err(MeshFailure::Faces(
            failures
                .into_iter()
                .map(|f| (f.index + 1, f.id, f.reason))
                .collect(),
        ));
    }
    let groups: Vec<String> = (1..=b.faces.len()).map(|n| format!("face_{n}")).collect();
    let mut mesh = weld(soup.positions, soup.triangles, soup.tri_face, groups, 1.0)
        .map_err(MeshFailure::Mesh)?;
    mesh.exact = b.faces.iter().map(exact_surface).collect();
    mesh.cad = Some(crate::geometry::CadFaces {
        kind,
        ids: b.faces.iter().map(|f| f.id).collect(),
    });
    Ok(mesh)
}

/// Each edge's faces: the curved ones where it bounds any, else all.
pub(super) fn edge_faces(b: &brep::Brep) -> HashMap<u64, Vec<usize>> {
    let mut all: HashMap<u64, Vec<usize>> = HashMap::new();
    for (i, f) in b.faces.iter().enumerate() {
        for bound in &f.bounds {
            if let brep::Bound::Edges(edges) = bound {
                for (e, _) in edges {
                    let faces = all.entry(b.edges[*e].id).or_default();
                    if !faces.contains(&i) {
                        faces.push(i);
                    }
                }
            }
        }
    }
    let curved = |i: &usize| !matches!(b.faces[*i].surface, geom::Surf::Plane(_));
    for faces in all.values_mut() {
        if faces.iter().any(curved) {
            faces.retain(curved);
        }
    }
    all
}

/// How far a datum target's point may lie from the face it is found on (mm): the
/// tessellation's chord and then some.
const TARGET_REACH_MM: f64 = 0.5;

/// Datums the file sets up by targets placed on supplemental geometry only: each target
/// point is located on the part, and the faces it lands on become the datum's, marked as
/// located so that callers say so.
fn locate_targets(p: &mut pmi::Pmi, mesh: &RawMesh) {
    let mut notes = Vec::new();
    for d in p.datums.iter_mut().filter(|d| d.faces.is_empty()) {
        let stated: Vec<_> = d.targets.iter().flat_map(|t| &t.points).collect();
        let model: Vec<_> = d
            .targets
            .iter()
            .flat_map(|t| &t.model_unit_points)
            .collect();
        if stated.is_empty() {
            continue;
        }
        let (mut faces, mut missed) = faces_under(&stated, mesh);
        if missed > 0 && !model.is_empty() {
            let (f2, m2) = faces_under(&model, mesh);
            if m2 < missed {
                notes.push(format!(
                    "datum {}: its targets' sizes, in the unit they state, put them off the part; they are read in the model's unit",
                    d.letter
                ));
                (faces, missed) = (f2, m2);
            }
        }
        if faces.is_empty() {
            notes.push(format!(
                "datum {} is set up by targets that lie on no face",
                d.letter
            ));
            continue;
        }
        if missed > 0 {
            notes.push(format!(
                "datum {}: {missed} point(s) of its targets lie on no face",
                d.letter
            ));
        }
        d.faces = faces.into_iter().collect();
        d.located = true;
    }
    p.notes.extend(notes);
}

/// The faces a set of points lies on (each point's nearest face within
/// [`TARGET_REACH_MM`]), and how many points lie on none.
fn faces_under(points: &[&[f64; 3]], mesh: &RawMesh) -> (BTreeSet<usize>, usize) {
    use parry3d_f64::query::PointQuery;
    use parry3d_f64::shape::Triangle;
    let mut faces = BTreeSet::new();
    let mut missed = 0;
    for pt in points {
        let q = P3::new(pt[0], pt[1], pt[2]);
        let best = mesh
            .triangles
            .iter()
            .zip(&mesh.tri_group)
            .map(|(t, g)| {
                let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
                (Triangle::new(a, b, c).distance_to_local_point(&q, true), *g)
            })
            .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        match best {
            Some((dist, g)) if dist <= TARGET_REACH_MM => {
                faces.insert(g as usize);
            }
            _ => missed += 1,
        }
    }
    (faces, missed)
}

/// The planner's view of a face's surface: planes, cylinders, cones and spheres exactly,
/// with the face's outward sense; tori and B-splines as free-form.
fn exact_surface(face: &brep::Face) -> Surface {
    use geom::Surf;
    let out = face.same_sense;
    match &face.surface {
        Surf::Plane(f) => Surface::Plane {
            origin: f.o,
            normal: if out { f.z } else { -f.z },
        },
        Surf::Cylinder(f, r) => Surface::Cylinder {
            origin: f.o,
            axis: f.z,
            radius: *r,
            convex: out,
        },
        Surf::Cone(f, r, a) => Surface::Cone {
            apex: P3::from(f.o - f.z * (r / a.tan())),
            axis: f.z,
            half_angle: *a,
            convex: out,
        },
        Surf::Sphere(f, r) => Surface::Sphere {
            center: f.o,
            radius: *r,
            convex: out,
        },
        Surf::Torus(..)
        | Surf::BSpline(_)
        | Surf::Extrusion(_)
        | Surf::Revolution(_)
        | Surf::Offset(_)
        | Surf::Ruled(_) => Surface::Freeform,
    }
}
