//! Tolerances: one table of GD&T rules per type, and the checks it drives.

use super::datum::{check_unique_datums, datum_ref, material};
use super::errors::ResolveError as E;
use super::props::{describe, num, path_text, Cx, Dim};
use super::scope::{Local, PartCx};
use crate::diag::suggest;
use crate::model::*;
use crate::source::Span;
use crate::syntax::ast::{self, ValueKind};

/// Whether a tolerance type takes a datum reference frame.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Datums {
    /// Form tolerances and sizes: never.
    Forbidden,
    /// Profiles: with or without.
    Optional,
    /// Orientation, location and runout: always.
    Required,
}

/// What the language accepts for one geometric tolerance type: datums, a material
/// modifier on the feature, a Ø zone (for writers of specs, e.g. `inspc import`).
#[derive(Clone, Copy, Debug)]
pub struct Accepts {
    /// Datums.
    pub datums: Datums,
    /// MMC/LMC on the toleranced feature.
    pub material: bool,
    /// A cylindrical zone.
    pub dia: bool,
    /// Its keyword.
    pub keyword: &'static str,
}

/// The rules of a tolerance type, as [`lower`] checks them.
pub fn accepts(kind: TolKind) -> Option<Accepts> {
    RULES.iter().find(|r| r.kind == kind).map(|r| Accepts {
        datums: r.datums,
        material: r.material,
        dia: r.dia,
        keyword: r.name,
    })
}

/// Every tolerance type's keyword, in the rules' order (the editor's completion).
pub fn keywords() -> impl Iterator<Item = &'static str> {
    RULES.iter().map(|r| r.name)
}

/// The rules of one tolerance type.
struct Rule {
    name: &'static str,
    kind: TolKind,
    datums: Datums,
    /// MMC/LMC allowed on the toleranced feature.
    material: bool,
    /// A cylindrical (Ø) zone allowed.
    dia: bool,
    /// Number of toleranced features (min, max).
    targets: (usize, usize),
    /// A size tolerance with limits of this dimension (geometric tolerances: `None`).
    size: Option<Dim>,
}

const fn geo(name: &'static str, kind: TolKind, datums: Datums, material: bool, dia: bool) -> Rule {
    Rule {
        name,
        kind,
        datums,
        material,
        dia,
        targets: (1, 1),
        size: None,
    }
}

const fn size(name: &'static str, kind: TolKind, targets: (usize, usize), dim: Dim) -> Rule {
    Rule {
        name,
        kind,
        datums: Datums::Forbidden,
        material: false,
        dia: false,
        targets,
        size: Some(dim),
    }
}

use Datums::*;
use TolKind as K;

/// ASME Y14.5-2009 rules, as a CMM program needs them.
const RULES: &[Rule] = &[
    geo("flatness", K::Flatness, Forbidden, false, false),
    geo("straightness", K::Straightness, Forbidden, true, true),
    geo("circularity", K::Circularity, Forbidden, false, false),
    geo("cylindricity", K::Cylindricity, Forbidden, false, false),
    geo("profile_line", K::ProfileLine, Optional, false, false),
    geo("profile_surface", K::ProfileSurface, Optional, false, false),
    geo(
        "perpendicularity",
        K::Perpendicularity,
        Required,
        true,
        true,
    ),
    geo("parallelism", K::Parallelism, Required, true, true),
    geo("angularity", K::Angularity, Required, true, true),
    geo("position", K::Position, Required, true, true),
    geo("concentricity", K::Concentricity, Required, false, true),
    geo("coaxiality", K::Coaxiality, Required, true, true),
    geo("symmetry", K::Symmetry, Required, false, false),
    geo("circular_runout", K::CircularRunout, Required, false, false),
    geo("total_runout", K::TotalRunout, Required, false, false),
    size("diameter", K::Diameter, (1, 1), Dim::Length),
    size("radius", K::Radius, (1, 1), Dim::Length),
    size("width", K::Width, (1, 1), Dim::Length),
    size("distance", K::Distance, (1, 2), Dim::Length),
    size("angle", K::Angle, (2, 2), Dim::Angle),
];

pub(super) fn lower(
    cx: &mut Cx,
    pc: &PartCx,
    name: &ast::Ident,
    call: &ast::Call,
) -> Option<Tolerance> {
    let rule = rule_of(cx, call)?;
    let mut args = Args::read(cx, pc, rule, call)?;
    args.check_arity(cx, rule, call);
    let per_unit = args.per_unit_zone(cx, rule);
    let Some((value, value_span)) = args.value.take() else {
        if args.ok {
            missing_value(cx, rule, call);
        }
        return None;
    };
    args.check_zero_zone(cx, rule, value_span);
    args.check_datums_allowed(cx, rule, call);
    args.check_basic_angle(cx, rule, call);
    check_unique_datums(cx, &pc.part, &args.datums);
    args.check_self_reference(cx, pc);
    args.ok.then(|| Tolerance {
        name: name.name.clone(),
        kind: rule.kind,
        targets: args.targets.into_iter().map(|t| t.0).collect(),
        value,
        modifier: args.modifier.map(|m| m.0),
        datums: args.datums.into_iter().map(|d| d.0).collect(),
        basic_angle: args.basic_angle,
        per_unit,
        span: name.span,
    })
}

/// The rule of the tolerance type a call names (`roundness` is `circularity`).
fn rule_of(cx: &mut Cx, call: &ast::Call) -> Option<&'static Rule> {
    let callee = call.callee.as_ident();
    let callee_name = callee.map_or_else(|| path_text(&call.callee), |i| i.name.clone());
    let lookup = if callee_name == "roundness" {
        "circularity"
    } else {
        callee_name.as_str()
    };
    let Some(rule) = RULES.iter().find(|r| r.name == lookup) else {
        let help =
            suggest::help_for_unknown("tolerance type", &callee_name, RULES.iter().map(|r| r.name));
        cx.err(E::UnknownName {
            span: call.callee.span,
            what: "tolerance type".into(),
            name: callee_name,
            help,
        });
        return None;
    };
    Some(rule)
}

/// A tolerance call's arguments as read in one pass, and whether all of them were good.
struct Args {
    targets: Vec<(FeatureId, Span)>,
    value: Option<(TolValue, Span)>,
    modifier: Option<(Material, Span)>,
    datums: Vec<(DatumRef, Span)>,
    basic_angle: Option<f64>,
    /// `per_unit(zone, stretch)`, read.
    per_unit: Option<(f64, UnitOf, Span)>,
    /// A zone written as 0 (described), legal only at MMC or LMC.
    zero: Option<String>,
    ok: bool,
    /// Whether the value has been written (valid or not): targets come before it,
    /// modifiers and datums after.
    past_value: bool,
    target_failed: bool,
}

impl Args {
    /// Reads every argument in order; None where a material modifier does not read
    /// (the tolerance is dropped without further checks).
    fn read(cx: &mut Cx, pc: &PartCx, rule: &Rule, call: &ast::Call) -> Option<Args> {
        let mut args = Args {
            targets: Vec::new(),
            value: None,
            modifier: None,
            datums: Vec::new(),
            basic_angle: None,
            per_unit: None,
            zero: None,
            ok: true,
            past_value: false,
            target_failed: false,
        };
        for a in &call.args {
            match a {
                ast::Arg::Named(k, v) => args.named(cx, rule, k, v),
                ast::Arg::Positional(v) => args.positional(cx, pc, rule, v)?,
            }
        }
        Some(args)
    }

    /// `dia 0.1 mm`, `basic 30 deg`, or an unknown name.
    fn named(&mut self, cx: &mut Cx, rule: &Rule, k: &ast::Ident, v: &ast::Value) {
        match k.name.as_str() {
            "dia" => {
                self.past_value = true;
                if !rule.dia {
                    cx.err(E::DiameterZone {
                        span: k.span,
                        kind: rule.name.into(),
                    });
                    self.ok = false;
                }
                match zone(cx, v, rule.name) {
                    Some(w) => {
                        if w == 0.0 {
                            self.zero = Some(describe(v));
                        }
                        let zone = TolValue::Zone {
                            width: w,
                            diameter: true,
                        };
                        self.value = Some((zone, v.span));
                    }
                    None => self.ok = false,
                }
            }
            "basic" => {
                if rule.kind != K::Angularity {
                    cx.err(E::UnknownProperty {
                        span: k.span,
                        key: "basic".into(),
                        item: rule.name.into(),
                        help: "only angularity takes a basic angle".into(),
                    });
                }
                self.basic_angle = cx.angle(v);
            }
            _ => {
                let help = suggest::help_for_unknown("argument", &k.name, ["dia", "basic"]);
                cx.err(E::UnknownProperty {
                    span: k.span,
                    key: k.name.clone(),
                    item: rule.name.into(),
                    help,
                });
                self.ok = false;
            }
        }
    }

    /// A value, a toleranced feature, a material modifier, a frame or a datum, told
    /// apart by form and by where it stands; None where a modifier does not read.
    fn positional(&mut self, cx: &mut Cx, pc: &PartCx, rule: &Rule, v: &ast::Value) -> Option<()> {
        match &v.kind {
            ValueKind::Quantity(_) | ValueKind::Limits { .. } | ValueKind::Range(..) => {
                self.value_arg(cx, rule, v);
            }
            ValueKind::Path(p) if !self.past_value => match target(cx, pc, p) {
                Some(f) => self.targets.push((f, p.span)),
                None => {
                    self.ok = false;
                    self.target_failed = true;
                }
            },
            ValueKind::Path(p)
                if p.as_ident()
                    .is_some_and(|i| matches!(i.name.as_str(), "MMC" | "LMC" | "RFS"))
                    && self.datums.is_empty() =>
            {
                self.modifier_arg(cx, rule, p)?;
            }
            ValueKind::Path(p)
                if p.segs.len() == 1
                    && matches!(pc.names.get(&p.head().name), Some((Local::Frame(_), _))) =>
            {
                let Some(Local::Frame(i)) = pc.local(cx, p.head()) else {
                    unreachable!()
                };
                match pc.part.frames.get(i) {
                    Some(f) => self
                        .datums
                        .extend(f.refs.iter().map(|r| (r.clone(), p.span))),
                    None => self.ok = false,
                }
            }
            ValueKind::Call(c) if c.callee.as_ident().is_some_and(|i| i.name == PER_UNIT) => {
                self.past_value = true;
                match per_unit(cx, rule, c) {
                    Some(p) => self.per_unit = Some(p),
                    None => self.ok = false,
                }
            }
            ValueKind::Path(_) | ValueKind::Call(_) => match datum_ref(cx, pc, v) {
                Some(d) => self.datums.push(d),
                None => self.ok = false,
            },
            _ => {
                cx.mismatch(
                    v,
                    "a feature, a value, a modifier or a datum",
                    &format!("write e.g. `{}(feature, 0.05 mm, A)`", rule.name),
                );
                self.ok = false;
            }
        }
        Some(())
    }

    /// The tolerance's value: limits for a size, a zone width for the others.
    fn value_arg(&mut self, cx: &mut Cx, rule: &Rule, v: &ast::Value) {
        self.past_value = true;
        let val = if let Some(dim) = rule.size {
            size_limits(cx, v, dim)
        } else {
            zone(cx, v, rule.name).map(|w| {
                if w == 0.0 {
                    self.zero = Some(describe(v));
                }
                TolValue::Zone {
                    width: w,
                    diameter: false,
                }
            })
        };
        match val {
            Some(val) => self.value = Some((val, v.span)),
            None => self.ok = false,
        }
    }

    /// The per-unit zone, checked against the tolerance's type and overall zone; where
    /// it stands alone it is the tolerance's value too.
    fn per_unit_zone(&mut self, cx: &mut Cx, rule: &Rule) -> Option<PerUnit> {
        let (zone, unit, span) = self.per_unit.take()?;
        let Some((overall, _)) = &self.value else {
            self.value = Some((
                TolValue::Zone {
                    width: zone,
                    diameter: false,
                },
                span,
            ));
            return Some(PerUnit {
                zone,
                unit,
                overall: false,
            });
        };
        if let TolValue::Zone { width, .. } = overall {
            if zone >= *width {
                cx.err(E::PerUnit {
                    span,
                    problem: format!(
                        "its zone {} mm is not tighter than the {} mm over the whole feature",
                        crate::model::fmt_num(zone),
                        crate::model::fmt_num(*width)
                    ),
                    help: format!("a unit zone limits abrupt change within a short stretch and is the smaller of the two (ASME Y14.5-2018 § 5.4.2.2); write `{}(feature, 0.1 mm, per_unit(0.02 mm, 25 mm))`, or the unit zone alone", rule.name),
                });
                self.ok = false;
            }
        }
        Some(PerUnit {
            zone,
            unit,
            overall: true,
        })
    }

    /// A position zone of width 0 reads only at MMC or LMC, where the feature's
    /// departure from that size is the whole tolerance (ASME Y14.5-2018 § 10.3.4, zero
    /// tolerance at MMC); elsewhere no part could pass it.
    fn check_zero_zone(&mut self, cx: &mut Cx, rule: &Rule, span: Span) {
        // Only a position gains the bonus that makes a zero zone hold a part (the
        // simulator's and a CMM's evaluation of TOL/POS); elsewhere 0 holds nothing.
        let at_material = rule.kind == K::Position
            && matches!(self.modifier, Some((Material::Mmc | Material::Lmc, _)));
        if let Some(value) = self.zero.take().filter(|_| !at_material) {
            cx.err(E::NonPositive {
                span,
                what: format!("the {} tolerance", rule.name),
                value,
                help: if rule.kind == K::Position {
                    "a zone of 0 reads only at MMC or LMC, where the size's departure from that condition is the tolerance (ASME Y14.5 zero tolerance at MMC); add `MMC` or give the zone a width".into()
                } else {
                    "a tolerance zone has a positive width".into()
                },
            });
            self.ok = false;
        }
    }

    /// `MMC`, `LMC` or `RFS` on the toleranced feature; None where it does not read.
    fn modifier_arg(&mut self, cx: &mut Cx, rule: &Rule, p: &ast::Path) -> Option<()> {
        let m = material(cx, p.as_ident()?)?;
        if !rule.material && m != Material::Rfs {
            let what = rule.name;
            cx.err(E::ModifierNotAllowed {
                span: p.span,
                kind: what.into(),
                modifier: p.head().name.clone(),
                help: format!("{what} applies regardless of feature size; material modifiers belong on features of size under orientation, position or coaxiality"),
            });
            self.ok = false;
        }
        self.modifier = Some((m, p.span));
        Some(())
    }

    /// As many toleranced features as the type takes (unless one already failed).
    fn check_arity(&mut self, cx: &mut Cx, rule: &Rule, call: &ast::Call) {
        let (min, max) = rule.targets;
        let n = self.targets.len();
        if self.target_failed || (min..=max).contains(&n) {
            return;
        }
        let expected = if min == max {
            format!("{min} feature{}", if min == 1 { "" } else { "s" })
        } else {
            format!("{min} or {max} features")
        };
        cx.err(E::Arity {
            span: self.targets.get(max).map_or(call.span, |t| t.1),
            kind: rule.name.into(),
            expected,
            found: format!("{n}"),
            help: format!(
                "the toleranced feature{} come{} first: `{}(…)`",
                if max > 1 { "s" } else { "" },
                if max > 1 { "" } else { "s" },
                rule.name
            ),
        });
        self.ok = false;
    }

    /// Datums where the type forbids them, or none where it requires them.
    fn check_datums_allowed(&mut self, cx: &mut Cx, rule: &Rule, call: &ast::Call) {
        let what = rule.name;
        match rule.datums {
            Forbidden => {
                if let Some((_, span)) = self.datums.first() {
                    let help = if rule.size.is_some() {
                        "sizes are checked without a datum frame".to_string()
                    } else {
                        format!("{what} is a form tolerance: it controls the feature on its own")
                    };
                    cx.err(E::DatumsForbidden {
                        span: *span,
                        kind: what.into(),
                        help,
                    });
                    self.ok = false;
                }
            }
            // A datum that failed to resolve was reported already: no cascade.
            Required if self.datums.is_empty() && self.ok => {
                cx.err(E::DatumsRequired { span: call.span, kind: what.into(), help: format!("{what} is measured relative to a datum: add one, e.g. `{}(feature, 0.05 mm, A)`", rule.name) });
                self.ok = false;
            }
            _ => {}
        }
    }

    /// Angularity's basic angle, unless something else failed already.
    fn check_basic_angle(&mut self, cx: &mut Cx, rule: &Rule, call: &ast::Call) {
        if rule.kind == K::Angularity && self.basic_angle.is_none() && self.ok {
            cx.err(E::MissingArgument {
                span: call.span,
                kind: rule.name.into(),
                what: "its basic angle".into(),
                help: "write `angularity(feature, 0.1 mm, A, basic 30 deg)`".into(),
            });
            self.ok = false;
        }
    }

    /// No datum whose feature is one the tolerance controls.
    fn check_self_reference(&mut self, cx: &mut Cx, pc: &PartCx) {
        for (d, span) in &self.datums {
            let df = pc.part.datums[d.datum.0].feature;
            if let Some((f, _)) = self.targets.iter().find(|(f, _)| *f == df) {
                cx.err(E::DatumSelfReference {
                    span: *span,
                    datum: pc.part.datums[d.datum.0].name.clone(),
                    feature: pc.part.features[f.0].name.clone(),
                });
                self.ok = false;
            }
        }
    }
}

/// Says a tolerance has no value: limits for a size, a zone for the others.
fn missing_value(cx: &mut Cx, rule: &Rule, call: &ast::Call) {
    let (what_value, example) = if rule.size.is_some() {
        ("limits, e.g. `10 mm ± 0.05 mm`", "10 mm ± 0.05 mm")
    } else {
        ("a tolerance value, e.g. `0.05 mm`", "0.05 mm")
    };
    cx.err(E::MissingArgument {
        span: call.span,
        kind: rule.name.into(),
        what: what_value.into(),
        help: format!("write `{}(feature, {example})`", rule.name),
    });
}

fn target(cx: &mut Cx, pc: &PartCx, p: &ast::Path) -> Option<FeatureId> {
    let head = p.head();
    if p.segs.len() > 1 {
        cx.err(E::TypeMismatch {
            span: p.span,
            expected: "a feature".into(),
            found: format!("the face `{}`", path_text(p)),
            help: format!(
                "tolerances apply to features: declare `feature {}_f = {}` and name it here",
                head.name,
                path_text(p)
            ),
        });
        return None;
    }
    match pc.local(cx, head) {
        Some(Local::Feature(i)) if p.segs.len() == 1 => {
            (i < pc.part.features.len()).then_some(FeatureId(i))
        }
        Some(Local::Datum(i)) if p.segs.len() == 1 => pc.part.datums.get(i).map(|d| d.feature),
        Some(other) => {
            cx.err(E::WrongKind {
                span: p.span,
                name: path_text(p),
                expected: "a feature".into(),
                found: other.word(&pc.part),
                help:
                    "tolerances apply to features: declare `feature name = faces` and name it here"
                        .into(),
            });
            None
        }
        None => {
            let features = pc
                .names
                .iter()
                .filter(|(_, (l, _))| matches!(l, Local::Feature(_)))
                .map(|(n, _)| n.as_str());
            let help = suggest::help_for_unknown("feature", &head.name, features);
            cx.err(E::UnknownName {
                span: p.span,
                what: "feature".into(),
                name: path_text(p),
                help,
            });
            None
        }
    }
}

/// The call that gives a zone per unit length or area.
const PER_UNIT: &str = "per_unit";

/// `per_unit(zone, length)` (straightness; flatness per square), `per_unit(zone,
/// length, width)` or `per_unit(zone, dia d)` (flatness per rectangle or circle): the
/// unit stretches ASME Y14.5-2018 § 5.4.1.4 and § 5.4.2.2 and ISO 1101 allow, for the
/// two tolerances they allow them on.
fn per_unit(cx: &mut Cx, rule: &Rule, c: &ast::Call) -> Option<(f64, UnitOf, Span)> {
    let example = "`per_unit(0.02 mm, 25 mm)`";
    if !matches!(rule.kind, K::Flatness | K::Straightness) {
        cx.err(E::PerUnit {
            span: c.callee.span,
            problem: format!("{} takes no zone per unit", rule.name),
            help: "a zone per unit length or area is a form control: straightness per unit length, flatness per unit area (ASME Y14.5-2018 § 5.4.1.4, § 5.4.2.2)".into(),
        });
        return None;
    }
    let area = rule.kind == K::Flatness;
    let mut lengths = Vec::new();
    let mut circle = None;
    for a in &c.args {
        match a {
            ast::Arg::Positional(v) => lengths.push(cx.positive(v, Dim::Length, PER_UNIT)?),
            ast::Arg::Named(k, v) if k.name == "dia" && area => {
                circle = Some(cx.positive(v, Dim::Length, PER_UNIT)?)
            }
            ast::Arg::Named(k, _) => {
                cx.err(E::UnknownProperty {
                    span: k.span,
                    key: k.name.clone(),
                    item: PER_UNIT.into(),
                    help: if area {
                        "`dia 25 mm` gives a circular unit area".into()
                    } else {
                        format!("straightness per unit takes a length: {example}")
                    },
                });
                return None;
            }
        }
    }
    let unit = match (lengths.as_slice(), circle, area) {
        ([zone, l], None, false) => Some((*zone, UnitOf::Length(*l))),
        ([zone, l], None, true) => Some((*zone, UnitOf::Rectangle(*l, *l))),
        ([zone, l, w], None, true) => Some((*zone, UnitOf::Rectangle(*l, *w))),
        ([zone], Some(d), true) => Some((*zone, UnitOf::Circle(d))),
        _ => None,
    };
    let Some((zone, unit)) = unit else {
        cx.err(E::PerUnit {
            span: c.span,
            problem: "it needs a zone and the unit's size".into(),
            help: if area {
                "flatness per unit area: `per_unit(0.02 mm, 25 mm)` (a 25 × 25 square), `per_unit(0.02 mm, 25 mm, 50 mm)` (a rectangle) or `per_unit(0.02 mm, dia 25 mm)` (a circle)".into()
            } else {
                format!("straightness per unit length: {example} (0.02 mm in any 25 mm)")
            },
        });
        return None;
    };
    Some((zone, unit, c.span))
}

fn zone(cx: &mut Cx, v: &ast::Value, what: &str) -> Option<f64> {
    match &v.kind {
        ValueKind::Quantity(_) => {
            let w = cx.length(v)?;
            // A zone of 0 is checked against the modifier once it is read.
            if w < 0.0 {
                cx.err(E::NonPositive {
                    span: v.span,
                    what: format!("the {what} tolerance"),
                    value: describe(v),
                    help: "a tolerance zone has a positive width".into(),
                });
                return None;
            }
            Some(w)
        }
        _ => {
            cx.mismatch(
                v,
                "a tolerance zone width such as `0.05 mm`",
                "limits belong to size tolerances (`diameter`, `width`, `distance`, `angle`)",
            );
            None
        }
    }
}

fn size_limits(cx: &mut Cx, v: &ast::Value, dim: Dim) -> Option<TolValue> {
    let (nominal, lower, upper) = match &v.kind {
        ValueKind::Limits {
            nominal,
            plus,
            minus,
        } => {
            let n = cx.quantity(nominal, dim);
            let p = cx.quantity(plus, dim);
            let m = cx.quantity(minus, dim);
            let (n, p, m) = (n?, p?, m?);
            (n, n + m, n + p)
        }
        ValueKind::Range(lo, hi) => {
            let lo = cx.quantity(lo, dim);
            let hi = cx.quantity(hi, dim);
            let (lo, hi) = (lo?, hi?);
            ((lo + hi) / 2.0, lo, hi)
        }
        _ => {
            cx.mismatch(
                v,
                "limits such as `10 mm ± 0.05 mm` or `9.95 mm .. 10.05 mm`",
                "a size tolerance gives its nominal and limits",
            );
            return None;
        }
    };
    if lower >= upper {
        cx.err(E::InvalidLimits {
            span: v.span,
            lower: num(lower),
            upper: num(upper),
        });
        return None;
    }
    if nominal <= 0.0 && dim == Dim::Length {
        cx.err(E::NonPositive {
            span: v.span,
            what: "the nominal size".into(),
            value: num(nominal),
            help: "sizes are positive".into(),
        });
        return None;
    }
    Some(TolValue::Size {
        nominal,
        lower,
        upper,
    })
}

#[cfg(test)]
mod tests {
    /// The table's names are the model's keywords, and it has a rule for every kind.
    #[test]
    fn rule_names_are_the_keywords() {
        for r in super::RULES {
            assert_eq!(r.name, r.kind.keyword());
        }
        assert_eq!(super::RULES.len(), 20);
    }
}
