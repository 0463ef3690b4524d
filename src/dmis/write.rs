//! The DMIS 5.3 writer: LLIP + spec → program text.
//!
//! Layout: header and units, approach/retract/search/clearance, one sensor per probe (per
//! A/B for an indexable head), the nominal of every surface measured (a feature's faces
//! on one surface are one `FEAT`; a surface whose points are split between groups is
//! measured as `FEAT/POINT`s joined by a best-fit `CONST`), then per setup the
//! operator's prompt, the manual 3-2-1 alignment and `DATSET`, and per group its sensor,
//! `MEAS` blocks of `GOTO` and `PTMEAS`, the `DATDEF` of datum features it completed and,
//! for each tolerance whose surfaces are all complete, its `TOL` (once, after the
//! `DATDEF`s it names) and `OUTPUT`; `ENDFIL` last. Coordinates are in the part frame: after each
//! setup's `DATSET`, a `TRANS` puts the origin back at the part's.
//!
//! Every statement form is one `docs/dmis.md` lists with the public source it was
//! checked against (NIST's I++ programs, the QIF community's DMIS bindings, PTC Creo's
//! and CMM Quarterly's references).
//!
//! **Decision: setups.** The program defines the machine's frame first
//! (`D(MACHINE)=DATSET/MCS`, as NIST's programs define `D(START)`), and each setup
//! after the first starts with `RECALL/D(MACHINE)`; a setup whose part is turned writes
//! the turn as `ROTATE`s about Z, X, Z (`D(NOMk)`), so the manual points that follow,
//! in part coordinates, mean the part at its nominal place on that setup's machine
//! axes, and the virtual CMM reads the setup from them. Each probe the program selects
//! is fitted by the operator at a `PAUSE`. A setup's prompt names its holder by the
//! rack's label and the fixture's own name, not its kind (`HOLD IT BY FIXTURE VISE
//! (VISE_150): JAWS ON …`: an angle plate is modelled as a sine plate at 90°, and the
//! operator fetches the angle plate), and says where the part's +X points on the
//! machine.
//!
//! **Decision: manual alignment in DMIS.** A manual step measures the feature kind its
//! touches determine (`manual_feature`): a secondary plane's two points, which lie
//! along it across the primary (two points one above the other would leave the turn
//! unmeasured), as a line; a tertiary's one as a point; a bore touched at one height as
//! a circle — never a plane or cylinder they cannot fix; a primary cylinder or a sphere
//! needs a block of at least 3 (4) touches. `DATSET` names its features through datum
//! labels (`DATDEF/FA(x),DAT(AL1_1)` first), as DMIS's `DATSET` takes no feature
//! directly; the reader and the virtual CMM also take `FA()` there. A `DATSET`
//! direction is the `FEAT`'s: its sign turns where a split bore's touched half runs
//! against the feature's first face. A head orientation indexed for a hand touch alone
//! (`path::join::align_orients`) gets its own sensor, selected for that step, and faces
//! touched by hand only to align are declared where the alignment measures them.
//!
//! **Decision: coordinates are the part frame.** After each setup's `DATSET` (axes and
//! origins from the alignment features), `TRANS` moves the origin back to the part's,
//! so every nominal, `GOTO` and `PTMEAS` is written once in part coordinates. Once the
//! program has measured every alignment feature of the setup itself, the same `DATSET`
//! and `TRANS` follow again on those measurements (`D(SETUPn_DCC)`): the hand-touched
//! points only start the alignment. One DCC pass, not a loop: its touches land within
//! the search distance of a part placed 5 mm and 3° off, and every tolerance then reads
//! what it reads in place to 10 µm (`a_part_placed_off_is_found_by_the_alignment` in
//! `tests/suite/simulate.rs`); a second pass would touch every alignment feature again
//! for a change below that. The DCC realignment keeps the manual features of faces
//! touched by hand only, and takes a slot's or tab's centre plane where the setup
//! measured both its walls (the datum a width establishes; one wall would move the
//! frame by half the width's error). A setup whose features leave rotations or origins free says so
//! to the operator (`TEXT/OPER`: place the part at its nominal position).
//!
//! **Decision: one DMIS feature per surface.** A feature's faces that lie on one
//! surface (`PartGeometry::one_surface`: a bore in two halves that touch along their
//! seam, a plane the CAD split, coplanar pads) are one block in the path stage and one
//! `FEAT`; coaxial holes that do not touch are each their own (`<FEATURE>_1`, …), and a
//! tolerance on the feature is output for every one of its surfaces. A surface whose
//! points the plan splits between groups is measured as `FEAT/POINT`s (a block of one
//! or two touches fits no cylinder) and joined by `CONST/<type>,F(X),BF,FA(X_P1),…` at
//! its last block; a block that touches a point again (a datum measured anew with
//! another probe) starts a new measurement of the surface. `TOL` is written just before
//! its first `OUTPUT`, which waits until every surface of the tolerance's features and
//! datum features is complete, so `DATDEF` comes first; an `OUTPUT` already written is
//! not repeated when a tolerance is recorded in several groups. A feature of two
//! opposed parallel planes (a slot, a tab) is a feature of size:
//! `CONST/PARPLN,F(X_MID),BF,…` from its walls once both are measured, which `DATDEF`
//! and every tolerance but form and profile (each wall) name. A datum feature of
//! several parallel bores or pins (FTC 06's F, FTC 08's G) is a pattern:
//! `F(X)=FEAT/PATERN,F(X_1),…` and, once every member is measured in the setup,
//! `CONST/PATERN,F(X),BF,FA(X_1),…` before `DAT(F)=DATDEF/FA(X)`; the datum is the
//! pattern's axis, centre and clocking, not its first hole.
//!
//! **Decision: sensors and words.** `SNSDEF/PROBE,FIXED,CART,0,0,-L,0,0,1,D` and
//! `SNSDEF/PROBE,INDEX,POL,A,B,VEC,i,j,k,L,D` (L tip centre to head, D tip diameter,
//! the vector tip to head in machine axes); `DATSET` direction words `XDIR`… with a
//! leading `-` for a negative normal; a datum on the table is `<FEATURE>_T` (the table
//! plane); free-form faces are `GSURF`, and so is a plane only profiles read whose
//! touches fix no plane (`points_only`). Probe changes happen on the clearance plane;
//! the rack is not modelled.
//!
//! **Decision: stand-offs.** A block whose stand-off differs from the program's
//! (`path::linearise::outlast`: a narrow bore, a feature whose tolerances let it stand proud) gets
//! its own `SNSET/APPRCH` and `RETRCT`; consecutive blocks of one stand-off share one
//! `SNSET`, and the default comes back before the next block that approaches by it, or
//! at the group's end (`group`).
//!
//! **Decision: drill depth.** A distance to a drilled hole (a bore and, on its axis,
//! the cone its drill point leaves) reaches the circle where the full diameter ends,
//! constructed as `CONST/CIRCLE,F(c),INTOF,FA(bore),FA(cone)` (`full_diameter`): a
//! blind hole's depth is that of its full diameter (ASME Y14.5), and a distance to the
//! cone's apex reads a good part's drill depth long (FTC 06's 12.7 mm depths as 14.6,
//! OUT).
//!
//! **Decision: datums measured again.** Where a setup measures again a datum its
//! tolerances read (`plan::remeasure`), the writer starts a new round of the surface
//! there (`DATDEF` again) and outputs the setup's tolerances after it (`ready`).
//!
//! **Decision: scans.** DMIS 5.3 measures along a path with `PAMEAS` inside a `MEAS`
//! block, the path defined beforehand
//! (`P(label)=PATH/LINE,CART,x1,y1,z1,x2,y2,z2,i,j,k`: start, end and the scanner's
//! direction from the surface), as vendors' DMIS (RationalDMIS, Creo's CMM output)
//! writes scans; a `MEAS` block that scans announces the cloud's size at the scanner's
//! spacing, which the standard leaves to the machine (`dmis::read` does not count it).
//! The scanner is `S(label)=SNSDEF/LASER,…` in the form of the probe definitions, the
//! stand-off in the length's place and the stripe's width in the diameter's: a
//! controller maps the label to its calibrated sensor as it does for probes. A face
//! scanned from several views is one partial feature per view joined by a best-fit
//! `CONST`, as split touches are.

use super::text::{num, plain, real, wrap, Labels};
use super::Input;
use crate::access::pose::{Contact, Head};
use crate::geometry::{FaceId, Surface, P3, V3};
use crate::model::{FeatureId, Material, SlotId, TolKind, TolValue, ToleranceId};
use crate::path::{BlockPath, GroupPath, SetupPath};
use crate::plan::poses::Holder;
use crate::plan::Names;
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// The program being written.
struct Out {
    text: String,
    /// Where the last `GOTO` went, to drop a repeated one.
    at: Option<[f64; 3]>,
}

impl Out {
    /// `SNSET/APPRCH` and `SNSET/RETRCT`: the stand-off touches approach and retract by.
    fn standoff(&mut self, approach: f64, retract: f64) {
        self.stmt(&format!("SNSET/APPRCH,{}", real(approach)));
        self.stmt(&format!("SNSET/RETRCT,{}", real(retract)));
    }

    fn stmt(&mut self, s: &str) {
        for line in wrap(s) {
            self.text.push_str(&line);
            self.text.push('\n');
        }
    }

    fn comment(&mut self, s: &str) {
        let _ = writeln!(self.text, "$$ {}", plain(s, 77).to_ascii_lowercase());
    }

    /// An operator message, split into `TEXT/OPER` statements that fit a line.
    fn oper(&mut self, s: &str) {
        // In plain ASCII first: a sign spelt out (`°` as ` DEG`) takes more room.
        let s = plain(s, usize::MAX);
        let words: Vec<&str> = s.split_whitespace().collect();
        let mut cur = String::new();
        for w in words {
            if !cur.is_empty() && cur.len() + 1 + w.len() > 60 {
                self.stmt(&format!("TEXT/OPER,'{}'", plain(&cur, 60)));
                cur.clear();
            }
            if !cur.is_empty() {
                cur.push(' ');
            }
            cur.push_str(w);
        }
        if !cur.is_empty() {
            self.stmt(&format!("TEXT/OPER,'{}'", plain(&cur, 60)));
        }
    }

    fn goto(&mut self, p: &[f64; 3]) {
        if self.at == Some(*p) {
            return;
        }
        self.at = Some(*p);
        self.stmt(&format!(
            "GOTO/{},{},{}",
            real(p[0]),
            real(p[1]),
            real(p[2])
        ));
    }
}

fn xyz(p: &P3) -> String {
    format!("{},{},{}", real(p.x), real(p.y), real(p.z))
}

fn ijk(v: &V3) -> String {
    format!("{},{},{}", real(v.x), real(v.y), real(v.z))
}

/// The feature a manual alignment step measures: its label, `MEAS` word and, for a
/// line, the `DATSET` direction keyword it gives in place of its wall's normal.
struct Manual {
    label: String,
    meas: &'static str,
    line_dir: Option<String>,
}

/// Where a block's nominal comes from.
#[derive(Clone)]
enum Nominal {
    Surface(Surface, P3),
    Table(P3, V3),
}

impl Nominal {
    /// The `MEAS` type word.
    fn meas(&self) -> &'static str {
        match self {
            Nominal::Table(..) => "PLANE",
            Nominal::Surface(s, _) => match s {
                Surface::Plane { .. } => "PLANE",
                Surface::Cylinder { .. } => "CYLNDR",
                Surface::Cone { .. } => "CONE",
                Surface::Sphere { .. } => "SPHERE",
                Surface::Freeform => "GSURF",
            },
        }
    }

    /// The fewest touches that fit the surface: 3 on a plane, 4 on a sphere, 6 on a
    /// cylinder (two circles of 3) or a cone.
    fn least_touches(&self) -> usize {
        match self {
            Nominal::Table(..) => 3,
            Nominal::Surface(s, _) => match s {
                Surface::Plane { .. } => 3,
                Surface::Sphere { .. } => 4,
                Surface::Cylinder { .. } | Surface::Cone { .. } => 6,
                Surface::Freeform => 1,
            },
        }
    }

    /// The `FEAT` statement's parameters.
    fn feat(&self) -> String {
        let side = |convex: bool| if convex { "OUTER" } else { "INNER" };
        match self {
            Nominal::Table(p, n) => format!("PLANE,CART,{},{}", xyz(p), ijk(n)),
            Nominal::Surface(s, c) => match s {
                Surface::Plane { origin, normal } => {
                    let p = c - normal * (c - origin).dot(normal);
                    format!("PLANE,CART,{},{}", xyz(&p), ijk(normal))
                }
                Surface::Cylinder {
                    origin,
                    axis,
                    radius,
                    convex,
                } => {
                    let p = origin + axis * (c - origin).dot(axis);
                    format!(
                        "CYLNDR,{},CART,{},{},{}",
                        side(*convex),
                        xyz(&p),
                        ijk(axis),
                        real(2.0 * radius)
                    )
                }
                Surface::Cone {
                    apex,
                    axis,
                    half_angle,
                    convex,
                } => format!(
                    "CONE,{},CART,{},{},{}",
                    side(*convex),
                    xyz(apex),
                    ijk(axis),
                    real(2.0 * half_angle.to_degrees())
                ),
                Surface::Sphere {
                    center,
                    radius,
                    convex,
                } => format!(
                    "SPHERE,{},CART,{},{}",
                    side(*convex),
                    xyz(center),
                    real(2.0 * radius)
                ),
                Surface::Freeform => format!("GSURF,CART,{}", xyz(c)),
            },
        }
    }
}

/// The `T` label of every tolerance of `part`, and of the unit zone of each that has
/// one besides its whole-feature zone: what the writer declares and a results file
/// reports them by.
pub fn tolerance_labels(part: &crate::model::Part) -> Vec<(String, Option<String>)> {
    let mut labels = Labels::default();
    let whole: Vec<String> = part
        .tolerances
        .iter()
        .map(|t| labels.fresh("T", &t.name))
        .collect();
    whole
        .into_iter()
        .zip(&part.tolerances)
        .map(|(l, t)| {
            let unit = t
                .per_unit
                .as_ref()
                .filter(|p| p.overall)
                .map(|_| labels.fresh("T", &format!("{}_unit", t.name)));
            (l, unit)
        })
        .collect()
}

/// The DMIS word of a tolerance kind.
pub fn tol_word(k: TolKind) -> &'static str {
    match k {
        TolKind::Flatness => "FLAT",
        TolKind::Straightness => "STRGHT",
        TolKind::Circularity => "CIRLTY",
        TolKind::Cylindricity => "CYLCTY",
        TolKind::ProfileLine => "PROFL",
        TolKind::ProfileSurface => "PROFS",
        TolKind::Perpendicularity => "PERP",
        TolKind::Parallelism => "PARLEL",
        TolKind::Angularity => "ANGLR",
        TolKind::Position => "POS",
        TolKind::Concentricity => "CONCEN",
        TolKind::Coaxiality => "COAXL",
        TolKind::Symmetry => "SYM",
        TolKind::CircularRunout => "CRNOUT",
        TolKind::TotalRunout => "TRNOUT",
        TolKind::Diameter => "DIAM",
        TolKind::Radius => "RAD",
        TolKind::Width => "WIDTH",
        TolKind::Distance => "DISTB",
        TolKind::Angle => "ANGLB",
    }
}

/// Tolerances whose `TOL` statement always carries a material-condition word (ANSI/DMIS
/// 105.2's `TOL/POS,2D|3D,tolzon,MMC|LMC|RFS,…`, and the orientation tolerances that
/// take the same word in the forms PTC Creo's "Supported DMIS Commands" lists).
const MATERIAL_WORD: &[TolKind] = &[
    TolKind::Position,
    TolKind::Perpendicularity,
    TolKind::Parallelism,
    TolKind::Angularity,
];

fn material(m: Option<Material>) -> Option<&'static str> {
    match m {
        Some(Material::Mmc) => Some("MMC"),
        Some(Material::Lmc) => Some("LMC"),
        Some(Material::Rfs) => Some("RFS"),
        None => None,
    }
}

/// The sensor key of a group: its probe and its angles as written.
type SensorKey = (SlotId, String, String);

fn sensor_key(g: &GroupPath) -> SensorKey {
    (g.probe, num(g.a), num(g.b))
}

/// The sensor that touches one step of a hand alignment: its group's, or the group's
/// probe with the head indexed to the step's own orientation.
fn step_sensor(sp: &crate::path::SetupPath, step: &crate::path::AlignStep) -> SensorKey {
    let g = &sp.groups[step.group];
    match step.orient {
        Some((a, b)) => (g.probe, num(a), num(b)),
        None => sensor_key(g),
    }
}

/// A block's place in the program: (setup, group, block).
type BlockKey = (usize, usize, usize);

/// One surface of a feature as the program measures it, round by round: a round in one
/// block measures the feature itself; one whose points are split between orientations
/// or setups measures each touch as a point feature, and a best-fit `CONST` joins them
/// into the whole at its last block.
struct Surf {
    /// The label of the whole surface: what `DATDEF` and `OUTPUT` name (empty for a
    /// free-form surface measured in several blocks, each its own feature).
    full: String,
    /// Its rounds of measurement, in program order.
    rounds: Vec<Round>,
    /// Its feature.
    feature: Option<FeatureId>,
    /// Whether the table stands in for it (a datum face the part rests on).
    on_table: bool,
}

/// One measurement of a surface: the blocks up to the one that touches a point again.
struct Round {
    /// The point features' labels, in program order; empty when one block measures it.
    partials: Vec<String>,
    /// The unit stretches of its zones per unit, each constructed from its points.
    windows: Vec<Window>,
    /// The block that completes it.
    last: BlockKey,
}

/// One unit stretch of a surface under a zone per unit ([`super::units`]).
struct Window {
    /// The tolerance whose unit zone it is checked against.
    tol: ToleranceId,
    /// Its feature's label.
    label: String,
    /// The labels of the point features it is constructed from.
    members: Vec<String>,
}

/// A feature touched by hand to align: its label, its touches (point, normal) and
/// the face the operator is told of.
type HandFeature = (String, Vec<(P3, V3)>, FaceId);

/// A surface about to be declared: its label's base, nominal and feature, and whether
/// the table stands in for it.
struct SurfaceOf {
    name: String,
    nominal: Nominal,
    feature: Option<FeatureId>,
    on_table: bool,
}

/// A setup's alignment, to repeat on the program's own measurements of its features.
struct Realign {
    setup: usize,
    /// The alignment features' labels.
    labels: Vec<String>,
    /// `DATSET` parameters and `TRANS` shifts.
    fa: Vec<String>,
    shifts: Vec<String>,
    /// Alignment-feature labels measured under DCC so far in the setup.
    measured: std::collections::BTreeSet<String>,
}

/// A slot's or tab's constructed `PARPLN`: its label, its walls' surfaces, and its
/// nominal centre and direction.
type Pair = (String, [usize; 2], (P3, V3));

/// The writer's state: the program so far and the labels handed out.
struct Writer<'a> {
    input: &'a Input<'a>,
    names: Names<'a>,
    o: Out,
    labels: Labels,
    /// Sensor labels by probe and angles.
    sensors: BTreeMap<SensorKey, String>,
    current_sensor: Option<String>,
    /// The probe on the head (its slot), once one is selected.
    current_probe: Option<SlotId>,
    /// Per block, the feature label its `MEAS` names, the surface and the round.
    feats: BTreeMap<BlockKey, (String, usize, usize)>,
    /// The surfaces measured.
    surfs: Vec<Surf>,
    /// The current setup's alignment, until it is repeated under DCC.
    realign: Option<Realign>,
    /// The `OUTPUT` statements written.
    outputs: std::collections::BTreeSet<String>,
    /// Per feature of two opposed planes, its constructed `PARPLN`, the two surfaces,
    /// and the plane's nominal centre and direction (the first wall's).
    pairs: BTreeMap<FeatureId, Pair>,
    /// Per datum feature of parallel bores or pins (a pattern), its `PATERN` and the
    /// members' surfaces.
    patterns: BTreeMap<FeatureId, (String, Vec<usize>)>,
    /// Per surface, the setup it was last completed in.
    done_in: BTreeMap<usize, usize>,
    /// The surfaces complete so far.
    done: std::collections::BTreeSet<usize>,
    /// Tolerances recorded before all their surfaces were complete.
    pending: Vec<ToleranceId>,
    /// Per touch of a joined surface's blocks, its point feature's label.
    points: BTreeMap<(BlockKey, usize), String>,
    /// Per feature, the labels of its measured surfaces in order.
    faces_of: BTreeMap<Option<FeatureId>, Vec<String>>,
    /// Tolerance statements written so far (each just before its first `OUTPUT`).
    defined_tols: std::collections::BTreeSet<usize>,
    /// The unit zones' `TOL` written.
    defined_units: std::collections::BTreeSet<usize>,
    /// Per tolerance, its `TOL` statement.
    tol_stmts: Vec<String>,
    /// Per surface label, the unit stretches its latest round constructed.
    windows_of: BTreeMap<String, Vec<(ToleranceId, String)>>,
    /// Per tolerance with a unit zone besides its whole one, the unit zone's label and
    /// `TOL` statement.
    unit_tols: Vec<Option<(String, String)>>,
    /// Nominals by feature label.
    nominals: BTreeMap<String, Nominal>,
    /// Per datum, its label.
    datums: Vec<String>,
    /// Per tolerance, its label.
    tols: Vec<String>,
    /// Per feature, the labels measured so far.
    measured: BTreeMap<Option<FeatureId>, Vec<String>>,
    /// Per datum, the setup its latest `DATDEF` was written in.
    defined_in: BTreeMap<crate::model::DatumId, usize>,
    /// Per drilled hole (a bore ending in a cone), its constructed full-diameter circle.
    depths: BTreeMap<FeatureId, String>,
}

/// Writes the program.
pub fn write(input: &Input) -> String {
    let mut labels = Labels::default();
    labels.fresh("D", "MACHINE");
    let mut w = Writer {
        input,
        names: Names::new(input.model, input.geometry, input.hlip.plan),
        o: Out {
            text: String::new(),
            at: None,
        },
        labels,
        sensors: BTreeMap::new(),
        current_sensor: None,
        current_probe: None,
        feats: BTreeMap::new(),
        surfs: Vec::new(),
        points: BTreeMap::new(),
        pairs: BTreeMap::new(),
        depths: BTreeMap::new(),
        patterns: BTreeMap::new(),
        done_in: BTreeMap::new(),
        realign: None,
        outputs: std::collections::BTreeSet::new(),
        done: std::collections::BTreeSet::new(),
        pending: Vec::new(),
        faces_of: BTreeMap::new(),
        defined_tols: std::collections::BTreeSet::new(),
        defined_units: std::collections::BTreeSet::new(),
        tol_stmts: Vec::new(),
        windows_of: BTreeMap::new(),
        unit_tols: Vec::new(),
        nominals: BTreeMap::new(),
        datums: Vec::new(),
        tols: Vec::new(),
        measured: BTreeMap::new(),
        defined_in: BTreeMap::new(),
    };
    w.header();
    w.sensor_definitions();
    w.nominals();
    w.tolerances();
    let setups_n = input.llip.setups.len();
    for (si, sp) in input.llip.setups.iter().enumerate() {
        w.setup(si, setups_n, sp);
        for (gi, g) in sp.groups.iter().enumerate() {
            w.group((si, gi), g);
        }
    }
    w.o.stmt("ENDFIL");
    w.o.text
}

impl Writer<'_> {
    fn indexable(&self) -> bool {
        self.input.hlip.head == Head::Indexable
    }

    /// Header comments, program name, units and the motion settings.
    fn header(&mut self) {
        let input = self.input;
        let (part, cmm) = (self.names.part(), &input.model.cmms[input.plan.cmm.0]);
        let (hlip, llip, motion) = (input.hlip, input.llip, input.llip.motion);
        let o = &mut self.o;
        o.comment(&format!(
            "inspc {}: plan {}, part {} on cmm {}",
            env!("CARGO_PKG_VERSION"),
            input.plan.name,
            part.name,
            cmm.name
        ));
        if !input.source.is_empty() {
            o.comment(&format!("from {}", input.source));
        }
        let s = &hlip.summary;
        o.comment(&format!(
            "{} setups, {} probes, {} orientations, {} touches, path {} mm",
            s.setups,
            s.probes_used,
            s.orientations,
            llip.summary.touches,
            num((llip.summary.length * 10.0).round() / 10.0)
        ));
        o.stmt(&format!("DMISMN/'{}',05.3", plain(&input.plan.name, 60)));
        // The results file's name, as NIST's `simple_in.dms` names its output file:
        // the controller writes every `OUTPUT` there.
        o.stmt(&format!("FILNAM/'{} RESULTS'", plain(&input.plan.name, 52)));
        o.stmt("UNITS/MM,ANGDEC");
        // The machine's own frame, under a label every later setup recalls: NIST's
        // `D(START) = DATSET/MCS`, not a `D(MCS)` a strict controller never defined.
        o.stmt("D(MACHINE)=DATSET/MCS");
        o.stmt("MODE/PROG,MAN");
        // Speeds: positioning at NIST's figure in `simple_in.dms` (1.8 m/min, 30 mm/s),
        // touches at 3 mm/s, slow enough for a touch-trigger probe's pre-travel to stay
        // within its repeatability; probe radius compensation on, so that every
        // actual is the surface, not the tip centre.
        o.stmt("FEDRAT/POSVEL,MPM,1.8");
        o.stmt("FEDRAT/MESVEL,MMPS,3.0");
        o.stmt("PRCOMP/ON");
        o.standoff(motion.prehit, motion.retract);
        o.stmt(&format!("SNSET/SEARCH,{}", real(motion.search)));
        o.stmt(&format!("SNSET/CLRSRF,{}", real(motion.clearance)));
    }

    /// One sensor per probe (per probe and A/B on an indexable head), in order of first
    /// use by the measuring groups, then those only a hand alignment indexes to. A laser
    /// scanner is `SNSDEF/LASER` in the form of a probe's, its stand-off in the length's
    /// place and its stripe's width in the diameter's (see the module's decision on
    /// scans).
    fn sensor_definitions(&mut self) {
        let input = self.input;
        let cmm = &input.model.cmms[input.plan.cmm.0];
        let probes = crate::access::ProbeShape::of_cmm(input.model, cmm);
        let scanners = crate::access::scan::ScannerShape::of_cmm(input.model, cmm);
        self.o.comment("sensors");
        // The groups' sensors, then orientations the head takes only to align by hand.
        let wanted: Vec<(SlotId, f64, f64)> = input
            .llip
            .setups
            .iter()
            .flat_map(|s| s.groups.iter().map(|g| (g.probe, g.a, g.b)))
            .chain(input.llip.setups.iter().flat_map(|s| {
                s.alignment
                    .steps
                    .iter()
                    .filter_map(|st| Some((s.groups.get(st.group)?.probe, st.orient?)))
                    .map(|(p, (a, b))| (p, a, b))
            }))
            .collect();
        for (probe, a, b) in wanted {
            let key = (probe, num(a), num(b));
            if self.sensors.contains_key(&key) {
                continue;
            }
            let (kind, len, diam) = match probes.get(probe.0) {
                Some(p) => ("PROBE", real(p.reach()), real(2.0 * p.tip_radius)),
                None => match scanners.get(probe.0 - probes.len()) {
                    Some(s) => ("LASER", real(s.optics.standoff), real(s.optics.stripe)),
                    None => continue,
                },
            };
            let label_text = self.names.probe(probe);
            let name = if self.indexable() {
                format!("{label_text}_A{}B{}", key.1, key.2)
                    .replace('-', "M")
                    .replace('.', "P")
            } else {
                label_text.to_string()
            };
            let label = self.labels.fresh("S", &name);
            if self.indexable() {
                // CMM Quarterly's form (`SNSDEF/PROBE,INDEX,POL,45,45,0,0,1,100,3`): the
                // head's A and B, the mounting vector of the head (a vertical ram: +Z),
                // the length from the head's centre of rotation to the tip centre, the
                // tip's diameter (docs/dmis.md).
                self.o.stmt(&format!(
                    "S({label})=SNSDEF/{kind},INDEX,POL,{},{},0.0,0.0,1.0,{len},{diam}",
                    real(a),
                    real(b),
                ));
            } else {
                self.o.stmt(&format!(
                    "S({label})=SNSDEF/{kind},FIXED,CART,0.0,0.0,-{len},0.0,0.0,1.0,{diam}"
                ));
            }
            self.sensors.insert(key, label);
        }
    }

    /// Whether a plane of `feature` touched in `blocks` is measured as points on a
    /// surface (`GSURF`) rather than a `PLANE`: its touches cannot fix a plane (fewer
    /// than three, or in a row: NIST STC 08's two 3 × 3 mm lands, one point each), and
    /// only profiles read it, which judge each point against its nominal (ASME
    /// Y14.5-2018 § 11.3: the zone is about the true profile, no fitted plane), never a
    /// datum or a tolerance that needs the plane.
    fn points_only(&self, feature: Option<FeatureId>, blocks: &[BlockKey]) -> bool {
        let Some(f) = feature else {
            return false;
        };
        let llip = self.input.llip;
        let block = |k: &BlockKey| &llip.setups[k.0].groups[k.1].blocks[k.2];
        // A scan's cloud fixes its plane.
        if blocks.iter().any(|k| !block(k).passes.is_empty()) {
            return false;
        }
        let pts: Vec<usize> = blocks
            .iter()
            .flat_map(|k| &block(k).touches)
            .map(|t| t.point)
            .collect();
        let positions: Vec<&P3> = pts
            .iter()
            .map(|&k| &self.input.hlip.points[k].position)
            .collect();
        if pts.len() >= 3 && crate::plan::spans_area(&positions) {
            return false;
        }
        let part = self.names.part();
        let profiles = part.tolerances.iter().filter(|t| t.targets.contains(&f));
        !part.datums.iter().any(|d| d.feature == f)
            && profiles.clone().count() > 0
            && profiles
                .into_iter()
                .all(|t| matches!(t.kind, TolKind::ProfileSurface | TolKind::ProfileLine))
    }

    /// One nominal per (feature, face, table) measured, in order of first use.
    /// One `FEAT` per surface of a feature (faces on one surface are one feature), and
    /// one per partial where the program measures a surface in several blocks.
    fn nominals(&mut self) {
        let llip = self.input.llip;
        self.o.comment("nominals");
        let surfs = self.surfaces_in_order();
        let block = |k: &BlockKey| &llip.setups[k.0].groups[k.1].blocks[k.2];
        let mut count: BTreeMap<Option<FeatureId>, usize> = BTreeMap::new();
        for s in &surfs {
            if s.1 == Contact::Part {
                *count.entry(s.0).or_default() += 1;
            }
        }
        let mut k_of: BTreeMap<Option<FeatureId>, usize> = BTreeMap::new();
        for (feature, contact, _, blocks) in surfs {
            let Some(nominal) = nominal_of(self.input, block(&blocks[0])) else {
                continue;
            };
            let name = self.names.feature(feature).to_string();
            let name = if contact == Contact::Table {
                format!("{name}_T")
            } else if count.get(&feature).copied().unwrap_or(1) > 1 {
                let k = k_of.entry(feature).or_default();
                *k += 1;
                format!("{name}_{k}")
            } else {
                name
            };
            let nominal = match nominal {
                Nominal::Surface(Surface::Plane { .. }, centre)
                    if self.points_only(feature, &blocks) =>
                {
                    Nominal::Surface(Surface::Freeform, centre)
                }
                n => n,
            };
            let surface = SurfaceOf {
                name,
                nominal,
                feature,
                on_table: contact == Contact::Table,
            };
            // A free-form surface has no best fit to join: each block stands alone.
            if matches!(surface.nominal, Nominal::Surface(Surface::Freeform, _)) && blocks.len() > 1
            {
                self.freeform_nominals(surface, &blocks);
                continue;
            }
            let plane = matches!(
                surface.nominal,
                Nominal::Surface(Surface::Plane { .. }, _) | Nominal::Table(..)
            );
            let points = &self.input.hlip.points;
            // A plane's touches fix it only spread across an area (never a row).
            let fixes = |pts: &[usize]| {
                !plane
                    || crate::plan::spans_area(
                        &pts.iter().map(|&k| &points[k].position).collect::<Vec<_>>(),
                    )
            };
            let rounds = measuring_rounds(llip, &blocks, surface.nominal.least_touches(), &fixes);
            self.surface_nominals(surface, &rounds);
        }
        self.centre_planes();
        self.datum_patterns();
    }

    /// The surfaces the program measures, in program order: (feature, contact, face,
    /// blocks); a feature's blocks on one surface of the part measure one.
    fn surfaces_in_order(&self) -> Vec<(Option<FeatureId>, Contact, FaceId, Vec<BlockKey>)> {
        let geometry = self.input.geometry;
        let mut surfs: Vec<(Option<FeatureId>, Contact, FaceId, Vec<BlockKey>)> = Vec::new();
        for (si, sp) in self.input.llip.setups.iter().enumerate() {
            for (gi, g) in sp.groups.iter().enumerate() {
                for (bi, b) in g.blocks.iter().enumerate() {
                    let same = |f: FaceId| {
                        f == b.face
                            || (b.contact == Contact::Part && geometry.one_surface(f, b.face))
                    };
                    match surfs
                        .iter_mut()
                        .find(|s| s.0 == b.feature && s.1 == b.contact && same(s.2))
                    {
                        Some(s) => s.3.push((si, gi, bi)),
                        None => surfs.push((b.feature, b.contact, b.face, vec![(si, gi, bi)])),
                    }
                }
            }
        }
        surfs
    }

    /// A free-form surface measured in several blocks: one `FEAT/GSURF` per block, each
    /// its own feature and round.
    fn freeform_nominals(&mut self, surface: SurfaceOf, blocks: &[BlockKey]) {
        let SurfaceOf {
            name,
            nominal,
            feature,
            on_table,
        } = surface;
        let id = self.surfs.len();
        let mut rounds = Vec::new();
        for (j, k) in blocks.iter().enumerate() {
            let label = self.labels.fresh("F", &format!("{name}_{}", j + 1));
            self.o.stmt(&format!("F({label})=FEAT/{}", nominal.feat()));
            self.nominals.insert(label.clone(), nominal.clone());
            self.feats.insert(*k, (label.clone(), id, j));
            self.faces_of.entry(feature).or_default().push(label);
            rounds.push(Round {
                partials: vec![],
                windows: vec![],
                last: *k,
            });
        }
        self.surfs.push(Surf {
            full: String::new(),
            rounds,
            feature,
            on_table,
        });
    }

    /// A surface's `FEAT` and, per round of several blocks, its partials: a
    /// `FEAT/POINT` per touch (a block of one or two touches fits no cylinder), or the
    /// surface itself per scanned block; a best-fit `CONST` over them all is the
    /// surface.
    fn surface_nominals(&mut self, surface: SurfaceOf, rounds_of: &[Vec<BlockKey>]) {
        let llip = self.input.llip;
        let block = |k: &BlockKey| &llip.setups[k.0].groups[k.1].blocks[k.2];
        let SurfaceOf {
            name,
            nominal,
            feature,
            on_table,
        } = surface;
        let id = self.surfs.len();
        let full = self.labels.fresh("F", &name);
        self.o.stmt(&format!("F({full})=FEAT/{}", nominal.feat()));
        self.nominals.insert(full.clone(), nominal.clone());
        self.faces_of.entry(feature).or_default().push(full.clone());
        // A surface under a zone per unit is measured as points, whatever its blocks:
        // its unit stretches are constructed from them.
        let units = self.unit_zones(feature);
        let mut rounds = Vec::new();
        let mut n = 0;
        let mut w = 0;
        for (r, keys) in rounds_of.iter().enumerate() {
            let mut partials = Vec::new();
            let mut touched: Vec<(String, P3)> = Vec::new();
            for k in keys {
                self.feats.insert(*k, (full.clone(), id, r));
                if keys.len() == 1 && units.is_empty() {
                    continue;
                }
                // A scanned block of a surface scanned from several views measures
                // the surface itself: the best fit joins the views' clouds.
                if !block(k).passes.is_empty() {
                    n += 1;
                    let label = self.labels.fresh("F", &format!("{name}_S{n}"));
                    self.o.stmt(&format!("F({label})=FEAT/{}", nominal.feat()));
                    self.nominals.insert(label.clone(), nominal.clone());
                    self.points.insert((*k, usize::MAX), label.clone());
                    partials.push(label);
                    continue;
                }
                for (ti, t) in block(k).touches.iter().enumerate() {
                    n += 1;
                    let label = self.labels.fresh("F", &format!("{name}_P{n}"));
                    let p = &self.input.hlip.points[t.point];
                    self.o.stmt(&format!(
                        "F({label})=FEAT/POINT,CART,{},{}",
                        xyz(&p.position),
                        ijk(&p.normal)
                    ));
                    self.points.insert((*k, ti), label.clone());
                    touched.push((label.clone(), p.position));
                    partials.push(label);
                }
            }
            let windows = self.unit_windows(&name, &nominal, &units, &touched, &mut w);
            rounds.push(Round {
                partials,
                windows,
                last: *keys.last().expect("a round has a block"),
            });
        }
        self.surfs.push(Surf {
            full,
            rounds,
            feature,
            on_table,
        });
    }

    /// The zones per unit of the tolerances on `feature`.
    fn unit_zones(&self, feature: Option<FeatureId>) -> Vec<(ToleranceId, crate::model::UnitOf)> {
        let part = self.names.part();
        part.tolerances
            .iter()
            .enumerate()
            .filter(|(_, t)| feature.is_some_and(|f| t.targets.contains(&f)))
            .filter_map(|(i, t)| t.per_unit.as_ref().map(|p| (ToleranceId(i), p.unit)))
            .collect()
    }

    /// The unit stretches of one round of a surface (`touched`: its point features and
    /// their nominal places), each declared as a feature of the surface's kind; where the
    /// surface has no touches to build them from (a scanned face), the program says so.
    fn unit_windows(
        &mut self,
        name: &str,
        nominal: &Nominal,
        units: &[(ToleranceId, crate::model::UnitOf)],
        touched: &[(String, P3)],
        n: &mut usize,
    ) -> Vec<Window> {
        let Nominal::Surface(surface, _) = nominal else {
            return Vec::new();
        };
        let points: Vec<P3> = touched.iter().map(|t| t.1).collect();
        let mut out = Vec::new();
        for &(tol, unit) in units {
            let sets = super::units::windows(surface, unit, &points);
            if sets.is_empty() {
                let t = &self.names.part().tolerances[tol.0];
                self.o.comment(&format!(
                    "{}: no unit stretch of {name} has touches enough to fit; its zone per {} is not checked",
                    t.name,
                    unit.text()
                ));
            }
            for members in sets {
                *n += 1;
                let label = self.labels.fresh("F", &format!("{name}_U{n}"));
                // Declared where its points are: the window's centre on the surface.
                let centre = members
                    .iter()
                    .fold(V3::zeros(), |a, &i| a + points[i].coords)
                    / members.len() as f64;
                let nominal = Nominal::Surface(surface.clone(), P3::from(centre));
                self.o.stmt(&format!("F({label})=FEAT/{}", nominal.feat()));
                self.nominals.insert(label.clone(), nominal);
                out.push(Window {
                    tol,
                    label,
                    members: members.into_iter().map(|i| touched[i].0.clone()).collect(),
                });
            }
        }
        out
    }

    /// A datum feature of several parallel bores or pins (a pattern of holes) is one
    /// datum: `FEAT/PATERN` of its members, constructed once all of them are measured in
    /// a setup, so `DATDEF` names the pattern (its centre, axis and clocking), not the
    /// first hole.
    fn datum_patterns(&mut self) {
        let part = self.names.part();
        let cos = (0.1f64).to_radians().cos();
        for (f, mut surfs) in self.surfaces_by_feature() {
            surfs.retain(|&k| !self.surfs[k].full.is_empty());
            let datum = part.datums.iter().any(|d| d.feature == f);
            if !datum || surfs.len() < 2 || self.pairs.contains_key(&f) {
                continue;
            }
            let axes: Option<Vec<V3>> = surfs
                .iter()
                .map(|&k| match self.nominals.get(&self.surfs[k].full) {
                    Some(Nominal::Surface(Surface::Cylinder { axis, .. }, _)) => Some(*axis),
                    _ => None,
                })
                .collect();
            let Some(axes) = axes else { continue };
            if axes.iter().any(|a| a.dot(&axes[0]).abs() < cos) {
                continue;
            }
            let name = self.names.feature(Some(f)).to_string();
            let label = self.labels.fresh("F", &name);
            let members: Vec<String> = surfs
                .iter()
                .map(|&k| format!("F({})", self.surfs[k].full))
                .collect();
            self.o
                .stmt(&format!("F({label})=FEAT/PATERN,{}", members.join(",")));
            self.patterns.insert(f, (label, surfs));
        }
    }

    /// Whether `label` is the table standing in for a datum face: a datum, never a
    /// toleranced surface.
    fn is_table(&self, label: &str) -> bool {
        self.surfs.iter().any(|s| s.on_table && s.full == label)
    }

    /// Per feature, its surfaces (indices into `surfs`) in program order.
    fn surfaces_by_feature(&self) -> BTreeMap<FeatureId, Vec<usize>> {
        let mut out: BTreeMap<FeatureId, Vec<usize>> = BTreeMap::new();
        for (k, s) in self.surfs.iter().enumerate() {
            if let Some(f) = s.feature {
                out.entry(f).or_default().push(k);
            }
        }
        out
    }

    /// A feature made of two opposed parallel planes (a slot, a tab) is a feature of
    /// size: its width, position, symmetry and orientation belong to the pair, a
    /// `FEAT/PARPLN` constructed from the two walls once both are measured. A wall the
    /// part rests on in some setup is still one of the two: the table's surface stands
    /// in for it there, not as a third wall.
    fn centre_planes(&mut self) {
        let cos = (0.1f64).to_radians().cos();
        for (f, surfs) in self.surfaces_by_feature() {
            let walls: Vec<usize> = surfs
                .into_iter()
                .filter(|&k| !self.surfs[k].on_table)
                .collect();
            let [a, b] = walls[..] else { continue };
            // Each wall's centre, a point of its plane and its normal.
            let plane = |k: usize| match self.nominals.get(&self.surfs[k].full) {
                Some(Nominal::Surface(Surface::Plane { origin, normal }, c)) => {
                    Some((*c, *origin, *normal))
                }
                _ => None,
            };
            let (Some((pa, oa, na)), Some((pb, ob, nb))) = (plane(a), plane(b)) else {
                continue;
            };
            if na.dot(&nb) > -cos {
                continue;
            }
            // On each wall's plane, the point nearest its centre.
            let width = (ob - oa).dot(&na).abs();
            let qa = pa - na * (pa - oa).dot(&na);
            let qb = pb - nb * (pb - ob).dot(&nb);
            let mid = P3::from((qa.coords + qb.coords) / 2.0);
            // A slot's walls face each other; a tab's face away.
            let inner = (ob - oa).dot(&na) > 0.0;
            let name = self.names.feature(Some(f)).to_string();
            let label = self.labels.fresh("F", &format!("{name}_MID"));
            self.o.stmt(&format!(
                "F({label})=FEAT/PARPLN,{},CART,{},{},{}",
                if inner { "INNER" } else { "OUTER" },
                xyz(&mid),
                ijk(&na),
                real(width)
            ));
            self.pairs.insert(f, (label, [a, b], (mid, na)));
        }
    }

    /// Datum labels, then every tolerance's label and statement; each statement is
    /// written just before its first `OUTPUT`, after the `DATDEF`s it names.
    fn tolerances(&mut self) {
        let part = self.names.part();
        for d in &part.datums {
            let label = self.labels.fresh("DAT", &d.name);
            self.datums.push(label);
        }
        let labels = tolerance_labels(part);
        for (t, (label, unit)) in part.tolerances.iter().zip(labels) {
            let unit_stmt = unit.map(|l| {
                let zone = t.per_unit.as_ref().map_or(0.0, |p| p.zone);
                let stmt = format!("T({l})=TOL/{},{}", tol_word(t.kind), real(zone));
                (l, stmt)
            });
            self.unit_tols.push(unit_stmt);
            let mut params = vec![tol_word(t.kind).to_string()];
            match &t.value {
                TolValue::Zone { width, diameter } => {
                    if t.kind == TolKind::Position {
                        params.push(if *diameter { "2D" } else { "3D" }.into());
                    }
                    if t.kind == TolKind::Angularity {
                        params.push(real(t.basic_angle.unwrap_or(0.0)));
                    }
                    if matches!(t.kind, TolKind::ProfileLine | TolKind::ProfileSurface) {
                        // A profile's zone as its lower and upper limits about the true
                        // profile, equally disposed (ASME Y14.5-2018 §11.3.1: without
                        // another indication the zone is equally disposed).
                        params.push(real(-width / 2.0));
                    }
                    params.push(real(
                        if matches!(t.kind, TolKind::ProfileLine | TolKind::ProfileSurface) {
                            width / 2.0
                        } else {
                            *width
                        },
                    ));
                    // A location or orientation zone names its material condition; with
                    // none on the drawing it is RFS (ASME Y14.5-2018 §5.8.1, rule #2:
                    // regardless of feature size applies where no modifier is given).
                    let word =
                        material(t.modifier).or(MATERIAL_WORD.contains(&t.kind).then_some("RFS"));
                    params.extend(word.map(String::from));
                }
                TolValue::Size {
                    nominal,
                    lower,
                    upper,
                } => {
                    if t.kind == TolKind::Distance {
                        params.push("NOMINL".into());
                    }
                    if matches!(t.kind, TolKind::Distance | TolKind::Angle) {
                        params.push(real(*nominal));
                    }
                    params.push(real(lower - nominal));
                    params.push(real(upper - nominal));
                }
            }
            for d in &t.datums {
                let l = &self.datums[d.datum.0];
                params.push(format!("DAT({l})"));
                params.extend(material(d.modifier).map(String::from));
            }
            self.tol_stmts
                .push(format!("T({label})=TOL/{}", params.join(",")));
            self.tols.push(label);
        }
    }

    /// A face as the operator knows it: the datum or feature the program measures on it,
    /// with the face's name (the one the viewer and `inspc faces` show), else that name.
    fn face_words(&self, f: FaceId) -> String {
        let face = self.names.face(f);
        let feature = self
            .input
            .llip
            .setups
            .iter()
            .flat_map(|s| &s.groups)
            .flat_map(|g| &g.blocks)
            .find(|b| b.face == f)
            .and_then(|b| b.feature);
        let Some(ft) = feature else {
            return face.to_string();
        };
        match self.names.part().datums.iter().find(|d| d.feature == ft) {
            Some(d) => format!("datum {} ({face})", d.name),
            None => format!("{} ({face})", self.names.feature(Some(ft))),
        }
    }

    /// A setup's operator prompt, its manual alignment and `DATSET`.
    fn setup(&mut self, si: usize, setups_n: usize, sp: &SetupPath) {
        self.place_part(si, setups_n, sp);
        if sp.alignment.steps.is_empty() {
            return;
        }
        let (fa, fa_manual) = self.hand_alignment(si, sp);
        self.start_measuring(si, sp, fa, &fa_manual);
    }

    /// The setup's nominal frame (`RECALL` of the machine's, then `ROTATE`s) and the
    /// operator's placing of the part: which way up, held by what, turned how, resting
    /// on which faces and squared how closely; then `PAUSE`.
    fn place_part(&mut self, si: usize, setups_n: usize, sp: &SetupPath) {
        let setup = &self.input.hlip.setups[sp.setup];
        self.o.comment(&format!("setup {} of {setups_n}", si + 1));
        // The frame the manual points are written in: the part's own, at its nominal
        // place in this setup (machine axes turned by the setup's rotation).
        let r = nalgebra::Matrix3::from_fn(|i, j| setup.rotation[i][j]);
        if si > 0 {
            self.o.stmt("RECALL/D(MACHINE)");
        }
        for (axis, angle) in zxz_rotations(&r) {
            let d = self.labels.fresh("D", &format!("NOM{}", si + 1));
            self.o
                .stmt(&format!("D({d})=ROTATE/{axis},{}", real(angle)));
        }
        self.o.oper(&format!(
            "SETUP {} OF {setups_n}: PLACE THE PART WITH ITS {} DIRECTION UP",
            si + 1,
            direction_words(&setup.up)
        ));
        let holder = self
            .names
            .holder_naming(&setup.holder, &setup.up, &|f| self.face_words(f));
        self.o
            .oper(&format!("HOLD IT BY {}", holder.to_uppercase()));
        self.turn_about_vertical(&setup.holder, &setup.up, &r);
        for f in &setup.on_table {
            let face = self.face_words(*f);
            self.o.oper(&format!("REST {face} ON THE TABLE"));
        }
        match setup.square_within {
            Some(w) if w > 0.0 => self.o.oper(&format!(
                "SQUARE IT TO THE MACHINE AXES WITHIN {} DEG: TURNED MORE, THE STYLUS HITS THE PART",
                crate::dmis::text::num(w)
            )),
            Some(_) => self.o.oper(
                "SQUARE IT EXACTLY TO THE MACHINE AXES (AGAINST A STOP): TURNED AT ALL, THE STYLUS HITS THE PART",
            ),
            None => {}
        }
        let al = &sp.alignment;
        if !al.missing.is_empty() {
            self.o.oper(&format!(
                "THE ALIGNMENT LEAVES {} FREE: PLACE THE PART AT ITS NOMINAL POSITION, SQUARE TO THE MACHINE AXES",
                al.missing.join(", ")
            ));
        }
        self.o.stmt("PAUSE");
    }

    /// How the part is turned about the vertical: on a tilted plate, where the plate's
    /// hinge runs and which way its raised end points (the part's lie on the plate is
    /// in the holder's words); else where a part axis across `up` points.
    fn turn_about_vertical(&mut self, holder: &Holder, up: &V3, r: &nalgebra::Matrix3<f64>) {
        if let Some((hinge, rising)) = self.plate_lie(holder, up) {
            let horizontal = |v: V3| {
                let h = V3::new(v.x, v.y, 0.0).normalize();
                direction_words(&V3::new(round3(h.x), round3(h.y), 0.0))
            };
            // The plate's face (the clamped face's inward normal, `rising × hinge`)
            // leans away from its raised end; an angle plate's looks level.
            let face = r * rising.cross(&hinge);
            let hinge = r * hinge;
            let sense = if hinge.x.abs() > 1e-6 {
                hinge.x
            } else {
                hinge.y
            };
            self.o.oper(&format!(
                "TURN THE PLATE SO THAT ITS HINGE RUNS ALONG MACHINE {} AND ITS FACE LOOKS TOWARDS MACHINE {}",
                horizontal(hinge * sense.signum()).trim_start_matches('+'),
                horizontal(face)
            ));
            return;
        }
        let across = if up.x.abs() < 0.9 { V3::x() } else { V3::y() };
        let name = if across == V3::x() { "X" } else { "Y" };
        let m = r * across;
        self.o.oper(&format!(
            "TURN IT SO THAT ITS +{name} DIRECTION POINTS ALONG MACHINE {}",
            direction_words(&V3::new(round3(m.x), round3(m.y), round3(m.z)))
        ));
    }

    /// The part directions along the hinge and up the slope of the tilted plate that
    /// holds it, if a tilted plate does ([`crate::plan::poses::plate_lie`]).
    fn plate_lie(&self, holder: &Holder, up: &V3) -> Option<(V3, V3)> {
        let Holder::Fixture { slot, faces, .. } = holder else {
            return None;
        };
        let (_, id) = &self.input.model.cmms[self.input.plan.cmm.0].fixtures[*slot];
        if !matches!(
            self.input.model.fixtures[id.0].kind,
            crate::model::FixtureKind::SinePlate { .. }
        ) {
            return None;
        }
        let Surface::Plane { normal, .. } =
            self.input.geometry.faces.get(faces.first()?.0)?.surface
        else {
            return None;
        };
        crate::plan::poses::plate_lie(&normal, up)
    }

    /// The setup's alignment by hand (`MODE/MAN`), feature by feature: the `DATSET`
    /// parameters of its features, as the DCC alignment takes them and as the manual
    /// one does.
    fn hand_alignment(&mut self, si: usize, sp: &SetupPath) -> (Vec<String>, Vec<String>) {
        let al = &sp.alignment;
        self.o.stmt("MODE/MAN");
        // The probe first (fitted if it is not on the head), then how to align.
        if let Some(step) = al.steps.first() {
            self.select_key(step_sensor(sp, step));
        }
        self.o.oper(
            "ALIGN BY HAND: TOUCH EACH POINT THE CONTROLLER SHOWS, FEATURE BY FEATURE, THEN LEAVE THE PROBE ABOVE THE PART",
        );
        let mut fa = Vec::new();
        let mut fa_manual = Vec::new();
        // The part axis the primary's direction fixes, once measured.
        let mut primary: Option<usize> = None;
        for k in 0..al.steps.len() {
            if let Some((dcc, manual)) = self.hand_step(si, sp, k, &mut primary) {
                fa.push(dcc);
                fa_manual.push(manual);
            }
        }
        (fa, fa_manual)
    }

    /// Step `k` of the hand alignment: the probe brought out where the head turns or
    /// the probe changes, the feature touched, and its `DATSET` parameters for the DCC
    /// alignment and for the manual one; `None` for a step with nothing to touch.
    fn hand_step(
        &mut self,
        si: usize,
        sp: &SetupPath,
        k: usize,
        primary: &mut Option<usize>,
    ) -> Option<(String, String)> {
        let al = &sp.alignment;
        let step = &al.steps[k];
        let key = step_sensor(sp, step);
        // By hand, the operator brings the probe out before the head indexes (or the
        // probe changes) between two features: the ball may be down a bore.
        let moved = al.steps[..k]
            .last()
            .is_some_and(|prev| step_sensor(sp, prev) != key);
        if moved {
            self.o.oper(
                "RAISE THE PROBE CLEAR ABOVE THE PART, THEN CONTINUE: THE HEAD TURNS THE PROBE FOR THE NEXT FEATURE",
            );
            self.o.stmt("PAUSE");
        }
        self.select_key(key);
        let (label, pts, face) = self.hand_feature(si, sp, step)?;
        let manual = self.hand_touches(&label, &pts, face, *primary);
        if primary.is_none() {
            *primary = step
                .keywords
                .iter()
                .find(|k| k.ends_with("DIR"))
                .and_then(|k| k.trim_start_matches('-').chars().next())
                .and_then(|c| "XYZ".find(c));
        }
        let keywords = self.step_keywords(sp, step, &label);
        let manual_keywords: Vec<String> = keywords
            .iter()
            .map(|k| match (&manual.line_dir, k.ends_with("DIR")) {
                (Some(d), true) => d.clone(),
                _ => k.clone(),
            })
            .collect();
        let manual_fa = format!("FA({}),{}", manual.label, manual_keywords.join(","));
        // A face touched by hand only stays what the DCC alignment takes it from.
        let fa = if step.block.is_some() {
            format!("FA({}),{}", label, keywords.join(","))
        } else {
            manual_fa.clone()
        };
        Some((fa, manual_fa))
    }

    /// The feature a hand step touches, its touches, and the face the operator is told
    /// of: a block's feature, or a face touched only to align (declared here).
    fn hand_feature(
        &mut self,
        si: usize,
        sp: &SetupPath,
        step: &crate::path::AlignStep,
    ) -> Option<HandFeature> {
        let hlip = self.input.hlip;
        match (step.block, &step.extra) {
            (Some(bi), _) => {
                let (label, ..) = self.feats.get(&(si, step.group, bi)).cloned()?;
                let b = sp.groups[step.group].blocks.get(bi)?;
                let pts: Vec<(P3, V3)> = step
                    .points
                    .iter()
                    .map(|&k| (hlip.points[k].position, hlip.points[k].normal))
                    .collect();
                Some((label, pts, b.face))
            }
            (None, Some(extra)) => {
                let label = self.extra_nominal(si, extra);
                Some((label, extra.touches.clone(), extra.face))
            }
            (None, None) => None,
        }
    }

    /// The operator told where to touch, and the `MEAS` block of the touches by hand.
    fn hand_touches(
        &mut self,
        label: &str,
        pts: &[(P3, V3)],
        face: FaceId,
        primary: Option<usize>,
    ) -> Manual {
        let n = pts.len();
        // The table beside the part stands in for the face resting on it.
        let on = if self.is_table(label) {
            format!("THE TABLE BESIDE THE PART (FOR {})", self.face_words(face))
        } else {
            self.face_words(face)
        };
        // Two touches are a line, whose direction runs from the first to the second:
        // touched the other way round, the axis it sets turns over.
        self.o.oper(&format!(
            "BY HAND: {n} TOUCH{} ON {on}{}",
            if n == 1 { "" } else { "ES" },
            if n == 2 { ", IN THE ORDER SHOWN" } else { "" }
        ));
        let manual = self.manual_feature(label, pts, primary);
        self.o.stmt(&format!(
            "MEAS/{},F({}),{}",
            manual.meas,
            manual.label,
            pts.len()
        ));
        for (p, n) in pts {
            ptmeas_at(&mut self.o, p, n);
        }
        self.o.stmt("ENDMES");
        manual
    }

    /// A hand step's `DATSET` keywords for feature `label`. A direction is the
    /// `FEAT`'s: where the feature's nominal axis (its first face's) runs against the
    /// touched face's (the other half of a split bore), the keyword's sign turns with it.
    fn step_keywords(
        &self,
        sp: &SetupPath,
        step: &crate::path::AlignStep,
        label: &str,
    ) -> Vec<String> {
        let axis = |n: Option<&Nominal>| match n {
            Some(Nominal::Surface(
                Surface::Cylinder { axis, .. } | Surface::Cone { axis, .. },
                _,
            )) => Some(*axis),
            _ => None,
        };
        let face_nominal = step
            .block
            .and_then(|bi| sp.groups[step.group].blocks.get(bi))
            .and_then(|b| nominal_of(self.input, b));
        let against = matches!(
            (axis(self.nominals.get(label)), axis(face_nominal.as_ref())),
            (Some(a), Some(b)) if a.dot(&b) < 0.0
        );
        step.keywords
            .iter()
            .map(
                |k| match (against, k.ends_with("DIR"), k.strip_prefix('-')) {
                    (true, true, Some(k)) => k.to_string(),
                    (true, true, None) => format!("-{k}"),
                    _ => k.clone(),
                },
            )
            .collect()
    }

    /// After the hand alignment: its `DATSET` and `TRANS`, the probe brought out where
    /// the measuring run starts with another orientation, `MODE/PROG,MAN`, and the
    /// alignment kept (`fa`) to repeat on the program's own measurements.
    fn start_measuring(
        &mut self,
        si: usize,
        sp: &SetupPath,
        fa: Vec<String>,
        fa_manual: &[String],
    ) {
        let al = &sp.alignment;
        let shifts: Vec<String> = al
            .trans
            .iter()
            .map(|(k, v)| format!("{k}ORIG,{}", real(-v)))
            .collect();
        self.datset(&format!("SETUP{}", si + 1), fa_manual, &shifts);
        // The measuring run starts with the setup's first group: where the head turns
        // or the probe changes for it, the operator first brings the probe out, as
        // between two hand features.
        let last = al.steps.last().map(|st| step_sensor(sp, st));
        if let (Some(last), Some(first)) = (last, sp.groups.first()) {
            if last != sensor_key(first) {
                self.o.oper(
                    "RAISE THE PROBE CLEAR ABOVE THE PART, THEN CONTINUE: THE MEASURING RUN STARTS WITH ANOTHER PROBE ORIENTATION",
                );
                self.o.stmt("PAUSE");
            }
        }
        self.o.stmt("MODE/PROG,MAN");
        // Once the program has measured the alignment features itself, it aligns again
        // on those measurements: the hand-touched points only start it.
        let labels: Vec<String> = al
            .steps
            .iter()
            .filter_map(|st| {
                self.feats
                    .get(&(si, st.group, st.block?))
                    .map(|f| f.0.clone())
            })
            .collect();
        self.realign = Some(Realign {
            setup: si,
            labels,
            fa,
            shifts,
            measured: std::collections::BTreeSet::new(),
        });
    }

    /// The nominal of a face touched by hand only to align (`F(AL1_TOP)=FEAT/PLANE,…`),
    /// declared where the alignment measures it.
    fn extra_nominal(&mut self, si: usize, extra: &crate::path::ExtraFace) -> String {
        let face = &self.input.geometry.faces[extra.face.0];
        let label = self
            .labels
            .fresh("F", &format!("AL{}_{}", si + 1, face.name));
        let n = extra.touches.len().max(1) as f64;
        let mean = P3::from(
            extra
                .touches
                .iter()
                .fold(V3::zeros(), |s, (p, _)| s + p.coords)
                / n,
        );
        let nominal = Nominal::Surface(face.surface.clone(), mean);
        self.o.stmt(&format!("F({label})=FEAT/{}", nominal.feat()));
        self.nominals.insert(label.clone(), nominal);
        label
    }

    /// The feature a manual alignment step touches, in the DMIS kind its touches
    /// determine: the block's own feature where they do (3 on a plane, circles on two
    /// levels of a bore); else a feature of its own, defined here — a line for 2 touches
    /// on a plane (the 3-2-1 secondary), a point for 1 (the tertiary), a circle for a
    /// bore touched at one level. DMIS fits no plane to 2 points and no cylinder to one
    /// circle (`MEAS/PLANE` needs 3, Hexagon's PC-DMIS help: "a plane is defined by 3
    /// points"), so neither does a controller running this program.
    fn manual_feature(&mut self, label: &str, pts: &[(P3, V3)], primary: Option<usize>) -> Manual {
        let nominal = self.nominals.get(label).cloned();
        let pts: Vec<Touched> = pts
            .iter()
            .map(|(position, normal)| Touched {
                position: *position,
                normal: *normal,
            })
            .collect();
        let own = |meas: &'static str| Manual {
            label: label.to_string(),
            meas,
            line_dir: None,
        };
        let Some(nominal) = nominal else {
            return own("PLANE");
        };
        let mean = P3::from(
            pts.iter().fold(V3::zeros(), |s, p| s + p.position.coords) / pts.len().max(1) as f64,
        );
        match (nominal.clone(), pts.len()) {
            (Nominal::Surface(Surface::Plane { .. }, _) | Nominal::Table(..), 1) => {
                let l = self.labels.fresh("F", &format!("{label}_PT"));
                let p = pts[0];
                self.o.stmt(&format!(
                    "F({l})=FEAT/POINT,CART,{},{}",
                    xyz(&p.position),
                    ijk(&p.normal)
                ));
                Manual {
                    label: l,
                    meas: "POINT",
                    line_dir: None,
                }
            }
            (Nominal::Surface(Surface::Plane { normal, .. }, _) | Nominal::Table(_, normal), 2) => {
                let d = (pts[1].position - pts[0].position).normalize();
                let plane = d.cross(&normal).normalize();
                let l = self.labels.fresh("F", &format!("{label}_LN"));
                self.o.stmt(&format!(
                    "F({l})=FEAT/LINE,UNBND,CART,{},{},{}",
                    xyz(&mean),
                    ijk(&d),
                    ijk(&plane)
                ));
                // The line's direction keyword: the part axis it runs along, across the
                // wall's normal and the primary's direction.
                let wall = (0..3).max_by(|&a, &b| normal[a].abs().total_cmp(&normal[b].abs()));
                let axis = (0..3)
                    .filter(|&k| Some(k) != wall && Some(k) != primary)
                    .max_by(|&a, &b| d[a].abs().total_cmp(&d[b].abs()))
                    .unwrap_or(0);
                let word = format!(
                    "{}{}DIR",
                    if d[axis] < 0.0 { "-" } else { "" },
                    ['X', 'Y', 'Z'][axis]
                );
                Manual {
                    label: l,
                    meas: "LINE",
                    line_dir: Some(word),
                }
            }
            (
                Nominal::Surface(
                    Surface::Cylinder {
                        origin,
                        axis,
                        radius,
                        convex,
                    },
                    _,
                ),
                _,
            ) if pts
                .iter()
                .all(|p| ((p.position - mean).dot(&axis)).abs() < 1e-6) =>
            {
                let c = origin + axis * (mean - origin).dot(&axis);
                let l = self.labels.fresh("F", &format!("{label}_CI"));
                self.o.stmt(&format!(
                    "F({l})=FEAT/CIRCLE,{},CART,{},{},{}",
                    if convex { "OUTER" } else { "INNER" },
                    xyz(&c),
                    ijk(&axis),
                    real(2.0 * radius)
                ));
                Manual {
                    label: l,
                    meas: "CIRCLE",
                    line_dir: None,
                }
            }
            _ => own(nominal.meas()),
        }
    }

    /// `DATSET` on the alignment features (`FA(label),keywords`), then the `TRANS` that
    /// puts the origin back at the part's.
    ///
    /// DATSET refers to features only through datum labels ("the DATSET statement … does
    /// not allow you to refer to features directly", MBC's DMIS datum notes:
    /// `D(DAT1)=DATSET/DAT(A),ZDIR,ZORIG,DAT(B),YDIR,YORIG,DAT(C),XORIG`): each
    /// alignment feature is given a datum label of its own by `DATDEF` first.
    fn datset(&mut self, name: &str, fa: &[String], shifts: &[String]) {
        let mut via_datums = Vec::new();
        for (k, entry) in fa.iter().enumerate() {
            let Some((feature, rest)) = entry.strip_prefix("FA(").and_then(|e| e.split_once(')'))
            else {
                via_datums.push(entry.clone());
                continue;
            };
            let dl = self
                .labels
                .fresh("DAT", &format!("{}_{}", name.replace("SETUP", "AL"), k + 1));
            self.o.stmt(&format!("DATDEF/FA({feature}),DAT({dl})"));
            via_datums.push(format!("DAT({dl}){rest}"));
        }
        let d = self.labels.fresh("D", name);
        self.o
            .stmt(&format!("D({d})=DATSET/{}", via_datums.join(",")));
        if !shifts.is_empty() {
            let dt = self.labels.fresh("D", &name.replace("SETUP", "PART"));
            self.o.stmt(&format!("D({dt})=TRANS/{}", shifts.join(",")));
        }
    }

    /// A group: its sensor, entry, `MEAS` blocks and exit, the datums it measured and
    /// the tolerances it completes.
    fn group(&mut self, (si, gi): (usize, usize), g: &GroupPath) {
        let motion = self.input.llip.motion;
        let angles = if self.indexable() {
            format!(" at a{} b{}", num(g.a), num(g.b))
        } else {
            String::new()
        };
        self.o.comment(&format!(
            "probe {}{angles}: {} features",
            self.names.probe(g.probe),
            g.blocks.len()
        ));
        // The previous group ended on the clearance plane: change the sensor there.
        self.select(g);
        for p in &g.entry {
            self.o.goto(p);
        }
        let mut in_group: Vec<String> = Vec::new();
        // The block's own stand-off in force (`None`: the default): consecutive blocks
        // with the same stand-off share one `SNSET`, and the default comes back before
        // a block that approaches by it, or at the group's end.
        let mut own: Option<f64> = None;
        // Per datum measured here, the label that completes its surface.
        let mut datums_here: Vec<(crate::model::DatumId, String)> = Vec::new();
        for (bi, b) in g.blocks.iter().enumerate() {
            let Some((label, surf, round)) = self.feats.get(&(si, gi, bi)).cloned() else {
                continue;
            };
            let meas = self.nominals.get(&label).map_or("PLANE", Nominal::meas);
            // A block with its own stand-off (shorter in a narrow bore, longer where the
            // tolerance lets the surface stand proud) approaches and retracts by it.
            let narrow = (b.standoff - motion.prehit.max(motion.retract)).abs() > 1e-9;
            let joined = !self.surfs[surf].rounds[round].partials.is_empty();
            let wanted = (narrow && b.passes.is_empty()).then_some(b.standoff);
            if own != wanted {
                match wanted {
                    Some(s) => self.o.standoff(s, s),
                    None => self.o.standoff(motion.prehit, motion.retract),
                }
                own = wanted;
            }
            if !b.passes.is_empty() {
                let target = if joined {
                    self.points[&((si, gi, bi), usize::MAX)].clone()
                } else {
                    label.clone()
                };
                self.scan(g, b, &target, meas);
            } else {
                self.touch_block((si, gi, bi), b, &label, meas, joined, narrow);
            }
            let Some(done) = self.complete_round((si, gi, bi), surf, round, &label, meas) else {
                // Measured anew: not complete until the round's last block.
                self.done.remove(&surf);
                continue;
            };
            let Some((done, datum_label)) = self.surface_done(si, surf, b, done) else {
                continue;
            };
            if let (Some(d), Some(l)) = (b.datum, datum_label) {
                if !datums_here.iter().any(|(x, _)| *x == d) {
                    datums_here.push((d, l));
                }
            }
            in_group.push(done);
        }
        if own.is_some() {
            self.o.standoff(motion.prehit, motion.retract);
        }
        for p in &g.exit {
            self.o.goto(p);
        }
        self.realign_once_measured(si);
        // Datums measured here, then the tolerances this group completes.
        for (d, label) in datums_here {
            self.defined_in.insert(d, si);
            let dl = &self.datums[d.0];
            self.o.stmt(&format!("DATDEF/FA({label}),DAT({dl})"));
        }
        self.output_ready((si, gi), g, &in_group);
    }

    /// A block of touches: one `MEAS` of the feature, or, where the round is joined
    /// from points, one `MEAS/POINT` per touch; each touch from its stand-off point by
    /// way of its via points.
    fn touch_block(
        &mut self,
        key: BlockKey,
        b: &BlockPath,
        label: &str,
        meas: &str,
        joined: bool,
        narrow: bool,
    ) {
        let (hlip, motion) = (self.input.hlip, self.input.llip.motion);
        let o = &mut self.o;
        if !joined {
            o.stmt(&format!("MEAS/{meas},F({label}),{}", b.touches.len()));
        }
        for (ti, t) in b.touches.iter().enumerate() {
            if joined {
                let point = &self.points[&(key, ti)];
                o.stmt(&format!("MEAS/POINT,F({point}),1"));
            }
            for v in &t.via {
                o.goto(v);
            }
            o.goto(&t.standoff);
            ptmeas(o, hlip, t.point);
            if !narrow && motion.retract < motion.prehit {
                o.goto(&t.standoff);
            }
            if joined {
                o.stmt("ENDMES");
            }
        }
        if !joined {
            o.stmt("ENDMES");
        }
    }

    /// The label that completes the surface's round with block `key`: the block's own
    /// feature, or at a joined round's last block the best-fit `CONST` over its points;
    /// `None` before that block.
    fn complete_round(
        &mut self,
        key: BlockKey,
        surf: usize,
        round: usize,
        label: &str,
        meas: &str,
    ) -> Option<String> {
        let s = &self.surfs[surf];
        let r = &s.rounds[round];
        if r.partials.is_empty() {
            Some(label.to_string())
        } else if r.last == key {
            let fa: Vec<String> = r.partials.iter().map(|l| format!("FA({l})")).collect();
            let full = s.full.clone();
            self.o
                .stmt(&format!("CONST/{meas},F({full}),BF,{}", fa.join(",")));
            let mut built = Vec::new();
            for w in &r.windows {
                let fa: Vec<String> = w.members.iter().map(|l| format!("FA({l})")).collect();
                self.o
                    .stmt(&format!("CONST/{meas},F({}),BF,{}", w.label, fa.join(",")));
                built.push((w.tol, w.label.clone()));
            }
            self.windows_of.insert(full.clone(), built);
            Some(full)
        } else {
            None
        }
    }

    /// Surface `surf` complete in setup `si` as `done`: the second wall of a slot or tab
    /// makes the pair (`CONST/PARPLN`), and the last member of a datum pattern measured
    /// in the setup the pattern (`CONST/PATERN`). The label the feature is measured by
    /// now, and the one its datum takes (none for a pattern not yet whole); `None` while
    /// a pair waits for its other wall.
    fn surface_done(
        &mut self,
        si: usize,
        surf: usize,
        b: &BlockPath,
        mut done: String,
    ) -> Option<(String, Option<String>)> {
        self.done.insert(surf);
        self.done_in.insert(surf, si);
        if let Some(r) = self.realign.as_mut() {
            r.measured.insert(done.clone());
        }
        // The second wall of a slot or tab makes the pair.
        if let Some((pair, walls, _)) = b.feature.and_then(|f| self.pairs.get(&f)).cloned() {
            if !walls.iter().all(|w| self.done.contains(w)) {
                return None;
            }
            let fa: Vec<String> = walls
                .iter()
                .map(|w| format!("FA({})", self.surfs[*w].full))
                .collect();
            self.o
                .stmt(&format!("CONST/PARPLN,F({pair}),BF,{}", fa.join(",")));
            done = pair;
        }
        let list = self.measured.entry(b.feature).or_default();
        if !list.contains(&done) {
            list.push(done.clone());
        }
        // A datum pattern is its datum once every member is measured in this setup.
        let mut datum_label = Some(done.clone());
        if let Some((pat, members)) = b.feature.and_then(|f| self.patterns.get(&f)).cloned() {
            datum_label = None;
            if members.iter().all(|m| self.done_in.get(m) == Some(&si)) {
                let fa: Vec<String> = members
                    .iter()
                    .map(|m| format!("FA({})", self.surfs[*m].full))
                    .collect();
                self.o
                    .stmt(&format!("CONST/PATERN,F({pat}),BF,{}", fa.join(",")));
                datum_label = Some(pat);
            }
        }
        Some((done, datum_label))
    }

    /// The DCC alignment of setup `si`, once every alignment feature is measured under
    /// the program.
    fn realign_once_measured(&mut self, si: usize) {
        if let Some(r) = self.realign.take() {
            if r.setup == si && r.labels.iter().all(|l| r.measured.contains(l)) {
                self.o
                    .comment("alignment again, on the features as the program measured them");
                let (fa, shifts) = self.on_centre_planes(si, &r);
                self.datset(&format!("SETUP{}_DCC", si + 1), &fa, &shifts);
            } else {
                self.realign = Some(r);
            }
        }
    }

    /// The DCC alignment's `DATSET` parameters and `TRANS` shifts with each wall of a
    /// slot or tab whose other wall the setup measured too replaced by their centre
    /// plane: a width is a feature of size and the datum it establishes is its centre
    /// plane (ASME Y14.5-2018 ch. 7, datum features of size; ISO 5459:2011, the median
    /// plane as a width's situation feature), so a part whose width runs to a limit keeps
    /// its frame where the drawing puts it, not half the change off with one wall —
    /// the frame every later move is written in (NIST FTC 06's datum B, a 304.8 mm
    /// width, moved the frame into a stand-off 0.09 mm from a counterbore's wall).
    fn on_centre_planes(&self, si: usize, r: &Realign) -> (Vec<String>, Vec<String>) {
        let mut fa = r.fa.clone();
        let mut shifts = r.shifts.clone();
        for entry in &mut fa {
            let Some((wall, rest)) = entry.strip_prefix("FA(").and_then(|e| e.split_once(')'))
            else {
                continue;
            };
            let Some((centre, mid, flip)) = self.centre_plane_of(si, r, wall) else {
                continue;
            };
            let mut words = Vec::new();
            for w in rest.split(',').filter(|w| !w.is_empty()) {
                if let Some(axis) = w.strip_suffix("ORIG") {
                    let k = usize::from(axis.as_bytes()[0].saturating_sub(b'X')).min(2);
                    let shift = format!("{axis}ORIG,{}", real(-mid[k]));
                    match shifts
                        .iter_mut()
                        .find(|s| s.starts_with(&format!("{axis}ORIG,")))
                    {
                        Some(s) => *s = shift,
                        None => shifts.push(shift),
                    }
                }
                words.push(match (w.ends_with("DIR") && flip, w.strip_prefix('-')) {
                    (false, _) => w.to_string(),
                    (true, Some(plain)) => plain.to_string(),
                    (true, None) => format!("-{w}"),
                });
            }
            *entry = format!("FA({centre}),{}", words.join(","));
        }
        (fa, shifts)
    }

    /// The centre plane of the slot or tab `wall` belongs to, where setup `si` measured
    /// both its walls under the program: its label, nominal centre, and whether its
    /// direction runs against the wall's.
    fn centre_plane_of(&self, si: usize, r: &Realign, wall: &str) -> Option<(&str, P3, bool)> {
        let (centre, walls, (mid, dir)) = self
            .pairs
            .values()
            .find(|(_, ws, _)| ws.iter().any(|&w| self.surfs[w].full == wall))?;
        let both = walls.iter().all(|&w| {
            self.done_in.get(&w) == Some(&si) && r.measured.contains(&self.surfs[w].full)
        });
        let Some(Nominal::Surface(Surface::Plane { normal, .. }, _)) = self.nominals.get(wall)
        else {
            return None;
        };
        both.then_some((centre.as_str(), *mid, normal.dot(dir) < 0.0))
    }

    /// The group's tolerances, and those pending from before, output where ready: once
    /// every surface of their features and datum features is complete (a surface
    /// joined from points completes at its last block); the others stay pending.
    fn output_ready(&mut self, at: (usize, usize), g: &GroupPath, in_group: &[String]) {
        self.pending.extend(g.records.iter().copied());
        let pending = std::mem::take(&mut self.pending);
        for r in pending {
            if self.ready(r, at) {
                self.output(r, in_group);
            } else {
                self.pending.push(r);
            }
        }
    }

    /// Whether every measured surface of tolerance `r`'s features and datum features
    /// is complete after group `at` (setup, group): a surface completed in an earlier
    /// setup that this setup measures again in a later group (a datum measured anew
    /// where it is read, see [`crate::plan`]'s `remeasure`) is read at that measurement.
    fn ready(&self, r: ToleranceId, at: (usize, usize)) -> bool {
        let part = self.names.part();
        let t = &part.tolerances[r.0];
        // A datum defined in this setup is the one the tolerance reads: its surfaces
        // measured in other setups are not waited for. The table standing in for a
        // toleranced feature (as another tolerance's datum) is not the feature.
        let datums: Vec<FeatureId> = t
            .datums
            .iter()
            .filter(|d| self.defined_in.get(&d.datum) != Some(&at.0))
            .map(|d| part.datums[d.datum.0].feature)
            .collect();
        self.surfs
            .iter()
            .enumerate()
            .filter(|(_, s)| {
                s.feature
                    .is_some_and(|f| datums.contains(&f) || (t.targets.contains(&f) && !s.on_table))
            })
            .all(|(k, s)| {
                let from_before = self.done_in.get(&k) != Some(&at.0);
                let again_later = s
                    .rounds
                    .iter()
                    .any(|round| round.last.0 == at.0 && round.last.1 > at.1);
                self.done.contains(&k) && !(from_before && again_later)
            })
    }

    /// Where a distance reaches a drilled hole — a bore and the cone its drill point
    /// leaves, on one axis — the circle where the full diameter ends, constructed as the
    /// intersection of the two (`CONST/CIRCLE,F(c),INTOF,FA(bore),FA(cone)`, the form of
    /// the "Supported DMIS Commands" tables vendors publish, e.g. PTC Creo's). A blind
    /// hole's depth is the depth of its full diameter, not of the drill point (ASME
    /// Y14.5, dimensioning of blind holes): a distance to the cone's apex reads FTC 06's
    /// 12.7 mm drill depth as 14.6. `None` for any other feature.
    fn full_diameter(&mut self, f: FeatureId, labels: &[String]) -> Option<String> {
        if let Some(l) = self.depths.get(&f) {
            return Some(l.clone());
        }
        let (mut bore, mut cone) = (None, None);
        for l in labels {
            match self.nominals.get(l) {
                Some(Nominal::Surface(
                    Surface::Cylinder {
                        origin,
                        axis,
                        radius,
                        convex: false,
                    },
                    _,
                )) if bore.is_none() => bore = Some((l, *origin, *axis, *radius)),
                Some(Nominal::Surface(
                    Surface::Cone {
                        apex,
                        axis,
                        half_angle,
                        convex: false,
                    },
                    _,
                )) if cone.is_none() => cone = Some((l, *apex, *axis, *half_angle)),
                _ => {}
            }
        }
        let ((bl, origin, axis, radius), (cl, apex, cone_axis, half)) = (bore?, cone?);
        // One axis: parallel, the apex on the bore's axis.
        let off = (apex - origin) - axis * (apex - origin).dot(&axis);
        if axis.dot(&cone_axis).abs() < 1.0 - 1e-6 || off.norm() > 1e-3 || half.tan() < 1e-6 {
            return None;
        }
        let centre = apex + cone_axis * (radius / half.tan());
        let name = self.names.feature(Some(f)).to_string();
        let label = self.labels.fresh("F", &format!("{name}_FULL"));
        self.o.stmt(&format!(
            "F({label})=FEAT/CIRCLE,INNER,CART,{},{},{}",
            xyz(&centre),
            ijk(&axis),
            real(2.0 * radius)
        ));
        self.o
            .stmt(&format!("CONST/CIRCLE,F({label}),INTOF,FA({bl}),FA({cl})"));
        self.depths.insert(f, label.clone());
        Some(label)
    }

    /// `OUTPUT` of a tolerance over its features' labels: those measured in this group,
    /// else those measured before.
    fn output(&mut self, r: ToleranceId, in_group: &[String]) {
        let part = self.names.part();
        let t = &part.tolerances[r.0];
        let tl = self.tols[r.0].clone();
        // Form and profile tolerances apply to each wall of a slot; the others to the pair.
        let per_wall = matches!(
            t.kind,
            TolKind::Flatness
                | TolKind::Straightness
                | TolKind::ProfileLine
                | TolKind::ProfileSurface
        );
        let sized = matches!(t.kind, TolKind::Diameter | TolKind::Radius);
        let labels_of = |f: FeatureId| -> Vec<String> {
            if let Some((pair, walls, _)) = self.pairs.get(&f) {
                return if per_wall {
                    walls.iter().map(|w| self.surfs[*w].full.clone()).collect()
                } else {
                    vec![pair.clone()]
                };
            }
            // Every surface of the feature, those of this group first: a tolerance is
            // output once all of them are complete, and it applies to each (a size on a
            // pattern of holes is every hole's size, not the last one measured).
            let f = Some(f);
            let mut labels: Vec<String> = self
                .faces_of
                .get(&f)
                .into_iter()
                .flatten()
                .filter(|l| in_group.contains(l))
                .cloned()
                .collect();
            for l in self.measured.get(&f).into_iter().flatten() {
                if !labels.contains(l) {
                    labels.push(l.clone());
                }
            }
            // The table stands in for a datum; the tolerance is the part's surface's.
            labels.retain(|l| !self.is_table(l));
            // A size is a circle's, cylinder's, cone's or sphere's: a free-form face
            // (`GSURF`) reports none (the graph stage warns, `size_on_freeform`).
            if sized {
                labels.retain(|l| {
                    !matches!(
                        self.nominals.get(l),
                        Some(Nominal::Surface(Surface::Freeform, _))
                    )
                });
            }
            labels
        };
        let profile = matches!(t.kind, TolKind::ProfileLine | TolKind::ProfileSurface);
        let mut lines = Vec::new();
        let mut unit_lines = Vec::new();
        if profile {
            // A profile of several surfaces is one zone over them all (Y14.5-2018
            // ch. 11): one `OUTPUT` naming every surface.
            let fa: Vec<String> = t
                .targets
                .iter()
                .flat_map(|&f| labels_of(f))
                .map(|l| format!("FA({l})"))
                .collect();
            if !fa.is_empty() {
                lines.push(format!("OUTPUT/{},TA({tl})", fa.join(",")));
            }
        } else if t.targets.len() > 1 {
            let firsts: Vec<(FeatureId, Vec<String>)> =
                t.targets.iter().map(|&f| (f, labels_of(f))).collect();
            let mut fa = Vec::new();
            for (f, labels) in firsts {
                let depth = (t.kind == TolKind::Distance)
                    .then(|| self.full_diameter(f, &labels))
                    .flatten();
                if let Some(l) = depth.or_else(|| labels.first().cloned()) {
                    fa.push(format!("FA({l})"));
                }
            }
            if fa.len() == t.targets.len() {
                lines.push(format!("OUTPUT/{},TA({tl})", fa.join(",")));
            }
        } else {
            let whole = t.per_unit.as_ref().is_none_or(|p| p.overall);
            for &f in &t.targets {
                for l in labels_of(f) {
                    if whole {
                        lines.push(format!("OUTPUT/FA({l}),TA({tl})"));
                    }
                    self.unit_outputs(r, &l, &mut unit_lines);
                }
            }
        }
        // A tolerance recorded in several groups reports the same features once.
        lines.retain(|l| !self.outputs.contains(l));
        unit_lines.retain(|l| !self.outputs.contains(l));
        self.outputs
            .extend(lines.iter().chain(&unit_lines).cloned());
        let own = lines.len()
            + if t.per_unit.as_ref().is_some_and(|p| !p.overall) {
                unit_lines.len()
            } else {
                0
            };
        if own > 0 && self.defined_tols.insert(r.0) {
            let stmt = self.tol_stmts[r.0].clone();
            self.o.stmt(&stmt);
        }
        for l in lines {
            self.o.stmt(&l);
        }
        if let (Some((_, stmt)), false) = (&self.unit_tols[r.0], unit_lines.is_empty()) {
            if self.defined_units.insert(r.0) {
                let stmt = stmt.clone();
                self.o.stmt(&stmt);
            }
        }
        for l in unit_lines {
            self.o.stmt(&l);
        }
    }

    /// The `OUTPUT`s of tolerance `r`'s unit zone on the unit stretches of surface
    /// `label`: under the unit zone's own label where the tolerance also bounds the whole
    /// feature, else under the tolerance's.
    fn unit_outputs(&self, r: ToleranceId, label: &str, lines: &mut Vec<String>) {
        let tl = match &self.unit_tols[r.0] {
            Some((l, _)) => l,
            None => &self.tols[r.0],
        };
        for (tol, w) in self.windows_of.get(label).into_iter().flatten() {
            if *tol == r {
                lines.push(format!("OUTPUT/FA({w}),TA({tl})"));
            }
        }
    }

    /// A scanned block: one `PATH/LINE` per pass (start, end, and the scanner's direction
    /// from the surface), then the `MEAS` of feature `target` running each pass with
    /// `PAMEAS` after the moves to its start. The point count is the cloud's at the
    /// scanner's spacing.
    fn scan(&mut self, g: &GroupPath, b: &BlockPath, target: &str, meas: &str) {
        let input = self.input;
        let cmm = &input.model.cmms[input.plan.cmm.0];
        let probes = cmm.probes.len();
        let optics = crate::access::scan::ScannerShape::of_cmm(input.model, cmm)
            .get(g.probe.0 - probes)
            .map(|s| s.optics);
        let dir = V3::from(g.direction);
        let mut paths = Vec::new();
        let mut count = 0.0;
        for (k, p) in b.passes.iter().enumerate() {
            let label = self.labels.fresh("P", &format!("{target}_{}", k + 1));
            let (s, e) = (P3::from(p.start), P3::from(p.end));
            self.o.stmt(&format!(
                "P({label})=PATH/LINE,CART,{},{},{}",
                xyz(&s),
                xyz(&e),
                ijk(&dir)
            ));
            if let Some(o) = optics {
                count +=
                    ((e - s).norm() / o.spacing[1]).floor() * (o.stripe / o.spacing[0]).floor();
            }
            paths.push(label);
        }
        let o = &mut self.o;
        o.stmt(&format!("MEAS/{meas},F({target}),{}", count as u64));
        for (p, label) in b.passes.iter().zip(&paths) {
            for v in &p.via {
                o.goto(v);
            }
            o.goto(&p.start);
            o.stmt(&format!("PAMEAS/P({label})"));
            o.at = Some(p.end);
        }
        o.stmt("ENDMES");
    }

    /// `SNSLCT` when the group's sensor is not the current one.
    /// `SNSLCT` of the group's sensor; where it is another probe than the one on the
    /// head (not only other angles), or the first, the operator is told to fit it and the
    /// program waits (`PAUSE`): the machine has no changer the spec declares, and a
    /// controller running with the wrong stylus would drive it into the part by the
    /// difference in length.
    fn select(&mut self, g: &GroupPath) {
        self.select_key(sensor_key(g));
    }

    /// [`Writer::select`] by the sensor's key: a group's, or an orientation the head
    /// takes only for the hand alignment.
    fn select_key(&mut self, key: SensorKey) {
        let probe = key.0;
        let Some(s) = self.sensors.get(&key).cloned() else {
            return;
        };
        if self.current_sensor.as_ref() == Some(&s) {
            return;
        }
        if self.current_probe != Some(probe) {
            let cmm = &self.input.model.cmms[self.input.plan.cmm.0];
            let what = cmm
                .probes
                .get(probe.0)
                .map(|(_, id)| self.input.model.probes[id.0].name.clone());
            let label = self.names.probe(probe);
            let kind = if self.names.is_scanner(probe) {
                "SCANNER"
            } else {
                "PROBE"
            };
            let verb = if self.current_probe.is_some() {
                "CHANGE THE"
            } else {
                "THE FIRST"
            };
            self.o.oper(&format!(
                "{verb} {kind}: FIT {label}{} ON THE HEAD, QUALIFIED, THEN CONTINUE",
                what.map_or(String::new(), |w| format!(" ({w})"))
            ));
            self.o.stmt("PAUSE");
        }
        self.o.at = None;
        self.o.stmt(&format!("SNSLCT/S({s})"));
        self.current_sensor = Some(s);
        self.current_probe = Some(probe);
    }
}

fn ptmeas(o: &mut Out, hlip: &crate::plan::Hlip, k: usize) {
    let p = &hlip.points[k];
    o.at = None;
    o.stmt(&format!(
        "PTMEAS/CART,{},{}",
        xyz(&p.position),
        ijk(&p.normal)
    ));
}

/// A touch by hand: where, and the surface's outward normal there.
#[derive(Clone, Copy)]
struct Touched {
    position: P3,
    normal: V3,
}

/// `PTMEAS` at a contact point with its outward normal.
fn ptmeas_at(o: &mut Out, p: &P3, n: &V3) {
    o.at = None;
    o.stmt(&format!("PTMEAS/CART,{},{}", xyz(p), ijk(n)));
}

/// The `ROTATE` statements that turn the machine's frame into the part's at its nominal
/// place: `r` (part → machine) as intrinsic rotations about Z, then X, then Z (degrees),
/// those of no angle left out. `ROTATE/ZAXIS,a` turns the current frame's axes by `a`
/// about its own Z, so the three compose as `Rz(α)·Rx(β)·Rz(γ) = r`.
pub(crate) fn zxz_rotations(r: &nalgebra::Matrix3<f64>) -> Vec<(&'static str, f64)> {
    let beta = r[(2, 2)].clamp(-1.0, 1.0).acos();
    let (alpha, gamma) = if beta.sin().abs() > 1e-9 {
        (r[(0, 2)].atan2(-r[(1, 2)]), r[(2, 0)].atan2(r[(2, 1)]))
    } else {
        (r[(1, 0)].atan2(r[(0, 0)]), 0.0)
    };
    [("ZAXIS", alpha), ("XAXIS", beta), ("ZAXIS", gamma)]
        .into_iter()
        .map(|(a, x)| (a, x.to_degrees()))
        .filter(|(_, x)| num(*x) != "0")
        .collect()
}

/// `+Z`, `-X`, or the vector for a direction off the axes.
fn direction_words(v: &V3) -> String {
    for (k, a) in ['X', 'Y', 'Z'].iter().enumerate() {
        if v[k].abs() > 1.0 - 1e-9 {
            return format!("{}{a}", if v[k] > 0.0 { "+" } else { "-" });
        }
    }
    format!("({}, {}, {})", num(v.x), num(v.y), num(v.z))
}

/// The nominal of a block: the face's analytic surface near its points, or the table.
fn nominal_of(input: &Input, b: &BlockPath) -> Option<Nominal> {
    let hlip = input.hlip;
    if b.contact == Contact::Table {
        let p = &hlip.points[b.touches.first()?.point];
        return Some(Nominal::Table(p.position, p.normal));
    }
    if b.touches.is_empty() && b.passes.is_empty() {
        return None;
    }
    let face = input.geometry.faces.get(b.face.0)?;
    let mut surface = face.surface.clone();
    // A round surface a size tolerance controls takes the drawing's size.
    if let (Some(f), Surface::Cylinder { radius, .. } | Surface::Sphere { radius, .. }) =
        (b.feature, &mut surface)
    {
        let part = &input.model.parts[input.plan.part.0];
        let drawing = part
            .tolerances
            .iter()
            .filter(|t| t.targets.contains(&f))
            .find_map(|t| t.drawing_diameter(2.0 * *radius));
        if let Some(d) = drawing {
            *radius = d / 2.0;
        }
    }
    Some(Nominal::Surface(surface, face.centroid))
}

/// A surface's blocks in rounds: a block that touches a point again (a datum measured
/// anew with another probe) starts a new round, which measures the surface anew. A
/// round of fewer touches than the surface needs (`least`), or whose touched points
/// do not fix it (`fixes`: a plane's three points in a row, NIST CTC 03's datum D
/// touched again along one edge), fits nothing: it joins the round before it, or after
/// it for the first.
fn measuring_rounds(
    llip: &crate::path::Llip,
    blocks: &[BlockKey],
    least: usize,
    fixes: &dyn Fn(&[usize]) -> bool,
) -> Vec<Vec<BlockKey>> {
    let block = |k: &BlockKey| &llip.setups[k.0].groups[k.1].blocks[k.2];
    let mut rounds_of: Vec<Vec<BlockKey>> = Vec::new();
    let mut seen: std::collections::BTreeSet<usize> = std::collections::BTreeSet::new();
    for k in blocks {
        let pts: Vec<usize> = block(k).touches.iter().map(|t| t.point).collect();
        if rounds_of.is_empty() || pts.iter().any(|p| seen.contains(p)) {
            rounds_of.push(Vec::new());
            seen.clear();
        }
        seen.extend(pts);
        rounds_of.last_mut().expect("a round").push(*k);
    }
    let touches = |keys: &[BlockKey]| -> usize {
        keys.iter()
            .map(|k| block(k).touches.len().max(block(k).passes.len() * least))
            .sum()
    };
    let fits = |keys: &[BlockKey]| {
        let scanned = keys.iter().any(|k| !block(k).passes.is_empty());
        let pts: Vec<usize> = keys
            .iter()
            .flat_map(|k| block(k).touches.iter().map(|t| t.point))
            .collect();
        touches(keys) >= least && (scanned || fixes(&pts))
    };
    let mut r = 0;
    while rounds_of.len() > 1 && r < rounds_of.len() {
        if fits(&rounds_of[r]) {
            r += 1;
            continue;
        }
        let keys = rounds_of.remove(r);
        let into = r.saturating_sub(1).min(rounds_of.len() - 1);
        if r == 0 {
            let mut joined = keys;
            joined.append(&mut rounds_of[0]);
            rounds_of[0] = joined;
        } else {
            rounds_of[into].extend(keys);
        }
    }
    rounds_of
}

/// A number rounded to 1e-3, without `-0`.
fn round3(x: f64) -> f64 {
    let r = (x * 1e3).round() / 1e3;
    if r == 0.0 {
        0.0
    } else {
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn operator_text_keeps_every_word_when_signs_are_spelt_out() {
        let mut o = Out {
            text: String::new(),
            at: None,
        };
        let msg = "hold it by fixture sine (sine_plate) under datum G (face_22), face_27, \
                   tilted 53.4°, its (0.707, -0.707, 0) direction along the hinge, its +x side \
                   rising, Ø8 ± 0.1";
        o.oper(msg);
        let said: Vec<String> = o
            .text
            .lines()
            .map(|l| {
                assert!(l.len() <= crate::dmis::text::LINE_MAX, "{l}");
                l.trim_start_matches("TEXT/OPER,'")
                    .trim_end_matches('\'')
                    .to_string()
            })
            .collect();
        assert_eq!(
            said.join(" "),
            plain(msg, usize::MAX)
                .split_whitespace()
                .collect::<Vec<_>>()
                .join(" ")
        );
    }
}
