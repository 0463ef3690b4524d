//! Constraint hierarchies (Spitz ch. 3.4): levels, groups and the order the solver needs.
//!
//! **Decision: hierarchy order.** The solver fixes setups, then probes, then
//! orientations (Spitz 3.5), so a hierarchy that ranks a `same_probe` level above a
//! `same_setup` level (or `same_orient` above either) is an error
//! (`insp::resolve::hierarchy_order`), never silently reordered. `(T, *, *)` is
//! accepted as `(T, *)`, and `same_orien` as `same_orient`.

use super::errors::ResolveError as E;
use super::props::Cx;
use crate::diag::suggest;
use crate::model::level_text;
use crate::model::{Group, Hierarchy, Level, SameVar};
use crate::syntax::ast;

pub(super) fn lower(cx: &mut Cx, h: &ast::Hierarchy) -> Hierarchy {
    let mut levels: Vec<Level> = Vec::new();
    let mut saw_required = false;
    for (k, l) in h.levels.iter().enumerate() {
        match l {
            ast::Level::Required(c, span) => {
                if c.name != "approachability" {
                    let help = suggest::help_for_unknown(
                        "required constraint",
                        &c.name,
                        ["approachability"],
                    );
                    cx.err(E::UnknownName {
                        span: c.span,
                        what: "required constraint".into(),
                        name: c.name.clone(),
                        help,
                    });
                } else if k != 0 || saw_required {
                    cx.err(E::HierarchyOrder {
                        span: *span,
                        level: "required approachability".into(),
                        above: "the soft levels".into(),
                        help: "the required level comes first, once".into(),
                    });
                }
                saw_required = true;
            }
            ast::Level::Same {
                constraint,
                group,
                span,
            } => {
                let var = match constraint.name.as_str() {
                    "same_setup" => SameVar::Setup,
                    "same_probe" => SameVar::Probe,
                    // Spitz spells it both ways.
                    "same_orient" | "same_orien" => SameVar::Orient,
                    other => {
                        let help = suggest::help_for_unknown(
                            "constraint",
                            other,
                            ["same_setup", "same_probe", "same_orient"],
                        );
                        cx.err(E::UnknownName {
                            span: constraint.span,
                            what: "constraint".into(),
                            name: other.into(),
                            help,
                        });
                        continue;
                    }
                };
                let text: Vec<&str> = group.iter().map(|g| g.name.as_str()).collect();
                let grp = match text.as_slice() {
                    ["T", "F", "*"] | ["T", "F"] => Group::TolFeature,
                    ["T", "*"] | ["T", "*", "*"] => Group::Tol,
                    ["*", "*"] | ["*", "*", "*"] | ["*"] => Group::All,
                    _ => {
                        let gspan = group[0].span.join(group[group.len() - 1].span);
                        cx.err(E::UnknownGroup {
                            span: gspan,
                            group: text.join(", "),
                        });
                        continue;
                    }
                };
                if let Some(first) = levels.iter().find(|o| o.var == var && o.group == grp) {
                    cx.err(E::DuplicateLevel {
                        span: *span,
                        first: first.span,
                        level: level_text(var, grp),
                    });
                    continue;
                }
                // The solver fixes setups, then probes, then orientations: a level on a
                // later variable may not outrank one on an earlier variable.
                if let Some(above) = levels.iter().find(|o| o.var > var) {
                    cx.err(E::HierarchyOrder {
                        span: *span,
                        level: level_text(above.var, above.group),
                        above: level_text(var, grp),
                        help: "the solver fixes setups, then probes, then orientations: rank every same_setup level above every same_probe level, and same_probe above same_orient".into(),
                    });
                    continue;
                }
                levels.push(Level {
                    var,
                    group: grp,
                    span: *span,
                });
            }
        }
    }
    if !saw_required {
        cx.err(E::HierarchyRequired {
            span: h.name.span,
            name: h.name.name.clone(),
        });
    }
    Hierarchy {
        name: h.name.name.clone(),
        levels,
        span: h.name.span,
    }
}
