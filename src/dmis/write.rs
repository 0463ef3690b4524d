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
use crate::geometry::{Surface, P3, V3};
use crate::model::{Material, TolKind, TolValue};
use crate::path::{BlockPath, GroupPath};
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

/// The sensor key of a group.
fn sensor_key(g: &GroupPath) -> (String, String, String) {
    (g.probe.clone(), num(g.a), num(g.b))
}

/// Writes the program.
pub fn write(input: &Input) -> String {
    let model = input.model;
    let part = &model.parts[input.plan.part.0];
    let cmm = &model.cmms[input.plan.cmm.0];
    let hlip = input.hlip;
    let llip = input.llip;
    let motion = llip.motion;
    let probes = crate::access::ProbeShape::of_cmm(model, cmm);
    let mut labels = Labels::default();
    let mut o = Out {
        text: String::new(),
        at: None,
    };

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

    // Sensors, in order of first use.
    o.comment("sensors");
    let mut sensors: BTreeMap<(String, String, String), String> = BTreeMap::new();
    for g in llip.setups.iter().flat_map(|s| &s.groups) {
        let key = sensor_key(g);
        if sensors.contains_key(&key) {
            continue;
        }
        let Some(probe) = probes.iter().find(|p| p.name == g.probe) else {
            continue;
        };
        let name = if hlip.indexable {
            format!("{}_A{}B{}", g.probe, key.1, key.2)
                .replace('-', "M")
                .replace('.', "P")
        } else {
            g.probe.clone()
        };
        let label = labels.fresh("S", &name);
        let diam = num(2.0 * probe.tip_radius);
        let len = num(probe.reach());
        if hlip.indexable {
            let d = crate::access::head_direction(g.a, g.b);
            o.stmt(&format!(
                "S({label})=SNSDEF/PROBE,INDEX,POL,{},{},VEC,{},{len},{diam}",
                num(g.a),
                num(g.b),
                ijk(&d)
            ));
        } else {
            o.stmt(&format!(
                "S({label})=SNSDEF/PROBE,FIXED,CART,0,0,-{len},0,0,1,{diam}"
            ));
        }
        sensors.insert(key, label);
    }

    // Nominals: one feature per (feature, face, table) measured, in order of first use.
    o.comment("nominals");
    let mut feats: BTreeMap<(String, String, bool), String> = BTreeMap::new();
    let mut faces_of: BTreeMap<String, Vec<String>> = BTreeMap::new();
    let mut nominals: BTreeMap<String, Nominal> = BTreeMap::new();
    // How many faces (or table stand-ins) each feature is measured on.
    let mut face_count: BTreeMap<String, usize> = BTreeMap::new();
    {
        let mut seen = std::collections::BTreeSet::new();
        for b in llip
            .setups
            .iter()
            .flat_map(|s| &s.groups)
            .flat_map(|g| &g.blocks)
        {
            if seen.insert((&b.feature, &b.face, b.table)) {
                *face_count.entry(b.feature.clone()).or_default() += 1;
            }
        }
    }
    for g in llip.setups.iter().flat_map(|s| &s.groups) {
        for b in &g.blocks {
            let key = (b.feature.clone(), b.face.clone(), b.table);
            if feats.contains_key(&key) {
                continue;
            }
            let Some(nominal) = nominal_of(input, b) else {
                continue;
            };
            let count = face_count.get(&b.feature).copied().unwrap_or(1);
            let k = faces_of.get(&b.feature).map_or(0, Vec::len) + 1;
            let name = if b.table {
                format!("{}_T", b.feature)
            } else if count > 1 {
                format!("{}_{k}", b.feature)
            } else {
                b.feature.clone()
            };
            let label = labels.fresh("F", &name);
            o.stmt(&format!("F({label})=FEAT/{}", nominal.feat()));
            faces_of
                .entry(b.feature.clone())
                .or_default()
                .push(label.clone());
            nominals.insert(label.clone(), nominal);
            feats.insert(key, label);
        }
    }

    // Tolerances.
    o.comment("tolerances");
    let mut datums: BTreeMap<String, String> = BTreeMap::new();
    for d in &part.datums {
        let label = labels.fresh("DAT", &d.name);
        datums.insert(d.name.clone(), label);
    }
    let mut tols: BTreeMap<String, String> = BTreeMap::new();
    for t in &part.tolerances {
        let label = labels.fresh("T", &t.name);
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
            let name = &part.datums[d.datum.0].name;
            if let Some(l) = datums.get(name) {
                params.push(format!("DAT({l})"));
                params.extend(material(d.modifier).map(String::from));
            }
        }
        o.stmt(&format!("T({label})=TOL/{}", params.join(",")));
        tols.insert(t.name.clone(), label);
    }

    let setups_n = llip.setups.len();
    let mut measured: BTreeMap<String, Vec<String>> = BTreeMap::new();
    let mut current_sensor: Option<String> = None;
    for (si, sp) in llip.setups.iter().enumerate() {
        let setup = &hlip.setups[sp.setup];
        let up = V3::from(setup.up);
        o.comment(&format!("setup {} of {setups_n}", si + 1));
        o.oper(&format!(
            "SETUP {} OF {setups_n}: PLACE THE PART WITH ITS {} DIRECTION UP",
            si + 1,
            direction_words(&up)
        ));
        for f in &setup.on_table {
            o.oper(&format!("REST FACE {f} ON THE TABLE"));
        }
        let al = &sp.alignment;
        if !al.missing.is_empty() {
            o.oper(&format!(
                "THE ALIGNMENT LEAVES {} FREE: PLACE THE PART AT ITS NOMINAL POSITION, SQUARE TO THE MACHINE AXES",
                al.missing.join(", ")
            ));
        }
        o.stmt("PAUSE");
        if !al.steps.is_empty() {
            o.stmt("MODE/MAN");
            o.oper("TOUCH THE POINTS SHOWN BY HAND, THEN LEAVE THE PROBE ABOVE THE PART");
            let mut fa = Vec::new();
            for step in &al.steps {
                let g = &sp.groups[step.group];
                let b = &g.blocks[step.block];
                let Some(label) = feats.get(&(b.feature.clone(), b.face.clone(), b.table)) else {
                    continue;
                };
                select(&mut o, &sensors, g, &mut current_sensor);
                let meas = nominals.get(label).map_or("PLANE", Nominal::meas);
                o.stmt(&format!("MEAS/{meas},F({label}),{}", step.points.len()));
                for &k in &step.points {
                    ptmeas(&mut o, hlip, k);
                }
                o.stmt("ENDMES");
                fa.push(format!("FA({label}),{}", step.keywords.join(",")));
            }
            let d = labels.fresh("D", &format!("SETUP{}", si + 1));
            o.stmt(&format!("D({d})=DATSET/{}", fa.join(",")));
            let shifts: Vec<String> = al
                .trans
                .iter()
                .map(|(k, v)| format!("{k}ORIG,{}", num(-v)))
                .collect();
            if !shifts.is_empty() {
                let dt = labels.fresh("D", &format!("PART{}", si + 1));
                o.stmt(&format!("D({dt})=TRANS/{}", shifts.join(",")));
            }
            o.stmt("MODE/PROG,MAN");
        }
        for g in &sp.groups {
            o.comment(&format!(
                "probe {}{}: {} features",
                g.probe,
                if hlip.indexable {
                    format!(" at a{} b{}", num(g.a), num(g.b))
                } else {
                    String::new()
                },
                g.blocks.len()
            ));
            // The previous group ended on the clearance plane: change the sensor there.
            select(&mut o, &sensors, g, &mut current_sensor);
            for p in &g.entry {
                o.goto(p);
            }
            let mut in_group: Vec<String> = Vec::new();
            for b in &g.blocks {
                let Some(label) = feats.get(&(b.feature.clone(), b.face.clone(), b.table)) else {
                    continue;
                };
                let meas = nominals.get(label).map_or("PLANE", Nominal::meas);
                // A narrow block approaches and retracts by its own, shorter stand-off.
                let narrow = b.standoff < motion.prehit.max(motion.retract) - 1e-9;
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
                    ptmeas(&mut o, hlip, t.point);
                    if !narrow && motion.retract < motion.prehit {
                        o.goto(&t.standoff);
                    }
                }
                o.stmt("ENDMES");
                if narrow {
                    o.stmt(&format!("SNSET/APPRCH,{}", num(motion.prehit)));
                    o.stmt(&format!("SNSET/RETRCT,{}", num(motion.retract)));
                }
                let list = measured.entry(b.feature.clone()).or_default();
                if !list.contains(label) {
                    list.push(label.clone());
                }
                in_group.push(label.clone());
            }
            for p in &g.exit {
                o.goto(p);
            }
            // Datums measured here, then the tolerances this group completes.
            let mut defined = Vec::new();
            for b in &g.blocks {
                if let (Some(d), Some(label)) = (
                    &b.datum,
                    feats.get(&(b.feature.clone(), b.face.clone(), b.table)),
                ) {
                    if !defined.contains(d) {
                        if let Some(dl) = datums.get(d) {
                            o.stmt(&format!("DAT({dl})=DATDEF/FA({label})"));
                        }
                        defined.push(d.clone());
                    }
                }
            }
            for r in &g.records {
                let Some(t) = part.tolerances.iter().find(|t| &t.name == r) else {
                    continue;
                };
                let Some(tl) = tols.get(r) else { continue };
                let labels_of = |f: &str| -> Vec<String> {
                    let here: Vec<String> = faces_of
                        .get(f)
                        .into_iter()
                        .flatten()
                        .filter(|l| in_group.contains(l))
                        .cloned()
                        .collect();
                    if here.is_empty() {
                        measured.get(f).cloned().unwrap_or_default()
                    } else {
                        here
                    }
                };
                let targets: Vec<&str> = t
                    .targets
                    .iter()
                    .map(|f| part.features[f.0].name.as_str())
                    .collect();
                if targets.len() > 1 {
                    let fa: Vec<String> = targets
                        .iter()
                        .filter_map(|f| labels_of(f).into_iter().next())
                        .map(|l| format!("FA({l})"))
                        .collect();
                    if fa.len() == targets.len() {
                        o.stmt(&format!("OUTPUT/{},TA({tl})", fa.join(",")));
                    }
                } else {
                    for f in &targets {
                        for l in labels_of(f) {
                            o.stmt(&format!("OUTPUT/FA({l}),TA({tl})"));
                        }
                    }
                }
            }
        }
    }
    o.stmt("ENDFIL");
    o.text
}

/// `SNSLCT` when the group's sensor is not the current one.
fn select(
    o: &mut Out,
    sensors: &BTreeMap<(String, String, String), String>,
    g: &GroupPath,
    current: &mut Option<String>,
) {
    if let Some(s) = sensors.get(&sensor_key(g)) {
        if current.as_ref() != Some(s) {
            o.at = None;
            o.stmt(&format!("SNSLCT/S({s})"));
            *current = Some(s.clone());
        }
    }
}

fn ptmeas(o: &mut Out, hlip: &crate::plan::Hlip, k: usize) {
    let p = &hlip.points[k];
    o.at = None;
    o.stmt(&format!(
        "PTMEAS/CART,{},{},{},{},{},{}",
        num(p.position[0]),
        num(p.position[1]),
        num(p.position[2]),
        num(p.normal[0]),
        num(p.normal[1]),
        num(p.normal[2])
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
    if b.table {
        let p = &hlip.points[first.point];
        return Some(Nominal::Table(P3::from(p.position), V3::from(p.normal)));
    }
    let face = input.geometry.faces.iter().find(|f| f.name == b.face)?;
    Some(Nominal::Surface(face.surface.clone(), face.centroid))
}
