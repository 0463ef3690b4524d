//! Face expressions inside a part: roles of the stock and operations (`stock.top`,
//! `slot.walls`), mesh groups and segments, selectors (`select(plane, normal +z)`), and
//! their unions and differences, lowered to [`FaceRef`]s the geometry stage resolves.

use super::errors::ResolveError as E;
use super::props::{path_text, Cx, Dim};
use super::scope::{Local, PartCx};
use crate::diag::suggest;
use crate::model::*;
use crate::source::Span;
use crate::syntax::ast::{self, PathSeg};

/// The face roles of the stock or an operation.
fn roles(part: &Part, source: &FaceSource) -> &'static [Role] {
    match source {
        FaceSource::Stock => match &part.geometry {
            Geometry::Stock(stock) => Role::of_stock(stock),
            Geometry::Mesh { .. } => &[],
        },
        FaceSource::Op(OpId(i), _) => Role::of_op(&part.ops[*i].kind),
    }
}

pub(super) fn face_expr(
    cx: &mut Cx,
    pc: &PartCx,
    e: &ast::FaceExpr,
    is_mesh: bool,
) -> Vec<FaceRef> {
    let mut out: Vec<FaceRef> = Vec::new();
    for t in &e.terms {
        for f in face_term(cx, pc, t, is_mesh) {
            if !out.iter().any(|o| same_face(o, &f)) {
                out.push(f);
            }
        }
    }
    out
}

fn same_face(a: &FaceRef, b: &FaceRef) -> bool {
    match (a, b) {
        (
            FaceRef::Role {
                source: s1,
                role: r1,
                ..
            },
            FaceRef::Role {
                source: s2,
                role: r2,
                ..
            },
        ) => s1 == s2 && r1 == r2,
        (FaceRef::Group(a, _), FaceRef::Group(b, _)) => a == b,
        (FaceRef::Segment(a, _), FaceRef::Segment(b, _)) => a == b,
        (FaceRef::FileFace(k, a, _), FaceRef::FileFace(l, b, _)) => k == l && a == b,
        _ => false,
    }
}

fn face_term(cx: &mut Cx, pc: &PartCx, t: &ast::FaceTerm, is_mesh: bool) -> Vec<FaceRef> {
    let needs_mesh = |cx: &mut Cx, span: Span, what: &str| {
        if !is_mesh {
            cx.err(E::NeedsMesh {
                span,
                what: what.into(),
                help: "on a stock part, name faces by role: `stock.top`, `slot1.walls`".into(),
            });
            false
        } else {
            true
        }
    };
    match t {
        ast::FaceTerm::Group(s) => {
            if needs_mesh(cx, s.span, "`group`") {
                vec![FaceRef::Group(s.value.clone(), s.span)]
            } else {
                vec![]
            }
        }
        ast::FaceTerm::Segment(n, span) => {
            if needs_mesh(cx, *span, "`segment`") {
                vec![FaceRef::Segment(*n, *span)]
            } else {
                vec![]
            }
        }
        ast::FaceTerm::FileFace(kind, n, span) => {
            if needs_mesh(cx, *span, &format!("`{}`", kind.keyword())) {
                vec![FaceRef::FileFace(*kind, u64::from(*n), *span)]
            } else {
                vec![]
            }
        }
        ast::FaceTerm::Select(args, span) => {
            if !needs_mesh(cx, *span, "`select`") {
                return vec![];
            }
            selector(cx, args, *span)
                .map(|s| vec![FaceRef::Select(s, *span)])
                .unwrap_or_default()
        }
        ast::FaceTerm::Path(path) => path_faces(cx, pc, path),
    }
}

/// The faces a path names: a feature's or a datum's, or one role of the stock or of an
/// operation.
fn path_faces(cx: &mut Cx, pc: &PartCx, path: &ast::Path) -> Vec<FaceRef> {
    match path_head(cx, pc, path) {
        PathHead::Faces(faces) => faces,
        PathHead::Owner(source, rest) => role_faces(cx, pc, path, source, rest),
    }
}

/// What the head of a face path stands for.
enum PathHead<'p> {
    /// Faces already: a feature's or a datum's, or none after an error.
    Faces(Vec<FaceRef>),
    /// The stock or an operation (instance), whose face the rest of the path names.
    Owner(FaceSource, &'p [PathSeg]),
}

/// Resolves the first name of a face path (and an operation's `[i]`).
fn path_head<'p>(cx: &mut Cx, pc: &PartCx, path: &'p ast::Path) -> PathHead<'p> {
    let head = path.head();
    let Some(local) = pc.local(cx, head) else {
        unknown_head(cx, pc, head);
        return PathHead::Faces(vec![]);
    };
    match (local, &path.segs[1..]) {
        (Local::Feature(i), []) => {
            if i >= pc.lowered_features {
                cx.err(E::UnknownName {
                    span: head.span,
                    what: "face or feature declared above".into(),
                    name: head.name.clone(),
                    help: format!(
                        "`{}` is declared further down; declare it before it is used",
                        head.name
                    ),
                });
                return PathHead::Faces(vec![]);
            }
            PathHead::Faces(pc.part.features[i].faces.clone())
        }
        (Local::Datum(i), []) if i < pc.part.datums.len() => {
            PathHead::Faces(pc.part.features[pc.part.datums[i].feature.0].faces.clone())
        }
        (Local::Stock, rest) => PathHead::Owner(FaceSource::Stock, rest),
        (Local::Op(i), [PathSeg::Index(n, ispan), rest @ ..]) => {
            match instance(cx, pc, head, i, *n, *ispan) {
                Some(source) => PathHead::Owner(source, rest),
                None => PathHead::Faces(vec![]),
            }
        }
        (Local::Op(i), rest) => PathHead::Owner(FaceSource::Op(OpId(i), None), rest),
        (other, _) => {
            cx.err(E::WrongKind {
                span: path.span,
                name: path_text(path),
                expected: "a face or feature".into(),
                found: other.word(&pc.part),
                help: "name faces and features here".into(),
            });
            PathHead::Faces(vec![])
        }
    }
}

/// Says a path's first name is no face, feature, operation or the stock.
fn unknown_head(cx: &mut Cx, pc: &PartCx, head: &ast::Ident) {
    let candidates: Vec<&str> = pc
        .names
        .iter()
        .filter(|(_, (l, _))| matches!(l, Local::Feature(_) | Local::Op(_) | Local::Stock))
        .map(|(n, _)| n.as_str())
        .collect();
    let help = suggest::help_for_unknown("face or feature", &head.name, candidates);
    cx.err(E::UnknownName {
        span: head.span,
        what: "face or feature".into(),
        name: head.name.clone(),
        help,
    });
}

/// Instance `[n]` of operation `i`: only a pattern has instances, numbered from 0.
fn instance(
    cx: &mut Cx,
    pc: &PartCx,
    head: &ast::Ident,
    i: usize,
    n: u32,
    ispan: Span,
) -> Option<FaceSource> {
    let count = pc.part.ops[i].pattern.as_ref().map(Pattern::count);
    match count {
        None => {
            cx.err(E::TypeMismatch {
                span: ispan,
                expected: "no index".into(),
                found: format!("`[{n}]`"),
                help: format!(
                    "`{}` is not a pattern; only patterned operations have instances",
                    head.name
                ),
            });
            None
        }
        Some(c) if n >= c => {
            cx.err(E::OutOfRange {
                span: ispan,
                what: "instance".into(),
                value: n.to_string(),
                range: format!("`{}` has instances 0 to {}", head.name, c - 1),
                help: "instances are numbered from 0, row by row".into(),
            });
            None
        }
        Some(_) => Some(FaceSource::Op(OpId(i), Some(n))),
    }
}

/// The face `rest` names on the stock or an operation: exactly one of its roles.
fn role_faces(
    cx: &mut Cx,
    pc: &PartCx,
    path: &ast::Path,
    source: FaceSource,
    rest: &[PathSeg],
) -> Vec<FaceRef> {
    let owner = match &source {
        FaceSource::Stock => "the stock".to_string(),
        FaceSource::Op(OpId(i), _) => {
            format!("{} `{}`", pc.part.ops[*i].kind.word(), pc.part.ops[*i].name)
        }
    };
    let known = roles(&pc.part, &source);
    match rest {
        [PathSeg::Name(role)] => {
            let Some(r) = Role::from_name(&role.name).filter(|r| known.contains(r)) else {
                let mut help =
                    suggest::help_for_unknown("face", &role.name, known.iter().map(|r| r.name()));
                if role.name == "bottom"
                    && matches!(&source, FaceSource::Op(OpId(i), _) if matches!(pc.part.ops[*i].kind, OpKind::Hole { depth: Depth::Through, .. }))
                {
                    help = "a through hole has no bottom".into();
                }
                cx.err(E::UnknownFace {
                    span: role.span,
                    owner,
                    role: role.name.clone(),
                    help,
                });
                return vec![];
            };
            vec![FaceRef::Role {
                source,
                role: r,
                span: path.span,
            }]
        }
        _ => {
            let roles = known
                .iter()
                .map(|r| format!("`{}.{r}`", path.head().name))
                .collect::<Vec<_>>()
                .join(", ");
            cx.err(E::TypeMismatch {
                span: path.span,
                expected: "a face".into(),
                found: format!("{owner} as a whole"),
                help: format!("name one of its faces: {roles}"),
            });
            vec![]
        }
    }
}

fn selector(cx: &mut Cx, args: &[ast::Arg], span: Span) -> Option<Selector> {
    let mut s = Selector::default();
    for a in args {
        match a {
            ast::Arg::Positional(v) => match cx.name(v).map(|i| (i.name.clone(), i.span)) {
                Some((n, nspan)) => match SurfaceKind::ALL.iter().find(|k| k.keyword() == n) {
                    Some(k) => s.surface = Some(*k),
                    None => {
                        let help = suggest::help_for_unknown(
                            "surface type",
                            &n,
                            SurfaceKind::ALL.iter().map(|k| k.keyword()),
                        );
                        cx.err(E::UnknownName {
                            span: nspan,
                            what: "surface type".into(),
                            name: n,
                            help,
                        });
                    }
                },
                None => return None,
            },
            ast::Arg::Named(k, v) => match k.name.as_str() {
                "normal" => s.normal = Some(cx.direction(v)?),
                "axis" => s.axis = Some(cx.direction(v)?),
                "radius" => s.radius = Some(cx.positive(v, Dim::Length, "radius")?),
                "nearest" => s.nearest = Some(cx.lengths::<3>(v)?),
                "highest" | "lowest" => {
                    let axis = cx.name(v)?;
                    let Some(ai) = ["x", "y", "z"].iter().position(|a| *a == axis.name) else {
                        cx.mismatch(v, "an axis `x`, `y` or `z`", "");
                        return None;
                    };
                    s.extreme = Some((ai as u8, k.name == "highest"));
                }
                other => {
                    let help = suggest::help_for_unknown(
                        "criterion",
                        other,
                        ["normal", "axis", "radius", "highest", "lowest", "nearest"],
                    );
                    cx.err(E::UnknownProperty {
                        span: k.span,
                        key: other.into(),
                        item: "`select`".into(),
                        help,
                    });
                }
            },
        }
    }
    if s == Selector::default() {
        cx.err(E::MissingArgument {
            span,
            kind: "`select`".into(),
            what: "a criterion".into(),
            help: "e.g. `select(plane, normal +z, highest z)`".into(),
        });
        return None;
    }
    Some(s)
}
