//! Fixtures beside a CMM: vises, chucks, V-blocks, risers, sine plates and mesh nests, with the
//! sizes that say what each can hold and how high it holds the part.

use super::errors::ResolveError as E;
use super::props::{describe, describe_only, num, Cx, Dim, Props};
use super::Resolver;
use crate::diag::suggest;
use crate::model::*;
use crate::syntax::ast::{self, ValueKind};

pub(super) fn fixture(
    r: &Resolver,
    cx: &mut Cx,
    p: &mut Props,
    name: String,
    span: crate::source::Span,
) -> Fixture {
    let kind_v = p.req(cx, "kind", "vise");
    let word = kind_v
        .and_then(|v| cx.name(v))
        .map(|i| (i.name.clone(), i.span));
    // A mesh fixture's mesh says where it holds the part; the others say how high.
    let height = if word.as_ref().is_some_and(|(w, _)| w == "mesh") {
        0.0
    } else {
        p.req(cx, "height", "100 mm")
            .and_then(|v| cx.positive(v, Dim::Length, "height"))
            .unwrap_or(100.0)
    };
    let kind = match word.as_ref().map(|(w, _)| w.as_str()) {
        Some("vise") => vise(cx, p),
        Some("chuck") => chuck(cx, p),
        Some("vblock") => {
            let diameter = p
                .req(cx, "diameter", "5 mm .. 100 mm")
                .and_then(|v| length_range(cx, v, "diameter"))
                .unwrap_or([1.0, 100.0]);
            FixtureKind::VBlock { diameter }
        }
        Some("risers") => FixtureKind::Risers {
            pads: length_or(cx, p, "pads", "20 mm", 20.0),
        },
        Some("sine_plate") => {
            let tilt = p
                .req(cx, "tilt", "0 deg .. 60 deg")
                .and_then(|v| tilt_range(cx, v))
                .unwrap_or([0.0, 0.0]);
            let plate = p.get("plate").and_then(|v| {
                positive_pair(
                    cx,
                    v,
                    "the plate's size",
                    "give the plate's top as (width, length)",
                )
            });
            FixtureKind::SinePlate { tilt, plate }
        }
        Some("mesh") => mesh_nest(r, cx, p),
        Some(other) => {
            if let Some((_, s)) = &word {
                let help = suggest::help_for_unknown(
                    "fixture kind",
                    other,
                    ["vise", "chuck", "vblock", "risers", "sine_plate", "mesh"],
                );
                cx.err(E::UnknownName {
                    span: *s,
                    what: "fixture kind".into(),
                    name: other.into(),
                    help,
                });
            }
            FixtureKind::SinePlate {
                tilt: [0.0, 0.0],
                plate: None,
            }
        }
        None => FixtureKind::SinePlate {
            tilt: [0.0, 0.0],
            plate: None,
        },
    };
    describe_only(cx, p);
    Fixture {
        name,
        kind,
        height,
        span,
    }
}

/// A required positive length, `default` where it is missing or wrong.
fn length_or(cx: &mut Cx, p: &mut Props, key: &'static str, example: &str, default: f64) -> f64 {
    p.req(cx, key, example)
        .and_then(|v| cx.positive(v, Dim::Length, key))
        .unwrap_or(default)
}

/// `kind vise`: its `opening` and `jaw (width, height)`.
fn vise(cx: &mut Cx, p: &mut Props) -> FixtureKind {
    let opening = length_or(cx, p, "opening", "160 mm", 100.0);
    let jaw = p
        .req(cx, "jaw", "(150 mm, 40 mm)")
        .and_then(|v| positive_pair(cx, v, "the jaw size", "give the jaws' width and height"))
        .unwrap_or([100.0, 30.0]);
    FixtureKind::Vise { opening, jaw }
}

/// Two positive lengths, `(150 mm, 40 mm)`; `what` and `help` word the error otherwise.
fn positive_pair(cx: &mut Cx, v: &ast::Value, what: &str, help: &str) -> Option<[f64; 2]> {
    let pair = cx.lengths::<2>(v)?;
    if pair.iter().any(|x| *x <= 0.0) {
        cx.err(E::NonPositive {
            span: v.span,
            what: what.into(),
            value: describe(v),
            help: help.into(),
        });
        return None;
    }
    Some(pair)
}

/// `kind chuck`: the `diameter` range it grips, its `jaws` and `body`.
fn chuck(cx: &mut Cx, p: &mut Props) -> FixtureKind {
    let diameter = p
        .req(cx, "diameter", "3 mm .. 200 mm")
        .and_then(|v| length_range(cx, v, "diameter"))
        .unwrap_or([1.0, 100.0]);
    let jaws = length_or(cx, p, "jaws", "20 mm", 20.0);
    let body = length_or(cx, p, "body", "200 mm", 200.0);
    FixtureKind::Chuck {
        diameter,
        jaws,
        body,
    }
}

/// `kind mesh`: a nest from a mesh file, its `units` and which way is `up`.
fn mesh_nest(r: &Resolver, cx: &mut Cx, p: &mut Props) -> FixtureKind {
    let file = p
        .req(cx, "mesh", "\"nest.stl\"")
        .and_then(|v| cx.string(v))
        .cloned();
    let unit_mm = p
        .get("units")
        .and_then(|v| cx.name(v).cloned())
        .and_then(|u| super::part::length_unit(cx, &u))
        .unwrap_or(1.0);
    let up = p
        .req(cx, "up", "+z")
        .and_then(|v| cx.direction(v))
        .unwrap_or([0.0, 0.0, 1.0]);
    match file.and_then(|f| super::part::mesh_file(r, cx, &f).map(|path| (path, f.span))) {
        Some((path, span)) => FixtureKind::Mesh {
            path,
            unit_mm,
            up,
            span,
        },
        None => FixtureKind::SinePlate {
            tilt: [0.0, 0.0],
            plate: None,
        },
    }
}

/// A range of positive lengths, `3 mm .. 200 mm`.
fn length_range(cx: &mut Cx, v: &ast::Value, what: &str) -> Option<[f64; 2]> {
    let ValueKind::Range(lo, hi) = &v.kind else {
        cx.mismatch(
            v,
            "a range of lengths",
            &format!("write `{what} 3 mm .. 200 mm`"),
        );
        return None;
    };
    let (lo, hi) = (cx.quantity(lo, Dim::Length), cx.quantity(hi, Dim::Length));
    let (lo, hi) = (lo?, hi?);
    if lo <= 0.0 || lo > hi {
        cx.err(E::OutOfRange {
            span: v.span,
            what: format!("`{what}` range"),
            value: format!("{} mm .. {} mm", num(lo), num(hi)),
            range: "it must be positive and run upwards".into(),
            help: "give the smallest and largest size from the data sheet".into(),
        });
        return None;
    }
    Some([lo, hi])
}

/// A sine plate's tilt range within 0°..90° (`90 deg .. 90 deg`: an angle plate).
fn tilt_range(cx: &mut Cx, v: &ast::Value) -> Option<[f64; 2]> {
    let ValueKind::Range(lo, hi) = &v.kind else {
        cx.mismatch(v, "an angle range", "write `tilt 0 deg .. 60 deg`");
        return None;
    };
    let (lo, hi) = (cx.quantity(lo, Dim::Angle), cx.quantity(hi, Dim::Angle));
    let (lo, hi) = (lo?, hi?);
    if lo < 0.0 || hi > 90.0 || lo > hi {
        cx.err(E::OutOfRange {
            span: v.span,
            what: "`tilt` range".into(),
            value: format!("{}°..{}°", num(lo), num(hi)),
            range: "it must run upwards within 0°..90°".into(),
            help: "a sine plate tilts from flat (0°) to square (90°, an angle plate)".into(),
        });
        return None;
    }
    Some([lo, hi])
}
