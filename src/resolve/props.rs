//! Properties and quantities: the schema mechanism every catalogue item uses, and unit
//! conversion to millimetres and degrees.
//!
//! **Decision: units.** Inside a part, bare numbers take the part's `units`; elsewhere
//! lengths and angles need a unit (a bare `0` is allowed). Percentages are ratios.

use super::errors::ResolveError as E;
use crate::diag::{suggest, Diagnostics};
use crate::model::Vec3;
use crate::source::{FileId, Span};
use crate::syntax::ast::{self, Quantity, Value, ValueKind};

use crate::model::MAX_LENGTH_MM;

/// A physical dimension a quantity must have.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Dim {
    Length,
    Angle,
    Ratio,
}

impl Dim {
    fn word(self) -> &'static str {
        match self {
            Dim::Length => "a length",
            Dim::Angle => "an angle",
            Dim::Ratio => "a ratio",
        }
    }
}

/// Every unit: name, dimension, factor to the internal unit (mm, degrees, fraction).
pub(crate) const UNITS: &[(&str, Dim, f64)] = &[
    ("mm", Dim::Length, 1.0),
    ("cm", Dim::Length, 10.0),
    ("m", Dim::Length, 1000.0),
    ("um", Dim::Length, 0.001),
    ("in", Dim::Length, 25.4),
    ("deg", Dim::Angle, 1.0),
    ("rad", Dim::Angle, 180.0 / std::f64::consts::PI),
    ("%", Dim::Ratio, 0.01),
];

pub(crate) use crate::model::fmt_num as num;

/// Every unit a quantity may carry, with what it measures (`a length`, `an angle`,
/// `a ratio`): the editor's completion of units.
pub fn units() -> impl Iterator<Item = (&'static str, &'static str)> {
    UNITS.iter().map(|(n, d, _)| (*n, d.word()))
}

/// Millimetres per unit for a length unit name (`mm`, `in`, …).
pub fn length_unit_mm(name: &str) -> Option<f64> {
    UNITS
        .iter()
        .find(|(n, d, _)| *n == name && *d == Dim::Length)
        .map(|(_, _, f)| *f)
}

/// Describes a value's form for "found …" messages.
pub(crate) fn describe(v: &Value) -> String {
    match &v.kind {
        ValueKind::Quantity(q) => match &q.unit {
            Some(u) => match UNITS.iter().find(|(n, _, _)| *n == u.name) {
                Some((_, d, _)) => format!("{} `{} {}`", d.word(), num(q.value), u.name),
                None => format!("`{} {}`", num(q.value), u.name),
            },
            None => format!("the number `{}`", num(q.value)),
        },
        ValueKind::Limits { .. } => "limits".into(),
        ValueKind::Range(..) => "a range".into(),
        ValueKind::Direction { .. } => "a direction".into(),
        ValueKind::Str(_) => "a string".into(),
        ValueKind::Tuple(t) => format!("a tuple of {}", t.len()),
        ValueKind::List(_) => "a list".into(),
        ValueKind::Block(_) => "a block".into(),
        ValueKind::Call(c) => format!("a call of `{}`", path_text(&c.callee)),
        ValueKind::Path(p) => format!("the name `{}`", path_text(p)),
    }
}

/// The text of a path as written.
pub(crate) fn path_text(p: &ast::Path) -> String {
    p.text.clone()
}

/// The context values are converted in: where errors go and what a bare length means.
pub(crate) struct Cx<'d> {
    pub diags: &'d mut Diagnostics,
    /// The names bound and blocks read so far (see [`crate::model::SourceIndex`]).
    pub index: &'d mut crate::model::SourceIndex,
    pub file: FileId,
    /// mm per bare number in a length position (inside a part), if any.
    pub unit_mm: Option<f64>,
}

impl Cx<'_> {
    pub fn err(&mut self, e: E) {
        self.diags.push(e);
    }

    /// Records that the name at `used` binds to the one declared at `decl`.
    pub fn bind(&mut self, used: Span, decl: Span) {
        self.index.names.push(crate::model::NameUse { used, decl });
    }

    pub(crate) fn mismatch(&mut self, v: &Value, expected: &str, help: &str) {
        let help = if !help.is_empty() {
            help.to_string()
        } else {
            match expected {
                "a length" => "write a length such as `10 mm`".into(),
                "an angle" => "write an angle such as `30 deg`".into(),
                "a name" => "write a name, without quotes".into(),
                _ => format!("write {expected} here"),
            }
        };
        self.err(E::TypeMismatch {
            span: v.span,
            expected: expected.into(),
            found: describe(v),
            help,
        });
    }

    /// Converts a quantity to the internal unit of `dim`.
    pub fn quantity(&mut self, q: &Quantity, dim: Dim) -> Option<f64> {
        let x = self.quantity_unbounded(q, dim)?;
        if dim == Dim::Length && x.abs() > MAX_LENGTH_MM {
            self.err(E::OutOfRange {
                span: q.span,
                what: "length".into(),
                value: format!("{x:e} mm"),
                range: format!("a spec's lengths are at most {} m", MAX_LENGTH_MM / 1000.0),
                help: "no CMM measures beyond 10 m; check the value and its unit".into(),
            });
            return None;
        }
        Some(x)
    }

    fn quantity_unbounded(&mut self, q: &Quantity, dim: Dim) -> Option<f64> {
        match &q.unit {
            None => {
                if dim == Dim::Ratio || q.value == 0.0 {
                    return Some(q.value);
                }
                if dim == Dim::Length {
                    if let Some(f) = self.unit_mm {
                        return Some(q.value * f);
                    }
                }
                let (units, example) = match dim {
                    Dim::Length => ("mm, cm, m, um or in", "mm"),
                    _ => ("deg or rad", "deg"),
                };
                let hint = if dim == Dim::Length {
                    "; inside a part, bare numbers take the part's `units`"
                } else {
                    ""
                };
                self.err(E::MissingUnit {
                    span: q.span,
                    value: num(q.value),
                    expected: dim.word().into(),
                    help: format!("write `{} {example}` ({units}){hint}", num(q.value)),
                });
                None
            }
            Some(u) => match UNITS.iter().find(|(n, _, _)| *n == u.name) {
                None => {
                    let help = suggest::help_for_unknown(
                        "unit",
                        &u.name,
                        UNITS.iter().map(|(n, _, _)| *n),
                    );
                    self.err(E::UnknownUnit {
                        span: u.span,
                        unit: u.name.clone(),
                        help,
                    });
                    None
                }
                Some((_, d, f)) if *d == dim => Some(q.value * f),
                Some((_, d, _)) => {
                    self.err(E::UnitMismatch {
                        span: q.span,
                        expected: dim.word().into(),
                        found: d.word().into(),
                        unit: u.name.clone(),
                        help: match dim {
                            Dim::Length => "lengths are in mm, cm, m, um or in".into(),
                            Dim::Angle => "angles are in deg or rad".into(),
                            Dim::Ratio => "ratios are plain numbers or percentages".into(),
                        },
                    });
                    None
                }
            },
        }
    }

    /// A quantity value of a dimension.
    pub fn dim(&mut self, v: &Value, dim: Dim) -> Option<f64> {
        match &v.kind {
            ValueKind::Quantity(q) => self.quantity(q, dim),
            _ => {
                self.mismatch(v, dim.word(), "");
                None
            }
        }
    }

    /// A length (mm).
    pub fn length(&mut self, v: &Value) -> Option<f64> {
        self.dim(v, Dim::Length)
    }

    /// An angle (degrees).
    pub fn angle(&mut self, v: &Value) -> Option<f64> {
        self.dim(v, Dim::Angle)
    }

    /// A quantity that must be > 0.
    pub fn positive(&mut self, v: &Value, dim: Dim, what: &str) -> Option<f64> {
        let x = self.dim(v, dim)?;
        if x <= 0.0 {
            self.err(E::NonPositive {
                span: v.span,
                what: format!("`{what}`"),
                value: describe(v),
                help: format!("`{what}` is a physical size; give it a positive value"),
            });
            return None;
        }
        Some(x)
    }

    /// A plain number (weights, costs, scales).
    pub fn number(&mut self, v: &Value) -> Option<f64> {
        match &v.kind {
            ValueKind::Quantity(Quantity {
                value, unit: None, ..
            }) => Some(*value),
            ValueKind::Quantity(Quantity { unit: Some(u), .. }) => {
                self.err(E::UnitMismatch {
                    span: v.span,
                    expected: "a plain number".into(),
                    found: UNITS
                        .iter()
                        .find(|(n, _, _)| *n == u.name)
                        .map_or("a quantity", |(_, d, _)| d.word())
                        .into(),
                    unit: u.name.clone(),
                    help: "weights and costs have no unit".into(),
                });
                None
            }
            _ => {
                self.mismatch(v, "a number", "");
                None
            }
        }
    }

    /// A plain number ≥ 0.
    pub(crate) fn non_negative(&mut self, v: &Value, what: &str) -> Option<f64> {
        let x = self.number(v)?;
        if x < 0.0 {
            self.err(E::OutOfRange {
                span: v.span,
                what: format!("`{what}`"),
                value: num(x),
                range: "it cannot be negative".into(),
                help: format!("give `{what}` a value of 0 or more"),
            });
            return None;
        }
        Some(x)
    }

    /// A whole number ≥ 1.
    pub fn count(&mut self, v: &Value, what: &str) -> Option<u32> {
        let x = self.number(v)?;
        if x.fract() != 0.0 || !(1.0..=1e6).contains(&x) {
            self.err(E::OutOfRange {
                span: v.span,
                what: format!("`{what}`"),
                value: num(x),
                range: "expected a whole number from 1 to 1000000".into(),
                help: format!("`{what}` counts things"),
            });
            return None;
        }
        Some(x as u32)
    }

    /// A unit direction: `+z` or `(x, y, z)`.
    pub fn direction(&mut self, v: &Value) -> Option<Vec3> {
        let raw = match &v.kind {
            ValueKind::Direction { axis, negative } => {
                let mut d = [0.0; 3];
                d[*axis as usize] = if *negative { -1.0 } else { 1.0 };
                return Some(d);
            }
            ValueKind::Tuple(items) if items.len() == 3 => {
                let mut d = [0.0; 3];
                for (k, it) in items.iter().enumerate() {
                    d[k] = self.number(it)?;
                }
                d
            }
            _ => {
                self.mismatch(
                    v,
                    "a direction",
                    "write `+x`, `-z` or a vector such as `(0, 1, 1)`",
                );
                return None;
            }
        };
        // Scaled by its largest component first, so that huge components do not
        // overflow into a zero vector.
        let scale = raw.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        if !(scale.is_finite() && scale > 0.0) {
            self.err(E::ZeroVector { span: v.span });
            return None;
        }
        let raw = raw.map(|x| x / scale);
        let n = (raw[0] * raw[0] + raw[1] * raw[1] + raw[2] * raw[2]).sqrt();
        Some([raw[0] / n, raw[1] / n, raw[2] / n])
    }

    /// A tuple of `N` lengths.
    pub(crate) fn lengths<const N: usize>(&mut self, v: &Value) -> Option<[f64; N]> {
        match &v.kind {
            ValueKind::Tuple(items) if items.len() == N => {
                let mut out = [0.0; N];
                let mut ok = true;
                for (k, it) in items.iter().enumerate() {
                    match self.length(it) {
                        Some(x) => out[k] = x,
                        None => ok = false,
                    }
                }
                ok.then_some(out)
            }
            _ => {
                let expected = if N == 3 {
                    "a point `(x, y, z)`".to_string()
                } else {
                    format!("a tuple of {N} lengths")
                };
                self.mismatch(v, &expected, "");
                None
            }
        }
    }

    /// A single name.
    pub fn name<'v>(&mut self, v: &'v Value) -> Option<&'v ast::Ident> {
        match &v.kind {
            ValueKind::Path(p) if p.as_ident().is_some() => p.as_ident(),
            _ => {
                self.mismatch(v, "a name", "");
                None
            }
        }
    }

    /// A string.
    pub fn string<'v>(&mut self, v: &'v Value) -> Option<&'v ast::Str> {
        match &v.kind {
            ValueKind::Str(s) => Some(s),
            _ => {
                self.mismatch(v, "a string", "write it in double quotes");
                None
            }
        }
    }
}

/// The properties of one item, checked against the keys the lowering asks for.
pub(crate) struct Props<'a> {
    item: String,
    owner: Span,
    props: Vec<&'a ast::Prop>,
    asked: Vec<&'static str>,
}

impl<'a> Props<'a> {
    /// Collects properties, reporting keys given twice.
    pub fn new(cx: &mut Cx, item: impl Into<String>, owner: Span, props: &'a [ast::Prop]) -> Self {
        let mut kept: Vec<&'a ast::Prop> = Vec::new();
        for p in props {
            match kept.iter().find(|k| k.key.name == p.key.name) {
                Some(first) => cx.err(E::DuplicateProperty {
                    span: p.key.span,
                    first: first.key.span,
                    key: p.key.name.clone(),
                }),
                None => kept.push(p),
            }
        }
        Props {
            item: item.into(),
            owner,
            props: kept,
            asked: Vec::new(),
        }
    }

    /// The value of an optional property.
    pub fn get(&mut self, key: &'static str) -> Option<&'a Value> {
        self.asked.push(key);
        self.props
            .iter()
            .find(|p| p.key.name == key)
            .map(|p| &p.value)
    }

    /// The value of a required property, reporting it missing.
    pub fn req(&mut self, cx: &mut Cx, key: &'static str, example: &str) -> Option<&'a Value> {
        let v = self.get(key);
        if v.is_none() {
            cx.err(E::MissingProperty {
                span: self.owner,
                key: key.into(),
                item: self.item.clone(),
                help: format!("add `{key} {example}`"),
            });
        }
        v
    }

    /// Reports every property nobody asked for.
    pub fn finish(self, cx: &mut Cx) {
        cx.index.keys.push(crate::model::KeySet {
            owner: self.owner,
            keys: self.asked.clone(),
        });
        for p in &self.props {
            if !self.asked.contains(&p.key.name.as_str()) {
                let help =
                    suggest::help_for_unknown("property", &p.key.name, self.asked.iter().copied());
                cx.err(E::UnknownProperty {
                    span: p.key.span,
                    key: p.key.name.clone(),
                    item: self.item.clone(),
                    help,
                });
            }
        }
    }
}

/// Positional or named arguments of a call, by parameter order.
pub(super) fn call_args<'c>(
    cx: &mut Cx,
    call: &'c ast::Call,
    params: &[&'static str],
    what: &str,
) -> Vec<Option<&'c ast::Value>> {
    let mut out: Vec<Option<&ast::Value>> = vec![None; params.len()];
    let mut next = 0;
    for a in &call.args {
        match a {
            ast::Arg::Positional(v) => {
                if next < params.len() {
                    out[next] = Some(v);
                    next += 1;
                } else {
                    cx.err(E::Arity {
                        span: v.span,
                        kind: what.into(),
                        expected: format!("{} arguments ({})", params.len(), params.join(", ")),
                        found: "one too many".into(),
                        help: format!("write `{}({})`", path_text(&call.callee), params.join(", ")),
                    });
                }
            }
            ast::Arg::Named(k, v) => match params.iter().position(|p| *p == k.name) {
                Some(i) => out[i] = Some(v),
                None => {
                    let help =
                        suggest::help_for_unknown("argument", &k.name, params.iter().copied());
                    cx.err(E::UnknownProperty {
                        span: k.span,
                        key: k.name.clone(),
                        item: what.into(),
                        help,
                    });
                }
            },
        }
    }
    for (i, p) in params.iter().enumerate() {
        if out[i].is_none() {
            cx.err(E::MissingArgument {
                span: call.span,
                kind: what.into(),
                what: format!("`{p}`"),
                help: format!("write `{}({})`", path_text(&call.callee), params.join(", ")),
            });
        }
    }
    out
}

/// Catalogue text fields that document an item without affecting planning.
pub(super) fn describe_only(cx: &mut Cx, p: &mut Props) {
    for key in ["part_no", "model"] {
        if let Some(v) = p.get(key) {
            cx.string(v);
        }
    }
}
