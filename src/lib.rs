//! inspc: a compiler for CMM inspection.
//!
//! `.insp` specs in, DMIS programs out. See `ARCHITECTURE.md` for the pipeline; each
//! stage is a module with one documented entry point:
//! [`syntax::parse`] → [`load::load`] → [`resolve::resolve`] → [`model::Model`].
//!
//! The driver decides what lies between the stages: which parts get geometry (those the
//! root files declare or their plans name), the margin each plan samples with
//! ([`sampling_margin`]), the surface checks after geometry ([`graph::check_surfaces`]:
//! a flatness on a cylinder is an error before any sampling), one measurement graph per
//! plan and per root part no plan names (sampled with `std::sampling::spread`), and
//! that such a part is `insp::plan::no_plan` when a build is asked for. Each stage runs
//! only when the stages before it left no error. `run(…, Until)` keeps every stage's
//! result, so the golden tests snapshot every stage from one run.
//!
//! **Architecture Invariant:** a stage imports earlier stages only, and no two files of
//! a folder import each other round a circle (`tests/suite/architecture.rs`). Ids go
//! down the pipeline; names come back only through `plan::Names`.
//!
//! **Decision: fpoints are probe-independent.** They keep a margin from face edges
//! equal to the largest tip radius of the plan's machine (1 mm without a plan), Fan &
//! Leu's `r`, so that every probe's tip fits; the sampler narrows it on a narrow face
//! and halves it on a face it leaves empty (see [`sample`]). Whether a tip fits at a
//! point is left to accessibility, which can say which probe fails and why. A face
//! whose candidates all fail is a warning (`insp::graph::no_points`).
//!
//! **Decision: the path stage is one more test.** A touch the planner validated but no
//! collision-free move reaches (the roadmap finds no way in, or no way up to the
//! clearance plane) bans that configuration (point, probe, setup, probe direction), and
//! the plan is made again with it failing validation (a point, probe and setup that fail
//! a second time, in every direction: `plan::Ban::widen`), at most `REPLANS` (16) times
//! (`paths_of`); the diagnostics of the last try are the ones reported. A re-plan
//! reuses the first planning's pure results (`plan::Memo`: cones, D2 caps, depth maps,
//! grid orientations, the scene), so it costs clustering and validation only, and from
//! the round where the new ban first matters (`plan::journal`: the rounds before it are
//! the last search's): one unreachable touch costs a re-plan, not the program.
#![warn(missing_docs)]

pub mod access;
pub mod diag;
pub mod dmis;
pub mod fmt;
pub mod geometry;
pub mod graph;
pub mod import;
pub mod load;
pub mod lsp;
pub mod model;
pub mod path;
pub mod plan;
pub mod resolve;
pub mod sample;
pub mod simulate;
pub mod source;
pub mod syntax;
pub mod verify;
pub mod view;

use std::path::{Path, PathBuf};

/// The result of checking a spec: the model (meaningful only without errors), every
/// diagnostic, and the sources they point into.
pub struct Checked {
    /// The resolved model.
    pub model: model::Model,
    /// Every diagnostic, in a stable order.
    pub diagnostics: Vec<diag::Diagnostic>,
    /// The files read.
    pub sources: source::SourceMap,
    /// The files named as roots (that loaded).
    pub roots: Vec<source::FileId>,
    /// Every module read, with its syntax tree (the language server's symbols).
    pub program: load::Program,
}

impl Checked {
    /// Whether any diagnostic is an error.
    pub fn has_errors(&self) -> bool {
        self.diagnostics
            .iter()
            .any(|d| d.severity() == miette::Severity::Error)
    }

    /// Adds a later stage's diagnostics, keeping the stable order.
    fn absorb(&mut self, later: diag::Diagnostics) {
        let mut all = diag::Diagnostics::new();
        for d in std::mem::take(&mut self.diagnostics) {
            all.push_boxed(d);
        }
        all.extend(later);
        self.diagnostics = all.sorted();
    }

    /// [`Checked::absorb`] for several stages' (or plans') diagnostics at once.
    fn absorb_all(&mut self, later: Vec<diag::Diagnostics>) {
        let mut all = diag::Diagnostics::new();
        for d in later {
            all.extend(d);
        }
        self.absorb(all);
    }

    /// Every file the run read or will read: the specs it loaded and the meshes their
    /// parts name. No output may replace one of them.
    pub fn inputs(&self) -> Vec<PathBuf> {
        let mut out: Vec<PathBuf> = self.sources.paths().map(Path::to_path_buf).collect();
        for part in &self.model.parts {
            if let model::Geometry::Mesh { path, .. } = &part.geometry {
                out.push(path.clone());
            }
        }
        for f in &self.model.fixtures {
            if let model::FixtureKind::Mesh { path, .. } = &f.kind {
                out.push(path.clone());
            }
        }
        out
    }

    /// The model as text, showing what the root files declare and use.
    pub fn summary(&self) -> String {
        self.model.summary(&|f| self.roots.contains(&f))
    }
}

/// A part's evaluated geometry and, per feature, the faces it names.
#[derive(Debug, Clone)]
pub struct PartData {
    /// The geometry.
    pub geometry: geometry::PartGeometry,
    /// Per feature of the part, its faces.
    pub feature_faces: Vec<Vec<geometry::FaceId>>,
    /// The mesh fixtures its plans name, placed with it.
    pub fixtures: Vec<geometry::FixtureMesh>,
}

/// Runs the front end and then evaluates the geometry of every part the root files
/// declare or their plans name, resolving each feature's faces; geometry diagnostics join the front end's.
/// A part whose geometry fails (or every part, when the front end failed) gets `None`.
pub fn check_geometry(
    world: &dyn source::World,
    roots: &[PathBuf],
) -> (Checked, Vec<Option<PartData>>) {
    let mut checked = check(world, roots);
    let parts = geometry_of(world, &mut checked);
    (checked, parts)
}

/// The geometry stage over a checked spec (see [`check_geometry`]).
fn geometry_of(world: &dyn source::World, checked: &mut Checked) -> Vec<Option<PartData>> {
    let mut out = vec![None; checked.model.parts.len()];
    if checked.has_errors() {
        return out;
    }
    let mut diags = diag::Diagnostics::new();
    for (k, part) in checked.model.parts.iter().enumerate() {
        let planned = checked.model.plans.iter().any(|p| p.part.0 == k);
        if !planned && !checked.roots.contains(&part.span.file) {
            continue;
        }
        let Some(geometry) = geometry::build(part, world, &mut diags) else {
            continue;
        };
        let feature_faces: Vec<Vec<geometry::FaceId>> = part
            .features
            .iter()
            .map(|f| {
                let mut faces: Vec<geometry::FaceId> = Vec::new();
                for r in &f.faces {
                    for id in geometry::resolve_faces(&geometry, r, &mut diags) {
                        if !faces.contains(&id) {
                            faces.push(id);
                        }
                    }
                }
                faces
            })
            .collect();
        graph::check_surfaces(part, &geometry, &feature_faces, &mut diags);
        let mut fixtures: Vec<geometry::FixtureMesh> = Vec::new();
        let model = &checked.model;
        for plan in model.plans.iter().filter(|p| p.part.0 == k) {
            let cmm = &model.cmms[plan.cmm.0];
            for &slot in &plan.fixtures {
                let Some((_, id)) = cmm.fixtures.get(slot) else {
                    continue;
                };
                let f = &model.fixtures[id.0];
                if matches!(f.kind, model::FixtureKind::Mesh { .. })
                    && !fixtures.iter().any(|m| m.fixture == *id)
                {
                    if let Some(m) =
                        geometry::place_fixture(&geometry, &part.name, *id, f, world, &mut diags)
                    {
                        fixtures.push(m);
                    }
                }
            }
        }
        out[k] = Some(PartData {
            geometry,
            feature_faces,
            fixtures,
        });
    }
    checked.absorb(diags);
    out
}

/// One measurement graph: for a plan of a root file, or for a root file's part that no
/// plan there names (sampled with `std::sampling::fan_leu`).
pub struct Graphed {
    /// Index into [`model::Model::parts`].
    pub part: usize,
    /// The graph.
    pub graph: graph::MeasurementGraph,
}

/// The margin fpoints keep from face edges for a plan: the largest tip radius of the
/// plan's machine (1 mm without a plan).
pub fn sampling_margin(model: &model::Model, plan: Option<&model::Plan>) -> f64 {
    let Some(plan) = plan else { return 1.0 };
    let cmm = &model.cmms[plan.cmm.0];
    cmm.probes
        .iter()
        .map(|(_, p)| model.styli[model.probes[p.0].stylus.0].tip / 2.0)
        .fold(0.0, f64::max)
        .max(1e-3)
}

/// The plan's probes as the sampler sees them (none without a plan): stylus length,
/// extensions and body, from the tip up.
pub fn probe_shanks(model: &model::Model, plan: Option<&model::Plan>) -> Vec<sample::Shank> {
    let Some(plan) = plan else { return Vec::new() };
    model.cmms[plan.cmm.0]
        .probes
        .iter()
        .map(|(_, p)| {
            let probe = &model.probes[p.0];
            let stylus = &model.styli[probe.stylus.0];
            let body = &model.bodies[probe.body.0];
            let extensions: Vec<(f64, f64)> = probe
                .extensions
                .iter()
                .rev()
                .map(|e| {
                    let e = &model.extensions[e.0];
                    (e.length, e.diameter / 2.0)
                })
                .collect();
            sample::Shank::new(
                stylus.length,
                &extensions,
                (body.length, body.diameter / 2.0),
            )
        })
        .collect()
}

/// Runs [`check_geometry`], then builds the measurement graph of every plan in the root
/// files, and of every root part no plan names. Sampling diagnostics join the others.
pub fn measurement_graphs(
    world: &dyn source::World,
    roots: &[PathBuf],
) -> (Checked, Vec<Option<PartData>>, Vec<Graphed>) {
    let (mut checked, parts) = check_geometry(world, roots);
    let graphs = graphs_of(&mut checked, &parts);
    (checked, parts, graphs)
}

/// The sampling and graph stage over a spec with geometry (see [`measurement_graphs`]).
fn graphs_of(checked: &mut Checked, parts: &[Option<PartData>]) -> Vec<Graphed> {
    let mut out = Vec::new();
    if checked.has_errors() {
        return out;
    }
    let model = &checked.model;
    let mut diags = diag::Diagnostics::new();
    let mut jobs: Vec<(usize, Option<&model::Plan>)> =
        model.plans.iter().map(|p| (p.part.0, Some(p))).collect();
    for (k, part) in model.parts.iter().enumerate() {
        if checked.roots.contains(&part.span.file) && !jobs.iter().any(|(j, _)| *j == k) {
            jobs.push((k, None));
        }
    }
    for (k, plan) in jobs {
        let Some(data) = &parts[k] else { continue };
        let sampling = match plan.map(|p| p.sampling).or(model.default_sampling) {
            Some(s) => &model.samplings[s.0],
            None => continue,
        };
        let input = graph::Input {
            part: &model.parts[k],
            geometry: &data.geometry,
            feature_faces: &data.feature_faces,
            plan: plan.map(|p| p.name.as_str()),
            sampling,
            overrides: plan.map_or(&[][..], |p| &p.overrides),
            margin: sampling_margin(model, plan),
            shanks: probe_shanks(model, plan),
            span: plan.map_or(model.parts[k].span, |p| p.span),
        };
        let mut built = graph::build(&input, &mut diags);
        if let Some(plan) = plan {
            built.sensors =
                graph::sensors::select(model, plan, &data.geometry, &data.feature_faces);
        }
        out.push(Graphed {
            part: k,
            graph: built,
        });
    }
    checked.absorb(diags);
    out
}

/// The names behind plan `plan`'s ids (its model and its part's geometry), when its
/// part's geometry was built.
pub fn plan_names<'a>(
    checked: &'a Checked,
    parts: &'a [Option<PartData>],
    plan: usize,
) -> Option<plan::Names<'a>> {
    let model = &checked.model;
    let data = parts.get(model.plans.get(plan)?.part.0)?.as_ref()?;
    Some(plan::Names::new(model, &data.geometry, model::PlanId(plan)))
}

/// One plan's result.
pub struct Planned {
    /// The plan, by index into [`model::Model::plans`].
    pub plan: usize,
    /// The HLIP, when planning succeeded.
    pub hlip: Option<plan::Hlip>,
}

/// Runs [`measurement_graphs`], then plans every plan of the root files. Parts the root
/// files declare that no plan names are an error: there is no machine to plan for.
/// Planning diagnostics join the others.
pub fn plans(
    world: &dyn source::World,
    roots: &[PathBuf],
    opts: &plan::PlanOptions,
) -> (Checked, Vec<Option<PartData>>, Vec<Graphed>, Vec<Planned>) {
    let (mut checked, parts, graphs) = measurement_graphs(world, roots);
    let out = plans_of(&mut checked, &parts, &graphs, opts);
    (checked, parts, graphs, out)
}

/// The planning stage over the measurement graphs (see [`plans`]).
fn plans_of(
    checked: &mut Checked,
    parts: &[Option<PartData>],
    graphs: &[Graphed],
    opts: &plan::PlanOptions,
) -> Vec<Planned> {
    let (out, each, _) = plan_each(checked, parts, graphs, opts);
    checked.absorb_all(each);
    out
}

/// [`plans_of`], keeping each plan's own diagnostics apart (the path stage may plan it
/// again); the others join `checked`.
fn plan_each(
    checked: &mut Checked,
    parts: &[Option<PartData>],
    graphs: &[Graphed],
    opts: &plan::PlanOptions,
) -> (Vec<Planned>, Vec<diag::Diagnostics>, Vec<plan::Memo>) {
    let mut out = Vec::new();
    let mut each = Vec::new();
    let mut memos = Vec::new();
    if checked.has_errors() {
        return (out, each, memos);
    }
    let mut diags = diag::Diagnostics::new();
    let model = &checked.model;
    for g in graphs {
        let Some(name) = &g.graph.plan else {
            let part = &model.parts[g.part];
            diags.push(plan::PlanError::NoPlan {
                span: part.span,
                part: part.name.clone(),
            });
            continue;
        };
        let Some(k) = model.plans.iter().position(|p| &p.name == name) else {
            continue;
        };
        let Some(data) = &parts[g.part] else { continue };
        if !plan::check_machine(model, &model.plans[k], &data.geometry, &mut diags) {
            continue;
        }
        let part = &model.parts[g.part];
        if part.tolerances.is_empty() {
            // A program that judges nothing is no inspection: refused, not written.
            diags.push(plan::PlanError::NoTolerance {
                span: model.plans[k].span,
                plan: name.clone(),
                part: part.name.clone(),
            });
            continue;
        }
        let input = plan::Input {
            model,
            plan: &model.plans[k],
            geometry: &data.geometry,
            fixtures: &data.fixtures,
            graph: &g.graph,
        };
        let mut own = diag::Diagnostics::new();
        let mut memo = plan::Memo::default();
        let hlip = plan::plan_with(&input, opts, &mut memo, &mut own);
        out.push(Planned { plan: k, hlip });
        each.push(own);
        memos.push(memo);
    }
    checked.absorb(diags);
    (out, each, memos)
}

/// One plan built: its HLIP, its paths and its DMIS program.
pub struct Built {
    /// The plan, by index into [`model::Model::plans`].
    pub plan: usize,
    /// The high-level plan.
    pub hlip: plan::Hlip,
    /// Its moves.
    pub llip: path::Llip,
    /// The DMIS program.
    pub dmis: String,
    /// The plan with its paths as JSON (`--plan-json`).
    pub json: serde_json::Value,
    /// The plan's measurement graph, when its `output { graph }` names a file: the text
    /// in the format that file's extension asks for.
    pub graph: Option<String>,
    /// Faces whose stand-offs keep less than the plan's margin, by name, with the least
    /// margin kept there (mm).
    pub tight: Vec<(String, f64)>,
}

/// Where a build's time went, stage by stage.
#[derive(Debug, Clone, Default)]
pub struct Timings {
    /// (stage, seconds), in pipeline order.
    pub stages: Vec<(&'static str, f64)>,
}

/// Reports a build's progress: (what, done, total).
pub type Progress<'a> = &'a (dyn Fn(&str, usize, usize) + Sync);

/// How far [`run`] goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Until {
    /// Front end, geometry and measurement graphs.
    Graph,
    /// On to plans, paths and DMIS.
    Build,
}

/// Everything one run of the pipeline produced, stage by stage.
pub struct Run {
    /// The front end's result and every diagnostic of the run.
    pub checked: Checked,
    /// Per part of the model, its geometry when built.
    pub parts: Vec<Option<PartData>>,
    /// The measurement graphs.
    pub graphs: Vec<Graphed>,
    /// Every plan that got through to a program.
    pub built: Vec<Built>,
    /// Where the time went.
    pub timings: Timings,
}

/// The whole pipeline: front end, geometry, graphs, plans, paths and DMIS. `Built` holds
/// every plan that got through; the caller writes nothing unless `Checked` has no errors.
pub fn build(
    world: &dyn source::World,
    roots: &[PathBuf],
    opts: &plan::PlanOptions,
    progress: Progress,
) -> (Checked, Vec<Built>, Timings) {
    let r = run(world, roots, opts, Until::Build, progress);
    (r.checked, r.built, r.timings)
}

/// The pipeline up to `until`, keeping every stage's result: what [`build`] runs, for
/// callers that want the intermediate results of the same run (the golden tests).
pub fn run(
    world: &dyn source::World,
    roots: &[PathBuf],
    opts: &plan::PlanOptions,
    until: Until,
    progress: Progress,
) -> Run {
    let mut t = Timings::default();
    let mut clock = std::time::Instant::now();
    let mut lap = |t: &mut Timings, stage: &'static str| {
        t.stages.push((stage, clock.elapsed().as_secs_f64()));
        clock = std::time::Instant::now();
    };
    progress("front end", 0, 1);
    let mut checked = check(world, roots);
    lap(&mut t, "front end");
    progress("geometry", 0, 1);
    let parts = geometry_of(world, &mut checked);
    lap(&mut t, "geometry");
    progress("measurement graph", 0, 1);
    let graphs = graphs_of(&mut checked, &parts);
    lap(&mut t, "graph");
    let mut run = Run {
        checked,
        parts,
        graphs,
        built: Vec::new(),
        timings: t,
    };
    if until < Until::Build {
        return run;
    }
    progress("planning", 0, 1);
    let (planned, each, memos) = plan_each(&mut run.checked, &run.parts, &run.graphs, opts);
    lap(&mut run.timings, "plan");
    if run.checked.has_errors() || each.iter().any(|d| d.has_errors()) {
        run.checked.absorb_all(each);
        return run;
    }
    let paths = paths_of(&mut run, planned, each, memos, opts, progress);
    lap(&mut run.timings, "paths");
    if run.checked.has_errors() {
        return run;
    }
    progress("dmis", 0, 1);
    run.built = programs_of(&run, paths);
    lap(&mut run.timings, "dmis");
    run
}

/// How many times a plan whose touches the path stage cannot reach is planned again.
/// Each re-plan bans what the last could not route; a block with a through passage or
/// a tunnel (MFCAD parts) takes up to a dozen before every touch has a way in and up,
/// and a part that routes at once never pays for the budget.
const REPLANS: usize = 16;

/// The plan, part and moves of each plan whose paths were planned.
type Pathed = Vec<(usize, usize, plan::Hlip, path::Llip)>;

/// The path stage over the plans (see [`run`]).
///
/// A touch no collision-free move reaches sends its plan back to the planner with that
/// configuration failing validation (at most [`REPLANS`] times): generate-and-test with
/// the path stage as one more test. The diagnostics of the last try are kept.
fn paths_of(
    run: &mut Run,
    planned: Vec<Planned>,
    each: Vec<diag::Diagnostics>,
    memos: Vec<plan::Memo>,
    opts: &plan::PlanOptions,
    progress: Progress,
) -> Pathed {
    let mut diags = diag::Diagnostics::new();
    let mut paths = Vec::new();
    for ((p, mut own), mut memo) in planned.into_iter().zip(each).zip(memos) {
        let Some(mut hlip) = p.hlip else {
            diags.extend(own);
            continue;
        };
        let plan = &run.checked.model.plans[p.plan];
        let Some(g) = run
            .graphs
            .iter()
            .find(|g| g.graph.plan.as_deref() == Some(&plan.name))
        else {
            continue;
        };
        let Some(data) = &run.parts[g.part] else {
            continue;
        };
        let input = plan::Input {
            model: &run.checked.model,
            plan,
            geometry: &data.geometry,
            fixtures: &data.fixtures,
            graph: &g.graph,
        };
        let report = |done: usize, total: usize| progress("paths", done, total);
        let mut bans_all: Vec<plan::Ban> = Vec::new();
        for attempt in 0.. {
            let mut moves = diag::Diagnostics::new();
            let mut bans = Vec::new();
            let scene = memo.scene(input.geometry);
            let llip = path::plan(&input, &hlip, &scene, &report, &mut moves, &mut bans);
            // A plan validated with the part turned (robust to it set off square) that
            // the path stage could not route after every re-plan gives way to one more,
            // validated at the nominal pose only: one the path stage routes, whose
            // setups say how square to set the part.
            let last = attempt >= REPLANS && !(attempt == REPLANS && memo.turned());
            if llip.is_some() || bans.is_empty() || last {
                diags.extend(own);
                diags.extend(moves);
                if let Some(llip) = llip {
                    paths.push((p.plan, g.part, hlip, llip));
                }
                break;
            }
            let bans = plan::Ban::widen(bans, &bans_all);
            bans_all.extend(bans);
            if attempt == REPLANS {
                memo.give_up_turned();
            }
            let again = plan::PlanOptions {
                bans: bans_all.clone(),
                ..opts.clone()
            };
            let mut replanned = diag::Diagnostics::new();
            match plan::plan_with(&input, &again, &mut memo, &mut replanned) {
                Some(h) => {
                    hlip = h;
                    own = replanned;
                }
                None => {
                    diags.extend(replanned);
                    diags.extend(moves);
                    break;
                }
            }
        }
    }
    run.checked.absorb(diags);
    paths
}

/// The DMIS stage: one program per planned path (see [`run`]).
fn programs_of(run: &Run, paths: Pathed) -> Vec<Built> {
    let checked = &run.checked;
    let mut out = Vec::new();
    for (k, part, hlip, llip) in paths {
        let Some(data) = &run.parts[part] else {
            continue;
        };
        let dmis = dmis::write(&dmis::Input {
            model: &checked.model,
            plan: &checked.model.plans[k],
            geometry: &data.geometry,
            hlip: &hlip,
            llip: &llip,
            source: checked
                .sources
                .get(checked.model.plans[k].span.file)
                .path
                .as_deref()
                .and_then(|p| p.file_name())
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default(),
        });
        let names = plan::Names::new(&checked.model, &data.geometry, hlip.plan);
        let json = path::json(&hlip, &llip, &names);
        let plan = &checked.model.plans[k];
        let graph = plan.outputs.graph.as_deref().and_then(|file| {
            let g = run
                .graphs
                .iter()
                .find(|g| g.graph.plan.as_deref() == Some(&plan.name))?;
            let p = &checked.model.parts[part];
            let ext = std::path::Path::new(file).extension();
            Some(match ext.and_then(|e| e.to_str()) {
                Some("mmd") => graph::mermaid(p, &data.geometry, &g.graph, false),
                Some("json") => {
                    let v = graph::json(p, &data.geometry, &g.graph);
                    serde_json::to_string_pretty(&v).unwrap_or_default() + "\n"
                }
                _ => graph::dot(p, &data.geometry, &g.graph, false),
            })
        });
        let tight = llip
            .summary
            .tight
            .iter()
            .map(|(f, m)| (names.face(*f).to_string(), *m))
            .collect();
        out.push(Built {
            plan: k,
            hlip,
            llip,
            dmis,
            json,
            graph,
            tight,
        });
    }
    out
}

/// Runs the front end (load, parse, resolve) over root files.
pub fn check(world: &dyn source::World, roots: &[PathBuf]) -> Checked {
    let mut sources = source::SourceMap::new();
    let mut diags = diag::Diagnostics::new();
    let program = load::load(world, roots, &mut sources, &mut diags);
    let model = resolve::resolve(&program, &sources, world, &mut diags);
    let roots = program
        .modules
        .iter()
        .filter(|m| m.root)
        .map(|m| m.file)
        .collect();
    Checked {
        model,
        diagnostics: diags.sorted(),
        sources,
        roots,
        program,
    }
}

/// Reads a file a run names outside the spec (a program, a deviations file) into the
/// source map; an unreadable one is still added, empty, for its diagnostic to point at.
fn read_beside(
    world: &dyn source::World,
    checked: &mut Checked,
    path: &Path,
    kind: source::FileKind,
) -> Result<source::FileId, source::io::IoError> {
    let shown = path.display().to_string();
    match world.read(path, kind) {
        Ok(b) => {
            let text = String::from_utf8_lossy(&b).into_owned();
            Ok(checked.sources.add(shown, Some(path.to_path_buf()), text))
        }
        Err(e) => {
            let file = checked
                .sources
                .add(shown.clone(), Some(path.to_path_buf()), String::new());
            Err(source::io::IoError::Unreadable {
                file,
                path: shown,
                reason: e.0,
            })
        }
    }
}

/// A program run on the virtual CMM (see [`simulate`]).
pub struct Simulated {
    /// The spec's front end and every diagnostic of the run (the program's and the
    /// deviations file's problems included, filed under their files).
    pub checked: Checked,
    /// The report, when the program ran to its end.
    pub report: Option<simulate::Report>,
}

/// Runs DMIS program `program` on the virtual CMM against the part of spec `spec` (the
/// plan whose name the program carries), deformed and placed as `deviations` says.
pub fn simulate(
    world: &dyn source::World,
    spec: &Path,
    program: &Path,
    deviations: Option<&Path>,
    opts: &simulate::Options,
) -> Simulated {
    let (mut checked, parts) = check_geometry(world, &[spec.to_path_buf()]);
    let mut diags = diag::Diagnostics::new();
    let read = |checked: &mut Checked, path: &Path, kind: source::FileKind| {
        read_beside(world, checked, path, kind)
    };
    let finish = |mut checked: Checked, diags: diag::Diagnostics, report| {
        checked.absorb(diags);
        Simulated { checked, report }
    };
    if checked.has_errors() {
        return Simulated {
            checked,
            report: None,
        };
    }
    let dmi = match read(&mut checked, program, source::FileKind::Dmis) {
        Ok(id) => id,
        Err(e) => {
            diags.push(e);
            return finish(checked, diags, None);
        }
    };
    let text = checked.sources.get(dmi).text.clone();
    let mut prog = match dmis::read(dmi, &text) {
        Ok(p) => p,
        Err(errors) => {
            for e in errors {
                diags.push(e);
            }
            return finish(checked, diags, None);
        }
    };
    for w in std::mem::take(&mut prog.warnings) {
        diags.push(w);
    }
    let plan = match simulate::plan_of(&checked.model, &prog, dmi, &text) {
        Ok(k) => k,
        Err(e) => {
            diags.push(e);
            return finish(checked, diags, None);
        }
    };
    let part = checked.model.plans[plan].part.0;
    let Some(data) = parts.get(part).and_then(|p| p.as_ref()) else {
        return finish(checked, diags, None);
    };
    let deviations = match deviations {
        None => simulate::Deviations::nominal(data.geometry.faces.len()),
        Some(path) => {
            let id = match read(&mut checked, path, source::FileKind::Spec) {
                Ok(id) => id,
                Err(e) => {
                    diags.push(e);
                    return finish(checked, diags, None);
                }
            };
            let dtext = checked.sources.get(id).text.clone();
            match simulate::deviation::parse(
                id,
                &dtext,
                &checked.model.parts[part],
                &data.geometry,
                &data.feature_faces,
            ) {
                Ok(d) => d,
                Err(errors) => {
                    for e in errors {
                        diags.push(e);
                    }
                    return finish(checked, diags, None);
                }
            }
        }
    };
    let input = simulate::Input {
        model: &checked.model,
        geometry: &data.geometry,
        feature_faces: &data.feature_faces,
        fixtures: &data.fixtures,
        program: &prog,
        file: dmi,
        text: &text,
        deviations: &deviations,
    };
    let report = match simulate::simulate(&input, opts) {
        Ok(r) => Some(r),
        Err(errors) => {
            for e in errors {
                diags.push(e);
            }
            None
        }
    };
    finish(checked, diags, report)
}

/// A spec's programs tried on the virtual CMM (see [`verify()`]).
pub struct Verified {
    /// The spec's front end and every diagnostic of the build and the runs.
    pub checked: Checked,
    /// Per program, the battery's results.
    pub results: Vec<verify::Verification>,
}

/// Runs the battery of [`verify`] on the program `program` of spec `spec`, or on every
/// plan of the spec built afresh when no program is given.
pub fn verify(
    world: &dyn source::World,
    spec: &Path,
    program: Option<&Path>,
    plan_opts: &plan::PlanOptions,
    opts: &verify::Options,
) -> Verified {
    let roots = [spec.to_path_buf()];
    let (mut checked, parts, programs) = match program {
        None => {
            let mut r = run(world, &roots, plan_opts, Until::Build, &|_, _, _| {});
            let programs: Vec<(source::FileId, String)> = r
                .built
                .iter()
                .map(|b| {
                    let name = format!("{}.dmi", r.checked.model.plans[b.plan].name);
                    let id = r.checked.sources.add(name, None, b.dmis.clone());
                    (id, b.dmis.clone())
                })
                .collect();
            (r.checked, r.parts, programs)
        }
        Some(path) => {
            let (mut checked, parts) = check_geometry(world, &roots);
            match read_beside(world, &mut checked, path, source::FileKind::Dmis) {
                Ok(id) => {
                    let text = checked.sources.get(id).text.clone();
                    (checked, parts, vec![(id, text)])
                }
                Err(e) => {
                    let mut diags = diag::Diagnostics::new();
                    diags.push(e);
                    checked.absorb(diags);
                    return Verified {
                        checked,
                        results: Vec::new(),
                    };
                }
            }
        }
    };
    let mut diags = diag::Diagnostics::new();
    let mut results = Vec::new();
    for (file, text) in programs {
        if checked.has_errors() {
            break;
        }
        if let Some(v) = verify_program(&checked.model, &parts, file, &text, opts, &mut diags) {
            results.push(v);
        }
    }
    checked.absorb(diags);
    Verified { checked, results }
}

/// The battery on one program of a built [`Run`] (the golden cases' `verify.txt`).
pub fn verify_built(
    run: &Run,
    built: &Built,
    opts: &verify::Options,
) -> Option<verify::Verification> {
    let mut diags = diag::Diagnostics::new();
    let file = source::FileId(u32::MAX);
    verify_program(
        &run.checked.model,
        &run.parts,
        file,
        &built.dmis,
        opts,
        &mut diags,
    )
}

/// The battery on a program's text; what stops it before any run is a diagnostic.
fn verify_program(
    model: &model::Model,
    parts: &[Option<PartData>],
    file: source::FileId,
    text: &str,
    opts: &verify::Options,
    diags: &mut diag::Diagnostics,
) -> Option<verify::Verification> {
    let prog = match dmis::read(file, text) {
        Ok(p) => p,
        Err(errors) => {
            for e in errors {
                diags.push(e);
            }
            return None;
        }
    };
    let plan = match simulate::plan_of(model, &prog, file, text) {
        Ok(k) => k,
        Err(e) => {
            diags.push(e);
            return None;
        }
    };
    let part = model.plans[plan].part.0;
    let data = parts.get(part).and_then(|p| p.as_ref())?;
    let nominal = simulate::Deviations::nominal(data.geometry.faces.len());
    let bench = verify::Bench {
        part,
        sim: simulate::Input {
            model,
            geometry: &data.geometry,
            feature_faces: &data.feature_faces,
            fixtures: &data.fixtures,
            program: &prog,
            file,
            text,
            deviations: &nominal,
        },
    };
    Some(verify::verify(&bench, opts))
}
