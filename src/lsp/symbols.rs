//! Names in the source: every declaration in the syntax trees, the name under the cursor
//! and what it binds to ([`crate::model::SourceIndex`]), references and renames.

use crate::source::{FileId, Span};
use crate::syntax::ast;
use crate::Checked;

/// What a declaration declares.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum DeclKind {
    /// `cmm`, `probe`, `head`, … items.
    Block(ast::BlockKind),
    /// `part name { … }`
    Part,
    /// `hierarchy name { … }`
    Hierarchy,
    /// `plan name { … }`
    Plan,
    /// `face name = …` inside a part.
    Face,
    /// `feature name = …` inside a part.
    Feature,
    /// `datum A = …` inside a part.
    Datum,
    /// `frame DRF = [A, B]` inside a part.
    Frame,
    /// `tolerance T = …` inside a part.
    Tolerance,
    /// `cut hole h { … }` or `add boss b { … }` inside a part.
    Op,
    /// A label in a cmm's rack: `probes [p1: TP20_D2_L20]`, `fixtures [vise: VISE_150]`.
    Label,
}

impl DeclKind {
    /// The keyword that declares it.
    pub fn keyword(self) -> &'static str {
        match self {
            DeclKind::Block(k) => k.keyword(),
            DeclKind::Part => "part",
            DeclKind::Hierarchy => "hierarchy",
            DeclKind::Plan => "plan",
            DeclKind::Face => "face",
            DeclKind::Feature => "feature",
            DeclKind::Datum => "datum",
            DeclKind::Frame => "frame",
            DeclKind::Tolerance => "tolerance",
            DeclKind::Op => "operation",
            DeclKind::Label => "label",
        }
    }
}

/// One declared name.
#[derive(Debug, Clone)]
pub struct Decl<'a> {
    /// The name as declared.
    pub name: &'a ast::Ident,
    /// What it declares.
    pub kind: DeclKind,
    /// The whole declaration.
    pub full: Span,
    /// For a name inside a part, that part.
    pub part: Option<&'a ast::Part>,
}

impl Decl<'_> {
    /// Whether it is a top-level item (not a name inside a part, not a rack label).
    pub(crate) fn is_item(&self) -> bool {
        self.part.is_none() && self.kind != DeclKind::Label
    }
}

/// Every declaration of every module the run read (stdlib included), in source order.
pub fn decls(checked: &Checked) -> Vec<Decl<'_>> {
    let mut out = Vec::new();
    for m in &checked.program.modules {
        for item in &m.ast.items {
            match item {
                ast::Item::Use(_) => {}
                ast::Item::Block(b) => {
                    out.push(Decl {
                        name: &b.name,
                        kind: DeclKind::Block(b.kind),
                        full: b.span,
                        part: None,
                    });
                    // A cmm's rack and fixtures: each label and the item it names.
                    let lists = b.props.iter().filter(|p| {
                        b.kind == ast::BlockKind::Cmm
                            && matches!(p.key.name.as_str(), "probes" | "fixtures" | "scanners")
                    });
                    for p in lists {
                        let ast::ValueKind::List(entries) = &p.value.kind else {
                            continue;
                        };
                        for e in entries {
                            if let Some(label) = &e.label {
                                out.push(Decl {
                                    name: label,
                                    kind: DeclKind::Label,
                                    full: label.span.join(e.value.span),
                                    part: None,
                                });
                            }
                        }
                    }
                }
                ast::Item::Hierarchy(h) => out.push(Decl {
                    name: &h.name,
                    kind: DeclKind::Hierarchy,
                    full: h.span,
                    part: None,
                }),
                ast::Item::Plan(p) => out.push(Decl {
                    name: &p.name,
                    kind: DeclKind::Plan,
                    full: p.span,
                    part: None,
                }),
                ast::Item::Part(p) => {
                    out.push(Decl {
                        name: &p.name,
                        kind: DeclKind::Part,
                        full: p.span,
                        part: None,
                    });
                    for s in &p.stmts {
                        let (name, kind, full) = match s {
                            ast::PartStmt::Named {
                                what, name, span, ..
                            } => (
                                name,
                                match what {
                                    ast::NamedKind::Face => DeclKind::Face,
                                    ast::NamedKind::Feature => DeclKind::Feature,
                                    ast::NamedKind::Datum => DeclKind::Datum,
                                },
                                *span,
                            ),
                            ast::PartStmt::Frame { name, span, .. } => {
                                (name, DeclKind::Frame, *span)
                            }
                            ast::PartStmt::Tolerance { name, span, .. } => {
                                (name, DeclKind::Tolerance, *span)
                            }
                            ast::PartStmt::Cut { name, span, .. } => (name, DeclKind::Op, *span),
                            _ => continue,
                        };
                        out.push(Decl {
                            name,
                            kind,
                            full,
                            part: Some(p),
                        });
                    }
                }
            }
        }
    }
    out
}

/// Whether byte `offset` of `file` is in `span` (its end included: the cursor just after
/// a name is on it).
pub fn contains(span: Span, file: FileId, offset: usize) -> bool {
    span.file == file && span.start as usize <= offset && offset <= span.end as usize
}

/// Whether span `inner` lies within span `outer` (in the same file).
pub fn within(inner: Span, outer: Span) -> bool {
    inner.file == outer.file && outer.start <= inner.start && inner.end <= outer.end
}

/// The name at `offset` of `file`: where it is written and the declared name it stands
/// for (itself, on a declaration).
pub fn target(checked: &Checked, file: FileId, offset: usize) -> Option<(Span, Span)> {
    let names = &checked.model.index.names;
    if let Some(u) = names.iter().find(|u| contains(u.used, file, offset)) {
        return Some((u.used, u.decl));
    }
    decls(checked)
        .into_iter()
        .find(|d| contains(d.name.span, file, offset))
        .map(|d| (d.name.span, d.name.span))
}

/// Every place the declared name `decl` is written: the declaration first, then its uses
/// in source order.
pub fn references(checked: &Checked, decl: Span) -> Vec<Span> {
    let mut out = vec![decl];
    out.extend(
        checked
            .model
            .index
            .names
            .iter()
            .filter(|u| u.decl == decl && u.used != decl)
            .map(|u| u.used),
    );
    out
}

/// Whether `name` can be written as a name: a letter or `_`, then letters, digits and `_`,
/// and not a word the language reserves.
pub(crate) fn is_name(name: &str) -> bool {
    let mut chars = name.chars();
    let first_ok = chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_');
    first_ok
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
        && !crate::syntax::KEYWORDS.contains(&name)
}

#[cfg(test)]
mod tests {
    #[test]
    fn names_are_names_and_not_keywords() {
        assert!(super::is_name("wide_slot") && !super::is_name("feature"));
        assert!(!super::is_name("2a") && !super::is_name("a-b") && !super::is_name(""));
    }
}
