//! Completion of face references inside a part: the roles after `stock.` or an
//! operation's name (`slot.walls`, `grid[2].wall`), and the faces of the part's mesh or
//! CAD file inside `group "…"`.
//!
//! Roles come from the model (`Role::of_stock`, `Role::of_op`: what the resolver accepts
//! after that dot); group names from the geometry stage's faces, the names
//! `geometry::resolve_faces` matches a `group` against (the mesh's groups, the CAD
//! file's `face_N`). Until the geometry is built there is nothing to offer.

use super::Deep;
use crate::model::{Geometry, Part, Role};
use crate::source::FileId;

/// The part of `model` whose text holds `offset` of `file`: the last one that starts
/// before it (the model may be of an earlier text, whose part ended sooner).
pub(super) fn part_at(model: &crate::model::Model, file: FileId, offset: usize) -> Option<&Part> {
    model
        .parts
        .iter()
        .filter(|p| p.span.file == file && p.span.start as usize <= offset)
        .max_by_key(|p| p.span.start)
}

/// A name to offer and what it is.
pub(super) type Offer = (String, String);

/// After `NAME.` (`head` is the line up to the word being typed): the roles of the stock
/// or of operation NAME of `part`; `None` when the text before the word is no such
/// reference.
pub(super) fn roles_after_dot(part: &Part, head: &str) -> Option<Vec<Offer>> {
    let before = head.strip_suffix('.')?;
    // `grid[2].` names one copy of a patterned operation.
    let before = match before.strip_suffix(']') {
        Some(b) => &b[..b.rfind('[')?],
        None => before,
    };
    let start = before
        .rfind(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .map_or(0, |i| i + 1);
    let name = &before[start..];
    let (roles, what): (&[Role], String) = if name == "stock" {
        match &part.geometry {
            Geometry::Stock(stock) => (Role::of_stock(stock), "a face of the stock".into()),
            Geometry::Mesh { .. } => return Some(Vec::new()),
        }
    } else {
        let op = part.ops.iter().find(|o| o.name == name)?;
        let what = format!("a face of {} {}", op.kind.word(), op.name);
        (Role::of_op(&op.kind), what)
    };
    Some(
        roles
            .iter()
            .map(|r| (r.name().to_string(), what.clone()))
            .collect(),
    )
}

/// Inside `group "` (`head` is the line up to the word being typed): the faces of
/// `part`'s mesh or CAD file, in the geometry stage's order, each name once.
pub(super) fn groups(part: &Part, head: &str, deep: Option<&Deep>) -> Option<Vec<Offer>> {
    let before_quote = head.strip_suffix('"')?;
    if !before_quote.trim_end().ends_with("group") {
        return None;
    }
    let Some(deep) = deep else {
        return Some(Vec::new());
    };
    let k = deep
        .checked
        .model
        .parts
        .iter()
        .position(|p| p.name == part.name)?;
    let data = deep.parts.get(k)?.as_ref()?;
    let mut seen = std::collections::BTreeSet::new();
    let items = data
        .geometry
        .faces
        .iter()
        .filter(|f| f.area > 0.0 && seen.insert(f.name.as_str()))
        .map(|f| {
            let what = format!(
                "{} face, {} mm²",
                f.surface.kind().keyword(),
                crate::model::fmt_num(f.area.round())
            );
            (f.name.clone(), what)
        })
        .collect();
    Some(items)
}
