//! Measuring points of every example and of the NIST parts: on their face's exact
//! surface, inside the face, with a normal pointing out of the solid.

use crate::common;

use inspc::geometry::{FaceId, PartGeometry};
use inspc::source::FsWorld;
use std::path::PathBuf;

/// Checks every fpoint of a geometry; returns one line per problem.
pub fn fpoint_problems(
    g: &PartGeometry,
    points: &[inspc::sample::Fpoint],
    step: f64,
) -> Vec<String> {
    let mut out = Vec::new();
    for (i, p) in points.iter().enumerate() {
        let face = &g.faces[p.face.0];
        if let Some(d) = face.surface.distance(&p.position) {
            if d > 1e-6 {
                out.push(format!("p{i} on {}: {d} mm off its surface", face.name));
            }
        }
        if (p.normal.norm() - 1.0).abs() > 1e-9 {
            out.push(format!("p{i} on {}: normal not unit", face.name));
        }
        if !g.face_covers(FaceId(p.face.0), &p.position, &p.normal, 1.0) {
            out.push(format!("p{i} on {}: outside its face", face.name));
        }
        let outside = g.winding_number(&(p.position + p.normal * step));
        let inside = g.winding_number(&(p.position - p.normal * step));
        if outside > 0.5 || inside < 0.5 {
            out.push(format!("p{i} on {}: normal does not point out of the solid (winding {outside:.3} out, {inside:.3} in)", face.name));
        }
    }
    out
}

fn check_spec(path: &str, step: f64) -> usize {
    let (checked, parts, graphs) = inspc::measurement_graphs(&FsWorld, &[PathBuf::from(path)]);
    assert!(
        !checked.has_errors(),
        "{path}: {:?}",
        checked
            .diagnostics
            .iter()
            .map(|d| d.message())
            .collect::<Vec<_>>()
    );
    assert!(!graphs.is_empty(), "{path}: no graph");
    let mut n = 0;
    for gr in &graphs {
        let g = &parts[gr.part].as_ref().expect("geometry").geometry;
        let problems = fpoint_problems(g, &gr.graph.fpoints, step);
        assert!(problems.is_empty(), "{path}:\n{}", problems.join("\n"));
        n += gr.graph.fpoints.len();
    }
    n
}

#[test]
fn every_example_fpoint_is_on_its_face_with_an_outward_normal() {
    let mut specs: Vec<PathBuf> = std::fs::read_dir("examples")
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "insp"))
        .collect();
    specs.sort();
    assert!(specs.len() >= 7);
    for s in specs {
        let n = check_spec(s.to_str().unwrap(), 0.2);
        assert!(n >= 4, "{}: only {n} fpoints", s.display());
    }
}

#[test]
fn nist_fpoints_are_on_their_faces_with_outward_normals() {
    common::require_shared_parts();
    for spec in ["tests/real/nist_ctc_01.insp", "tests/real/nist_ftc_08.insp"] {
        assert!(check_spec(spec, 0.5) > 100, "{spec}");
    }
}
