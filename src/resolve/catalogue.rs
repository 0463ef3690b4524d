//! Catalogue items: heads, styli, bodies, extensions, probes, CMMs and samplings.

use super::errors::ResolveError as E;
use super::fixture::fixture;
use super::props::{describe, describe_only, num, Cx, Dim, Props};
use super::{Kind, Resolver};
use crate::diag::suggest;
use crate::load::ModuleId;
use crate::model::*;
use crate::syntax::ast::{self, ValueKind};

/// The most points a sampling strategy may ask for on one face: each is a touch, and the
/// tour over a group's touches is quadratic in their number.
const MAX_POINTS_PER_FACE: u32 = 1_000;

/// Lowers one property item and pushes it onto the model (always exactly one entry, so
/// indices stay aligned with declarations even after errors).
pub(super) fn lower(
    r: &Resolver,
    cx: &mut Cx,
    module: ModuleId,
    kind: Kind,
    b: &ast::BlockItem,
    model: &mut Model,
) {
    let name = b.name.name.clone();
    let span = b.name.span;
    let item = format!("{} `{name}`", kind.noun());
    let mut p = Props::new(cx, item, span, &b.props);
    match kind {
        Kind::Head => {
            let head = head(cx, &mut p, name, span);
            model.heads.push(head);
        }
        Kind::Stylus => {
            let stylus = stylus(cx, &mut p, name, span);
            model.styli.push(stylus);
        }
        Kind::Body => {
            let (diameter, length) = envelope(cx, &mut p);
            model.bodies.push(Body {
                name,
                diameter,
                length,
                span,
            });
        }
        Kind::Extension => {
            let (diameter, length) = envelope(cx, &mut p);
            model.extensions.push(Extension {
                name,
                diameter,
                length,
                span,
            });
        }
        Kind::Probe => {
            let probe = probe(r, cx, module, &mut p, name, span);
            model.probes.push(probe);
        }
        Kind::Fixture => {
            let f = fixture(r, cx, &mut p, name, span);
            model.fixtures.push(f);
        }
        Kind::Scanner => {
            let s = scanner(cx, &mut p, name, span);
            model.scanners.push(s);
        }
        Kind::Cmm => {
            let cmm = cmm(r, cx, module, &mut p, name, span);
            model.cmms.push(cmm);
        }
        Kind::Sampling => {
            let sampling = sampling(cx, &mut p, name, span);
            model.samplings.push(sampling);
        }
        Kind::Part | Kind::Hierarchy | Kind::Plan => unreachable!("not a property item"),
    }
    p.finish(cx);
}

/// A stylus: its `tip`, `length` and `stem`, the stem thinner than the tip.
fn stylus(cx: &mut Cx, p: &mut Props, name: String, span: crate::source::Span) -> Stylus {
    let tip_ok = p
        .req(cx, "tip", "2 mm")
        .and_then(|v| cx.positive(v, Dim::Length, "tip"));
    let tip = tip_ok.unwrap_or(1.0);
    let length = p
        .req(cx, "length", "20 mm")
        .and_then(|v| cx.positive(v, Dim::Length, "length"))
        .unwrap_or(1.0);
    let stem_v = p.req(cx, "stem", "1.5 mm");
    let stem_ok = stem_v.and_then(|v| cx.positive(v, Dim::Length, "stem"));
    let stem = stem_ok.unwrap_or(0.5);
    // Only two good values are compared: a bad one was reported already.
    if let (Some(v), Some(_), Some(_)) = (stem_v, stem_ok, tip_ok) {
        if stem >= tip {
            cx.err(E::StemThickerThanTip {
                span: v.span,
                name: name.clone(),
                stem: num(stem),
                tip: num(tip),
            });
        }
    }
    describe_only(cx, p);
    Stylus {
        name,
        tip,
        length,
        stem,
        span,
    }
}

/// A probe body's or an extension's envelope: (diameter, length).
fn envelope(cx: &mut Cx, p: &mut Props) -> (f64, f64) {
    let diameter = p
        .req(cx, "diameter", "13.2 mm")
        .and_then(|v| cx.positive(v, Dim::Length, "diameter"))
        .unwrap_or(1.0);
    let length = p
        .req(cx, "length", "30 mm")
        .and_then(|v| cx.positive(v, Dim::Length, "length"))
        .unwrap_or(1.0);
    describe_only(cx, p);
    (diameter, length)
}

/// A probe: its `body`, `extensions` and `stylus` by name, and its `cost`.
fn probe(
    r: &Resolver,
    cx: &mut Cx,
    module: ModuleId,
    p: &mut Props,
    name: String,
    span: crate::source::Span,
) -> Probe {
    let body = p
        .req(cx, "body", "TP20_SF")
        .and_then(|v| r.lookup_value(cx, module, v, Kind::Body))
        .unwrap_or(0);
    let stylus = p
        .req(cx, "stylus", "M2_D2_L20")
        .and_then(|v| r.lookup_value(cx, module, v, Kind::Stylus))
        .unwrap_or(0);
    let mut extensions = Vec::new();
    if let Some(v) = p.get("extensions") {
        match &v.kind {
            ValueKind::List(entries) => {
                for e in entries {
                    if let Some(i) = r.lookup_value(cx, module, &e.value, Kind::Extension) {
                        extensions.push(ExtensionId(i));
                    }
                }
            }
            _ => cx.mismatch(v, "a list of extensions", "write `extensions [PEM20]`"),
        }
    }
    let cost = p
        .get("cost")
        .and_then(|v| cx.non_negative(v, "cost"))
        .unwrap_or(1.0);
    describe_only(cx, p);
    Probe {
        name,
        body: BodyId(body),
        extensions,
        stylus: StylusId(stylus),
        cost,
        span,
    }
}

/// A sampling: a strategy per surface type it names.
fn sampling(cx: &mut Cx, p: &mut Props, name: String, span: crate::source::Span) -> Sampling {
    let mut per_surface = Vec::new();
    for s in SurfaceKind::ALL {
        if let Some(v) = p.get(s.keyword()) {
            if let Some(st) = strategy(cx, v, Some(s)) {
                per_surface.push((s, st));
            }
        }
    }
    Sampling {
        name,
        per_surface,
        span,
    }
}

fn head(cx: &mut Cx, p: &mut Props, name: String, span: crate::source::Span) -> Head {
    let length = p
        .req(cx, "length", "50 mm")
        .and_then(|v| cx.positive(v, Dim::Length, "length"))
        .unwrap_or(1.0);
    let diameter = p
        .req(cx, "diameter", "25 mm")
        .and_then(|v| cx.positive(v, Dim::Length, "diameter"))
        .unwrap_or(1.0);
    describe_only(cx, p);
    let kind_v = p.req(cx, "kind", "fixed");
    let kind_name = kind_v
        .and_then(|v| cx.name(v))
        .map(|i| (i.name.as_str(), i.span));
    let kind = match kind_name {
        Some(("indexable", _)) => {
            let a = p
                .req(cx, "a", "0 deg .. 105 deg")
                .and_then(|v| angle_range(cx, v, "a", [0.0, 180.0]));
            let b = p
                .req(cx, "b", "-180 deg .. 180 deg")
                .and_then(|v| angle_range(cx, v, "b", [-360.0, 360.0]));
            let step_v = p.req(cx, "step", "7.5 deg");
            let step = step_v.and_then(|v| cx.positive(v, Dim::Angle, "step"));
            if let (Some(step), Some(v)) = (step, step_v) {
                for (axis, range) in [("A", a), ("B", b)] {
                    let Some(range) = range else { continue };
                    let n = (range[1] - range[0]) / step;
                    if (n - n.round()).abs() > 1e-9 {
                        let rtxt = format!("{}°..{}°", num(range[0]), num(range[1]));
                        cx.err(E::StepNotDividing {
                            span: v.span,
                            step: format!("{}°", num(step)),
                            axis: axis.into(),
                            help: format!("{rtxt} spans {}°, which is {} steps of {}°; choose a step that divides it", num(range[1] - range[0]), num(n), num(step)),
                            range: rtxt,
                        });
                    }
                }
            }
            match (a, b, step) {
                (Some(a), Some(b), Some(step)) => HeadKind::Indexable { a, b, step },
                _ => HeadKind::Indexable {
                    a: [0.0, 0.0],
                    b: [0.0, 0.0],
                    step: 1.0,
                },
            }
        }
        Some(("fixed", _)) | None => HeadKind::Fixed,
        Some((other, s)) => {
            let help = suggest::help_for_unknown("head kind", other, ["fixed", "indexable"]);
            cx.err(E::UnknownName {
                span: s,
                what: "head kind".into(),
                name: other.into(),
                help,
            });
            HeadKind::Fixed
        }
    };
    Head {
        name,
        kind,
        length,
        diameter,
        span,
    }
}

fn angle_range(cx: &mut Cx, v: &ast::Value, axis: &str, limits: [f64; 2]) -> Option<[f64; 2]> {
    let ValueKind::Range(lo, hi) = &v.kind else {
        cx.mismatch(
            v,
            "an angle range",
            &format!("write `{axis} 0 deg .. 105 deg`"),
        );
        return None;
    };
    let lo = cx.quantity(lo, Dim::Angle);
    let hi = cx.quantity(hi, Dim::Angle);
    let (lo, hi) = (lo?, hi?);
    if lo >= hi || lo < limits[0] || hi > limits[1] {
        cx.err(E::OutOfRange {
            span: v.span,
            what: format!("`{axis}` range"),
            value: format!("{}°..{}°", num(lo), num(hi)),
            range: format!(
                "it must run upwards within {}°..{}°",
                num(limits[0]),
                num(limits[1])
            ),
            help: "give the head's mechanical limits from its data sheet".into(),
        });
        return None;
    }
    Some([lo, hi])
}

fn cmm(
    r: &Resolver,
    cx: &mut Cx,
    module: ModuleId,
    p: &mut Props,
    name: String,
    span: crate::source::Span,
) -> Cmm {
    let (table_z, table_size) = p.get("table").map_or((0.0, None), |v| table(cx, v));
    let (ram_radius, ram_length) = p
        .req(cx, "ram", "{ radius 35 mm, length 600 mm }")
        .map_or((1.0, 1.0), |v| ram(cx, v));
    let head = p
        .req(cx, "head", "PH6")
        .and_then(|v| r.lookup_value(cx, module, v, Kind::Head))
        .unwrap_or(0);
    let (probes, probe_labels) = p
        .req(cx, "probes", "[p1: TP20_D2_L20]")
        .map(|v| rack_probes(r, cx, module, v, &name))
        .unwrap_or_default();
    let (fixtures, fixture_labels) = p
        .get("fixtures")
        .map(|v| cmm_fixtures(r, cx, module, v))
        .unwrap_or_default();
    let (scanners, scanner_labels) = p
        .get("scanners")
        .map(|v| rack_scanners(r, cx, module, v, &probes))
        .unwrap_or_default();
    Cmm {
        name,
        table_z,
        table_size,
        ram_radius,
        ram_length,
        head: HeadId(head),
        probes,
        fixtures,
        scanners,
        probe_labels,
        fixture_labels,
        scanner_labels,
        span,
    }
}

/// `table { z 0 mm, size (2000 mm, 1200 mm) }`: its height and, when given, its size.
fn table(cx: &mut Cx, v: &ast::Value) -> (f64, Option<[f64; 2]>) {
    let mut table_z = 0.0;
    let mut table_size = None;
    if let ValueKind::Block(props) = &v.kind {
        let mut t = Props::new(cx, "the table", v.span, props);
        if let Some(z) = t.get("z").and_then(|z| cx.length(z)) {
            table_z = z;
        }
        if let Some(s) = t.get("size") {
            if let Some(size) = cx.lengths::<2>(s) {
                if size.iter().any(|x| *x <= 0.0) {
                    cx.err(E::NonPositive {
                        span: s.span,
                        what: "the table size".into(),
                        value: describe(s),
                        help: "give the table's length and width".into(),
                    });
                } else {
                    table_size = Some(size);
                }
            }
        }
        t.finish(cx);
    } else {
        cx.mismatch(v, "a block `{ z 0 mm, size (…) }`", "");
    }
    (table_z, table_size)
}

/// `ram { radius 35 mm, length 600 mm }`: (radius, length), 1 mm where one is wrong.
fn ram(cx: &mut Cx, v: &ast::Value) -> (f64, f64) {
    match &v.kind {
        ValueKind::Block(props) => {
            let mut t = Props::new(cx, "the ram", v.span, props);
            let radius = t
                .req(cx, "radius", "35 mm")
                .and_then(|x| cx.positive(x, Dim::Length, "radius"))
                .unwrap_or(1.0);
            let length = t
                .req(cx, "length", "600 mm")
                .and_then(|x| cx.positive(x, Dim::Length, "length"))
                .unwrap_or(1.0);
            t.finish(cx);
            (radius, length)
        }
        _ => {
            cx.mismatch(v, "a block `{ radius …, length … }`", "");
            (1.0, 1.0)
        }
    }
}

/// Labelled items of a CMM (its probes, fixtures or scanners) and where each label is.
type Labelled<Id> = (Vec<(String, Id)>, Vec<crate::source::Span>);

/// `probes [p1: TP20_D2_L20, …]`: the rack, at least one probe.
fn rack_probes(
    r: &Resolver,
    cx: &mut Cx,
    module: ModuleId,
    v: &ast::Value,
    cmm: &str,
) -> Labelled<ProbeId> {
    let mut out: Labelled<ProbeId> = Default::default();
    match &v.kind {
        ValueKind::List(entries) if !entries.is_empty() => {
            for (l, id, at) in labelled(r, cx, module, entries, Kind::Probe, "probe in the rack") {
                out.0.push((l, ProbeId(id)));
                out.1.push(at);
            }
        }
        ValueKind::List(_) => cx.err(E::MissingProperty {
            span: v.span,
            key: "probes".into(),
            item: format!("cmm `{cmm}`"),
            help: "a CMM needs at least one probe: `probes [p1: TP20_D2_L20]`".into(),
        }),
        _ => cx.mismatch(v, "a list of probes", "write `probes [p1: TP20_D2_L20]`"),
    }
    out
}

/// `fixtures [vise: VISE_150, …]`: the fixtures beside the CMM.
fn cmm_fixtures(
    r: &Resolver,
    cx: &mut Cx,
    module: ModuleId,
    v: &ast::Value,
) -> Labelled<FixtureId> {
    let mut out: Labelled<FixtureId> = Default::default();
    match &v.kind {
        ValueKind::List(entries) => {
            for (l, id, at) in labelled(
                r,
                cx,
                module,
                entries,
                Kind::Fixture,
                "fixture beside the CMM",
            ) {
                out.0.push((l, FixtureId(id)));
                out.1.push(at);
            }
        }
        _ => cx.mismatch(v, "a list of fixtures", "write `fixtures [vise: VISE_150]`"),
    }
    out
}

/// `scanners [l1: LC15Dx, …]`: scanners in the rack, labelled apart from its probes.
fn rack_scanners(
    r: &Resolver,
    cx: &mut Cx,
    module: ModuleId,
    v: &ast::Value,
    probes: &[(String, ProbeId)],
) -> Labelled<ScannerId> {
    let mut out: Labelled<ScannerId> = Default::default();
    match &v.kind {
        ValueKind::List(entries) => {
            for (l, id, at) in
                labelled(r, cx, module, entries, Kind::Scanner, "scanner in the rack")
            {
                if probes.iter().any(|(pl, _)| *pl == l) {
                    cx.err(E::DuplicateName {
                        span: at,
                        first: None,
                        name: l,
                        help: "a scanner and a probe of one rack need their own labels".into(),
                    });
                    continue;
                }
                out.0.push((l, ScannerId(id)));
                out.1.push(at);
            }
        }
        _ => cx.mismatch(v, "a list of scanners", "write `scanners [l1: LC15Dx]`"),
    }
    out
}

/// A laser line scanner: its optics (stripe, stand-off, depth of field, triangulation
/// and incidence angles, point spacing), accuracy and housing.
fn scanner(cx: &mut Cx, p: &mut Props, name: String, span: crate::source::Span) -> Scanner {
    let len = |cx: &mut Cx, p: &mut Props, key: &'static str, example: &str| {
        p.req(cx, key, example)
            .and_then(|v| cx.positive(v, Dim::Length, key))
            .unwrap_or(1.0)
    };
    let stripe_width = len(cx, p, "stripe_width", "18 mm");
    let standoff = len(cx, p, "standoff", "60 mm");
    let depth_of_field = len(cx, p, "depth_of_field", "15 mm");
    let angle = |cx: &mut Cx, p: &mut Props, key: &'static str, example: &str, hi: f64| {
        let v = p.req(cx, key, example)?;
        let a = cx.positive(v, Dim::Angle, key)?;
        if a >= hi {
            cx.err(E::OutOfRange {
                span: v.span,
                what: key.replace('_', " "),
                value: format!("{}°", num(a)),
                range: format!("0° < {key} < {}°", num(hi)),
                help: "give the angle in degrees from the scanner's data sheet".into(),
            });
            return None;
        }
        Some(a)
    };
    let triangulation = angle(cx, p, "triangulation", "30 deg", 90.0).unwrap_or(30.0);
    let max_incidence = angle(cx, p, "max_incidence", "75 deg", 90.0).unwrap_or(75.0);
    let mut spacing = [stripe_width / 500.0; 2];
    if let Some(v) = p.req(cx, "spacing", "(0.022 mm, 0.022 mm)") {
        if let Some(s) = cx.lengths::<2>(v) {
            if s.iter().any(|x| *x <= 0.0) {
                cx.err(E::NonPositive {
                    span: v.span,
                    what: "the point spacing".into(),
                    value: describe(v),
                    help: "give the spacing along the stripe and between stripes".into(),
                });
            } else {
                spacing = s;
            }
        }
    }
    let accuracy = len(cx, p, "accuracy", "0.0019 mm");
    let mut body = [50.0, 100.0];
    if let Some(v) = p.req(cx, "body", "{ diameter 60 mm, length 110 mm }") {
        match &v.kind {
            ValueKind::Block(props) => {
                let mut t = Props::new(cx, "the scanner's body", v.span, props);
                for (k, key, example) in [(0, "diameter", "60 mm"), (1, "length", "110 mm")] {
                    if let Some(x) = t
                        .req(cx, key, example)
                        .and_then(|x| cx.positive(x, Dim::Length, key))
                    {
                        body[k] = x;
                    }
                }
                t.finish(cx);
            }
            _ => cx.mismatch(v, "a block `{ diameter …, length … }`", ""),
        }
    }
    let cost = p
        .get("cost")
        .and_then(|v| cx.non_negative(v, "cost"))
        .unwrap_or(1.0);
    describe_only(cx, p);
    Scanner {
        name,
        stripe_width,
        standoff,
        depth_of_field,
        triangulation,
        max_incidence,
        spacing,
        accuracy,
        body,
        cost,
        span,
    }
}

/// A list of catalogue items of one kind with labels (`[p1: TP20_D2_L20, VISE_150]`; an
/// unlabelled entry is labelled by its name): (label, index), each label once.
fn labelled(
    r: &Resolver,
    cx: &mut Cx,
    module: ModuleId,
    entries: &[ast::ListEntry],
    kind: Kind,
    what: &str,
) -> Vec<(String, usize, crate::source::Span)> {
    let mut out: Vec<(String, usize, crate::source::Span)> = Vec::new();
    for e in entries {
        let Some(id) = r.lookup_value(cx, module, &e.value, kind) else {
            continue;
        };
        let (label, lspan) = match &e.label {
            Some(l) => (l.name.clone(), l.span),
            None => (
                match &e.value.kind {
                    ValueKind::Path(path) => super::props::path_text(path),
                    _ => String::new(),
                },
                e.value.span,
            ),
        };
        if out.iter().any(|(l, _, _)| *l == label) {
            cx.err(E::DuplicateName {
                span: lspan,
                first: None,
                name: label,
                help: format!("each {what} needs its own label"),
            });
            continue;
        }
        out.push((label, id, lspan));
    }
    out
}

/// A sampling strategy: `fan_leu`, `uniform(points 9, inset 1 mm)`, `hammersley(points 16)`.
/// `surface` is the surface type it is for, when known.
pub(super) fn strategy(
    cx: &mut Cx,
    v: &ast::Value,
    surface: Option<SurfaceKind>,
) -> Option<Strategy> {
    let (callee, args): (&ast::Ident, &[ast::Arg]) = match &v.kind {
        ValueKind::Path(p) if p.as_ident().is_some() => (p.as_ident()?, &[]),
        ValueKind::Call(c) if c.callee.as_ident().is_some() => (c.callee.as_ident()?, &c.args),
        _ => {
            cx.mismatch(
                v,
                "a sampling method",
                "write `fan_leu`, `uniform(points 9)` or `hammersley(points 16)`",
            );
            return None;
        }
    };
    let method = match callee.name.as_str() {
        "fan_leu" => SampleMethod::FanLeu,
        "spread" => SampleMethod::Spread,
        "uniform" => SampleMethod::Uniform,
        "hammersley" => SampleMethod::Hammersley,
        other => {
            let help = suggest::help_for_unknown(
                "sampling method",
                other,
                ["fan_leu", "spread", "uniform", "hammersley"],
            );
            cx.err(E::UnknownName {
                span: callee.span,
                what: "sampling method".into(),
                name: other.into(),
                help,
            });
            return None;
        }
    };
    if matches!(method, SampleMethod::FanLeu | SampleMethod::Spread)
        && matches!(surface, Some(SurfaceKind::Sphere | SurfaceKind::Freeform))
    {
        cx.err(E::OutOfRange {
            span: callee.span,
            what: if method == SampleMethod::FanLeu {
                "Fan & Leu sampling".into()
            } else {
                format!("`{}` sampling", callee.name)
            },
            value: format!("on a {}", surface.map_or("", SurfaceKind::keyword)),
            range: "its rules cover planes, cylinders and cones".into(),
            help: "use `uniform(points N)` or `hammersley(points N)` for this surface type".into(),
        });
        return None;
    }
    let mut points = None;
    let mut inset = None;
    for a in args {
        match a {
            ast::Arg::Named(k, val) if k.name == "points" => {
                points = cx.count(val, "points").and_then(|n| {
                    if n > MAX_POINTS_PER_FACE {
                        cx.err(E::OutOfRange {
                            span: val.span,
                            what: "`points`".into(),
                            value: n.to_string(),
                            range: format!("a face gets at most {MAX_POINTS_PER_FACE} points"),
                            help: "touch probes take tens of points a face; a dense cloud is a scanner's job".into(),
                        });
                        return None;
                    }
                    Some(n)
                })
            }
            ast::Arg::Named(k, val) if k.name == "inset" => inset = inset_value(cx, val),
            ast::Arg::Named(k, _) => {
                let help = suggest::help_for_unknown("option", &k.name, ["points", "inset"]);
                cx.err(E::UnknownProperty {
                    span: k.span,
                    key: k.name.clone(),
                    item: "a sampling method".into(),
                    help,
                });
            }
            ast::Arg::Positional(val) => {
                cx.mismatch(val, "a named option", "write `points 9` or `inset 1 mm`")
            }
        }
    }
    if !matches!(method, SampleMethod::FanLeu | SampleMethod::Spread)
        && points.is_none()
        && !args
            .iter()
            .any(|a| matches!(a, ast::Arg::Named(k, _) if k.name == "points"))
    {
        cx.err(E::MissingArgument {
            span: v.span,
            kind: format!("`{}`", callee.name),
            what: "a number of points".into(),
            help: format!("write `{}(points 9)`", callee.name),
        });
        return None;
    }
    Some(Strategy {
        method,
        points,
        inset,
        spacing: None,
    })
}

fn inset_value(cx: &mut Cx, v: &ast::Value) -> Option<Inset> {
    let ValueKind::Quantity(q) = &v.kind else {
        cx.mismatch(v, "a length or a percentage", "");
        return None;
    };
    if q.unit.as_ref().is_some_and(|u| u.name == "%") {
        let f = cx.quantity(q, Dim::Ratio)?;
        if !(0.0..0.5).contains(&f) {
            cx.err(E::OutOfRange {
                span: v.span,
                what: "`inset`".into(),
                value: describe(v),
                range: "a percentage from 0 % to below 50 %".into(),
                help: "the inset is taken from each side".into(),
            });
            return None;
        }
        return Some(Inset::Fraction(f));
    }
    let x = cx.length(v)?;
    if x < 0.0 {
        cx.err(E::OutOfRange {
            span: v.span,
            what: "`inset`".into(),
            value: describe(v),
            range: "it cannot be negative".into(),
            help: "give a distance from the face's boundary".into(),
        });
        return None;
    }
    Some(Inset::Length(x))
}

impl Resolver<'_> {
    /// Looks up a value that must be a name of the given kind.
    pub(super) fn lookup_value(
        &self,
        cx: &mut Cx,
        module: ModuleId,
        v: &ast::Value,
        kind: Kind,
    ) -> Option<usize> {
        match &v.kind {
            ValueKind::Path(p) => self.lookup(cx, module, p, kind),
            _ => {
                cx.mismatch(v, &format!("the name of {}", kind.word()), "");
                None
            }
        }
    }
}
