//! The names inside a part while it is lowered: what each stands for, and the part so
//! far. Shared by the part, datum and tolerance lowering (`part.rs`, `datum.rs`,
//! `tolerance.rs`), none of which imports another that imports it back.

use crate::model::{Declared, Part};
use crate::source::Span;
use crate::syntax::ast::{Ident, PartStmt};
use std::collections::BTreeMap;

/// What a name inside a part stands for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Local {
    Stock,
    Op(usize),
    Feature(usize),
    Datum(usize),
    Frame(usize),
    Tolerance,
}

impl Local {
    /// What the name is, for messages.
    pub(super) fn word(self, part: &Part) -> String {
        match self {
            Local::Stock => "the stock".into(),
            Local::Op(i) => format!("a {}", part.ops[i].kind.word()),
            Local::Feature(i) if part.features[i].declared == Declared::Face => "a face".into(),
            Local::Feature(_) => "a feature".into(),
            Local::Datum(_) => "a datum".into(),
            Local::Frame(_) => "a datum reference frame".into(),
            Local::Tolerance => "a tolerance".into(),
        }
    }
}

/// The part being lowered and its local names.
pub(super) struct PartCx<'p> {
    pub part: Part,
    /// Name → what it is, for every name declared in the part (declared or not yet lowered).
    pub names: BTreeMap<String, (Local, Span)>,
    /// Features lowered so far (features may only use those above them).
    pub lowered_features: usize,
    pub stmts: &'p [PartStmt],
}

impl PartCx<'_> {
    /// What a name inside the part stands for, recording the binding (see
    /// [`crate::model::Model::names`]).
    pub(super) fn local(&self, cx: &mut super::props::Cx, name: &Ident) -> Option<Local> {
        let &(local, decl) = self.names.get(&name.name)?;
        cx.bind(name.span, decl);
        Some(local)
    }
}
