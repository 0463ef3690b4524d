//! A stable, readable text dump of the model, for golden tests and `inspc check --emit model`.

use super::*;
use std::fmt::Write;

/// Formats a number the one way inspc prints numbers in reports: at most six decimals,
/// trailing zeros trimmed, never `-0`.
pub fn fmt_num(v: f64) -> String {
    let s = format!("{v:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}

fn v3(v: &Vec3) -> String {
    format!("({}, {}, {})", fmt_num(v[0]), fmt_num(v[1]), fmt_num(v[2]))
}

/// A top-level item of the model by kind and index: what [`Model::describe`] describes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ItemRef {
    /// `heads[i]`
    Head(usize),
    /// `styli[i]`
    Stylus(usize),
    /// `bodies[i]`
    Body(usize),
    /// `extensions[i]`
    Extension(usize),
    /// `probes[i]`
    Probe(usize),
    /// `cmms[i]`, with its fixtures
    Cmm(usize),
    /// `fixtures[i]`
    Fixture(usize),
    /// `scanners[i]`
    Scanner(usize),
    /// `hierarchies[i]`
    Hierarchy(usize),
    /// `samplings[i]`
    Sampling(usize),
    /// `parts[i]`, with its operations, features, datums and tolerances
    Part(usize),
    /// `plans[i]`, with its preferences
    Plan(usize),
}

impl Model {
    /// The model as indented text, in declaration order: every part, CMM and plan, and
    /// the catalogue items they use or that a file for which `shown` holds declares.
    pub fn summary(&self, shown: &dyn Fn(crate::source::FileId) -> bool) -> String {
        let used = self.used(shown);
        let keep = |span: &crate::source::Span, kind: u8, index: usize| {
            shown(span.file) || used.contains(&(kind, index))
        };
        let mut items: Vec<ItemRef> = Vec::new();
        let mut add =
            |n: usize, kind: u8, span: &dyn Fn(usize) -> Span, item: fn(usize) -> ItemRef| {
                items.extend((0..n).filter(|&i| keep(&span(i), kind, i)).map(item));
            };
        add(self.heads.len(), 0, &|i| self.heads[i].span, ItemRef::Head);
        add(
            self.styli.len(),
            1,
            &|i| self.styli[i].span,
            ItemRef::Stylus,
        );
        add(
            self.bodies.len(),
            2,
            &|i| self.bodies[i].span,
            ItemRef::Body,
        );
        add(
            self.extensions.len(),
            3,
            &|i| self.extensions[i].span,
            ItemRef::Extension,
        );
        add(
            self.probes.len(),
            4,
            &|i| self.probes[i].span,
            ItemRef::Probe,
        );
        add(
            self.scanners.len(),
            8,
            &|i| self.scanners[i].span,
            ItemRef::Scanner,
        );
        // CMMs and parts only when shown (kind 7 is never used).
        add(self.cmms.len(), 7, &|i| self.cmms[i].span, ItemRef::Cmm);
        add(
            self.hierarchies.len(),
            5,
            &|i| self.hierarchies[i].span,
            ItemRef::Hierarchy,
        );
        add(
            self.samplings.len(),
            6,
            &|i| self.samplings[i].span,
            ItemRef::Sampling,
        );
        add(self.parts.len(), 7, &|i| self.parts[i].span, ItemRef::Part);
        items.extend((0..self.plans.len()).map(ItemRef::Plan));
        items.iter().map(|&item| self.describe(item)).collect()
    }

    /// One item as the summary prints it: a line `kind name: …`, then its members
    /// indented (a CMM's fixtures, a part's operations and features, a plan's preferences).
    pub fn describe(&self, item: ItemRef) -> String {
        let mut o = String::new();
        match item {
            ItemRef::Head(i) => head_summary(&mut o, &self.heads[i]),
            ItemRef::Stylus(i) => {
                let s = &self.styli[i];
                let _ = writeln!(
                    o,
                    "stylus {}: tip Ø{}, length {}, stem Ø{}",
                    s.name,
                    fmt_num(s.tip),
                    fmt_num(s.length),
                    fmt_num(s.stem)
                );
            }
            ItemRef::Body(i) => {
                let b = &self.bodies[i];
                let _ = writeln!(
                    o,
                    "body {}: Ø{} × {}",
                    b.name,
                    fmt_num(b.diameter),
                    fmt_num(b.length)
                );
            }
            ItemRef::Extension(i) => {
                let e = &self.extensions[i];
                let _ = writeln!(
                    o,
                    "extension {}: Ø{} × {}",
                    e.name,
                    fmt_num(e.diameter),
                    fmt_num(e.length)
                );
            }
            ItemRef::Probe(i) => self.probe_summary(&mut o, &self.probes[i]),
            ItemRef::Cmm(i) => self.cmm_summary(&mut o, &self.cmms[i]),
            ItemRef::Scanner(i) => scanner_summary(&mut o, &self.scanners[i]),
            ItemRef::Fixture(i) => fixture_summary(&mut o, &self.fixtures[i]),
            ItemRef::Hierarchy(i) => {
                let h = &self.hierarchies[i];
                let levels: Vec<String> = h.levels.iter().map(|l| l.text()).collect();
                let _ = writeln!(
                    o,
                    "hierarchy {}: required approachability > {}",
                    h.name,
                    levels.join(" > ")
                );
            }
            ItemRef::Sampling(i) => {
                let s = &self.samplings[i];
                let per: Vec<String> = s
                    .per_surface
                    .iter()
                    .map(|(k, st)| format!("{} {}", k.keyword(), strategy_text(st)))
                    .collect();
                let _ = writeln!(o, "sampling {}: {}", s.name, per.join(", "));
            }
            ItemRef::Part(i) => part_summary(&mut o, &self.parts[i]),
            ItemRef::Plan(i) => self.plan_summary(&mut o, &self.plans[i]),
        }
        o
    }

    /// `probe NAME: body …, extensions […], stylus …, cost …`
    fn probe_summary(&self, o: &mut String, p: &Probe) {
        let ext: Vec<&str> = p
            .extensions
            .iter()
            .map(|e| self.extensions[e.0].name.as_str())
            .collect();
        let _ = writeln!(
            o,
            "probe {}: body {}, extensions [{}], stylus {}, cost {}",
            p.name,
            self.bodies[p.body.0].name,
            ext.join(", "),
            self.styli[p.stylus.0].name,
            fmt_num(p.cost)
        );
    }

    /// A CMM's line, then each of its fixtures indented.
    fn cmm_summary(&self, o: &mut String, c: &Cmm) {
        let probes: Vec<String> = c
            .probes
            .iter()
            .map(|(l, p)| format!("{l}: {}", self.probes[p.0].name))
            .collect();
        let size = c.table_size.map_or(String::new(), |s| {
            format!(" size {} × {}", fmt_num(s[0]), fmt_num(s[1]))
        });
        let fixtures: Vec<String> = c
            .fixtures
            .iter()
            .map(|(l, f)| format!("{l}: {}", self.fixtures[f.0].name))
            .collect();
        let fixtures = if fixtures.is_empty() {
            String::new()
        } else {
            format!(", fixtures [{}]", fixtures.join(", "))
        };
        let scanners: Vec<String> = c
            .scanners
            .iter()
            .map(|(l, s)| format!("{l}: {}", self.scanners[s.0].name))
            .collect();
        let fixtures = if scanners.is_empty() {
            fixtures
        } else {
            format!("{fixtures}, scanners [{}]", scanners.join(", "))
        };
        let _ = writeln!(
            o,
            "cmm {}: table z {}{size}, ram r {} l {}, head {}, probes [{}]{fixtures}",
            c.name,
            fmt_num(c.table_z),
            fmt_num(c.ram_radius),
            fmt_num(c.ram_length),
            self.heads[c.head.0].name,
            probes.join(", ")
        );
        for (_, f) in &c.fixtures {
            o.push_str("  ");
            o.push_str(&self.describe(ItemRef::Fixture(f.0)));
        }
    }

    fn plan_summary(&self, o: &mut String, p: &Plan) {
        let _ = writeln!(
            o,
            "plan {}: part {}, cmm {}, hierarchy {}, sampling {}",
            p.name,
            self.parts[p.part.0].name,
            self.cmms[p.cmm.0].name,
            self.hierarchies[p.hierarchy.0].name,
            self.samplings[p.sampling.0].name
        );
        let verb = |s: &super::Stance<f64>| match s {
            super::Stance::Forbid => "forbid".to_string(),
            super::Stance::Prefer(w) => format!("prefer (weight {})", fmt_num(*w)),
        };
        if !p.fixtures.is_empty() {
            let cmm = &self.cmms[p.cmm.0];
            let labels: Vec<&str> = p
                .fixtures
                .iter()
                .filter_map(|&k| cmm.fixtures.get(k).map(|(l, _)| l.as_str()))
                .collect();
            let _ = writeln!(o, "  fixtures [{}]", labels.join(", "));
        }
        for s in &p.setups {
            let verb = verb(&s.stance);
            let _ = writeln!(o, "  {verb} setup {}", v3(&s.direction));
        }
        for s in &p.orientations {
            let verb = verb(&s.stance);
            let _ = writeln!(
                o,
                "  {verb} orientation A {} B {}",
                fmt_num(s.a),
                fmt_num(s.b)
            );
        }
        for s in &p.probes {
            let what = match s.stance {
                super::Stance::Forbid => "forbid".to_string(),
                super::Stance::Prefer(cost) => {
                    format!("cost {}", cost.map_or("-".into(), fmt_num))
                }
            };
            let _ = writeln!(o, "  probe {}: {what}", s.label);
        }
        for (f, st) in &p.overrides {
            let _ = writeln!(
                o,
                "  sample {} with {}",
                self.parts[p.part.0].features[f.0].name,
                strategy_text(st)
            );
        }
    }
}

impl Model {
    /// Catalogue items used by the shown CMMs and plans, as (kind, index) pairs.
    fn used(
        &self,
        shown: &dyn Fn(crate::source::FileId) -> bool,
    ) -> std::collections::BTreeSet<(u8, usize)> {
        let mut used = std::collections::BTreeSet::new();
        let mut cmms: Vec<usize> = self
            .cmms
            .iter()
            .enumerate()
            .filter(|(_, c)| shown(c.span.file))
            .map(|(i, _)| i)
            .collect();
        for p in &self.plans {
            cmms.push(p.cmm.0);
            used.insert((5, p.hierarchy.0));
            used.insert((6, p.sampling.0));
        }
        let mut probes: Vec<usize> = self
            .probes
            .iter()
            .enumerate()
            .filter(|(_, p)| shown(p.span.file))
            .map(|(i, _)| i)
            .collect();
        for c in cmms {
            used.insert((0, self.cmms[c].head.0));
            used.extend(self.cmms[c].scanners.iter().map(|(_, s)| (8, s.0)));
            probes.extend(self.cmms[c].probes.iter().map(|(_, p)| p.0));
        }
        for p in probes {
            let probe = &self.probes[p];
            used.insert((4, p));
            used.insert((2, probe.body.0));
            used.insert((1, probe.stylus.0));
            used.extend(probe.extensions.iter().map(|e| (3, e.0)));
        }
        used
    }
}

/// `head NAME: fixed|indexable …, envelope Ø… × …`
fn head_summary(o: &mut String, h: &Head) {
    let kind = match &h.kind {
        HeadKind::Fixed => "fixed".to_string(),
        HeadKind::Indexable { a, b, step } => format!(
            "indexable A {}..{} B {}..{} step {} ({} orientations)",
            fmt_num(a[0]),
            fmt_num(a[1]),
            fmt_num(b[0]),
            fmt_num(b[1]),
            fmt_num(*step),
            h.orientations().len()
        ),
    };
    let _ = writeln!(
        o,
        "head {}: {kind}, envelope Ø{} × {}",
        h.name,
        fmt_num(h.diameter),
        fmt_num(h.length)
    );
}

/// `scanner NAME: stripe … at stand-off …`, its optics, accuracy, housing and cost.
fn scanner_summary(o: &mut String, s: &Scanner) {
    let _ = writeln!(
        o,
        "scanner {}: stripe {} at stand-off {} ± {}, triangulation {}°, incidence ≤ {}°, \
         spacing {} × {}, accuracy {}, body Ø{} × {}, cost {}",
        s.name,
        fmt_num(s.stripe_width),
        fmt_num(s.standoff),
        fmt_num(s.depth_of_field / 2.0),
        fmt_num(s.triangulation),
        fmt_num(s.max_incidence),
        fmt_num(s.spacing[0]),
        fmt_num(s.spacing[1]),
        fmt_num(s.accuracy),
        fmt_num(s.body[0]),
        fmt_num(s.body[1]),
        fmt_num(s.cost)
    );
}

/// `fixture NAME: kind sizes, height …` (a mesh nest: its file, units and up).
fn fixture_summary(o: &mut String, f: &Fixture) {
    let r =
        |x: &[f64; 2], unit: &str| format!("{} {unit} .. {} {unit}", fmt_num(x[0]), fmt_num(x[1]));
    let what = match &f.kind {
        FixtureKind::Vise { opening, jaw } => format!(
            "opening {} mm, jaw {} × {} mm",
            fmt_num(*opening),
            fmt_num(jaw[0]),
            fmt_num(jaw[1])
        ),
        FixtureKind::Chuck {
            diameter,
            jaws,
            body,
        } => format!(
            "diameter {}, jaws {} mm, body {} mm",
            r(diameter, "mm"),
            fmt_num(*jaws),
            fmt_num(*body)
        ),
        FixtureKind::VBlock { diameter } => format!("diameter {}", r(diameter, "mm")),
        FixtureKind::Risers { pads } => format!("pads Ø{} mm", fmt_num(*pads)),
        FixtureKind::SinePlate { tilt, plate } => format!(
            "tilt {}{}",
            r(tilt, "deg"),
            plate.map_or(String::new(), |p| format!(
                ", plate {} × {} mm",
                fmt_num(p[0]),
                fmt_num(p[1])
            ))
        ),
        FixtureKind::Mesh {
            path, unit_mm, up, ..
        } => format!(
            "file {}, units ×{}, up {}",
            path.file_name()
                .map_or(String::new(), |n| n.to_string_lossy().into_owned()),
            fmt_num(*unit_mm),
            v3(up)
        ),
    };
    let height = match f.kind {
        FixtureKind::Mesh { .. } => String::new(),
        _ => format!(", height {} mm", fmt_num(f.height)),
    };
    let _ = writeln!(o, "fixture {}: {} {what}{height}", f.name, f.kind.word());
}

fn strategy_text(s: &Strategy) -> String {
    let m = match s.method {
        SampleMethod::FanLeu => "fan_leu",
        SampleMethod::Spread => "spread",
        SampleMethod::Uniform => "uniform",
        SampleMethod::Hammersley => "hammersley",
    };
    let mut args = Vec::new();
    if let Some(n) = s.points {
        args.push(format!("points {n}"));
    }
    match s.inset {
        Some(Inset::Length(l)) => args.push(format!("inset {} mm", fmt_num(l))),
        Some(Inset::Fraction(f)) => args.push(format!("inset {} %", fmt_num(f * 100.0))),
        None => {}
    }
    if args.is_empty() {
        m.to_string()
    } else {
        format!("{m}({})", args.join(", "))
    }
}

fn part_summary(o: &mut String, p: &Part) {
    let geometry = geometry_text(&p.geometry);
    let _ = writeln!(o, "part {}: {geometry}", p.name);
    for op in &p.ops {
        let verb = op.action.keyword();
        let shape = op_shape_text(&op.kind);
        let pattern = pattern_text(op.pattern.as_ref());
        let _ = writeln!(o, "  {verb} {}: {shape}{pattern}", op.name);
    }
    for f in &p.features {
        let _ = writeln!(o, "  {}", f.text(p));
    }
    for d in &p.datums {
        let _ = writeln!(o, "  datum {} on {}", d.name, p.features[d.feature.0].name);
    }
    for f in &p.frames {
        let _ = writeln!(o, "  frame {} = [{}]", f.name, datum_refs(p, &f.refs));
    }
    for t in &p.tolerances {
        let _ = writeln!(o, "  {}", t.text(p));
    }
}

/// A part's geometry source: a stock shape, a CAD file or a mesh.
fn geometry_text(geometry: &Geometry) -> String {
    match geometry {
        Geometry::Stock(Stock::Box { size }) => format!("box {}", v3(size)),
        Geometry::Stock(Stock::Cylinder { diameter, height }) => {
            format!("cylinder Ø{} × {}", fmt_num(*diameter), fmt_num(*height))
        }
        Geometry::Stock(Stock::Sphere { diameter }) => format!("sphere Ø{}", fmt_num(*diameter)),
        Geometry::Mesh {
            path,
            unit_mm,
            chord_mm,
            scale,
            ..
        } => {
            let name = path
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            let text = match CadKind::of_path(path) {
                Some(_) => format!(
                    "CAD {name} (in the file's unit, chord {} mm)",
                    fmt_num(chord_mm.unwrap_or(super::DEFAULT_CHORD_MM))
                ),
                None => format!("mesh {name} (× {} mm)", fmt_num(*unit_mm)),
            };
            match *scale == 1.0 {
                true => text,
                false => format!("{text} scaled × {}", fmt_num(*scale)),
            }
        }
    }
}

/// An operation's kind and sizes: `hole at … axis … Ø… depth …`, `slot at …`, ….
fn op_shape_text(kind: &OpKind) -> String {
    match kind {
        OpKind::Hole {
            at,
            axis,
            diameter,
            depth,
        } => {
            let at = match at {
                Placement::At(p) => format!("at {}", v3(p)),
                Placement::Radial(d) => format!("radial {}", v3(d)),
            };
            let depth = match depth {
                Depth::Through => "through".to_string(),
                Depth::Blind(d) => format!("depth {}", fmt_num(*d)),
            };
            format!(
                "hole {at} axis {} Ø{} {depth}",
                v3(axis),
                fmt_num(*diameter)
            )
        }
        OpKind::Slot {
            at,
            along,
            into,
            width,
            depth,
            length,
        } => format!(
            "slot at {} along {} into {} width {} depth {}{}",
            v3(at),
            v3(along),
            v3(into),
            fmt_num(*width),
            fmt_num(*depth),
            length.map_or(String::new(), |l| format!(" length {}", fmt_num(l)))
        ),
        OpKind::Pocket {
            at,
            along,
            into,
            size,
            depth,
            corner_radius,
        } => format!(
            "pocket at {} along {} into {} size {} × {} depth {} corner r {}",
            v3(at),
            v3(along),
            v3(into),
            fmt_num(size[0]),
            fmt_num(size[1]),
            fmt_num(*depth),
            fmt_num(*corner_radius)
        ),
        OpKind::Step {
            at,
            along,
            into,
            width,
            depth,
        } => format!(
            "step at {} along {} into {} width {} depth {}",
            v3(at),
            v3(along),
            v3(into),
            fmt_num(*width),
            fmt_num(*depth)
        ),
        OpKind::Boss {
            at,
            axis,
            diameter,
            height,
        } => format!(
            "boss at {} axis {} Ø{} height {}",
            v3(at),
            v3(axis),
            fmt_num(*diameter),
            fmt_num(*height)
        ),
    }
}

/// An operation's pattern after its shape (` × grid 3×2 pitch …`); empty without one.
fn pattern_text(pattern: Option<&Pattern>) -> String {
    match pattern {
        None => String::new(),
        Some(Pattern::Grid { nx, ny, pitch }) => format!(
            " × grid {nx}×{ny} pitch {} × {}",
            fmt_num(pitch[0]),
            fmt_num(pitch[1])
        ),
        Some(Pattern::Linear { count, step }) => format!(" × linear {count} step {}", v3(step)),
        Some(Pattern::Polar {
            count,
            axis,
            center,
        }) => format!(" × polar {count} about {} through {}", v3(axis), v3(center)),
    }
}

impl Feature {
    /// The feature as the summary prints it: `feature name = faces`.
    pub fn text(&self, p: &Part) -> String {
        let faces: Vec<String> = self.faces.iter().map(|r| face_text(p, r)).collect();
        let what = match self.declared {
            super::Declared::Face => "face",
            super::Declared::Feature => "feature",
        };
        format!("{what} {} = {}", self.name, faces.join(" + "))
    }
}

impl FaceRef {
    /// The reference as the spec writes it: `stock.top`, `group "face_90"`.
    pub fn text(&self, p: &Part) -> String {
        face_text(p, self)
    }
}

impl Tolerance {
    /// The tolerance as the summary prints it: `tolerance name: kind(features) value | datums`.
    pub fn text(&self, p: &Part) -> String {
        let targets: Vec<&str> = self
            .targets
            .iter()
            .map(|f| p.features[f.0].name.as_str())
            .collect();
        let value = self.value.text();
        let m = match self.modifier {
            Some(Material::Mmc) => " MMC",
            Some(Material::Lmc) => " LMC",
            Some(Material::Rfs) => " RFS",
            None => "",
        };
        let datums = if self.datums.is_empty() {
            String::new()
        } else {
            format!(" | {}", datum_refs(p, &self.datums))
        };
        let basic = self
            .basic_angle
            .map_or(String::new(), |a| format!(" basic {}°", fmt_num(a)));
        let kind = self.kind.keyword();
        format!(
            "tolerance {}: {kind}({}) {value}{m}{datums}{basic}",
            self.name,
            targets.join(", ")
        )
    }
}

fn datum_refs(p: &Part, refs: &[DatumRef]) -> String {
    refs.iter()
        .map(|r| {
            let n = &p.datums[r.datum.0].name;
            match r.modifier {
                Some(Material::Mmc) => format!("{n}(MMC)"),
                Some(Material::Lmc) => format!("{n}(LMC)"),
                Some(Material::Rfs) => format!("{n}(RFS)"),
                None => n.clone(),
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}

fn face_text(p: &Part, r: &FaceRef) -> String {
    match r {
        FaceRef::Role {
            source: FaceSource::Stock,
            role,
            ..
        } => format!("stock.{role}"),
        FaceRef::Role {
            source: FaceSource::Op(op, None),
            role,
            ..
        } => format!("{}.{role}", p.ops[op.0].name),
        FaceRef::Role {
            source: FaceSource::Op(op, Some(i)),
            role,
            ..
        } => format!("{}[{i}].{role}", p.ops[op.0].name),
        FaceRef::Group(g, _) => format!("group {g:?}"),
        FaceRef::Segment(n, _) => format!("segment {n}"),
        FaceRef::FileFace(k, n, _) => format!("{} {n}", k.keyword()),
        FaceRef::Select(s, _) => format!("select{s:?}"),
    }
}
