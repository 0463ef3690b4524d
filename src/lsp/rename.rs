//! Rename: the places a declared name is written, or why it must not be renamed.
//!
//! **Decision: a rename that would change meaning is refused, and the check is the
//! resolver's own.** A new name must be a name (not a keyword: `syntax::KEYWORDS`),
//! else -32602 Invalid params. Then two checks, each answering -32803 RequestFailed
//! (LSP 3.17: the request was valid, the server declines) with the declaration in the
//! way named and placed:
//! 1. a declaration of that name in the same scope — the same part for a part's names,
//!    the same machine's rack for a rack label, the same file for an item;
//! 2. the spec re-checked with the edits applied: a rename is refused where it would
//!    add an error (a duplicate, an ambiguity between imports) or change how many uses
//!    bind to the renamed declaration (it would capture an imported name or a name
//!    that did not resolve). The scopes of the first check are only a faster, clearer
//!    message for the common case; the second holds wherever the scoping rules go.

use super::rpc::{Code, Failure};
use super::symbols::{self, Decl, DeclKind};
use super::Overlay;
use crate::source::{FileId, Span, World};
use crate::Checked;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;

/// Every place to write `new_name` to rename the name at `offset` of `file`: the
/// declaration first, then its uses.
pub(crate) fn rename(
    checked: &Checked,
    world: &Overlay,
    file: FileId,
    offset: usize,
    new_name: &str,
) -> Result<Vec<Span>, Failure> {
    let bad = |why: String| (Code::InvalidParams, why);
    if !symbols::is_name(new_name) {
        return Err(bad(format!(
            "`{new_name}` is not a name: a letter or `_`, then letters, digits and `_`, and not a keyword"
        )));
    }
    let Some((_, decl)) = symbols::target(checked, file, offset) else {
        return Err(bad("no name here to rename".into()));
    };
    if checked.sources.get(decl.file).path.is_none() {
        return Err(bad("a standard-library name cannot be renamed".into()));
    }
    let spans = symbols::references(checked, decl);
    if checked.sources.slice(decl) == new_name {
        return Ok(spans);
    }
    let refused = |why: String| (Code::RequestFailed, why);
    let all = symbols::decls(checked);
    if let Some(d) = same_scope(&all, decl, new_name) {
        return Err(refused(format!(
            "`{new_name}` is already declared in this scope: {}",
            describe(checked, d)
        )));
    }
    if let Some(why) = changes_meaning(checked, world, decl, &spans, new_name) {
        return Err(refused(why));
    }
    Ok(spans)
}

/// A declaration named `name` in the scope of the declaration `decl`.
fn same_scope<'a>(all: &'a [Decl<'a>], decl: Span, name: &str) -> Option<&'a Decl<'a>> {
    let this = all.iter().find(|d| d.name.span == decl)?;
    let part = |d: &Decl| d.part.map(|p| p.name.span);
    // For a rack label, the machine whose rack holds it.
    let machine = |d: &Decl| {
        all.iter()
            .find(|m| m.kind == DeclKind::Block(crate::syntax::ast::BlockKind::Cmm))
            .filter(|m| symbols::within(d.full, m.full))
            .map(|m| m.full)
    };
    all.iter().filter(|d| d.name.name == name).find(|d| {
        if this.part.is_some() {
            part(d) == part(this)
        } else if this.kind == DeclKind::Label {
            d.kind == DeclKind::Label && machine(d) == machine(this)
        } else {
            d.is_item() && d.name.span.file == decl.file
        }
    })
}

/// `feature top` at `main.insp:4:13`.
fn describe(checked: &Checked, d: &Decl) -> String {
    format!(
        "{} `{}` at {}",
        d.kind.keyword(),
        d.name.name,
        place(checked, d.name.span)
    )
}

fn place(checked: &Checked, span: Span) -> String {
    let f = checked.sources.get(span.file);
    let (line, col) = f.line_col(span.start as usize);
    format!("{}:{line}:{col}", f.name)
}

/// Why the spec would mean something else with `spans` renamed to `new_name`, if it
/// would: more errors, or another number of uses bound to the declaration.
fn changes_meaning(
    checked: &Checked,
    world: &Overlay,
    decl: Span,
    spans: &[Span],
    new_name: &str,
) -> Option<String> {
    let (after_world, new_decl) = renamed(checked, world, decl, spans, new_name)?;
    let roots: Vec<PathBuf> = checked
        .roots
        .iter()
        .filter_map(|&f| checked.sources.get(f).path.clone())
        .collect();
    let after = crate::check(&after_world, &roots);
    let errors = |c: &Checked| {
        c.diagnostics
            .iter()
            .filter(|d| d.severity() == miette::Severity::Error)
            .count()
    };
    let new_file = after.sources.find_path(&new_decl.0)?;
    let new_decl = Span::new(new_file, new_decl.1, new_decl.1 + new_name.len());
    let uses_after = symbols::references(&after, new_decl).len();
    if errors(&after) <= errors(checked) && uses_after == spans.len() {
        return None;
    }
    // What the new name stands for now, where it is used.
    let existing = checked
        .model
        .index
        .names
        .iter()
        .find(|u| checked.sources.slice(u.used) == new_name && u.decl != decl)
        .map(|u| {
            symbols::decls(checked)
                .iter()
                .find(|d| d.name.span == u.decl)
                .map_or_else(|| place(checked, u.decl), |d| describe(checked, d))
        });
    Some(match existing {
        Some(d) => format!("`{new_name}` already names {d}; renaming would change what it refers to"),
        None => format!(
            "renaming to `{new_name}` would change the spec's meaning: {} errors after it, {} before, {uses_after} uses of the name after it, {} before",
            errors(&after),
            errors(checked),
            spans.len()
        ),
    })
}

/// The world with the renaming applied, and the renamed declaration's file and new
/// start there.
fn renamed(
    checked: &Checked,
    world: &Overlay,
    decl: Span,
    spans: &[Span],
    new_name: &str,
) -> Option<(Overlay, (PathBuf, usize))> {
    let mut by_file: BTreeMap<FileId, Vec<Span>> = BTreeMap::new();
    for s in spans {
        by_file.entry(s.file).or_default().push(*s);
    }
    let mut docs = (*world.docs).clone();
    for (file, mut here) in by_file {
        let f = checked.sources.get(file);
        here.sort_by_key(|s| std::cmp::Reverse(s.start));
        here.dedup();
        let mut text = f.text.clone();
        for s in here {
            text.replace_range(s.range(), new_name);
        }
        docs.insert(world.canonical(f.path.as_ref()?), text);
    }
    // Each rename before the declaration moves it by the difference in length.
    let before = spans
        .iter()
        .filter(|s| s.file == decl.file && s.start < decl.start)
        .count();
    let old_len = decl.range().len();
    let start = decl.start as usize - before * old_len + before * new_name.len();
    let path = checked.sources.get(decl.file).path.clone()?;
    let overlay = Overlay {
        docs: Arc::new(docs),
        work: world.work,
    };
    Some((overlay, (world.canonical(&path), start)))
}
