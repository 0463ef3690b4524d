//! Datums: a datum's declaration (`datum A = feature`), references to datums in
//! tolerances and frames (`A`, `B(mmc)`), material modifiers, and the rule that a
//! reference frame names each datum once.
//!
//! **Decision:** datums are capital letters other than I, O and Q, as ASME Y14.5 names
//! them, or a common datum's letters joined by `_` (`E_F_G`; a warning otherwise). A datum on a face expression rather than a named feature
//! gets a feature of its own.

use super::errors::ResolveError as E;
use super::faces::face_expr;
use super::props::{path_text, Cx};
use super::scope::{Local, PartCx};
use crate::diag::suggest;
use crate::model::*;
use crate::source::Span;
use crate::syntax::ast::{self, ValueKind};

pub(super) fn datum(
    cx: &mut Cx,
    pc: &mut PartCx,
    name: &ast::Ident,
    expr: Option<&ast::FaceExpr>,
    span: Span,
    is_mesh: bool,
) {
    // A datum letter (`A`, … `AA`), or a common datum's letters joined by `_`
    // (`E_F_G` for ASME Y14.5's E-F-G, established by its features together).
    let letters_ok = name.name.split('_').all(|part| {
        !part.is_empty()
            && part.len() <= 2
            && part
                .chars()
                .all(|c| c.is_ascii_uppercase() && !matches!(c, 'I' | 'O' | 'Q'))
    });
    if !letters_ok {
        cx.err(E::DatumLetter {
            span: name.span,
            name: name.name.clone(),
        });
    }
    let Some(expr) = expr else {
        cx.err(E::MissingArgument {
            span,
            kind: format!("datum `{}`", name.name),
            what: "a datum feature".into(),
            help: format!("write `datum {} = top`", name.name),
        });
        return;
    };
    // A single name of a feature is that feature; anything else becomes a feature of its own.
    let single = match expr.terms.as_slice() {
        [ast::FaceTerm::Path(p)] if p.segs.len() == 1 => match pc.names.get(&p.head().name) {
            Some(&(Local::Feature(i), decl)) if i < pc.lowered_features => {
                cx.bind(p.head().span, decl);
                Some(FeatureId(i))
            }
            _ => None,
        },
        _ => None,
    };
    let feature = match single {
        Some(f) => f,
        None => {
            let faces = face_expr(cx, pc, expr, is_mesh);
            if faces.is_empty() {
                return;
            }
            pc.part.features.push(Feature {
                name: name.name.clone(),
                faces,
                declared: Declared::Feature,
                span: name.span,
            });
            FeatureId(pc.part.features.len() - 1)
        }
    };
    pc.part.datums.push(Datum {
        name: name.name.clone(),
        feature,
        span: name.span,
    });
}

/// A datum reference `A` or `A(MMC)`; the span is for duplicate reports.
pub(super) fn datum_ref(cx: &mut Cx, pc: &PartCx, v: &ast::Value) -> Option<(DatumRef, Span)> {
    let (path, modifier) = match &v.kind {
        ValueKind::Path(p) => (p, None),
        ValueKind::Call(c) => {
            let m = match c.args.as_slice() {
                [ast::Arg::Positional(a)] => cx.name(a).and_then(|i| material(cx, i)),
                _ => {
                    cx.mismatch(v, "a datum with one modifier, e.g. `B(MMC)`", "");
                    None
                }
            };
            (&c.callee, Some(m?))
        }
        _ => {
            cx.mismatch(v, "a datum", "");
            return None;
        }
    };
    let head = path.head();
    match pc.local(cx, head) {
        Some(Local::Datum(i)) if path.segs.len() == 1 => {
            if i >= pc.part.datums.len() {
                return None; // the datum itself failed to resolve and was reported
            }
            Some((
                DatumRef {
                    datum: DatumId(i),
                    modifier,
                },
                path.span,
            ))
        }
        Some(other) => {
            cx.err(E::WrongKind {
                span: path.span,
                name: path_text(path),
                expected: "a datum".into(),
                found: other.word(&pc.part),
                help: "declare it with `datum A = feature` first".into(),
            });
            None
        }
        None => {
            let datums = pc
                .names
                .iter()
                .filter(|(_, (l, _))| matches!(l, Local::Datum(_)))
                .map(|(n, _)| n.as_str());
            let help = suggest::help_for_unknown("datum", &head.name, datums);
            cx.err(E::UnknownName {
                span: path.span,
                what: "datum".into(),
                name: path_text(path),
                help,
            });
            None
        }
    }
}

pub(super) fn material(cx: &mut Cx, i: &ast::Ident) -> Option<Material> {
    match i.name.as_str() {
        "MMC" => Some(Material::Mmc),
        "LMC" => Some(Material::Lmc),
        "RFS" => Some(Material::Rfs),
        other => {
            let help = suggest::help_for_unknown("modifier", other, ["MMC", "LMC", "RFS"]);
            cx.err(E::UnknownName {
                span: i.span,
                what: "material modifier".into(),
                name: other.into(),
                help,
            });
            None
        }
    }
}

pub(super) fn check_unique_datums(cx: &mut Cx, part: &Part, refs: &[(DatumRef, Span)]) {
    for (k, (r, span)) in refs.iter().enumerate() {
        if refs[..k].iter().any(|(o, _)| o.datum == r.datum) {
            cx.err(E::DuplicateDatum {
                span: *span,
                datum: part.datums[r.datum.0].name.clone(),
            });
        }
    }
}
