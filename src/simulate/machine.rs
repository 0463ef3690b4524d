//! The virtual CMM's interpreter: one pass over the program's statements.
//!
//! Sensors are matched to the plan's probes by tip and length. Each setup's `RECALL` of
//! the machine's frame and its `ROTATE`s before its `PAUSE` give the part's nominal
//! place (the operator's placement error from the deviations on top); manual touches
//! land where the program shows them on the part; every move under `MODE/PROG` is swept
//! by `access::Pose` (part, table under the setup's holder, fixture). Each `PTMEAS` is
//! searched from its approach point along its vector on the face the ball's foot meets
//! in the mesh, and solved exactly on that face's deviated analytic surface (a
//! free-form face: the ball swept against its moved triangles); where the ball cannot
//! reach that face (a corner radius hardly larger than the ball, the part set off by
//! more than the ball's play in it) it stops where it first meets another face whose
//! facets lie near its path, on that face's actual surface, as a machine's probe does.
//! The approach is then checked against the nominal mesh from where the tip stops, or
//! from where the ball clears the touched face's nominal triangles when that face lies
//! deeper. Features are fitted to tip centres and offset by the tip radius; `CONST`
//! makes best fits, centre planes and patterns (a datum of parallel bores is their mean
//! axis through the centroid of their axes, the members giving its clocking); `DATSET`
//! takes directions primary first, then secondary projected, origins at the feature's
//! location along each axis named and the rest from the current frame.
//!
//! A scanner (`SNSDEF/LASER`) runs `PAMEAS` along a `PATH/LINE`: the housing swept from
//! start to end, the stripe sampled at the scanner's spacing (thinned evenly to
//! `CLOUD`, about 40 stripes of 10 points a pass) by rays along its direction onto the
//! actual surfaces, a point kept within the depth of field, seen by laser and camera
//! (`access::scan::sees`) and on a face whose surface is the block's nominal, with the
//! scanner's noise. A program written elsewhere (NIST's `simple_in.dms`) runs against
//! the spec's only plan whatever its `DMISMN` says: its first setup starts at its first
//! motion where its alignment puts the part (`DATSET/MCS`, the machine's frame), the
//! probe it selects first is on the ram before its first `SNSLCT`, fixed probes match
//! in either `SNSDEF` sign convention, and `FEAT/CIRCLE` is fitted as a cylinder's
//! section about the nominal axis.
//!
//! A distance to a drilled hole's full diameter
//! (`CONST/CIRCLE,F(c),INTOF,FA(bore),FA(cone)`, see the DMIS writer) intersects the
//! measured cone with the measured bore's radius (`full_diameter`).

use super::deviation::Deviations;
use super::errors::SimError;
use super::evaluate::{self, Measured, TolDef};
use super::fit::{self, Shape};
use super::number;
use super::report::{FeatureRow, Report, Row};
use super::{Input, Options};
use crate::access::pose::{Blocker, Contact, Pose, Solid};
use crate::access::scan::{Optics, ScannerShape};
use crate::access::{ProbeShape, Scene};
use crate::dmis::{Program, Statement};
use crate::geometry::{FaceId, P3, V3};
use crate::model::{Model, Plan};
use crate::plan::poses::Setups;
use crate::source::Span;
use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, Unit, UnitQuaternion};
use parry3d_f64::bounding_volume::{Aabb, BoundingVolume};
use parry3d_f64::query::{cast_shapes, PointQuery, Ray, RayCast, ShapeCastOptions};
use parry3d_f64::shape::{Ball, Triangle};
use std::collections::{BTreeMap, BTreeSet};

/// What the virtual CMM runs.
const SUPPORTED: &str = "DMISMN, DMISMD, FILNAM, UNITS/MM, MODE, FEDRAT, PRCOMP, SNSET, SNSDEF, SNSLCT, FEAT (PLANE, LINE, POINT, CIRCLE, CYLNDR, CONE, SPHERE, PARPLN, PATERN, GSURF), TOL, TEXT, PAUSE, SAVE, RECALL, ROTATE, DATSET, TRANS, GOTO, MEAS, PTMEAS, PATH/LINE, PAMEAS, ENDMES, CONST, DATDEF, OUTPUT, ENDFIL";

/// How far the surface of the face a scanned point lies on may be from the block's
/// nominal (mm, and per mm for directions) for the point to be the feature's: the
/// clipping of the cloud to the feature, as scanning software does per feature.
const CLIP: f64 = 2e-3;

/// The most stripes and points per stripe one simulated pass keeps: the cloud thinned
/// from the scanner's spacing evenly, which a fit at nominal does not notice.
const CLOUD: (usize, usize) = (40, 10);

/// The step of the contact search along a touch's vector (mm); the contact is then
/// bisected to a nanometre.
const SEARCH_STEP: f64 = 0.01;

/// The plan (index into `model.plans`) that wrote `program`: the one whose name its
/// `DMISMN` carries, or the spec's only plan.
pub fn plan_of(
    model: &Model,
    program: &Program,
    file: crate::source::FileId,
    text: &str,
) -> Result<usize, SimError> {
    let (name, at) = program
        .statements
        .iter()
        .find_map(|s| match s {
            Statement::Command {
                major, params, at, ..
            } if major == "DMISMN" => Some((
                params
                    .first()
                    .map(|p| p.trim_matches('\'').to_string())
                    .unwrap_or_default(),
                *at,
            )),
            _ => None,
        })
        .unwrap_or_default();
    // A program written elsewhere names itself, not a plan of ours: with one plan in
    // the spec, that plan's part, machine and setups are the ones it runs on.
    let found = model
        .plans
        .iter()
        .position(|p| crate::dmis::text::plain(&p.name, 60) == name)
        .or_else(|| (model.plans.len() == 1).then_some(0));
    found.ok_or_else(|| SimError::NoPlan {
        span: line_span(file, text, at),
        program: name,
        plans: if model.plans.is_empty() {
            "none".into()
        } else {
            model
                .plans
                .iter()
                .map(|p| format!("`{}`", p.name))
                .collect::<Vec<_>>()
                .join(", ")
        },
    })
}

fn line_span(file: crate::source::FileId, text: &str, at: usize) -> Span {
    let at = at.min(text.len());
    let end = text[at..].find('\n').map_or(text.len(), |e| at + e);
    Span::new(file, at, end.max(at))
}

/// The point of a block's nominal surface nearest `x` (program frame): along the
/// shape's normal for a plane, cylinder, cone or sphere; on the nominal mesh for a
/// free-form surface (or none known); `x` itself when neither says.
fn nominal_foot(nominal: Option<&Shape>, mesh: Option<&parry3d_f64::shape::TriMesh>, x: &P3) -> P3 {
    if let Some(shape) = nominal.filter(|s| !matches!(s, Shape::Surface)) {
        if let Some(n) = shape.normal_at(x) {
            return x - n * shape.signed(x);
        }
    }
    match mesh {
        Some(m) => m.project_local_point(x, false).point,
        None => *x,
    }
}

/// A feature measured, in the machine frame of its setup.
#[derive(Debug, Clone)]
struct Stored {
    m: Measured,
    /// Its setup, from 1.
    setup: usize,
}

/// A measured feature and its label.
type Labelled = (Stored, String);

/// The setup the part stands in.
struct SetupCtx {
    /// Part frame → machine.
    place: Isometry3<f64>,
    /// The ram direction in the part frame.
    up: V3,
    /// The table's height along `up` (part frame).
    table: f64,
    /// The fixture's solids (part frame).
    solids: Vec<Solid>,
}

/// An open `MEAS` block.
struct Block {
    label: String,
    word: String,
    /// (nominal point, nominal vector — program frame —, tip centre and vector —
    /// machine frame —, tip radius).
    touches: Vec<(P3, V3, P3, V3, f64)>,
    at: usize,
    /// Whether a scan pass ran in it.
    scanned: bool,
}

/// What `DATSET`'s keywords ask for: directions by axis (0 for x), and the shapes that
/// give the origin along an axis.
type DatsetTargets = (Vec<(usize, V3)>, Vec<(usize, Shape)>);

/// One scan pass of `PAMEAS`, in the part frame of its setup.
struct Pass {
    /// Where it starts, and the run to its end.
    start: P3,
    run: V3,
    /// The scanner's direction (from the surface towards it), and across its stripe.
    dir: V3,
    across: V3,
    optics: Optics,
    /// The block's nominal, which the points kept lie on.
    nominal: Option<Shape>,
    /// Part frame → machine.
    place: Isometry3<f64>,
}

/// A nominal from `FEAT`: its shape (program frame) and whether it is convex.
#[derive(Debug, Clone)]
struct Nominal {
    shape: Shape,
    convex: bool,
    /// The `FEAT` word (`CIRCLE`, `PLANE`, …) and its numbers after `CART`.
    word: String,
    numbers: Vec<f64>,
}

/// A sensor: its probe (slot) and head angles.
#[derive(Debug, Clone, Copy)]
struct Sensor {
    slot: usize,
    a: f64,
    b: f64,
}

/// splitmix64 with Box–Muller: a small, portable, seeded Gaussian source.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        ((z >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    fn gauss(&mut self) -> f64 {
        let (u, v) = (self.next(), self.next());
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
    }
}

struct Machine<'a> {
    input: &'a Input<'a>,
    opts: Options,
    plan: &'a Plan,
    scene: Scene,
    setups: Setups<'a>,
    /// The sensors by slot: the rack's probes, then its scanners (no tip).
    probes: Vec<ProbeShape>,
    /// Per slot, a scanner's optics and accuracy (`None` for a probe).
    optics: Vec<Option<(Optics, f64)>>,
    /// `PATH/LINE`s by label: start, end (program frame).
    paths: BTreeMap<String, (P3, P3)>,
    exact: Vec<V3>,
    centre: P3,
    apprch: f64,
    retrct: f64,
    search: f64,
    manual: bool,
    sensors: BTreeMap<String, Sensor>,
    sensor: Option<Sensor>,
    /// The probe on the ram when the program starts: the one it selects first. A
    /// program may move before its first `SNSLCT` (NIST's `simple_in.dms` does); the
    /// machine moves whatever is mounted, and a program that selects a probe first
    /// selects the one it expects to be there.
    mounted: Option<Sensor>,
    nominals: BTreeMap<String, Nominal>,
    tols: BTreeMap<String, TolDef>,
    /// Per tolerance, its `2D`/`3D`, material words and datum references as written.
    tol_words: BTreeMap<String, Vec<String>>,
    /// Program → machine: the current alignment.
    frame: Isometry3<f64>,
    saved: BTreeMap<String, Isometry3<f64>>,
    /// Labels of the machine's own frame (`D(x)=DATSET/MCS`): recalling one leaves the
    /// setups, as `RECALL/D(MCS)` does.
    machine_frames: BTreeSet<String>,
    setup: Option<SetupCtx>,
    /// Per setup, its latest alignment.
    aligns: Vec<Isometry3<f64>>,
    /// Between setups: after a `RECALL`, before the next `PAUSE`, alignments belong to
    /// the setup to come.
    between: bool,
    actuals: BTreeMap<String, Stored>,
    /// Per datum label: the feature `DATDEF` names and, for a pattern, its members
    /// after it (they give its clocking).
    datums: BTreeMap<String, Vec<Labelled>>,
    /// Per pattern (`FEAT/PATERN`), its members' labels.
    patterns: BTreeMap<String, Vec<String>>,
    block: Option<Block>,
    /// The tip centre (part frame), when known.
    at: Option<P3>,
    rng: Rng,
    rows: Vec<Row>,
    /// The features output, each once, as it was when first output.
    features: Vec<FeatureRow>,
    sizes: BTreeMap<String, (f64, f64, f64)>,
    touches: usize,
    /// Points the scan passes kept.
    scanned: usize,
    moves: usize,
}

/// Runs the program on the virtual CMM; the first problem stops the run, as on a
/// machine.
pub fn simulate(input: &Input, opts: &Options) -> Result<Report, Vec<SimError>> {
    let k = plan_of(input.model, input.program, input.file, input.text).map_err(|e| vec![e])?;
    let plan = &input.model.plans[k];
    let cmm = &input.model.cmms[plan.cmm.0];
    let setups = Setups::new(input.model, plan, input.geometry, input.fixtures);
    let exact = setups.exact_dirs();
    let (lo, hi) = input.geometry.bounds();
    let mut m = Machine {
        input,
        opts: *opts,
        plan,
        scene: Scene::of_part(input.geometry),
        setups,
        probes: ProbeShape::of_cmm(input.model, cmm)
            .into_iter()
            .chain(
                ScannerShape::of_cmm(input.model, cmm)
                    .into_iter()
                    .map(|s| s.probe),
            )
            .collect(),
        optics: cmm
            .probes
            .iter()
            .map(|_| None)
            .chain(
                ScannerShape::of_cmm(input.model, cmm)
                    .into_iter()
                    .zip(&cmm.scanners)
                    .map(|(s, (_, id))| Some((s.optics, input.model.scanners[id.0].accuracy))),
            )
            .collect(),
        paths: BTreeMap::new(),
        exact,
        centre: P3::from((lo.coords + hi.coords) / 2.0),
        apprch: 2.0,
        retrct: 2.0,
        search: 4.0,
        manual: false,
        sensors: BTreeMap::new(),
        sensor: None,
        mounted: None,
        nominals: BTreeMap::new(),
        tols: BTreeMap::new(),
        tol_words: BTreeMap::new(),
        frame: Isometry3::identity(),
        saved: BTreeMap::new(),
        machine_frames: BTreeSet::new(),
        setup: None,
        aligns: Vec::new(),
        between: false,
        actuals: BTreeMap::new(),
        datums: BTreeMap::new(),
        patterns: BTreeMap::new(),
        block: None,
        at: None,
        rng: Rng(opts.seed ^ 0x5EED_1A5E_D00D_F00D),
        rows: Vec::new(),
        features: Vec::new(),
        sizes: BTreeMap::new(),
        touches: 0,
        scanned: 0,
        moves: 0,
    };
    m.mounted = m.first_selected().map_err(|e| vec![e])?;
    for s in &input.program.statements {
        let Statement::Command {
            label,
            major,
            params,
            at,
        } = s
        else {
            continue;
        };
        m.statement(label.as_ref(), major, params, *at)
            .map_err(|e| vec![e])?;
    }
    let missing = input.deviations.missing_setups(m.aligns.len());
    if !missing.is_empty() {
        return Err(missing);
    }
    let program = input
        .program
        .commands("DMISMN")
        .next()
        .and_then(|p| p.first())
        .map(|p| p.trim_matches('\'').to_string())
        .unwrap_or_default();
    let filnam = input
        .program
        .commands("FILNAM")
        .next()
        .and_then(|p| p.first())
        .map(|p| p.trim_matches('\'').to_string())
        .unwrap_or_else(|| program.clone());
    Ok(Report {
        filnam,
        program: input
            .program
            .commands("DMISMN")
            .next()
            .and_then(|p| p.first())
            .map(|p| p.trim_matches('\'').to_string())
            .unwrap_or_default(),
        plan: plan.name.clone(),
        part: input.model.parts[plan.part.0].name.clone(),
        setups: m.aligns.len(),
        touches: m.touches,
        scanned: m.scanned,
        moves: m.moves,
        noise: opts.noise,
        seed: opts.seed,
        rows: m.rows,
        features: m.features,
    })
}

fn label_of(p: &str) -> Option<&str> {
    let (_, rest) = p.split_once('(')?;
    rest.strip_suffix(')')
}

/// The `k`th parameter, or nothing.
fn param(params: &[String], k: usize) -> &str {
    params.get(k).map(String::as_str).unwrap_or("")
}

/// The numbers among a statement's parameters, in order (its words left out).
fn nums(params: &[String]) -> Vec<f64> {
    params.iter().filter_map(|p| number::value(p)).collect()
}

impl Machine<'_> {
    fn span(&self, at: usize) -> Span {
        line_span(self.input.file, self.input.text, at)
    }

    fn bad(&self, at: usize, what: &str, help: &str) -> SimError {
        SimError::BadStatement {
            span: self.span(at),
            what: what.into(),
            help: help.into(),
        }
    }

    fn statement(
        &mut self,
        label: Option<&(String, String)>,
        major: &str,
        params: &[String],
        at: usize,
    ) -> Result<(), SimError> {
        if crate::dmis::word(major) != crate::dmis::Word::Runs {
            // The reader warned on it: DMIS the virtual CMM does not run, or not DMIS.
            return Ok(());
        }
        // Every number a statement gives is read here, once, for all statements (see
        // `number`): what reads them later sees only usable numbers.
        for p in params {
            if let Err(why) = number::number(p) {
                return Err(self.bad(at, &format!("{major} with {}", why.what(p)), &why.help()));
            }
        }
        match major {
            // What a real controller needs and a virtual one has no use for: names, feed
            // rates, probe compensation (always on here), the work plane, the results
            // file (the report goes where `--report` says).
            "DMISMN" | "DMISMD" | "FILNAM" | "TEXT" | "ENDFIL" | "FEDRAT" | "ACLRAT" | "PRCOMP"
            | "WKPLAN" | "DECPL" | "DEVICE" | "OPEN" | "CLOSE" | "DISPLY" | "PARTID" | "PARTRV"
            | "PARTSN" | "PLANID" => {}
            "SAVE" => {
                for p in params {
                    if let Some(l) = label_of(p) {
                        self.saved.insert(l.to_string(), self.frame);
                    }
                }
            }
            "UNITS" => {
                if param(params, 0) != "MM" {
                    return Err(self.unsupported(at, &format!("UNITS/{}", params.join(","))));
                }
            }
            "MODE" => {
                self.manual =
                    params.iter().any(|p| p == "MAN") && !params.iter().any(|p| p == "PROG");
                self.at = None;
            }
            "SNSET" => self.snset(params, at)?,
            "SNSDEF" => self.snsdef(label, params, at)?,
            "SNSLCT" => self.snslct(params, at)?,
            "FEAT" => self.feat(label, params, at)?,
            "TOL" => self.tol(label, params, at)?,
            // A `PAUSE` after the part was let go (`RECALL` of the machine's frame), or
            // before any setup, is the next setup's placing; any other waits for the
            // operator (a probe changed by hand), who may move the ram meanwhile.
            "PAUSE" if self.setup.is_none() || self.between => self.start_setup(at)?,
            "PAUSE" => self.at = None,
            "RECALL" => self.recall(label, params, at)?,
            "ROTATE" => self.rotate(label, params, at)?,
            // `DATSET/MCS`: the machine's own axes and origin (NIST's `simple_in.dms`).
            "DATSET" if params.len() == 1 && params[0] == "MCS" => {
                self.frame = Isometry3::identity();
                if let Some((_, l)) = label {
                    self.machine_frames.insert(l.clone());
                }
                self.realigned(label);
            }
            "DATSET" => {
                self.frame = self.datset(params, at)?;
                self.realigned(label);
            }
            "TRANS" => self.trans(label, params, at)?,
            "GOTO" => self.goto(params, at)?,
            "MEAS" => {
                let l = params
                    .get(1)
                    .and_then(|p| label_of(p))
                    .unwrap_or("")
                    .to_string();
                self.block = Some(Block {
                    label: l,
                    word: param(params, 0).to_string(),
                    touches: Vec::new(),
                    at,
                    scanned: false,
                });
            }
            "PTMEAS" => self.ptmeas(params, at)?,
            "PATH" => {
                let v = nums(params);
                let (Some((_, l)), "LINE", 9) = (label, param(params, 0), v.len()) else {
                    return Err(self.unsupported(at, &format!("PATH/{}", params.join(","))));
                };
                let (a, b) = (P3::new(v[0], v[1], v[2]), P3::new(v[3], v[4], v[5]));
                self.paths.insert(l.clone(), (a, b));
            }
            "PAMEAS" => self.pameas(params, at)?,
            "ENDMES" => self.endmes(at)?,
            "CONST" => self.construct(params, at)?,
            "DATDEF" => self.datdef(params, at)?,
            "OUTPUT" => self.output(params, at)?,
            other => return Err(self.unsupported(at, other)),
        }
        Ok(())
    }

    /// `SNSET/APPRCH|RETRCT|SEARCH|CLRSRF,d`: the touch distances (a clearance
    /// surface is the controller's own business).
    fn snset(&mut self, params: &[String], at: usize) -> Result<(), SimError> {
        let v = nums(&params[1.min(params.len())..]).first().copied();
        match (param(params, 0), v) {
            ("APPRCH", Some(v)) => self.apprch = v,
            ("RETRCT", Some(v)) => self.retrct = v,
            ("SEARCH", Some(v)) => self.search = v,
            ("CLRSRF", Some(_)) => {}
            _ => return Err(self.unsupported(at, &format!("SNSET/{}", params.join(",")))),
        }
        Ok(())
    }

    /// `S(label)=SNSDEF/…`: the rack's sensor of that definition, under its label.
    fn snsdef(
        &mut self,
        label: Option<&(String, String)>,
        params: &[String],
        at: usize,
    ) -> Result<(), SimError> {
        let Some((_, l)) = label else {
            return Err(self.bad(at, "SNSDEF without a label", "write `S(label)=SNSDEF/…`"));
        };
        let s = self.sensor_def(l, params, at)?;
        self.sensors.insert(l.clone(), s);
        Ok(())
    }

    /// `SNSLCT/S(label)`: the sensor defined under that label, on the ram.
    fn snslct(&mut self, params: &[String], at: usize) -> Result<(), SimError> {
        let l = params.first().and_then(|p| label_of(p)).unwrap_or("");
        let Some(s) = self.sensors.get(l).copied() else {
            return Err(self.bad(
                at,
                &format!("sensor `{l}` is not defined"),
                "define it with SNSDEF first",
            ));
        };
        self.sensor = Some(s);
        self.at = None;
        Ok(())
    }

    /// `F(label)=FEAT/…`: a feature's nominal, a pattern's from its members'.
    fn feat(
        &mut self,
        label: Option<&(String, String)>,
        params: &[String],
        at: usize,
    ) -> Result<(), SimError> {
        let Some((_, l)) = label else {
            return Err(self.bad(at, "FEAT without a label", "write `F(label)=FEAT/…`"));
        };
        if param(params, 0) == "PATERN" {
            let (n, members) = self.pattern(params, at)?;
            self.nominals.insert(l.clone(), n);
            self.patterns.insert(l.clone(), members);
        } else {
            let n = nominal(params)
                .ok_or_else(|| self.unsupported(at, &format!("FEAT/{}", param(params, 0))))?;
            if let Some(what) = sizeless(&n.shape) {
                return Err(self.bad(
                    at,
                    &format!("FEAT/{} with {what}", n.word),
                    "a nominal feature's size is positive (a cone's angle under 180°)",
                ));
            }
            self.nominals.insert(l.clone(), n);
        }
        Ok(())
    }

    /// `FEAT/PATERN,F(m1),F(m2),…`: the pattern's nominal, fitted to its members'
    /// (cylinders defined before it), and their labels.
    fn pattern(&self, params: &[String], at: usize) -> Result<(Nominal, Vec<String>), SimError> {
        let members: Vec<String> = params[1..]
            .iter()
            .filter_map(|p| label_of(p))
            .map(str::to_string)
            .collect();
        let shapes: Vec<Shape> = members
            .iter()
            .filter_map(|m| self.nominals.get(m).map(|n| n.shape.clone()))
            .collect();
        let shape = (shapes.len() == members.len())
            .then(|| fit::pattern(&shapes))
            .flatten()
            .ok_or_else(|| {
                self.bad(
                    at,
                    "a pattern's members must be cylinders defined before it",
                    "write `F(p)=FEAT/PATERN,F(bore1),F(bore2),…` after their FEATs",
                )
            })?;
        let convex = members
            .first()
            .and_then(|m| self.nominals.get(m))
            .is_some_and(|n| n.convex);
        let n = Nominal {
            shape,
            convex,
            word: "PATERN".into(),
            numbers: Vec::new(),
        };
        Ok((n, members))
    }

    /// `T(label)=TOL/…`: the tolerance, and the words its report row repeats.
    fn tol(
        &mut self,
        label: Option<&(String, String)>,
        params: &[String],
        at: usize,
    ) -> Result<(), SimError> {
        let Some((_, l)) = label else {
            return Err(self.bad(at, "TOL without a label", "write `T(label)=TOL/…`"));
        };
        let def = TolDef::parse(params)
            .ok_or_else(|| self.unsupported(at, &format!("TOL/{}", params.join(","))))?;
        if let Some((what, help)) = def.empty_zone() {
            return Err(self.bad(at, &what, help));
        }
        self.tols.insert(l.clone(), def);
        let words = params[1..]
            .iter()
            .filter(|p| {
                matches!(p.as_str(), "2D" | "3D" | "MMC" | "LMC" | "RFS") || p.starts_with("DAT(")
            })
            .cloned()
            .collect();
        self.tol_words.insert(l.clone(), words);
        Ok(())
    }

    /// `RECALL/D(label)`: a saved alignment, or the machine's own (`D(MCS)`), which lets
    /// the part go until the next setup's `PAUSE`.
    fn recall(
        &mut self,
        label: Option<&(String, String)>,
        params: &[String],
        at: usize,
    ) -> Result<(), SimError> {
        let l = params.first().and_then(|p| label_of(p)).unwrap_or("");
        self.frame = if l == "MCS" {
            Isometry3::identity()
        } else {
            *self.saved.get(l).ok_or_else(|| {
                self.bad(
                    at,
                    &format!("alignment `{l}` is not defined"),
                    "RECALL an alignment saved before",
                )
            })?
        };
        self.between = l == "MCS" || self.machine_frames.contains(l);
        self.realigned(label);
        Ok(())
    }

    /// `ROTATE/XAXIS|YAXIS|ZAXIS,deg`: the alignment turned about one of its axes.
    fn rotate(
        &mut self,
        label: Option<&(String, String)>,
        params: &[String],
        at: usize,
    ) -> Result<(), SimError> {
        let axis = match param(params, 0) {
            "XAXIS" => V3::x(),
            "YAXIS" => V3::y(),
            "ZAXIS" => V3::z(),
            _ => return Err(self.unsupported(at, &format!("ROTATE/{}", params.join(",")))),
        };
        let Some(angle) = params.get(1).and_then(|p| number::value(p)) else {
            return Err(self.unsupported(at, &format!("ROTATE/{}", params.join(","))));
        };
        let q = UnitQuaternion::from_axis_angle(&Unit::new_normalize(axis), angle.to_radians());
        self.frame = Isometry3::from_parts(self.frame.translation, self.frame.rotation * q);
        self.realigned(label);
        Ok(())
    }

    /// `TRANS/XORIG,x[,YORIG,y…]`: the alignment's origin moved along its axes.
    fn trans(
        &mut self,
        label: Option<&(String, String)>,
        params: &[String],
        at: usize,
    ) -> Result<(), SimError> {
        let mut o = self.frame.translation.vector;
        for pair in params.chunks(2) {
            let k = match pair[0].as_str() {
                "XORIG" => 0,
                "YORIG" => 1,
                "ZORIG" => 2,
                _ => return Err(self.unsupported(at, &format!("TRANS/{}", params.join(",")))),
            };
            let v = pair.get(1).and_then(|p| number::value(p)).ok_or_else(|| {
                self.bad(at, "TRANS without a value", "write `TRANS/XORIG,value`")
            })?;
            o += self.frame.rotation * (V3::ith(k, 1.0) * v);
        }
        self.frame = Isometry3::from_parts(Translation3::from(o), self.frame.rotation);
        self.realigned(label);
        Ok(())
    }

    /// `GOTO/x,y,z`: a move under `MODE/PROG`; by hand, the operator's business.
    fn goto(&mut self, params: &[String], at: usize) -> Result<(), SimError> {
        let v = nums(params);
        if v.len() != 3 {
            return Err(self.bad(at, "GOTO takes x, y, z", "write `GOTO/x,y,z`"));
        }
        if !self.manual {
            let q = self.frame * P3::new(v[0], v[1], v[2]);
            self.move_to(q, at, "moving here")?;
        }
        Ok(())
    }

    /// `DATDEF/FA(f),DAT(x)` (ANSI/DMIS 105.2; NIST's and the QIF bindings' form): the
    /// datum, the last parameter, is the measured feature and, for a pattern, its
    /// members after it.
    fn datdef(&mut self, params: &[String], at: usize) -> Result<(), SimError> {
        let Some(d) = params
            .last()
            .filter(|p| p.starts_with("DAT("))
            .and_then(|p| label_of(p))
            .map(str::to_string)
        else {
            return Err(self.bad(
                at,
                "DATDEF without the datum it defines",
                "write `DATDEF/FA(label),DAT(A)`",
            ));
        };
        let l = params
            .first()
            .and_then(|p| label_of(p))
            .unwrap_or("")
            .to_string();
        let f = self.actuals.get(&l).cloned().ok_or_else(|| {
            self.bad(
                at,
                &format!("feature `{l}` is not measured"),
                "measure a datum feature before DATDEF",
            )
        })?;
        let members: Vec<Labelled> = self
            .patterns
            .get(&l)
            .into_iter()
            .flatten()
            .filter_map(|m| Some((self.actuals.get(m).cloned()?, m.clone())))
            .collect();
        let all = std::iter::once((f, l)).chain(members).collect();
        self.datums.insert(d, all);
        Ok(())
    }

    fn unsupported(&self, at: usize, what: &str) -> SimError {
        SimError::Unsupported {
            span: self.span(at),
            what: what.to_string(),
            supported: SUPPORTED.into(),
        }
    }

    /// After a statement that sets the alignment: saved under its label, and the
    /// setup's latest.
    fn realigned(&mut self, label: Option<&(String, String)>) {
        if let Some((_, l)) = label {
            self.saved.insert(l.clone(), self.frame);
        }
        if self.between {
            return;
        }
        if let Some(last) = self.aligns.last_mut() {
            *last = self.frame;
        }
    }

    /// `SNSDEF/PROBE,FIXED,CART,x,y,z,i,j,k,diam` (in either sign convention: see
    /// [`fixed_length`]) or `…,INDEX,POL,a,b,VEC,i,j,k,len,diam`:
    /// the probe of the plan's machine with that tip and length (the label names it when
    /// several match); `SNSDEF/LASER,…` in the same form, the scanner with that stand-off
    /// (the length) and stripe (the diameter).
    fn sensor_def(&self, label: &str, params: &[String], at: usize) -> Result<Sensor, SimError> {
        let v = nums(params);
        let (a, b) = if params.get(1).map(String::as_str) == Some("INDEX") {
            (
                v.first().copied().unwrap_or(0.0),
                v.get(1).copied().unwrap_or(0.0),
            )
        } else {
            (0.0, 0.0)
        };
        let diam = v.last().copied().unwrap_or(0.0);
        let len = if params.get(1).map(String::as_str) == Some("INDEX") {
            v.get(v.len().wrapping_sub(2)).copied().unwrap_or(0.0)
        } else {
            fixed_length(&v).ok_or_else(|| {
                self.bad(
                    at,
                    "SNSDEF/PROBE,FIXED,CART with a tip offset not along its direction",
                    "write `SNSDEF/PROBE,FIXED,CART,x,y,z,i,j,k,diam`, the tip's offset x,y,z along the probe's direction i,j,k (docs/dmis.md)",
                )
            })?
        };
        let cmm = &self.input.model.cmms[self.plan.cmm.0];
        let laser = params.first().map(String::as_str) == Some("LASER");
        let matching: Vec<usize> = self
            .probes
            .iter()
            .zip(&self.optics)
            .enumerate()
            .filter(|(_, (p, o))| match (laser, o) {
                (false, None) => {
                    (2.0 * p.tip_radius - diam).abs() < 2e-4 && (p.reach() - len).abs() < 2e-4
                }
                (true, Some((o, _))) => {
                    (o.stripe - diam).abs() < 2e-4 && (o.standoff - len).abs() < 2e-4
                }
                _ => false,
            })
            .map(|(k, _)| k)
            .collect();
        let name_of = |k: usize| match cmm.probes.get(k) {
            Some(p) => &p.0,
            None => &cmm.scanners[k - cmm.probes.len()].0,
        };
        let by_name = matching.iter().copied().find(|&k| {
            let mut l = crate::dmis::text::Labels::default();
            let base = l.fresh("S", name_of(k));
            label == base || label.starts_with(&format!("{base}_"))
        });
        match by_name.or(matching.first().copied()) {
            Some(slot) => Ok(Sensor { slot, a, b }),
            None => Err(SimError::UnknownSensor {
                span: self.span(at),
                label: label.to_string(),
                cmm: cmm.name.clone(),
                probes: (0..self.probes.len())
                    .map(|k| {
                        let (n, p) = (name_of(k), &self.probes[k]);
                        match &self.optics[k] {
                            None => format!(
                                "`{n}` (tip Ø{} mm, {} mm long)",
                                crate::dmis::text::num(2.0 * p.tip_radius),
                                crate::dmis::text::num(p.reach())
                            ),
                            Some((o, _)) => format!(
                                "`{n}` (scanner, stand-off {} mm, stripe {} mm)",
                                crate::dmis::text::num(o.standoff),
                                crate::dmis::text::num(o.stripe)
                            ),
                        }
                    })
                    .collect::<Vec<_>>()
                    .join(", "),
            }),
        }
    }

    /// `PAUSE`: the operator places the part for the next setup, where the current frame
    /// says, off by the deviations' placement.
    fn start_setup(&mut self, at: usize) -> Result<(), SimError> {
        let k = self.aligns.len() + 1;
        let r = self.frame.rotation;
        let up_raw = r.inverse() * V3::z();
        // The direction the setup names, to the precision the program writes angles.
        let up = self
            .exact
            .iter()
            .copied()
            .filter(|d| (d - up_raw).norm() < 1e-3)
            .min_by(|a, b| (a - up_raw).norm().total_cmp(&(b - up_raw).norm()))
            .unwrap_or(up_raw);
        let Some(holder) = self.setups.holder(&up) else {
            return Err(SimError::NoSetup {
                span: self.span(at),
                setup: k,
                plan: self.plan.name.clone(),
                up: format!("{:.4}, {:.4}, {:.4}", up.x, up.y, up.z),
            });
        };
        let solids = self.setups.solids(&holder, &up);
        let table = self.setups.table(&holder, &up, &solids);
        let p = self.input.deviations.placement_of(k);
        let nominal = self.frame;
        let c = nominal * self.centre;
        let turn =
            UnitQuaternion::from_axis_angle(&Unit::new_normalize(V3::z()), p.turn.to_radians());
        let shift = V3::new(p.shift[0], p.shift[1], 0.0);
        // x ↦ turn·(x − c) + c + shift, about the vertical through the part's centre.
        let d = Isometry3::from_parts(Translation3::from(c.coords - turn * c.coords + shift), turn);
        self.setup = Some(SetupCtx {
            place: d * nominal,
            up,
            table,
            solids,
        });
        self.aligns.push(self.frame);
        self.between = false;
        self.at = None;
        Ok(())
    }

    /// A program that moves before any `PAUSE` (one written elsewhere, as NIST's
    /// `simple_in.dms`) runs on the part where it already stands: its first setup starts
    /// at its first motion, the part placed where the program's alignment then says.
    fn ensure_setup(&mut self, at: usize) -> Result<(), SimError> {
        if self.setup.is_none() && self.aligns.is_empty() {
            self.start_setup(at)?;
        }
        Ok(())
    }

    fn ctx(&self, at: usize) -> Result<&SetupCtx, SimError> {
        self.setup.as_ref().ok_or_else(|| {
            self.bad(
                at,
                "a touch or move before the first setup's PAUSE",
                "place the part (TEXT/OPER, PAUSE) before measuring",
            )
        })
    }

    /// The sensor the program's first `SNSLCT` selects, from its `SNSDEF`: none when
    /// it selects none; an error when the rack holds no probe of that definition.
    fn first_selected(&self) -> Result<Option<Sensor>, SimError> {
        let commands = || {
            self.input
                .program
                .statements
                .iter()
                .filter_map(Statement::command)
        };
        let Some(l) = commands()
            .find(|c| c.1 == "SNSLCT")
            .and_then(|c| c.2.first().and_then(|p| label_of(p)))
        else {
            return Ok(None);
        };
        let Some((_, _, params, at)) = commands()
            .find(|c| c.1 == "SNSDEF" && c.0.as_ref().is_some_and(|(k, x)| k == "S" && x == l))
        else {
            return Ok(None);
        };
        self.sensor_def(l, params, at).map(Some)
    }

    fn sensor(&self, at: usize) -> Result<Sensor, SimError> {
        self.sensor.or(self.mounted).ok_or_else(|| {
            self.bad(
                at,
                "a touch or move with no sensor selected",
                "select one with SNSLCT",
            )
        })
    }

    /// The probe posed in the current setup (part frame).
    fn pose<'p>(&'p self, ctx: &'p SetupCtx, s: Sensor) -> Pose<'p> {
        let probe = &self.probes[s.slot];
        let dir = self.sensor_dir(ctx, s);
        Pose::new(&self.scene, probe, dir, ctx.up, ctx.table).with_fixture(&ctx.solids)
    }

    /// The sensor's direction (tip to head, or a scanner's from the surface towards
    /// it) in the part frame of the current setup.
    fn sensor_dir(&self, ctx: &SetupCtx, s: Sensor) -> V3 {
        match self.probes[s.slot].head {
            crate::access::pose::Head::Fixed => ctx.up,
            crate::access::pose::Head::Indexable => {
                (ctx.place.rotation.inverse() * crate::access::head_direction(s.a, s.b)).normalize()
            }
        }
    }

    fn collision(&self, at: usize, b: Blocker, during: &str) -> SimError {
        let (what, obstacle) = match b {
            Blocker::Tip => ("tip".to_string(), "the part"),
            Blocker::TipOnTable => ("tip".to_string(), "the table"),
            Blocker::Component(c) => (c, "the part"),
            Blocker::ComponentOnTable(c) => (c, "the table"),
            Blocker::Fixture(c) => (c, "the fixture"),
            Blocker::Path => ("probe".to_string(), "the part"),
        };
        SimError::Collision {
            span: self.span(at),
            what,
            obstacle: obstacle.to_string(),
            during: during.to_string(),
        }
    }

    /// A move of the tip centre to `q` (machine frame).
    fn move_to(&mut self, q: P3, at: usize, during: &str) -> Result<(), SimError> {
        self.ensure_setup(at)?;
        let ctx = self.ctx(at)?;
        let s = self.sensor(at)?;
        let qp = ctx.place.inverse() * q;
        let pose = self.pose(ctx, s);
        let r = match self.at {
            Some(p) => pose.segment(&p, &qp),
            None => pose.free(&qp),
        };
        if let Err(b) = r {
            return Err(self.collision(at, b, during));
        }
        self.moves += 1;
        self.at = Some(qp);
        Ok(())
    }

    /// A touch: approach, search for the surface, record the tip centre.
    fn ptmeas(&mut self, params: &[String], at: usize) -> Result<(), SimError> {
        self.ensure_setup(at)?;
        let (p, n) = self.touch_point(params, at)?;
        let s = self.sensor(at)?;
        let r = self.probes[s.slot].tip_radius;
        let ctx = self.ctx(at)?;
        // Where the touch is on the part: the operator touches the point shown on the
        // part itself; the machine goes where the alignment puts it.
        let (pp, np) = if self.manual {
            (p, n)
        } else {
            let inv = ctx.place.inverse() * self.frame;
            (inv * p, inv * n)
        };
        let appr = if self.manual {
            self.hand_approach(ctx, pp, np, r)
        } else {
            self.apprch
        };
        let c0 = pp + np * (r + appr);
        if !self.manual {
            self.move_to(ctx.place * c0, at, "on the way to the approach point")?;
        }
        let ctx = self.ctx(at)?;
        let travel = appr + self.search;
        let found = self.touch_contact(ctx, &c0, &np, r, travel, at)?;
        let centre = found.0;
        if !self.manual {
            self.check_touch_approach(ctx, s, pp + np * r, &np, found, at)?;
        }
        let place = ctx.place;
        let nw = self.frame.rotation * n;
        let noise = if self.opts.noise > 0.0 {
            self.opts.noise * self.rng.gauss()
        } else {
            0.0
        };
        let cw = place * centre + nw * noise;
        self.touches += 1;
        self.at = (!self.manual).then(|| centre + np * self.retrct);
        if let Some(b) = self.block.as_mut() {
            b.touches.push((p, n, cw, nw, r));
        }
        Ok(())
    }

    /// `PTMEAS/CART,x,y,z,i,j,k`'s point and unit vector (program frame), in an open
    /// `MEAS` block.
    fn touch_point(&self, params: &[String], at: usize) -> Result<(P3, V3), SimError> {
        let v = nums(params);
        if v.len() != 6 {
            return Err(self.bad(
                at,
                "PTMEAS takes x, y, z and a vector",
                "write `PTMEAS/CART,x,y,z,i,j,k`",
            ));
        }
        if self.block.is_none() {
            return Err(self.bad(
                at,
                "PTMEAS outside a MEAS block",
                "put touches between MEAS and ENDMES",
            ));
        }
        let p = P3::new(v[0], v[1], v[2]);
        let n = V3::new(v[3], v[4], v[5])
            .try_normalize(1e-9)
            .ok_or_else(|| {
                self.bad(
                    at,
                    "PTMEAS with a zero vector",
                    "give the surface's outward vector",
                )
            })?;
        Ok((p, n))
    }

    /// By hand, the operator starts as near the surface as there is room for: the
    /// first of `SNSET/APPRCH`, 2, 4 and 8 times it, then a half down to a sixteenth of
    /// it, whose search does not start in the material (`APPRCH` when none does).
    fn hand_approach(&self, ctx: &SetupCtx, pp: P3, np: V3, r: f64) -> f64 {
        let a = self.apprch;
        let tries = [
            a,
            2.0 * a,
            4.0 * a,
            8.0 * a,
            a / 2.0,
            a / 4.0,
            a / 8.0,
            a / 16.0,
        ];
        tries
            .into_iter()
            .find(|&x| {
                let c = pp + np * (r + x);
                !matches!(
                    self.search_surface(ctx, &c, &np, r, x + self.search),
                    Found::Inside
                )
            })
            .unwrap_or(a)
    }

    /// The contact of a touch's search from `c0` along `−np` within `travel` (part
    /// frame): the tip centre, what it touched and the part's face; an error when the
    /// search starts inside the part or meets nothing.
    fn touch_contact(
        &self,
        ctx: &SetupCtx,
        c0: &P3,
        np: &V3,
        r: f64,
        travel: f64,
        at: usize,
    ) -> Result<(P3, Contact, Option<FaceId>), SimError> {
        match self.search_surface(ctx, c0, np, r, travel) {
            Found::Contact(c, k, f) => Ok((c, k, f)),
            Found::Inside => Err(SimError::InsidePart {
                span: self.span(at),
            }),
            Found::Nothing => Err(SimError::NoSurface {
                span: self.span(at),
                travel: crate::dmis::text::num(travel),
            }),
        }
    }

    /// Under `MODE/PROG`, the touch's approach to the contact `found` swept with the
    /// probe: from the approach point, `SNSET/APPRCH` out from the nominal tip centre
    /// `nominal` along the touch's vector (ANSI/DMIS 105.2 `SNSET/APPRCH`: the distance
    /// from the nominal point at which the approach starts), to the nominal tip centre
    /// or, where the actual surface stands proud of it, to the contact.
    fn check_touch_approach(
        &self,
        ctx: &SetupCtx,
        s: Sensor,
        nominal: P3,
        np: &V3,
        (centre, contact, touched): (P3, Contact, Option<FaceId>),
        at: usize,
    ) -> Result<(), SimError> {
        let r = self.probes[s.slot].tip_radius;
        // The tip stops at the actual surface: where that stands proud of the
        // nominal (a moved face, or a frame off by a moved datum) the approach ends
        // there, on the machine's first contact; where it lies deeper the search
        // itself covered the way down from the nominal touch.
        let mut outer = if (centre - nominal).dot(np) > 0.0 {
            centre
        } else {
            nominal
        };
        // The scene is the nominal part: where the touched face itself lies deeper
        // (tilted, or the frame off), the ball is nearer its nominal triangles than
        // a tip is allowed to be, and no material is there. The check starts where
        // the ball clears them.
        // The nearest facet need not lie along the touch's vector (a small bore's facets
        // stand across it): a few steps out until the ball clears them.
        for _ in 0..4 {
            match self.nearest_face(&outer) {
                Some((face, d)) if Some(face) == touched && d < r - 1e-6 => outer += np * (r - d),
                _ => break,
            }
        }
        let travel = (self.apprch - (outer - nominal).dot(np)).max(0.0);
        let pose = self.pose(ctx, s);
        if let Err(b) = pose.approach(&outer, np, travel, contact) {
            return Err(self.collision(at, b, "on the touch's approach"));
        }
        Ok(())
    }

    /// `PAMEAS/P(path)`: a scanner's pass along a `PATH/LINE` of the open `MEAS` block.
    /// The housing sweeps from the path's start to its end (checked like any move);
    /// the laser's stripe, square to the motion, samples the actual part along the
    /// scanner's direction at its spacing (thinned to [`CLOUD`]); a point is kept when
    /// it lies in the depth of field, the laser and the camera both reach it within the
    /// incidence limit (exact ray casts on the nominal part), and the face it lies on is
    /// the block's nominal surface ([`CLIP`]). Each point carries the scanner's noise when the run
    /// has noise: the larger of the run's and half the scanner's accuracy.
    fn pameas(&mut self, params: &[String], at: usize) -> Result<(), SimError> {
        self.ensure_setup(at)?;
        let ((s, e), sensor, optics, accuracy) = self.scan_pass(params, at)?;
        let ctx = self.ctx(at)?;
        let inv = ctx.place.inverse() * self.frame;
        let (sp, ep) = (inv * s, inv * e);
        let place = ctx.place;
        self.move_to(place * sp, at, "on the way to the pass")?;
        self.move_to(place * ep, at, "along the scan pass")?;
        let ctx = self.ctx(at)?;
        let dir = self.sensor_dir(ctx, sensor);
        let run = ep - sp;
        let motion = run
            .try_normalize(1e-9)
            .unwrap_or_else(|| fit::across(&dir).0);
        let across = dir.cross(&motion).normalize();
        // The block's nominal in the part frame (the program's frame is the part's).
        let nominal = self
            .block
            .as_ref()
            .and_then(|b| self.nominals.get(&b.label))
            .map(|n| n.shape.clone());
        let pass = Pass {
            start: sp,
            run,
            dir,
            across,
            optics,
            nominal,
            place,
        };
        let cloud = self.thinned_cloud(ctx, &pass);
        let sigma = if self.opts.noise > 0.0 {
            self.opts.noise.max(accuracy / 2.0)
        } else {
            0.0
        };
        self.record_scan(cloud, sigma, pass.nominal.as_ref());
        Ok(())
    }

    /// `PAMEAS/P(path)`'s path (start and end, program frame), and the scanner on the
    /// ram that runs it with its optics and accuracy, in an open `MEAS` block.
    fn scan_pass(
        &self,
        params: &[String],
        at: usize,
    ) -> Result<((P3, P3), Sensor, Optics, f64), SimError> {
        let l = params.first().and_then(|p| label_of(p)).unwrap_or("");
        let Some(&path) = self.paths.get(l) else {
            return Err(self.bad(
                at,
                &format!("path `{l}` is not defined"),
                "define it with `P(label)=PATH/LINE,CART,x1,y1,z1,x2,y2,z2,i,j,k` first",
            ));
        };
        if self.block.is_none() {
            return Err(self.bad(
                at,
                "PAMEAS outside a MEAS block",
                "put scan passes between MEAS and ENDMES",
            ));
        }
        let sensor = self.sensor(at)?;
        let Some((optics, accuracy)) = self.optics[sensor.slot] else {
            return Err(self.bad(
                at,
                "PAMEAS with a touch probe selected",
                "select a scanner (`SNSDEF/LASER`) with SNSLCT before its passes",
            ));
        };
        Ok((path, sensor, optics, accuracy))
    }

    /// The pass's points (machine frame, with their normals), thinned to [`CLOUD`]; on
    /// a feature narrower than the thinned stripe (a strip the pass runs along) or
    /// shorter than its spacing, sampled 4 and 16 times as densely across and along,
    /// up to the scanner's own spacing, until the points lie on three stripes and three
    /// positions along them.
    fn thinned_cloud(&self, ctx: &SetupCtx, pass: &Pass) -> Vec<(P3, V3)> {
        let optics = &pass.optics;
        let most = (
            ((pass.run.norm() / optics.spacing[1]).floor() as usize).max(1),
            ((optics.stripe / optics.spacing[0]).floor() as usize).max(1),
        );
        let mut cloud = Vec::new();
        for k in [1, 4, 16] {
            let (along_n, across_n) = ((CLOUD.0 * k).min(most.0), (CLOUD.1 * k).min(most.1));
            let (points, spread) = self.sample_pass(ctx, pass, along_n, across_n);
            cloud = points;
            let finest = along_n == most.0 && across_n == most.1;
            if spread >= 3 || finest {
                break;
            }
        }
        cloud
    }

    /// The stripe sampled `along_n` + 1 times, `across_n` + 1 points each: the points
    /// kept (machine frame, with their normals), and on how many stripes and stripe
    /// positions they lie (the fewer).
    fn sample_pass(
        &self,
        ctx: &SetupCtx,
        pass: &Pass,
        along_n: usize,
        across_n: usize,
    ) -> (Vec<(P3, V3)>, usize) {
        let mut cloud = Vec::new();
        let (mut rows, mut cols) = (BTreeSet::new(), BTreeSet::new());
        for i in 0..=along_n {
            for j in 0..=across_n {
                let f = pass.start
                    + pass.run * (i as f64 / along_n as f64)
                    + pass.across * (pass.optics.stripe * (j as f64 / across_n as f64 - 0.5));
                let Some((c, n)) = self.scanned_point(ctx, pass, f) else {
                    continue;
                };
                rows.insert(i);
                cols.insert(j);
                cloud.push((pass.place * c, pass.place.rotation * n));
            }
        }
        (cloud, rows.len().min(cols.len()))
    }

    /// The point of the actual part the laser meets from `f` on the stripe, and the
    /// normal there (part frame), when the pass keeps it: in the depth of field, seen
    /// by laser and camera, and on the block's nominal surface ([`CLIP`]).
    fn scanned_point(&self, ctx: &SetupCtx, pass: &Pass, f: P3) -> Option<(P3, V3)> {
        let g = self.input.geometry;
        let (optics, dir) = (&pass.optics, pass.dir);
        let near = optics.standoff - optics.depth / 2.0;
        let c0 = f + dir * optics.standoff;
        let travel = optics.standoff + optics.depth / 2.0;
        let Found::Contact(c, Contact::Part, Some(face)) =
            self.search_surface(ctx, &c0, &dir, 0.0, travel)
        else {
            return None;
        };
        if (c0 - c).dot(&dir) < near {
            return None;
        }
        let n = g.faces[face.0]
            .surface
            .normal_at(&c)
            .unwrap_or(dir)
            .normalize();
        // Seen from where the nominal surface is: the scene is the nominal
        // part, and a face set back behind it is not hidden by itself.
        let seen_at = nominal_foot(pass.nominal.as_ref(), self.scene.mesh(), &c);
        if !crate::access::scan::sees(&self.scene, &seen_at, &n, &dir, optics) {
            return None;
        }
        // A point on a face of another surface (a fillet, the next wall) is
        // not the feature's; a free-form nominal keeps every point.
        let own = match (&pass.nominal, Shape::of_surface(&g.faces[face.0].surface)) {
            (Some(Shape::Surface) | None, _) => true,
            (Some(shape), Some((surface, _))) => shape.same_surface(&surface, CLIP),
            (Some(_), None) => false,
        };
        own.then_some((c, n))
    }

    /// The pass's points (machine frame) in the open block, each with the noise of
    /// `sigma` along its normal, against its nominal: the foot on `nominal`.
    fn record_scan(&mut self, cloud: Vec<(P3, V3)>, sigma: f64, nominal: Option<&Shape>) {
        let prog = self.frame.inverse();
        for (cw, nw) in cloud {
            let noise = if sigma > 0.0 {
                sigma * self.rng.gauss()
            } else {
                0.0
            };
            let q = cw + nw * noise;
            // A scanned point's nominal is the nominal surface's point nearest it (its
            // foot along the nominal's normal), as a scan is compared with the CAD model
            // (ASME Y14.5-2018 ch. 11: a profile zone lies normal to the true profile);
            // the point found is where the actual surface is.
            let at = prog * cw;
            let foot = nominal_foot(nominal, self.scene.mesh(), &at);
            if let Some(b) = self.block.as_mut() {
                b.touches.push((foot, prog * nw, q, nw, 0.0));
                b.scanned = true;
            }
            self.scanned += 1;
        }
        if let Some(b) = self.block.as_mut() {
            b.scanned = true;
        }
    }

    /// The part's face nearest `x` (part frame) on the nominal mesh, and its distance.
    fn nearest_face(&self, x: &P3) -> Option<(FaceId, f64)> {
        let mesh = self.scene.mesh()?;
        let g = self.input.geometry;
        let (proj, feature) = mesh.project_local_point_and_get_feature(x);
        let parry3d_f64::shape::FeatureId::Face(i) = feature else {
            return None;
        };
        let face = FaceId(*g.tri_face.get(i as usize % g.triangles.len().max(1))? as usize);
        Some((face, (proj.point - x).norm()))
    }

    /// Where the ball moving from `c0` along `−n` meets `face`'s actual surface within
    /// `travel` (the distance moved), if it does; `Err` when the ball starts inside the
    /// part there (`inside` asks for that check: the approach point in the material).
    #[allow(clippy::too_many_arguments)]
    fn contact_on(
        &self,
        mesh: &parry3d_f64::shape::TriMesh,
        face: FaceId,
        c0: &P3,
        n: &V3,
        r: f64,
        travel: f64,
        inside: bool,
    ) -> Result<Option<f64>, ()> {
        let g = self.input.geometry;
        let dev: &Deviations = self.input.deviations;
        let surface = dev.surface(g, face);
        let bow = dev.lift_of(g, face);
        Ok(match Shape::of_surface(&surface) {
            Some((shape, convex)) => {
                // The distance on the solid's free side, less any bow.
                let k = if convex { 1.0 } else { -1.0 };
                let gap = |t: f64| {
                    let x = c0 - n * t;
                    let lift = match (&bow, shape.direction()) {
                        (Some(b), Some(normal)) => b.at(&normal, &x),
                        _ => 0.0,
                    };
                    k * shape.signed(&x) - lift - r
                };
                // A plane above the approach point, or the ball there in the part (a
                // concave face's distance is that of the whole bore: an approach point
                // past a fillet's axis is in the open).
                let planar = matches!(shape, Shape::Plane { .. });
                if gap(0.0) <= 0.0 {
                    if !inside {
                        // A neighbour's surface the ball starts behind (its extension
                        // past the face): not the face the ball meets.
                        return Ok(None);
                    }
                    if planar || self.scene.distance(c0) < r {
                        return Err(());
                    }
                }
                first_root(&gap, travel)
            }
            None => {
                // Free-form: the ball swept against the triangles, moved with the face.
                // Not the foot's ray: off the programmed point in a fillet, the ball meets
                // the facets beside the foot first.
                let m = dev
                    .faces
                    .get(face.0)
                    .map(|c| c.motion)
                    .unwrap_or_else(Isometry3::identity);
                let at = Isometry3::from_parts(
                    Translation3::from((m.inverse() * c0).coords),
                    UnitQuaternion::identity(),
                );
                let hit = cast_shapes(
                    &at,
                    &(m.inverse() * -n),
                    &Ball::new(r),
                    &Isometry3::identity(),
                    &V3::zeros(),
                    mesh,
                    ShapeCastOptions::with_max_time_of_impact(travel),
                );
                hit.ok()
                    .flatten()
                    .map(|h| h.time_of_impact)
                    .filter(|t| *t <= travel)
            }
        })
    }

    /// The first contact of the tip ball moving from centre `c0` along `−n` (part
    /// frame) within `travel`: the part's face the foot of the ball meets on the mesh,
    /// found exactly on its actual surface; or the table. Where the ball cannot reach
    /// that face (a corner radius hardly larger than the ball, the part set off by
    /// more than the ball's play in it), it stops on the face it meets first, as a
    /// machine's probe does: of the faces whose facets lie near its path, the nearest
    /// contact on their actual surfaces.
    fn search_surface(&self, ctx: &SetupCtx, c0: &P3, n: &V3, r: f64, travel: f64) -> Found {
        let g = self.input.geometry;
        let mut best: Option<(f64, Contact, Option<FaceId>)> = None;
        if let Some(mesh) = self.scene.mesh() {
            let face_of = |i: u32| {
                FaceId(
                    g.tri_face
                        .get(i as usize % g.triangles.len().max(1))
                        .copied()
                        .unwrap_or(0) as usize,
                )
            };
            let foot =
                foot_ray(mesh, &(c0 - n * r), n, travel + 1.0).map(|hit| match hit.feature {
                    parry3d_f64::shape::FeatureId::Face(i) => face_of(i),
                    _ => face_of(0),
                });
            if let Some(face) = foot {
                match self.contact_on(mesh, face, c0, n, r, travel, true) {
                    Err(()) => return Found::Inside,
                    Ok(Some(t)) => best = Some((t, Contact::Part, Some(face))),
                    Ok(None) => {}
                }
            }
            // (A scanner's ray, r = 0, keeps to the face under it: a point past a
            // deviated face's edge is not the feature's.)
            if best.is_none() && r > 0.0 {
                // The faces whose facets come near the ball's path, the foot's own
                // (moved away from the ball, it is not met at all) left out; the
                // nearest contact on their actual surfaces.
                let end = c0 - n * travel;
                let path = Aabb::new(c0.inf(&end), c0.sup(&end)).loosened(r);
                let mut near: Vec<FaceId> = Vec::new();
                for (tri, &f) in g.triangles.iter().zip(&g.tri_face) {
                    let [a, b, c] = tri.map(|i| g.vertices[i as usize]);
                    let f = FaceId(f as usize);
                    if Some(f) != foot
                        && !near.contains(&f)
                        && path.intersects(&Triangle::new(a, b, c).local_aabb())
                    {
                        near.push(f);
                    }
                }
                for face in near {
                    if let Ok(Some(t)) = self.contact_on(mesh, face, c0, n, r, travel, false) {
                        if best.is_none_or(|(b, ..)| t < b) {
                            best = Some((t, Contact::Part, Some(face)));
                        }
                    }
                }
            }
        }
        let rise = n.dot(&ctx.up);
        if rise > 1e-9 {
            let t = ((c0.coords.dot(&ctx.up)) - r - ctx.table) / rise;
            if (0.0..=travel).contains(&t) && best.is_none_or(|(b, ..)| t < b) {
                best = Some((t, Contact::Table, None));
            }
        }
        match best {
            Some((t, k, face)) => Found::Contact(c0 - n * t, k, face),
            None => Found::Nothing,
        }
    }

    /// `ENDMES`: the block's feature fitted to the tip centres and offset by the tip.
    fn endmes(&mut self, at: usize) -> Result<(), SimError> {
        let Some(b) = self.block.take() else {
            return Err(self.bad(at, "ENDMES without MEAS", "open the block with MEAS"));
        };
        let nominal = self.nominals.get(&b.label).cloned().ok_or_else(|| {
            self.bad(
                b.at,
                &format!("feature `{}` has no nominal", b.label),
                "define it with FEAT before measuring it",
            )
        })?;
        let r = b.touches.first().map(|t| t.4).unwrap_or(0.0);
        let centres: Vec<P3> = b.touches.iter().map(|t| t.2).collect();
        let guess = nominal.shape.moved(&self.frame);
        let fitted = match b.word.as_str() {
            // A plane takes 3 touches off a line: a controller fits none to fewer.
            "PLANE" => {
                let near = guess.direction().unwrap_or(V3::z());
                fit::plane(&centres, &near).map(|s| s.offset(-r, true))
            }
            // A line on a face (the 3-2-1 secondary): the surface points the touches
            // found, the face's normal from their vectors.
            "LINE" => {
                let surface: Vec<P3> = b.touches.iter().map(|t| t.2 - t.3 * t.4).collect();
                let n = b.touches.iter().fold(V3::zeros(), |s, t| s + t.3);
                let run = guess.direction().unwrap_or(V3::x());
                fit::line(&surface, &n, &run)
            }
            "CYLNDR" => fit::cylinder(&centres, &guess.offset(r, nominal.convex))
                .map(|s| s.offset(-r, nominal.convex)),
            // A circle is a cylinder's section: its axis the nominal's, its centre at the
            // touches' mean height along it (NIST's `output.dms` reports the circle of
            // `simple_in.dms` at the touches' z).
            "CIRCLE" => fit::circle(&centres, &guess.offset(r, nominal.convex))
                .map(|s| s.offset(-r, nominal.convex)),
            "CONE" => fit::cone(&centres, &guess.offset(r, nominal.convex))
                .map(|s| s.offset(-r, nominal.convex)),
            "SPHERE" => fit::sphere(&centres, &guess.offset(r, nominal.convex))
                .map(|s| s.offset(-r, nominal.convex)),
            "POINT" => b.touches.first().map(|t| Shape::Point {
                p: t.2 - t.3 * t.4,
                n: t.3,
            }),
            "GSURF" => Some(Shape::Surface),
            other => return Err(self.unsupported(b.at, &format!("MEAS/{other}"))),
        };
        if b.scanned && b.touches.len() < 3 {
            return Err(self.bad(
                b.at,
                &format!(
                    "the scan passes saw {} points of feature `{}`",
                    b.touches.len(),
                    b.label
                ),
                "the passes must run over the feature within the scanner's depth of field, its laser and camera seeing it",
            ));
        }
        let Some(shape) = fitted else {
            return Err(self.bad(
                b.at,
                &format!(
                    "{} touches fit no {} to feature `{}`",
                    b.touches.len(),
                    b.word.to_lowercase(),
                    b.label
                ),
                "a plane needs 3 touches off a line, a cylinder or cone 3 on a circle, a sphere 4",
            ));
        };
        let touches = b
            .touches
            .iter()
            .map(|t| (t.0, t.1, t.2 - t.3 * t.4))
            .collect();
        let setup = self.aligns.len();
        self.actuals.insert(
            b.label,
            Stored {
                m: Measured {
                    shape,
                    touches,
                    median: Vec::new(),
                },
                setup,
            },
        );
        Ok(())
    }

    /// A stored feature in the program frame: through its setup's latest alignment.
    fn in_program(&self, f: &Stored) -> Measured {
        let a = self
            .aligns
            .get(f.setup.wrapping_sub(1))
            .copied()
            .unwrap_or_else(Isometry3::identity);
        f.m.moved(&a.inverse())
    }

    /// A stored feature in the current setup's machine frame.
    fn in_machine(&self, f: &Stored) -> Measured {
        if f.setup == self.aligns.len() {
            f.m.clone()
        } else {
            self.in_program(f).moved(&self.frame)
        }
    }

    fn feature(&self, p: &str, at: usize) -> Result<(String, &Stored), SimError> {
        let l = label_of(p).unwrap_or("").to_string();
        match self.actuals.get(&l) {
            Some(f) => Ok((l, f)),
            None => Err(self.bad(
                at,
                &format!("feature `{l}` is not measured"),
                "measure a feature before using it",
            )),
        }
    }

    /// `CONST/type,F(label),BF,FA(…),…`: a best fit over the sources' points, or a centre
    /// plane from two walls (`PARPLN`), in the program frame.
    fn construct(&mut self, params: &[String], at: usize) -> Result<(), SimError> {
        let word = params.first().cloned().unwrap_or_default();
        let label = params
            .get(1)
            .and_then(|p| label_of(p))
            .unwrap_or("")
            .to_string();
        let nominal = self.nominals.get(&label).cloned().ok_or_else(|| {
            self.bad(
                at,
                &format!("feature `{label}` has no nominal"),
                "define it with FEAT first",
            )
        })?;
        let mut sources = Vec::new();
        for p in params.iter().skip(3) {
            let (_, f) = self.feature(p, at)?;
            sources.push(self.in_program(f));
        }
        let touches: Vec<(P3, V3, P3)> = sources
            .iter()
            .flat_map(|s| s.touches.iter().copied())
            .collect();
        let pts: Vec<P3> = touches.iter().map(|t| t.2).collect();
        let intof = params.get(2).map(String::as_str) == Some("INTOF");
        let fitted = match word.as_str() {
            "CIRCLE" if intof => {
                // The circle is the features' intersection, not a fit over their points.
                let circle = self.intersection_circle(&sources, at)?;
                return self.store_constructed(label, circle);
            }
            "PARPLN" => Some(self.centre_plane(&sources, &nominal, at)?),
            "PLANE" => {
                fit::plane(&pts, &nominal.shape.direction().unwrap_or(V3::z())).map(|s| (s, vec![]))
            }
            "CYLNDR" => fit::cylinder(&pts, &nominal.shape).map(|s| (s, vec![])),
            "PATERN" => {
                let shapes: Vec<Shape> = sources.iter().map(|m| m.shape.clone()).collect();
                fit::pattern(&shapes).map(|s| (s, vec![]))
            }
            "CONE" => fit::cone(&pts, &nominal.shape).map(|s| (s, vec![])),
            "SPHERE" => fit::sphere(&pts, &nominal.shape).map(|s| (s, vec![])),
            other => return Err(self.unsupported(at, &format!("CONST/{other}"))),
        };
        let Some((shape, median)) = fitted else {
            return Err(self.bad(
                at,
                &format!(
                    "{} points fit no {} to feature `{label}`",
                    pts.len(),
                    word.to_lowercase()
                ),
                "a plane needs 3 points off a line, a cylinder 5, a sphere 4",
            ));
        };
        let m = Measured {
            shape,
            touches,
            median,
        }
        .moved(&self.frame);
        let setup = self.aligns.len();
        self.actuals.insert(label, Stored { m, setup });
        Ok(())
    }

    /// `CONST/CIRCLE,F(c),INTOF,FA(bore),FA(cone)`: the circle where the bore meets
    /// the cone on its axis.
    fn intersection_circle(&self, sources: &[Measured], at: usize) -> Result<Shape, SimError> {
        let [bore, cone] = sources else {
            return Err(self.bad(
                at,
                "an intersection circle takes two features",
                "write `CONST/CIRCLE,F(c),INTOF,FA(bore),FA(cone)`",
            ));
        };
        full_diameter(&bore.shape, &cone.shape).ok_or_else(|| {
            self.bad(
                at,
                "these features meet in no circle",
                "intersect a bore with the cone on its axis",
            )
        })
    }

    /// `CONST/PARPLN,F(mid),BF,FA(wall1),FA(wall2)`: the plane midway between two
    /// measured walls, facing the way its nominal does, their width apart, and the
    /// walls' points moved onto it (its median points).
    fn centre_plane(
        &self,
        sources: &[Measured],
        nominal: &Nominal,
        at: usize,
    ) -> Result<(Shape, Vec<P3>), SimError> {
        let [a, b] = sources else {
            return Err(self.bad(
                at,
                "a centre plane takes two walls",
                "write `CONST/PARPLN,F(mid),BF,FA(wall1),FA(wall2)`",
            ));
        };
        let (Shape::Plane { p: pa, n: na }, Shape::Plane { p: pb, n: nb }) = (&a.shape, &b.shape)
        else {
            return Err(self.bad(
                at,
                "a centre plane's walls must be planes",
                "construct it from two measured planes",
            ));
        };
        let Some(nn) = nominal.shape.direction() else {
            return Err(self.bad(
                at,
                "a centre plane's nominal has no normal",
                "define it as FEAT/PARPLN",
            ));
        };
        let mut n = (na - nb).normalize();
        if n.dot(&nn) < 0.0 {
            n = -n;
        }
        let centroid = |m: &Measured| {
            P3::from(
                m.touches.iter().fold(V3::zeros(), |s, t| s + t.2.coords)
                    / m.touches.len().max(1) as f64,
            )
        };
        let (ca, cb) = (centroid(a), centroid(b));
        let qa = ca - nb * (ca - pb).dot(nb);
        let qb = cb - na * (cb - pa).dot(na);
        let width = ((qa - ca).norm() + (qb - cb).norm()) / 2.0;
        let mid = P3::from((ca.coords + qa.coords + cb.coords + qb.coords) / 4.0);
        let mut median = Vec::new();
        for (m, p, nw) in [(a, pa, na), (b, pb, nb)] {
            let s0 = (mid - p).dot(&n) / nw.dot(&n);
            median.extend(m.touches.iter().map(|t| t.2 + nw * s0));
        }
        Ok((Shape::Parpln { p: mid, n, width }, median))
    }

    /// A constructed feature with no points of its own, in the program frame.
    fn store_constructed(&mut self, label: String, shape: Shape) -> Result<(), SimError> {
        let m = Measured {
            shape,
            touches: Vec::new(),
            median: Vec::new(),
        }
        .moved(&self.frame);
        let setup = self.aligns.len();
        self.actuals.insert(label, Stored { m, setup });
        Ok(())
    }

    /// `DATSET/FA(f),[-]XDIR,XORIG,…`: the frame whose axes and origin the features
    /// give; what they leave free comes from the current frame.
    fn datset(&self, params: &[String], at: usize) -> Result<Isometry3<f64>, SimError> {
        let params = self.datums_as_features(params, at)?;
        let (dirs, origins) = self.datset_targets(&params, at)?;
        let axes = self.datset_axes(&dirs, at)?;
        let o = self.datset_origin(&axes, &origins, at)?;
        let r = Rotation3::from_matrix_unchecked(Matrix3::from_columns(&axes));
        Ok(Isometry3::from_parts(
            Translation3::from(o),
            UnitQuaternion::from_rotation_matrix(&r),
        ))
    }

    /// `DATSET`'s parameters with each `DAT(x)` written as the feature its `DATDEF`
    /// named, `FA(f)` (DMIS's DATSET names features through datum labels; `FA(x)`
    /// directly is read too).
    fn datums_as_features(&self, params: &[String], at: usize) -> Result<Vec<String>, SimError> {
        params
            .iter()
            .map(
                |p| match p.strip_prefix("DAT(").and_then(|r| r.strip_suffix(')')) {
                    Some(d) => match self.datums.get(d).and_then(|fs| fs.first()) {
                        Some((_, l)) => Ok(format!("FA({l})")),
                        None => Err(self.bad(
                            at,
                            &format!("datum `{d}` is not defined"),
                            "define it with DATDEF/FA(feature),DAT(x) before DATSET",
                        )),
                    },
                    None => Ok(p.clone()),
                },
            )
            .collect()
    }

    /// What `DATSET`'s keywords ask of the features before them (machine frame): the
    /// directions by axis (0 for x), each the way its nominal points, and the shapes
    /// that give the origin along an axis.
    fn datset_targets(&self, params: &[String], at: usize) -> Result<DatsetTargets, SimError> {
        let mut dirs: Vec<(usize, V3)> = Vec::new();
        let mut origins: Vec<(usize, Shape)> = Vec::new();
        let mut cur: Option<Measured> = None;
        let mut nominal_dir: Option<V3> = None;
        for p in params {
            if p.starts_with("FA(") {
                let (l, f) = self.feature(p, at)?;
                cur = Some(self.in_machine(f));
                nominal_dir = self
                    .nominals
                    .get(&l)
                    .and_then(|n| n.shape.direction())
                    .map(|d| self.frame.rotation * d);
                continue;
            }
            let Some(f) = &cur else {
                return Err(self.bad(
                    at,
                    "DATSET keyword before any feature",
                    "write `DATSET/FA(label),ZDIR,ZORIG,…`",
                ));
            };
            let axis = |c: char| "XYZ".find(c);
            let w = p.trim_start_matches('-');
            if let Some(k) = w
                .strip_suffix("DIR")
                .and_then(|a| a.chars().next())
                .and_then(axis)
            {
                let Some(mut d) = f.shape.direction() else {
                    return Err(self.bad(
                        at,
                        "a DATSET direction from a feature without one",
                        "directions come from planes and axes",
                    ));
                };
                if nominal_dir.is_some_and(|nd| nd.dot(&d) < 0.0) {
                    d = -d;
                }
                dirs.push((k, if p.starts_with('-') { -d } else { d }));
            } else if let Some(k) = w
                .strip_suffix("ORIG")
                .and_then(|a| a.chars().next())
                .and_then(axis)
            {
                origins.push((k, f.shape.clone()));
            } else {
                return Err(self.unsupported(at, &format!("DATSET keyword {p}")));
            }
        }
        Ok((dirs, origins))
    }

    /// The new frame's axes: the first two directions `dirs` names, each made square
    /// to those before it; the axes they leave free from the current frame, across
    /// them; the third the cross product of the other two.
    fn datset_axes(&self, dirs: &[(usize, V3)], at: usize) -> Result<[V3; 3], SimError> {
        let old = self.frame.rotation.to_rotation_matrix().into_inner();
        let mut e: [Option<V3>; 3] = [None, None, None];
        let mut order: Vec<usize> = Vec::new();
        for (k, d) in dirs {
            if e[*k].is_some() {
                continue;
            }
            let mut v = *d;
            for j in &order {
                let ej = e[*j].expect("set");
                v -= ej * v.dot(&ej);
            }
            let Some(v) = v.try_normalize(1e-6) else {
                return Err(self.bad(
                    at,
                    "DATSET directions are parallel",
                    "the secondary direction must cross the primary",
                ));
            };
            if order.len() < 2 {
                e[*k] = Some(v);
                order.push(*k);
            }
        }
        // Free axes from the current frame, across the fixed ones.
        for j in 0..3 {
            if order.len() >= 2 {
                break;
            }
            if e[j].is_some() {
                continue;
            }
            let mut v: V3 = old.column(j).into_owned();
            for i in &order {
                let ei = e[*i].expect("set");
                v -= ei * v.dot(&ei);
            }
            if let Some(v) = v.try_normalize(0.1) {
                e[j] = Some(v);
                order.push(j);
            }
        }
        let third = (0..3).find(|j| e[*j].is_none()).unwrap_or(2);
        let (a, b) = ((third + 1) % 3, (third + 2) % 3);
        e[third] = Some(e[a].expect("two axes").cross(&e[b].expect("two axes")));
        Ok([e[0].expect("x"), e[1].expect("y"), e[2].expect("z")])
    }

    /// The new frame's origin: along each axis an ORIG names, the feature's location
    /// (a plane's touched centroid, a point of an axis, a centre); along the others
    /// the old origin's.
    fn datset_origin(
        &self,
        axes: &[V3; 3],
        origins: &[(usize, Shape)],
        at: usize,
    ) -> Result<V3, SimError> {
        let o_old = self.frame.translation.vector;
        let mut m = Matrix3::zeros();
        let mut rhs = V3::zeros();
        for k in 0..3 {
            let at = match origins.iter().find(|(j, _)| *j == k).map(|(_, s)| s) {
                Some(Shape::Surface) => {
                    return Err(self.bad(
                        at,
                        "a DATSET origin from a free-form surface",
                        "origins come from planes, axes and centres",
                    ))
                }
                Some(s) => s.location().map_or(o_old, |p| p.coords),
                None => o_old,
            };
            m.set_row(k, &axes[k].transpose());
            rhs[k] = axes[k].dot(&at);
        }
        m.lu().solve(&rhs).ok_or_else(|| {
            self.bad(
                at,
                "DATSET origins do not meet in a point",
                "each origin must come from a feature across its axis",
            )
        })
    }

    /// `OUTPUT/FA(…)[,FA(…)],TA(t)`: the tolerance evaluated on its features as the
    /// program measured them, its datums as `DATDEF` defined them.
    fn output(&mut self, params: &[String], at: usize) -> Result<(), SimError> {
        for p in params.iter().filter(|p| p.starts_with("FA(")) {
            let (l, f) = self.feature(p, at)?;
            if self.features.iter().any(|r| r.label == l) {
                continue;
            }
            let row = self.feature_row(&l, &self.in_program(f));
            self.features.extend(row);
        }
        // Each tolerance the statement names is judged (a feature output alone reports
        // its actual, nothing to judge).
        let tols: Vec<String> = params
            .iter()
            .filter(|p| p.starts_with("TA("))
            .filter_map(|p| label_of(p))
            .map(str::to_string)
            .collect();
        for tl in &tols {
            self.judge(tl, params, at)?;
        }
        Ok(())
    }

    /// One tolerance of an `OUTPUT`, on the statement's features.
    fn judge(&mut self, tl: &str, params: &[String], at: usize) -> Result<(), SimError> {
        let def = self.tols.get(tl).cloned().ok_or_else(|| {
            self.bad(
                at,
                &format!("tolerance `{tl}` is not defined"),
                "define it with TOL before OUTPUT",
            )
        })?;
        let mut labels = Vec::new();
        let mut measured = Vec::new();
        for p in params.iter().filter(|p| p.starts_with("FA(")) {
            let (l, f) = self.feature(p, at)?;
            measured.push(self.in_program(f));
            labels.push(l);
        }
        let mut noms = Vec::new();
        for l in &labels {
            noms.push(self.nominals.get(l).cloned().ok_or_else(|| {
                self.bad(
                    at,
                    &format!("feature `{l}` has no nominal"),
                    "define it with FEAT",
                )
            })?);
        }
        let targets: Vec<evaluate::Target> = measured
            .iter()
            .zip(&noms)
            .zip(&labels)
            .map(|((m, n), l)| evaluate::Target {
                measured: m,
                nominal: &n.shape,
                convex: n.convex,
                size: self.sizes.get(l).copied(),
            })
            .collect();
        let mut datums = Vec::new();
        for d in &def.datums {
            let features = self.datums.get(d).ok_or_else(|| {
                self.bad(
                    at,
                    &format!("datum `{d}` is not defined"),
                    "define it with DATDEF before the tolerance's OUTPUT",
                )
            })?;
            for (f, l) in features {
                let n = self.nominals.get(l).map(|n| n.shape.clone());
                datums.push((self.in_program(f).shape, n.unwrap_or(Shape::Surface)));
            }
        }
        let out = evaluate::evaluate(&def, &targets, &datums);
        if def.word == "DIAM" && labels.len() == 1 && out.actual.is_finite() {
            let (lo, hi) = def.limits.unwrap_or((0.0, 0.0));
            self.sizes.insert(labels[0].clone(), (out.nominal, lo, hi));
        }
        self.rows.push(Row {
            tolerance: tl.to_string(),
            kind: def.word.clone(),
            features: labels,
            datums: def.datums.clone(),
            words: self.tol_words.get(tl).cloned().unwrap_or_default(),
            outcome: out,
        });
        Ok(())
    }
}

impl Machine<'_> {
    /// A feature's actual beside its nominal, in the `FEAT` statement's layout.
    fn feature_row(&self, label: &str, m: &Measured) -> Option<FeatureRow> {
        let n = self.nominals.get(label)?;
        let ijk = |v: &V3| [v.x, v.y, v.z];
        // A direction reported the way the nominal's points (a fit may turn it over).
        let along = |v: &V3| match n.shape.direction() {
            Some(d) if d.dot(v) < 0.0 => -v,
            _ => *v,
        };
        let xyz = |p: &P3| vec![p.x, p.y, p.z];
        let with = |mut v: Vec<f64>, more: &[f64]| {
            v.extend_from_slice(more);
            v
        };
        let actual: Vec<f64> = match &m.shape {
            Shape::Plane { p, n: v } | Shape::Point { p, n: v } => with(xyz(p), &ijk(&along(v))),
            Shape::Line { p, d, n: v } => with(with(xyz(p), &ijk(&along(d))), &ijk(v)),
            Shape::Cylinder { p, a, r } => with(with(xyz(p), &ijk(&along(a))), &[2.0 * r]),
            Shape::Cone { apex, a, half } => {
                with(with(xyz(apex), &ijk(&along(a))), &[2.0 * half.to_degrees()])
            }
            Shape::Sphere { c, r } => with(xyz(c), &[2.0 * r]),
            Shape::Parpln { p, n: v, width } => with(with(xyz(p), &ijk(&along(v))), &[*width]),
            Shape::Surface => Vec::new(),
        };
        let form = match &m.shape {
            Shape::Point { .. } | Shape::Surface => None,
            shape if !m.touches.is_empty() && n.word != "PATERN" => Some(
                m.touches
                    .iter()
                    .map(|t| shape.signed(&t.2))
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), d| {
                        (lo.min(d), hi.max(d))
                    }),
            )
            .map(|(lo, hi)| hi - lo),
            _ => None,
        };
        Some(FeatureRow {
            label: label.to_string(),
            kind: n.word.clone(),
            inner: !n.convex,
            nominal: n.numbers.clone(),
            actual,
            form,
            points: m.touches.len(),
        })
    }
}

/// What a touch's search finds.
enum Found {
    /// The tip centre at contact, what it touched, and the part's face it touched.
    Contact(P3, Contact, Option<FaceId>),
    Inside,
    Nothing,
}

/// The first `t` in `[0, max]` where `gap` falls from positive to zero, by steps then
/// bisection. The gaps are signed distances (less a bow of small slope), which change
/// by at most twice the distance moved: a step of half the gap, or [`SEARCH_STEP`]
/// where that is more, cannot cross a root, so a scanner's point 100 mm from where its
/// search starts takes a few dozen steps, not ten thousand.
fn first_root(gap: &dyn Fn(f64) -> f64, max: f64) -> Option<f64> {
    let mut lo = 0.0;
    let mut g = gap(0.0);
    let mut armed = g > 0.0;
    while lo < max {
        let hi = (lo + (g.abs() / 2.0).max(SEARCH_STEP)).min(max);
        let gh = gap(hi);
        if armed && gh <= 0.0 {
            let (mut a, mut b) = (lo, hi);
            for _ in 0..60 {
                let m = 0.5 * (a + b);
                if gap(m) > 0.0 {
                    a = m;
                } else {
                    b = m;
                }
            }
            return Some(0.5 * (a + b));
        }
        armed |= gh > 0.0;
        lo = hi;
        g = gh;
    }
    None
}

/// The length of a fixed probe from `SNSDEF/PROBE,FIXED,CART,x,y,z,i,j,k,diam`'s numbers:
/// the tip's offset `x,y,z` from the gauge point, along the probe's direction `i,j,k`.
/// Writers differ in the signs: CMM Quarterly's "DMIS Probe Command Set" (and inspc)
/// write the tip's offset in machine axes with the mounting direction, tip to head
/// (`0,0,-50,0,0,1` for a probe hanging 50 mm below the ram); NIST's I++ simple-part
/// program writes `0,0,30,0,0,-1` — the same probe the other way round. Both put the
/// tip on the probe's axis at `|x,y,z|` from the gauge point; anything off that axis is
/// no probe the rack can hold (`None`).
fn fixed_length(v: &[f64]) -> Option<f64> {
    let off = V3::new(*v.first()?, *v.get(1)?, *v.get(2)?);
    let dir = V3::new(*v.get(3)?, *v.get(4)?, *v.get(5)?).try_normalize(1e-9)?;
    let len = off.norm();
    (off.cross(&dir).norm() <= 1e-6 * len.max(1.0)).then_some(len)
}

/// What a nominal shape lacks to be a feature, if anything: a diameter, width or cone
/// angle of 0 or less (or a cone angle of 180° or more), which no part has.
fn sizeless(shape: &Shape) -> Option<String> {
    match *shape {
        Shape::Cylinder { r, .. } | Shape::Sphere { r, .. } if r <= 0.0 => {
            Some(format!("a diameter of {}", 2.0 * r))
        }
        Shape::Parpln { width, .. } if width <= 0.0 => Some(format!("a width of {width}")),
        Shape::Cone { half, .. } if half <= 0.0 || half >= std::f64::consts::FRAC_PI_2 => {
            Some(format!("a cone angle of {}°", 2.0 * half.to_degrees()))
        }
        _ => None,
    }
}

/// A nominal from `FEAT` parameters.
fn nominal(params: &[String]) -> Option<Nominal> {
    let word = params.first()?.as_str();
    let convex = !params.iter().any(|p| p == "INNER");
    let v = nums(params);
    let p = |k: usize| Some(P3::new(*v.get(k)?, *v.get(k + 1)?, *v.get(k + 2)?));
    let d = |k: usize| V3::new(*v.get(k)?, *v.get(k + 1)?, *v.get(k + 2)?).try_normalize(1e-9);
    let shape = match word {
        "PLANE" => Shape::Plane { p: p(0)?, n: d(3)? },
        "POINT" => Shape::Point { p: p(0)?, n: d(3)? },
        // `FEAT/CYLNDR,INNER|OUTER,CART,x,y,z,i,j,k,diam[,len]`; a circle
        // (`FEAT/CIRCLE,…,x,y,z,i,j,k,diam`) is held as the cylinder it is a section
        // of, its point the circle's centre.
        "CYLNDR" | "CIRCLE" => Shape::Cylinder {
            p: p(0)?,
            a: d(3)?,
            r: v.get(6)? / 2.0,
        },
        "CONE" => Shape::Cone {
            apex: p(0)?,
            a: d(3)?,
            half: (v.get(6)? / 2.0).to_radians(),
        },
        "SPHERE" => Shape::Sphere {
            c: p(0)?,
            r: v.get(3)? / 2.0,
        },
        "PARPLN" => Shape::Parpln {
            p: p(0)?,
            n: d(3)?,
            width: *v.get(6)?,
        },
        // `FEAT/LINE,UNBND,CART,x,y,z,i,j,k,pi,pj,pk`: a point, the line's direction and
        // the normal of the plane it lies in (`BND`: its two ends, then that normal;
        // Horsfall's DMIS notes, CAMCAD's writer);
        // the face's normal across it is the one in that plane, square to the line.
        "LINE" => {
            let (p, d, plane) = if params.iter().any(|w| w == "BND") {
                // Bounded: its two ends, then the plane's normal.
                let (a, b) = (p(0)?, p(3)?);
                (a, (b - a).try_normalize(1e-9)?, d(6)?)
            } else {
                (p(0)?, d(3)?, d(6)?)
            };
            let n = d.cross(&plane).try_normalize(1e-9)?;
            Shape::Line { p, d, n }
        }
        "GSURF" => Shape::Surface,
        _ => return None,
    };
    Some(Nominal {
        shape,
        convex,
        word: word.to_string(),
        numbers: v,
    })
}

/// The face under the ball's foot, by a ray along `-n`. A ray through a shared edge or
/// vertex of the tessellation can slip between its triangles (a touch programmed on the
/// line where a face's facets meet); the ray is then cast again from four points a
/// tenth of a micrometre beside the foot, in a fixed order.
fn foot_ray(
    mesh: &parry3d_f64::shape::TriMesh,
    foot: &P3,
    n: &V3,
    reach: f64,
) -> Option<parry3d_f64::query::RayIntersection> {
    const NUDGE: f64 = 1e-4;
    let (u, v) = fit::across(n);
    [V3::zeros(), u, -u, v, -v].into_iter().find_map(|d| {
        let ray = Ray::new(foot + d * NUDGE, -n);
        mesh.cast_ray_and_get_normal(&Isometry3::identity(), &ray, reach, false)
    })
}

/// The circle where a bore meets the cone on its axis (a drilled hole's full diameter
/// ends there): on the cone's axis, where the cone's radius is the bore's; held as the
/// cylinder it is a section of, as a `FEAT/CIRCLE` nominal is. `None` unless the
/// features are a cylinder and a cone whose axes agree within 1°.
fn full_diameter(bore: &Shape, cone: &Shape) -> Option<Shape> {
    let (Shape::Cylinder { a, r, .. }, Shape::Cone { apex, a: ca, half }) = (bore, cone) else {
        return None;
    };
    if a.dot(ca).abs() < 1f64.to_radians().cos() || half.tan() < 1e-9 {
        return None;
    }
    Some(Shape::Cylinder {
        p: apex + ca * (r / half.tan()),
        a: *a,
        r: *r,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_noise_is_the_same_for_a_seed() {
        let (mut a, mut b) = (Rng(7), Rng(7));
        let xs: Vec<f64> = (0..4).map(|_| a.gauss()).collect();
        let ys: Vec<f64> = (0..4).map(|_| b.gauss()).collect();
        assert_eq!(xs, ys);
        let mut c = Rng(8);
        assert_ne!(xs[0], c.gauss());
    }

    /// FTC 06's drilled holes: Ø6.35, a 118° point whose apex lies 1.9077 mm past the
    /// end of the full diameter (3.175 / tan 59°).
    #[test]
    fn a_drilled_hole_ends_where_the_cone_is_as_wide_as_the_bore() {
        let bore = Shape::Cylinder {
            p: P3::new(76.2, 78.74, -158.75),
            a: -V3::y(),
            r: 3.175,
        };
        let cone = Shape::Cone {
            apex: P3::new(76.2, 70.4823, -158.75),
            a: V3::y(),
            half: 59f64.to_radians(),
        };
        let Some(Shape::Cylinder { p, r, .. }) = full_diameter(&bore, &cone) else {
            panic!("no circle");
        };
        assert!((p - P3::new(76.2, 72.39, -158.75)).norm() < 1e-3, "{p}");
        assert_eq!(r, 3.175);
        let askew = Shape::Cone {
            apex: P3::new(76.2, 70.4823, -158.75),
            a: V3::x(),
            half: 59f64.to_radians(),
        };
        assert!(full_diameter(&bore, &askew).is_none());
    }

    #[test]
    fn the_root_is_bisected_to_the_contact() {
        let t = first_root(&|t| 3.25 - t, 10.0).expect("a root");
        assert!((t - 3.25).abs() < 1e-9);
        assert!(first_root(&|t| 30.0 - t, 10.0).is_none());
    }
}
