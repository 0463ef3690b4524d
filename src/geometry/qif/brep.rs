//! From a QIF document's product geometry and topology to the B-rep the STEP reader
//! builds: faces of the solid bodies in shell order with their exact surfaces, edges with
//! their curves, all in millimetres.
//!
//! QIF gives a face no sense flag, and its loops do not say which side the material is
//! on: the senses come from the topology in [`super::read`] (the module's decision).

use super::curves::curve_core;
use super::doc::{core, malformed, Doc};
use super::surfaces::analytic_surface;
use super::xml::Node;
use super::QifError;
use crate::geometry::step::brep::{Bound, Brep, Edge, Face};
use crate::geometry::step::curve::Curve;
use crate::geometry::step::geom::Surf;
use crate::geometry::P3;
use std::collections::{HashMap, HashSet};
use std::f64::consts::TAU;

/// A surface element's analytic surface (`Plane23`, …), or `None` for the kinds
/// `surfaces.rs` reads.
fn surface(d: &Doc, n: &Node) -> Result<Option<Surf>, QifError> {
    match n.name.as_str() {
        "Plane23" | "Cylinder23" | "Cone23" | "Sphere23" | "Torus23" => {
            analytic_surface(d, core(n)?).map(Some)
        }
        "Nurbs23" | "Spline23" | "Extrude23" | "Revolution23" | "Ruled23" | "Offset23" => Ok(None),
        _ => Err(QifError::Unsupported {
            id: n.id(),
            line: n.line,
            what: format!("surface {}", n.name),
        }),
    }
}

/// Reads the B-rep of the solid bodies (or, when there is none, the visible sheet
/// bodies) of a document.
pub fn read(d: &Doc, root: &Node) -> Result<Brep, QifError> {
    let topo = root.at(&["Product", "TopologySet"]);
    let bodies: Vec<&Node> = topo
        .and_then(|t| t.child("BodySet"))
        .map(|b| b.all("Body").collect())
        .unwrap_or_default();
    let visible = |b: &&&Node| b.attr("hidden") != Some("true");
    let solids: Vec<&Node> = bodies
        .iter()
        .filter(visible)
        .filter(|b| b.attr("form") == Some("SOLID"))
        .copied()
        .collect();
    let sheets: Vec<&Node> = bodies
        .iter()
        .filter(visible)
        .filter(|b| b.attr("form") != Some("SOLID"))
        .copied()
        .collect();
    let body_faces = |list: &[&Node]| -> Result<Vec<u64>, QifError> {
        let mut out = Vec::new();
        let mut seen = HashSet::new();
        for b in list {
            let shells = Doc::id_list(b, "ShellIds");
            let mut ids = Vec::new();
            for s in &shells {
                ids.extend(Doc::id_list(d.get(*s, b)?, "FaceIds"));
            }
            if shells.is_empty() {
                ids = Doc::id_list(b, "FaceIds");
            }
            out.extend(ids.into_iter().filter(|id| seen.insert(*id)));
        }
        Ok(out)
    };
    let mut face_ids = body_faces(&solids)?;
    let solid_faces = face_ids.len();
    if solid_faces == 0 {
        face_ids = body_faces(&sheets)?;
    }
    if face_ids.is_empty() {
        return Err(QifError::NoSolid);
    }

    let mut edges: Vec<Edge> = Vec::new();
    let mut edge_index: HashMap<u64, usize> = HashMap::new();
    let mut surfaces: HashMap<u64, Surf> = HashMap::new();
    let mut faces = Vec::new();
    for fid in face_ids {
        let f = d.get(fid, root)?;
        if f.name != "Face" {
            return Err(if f.name == "FaceMesh" {
                QifError::Unsupported {
                    id: Some(fid),
                    line: f.line,
                    what: "face given as a mesh (FaceMesh)".into(),
                }
            } else {
                malformed(f, "a body lists it as a face")
            });
        }
        let sid = d.ref_id(f, "Surface")?;
        let mut bounds = Vec::new();
        for lid in Doc::id_list(f, "LoopIds") {
            let l = d.get(lid, f)?;
            let mut list = Vec::new();
            if let Some(ces) = l.child("CoEdges") {
                for ce in ces.all("CoEdge") {
                    let eo = ce
                        .child("EdgeOriented")
                        .ok_or_else(|| malformed(l, "a co-edge has no <EdgeOriented>"))?;
                    let eid: u64 = eo
                        .text_at(&["Id"])
                        .and_then(|t| t.trim().parse().ok())
                        .ok_or_else(|| malformed(l, "a co-edge names no edge"))?;
                    let idx = match edge_index.get(&eid) {
                        Some(i) => *i,
                        None => {
                            let e = edge(d, d.get(eid, l)?)?;
                            edges.push(e);
                            edge_index.insert(eid, edges.len() - 1);
                            edges.len() - 1
                        }
                    };
                    list.push((idx, eo.attr("turned") != Some("true")));
                }
            }
            bounds.push(if list.is_empty() {
                Bound::Vertex
            } else {
                Bound::Edges(list)
            });
        }
        let surf = match surfaces.get(&sid) {
            Some(s) => s.clone(),
            None => {
                let n = d.get(sid, f)?;
                let s = match surface(d, n)? {
                    Some(s) => s,
                    None => super::surfaces::read(d, n, &bound_vertices(&bounds, &edges))?,
                };
                surfaces.insert(sid, s.clone());
                s
            }
        };
        faces.push(Face {
            id: fid,
            surface: surf,
            same_sense: true,
            bounds,
        });
    }
    Ok(Brep {
        sheet_faces: faces.len() - solid_faces.min(faces.len()),
        faces,
        edges,
        unit_mm: d.unit,
        unit_name: String::new(),
    })
}

/// Points of a face's bounds (each edge's vertices and three points along it): where the
/// file's topology says its surface passes.
fn bound_vertices(bounds: &[Bound], edges: &[Edge]) -> Vec<P3> {
    bounds
        .iter()
        .flat_map(Bound::edges)
        .flat_map(|(e, _)| edge_samples(&edges[*e]))
        .collect()
}

/// An edge's start and three points along its curve between its vertices (once round
/// for a closed one).
fn edge_samples(e: &Edge) -> Vec<P3> {
    let c = &e.curve;
    let mut out = vec![e.start];
    let (t0, t1) = match c {
        Curve::Line(..) => {
            out.push(nalgebra::center(&e.start, &e.end));
            return out;
        }
        Curve::Polyline(p) => {
            out.extend(p.get(p.len() / 2));
            return out;
        }
        Curve::BSpline(b) if (e.start - e.end).norm() < 1e-9 => b.knots.range(),
        _ if (e.start - e.end).norm() < 1e-9 => {
            let t = c.param(&e.start);
            (t, t + TAU)
        }
        Curve::Circle(..) | Curve::Ellipse(..) => {
            // Round the way the edge runs along the curve.
            let (a, b) = (c.param(&e.start), c.param(&e.end));
            if e.same_sense {
                (a, a + (b - a).rem_euclid(TAU))
            } else {
                (a, a - (a - b).rem_euclid(TAU))
            }
        }
        _ => (c.param(&e.start), c.param(&e.end)),
    };
    out.extend((1..4).map(|k| c.eval(t0 + (t1 - t0) * k as f64 / 4.0)));
    out
}

/// An edge: its vertices, its curve, and whether it runs along the curve (the vertex
/// it begins at is the curve's start).
fn edge(d: &Doc, e: &Node) -> Result<Edge, QifError> {
    if e.name != "Edge" {
        return Err(malformed(e, "a co-edge names it as an edge"));
    }
    let vertex = |name: &str| -> Result<P3, QifError> {
        let v = d.get(d.ref_id(e, name)?, e)?;
        let p = d.get(d.ref_id(v, "Point")?, v)?;
        d.point(p, "XYZ")
    };
    let (start, end) = (vertex("VertexBeg")?, vertex("VertexEnd")?);
    let cid = d.ref_id(e, "Curve")?;
    let cached = d.curves.borrow().get(&cid).cloned();
    let (curve, curve_start) = match cached {
        Some(read) => read,
        None => {
            let c = d.get(cid, e)?;
            let read = curve_core(d, core(c)?, c)?;
            d.curves.borrow_mut().insert(cid, read.clone());
            read
        }
    };
    if let Curve::Ellipse(..) | Curve::Parabola(..) | Curve::Hyperbola(..) = curve {
        for p in [start, end] {
            let off = (curve.eval(curve.param(&p)) - p).norm();
            if off > 1e-3 {
                return Err(malformed(
                    e,
                    &format!("its vertex lies {off:.3} mm off its conic arc (semi-axes read as half of <A> and <B>)"),
                ));
            }
        }
    }
    let same_sense = match curve_start {
        Some(s) => (s - start).norm() <= (s - end).norm() + 1e-9,
        None => true,
    };
    Ok(Edge {
        id: e.id().unwrap_or(0),
        start,
        end,
        curve,
        same_sense,
    })
}
