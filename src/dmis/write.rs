//! The DMIS 5.3 writer: LLIP + spec → program text (DESIGN.md, DMIS conventions).
//!
//! Layout: header and units, approach/retract/search/clearance, one sensor per probe (per
//! A/B for an indexable head), the nominal of every face measured, datum-free
//! tolerances and datum tolerances, then per setup the operator's prompt, the manual
//! 3-2-1 alignment and `DATSET`, and per group its sensor, `MEAS` blocks of `GOTO` and
//! `PTMEAS`, the `DATDEF` of datum features it measured and the `OUTPUT` of the
//! tolerances it completes; `ENDFIL` last. Coordinates are in the part frame: after each
//! setup's `DATSET`, a `TRANS` puts the origin back at the part's.

use super::text::{num, plain, wrap, Labels};
use super::Input;
use crate::access::pose::{Contact, Head};
use crate::geometry::{FaceId, Surface, P3, V3};
use crate::model::{FeatureId, Material, SlotId, TolKind, TolValue, ToleranceId};
use crate::path::{BlockPath, GroupPath, SetupPath};
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
        self.stmt(&format!("GOTO/{},{},{}", num(p[0]), num(p[1]), num(p[2])));
    }
}

fn xyz(p: &P3) -> String {
    format!("{},{},{}", num(p.x), num(p.y), num(p.z))
}

fn ijk(v: &V3) -> String {
    format!("{},{},{}", num(v.x), num(v.y), num(v.z))
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
                        num(2.0 * radius)
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
                    num(2.0 * half_angle.to_degrees())
                ),
                Surface::Sphere {
                    center,
                    radius,
                    convex,
                } => format!(
                    "SPHERE,{},CART,{},{}",
                    side(*convex),
                    xyz(center),
                    num(2.0 * radius)
                ),
                Surface::Freeform => format!("GSURF,CART,{}", xyz(c)),
            },
        }
    }
}

/// The DMIS word of a tolerance kind.
fn tol_word(k: TolKind) -> &'static str {
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

/// A measured face's key: (feature, face, contact).
type FaceKey = (Option<FeatureId>, FaceId, Contact);

fn face_key(b: &BlockPath) -> FaceKey {
    (b.feature, b.face, b.contact)
}

/// The writer's state: the program so far and the labels handed out.
struct Writer<'a> {
    input: &'a Input<'a>,
    names: Names<'a>,
    o: Out,
    labels: Labels,
    /// Sensor labels by probe and angles.
    sensors: BTreeMap<SensorKey, String>,
    current_sensor: Option<String>,
    /// Feature labels by measured face.
    feats: BTreeMap<FaceKey, String>,
    /// Per feature, the labels of its measured faces in order.
    faces_of: BTreeMap<Option<FeatureId>, Vec<String>>,
    /// Nominals by feature label.
    nominals: BTreeMap<String, Nominal>,
    /// Per datum, its label.
    datums: Vec<String>,
    /// Per tolerance, its label.
    tols: Vec<String>,
    /// Per feature, the labels measured so far.
    measured: BTreeMap<Option<FeatureId>, Vec<String>>,
}

/// Writes the program.
pub fn write(input: &Input) -> String {
    let mut w = Writer {
        input,
        names: Names::new(input.model, input.geometry, input.hlip.plan),
        o: Out {
            text: String::new(),
            at: None,
        },
        labels: Labels::default(),
        sensors: BTreeMap::new(),
        current_sensor: None,
        feats: BTreeMap::new(),
        faces_of: BTreeMap::new(),
        nominals: BTreeMap::new(),
        datums: Vec::new(),
        tols: Vec::new(),
        measured: BTreeMap::new(),
    };
    w.header();
    w.sensor_definitions();
    w.nominals();
    w.tolerances();
    let setups_n = input.llip.setups.len();
    for (si, sp) in input.llip.setups.iter().enumerate() {
        w.setup(si, setups_n, sp);
        for g in &sp.groups {
            w.group(g);
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
        o.stmt("UNITS/MM,ANGDEC");
        o.stmt("MODE/PROG,MAN");
        o.stmt(&format!("SNSET/APPRCH,{}", num(motion.prehit)));
        o.stmt(&format!("SNSET/RETRCT,{}", num(motion.retract)));
        o.stmt(&format!("SNSET/SEARCH,{}", num(motion.search)));
        o.stmt(&format!("SNSET/CLRSRF,{}", num(motion.clearance)));
    }

    /// One sensor per probe (per probe and A/B on an indexable head), in order of first
    /// use.
    fn sensor_definitions(&mut self) {
        let input = self.input;
        let cmm = &input.model.cmms[input.plan.cmm.0];
        let probes = crate::access::ProbeShape::of_cmm(input.model, cmm);
        self.o.comment("sensors");
        for g in input.llip.setups.iter().flat_map(|s| &s.groups) {
            let key = sensor_key(g);
            if self.sensors.contains_key(&key) {
                continue;
            }
            let Some(probe) = probes.get(g.probe.0) else {
                continue;
            };
            let label_text = self.names.probe(g.probe);
            let name = if self.indexable() {
                format!("{label_text}_A{}B{}", key.1, key.2)
                    .replace('-', "M")
                    .replace('.', "P")
            } else {
                label_text.to_string()
            };
            let label = self.labels.fresh("S", &name);
            let diam = num(2.0 * probe.tip_radius);
            let len = num(probe.reach());
            if self.indexable() {
                let d = crate::access::head_direction(g.a, g.b);
                self.o.stmt(&format!(
                    "S({label})=SNSDEF/PROBE,INDEX,POL,{},{},VEC,{},{len},{diam}",
                    num(g.a),
                    num(g.b),
                    ijk(&d)
                ));
            } else {
                self.o.stmt(&format!(
                    "S({label})=SNSDEF/PROBE,FIXED,CART,0,0,-{len},0,0,1,{diam}"
                ));
            }
            self.sensors.insert(key, label);
        }
    }

    /// One nominal per (feature, face, table) measured, in order of first use.
    fn nominals(&mut self) {
        let llip = self.input.llip;
        self.o.comment("nominals");
        // How many faces (or table stand-ins) each feature is measured on.
        let mut face_count: BTreeMap<Option<FeatureId>, usize> = BTreeMap::new();
        let mut seen = std::collections::BTreeSet::new();
        let blocks = || {
            llip.setups
                .iter()
                .flat_map(|s| &s.groups)
                .flat_map(|g| &g.blocks)
        };
        for b in blocks() {
            if seen.insert(face_key(b)) {
                *face_count.entry(b.feature).or_default() += 1;
            }
        }
        for b in blocks() {
            let key = face_key(b);
            if self.feats.contains_key(&key) {
                continue;
            }
            let Some(nominal) = nominal_of(self.input, b) else {
                continue;
            };
            let count = face_count.get(&b.feature).copied().unwrap_or(1);
            let k = self.faces_of.get(&b.feature).map_or(0, Vec::len) + 1;
            let feature = self.names.feature(b.feature);
            let name = if b.contact == Contact::Table {
                format!("{feature}_T")
            } else if count > 1 {
                format!("{feature}_{k}")
            } else {
                feature.to_string()
            };
            let label = self.labels.fresh("F", &name);
            self.o.stmt(&format!("F({label})=FEAT/{}", nominal.feat()));
            self.faces_of
                .entry(b.feature)
                .or_default()
                .push(label.clone());
            self.nominals.insert(label.clone(), nominal);
            self.feats.insert(key, label);
        }
    }

    /// Datum labels, then every tolerance of the part.
    fn tolerances(&mut self) {
        let part = self.names.part();
        self.o.comment("tolerances");
        for d in &part.datums {
            let label = self.labels.fresh("DAT", &d.name);
            self.datums.push(label);
        }
        for t in &part.tolerances {
            let label = self.labels.fresh("T", &t.name);
            let mut params = vec![tol_word(t.kind).to_string()];
            match &t.value {
                TolValue::Zone { width, diameter } => {
                    if t.kind == TolKind::Position {
                        params.push(if *diameter { "2D" } else { "3D" }.into());
                    }
                    if t.kind == TolKind::Angularity {
                        params.push(num(t.basic_angle.unwrap_or(0.0)));
                    }
                    params.push(num(*width));
                    params.extend(material(t.modifier).map(String::from));
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
                        params.push(num(*nominal));
                    }
                    params.push(num(lower - nominal));
                    params.push(num(upper - nominal));
                }
            }
            for d in &t.datums {
                let l = &self.datums[d.datum.0];
                params.push(format!("DAT({l})"));
                params.extend(material(d.modifier).map(String::from));
            }
            self.o.stmt(&format!("T({label})=TOL/{}", params.join(",")));
            self.tols.push(label);
        }
    }

    /// A setup's operator prompt, its manual alignment and `DATSET`.
    fn setup(&mut self, si: usize, setups_n: usize, sp: &SetupPath) {
        let hlip = self.input.hlip;
        let setup = &hlip.setups[sp.setup];
        self.o.comment(&format!("setup {} of {setups_n}", si + 1));
        self.o.oper(&format!(
            "SETUP {} OF {setups_n}: PLACE THE PART WITH ITS {} DIRECTION UP",
            si + 1,
            direction_words(&setup.up)
        ));
        self.o.oper(&format!(
            "HOLD IT BY {}",
            self.names.holder(&setup.holder, &setup.up).to_uppercase()
        ));
        // How it is turned about the vertical: where a part axis across `up` points.
        let r = nalgebra::Matrix3::from_fn(|i, j| setup.rotation[i][j]);
        let across = if setup.up.x.abs() < 0.9 {
            V3::x()
        } else {
            V3::y()
        };
        let name = if across == V3::x() { "X" } else { "Y" };
        let m = r * across;
        self.o.oper(&format!(
            "TURN IT SO THAT ITS +{name} DIRECTION POINTS ALONG MACHINE {}",
            direction_words(&V3::new(round3(m.x), round3(m.y), round3(m.z)))
        ));
        for f in &setup.on_table {
            let face = self.names.face(*f);
            self.o.oper(&format!("REST FACE {face} ON THE TABLE"));
        }
        let al = &sp.alignment;
        if !al.missing.is_empty() {
            self.o.oper(&format!(
                "THE ALIGNMENT LEAVES {} FREE: PLACE THE PART AT ITS NOMINAL POSITION, SQUARE TO THE MACHINE AXES",
                al.missing.join(", ")
            ));
        }
        self.o.stmt("PAUSE");
        if al.steps.is_empty() {
            return;
        }
        self.o.stmt("MODE/MAN");
        self.o
            .oper("TOUCH THE POINTS SHOWN BY HAND, THEN LEAVE THE PROBE ABOVE THE PART");
        let mut fa = Vec::new();
        for step in &al.steps {
            let g = &sp.groups[step.group];
            let b = &g.blocks[step.block];
            let Some(label) = self.feats.get(&face_key(b)).cloned() else {
                continue;
            };
            self.select(g);
            let meas = self.nominals.get(&label).map_or("PLANE", Nominal::meas);
            self.o
                .stmt(&format!("MEAS/{meas},F({label}),{}", step.points.len()));
            for &k in &step.points {
                ptmeas(&mut self.o, hlip, k);
            }
            self.o.stmt("ENDMES");
            fa.push(format!("FA({label}),{}", step.keywords.join(",")));
        }
        let d = self.labels.fresh("D", &format!("SETUP{}", si + 1));
        self.o.stmt(&format!("D({d})=DATSET/{}", fa.join(",")));
        let shifts: Vec<String> = al
            .trans
            .iter()
            .map(|(k, v)| format!("{k}ORIG,{}", num(-v)))
            .collect();
        if !shifts.is_empty() {
            let dt = self.labels.fresh("D", &format!("PART{}", si + 1));
            self.o.stmt(&format!("D({dt})=TRANS/{}", shifts.join(",")));
        }
        self.o.stmt("MODE/PROG,MAN");
    }

    /// A group: its sensor, entry, `MEAS` blocks and exit, the datums it measured and
    /// the tolerances it completes.
    fn group(&mut self, g: &GroupPath) {
        let (hlip, motion) = (self.input.hlip, self.input.llip.motion);
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
        for b in &g.blocks {
            let Some(label) = self.feats.get(&face_key(b)).cloned() else {
                continue;
            };
            let meas = self.nominals.get(&label).map_or("PLANE", Nominal::meas);
            // A narrow block approaches and retracts by its own, shorter stand-off.
            let narrow = b.standoff < motion.prehit.max(motion.retract) - 1e-9;
            let o = &mut self.o;
            if narrow {
                o.stmt(&format!("SNSET/APPRCH,{}", num(b.standoff)));
                o.stmt(&format!("SNSET/RETRCT,{}", num(b.standoff)));
            }
            o.stmt(&format!("MEAS/{meas},F({label}),{}", b.touches.len()));
            for t in &b.touches {
                for v in &t.via {
                    o.goto(v);
                }
                o.goto(&t.standoff);
                ptmeas(o, hlip, t.point);
                if !narrow && motion.retract < motion.prehit {
                    o.goto(&t.standoff);
                }
            }
            o.stmt("ENDMES");
            if narrow {
                o.stmt(&format!("SNSET/APPRCH,{}", num(motion.prehit)));
                o.stmt(&format!("SNSET/RETRCT,{}", num(motion.retract)));
            }
            let list = self.measured.entry(b.feature).or_default();
            if !list.contains(&label) {
                list.push(label.clone());
            }
            in_group.push(label);
        }
        for p in &g.exit {
            self.o.goto(p);
        }
        // Datums measured here, then the tolerances this group completes.
        let mut defined = Vec::new();
        for b in &g.blocks {
            if let (Some(d), Some(label)) = (b.datum, self.feats.get(&face_key(b))) {
                if !defined.contains(&d) {
                    let dl = &self.datums[d.0];
                    self.o.stmt(&format!("DAT({dl})=DATDEF/FA({label})"));
                    defined.push(d);
                }
            }
        }
        for &r in &g.records {
            self.output(r, &in_group);
        }
    }

    /// `OUTPUT` of a tolerance over its features' labels: those measured in this group,
    /// else those measured before.
    fn output(&mut self, r: ToleranceId, in_group: &[String]) {
        let part = self.names.part();
        let t = &part.tolerances[r.0];
        let tl = &self.tols[r.0];
        let labels_of = |f: FeatureId| -> Vec<String> {
            let f = Some(f);
            let here: Vec<String> = self
                .faces_of
                .get(&f)
                .into_iter()
                .flatten()
                .filter(|l| in_group.contains(l))
                .cloned()
                .collect();
            if here.is_empty() {
                self.measured.get(&f).cloned().unwrap_or_default()
            } else {
                here
            }
        };
        let mut lines = Vec::new();
        if t.targets.len() > 1 {
            let fa: Vec<String> = t
                .targets
                .iter()
                .filter_map(|&f| labels_of(f).into_iter().next())
                .map(|l| format!("FA({l})"))
                .collect();
            if fa.len() == t.targets.len() {
                lines.push(format!("OUTPUT/{},TA({tl})", fa.join(",")));
            }
        } else {
            for &f in &t.targets {
                for l in labels_of(f) {
                    lines.push(format!("OUTPUT/FA({l}),TA({tl})"));
                }
            }
        }
        for l in lines {
            self.o.stmt(&l);
        }
    }

    /// `SNSLCT` when the group's sensor is not the current one.
    fn select(&mut self, g: &GroupPath) {
        if let Some(s) = self.sensors.get(&sensor_key(g)) {
            if self.current_sensor.as_ref() != Some(s) {
                self.o.at = None;
                self.o.stmt(&format!("SNSLCT/S({s})"));
                self.current_sensor = Some(s.clone());
            }
        }
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
    let first = b.touches.first()?;
    if b.contact == Contact::Table {
        let p = &hlip.points[first.point];
        return Some(Nominal::Table(p.position, p.normal));
    }
    let face = input.geometry.faces.get(b.face.0)?;
    Some(Nominal::Surface(face.surface.clone(), face.centroid))
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
