//! The pipeline end to end: golden plans and DMIS programs (one folder per case under
//! `tests/plans/`), each program read back and checked, every move re-checked for
//! collisions, the seed's results, the properties every plan keeps, and determinism
//! across runs and thread counts. See `tests/README.md`.

use inspc::diag::{render_human, RenderOptions};
use inspc::plan::{Hlip, PlanOptions};
use inspc::source::FsWorld;
use inspc::Built;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

mod common;
use common::{diff, spec_of};

/// `Ok` without errors, else the errors rendered.
fn errors_of(checked: &inspc::Checked) -> Result<(), String> {
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
        Ok(())
    } else {
        Err(errors
            .iter()
            .map(|d| render_human(&checked.sources, d, opts))
            .collect())
    }
}

/// Plans a spec: the HLIPs, or the rendered diagnostics.
fn plan(spec: &Path) -> Result<Vec<Hlip>, String> {
    let (checked, _, _, planned) =
        inspc::plans(&FsWorld, &[spec.to_path_buf()], &PlanOptions::default());
    errors_of(&checked)?;
    Ok(planned.into_iter().filter_map(|p| p.hlip).collect())
}

fn one(spec: &str) -> Hlip {
    let mut v = plan(Path::new(spec)).unwrap_or_else(|e| panic!("{spec}: {e}"));
    assert_eq!(v.len(), 1, "{spec}: one plan");
    v.remove(0)
}

/// Builds a spec: every plan built, or the rendered diagnostics.
fn build(spec: &Path) -> Result<Vec<Built>, String> {
    let (checked, built, _) = inspc::build(
        &FsWorld,
        &[spec.to_path_buf()],
        &PlanOptions::default(),
        &|_, _, _| {},
    );
    errors_of(&checked)?;
    Ok(built)
}

/// The program read back: it passes the reader's checks, prints back byte for byte, and
/// touches exactly the plan's points.
fn read_back(case: &Path, b: &Built) -> Result<(), String> {
    let program = inspc::dmis::read("program.dmi", &b.dmis).map_err(|errors| {
        format!(
            "{}: the reader rejects the program: {:?}",
            case.display(),
            errors.iter().map(|e| e.to_string()).collect::<Vec<_>>()
        )
    })?;
    if program.to_text() != b.dmis {
        return Err(format!(
            "{}: the program does not print back the same:\n{}",
            case.display(),
            diff(&b.dmis, &program.to_text())
        ));
    }
    // Every touch of the plan, in program order (the manual alignment's first).
    let mut want: Vec<[f64; 3]> = Vec::new();
    for s in &b.llip.setups {
        for step in &s.alignment.steps {
            want.extend(step.points.iter().map(|&k| b.hlip.points[k].position));
        }
        for g in &s.groups {
            for bl in &g.blocks {
                want.extend(bl.touches.iter().map(|t| b.hlip.points[t.point].position));
            }
        }
    }
    let got: Vec<[f64; 3]> = program
        .commands("PTMEAS")
        .map(|p| {
            let v: Vec<f64> = p[1..4].iter().map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    if got.len() != want.len()
        || got
            .iter()
            .zip(&want)
            .any(|(a, b)| (0..3).any(|k| (a[k] - b[k]).abs() > 1e-4))
    {
        return Err(format!(
            "{}: the program touches {} points, the plan {}",
            case.display(),
            got.len(),
            want.len()
        ));
    }
    Ok(())
}

#[test]
fn golden_plans_and_programs() {
    let bless = std::env::var_os("INSPC_BLESS").is_some();
    let cases = common::cases("tests/plans", 10);
    let mut failures = Vec::new();
    for case in &cases {
        let (plan, program) = match build(&spec_of(case)) {
            Ok(built) => {
                for b in &built {
                    if let Err(e) = read_back(case, b) {
                        failures.push(e);
                    }
                }
                (
                    built
                        .iter()
                        .map(|b| inspc::plan::text(&b.hlip))
                        .collect::<String>(),
                    built.iter().map(|b| b.dmis.clone()).collect::<String>(),
                )
            }
            Err(d) => (d, String::new()),
        };
        for (name, actual) in [("plan.txt", plan), ("program.dmi", program)] {
            let file = case.join(name);
            if actual.is_empty() && name == "program.dmi" {
                assert!(
                    !file.exists(),
                    "{}: a failed build has no program",
                    case.display()
                );
                continue;
            }
            if bless {
                std::fs::write(&file, &actual).unwrap();
                continue;
            }
            let expected = std::fs::read_to_string(&file).unwrap_or_default();
            if expected != actual {
                failures.push(format!("{}:\n{}", file.display(), diff(&expected, &actual)));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "plans or programs differ (INSPC_BLESS=1 to accept):\n{}",
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
fn programs_do_not_depend_on_the_run_or_the_thread_count() {
    for spec in [
        "examples/f4.insp",
        "examples/swiss_sphere_fixed.insp",
        "tests/real/nist_ctc_01.insp",
    ] {
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| build(Path::new(spec)).unwrap_or_else(|e| panic!("{spec}: {e}")))
        };
        let (a, b, c) = (run(1), run(3), run(3));
        for (x, y) in [(&a, &b), (&b, &c)] {
            assert_eq!(x.len(), y.len(), "{spec}");
            for (p, q) in x.iter().zip(y.iter()) {
                assert_eq!(p.hlip, q.hlip, "{spec}");
                assert_eq!(p.llip, q.llip, "{spec}");
                assert!(p.dmis == q.dmis, "{spec}: programs differ");
            }
        }
    }
}

/// Every move of a program, re-checked with parry on its own: the probe of each group
/// swept along every segment between the positions the program commands.
#[test]
fn every_move_is_collision_free() {
    for spec in [
        "examples/f2.insp",
        "examples/f4.insp",
        "examples/swiss_block.insp",
        "examples/swiss_sphere_indexed.insp",
        "tests/real/nist_ctc_01.insp",
    ] {
        let path = PathBuf::from(spec);
        let built = build(&path).unwrap_or_else(|e| panic!("{spec}: {e}"));
        let (checked, parts) = inspc::check_geometry(&FsWorld, &[path]);
        let model = &checked.model;
        for b in &built {
            let plan = &model.plans[b.plan];
            let geometry = &parts[plan.part.0].as_ref().unwrap().geometry;
            let scene = inspc::access::Scene::of_part(geometry);
            let probes = inspc::access::ProbeShape::of_cmm(model, &model.cmms[plan.cmm.0]);
            let mut segments = 0;
            for s in &b.llip.setups {
                let up = nalgebra::Vector3::from(b.hlip.setups[s.setup].up);
                let table = geometry
                    .vertices
                    .iter()
                    .map(|v| v.coords.dot(&up))
                    .fold(f64::INFINITY, f64::min);
                for g in &s.groups {
                    let probe = probes.iter().find(|p| p.name == g.probe).unwrap();
                    let pose = inspc::path::Pose::new(
                        &scene,
                        probe,
                        nalgebra::Vector3::from(g.direction),
                        up,
                        table,
                    );
                    let mut pts: Vec<[f64; 3]> = g.entry.clone();
                    for bl in &g.blocks {
                        for t in &bl.touches {
                            pts.extend(t.via.iter().copied());
                            pts.push(t.standoff);
                        }
                    }
                    pts.extend(g.exit.iter().copied());
                    for w in pts.windows(2) {
                        let (p, q) = (w[0].into(), w[1].into());
                        if let Err(e) = pose.segment(&p, &q) {
                            panic!(
                                "{spec}: {} A{} B{}: {:?} -> {:?}: {e}",
                                g.probe, g.a, g.b, w[0], w[1]
                            );
                        }
                        segments += 1;
                    }
                }
            }
            assert!(segments > 10, "{spec}: {segments} segments");
        }
    }
}
