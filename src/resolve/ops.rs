//! Machining operations inside a part (`cut hole`, `cut slot`, `cut pocket`, `cut step`,
//! `add boss`) and their patterns, lowered to [`Op`]s the geometry stage booleans.

use super::errors::ResolveError as E;
use super::props::{call_args, describe, path_text, Cx, Dim, Props};
use super::scope::PartCx;
use crate::diag::suggest;
use crate::model::*;
use crate::syntax::ast::{self, PartStmt, ValueKind};

/// Lowers every `cut` and `add` of a part, in order: one [`Op`] per statement, a
/// placeholder where one fails, so operation indices stay aligned with declarations.
pub(super) fn lower(cx: &mut Cx, pc: &mut PartCx, is_mesh: bool) {
    let mut instances: u64 = 0;
    for s in pc.stmts {
        let PartStmt::Cut {
            add,
            kind,
            name,
            props,
            span,
        } = s
        else {
            continue;
        };
        if is_mesh {
            cx.err(E::NeedsStock {
                span: *span,
                what: format!("`{}` {}", if *add { "add" } else { "cut" }, kind.name),
            });
        }
        let op = operation(cx, *add, kind, name, props)
            .and_then(|o| within_instance_limit(cx, o, &mut instances));
        pc.part
            .ops
            .push(op.unwrap_or_else(|| placeholder(*add, name)));
    }
}

/// The part's operations together stay within the instance limit: every instance is
/// booleaned, sampled and measured. `instances` counts those accepted so far.
fn within_instance_limit(cx: &mut Cx, o: Op, instances: &mut u64) -> Option<Op> {
    let n = u64::from(o.pattern.as_ref().map_or(1, Pattern::count));
    if *instances + n > u64::from(MAX_INSTANCES) {
        cx.err(E::OutOfRange {
            span: o.span,
            what: format!("`{}`", o.name),
            value: format!("brings the part to {} instances", *instances + n),
            range: format!("a part has at most {MAX_INSTANCES}"),
            help: "a CMM program measures each instance; check the pattern counts".into(),
        });
        return None;
    }
    *instances += n;
    Some(o)
}

/// What stands in for an operation that failed (a unit boss), keeping the indices of
/// the operations after it.
fn placeholder(add: bool, name: &ast::Ident) -> Op {
    Op {
        name: name.name.clone(),
        action: if add { Action::Add } else { Action::Cut },
        kind: OpKind::Boss {
            at: [0.0; 3],
            axis: [0.0, 0.0, 1.0],
            diameter: 1.0,
            height: 1.0,
        },
        pattern: None,
        span: name.span,
    }
}

/// One `cut kind name { … }` or `add boss name { … }`; None after saying why.
fn operation(
    cx: &mut Cx,
    add: bool,
    kind: &ast::Ident,
    name: &ast::Ident,
    props: &[ast::Prop],
) -> Option<Op> {
    const KINDS: [&str; 5] = ["hole", "slot", "pocket", "step", "boss"];
    if !KINDS.contains(&kind.name.as_str()) {
        let help = suggest::help_for_unknown("machining feature", &kind.name, KINDS);
        cx.err(E::UnknownName {
            span: kind.span,
            what: "machining feature".into(),
            name: kind.name.clone(),
            help,
        });
        return None;
    }
    check_action(cx, add, kind, name);
    let mut p = Props::new(
        cx,
        format!("{} `{}`", kind.name, name.name),
        name.span,
        props,
    );
    let op = match kind.name.as_str() {
        "hole" => hole(cx, &mut p, name)?,
        "slot" | "step" => slot_or_step(cx, &mut p, kind)?,
        "pocket" => pocket(cx, &mut p)?,
        _ => boss(cx, &mut p)?,
    };
    let pattern = p.get("pattern").and_then(|v| pattern_within_limit(cx, v));
    p.finish(cx);
    Some(Op {
        name: name.name.clone(),
        action: if add { Action::Add } else { Action::Cut },
        kind: op,
        pattern,
        span: name.span,
    })
}

/// A boss is added and the other kinds are cut: says so where the spec has it the other
/// way round.
fn check_action(cx: &mut Cx, add: bool, kind: &ast::Ident, name: &ast::Ident) {
    let adds = kind.name == "boss";
    if add != adds {
        let (verb, fix) = if add { ("add", "cut") } else { ("cut", "add") };
        cx.err(E::WrongOperation {
            span: kind.span,
            kind: format!("a {}", kind.name),
            op: if adds {
                "adds material, it cannot be written".into()
            } else {
                "removes material, it cannot be written".into()
            },
            verb: verb.into(),
            fix: format!("{fix} {}", kind.name),
            help: format!("write `{fix} {} {} {{ … }}`", kind.name, name.name),
        });
    }
}

/// A direction property: `default` where it is left out, or required without one.
fn direction(cx: &mut Cx, p: &mut Props, key: &'static str, default: Option<Vec3>) -> Option<Vec3> {
    match p.get(key) {
        Some(v) => cx.direction(v),
        None if default.is_some() => default,
        None => p.req(cx, key, "+x").and_then(|v| cx.direction(v)),
    }
}

/// The required `at` point.
fn at_point(cx: &mut Cx, p: &mut Props) -> Option<Vec3> {
    p.req(cx, "at", "(10, 10, 40)")
        .and_then(|v| cx.lengths::<3>(v))
}

/// A required positive length.
fn positive_length(cx: &mut Cx, p: &mut Props, key: &'static str) -> Option<f64> {
    p.req(cx, key, "10")
        .and_then(|v| cx.positive(v, Dim::Length, key))
}

/// `cut hole { at (…) or radial +x, axis, diameter, depth 20 mm or depth through }`; the
/// axis of a radial hole points back along its direction unless given.
fn hole(cx: &mut Cx, p: &mut Props, name: &ast::Ident) -> Option<OpKind> {
    let radial = p.get("radial").and_then(|v| cx.direction(v));
    let at = match (p.get("at"), radial) {
        (Some(v), None) => cx.lengths::<3>(v).map(Placement::At),
        (None, Some(d)) => Some(Placement::Radial(d)),
        (Some(v), Some(_)) => {
            cx.err(E::DuplicateGeometry {
                span: v.span,
                first: p.get("radial").map_or(v.span, |r| r.span),
                part: name.name.clone(),
            });
            None
        }
        (None, None) => p.req(cx, "at", "(10, 10, 40)").and(None),
    };
    let axis = match radial {
        Some(d) => direction(cx, p, "axis", Some([-d[0], -d[1], -d[2]])),
        None => direction(cx, p, "axis", None),
    };
    let diameter = positive_length(cx, p, "diameter");
    let depth = match p.req(cx, "depth", "20 mm or `depth through`") {
        Some(v) if matches!(&v.kind, ValueKind::Path(pp) if pp.as_ident().is_some_and(|i| i.name == "through")) => {
            Some(Depth::Through)
        }
        Some(v) => cx.positive(v, Dim::Length, "depth").map(Depth::Blind),
        None => None,
    };
    Some(OpKind::Hole {
        at: at?,
        axis: axis?,
        diameter: diameter?,
        depth: depth?,
    })
}

/// `cut slot { at, along, into, width, depth, length }` or `cut step { … }` (no length);
/// None, before the pattern is read, where a slot's length does not read.
fn slot_or_step(cx: &mut Cx, p: &mut Props, kind: &ast::Ident) -> Option<OpKind> {
    let at = at_point(cx, p);
    let along = direction(cx, p, "along", None);
    let into = direction(cx, p, "into", Some([0.0, 0.0, -1.0]));
    let width = positive_length(cx, p, "width");
    let depth = positive_length(cx, p, "depth");
    perpendicular(cx, p, along, into);
    if kind.name != "slot" {
        return Some(OpKind::Step {
            at: at?,
            along: along?,
            into: into?,
            width: width?,
            depth: depth?,
        });
    }
    let length = match p.get("length") {
        Some(v) => Some(cx.positive(v, Dim::Length, "length")?),
        None => None,
    };
    Some(OpKind::Slot {
        at: at?,
        along: along?,
        into: into?,
        width: width?,
        depth: depth?,
        length,
    })
}

/// `cut pocket { at, along, into, size (l, w), depth, corner_radius }`.
fn pocket(cx: &mut Cx, p: &mut Props) -> Option<OpKind> {
    let at = at_point(cx, p);
    let along = direction(cx, p, "along", Some([1.0, 0.0, 0.0]));
    let into = direction(cx, p, "into", Some([0.0, 0.0, -1.0]));
    perpendicular(cx, p, along, into);
    let size = p.req(cx, "size", "(40, 20)").and_then(|v| {
        let s = cx.lengths::<2>(v)?;
        if s.iter().any(|x| *x <= 0.0) {
            cx.err(E::NonPositive {
                span: v.span,
                what: "`size`".into(),
                value: describe(v),
                help: "a pocket's length and width are positive".into(),
            });
            return None;
        }
        Some(s)
    });
    let depth = positive_length(cx, p, "depth");
    let corner_radius = match p.get("corner_radius") {
        Some(v) => cx.length(v).and_then(|x| {
            if x < 0.0 {
                cx.err(E::OutOfRange {
                    span: v.span,
                    what: "`corner_radius`".into(),
                    value: describe(v),
                    range: "it cannot be negative".into(),
                    help: "a corner radius is 0 (sharp) or more".into(),
                });
                return None;
            }
            Some(x)
        }),
        None => Some(0.0),
    };
    Some(OpKind::Pocket {
        at: at?,
        along: along?,
        into: into?,
        size: size?,
        depth: depth?,
        corner_radius: corner_radius?,
    })
}

/// `add boss { at, axis, diameter, height }`.
fn boss(cx: &mut Cx, p: &mut Props) -> Option<OpKind> {
    let at = at_point(cx, p);
    let axis = direction(cx, p, "axis", Some([0.0, 0.0, 1.0]));
    let diameter = positive_length(cx, p, "diameter");
    let height = positive_length(cx, p, "height");
    Some(OpKind::Boss {
        at: at?,
        axis: axis?,
        diameter: diameter?,
        height: height?,
    })
}

/// An operation's `pattern`, within the instance limit of one pattern.
fn pattern_within_limit(cx: &mut Cx, v: &ast::Value) -> Option<Pattern> {
    let pat = pattern(cx, v)?;
    if pat.count() > MAX_INSTANCES {
        cx.err(E::OutOfRange {
            span: v.span,
            what: "pattern".into(),
            value: format!("of {} instances", pat.count()),
            range: format!("at most {MAX_INSTANCES}"),
            help: "a CMM program measures each instance; split the pattern or check the counts"
                .into(),
        });
        return None;
    }
    Some(pat)
}

/// The most instances one pattern, or all of a part's operations together, may have:
/// the booleans triangulate a face pierced by every instance, which grows faster than
/// linearly (2,000 holes in one face: about 9 s; 10,000: over two minutes).
const MAX_INSTANCES: u32 = 2_000;

fn perpendicular(cx: &mut Cx, p: &mut Props, along: Option<Vec3>, into: Option<Vec3>) {
    if let (Some(a), Some(i)) = (along, into) {
        let dot = a[0] * i[0] + a[1] * i[1] + a[2] * i[2];
        if dot.abs() > 1e-6 {
            let v = p.get("along").or_else(|| p.get("into"));
            if let Some(v) = v {
                cx.err(E::OutOfRange {
                    span: v.span,
                    what: "`along`".into(),
                    value: "direction".into(),
                    range: "it must be perpendicular to `into`".into(),
                    help: "a slot, pocket or step runs across the material it goes into; e.g. `along +y` with `into -z`".into(),
                });
            }
        }
    }
}

fn pattern(cx: &mut Cx, v: &ast::Value) -> Option<Pattern> {
    let ValueKind::Call(call) = &v.kind else {
        cx.mismatch(v, "a pattern", "write `grid(nx, ny, pitch_x, pitch_y)`, `linear(count, (dx, dy, dz))` or `polar(count, axis, (cx, cy, cz))`");
        return None;
    };
    let name = call
        .callee
        .as_ident()
        .map(|i| i.name.as_str())
        .unwrap_or("");
    match name {
        "grid" => {
            let a = call_args(
                cx,
                call,
                &["nx", "ny", "pitch_x", "pitch_y"],
                "a grid pattern",
            );
            let nx = a[0].and_then(|v| cx.count(v, "nx"));
            let ny = a[1].and_then(|v| cx.count(v, "ny"));
            let px = a[2].and_then(|v| cx.positive(v, Dim::Length, "pitch_x"));
            let py = a[3].and_then(|v| cx.positive(v, Dim::Length, "pitch_y"));
            Some(Pattern::Grid {
                nx: nx?,
                ny: ny?,
                pitch: [px?, py?],
            })
        }
        "linear" => {
            let a = call_args(cx, call, &["count", "step"], "a linear pattern");
            let count = a[0].and_then(|v| cx.count(v, "count"));
            let step = a[1].and_then(|v| cx.lengths::<3>(v));
            Some(Pattern::Linear {
                count: count?,
                step: step?,
            })
        }
        "polar" => {
            let a = call_args(cx, call, &["count", "axis", "center"], "a polar pattern");
            let count = a[0].and_then(|v| cx.count(v, "count"));
            let axis = a[1].and_then(|v| cx.direction(v));
            let center = a[2].and_then(|v| cx.lengths::<3>(v));
            Some(Pattern::Polar {
                count: count?,
                axis: axis?,
                center: center?,
            })
        }
        other => {
            let help = suggest::help_for_unknown("pattern", other, ["grid", "linear", "polar"]);
            cx.err(E::UnknownName {
                span: call.callee.span,
                what: "pattern".into(),
                name: path_text(&call.callee),
                help,
            });
            None
        }
    }
}
