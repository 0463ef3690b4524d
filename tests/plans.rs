//! The planner end to end: golden plans (one folder per case under `tests/plans/`), the
//! seed's results, the properties every plan keeps, and determinism across thread
//! counts. See `tests/README.md`.

use inspc::diag::{render_human, RenderOptions};
use inspc::plan::{Hlip, PlanOptions};
use inspc::source::FsWorld;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

mod common;
use common::{diff, spec_of};

/// Plans a spec: the HLIPs, or the rendered diagnostics.
fn plan(spec: &Path) -> Result<Vec<Hlip>, String> {
    let (checked, _, _, planned) =
        inspc::plans(&FsWorld, &[spec.to_path_buf()], &PlanOptions::default());
    let opts = RenderOptions {
        width: 100,
        color: false,
    };
    let errors: Vec<_> = checked
        .diagnostics
        .iter()
        .filter(|d| d.severity() == miette::Severity::Error)
        .collect();
    if errors.is_empty() {
        Ok(planned.into_iter().filter_map(|p| p.hlip).collect())
    } else {
        Err(errors
            .iter()
            .map(|d| render_human(&checked.sources, d, opts))
            .collect())
    }
}

fn one(spec: &str) -> Hlip {
    let mut v = plan(Path::new(spec)).unwrap_or_else(|e| panic!("{spec}: {e}"));
    assert_eq!(v.len(), 1, "{spec}: one plan");
    v.remove(0)
}

#[test]
fn golden_plans() {
    let bless = std::env::var_os("INSPC_BLESS").is_some();
    let mut cases: Vec<PathBuf> = std::fs::read_dir("tests/plans")
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    cases.sort();
    assert!(
        cases.len() >= 10,
        "expected the plan cases, found {}",
        cases.len()
    );
    let mut failures = Vec::new();
    for case in &cases {
        let actual = match plan(&spec_of(case)) {
            Ok(h) => h.iter().map(inspc::plan::text).collect::<String>(),
            Err(d) => d,
        };
        let file = case.join("plan.txt");
        if bless {
            std::fs::write(&file, &actual).unwrap();
            continue;
        }
        let expected = std::fs::read_to_string(&file).unwrap_or_default();
        if expected != actual {
            failures.push(format!("{}:\n{}", case.display(), diff(&expected, &actual)));
        }
    }
    assert!(
        failures.is_empty(),
        "plans differ (INSPC_BLESS=1 to accept):\n{}",
        failures.join("\n")
    );
}

/// Which (probe, A, B) inspect a feature.
fn configs_of(h: &Hlip, feature: &str) -> BTreeSet<(String, String)> {
    let mut out = BTreeSet::new();
    for s in &h.setups {
        for p in &s.probes {
            for o in &p.orients {
                if o.inspections.iter().any(|i| i.feature == feature) {
                    out.insert((p.probe.clone(), format!("{} {}", o.a, o.b)));
                }
            }
        }
    }
    out
}

#[test]
fn the_seeds_results() {
    // F2 (fig. 3.10): one setup, two probes, the top inspected under each.
    let h = one("examples/f2.insp");
    assert_eq!((h.summary.setups, h.summary.probes_used), (1, 2));
    let probes: BTreeSet<String> = configs_of(&h, "top").into_iter().map(|c| c.0).collect();
    assert_eq!(probes.len(), 2, "the top under each probe");
    // F3: two setups on a fixed head; one setup, one probe, two orientations indexed.
    assert_eq!(one("examples/f3_fixed.insp").summary.setups, 2);
    let h = one("examples/f3_indexed.insp");
    let s = &h.summary;
    assert_eq!((s.setups, s.probes_used, s.orientations), (1, 1, 2));
    // F4: each hole by a different probe and orientation.
    let h = one("examples/f4.insp");
    let (large, small) = (configs_of(&h, "large_hole"), configs_of(&h, "small_hole"));
    assert_eq!((large.len(), small.len()), (1, 1), "{large:?} {small:?}");
    let (l, s) = (large.first().unwrap(), small.first().unwrap());
    assert!(l.0 != s.0 && l.1 != s.1, "{l:?} {s:?}");
    // The swiss-block in one setup, the swiss-sphere in 20 (fixed) or 2 (indexable).
    assert_eq!(one("examples/swiss_block.insp").summary.setups, 1);
    assert_eq!(one("examples/swiss_sphere_fixed.insp").summary.setups, 20);
    assert_eq!(one("examples/swiss_sphere_indexed.insp").summary.setups, 2);
}

#[test]
fn plans_cover_the_graph_and_find_the_minimum_setups() {
    for spec in [
        "examples/f2.insp",
        "examples/f4.insp",
        "examples/swiss_sphere_fixed.insp",
        "tests/real/nist_ctc_01.insp",
    ] {
        let (checked, _, graphs, planned) =
            inspc::plans(&FsWorld, &[PathBuf::from(spec)], &PlanOptions::default());
        assert!(!checked.has_errors(), "{spec}");
        let h = planned[0].hlip.as_ref().unwrap();
        let g = &graphs[0].graph;
        // Every face of the graph is inspected (or the table stands in for it), and
        // every point inspected is a point of its face.
        let mut faces = BTreeSet::new();
        for s in &h.setups {
            for p in &s.probes {
                for o in &p.orients {
                    for i in &o.inspections {
                        for f in &i.faces {
                            faces.insert(f.face.clone());
                            for &k in &f.points {
                                assert_eq!(h.points[k].face, f.face, "{spec}");
                                assert_eq!(h.points[k].table, f.table, "{spec}");
                            }
                        }
                    }
                }
            }
        }
        for n in g.graph.node_indices() {
            if let inspc::graph::Node::Face { face, .. } = g.graph[n] {
                let face_name = g
                    .fpoints
                    .iter()
                    .position(|f| f.face == face)
                    .map(|k| h.points[k].face.clone());
                if let Some(fname) = face_name {
                    assert!(
                        faces.contains(&fname),
                        "{spec}: face {fname} is not inspected"
                    );
                }
            }
        }
        // No plan has fewer setups than the proven minimum.
        let (min, proven) = h.summary.min_setups;
        assert!(h.summary.setups >= min || !proven, "{spec}");
        // Violations are reported for every level of the hierarchy.
        assert_eq!(
            h.summary.violations.len(),
            checked.model.hierarchies[checked.model.plans[planned[0].plan].hierarchy.0]
                .levels
                .len()
        );
    }
}

#[test]
fn plans_do_not_depend_on_the_thread_count() {
    for spec in ["examples/f4.insp", "examples/swiss_sphere_fixed.insp"] {
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| one(spec))
        };
        assert_eq!(run(1), run(3), "{spec}");
    }
}
