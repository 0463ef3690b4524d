//! QIF 3 MBD parts: the B-rep of the document's solid body with each face's exact
//! surface, meshed by the STEP reader's tessellator, and the document's PMI (datums,
//! reference frames, characteristics, sizes) linked to the faces.
//!
//! `xml.rs` reads the document into an element tree, `brep.rs` the faces, edges and
//! surfaces, `pmi.rs` the features and characteristics, `error.rs` why a document could
//! not be read. [`read`] is the entry point:
//! bytes in, a [`CadPart`] out whose groups are the faces (`face_<n>`, numbered from 1 in
//! the body's shell order).
//!
//! Unknown elements are skipped. A document of another QIF major version, a face that
//! cannot be meshed, a reference to a missing id: each is an error naming what is wrong,
//! never a silently missing face.
//!
//! **Decision: one B-rep, senses from the topology.** QIF 3 (`part p { mesh "x.qif" }`)
//! is read into the STEP reader's `Brep` and meshed by the same tessellator, so both
//! formats make the same faces (the suite matches every QIF face of the three NIST QIF
//! files to its STEP face: type, area, centroid, sense). quick-xml reads the document
//! into a small element tree. Faces are those of the visible `SOLID` bodies in shell
//! order (sheet bodies only when there is no solid; hidden bodies are construction
//! geometry: FTC 08's QIF keeps the STEP file's stray sheet face there). Forced by the
//! files:
//! - QIF gives a face no sense flag and its loops run counter-clockwise in the
//!   surface's parameters whatever side the material is on, so the senses come from the
//!   topology: each edge between two faces must be walked in opposite directions once
//!   both faces are oriented, which fixes every face of a shell from one, and a shell
//!   whose volume comes out negative is turned; a conflict is a `qif_face` error.
//! - `Product/Header/ScaleCoefficient` draws the geometry at a scale (FTC 08's QIF is
//!   at 2:1); the part is the geometry divided by it.
//! - PMI values are in `PMILinearUnit` where the file names one (FTC 06: inch values in
//!   a millimetre model), else through each value's `linearUnit`.
//!
//! Characteristics follow characteristic nominal → feature nominals →
//! `EntityInternalIds` (faces, or edges as their curved faces); datums follow their
//! feature nominals or their targets' feature nominals; composite frames' second
//! segments become lower segments; the angle of a two-plane feature is the angle
//! between its planes, as STEP files state it. Surfaces: every QIF 3 kind — plane,
//! cylinder, cone, sphere, torus, NURBS, spline (`splines.rs`), extrusion, revolution,
//! ruled, offset (`surfaces.rs`); curves: every kind — segment, circular and conic arc,
//! NURBS, spline, polyline and aggregates of them; meshed faces and binary control
//! points are `qif_unsupported`.

mod brep;
mod curves;
mod doc;
pub(in crate::geometry) mod error;
mod pmi;
mod refs;
mod splines;
mod surfaces;
mod xml;

pub use error::QifError;

use super::errors::MeshError;
use super::step::{self, CadPart, MeshFailure, Resolution};
use super::weld::RawMesh;
use std::collections::HashMap;

/// Millimetres per unit of a `LinearUnit` element: its conversion factor to metres, or
/// a unit known by name.
fn unit_mm(u: &xml::Node) -> Option<f64> {
    if let Some(f) = u.at(&["UnitConversion", "Factor"]) {
        let x: f64 = f.text.trim().parse().ok()?;
        let si = u.text_at(&["SIUnitName"]).map(str::trim).unwrap_or("meter");
        return (x > 0.0 && x.is_finite() && matches!(si, "meter" | "metre")).then_some(x * 1000.0);
    }
    named_unit_mm(u.text_at(&["UnitName"])?.trim())
}

/// Millimetres per unit of a length unit known by name.
fn named_unit_mm(name: &str) -> Option<f64> {
    match name {
        "mm" | "millimeter" | "millimetre" => Some(1.0),
        "cm" | "centimeter" | "centimetre" => Some(10.0),
        "m" | "meter" | "metre" => Some(1000.0),
        "um" | "micrometer" | "micron" => Some(0.001),
        "in" | "inch" => Some(25.4),
        "ft" | "foot" | "feet" => Some(304.8),
        _ => None,
    }
}

/// Reads a QIF document's solid and PMI, and meshes the solid.
pub fn read(bytes: &[u8], res: Resolution) -> Result<CadPart, MeshError> {
    let q = |e| MeshError::Qif(e);
    let root = xml::parse(bytes).map_err(|e| {
        q(QifError::Syntax {
            line: e.line,
            message: e.message,
        })
    })?;
    if root.name != "QIFDocument" {
        return Err(q(QifError::Version(format!(
            "its root element is <{}>, not <QIFDocument>",
            root.name
        ))));
    }
    match root.attr("versionQIF").map(str::trim) {
        Some(v) if v == "3" || v.starts_with("3.") => {}
        Some(v) => {
            return Err(q(QifError::Version(format!(
                "it is a QIF {v} document; inspc reads QIF 3"
            ))))
        }
        None => {
            return Err(q(QifError::Version(
                "it states no QIF version (versionQIF)".into(),
            )))
        }
    }
    let unit = root
        .at(&["FileUnits", "PrimaryUnits", "LinearUnit"])
        .ok_or_else(|| {
            q(QifError::Unit(
                "it states no length unit (FileUnits/PrimaryUnits/LinearUnit)".into(),
            ))
        })?;
    let unit_name = unit.text_at(&["UnitName"]).unwrap_or("").trim().to_string();
    let file_mm = unit_mm(unit).ok_or_else(|| {
        q(QifError::Unit(format!(
            "its length unit `{unit_name}` has no conversion to metres inspc can read"
        )))
    })?;
    // The product's geometry may be drawn at a scale (`<ScaleCoefficient>2`): the part
    // is the geometry divided by it.
    let scale = match root.text_at(&["Product", "Header", "ScaleCoefficient"]) {
        Some(t) => match t.trim().parse::<f64>() {
            Ok(s) if s > 0.0 && s.is_finite() => s,
            _ => {
                return Err(q(QifError::Unit(format!(
                    "its scale coefficient `{}` is not a positive number",
                    t.trim()
                ))))
            }
        },
        None => 1.0,
    };
    // PMI values are in the PMI's own unit where the file names one.
    let value_unit = match root.at(&["FileUnits", "PrimaryUnits", "PMILinearUnit"]) {
        Some(u) => unit_mm(u).ok_or_else(|| {
            q(QifError::Unit(format!(
                "its PMI length unit `{}` has no conversion to metres inspc can read",
                u.text_at(&["UnitName"]).unwrap_or("").trim()
            )))
        })?,
        None => file_mm,
    };
    let doc = doc::Doc {
        ids: xml::index(&root),
        unit: file_mm / scale,
        value_unit,
        samples: std::cell::Cell::new(doc::MAX_SAMPLES),
        curves: Default::default(),
    };
    let mut b = brep::read(&doc, &root).map_err(q)?;
    b.unit_name = unit_name.clone();
    // The PMI links faces and edges, not the mesh: it is read (and a circle of its
    // features found) before the faces are meshed.
    let face_ids: Vec<u64> = b.faces.iter().map(|f| f.id).collect();
    let edge_faces: HashMap<u64, Vec<usize>> = step::edge_faces(&b);
    let pmi = pmi::read(&doc, &root, &face_ids, &edge_faces).map_err(q)?;
    step::check_extent(&b)?;
    let shell = orient(&mut b, res)?;
    let mesh_of = |b: &step::brep::Brep| {
        step::mesh_brep(b, res, crate::model::CadKind::Qif).map_err(|e| match e {
            MeshFailure::Faces(list) => q(QifError::Faces(list)),
            MeshFailure::Mesh(e) => e,
        })
    };
    let mut mesh = mesh_of(&b)?;
    if outward(&mut b, &mesh, &shell) {
        mesh = mesh_of(&b)?;
    }
    Ok(CadPart {
        pmi,
        mesh,
        face_ids,
        unit: (unit_name, file_mm),
        // Sheet bodies are read only when there is no solid: then they are the part.
        sheet_faces: 0,
    })
}

/// Gives each face its sense and bounds in the STEP reader's terms (the face lies left
/// of its bounds seen from outside).
///
/// QIF states no sense: a face's loops run counter-clockwise in its surface's
/// parameters whichever side the material is on (so they are read as-is first), and a
/// face faces out or in as the solid has it. The senses are found from the topology: an
/// edge between two faces is walked in opposite directions by their bounds once both
/// are oriented, so one face's choice fixes its neighbours', across each connected shell.
/// Returns each face's shell, for [`outward`] to turn a shell whose mesh comes out
/// inside out.
fn orient(b: &mut step::brep::Brep, res: Resolution) -> Result<Vec<usize>, MeshError> {
    use step::brep::Bound;
    let edges = step::edges::edge_polylines(b, res).map_err(MeshError::TooLarge)?;
    let natural: Vec<bool> = b
        .faces
        .iter()
        .map(|f| step::tess::bound_sense(f, &edges).unwrap_or(true))
        .collect();
    let mut uses: Vec<Vec<(usize, bool)>> = vec![Vec::new(); b.edges.len()];
    for (i, f) in b.faces.iter().enumerate() {
        for bound in &f.bounds {
            if let Bound::Edges(list) = bound {
                for &(e, fwd) in list {
                    uses[e].push((i, fwd));
                }
            }
        }
    }
    // flip[f]: whether the face's bounds are walked backwards to obey the rule.
    let n = b.faces.len();
    let mut flip: Vec<Option<bool>> = vec![None; n];
    let mut shell = vec![0usize; n];
    let mut shells = 0;
    for seed in 0..n {
        if flip[seed].is_some() {
            continue;
        }
        flip[seed] = Some(false);
        shell[seed] = shells;
        let mut queue = std::collections::VecDeque::from([seed]);
        while let Some(f) = queue.pop_front() {
            let ff = flip[f].unwrap_or(false);
            for bound in &b.faces[f].bounds {
                let Bound::Edges(list) = bound else { continue };
                for &(e, fwd) in list {
                    // Only an edge of two faces (one of them maybe twice, along a seam)
                    // fixes a neighbour's sense; one used more often says nothing, and
                    // is not searched (a file may name an edge in every loop).
                    if uses[e].len() > 3 {
                        continue;
                    }
                    let others: Vec<(usize, bool)> =
                        uses[e].iter().copied().filter(|(g, _)| *g != f).collect();
                    let [(g, gfwd)] = others.as_slice() else {
                        continue;
                    };
                    // Walked as `fwd ^ ff` here; the neighbour must walk it the other way.
                    let want = *gfwd ^ !(fwd ^ ff);
                    match flip[*g] {
                        None => {
                            flip[*g] = Some(want);
                            shell[*g] = shells;
                            queue.push_back(*g);
                        }
                        Some(have) if have != want => {
                            return Err(MeshError::Qif(QifError::Faces(vec![(
                                g + 1,
                                b.faces[*g].id,
                                format!(
                                    "its bounds and face_{}'s walk their shared edge {} the same way whichever way the faces are turned: the shell is not orientable",
                                    f + 1,
                                    b.edges[e].id
                                ),
                            )])));
                        }
                        Some(_) => {}
                    }
                }
            }
        }
        shells += 1;
    }
    for (i, face) in b.faces.iter_mut().enumerate() {
        face.same_sense = natural[i];
        if flip[i] == Some(true) {
            turn(face);
        }
    }
    Ok(shell)
}

/// A face turned over: the other sense, its bounds walked backwards.
fn turn(face: &mut step::brep::Face) {
    face.same_sense = !face.same_sense;
    for bound in &mut face.bounds {
        if let step::brep::Bound::Edges(list) = bound {
            list.reverse();
            for (_, fwd) in list.iter_mut() {
                *fwd = !*fwd;
            }
        }
    }
}

/// Turns over, in the B-rep, every shell whose mesh encloses a negative volume;
/// whether any was turned (then the B-rep is meshed again).
fn outward(b: &mut step::brep::Brep, mesh: &RawMesh, shell: &[usize]) -> bool {
    let shells = shell.iter().max().map_or(0, |m| m + 1);
    let mut volume = vec![0.0; shells];
    for (t, g) in mesh.triangles.iter().zip(&mesh.tri_group) {
        let [a, bb, c] = t.map(|i| mesh.vertices[i as usize].coords);
        volume[shell[*g as usize]] += a.dot(&bb.cross(&c)) / 6.0;
    }
    let mut turned = false;
    for (i, face) in b.faces.iter_mut().enumerate() {
        if volume[shell[i]] < 0.0 {
            turn(face);
            turned = true;
        }
    }
    turned
}
