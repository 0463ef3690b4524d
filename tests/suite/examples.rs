//! Every example, every stdlib module and the real NIST specs check clean, through
//! geometry and sampling.

use inspc::source::{FsWorld, MemoryWorld};
use std::path::PathBuf;

fn insp_files(dir: &str) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![PathBuf::from(dir)];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "insp") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// Runs the pipeline up to the measurement graph; only the real meshes' known defects
/// (`mesh_defects` warnings) are allowed.
fn assert_clean(path: &std::path::Path) -> inspc::Checked {
    let (checked, _, _) = inspc::measurement_graphs(&FsWorld, &[path.to_path_buf()]);
    let rendered: Vec<String> = checked
        .diagnostics
        .iter()
        .filter(|d| d.code() != "insp::geometry::mesh_defects")
        .map(|d| format!("{}: {}", d.code(), d.message()))
        .collect();
    assert!(
        rendered.is_empty(),
        "{} has diagnostics:\n{}",
        path.display(),
        rendered.join("\n")
    );
    checked
}

#[test]
fn every_example_checks_clean_with_one_plan() {
    let files = insp_files("examples");
    let top: Vec<&PathBuf> = files
        .iter()
        .filter(|p| p.parent() == Some(std::path::Path::new("examples")))
        .collect();
    for name in [
        "f2",
        "f3_fixed",
        "f3_indexed",
        "f4",
        "swiss_block",
        "swiss_sphere_fixed",
        "swiss_sphere_indexed",
    ] {
        assert!(
            top.iter().any(|p| p.file_stem().unwrap() == name),
            "examples/{name}.insp is missing"
        );
    }
    for f in &files {
        let checked = assert_clean(f);
        let expected_plans = if top.contains(&f) { 1 } else { 0 };
        assert_eq!(
            checked.model.plans.len(),
            expected_plans,
            "{} should declare {expected_plans} plan(s)",
            f.display()
        );
    }
}

#[test]
fn every_stdlib_module_checks_clean() {
    // The standard library is always loaded, so an empty spec checks every module.
    let mut w = MemoryWorld::new();
    w.insert("empty.insp", "");
    let checked = inspc::check(&w, &["empty.insp".into()]);
    let rendered: Vec<String> = checked
        .diagnostics
        .iter()
        .map(|d| format!("{}: {}", d.code(), d.message()))
        .collect();
    assert!(
        rendered.is_empty(),
        "stdlib diagnostics:\n{}",
        rendered.join("\n")
    );
    for (name, _) in inspc::load::STD_MODULES {
        let short = name.trim_start_matches("std::");
        assert!(
            checked
                .sources
                .find_name(&format!("<std>/{short}.insp"))
                .is_some(),
            "{name} was not loaded"
        );
    }
    let m = &checked.model;
    assert_eq!(m.hierarchies.len(), 5);
    assert!(m.heads.len() >= 4 && m.probes.len() >= 10 && m.styli.len() >= 10);
    // The stdlib's files on disk are the ones embedded.
    for (name, text) in inspc::load::STD_MODULES {
        let path = format!("stdlib/{}.insp", name.trim_start_matches("std::"));
        assert_eq!(std::fs::read_to_string(&path).unwrap(), *text, "{path}");
    }
}

#[test]
fn the_nist_ctc_01_spec_checks_clean() {
    let mesh = PathBuf::from("../shared/parts/nist_ctc_01_asme1_ap242-e1.stp");
    assert!(
        mesh.exists(),
        "the NIST parts are expected in ../shared/parts/ beside the repository, as CI has them"
    );
    let checked = assert_clean(&PathBuf::from("tests/real/nist_ctc_01.insp"));
    let part = &checked.model.parts[0];
    assert_eq!(
        part.tolerances.len(),
        14,
        "6 geometric tolerances and 8 toleranced sizes in the PMI"
    );
    assert_eq!(
        part.datums
            .iter()
            .map(|d| d.name.as_str())
            .collect::<Vec<_>>(),
        ["A", "B", "C"]
    );
}

#[test]
fn the_nist_ftc_08_spec_checks_clean() {
    assert!(
        PathBuf::from("../shared/parts/nist_ftc_08_asme1_ap242-e1.obj").exists(),
        "the NIST parts are expected in ../shared/parts/ beside the repository, as CI has them"
    );
    let checked = assert_clean(&PathBuf::from("tests/real/nist_ftc_08.insp"));
    let part = &checked.model.parts[0];
    assert_eq!(
        part.tolerances.len(),
        42,
        "33 geometric tolerances and 9 toleranced sizes in the PMI"
    );
    assert_eq!(part.datums.len(), 11, "datums A to L without I");
}
