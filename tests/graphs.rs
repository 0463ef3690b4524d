//! Golden measurement graphs: for every example and both NIST parts, the graph as DOT and
//! every fpoint (face, position, normal) under `tests/graphs/<name>/`. Bless with
//! `INSPC_BLESS=1 cargo test --test graphs`.

mod common;

use inspc::model::fmt_num;
use inspc::source::FsWorld;
use std::fmt::Write;
use std::path::{Path, PathBuf};

fn specs() -> Vec<PathBuf> {
    let mut out = Vec::new();
    for dir in ["examples", "tests/real"] {
        out.extend(
            std::fs::read_dir(dir)
                .unwrap()
                .map(|e| e.unwrap().path())
                .filter(|p| p.extension().is_some_and(|e| e == "insp")),
        );
    }
    out.sort();
    out
}

/// (file name, contents) of the expected outputs of one spec.
fn render(spec: &Path) -> Vec<(&'static str, String)> {
    let (checked, parts, graphs) = inspc::measurement_graphs(&FsWorld, &[spec.to_path_buf()]);
    assert!(
        !checked.has_errors(),
        "{}: {:?}",
        spec.display(),
        checked
            .diagnostics
            .iter()
            .map(|d| d.message())
            .collect::<Vec<_>>()
    );
    let (mut dot, mut points) = (String::new(), String::new());
    let r = |v: f64| fmt_num((v * 1e6).round() / 1e6);
    for gr in &graphs {
        let part = &checked.model.parts[gr.part];
        let g = &parts[gr.part].as_ref().unwrap().geometry;
        dot += &inspc::graph::dot(part, g, &gr.graph, false);
        let _ = writeln!(
            points,
            "# {} · plan {} · sampling {}",
            part.name,
            gr.graph.plan.as_deref().unwrap_or("-"),
            gr.graph.sampling
        );
        for (i, p) in gr.graph.fpoints.iter().enumerate() {
            let (q, n) = (&p.position, &p.normal);
            let _ = writeln!(
                points,
                "p{i}\t{}\t{} {} {}\t{} {} {}",
                g.faces[p.face.0].name,
                r(q.x),
                r(q.y),
                r(q.z),
                r(n.x),
                r(n.y),
                r(n.z)
            );
        }
    }
    vec![("graph.dot", dot), ("fpoints.txt", points)]
}

#[test]
fn golden_graphs() {
    common::require_shared_parts();
    let bless = std::env::var_os("INSPC_BLESS").is_some();
    let specs = specs();
    assert!(
        specs.len() >= 9,
        "expected every example and both NIST parts, found {}",
        specs.len()
    );
    let mut failures = Vec::new();
    for spec in &specs {
        let dir = Path::new("tests/graphs").join(spec.file_stem().unwrap());
        for (name, actual) in render(spec) {
            let path = dir.join(name);
            if bless {
                std::fs::create_dir_all(&dir).unwrap();
                std::fs::write(&path, &actual).unwrap();
                continue;
            }
            match std::fs::read_to_string(&path) {
                Ok(expected) if expected == actual => {}
                Ok(expected) => failures.push(format!(
                    "{}: differs\n{}",
                    path.display(),
                    common::diff(&expected, &actual)
                )),
                Err(_) => failures.push(format!(
                    "{}: no expectation; run `INSPC_BLESS=1 cargo test --test graphs`",
                    path.display()
                )),
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}
