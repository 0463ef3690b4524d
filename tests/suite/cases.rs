//! The golden cases: one folder per case under `tests/cases/`, run once, a snapshot per
//! stage, and every check of the results (read-back, collision re-check of every move,
//! the seed's results, coverage) on that one run. See `tests/README.md`.
//!
//! Each case runs on a one-thread pool while cases run side by side, so comparing with
//! the snapshots (blessed on any number of threads) is also the determinism check; a
//! `slow` case runs on every thread instead, so that it does not hold up the suite.

use inspc::diag::{render_human, RenderOptions};
use inspc::model::fmt_num;
use inspc::plan::poses::{Holder, MIN_TIP_DEG};
use inspc::plan::{Hlip, Names, PlanOptions};
use inspc::source::FsWorld;
use inspc::{Built, Run, Until};
use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use crate::common;
use common::diff;

/// How far a case runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Depth {
    /// The front end: `model.txt`.
    Check,
    /// Through the measurement graphs: `graph.dot`, `fpoints.txt`.
    Graph,
    /// Through plans, paths and DMIS: `plan.txt`, `program.dmi`.
    Build,
}

/// A case folder and what its `case.txt` says.
struct Case {
    name: String,
    dir: PathBuf,
    spec: PathBuf,
    depth: Depth,
    slow: bool,
    /// Generate-and-test rounds (`rounds N`; the default otherwise).
    rounds: Option<usize>,
}

/// What one run of a case produced.
struct Outcome {
    /// Snapshots by file name.
    files: Vec<(&'static str, String)>,
    /// The run, when it went past the front end.
    run: Option<Run>,
}

/// Reads `case.txt`: `spec PATH` (default `main.insp` in the folder), `until check|graph|build`
/// (default `check`), `rounds N` to cut generate-and-test short, and `slow` for cases that
/// take more than a few seconds.
fn case(dir: &Path) -> Case {
    let mut spec = dir.join("main.insp");
    let mut depth = Depth::Check;
    let mut slow = false;
    let mut rounds = None;
    let text = std::fs::read_to_string(dir.join("case.txt")).unwrap_or_default();
    for line in text.lines().map(str::trim).filter(|l| !l.is_empty()) {
        match line.split_once(' ') {
            Some(("spec", p)) => spec = PathBuf::from(p.trim()),
            Some(("until", "check")) => depth = Depth::Check,
            Some(("until", "graph")) => depth = Depth::Graph,
            Some(("until", "build")) => depth = Depth::Build,
            Some(("rounds", n)) if n.trim().parse::<usize>().is_ok() => {
                rounds = n.trim().parse().ok()
            }
            None if line == "slow" => slow = true,
            _ => panic!("{}: cannot read `{line}` in case.txt", dir.display()),
        }
    }
    Case {
        name: dir.file_name().unwrap().to_string_lossy().into_owned(),
        dir: dir.to_path_buf(),
        spec,
        depth,
        slow,
        rounds,
    }
}

/// Every diagnostic rendered at width 100 without colour.
fn render(checked: &inspc::Checked) -> String {
    let opts = RenderOptions {
        width: 100,
        color: false,
    };
    checked
        .diagnostics
        .iter()
        .map(|d| render_human(&checked.sources, d, opts))
        .collect()
}

/// The graphs of a run as DOT, and every fpoint (face, position, normal).
fn graph_files(run: &Run) -> (String, String) {
    let (mut dot, mut points) = (String::new(), String::new());
    let r = |v: f64| fmt_num((v * 1e6).round() / 1e6);
    for gr in &run.graphs {
        let part = &run.checked.model.parts[gr.part];
        let g = &run.parts[gr.part].as_ref().unwrap().geometry;
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
    (dot, points)
}

/// The names behind a built plan's ids.
fn names<'a>(run: &'a Run, b: &Built) -> Names<'a> {
    inspc::plan_names(&run.checked, &run.parts, b.plan).expect("a built plan has geometry")
}

/// Runs one case once, as far as it goes.
fn run_case(c: &Case) -> Outcome {
    let roots = [c.spec.clone()];
    let front = inspc::check(&FsWorld, &roots);
    if front.has_errors() {
        return Outcome {
            files: vec![("diagnostics.txt", render(&front))],
            run: None,
        };
    }
    let mut files = vec![("model.txt", front.summary() + &render(&front))];
    if c.depth == Depth::Check {
        return Outcome { files, run: None };
    }
    let until = if c.depth == Depth::Build {
        Until::Build
    } else {
        Until::Graph
    };
    let defaults = PlanOptions::default();
    let opts = PlanOptions {
        max_iterations: c.rounds.unwrap_or(defaults.max_iterations),
        ..defaults
    };
    let run = inspc::run(&FsWorld, &roots, &opts, until, &|_, _, _| {});
    if !run.graphs.is_empty() || !run.checked.has_errors() {
        let (dot, points) = graph_files(&run);
        files.push(("graph.dot", dot));
        files.push(("fpoints.txt", points));
    }
    if run.checked.has_errors() {
        files.push(("diagnostics.txt", render(&run.checked)));
    } else if c.depth == Depth::Build {
        let plan: String = run
            .built
            .iter()
            .map(|b| inspc::plan::text(&b.hlip, &names(&run, b)))
            .collect();
        let program: String = run.built.iter().map(|b| b.dmis.clone()).collect();
        files.push(("plan.txt", plan));
        files.push(("program.dmi", program));
        // `inspc verify` on every program: its report is a snapshot (6 placements keep
        // the suite short; the CLI's default is 20).
        let opts = inspc::verify::Options {
            placements: 6,
            ..Default::default()
        };
        let verified: String = run
            .built
            .iter()
            .filter_map(|b| inspc::verify_built(&run, b, &opts))
            .map(|v| v.text())
            .collect();
        files.push(("verify.txt", verified));
        // The build's warnings past the front end's (model.txt has those).
        let warnings = render(&run.checked);
        let front_end = render(&front);
        let later = warnings
            .strip_prefix(front_end.as_str())
            .unwrap_or(&warnings);
        if !later.is_empty() {
            files.push(("warnings.txt", later.to_string()));
        }
    }
    Outcome {
        files,
        run: Some(run),
    }
}

/// Whether slow cases are skipped (without `INSPC_SLOW`, the local loop; CI runs them all).
fn quick() -> bool {
    !common::slow()
}

/// Every case, run once: side by side, each on a one-thread pool.
fn outcomes() -> &'static [(Case, Outcome)] {
    static ALL: OnceLock<Vec<(Case, Outcome)>> = OnceLock::new();
    ALL.get_or_init(|| {
        let cases: Vec<Case> = common::cases("tests/cases", 20)
            .iter()
            .map(|d| case(d))
            .filter(|c| !(c.slow && quick()))
            .collect();
        // Slow cases start first, so that the others run beside them.
        let mut order: Vec<usize> = (0..cases.len()).collect();
        order.sort_by_key(|&k| (!cases[k].slow, k));
        let next = std::sync::atomic::AtomicUsize::new(0);
        let workers = std::thread::available_parallelism().map_or(2, |n| n.get());
        let mut done: Vec<(usize, Outcome)> = std::thread::scope(|s| {
            let handles: Vec<_> = (0..workers)
                .map(|_| {
                    s.spawn(|| {
                        let pool = rayon::ThreadPoolBuilder::new()
                            .num_threads(1)
                            .build()
                            .unwrap();
                        let mut out = Vec::new();
                        loop {
                            let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                            let Some(&k) = order.get(i) else { break };
                            let c = &cases[k];
                            // A slow case takes every thread (it would otherwise be the
                            // whole suite's critical path); the rest take one each.
                            let outcome = if c.slow {
                                rayon::ThreadPoolBuilder::new()
                                    .num_threads(workers)
                                    .build()
                                    .unwrap()
                                    .install(|| run_case(c))
                            } else {
                                pool.install(|| run_case(c))
                            };
                            out.push((k, outcome));
                        }
                        out
                    })
                })
                .collect();
            handles
                .into_iter()
                .flat_map(|h| h.join().unwrap())
                .collect()
        });
        done.sort_by_key(|(k, _)| *k);
        cases
            .into_iter()
            .zip(done)
            .map(|(c, (_, o))| (c, o))
            .collect()
    })
}

/// The built plans of every case that built, with the run they came from.
fn built() -> impl Iterator<Item = (&'static Case, &'static Run, &'static Built)> {
    outcomes().iter().flat_map(|(c, o)| {
        o.run
            .iter()
            .flat_map(move |r| r.built.iter().map(move |b| (c, r, b)))
    })
}

/// The one plan of a case, which must have built.
fn one(name: &str) -> (&'static Run, &'static Built) {
    let (_, o) = outcomes()
        .iter()
        .find(|(c, _)| c.name == name)
        .unwrap_or_else(|| panic!("no case {name}"));
    let run = o
        .run
        .as_ref()
        .unwrap_or_else(|| panic!("{name} did not run"));
    assert_eq!(run.built.len(), 1, "{name}: one plan");
    (run, &run.built[0])
}

#[test]
fn golden_cases() {
    let bless = std::env::var_os("INSPC_BLESS").is_some();
    let mut failures = Vec::new();
    for (c, o) in outcomes() {
        let has = |f: &str| o.files.iter().any(|(n, _)| *n == f);
        // A case never silently flips between passing and failing, even under bless.
        for (file, state) in [
            ("model.txt", "fails in the front end"),
            ("diagnostics.txt", "passes"),
        ] {
            if !has(file) && c.dir.join(file).exists() {
                failures.push(format!(
                    "{}: now {state}, but it expects {file}; if that is intended, delete it and bless",
                    c.name
                ));
            }
        }
        if failures
            .iter()
            .any(|f| f.starts_with(&format!("{}:", c.name)))
        {
            continue;
        }
        for (name, actual) in &o.files {
            let path = c.dir.join(name);
            if bless {
                std::fs::write(&path, actual).unwrap();
                continue;
            }
            match std::fs::read_to_string(&path) {
                Ok(expected) if &expected == actual => {}
                Ok(expected) => failures.push(format!(
                    "{}: differs\n{}",
                    path.display(),
                    diff(&expected, actual)
                )),
                Err(_) => failures.push(format!(
                    "{}: no expectation; run `INSPC_BLESS=1 cargo test --test suite cases::`",
                    path.display()
                )),
            }
        }
    }
    assert!(
        failures.is_empty(),
        "snapshots differ (INSPC_BLESS=1 to accept):\n{}",
        failures.join("\n\n")
    );
}

#[test]
fn failed_builds_write_no_program() {
    for (c, o) in outcomes() {
        if o.files.iter().any(|(n, _)| *n == "diagnostics.txt") {
            assert!(
                !c.dir.join("program.dmi").exists() && !c.dir.join("plan.txt").exists(),
                "{}: a failed case has no plan or program",
                c.name
            );
        }
    }
}

/// Every program read back: it passes the reader's checks, prints back byte for byte,
/// and touches exactly the plan's points in the plan's order.
#[test]
fn programs_read_back() {
    let mut n = 0;
    for (c, _, b) in built() {
        let program =
            inspc::dmis::read(inspc::source::FileId(0), &b.dmis).unwrap_or_else(|errors| {
                panic!(
                    "{}: the reader rejects the program: {:?}",
                    c.name,
                    errors.iter().map(|e| e.to_string()).collect::<Vec<_>>()
                )
            });
        assert!(
            program.warnings.is_empty(),
            "{}: the reader warns on the program: {:?}",
            c.name,
            program
                .warnings
                .iter()
                .map(|e| e.to_string())
                .collect::<Vec<_>>()
        );
        assert!(
            program.to_text() == b.dmis,
            "{}: the program does not print back the same:\n{}",
            c.name,
            diff(&b.dmis, &program.to_text())
        );
        // Every touch of the plan, in program order (the manual alignment's first).
        let mut want = Vec::new();
        for s in &b.llip.setups {
            for step in &s.alignment.steps {
                want.extend(step.points.iter().map(|&k| b.hlip.points[k].position));
                if let Some(extra) = &step.extra {
                    want.extend(extra.touches.iter().map(|(p, _)| *p));
                }
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
        assert_eq!(got.len(), want.len(), "{}: touches", c.name);
        for (a, w) in got.iter().zip(&want) {
            assert!(
                (0..3).all(|k| (a[k] - w[k]).abs() <= 1e-4),
                "{}: touches {a:?}, the plan {w:?}",
                c.name
            );
        }
        n += 1;
    }
    assert!(n >= 8, "only {n} programs");
}

/// Every move of every program, re-checked with parry on its own: the probe of each
/// group, grown by the plan's margin (less only at the stand-offs the program says keep
/// less), swept along every segment between the positions the program commands, over a
/// table computed here from the part's vertices and the fixture holding the part.
#[test]
fn every_move_is_collision_free() {
    let mut programs = 0;
    for (c, run, b) in built() {
        let model = &run.checked.model;
        let plan = &model.plans[b.plan];
        let geometry = &run.parts[plan.part.0].as_ref().unwrap().geometry;
        let scene = inspc::access::Scene::of_part(geometry);
        // The sensors by slot: the probes, then the scanners (no tip).
        let cmm = &model.cmms[plan.cmm.0];
        let probes = inspc::access::scan::sensor_shapes(model, cmm);
        let mut segments = 0;
        for s in &b.llip.setups {
            let setup = &b.hlip.setups[s.setup];
            let up = setup.up;
            let low = geometry
                .vertices
                .iter()
                .map(|v| v.coords.dot(&up))
                .fold(f64::INFINITY, f64::min);
            // On the table the part rests on its lowest point; a fixture holds it higher.
            let table = match setup.holder {
                Holder::Table { .. } => low,
                Holder::Fixture { .. } => {
                    assert!(setup.table < low, "{}: a fixture under the part", c.name);
                    setup.table
                }
            };
            for g in &s.groups {
                let probe = &probes[g.probe.0];
                let dir = nalgebra::Vector3::from(g.direction);
                // Every move keeps the plan's margin, less only next to a stand-off
                // that keeps less (the program records how much).
                let mut pose = inspc::access::Pose::new(&scene, probe, dir, up, table)
                    .with_fixture(&setup.fixture)
                    .with_margin(plan.motion.margin);
                for bl in &g.blocks {
                    for t in &bl.touches {
                        assert!(t.margin <= plan.motion.margin && t.margin >= 0.0);
                        pose.set_tight(&t.standoff.into(), t.margin);
                    }
                }
                let mut pts: Vec<[f64; 3]> = g.entry.clone();
                for bl in &g.blocks {
                    for t in &bl.touches {
                        pts.extend(t.via.iter().copied());
                        pts.push(t.standoff);
                    }
                    // A scanner's passes: the moves to each, and the pass itself.
                    for p in &bl.passes {
                        pts.extend(p.via.iter().copied());
                        pts.push(p.start);
                        pts.push(p.end);
                    }
                }
                pts.extend(g.exit.iter().copied());
                for w in pts.windows(2) {
                    let (p, q) = (w[0].into(), w[1].into());
                    if let Err(e) = pose.segment(&p, &q) {
                        panic!(
                            "{}: {} A{} B{}: {:?} -> {:?}: {e}",
                            c.name, probe.name, g.a, g.b, w[0], w[1]
                        );
                    }
                    segments += 1;
                }
            }
        }
        assert!(segments > 10, "{}: {segments} segments", c.name);
        programs += 1;
    }
    assert!(programs >= 8, "only {programs} programs");
}

/// Every setup of every golden plan is one an operator can realise, checked here on its
/// own: resting on the table, the part's centre of mass (from the tetrahedra of its
/// mesh) lies over the support polygon of its lowest vertices with at least
/// `MIN_TIP_DEG` to tip; or one of the fixtures the plan names holds it.
#[test]
fn every_setup_stands_or_is_held() {
    let mut setups = 0;
    for (c, run, b) in built() {
        let model = &run.checked.model;
        let plan = &model.plans[b.plan];
        let g = &run.parts[plan.part.0].as_ref().unwrap().geometry;
        let (mut vol, mut m) = (0.0, nalgebra::Vector3::zeros());
        for t in &g.triangles {
            let [p, q, r] = t.map(|i| g.vertices[i as usize].coords);
            let v = p.dot(&q.cross(&r)) / 6.0;
            vol += v;
            m += (p + q + r) / 4.0 * v;
        }
        let com = m / vol;
        for (si, s) in b.hlip.setups.iter().enumerate() {
            setups += 1;
            match &s.holder {
                Holder::Fixture { slot, .. } => assert!(
                    plan.fixtures.contains(slot),
                    "{}: setup {} uses a fixture the plan does not name",
                    c.name,
                    si + 1
                ),
                Holder::Table { .. } => {
                    let up = s.up;
                    let (e1, e2) = inspc::sample::perpendicular_basis(&up);
                    let low = g
                        .vertices
                        .iter()
                        .map(|v| v.coords.dot(&up))
                        .fold(f64::INFINITY, f64::min);
                    let mut pts: Vec<(f64, f64)> = g
                        .vertices
                        .iter()
                        .filter(|v| v.coords.dot(&up) < low + 1e-3)
                        .map(|v| (v.coords.dot(&e1), v.coords.dot(&e2)))
                        .collect();
                    pts.sort_by(|a, b| a.partial_cmp(b).unwrap());
                    pts.dedup();
                    // Monotone chain, counter-clockwise.
                    let cross = |o: (f64, f64), a: (f64, f64), b: (f64, f64)| {
                        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
                    };
                    let mut hull: Vec<(f64, f64)> = Vec::new();
                    for pass in [pts.clone(), pts.iter().rev().copied().collect()] {
                        let start = hull.len();
                        for p in pass {
                            while hull.len() >= start + 2
                                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
                            {
                                hull.pop();
                            }
                            hull.push(p);
                        }
                        hull.pop();
                    }
                    assert!(
                        hull.len() >= 3,
                        "{}: setup {} rests on a line",
                        c.name,
                        si + 1
                    );
                    let c2 = (com.dot(&e1), com.dot(&e2));
                    let h = com.dot(&up) - low;
                    let d = (0..hull.len())
                        .map(|k| {
                            let (a, b) = (hull[k], hull[(k + 1) % hull.len()]);
                            let len = ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt();
                            cross(a, b, c2) / len
                        })
                        .fold(f64::INFINITY, f64::min);
                    let tip = d.atan2(h).to_degrees();
                    assert!(
                        tip >= MIN_TIP_DEG - 1e-6,
                        "{}: setup {} up {:?} tips over at {tip:.1}°",
                        c.name,
                        si + 1,
                        up
                    );
                }
            }
        }
    }
    assert!(setups >= 10, "only {setups} setups");
}

/// Every tolerance of every golden plan is measured and reported: its `TOL` is defined
/// and an `OUTPUT` names it (the summary counts it among those measured).
#[test]
fn every_tolerance_is_output() {
    let mut tolerances = 0;
    for (c, run, b) in built() {
        let part = &run.checked.model.parts[run.checked.model.plans[b.plan].part.0];
        let (measured, total) = b.hlip.summary.tolerances;
        assert_eq!(
            (measured, total),
            (part.tolerances.len(), part.tolerances.len()),
            "{}",
            c.name
        );
        let defined: Vec<&str> = b
            .dmis
            .lines()
            .filter_map(|l| l.strip_prefix("T(")?.split_once(")=TOL/").map(|(t, _)| t))
            .collect();
        assert_eq!(defined.len(), total, "{}: TOL statements", c.name);
        // Statements, a continued line (`$` last) joined to the next.
        let statements: Vec<String> = b
            .dmis
            .replace("$\n", "")
            .lines()
            .map(str::to_string)
            .collect();
        for t in defined {
            assert!(
                statements
                    .iter()
                    .any(|l| l.starts_with("OUTPUT/") && l.contains(&format!("TA({t})"))),
                "{}: tolerance {t} is never output",
                c.name
            );
            tolerances += 1;
        }
    }
    assert!(tolerances >= 20, "only {tolerances} tolerances");
}

/// Which (probe, A, B) inspect a feature.
fn configs_of(run: &Run, b: &Built, feature: &str) -> BTreeSet<(String, String)> {
    let names = names(run, b);
    let mut out = BTreeSet::new();
    for s in &b.hlip.setups {
        for p in &s.probes {
            for o in &p.orients {
                if o.inspections
                    .iter()
                    .any(|i| names.feature(i.feature) == feature)
                {
                    out.insert((names.probe(p.probe).to_string(), format!("{} {}", o.a, o.b)));
                }
            }
        }
    }
    out
}

fn hlip(name: &str) -> &'static Hlip {
    &one(name).1.hlip
}

#[test]
fn the_seeds_results() {
    // F2 (fig. 3.10): one setup, two probes, the top inspected under each.
    let (run, b) = one("example_f2");
    assert_eq!((b.hlip.summary.setups, b.hlip.summary.probes_used), (1, 2));
    let probes: BTreeSet<String> = configs_of(run, b, "top").into_iter().map(|c| c.0).collect();
    assert_eq!(probes.len(), 2, "the top under each probe");
    // F3: two setups on a fixed head; one setup, one probe indexed. Spitz's two
    // orientations hold the part square; kept clear with it set 3° off (the stylus along
    // the horizontal hole turns with the head, not the part), the hole's touches take
    // two orientations more.
    assert_eq!(hlip("example_f3_fixed").summary.setups, 2);
    let s = &hlip("example_f3_indexed").summary;
    assert_eq!((s.setups, s.probes_used, s.orientations), (1, 1, 4));
    // F4: each hole by a different probe and orientation.
    let (run, b) = one("example_f4");
    let (large, small) = (
        configs_of(run, b, "large_hole"),
        configs_of(run, b, "small_hole"),
    );
    assert_eq!((large.len(), small.len()), (1, 1), "{large:?} {small:?}");
    let (l, s) = (large.first().unwrap(), small.first().unwrap());
    assert!(l.0 != s.0 && l.1 != s.1, "{l:?} {s:?}");
    // The swiss-block in one setup, the swiss-sphere in 20 (fixed) or 2 (indexable).
    assert_eq!(hlip("example_swiss_block").summary.setups, 1);
    assert_eq!(hlip("example_swiss_sphere_fixed").summary.setups, 20);
    assert_eq!(hlip("example_swiss_sphere_indexed").summary.setups, 2);
}

/// Every face of the graph is inspected (or the table stands in for it), every point
/// inspected is a point of its face, no plan has fewer setups than the proven minimum,
/// and violations are counted for every level of the hierarchy.
#[test]
fn plans_cover_the_graph_and_find_the_minimum_setups() {
    for (c, run, b) in built() {
        let h = &b.hlip;
        let g = &run
            .graphs
            .iter()
            .find(|g| g.graph.plan.as_deref() == Some(&run.checked.model.plans[b.plan].name))
            .unwrap()
            .graph;
        let mut faces = BTreeSet::new();
        for s in &h.setups {
            for p in &s.probes {
                for o in &p.orients {
                    for i in &o.inspections {
                        for f in &i.faces {
                            faces.insert(f.face);
                            for &k in &f.points {
                                assert_eq!(h.points[k].face, f.face, "{}", c.name);
                                assert_eq!(h.points[k].at.contact(), f.contact, "{}", c.name);
                            }
                        }
                    }
                }
            }
        }
        for n in g.graph.node_indices() {
            if let inspc::graph::Node::Face { face, .. } = g.graph[n] {
                if g.fpoints.iter().any(|f| f.face == face) {
                    assert!(
                        faces.contains(&face),
                        "{}: face {} is not inspected",
                        c.name,
                        names(run, b).face(face)
                    );
                }
            }
        }
        let (min, proven) = h.summary.min_setups;
        assert!(h.summary.setups >= min || !proven, "{}", c.name);
        let model = &run.checked.model;
        assert_eq!(
            h.summary.violations.len(),
            model.hierarchies[model.plans[b.plan].hierarchy.0]
                .levels
                .len(),
            "{}",
            c.name
        );
    }
}

/// Every face a golden plan scans is covered to the plan's `scan_coverage`, judged here
/// without the planner's cones: 2,000 area-weighted points of the face (a fixed
/// sequence), each covered when some pass of its group runs over it — within the
/// pass's length, the stripe's half-width across and half the depth of field along the
/// scanner's direction — and exact ray casts see it from that direction
/// (`access::scan::sees`: incidence, laser and camera).
#[test]
fn every_scanned_face_reaches_the_plans_coverage_by_exact_rays() {
    let mut faces = 0;
    for (c, run, b) in built() {
        let model = &run.checked.model;
        let plan = &model.plans[b.plan];
        let cmm = &model.cmms[plan.cmm.0];
        let geometry = &run.parts[plan.part.0].as_ref().unwrap().geometry;
        let scene = inspc::access::Scene::of_part(geometry);
        let scanners = inspc::access::scan::ScannerShape::of_cmm(model, cmm);
        for sc in &b.hlip.scans {
            let optics = scanners[sc.scanner.0 - cmm.probes.len()].optics;
            // The passes over this face, with their scanner direction.
            let mut passes = Vec::new();
            for s in b.llip.setups.iter().filter(|s| s.setup == sc.setup) {
                for g in &s.groups {
                    let d = nalgebra::Vector3::from(g.direction);
                    for bl in g.blocks.iter().filter(|bl| bl.face == sc.face) {
                        for p in &bl.passes {
                            passes.push((
                                nalgebra::Point3::from(p.start),
                                nalgebra::Point3::from(p.end),
                                d,
                            ));
                        }
                    }
                }
            }
            let points = face_points(geometry, sc.face.0, 2000);
            let covered = points
                .iter()
                .filter(|(q, n)| {
                    passes.iter().any(|(s, e, d)| {
                        let run = e - s;
                        let len = run.norm().max(1e-9);
                        let m = run / len;
                        let across = d.cross(&m);
                        let v = q - s;
                        (-1e-6..=len + 1e-6).contains(&v.dot(&m))
                            && v.dot(&across).abs() <= optics.stripe / 2.0
                            && v.dot(d).abs() <= optics.depth / 2.0
                            && inspc::access::scan::sees(&scene, q, n, d, &optics)
                    })
                })
                .count();
            let share = covered as f64 / points.len() as f64;
            assert!(
                share >= plan.scan_coverage - 0.02,
                "{}: face {} covered {:.3} by exact rays, the plan says {:.3}",
                c.name,
                geometry.faces[sc.face.0].name,
                share,
                sc.coverage
            );
            faces += 1;
        }
    }
    assert!(faces >= 2, "only {faces} scanned faces");
}

/// `count` points of a face spread by area (a fixed low-discrepancy sequence over its
/// triangles), with the surface's outward normal at each.
fn face_points(
    g: &inspc::geometry::PartGeometry,
    face: usize,
    count: usize,
) -> Vec<(nalgebra::Point3<f64>, nalgebra::Vector3<f64>)> {
    let f = &g.faces[face];
    let tris: Vec<[nalgebra::Point3<f64>; 3]> = f
        .triangles
        .iter()
        .map(|&t| g.triangles[t as usize].map(|i| g.vertices[i as usize]))
        .collect();
    let areas: Vec<f64> = tris
        .iter()
        .map(|v| (v[1] - v[0]).cross(&(v[2] - v[0])).norm() / 2.0)
        .collect();
    let total: f64 = areas.iter().sum();
    let mut out = Vec::new();
    let mut acc = 0.0;
    let mut k = 0;
    for (v, a) in tris.iter().zip(&areas) {
        acc += a;
        // The points whose cumulative share falls in this triangle.
        while k < count && (k as f64 + 0.5) / count as f64 * total <= acc {
            // A golden-ratio sequence folded into the triangle.
            let (u, w) = (
                (k as f64 * 0.618_033_988_7).fract(),
                (k as f64 * 0.754_877_666_2).fract(),
            );
            let (u, w) = if u + w > 1.0 {
                (1.0 - u, 1.0 - w)
            } else {
                (u, w)
            };
            let q = v[0] + (v[1] - v[0]) * u + (v[2] - v[0]) * w;
            let tn = (v[1] - v[0]).cross(&(v[2] - v[0]));
            let n = f.surface.normal_at(&q).unwrap_or_else(|| tn.normalize());
            out.push((q, n));
            k += 1;
        }
    }
    out
}
