//! Stage 3, resolve: parsed modules → [`Model`].
//!
//! Binds every name (items across modules through `use`, faces, features and datums
//! inside a part, probes inside a CMM), checks every property against its item's schema,
//! converts every quantity to millimetres or degrees, and checks the values a metrology
//! engineer can get wrong: non-positive sizes, head ranges and steps, datum rules of each
//! tolerance type, hierarchy order. It keeps going after an error, so one run reports
//! everything it can.
//!
//! **Architecture Invariant:** `resolve` reads no file contents; it only asks the
//! [`World`] whether a mesh file exists. Geometry is evaluated by a later stage.
//!
//! **Decision: plans in imported files are not run.** A file can be imported for its
//! parts and machines without planning them: only the root files' plans are bound.

mod catalogue;
mod datum;
mod errors;
mod faces;
mod fixture;
mod hierarchy;
mod ops;
mod part;
mod plan;
mod props;
mod scope;
mod tolerance;

pub use props::{length_unit_mm, units};
pub use tolerance::{accepts, keywords as tolerance_keywords, Accepts, Datums};

use crate::diag::{suggest, Diagnostics};
use crate::load::{ModuleId, Program};
use crate::model::{Model, NameUse, SourceIndex};
use crate::source::{FileId, SourceMap, World};
use crate::syntax::ast;
use errors::ResolveError as E;
use props::Cx;
use std::collections::BTreeMap;

/// What kind of item a declaration is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Kind {
    Part,
    Cmm,
    Head,
    Probe,
    Stylus,
    Body,
    Extension,
    Hierarchy,
    Sampling,
    Fixture,
    Scanner,
    Plan,
}

impl Kind {
    pub(crate) fn word(self) -> &'static str {
        match self {
            Kind::Part => "a part",
            Kind::Cmm => "a cmm",
            Kind::Head => "a head",
            Kind::Probe => "a probe",
            Kind::Stylus => "a stylus",
            Kind::Body => "a probe body",
            Kind::Extension => "an extension",
            Kind::Hierarchy => "a hierarchy",
            Kind::Sampling => "a sampling",
            Kind::Fixture => "a fixture",
            Kind::Scanner => "a scanner",
            Kind::Plan => "a plan",
        }
    }

    fn noun(self) -> &'static str {
        self.word()
            .trim_start_matches("an ")
            .trim_start_matches("a ")
    }
}

/// Marks a scope entry whose import failed (already reported).
const POISONED: usize = usize::MAX;

/// One top-level declaration.
pub(crate) struct Decl<'a> {
    module: ModuleId,
    file: FileId,
    kind: Kind,
    /// Index among declarations of the same kind = index into the model's vector.
    index: usize,
    name: &'a ast::Ident,
    item: &'a ast::Item,
}

/// The resolver's state.
pub(crate) struct Resolver<'a> {
    program: &'a Program,
    sources: &'a SourceMap,
    world: &'a dyn World,
    decls: Vec<Decl<'a>>,
    /// Per module: name → declaration index.
    scopes: Vec<BTreeMap<String, usize>>,
    /// The names `use` statements bound (see [`SourceIndex::names`]).
    imported: Vec<NameUse>,
}

/// Resolves a loaded program. The entry point of the resolve stage.
pub fn resolve(
    program: &Program,
    sources: &SourceMap,
    world: &dyn World,
    diags: &mut Diagnostics,
) -> Model {
    let mut r = Resolver {
        program,
        sources,
        world,
        decls: Vec::new(),
        scopes: Vec::new(),
        imported: Vec::new(),
    };
    r.declare(diags);
    r.import(diags);
    let mut index = SourceIndex {
        names: std::mem::take(&mut r.imported),
        keys: Vec::new(),
    };
    let mut model = r.lower(diags, &mut index);
    index.names.sort();
    index.names.dedup();
    model.index = index;
    model.default_sampling = r
        .std_item("std::sampling", "spread", Kind::Sampling)
        .map(crate::model::SamplingId);
    model
}

impl<'a> Resolver<'a> {
    /// Numbers every declaration and fills each module's scope with its own items.
    fn declare(&mut self, diags: &mut Diagnostics) {
        let mut counts: BTreeMap<Kind, usize> = BTreeMap::new();
        for (mi, module) in self.program.modules.iter().enumerate() {
            let mut scope: BTreeMap<String, usize> = BTreeMap::new();
            for item in &module.ast.items {
                let (kind, name) = match item {
                    ast::Item::Use(_) => continue,
                    ast::Item::Part(p) => (Kind::Part, &p.name),
                    ast::Item::Hierarchy(h) => (Kind::Hierarchy, &h.name),
                    ast::Item::Plan(p) => {
                        if !module.root {
                            continue;
                        }
                        (Kind::Plan, &p.name)
                    }
                    ast::Item::Block(b) => (
                        match b.kind {
                            ast::BlockKind::Cmm => Kind::Cmm,
                            ast::BlockKind::Head => Kind::Head,
                            ast::BlockKind::Probe => Kind::Probe,
                            ast::BlockKind::Stylus => Kind::Stylus,
                            ast::BlockKind::Body => Kind::Body,
                            ast::BlockKind::Extension => Kind::Extension,
                            ast::BlockKind::Sampling => Kind::Sampling,
                            ast::BlockKind::Fixture => Kind::Fixture,
                            ast::BlockKind::Scanner => Kind::Scanner,
                        },
                        &b.name,
                    ),
                };
                if let Some(&first) = scope.get(&name.name) {
                    diags.push(E::DuplicateName {
                        span: name.span,
                        first: Some(self.decls[first].name.span),
                        name: name.name.clone(),
                        help: "rename one of them".into(),
                    });
                    continue;
                }
                let count = counts.entry(kind).or_default();
                scope.insert(name.name.clone(), self.decls.len());
                self.decls.push(Decl {
                    module: ModuleId(mi),
                    file: module.file,
                    kind,
                    index: *count,
                    name,
                    item,
                });
                *count += 1;
            }
            self.scopes.push(scope);
        }
    }

    /// Adds imported names to each module's scope.
    fn import(&mut self, diags: &mut Diagnostics) {
        for (mi, module) in self.program.modules.iter().enumerate() {
            for &(item_index, target) in &module.imports {
                let ast::Item::Use(u) = &module.ast.items[item_index] else {
                    continue;
                };
                let exported: Vec<(String, usize)> = self.own_items(target);
                let wanted: Vec<&ast::Ident> = match (&u.select, &u.source) {
                    (ast::UseSelect::Names(names), _) => names.iter().collect(),
                    (ast::UseSelect::Implicit, ast::UseSource::Module(segs)) => {
                        segs.last().into_iter().collect()
                    }
                    _ => {
                        // A glob: own declarations shadow glob imports silently.
                        for (name, d) in exported {
                            self.scopes[mi].entry(name).or_insert(d);
                        }
                        continue;
                    }
                };
                for ident in wanted {
                    let Some(&(_, d)) = exported.iter().find(|(n, _)| *n == ident.name) else {
                        let module_name = self.module_name(target);
                        let help = match suggest::did_you_mean(
                            &ident.name,
                            exported.iter().map(|(n, _)| n.as_str()),
                        ) {
                            Some(s) => format!(
                                "`{module_name}` has no `{}`; did you mean `{s}`?",
                                ident.name
                            ),
                            None => format!(
                                "`{module_name}` has no `{}`; its {}",
                                ident.name,
                                suggest::help_for_unknown(
                                    "item",
                                    &ident.name,
                                    exported.iter().map(|(n, _)| n.as_str())
                                )
                                .trim_start_matches("known ")
                            ),
                        };
                        diags.push(E::UnknownName {
                            span: ident.span,
                            what: "item".into(),
                            name: ident.name.clone(),
                            help,
                        });
                        // Poison the name so its uses do not report it again.
                        self.scopes[mi]
                            .entry(ident.name.clone())
                            .or_insert(POISONED);
                        continue;
                    };
                    match self.scopes[mi].get(&ident.name) {
                        Some(&existing) if existing != d && existing != POISONED => {
                            let first = self.decls[existing].name.span;
                            diags.push(E::DuplicateName {
                                span: ident.span,
                                first: (first.file == module.file).then_some(first),
                                name: ident.name.clone(),
                                help: "an imported name cannot also be declared or imported from elsewhere; rename one".into(),
                            });
                        }
                        _ => {
                            self.scopes[mi].insert(ident.name.clone(), d);
                            self.imported.push(NameUse {
                                used: ident.span,
                                decl: self.decls[d].name.span,
                            });
                        }
                    }
                }
            }
        }
    }

    fn own_items(&self, module: ModuleId) -> Vec<(String, usize)> {
        self.decls
            .iter()
            .enumerate()
            .filter(|(_, d)| d.module == module)
            .map(|(i, d)| (d.name.name.clone(), i))
            .collect()
    }

    fn module_name(&self, id: ModuleId) -> String {
        let m = &self.program.modules[id.0];
        m.std_name
            .clone()
            .unwrap_or_else(|| self.sources.get(m.file).name.clone())
    }

    /// Looks up a name of an expected kind in a module's scope; `std::x::y` paths reach
    /// the standard library directly.
    pub(crate) fn lookup(
        &self,
        cx: &mut Cx,
        module: ModuleId,
        path: &ast::Path,
        kind: Kind,
    ) -> Option<usize> {
        let names: Vec<&ast::Ident> = path
            .segs
            .iter()
            .filter_map(|s| match s {
                ast::PathSeg::Name(i) => Some(i),
                ast::PathSeg::Index(..) => None,
            })
            .collect();
        let found =
            if names.len() == 1 && self.scopes[module.0].get(&names[0].name) == Some(&POISONED) {
                return None;
            } else if names.len() > 1 && names[0].name == "std" {
                let module_name = names[..names.len() - 1]
                    .iter()
                    .map(|i| i.name.as_str())
                    .collect::<Vec<_>>()
                    .join("::");
                let last = names[names.len() - 1];
                self.program
                    .std_module(&module_name)
                    .and_then(|m| self.own_items(m).into_iter().find(|(n, _)| *n == last.name))
                    .map(|(_, d)| d)
            } else if names.len() == 1 && path.segs.len() == 1 {
                self.scopes[module.0].get(&names[0].name).copied()
            } else {
                None
            };
        let Some(d) = found else {
            let candidates: Vec<&str> = self.scopes[module.0]
                .iter()
                .filter(|(_, &d)| d != POISONED && self.decls[d].kind == kind)
                .map(|(n, _)| n.as_str())
                .collect();
            let name = props::path_text(path);
            let mut help =
                suggest::help_for_unknown(kind.noun(), &name, candidates.iter().copied());
            if candidates.is_empty() {
                help = format!("no {} is declared or imported here; import one with `use std::…::{{{name}}}` or declare it", kind.noun());
            }
            cx.err(E::UnknownName {
                span: path.span,
                what: kind.noun().into(),
                name,
                help,
            });
            return None;
        };
        let decl = &self.decls[d];
        cx.bind(names[names.len() - 1].span, decl.name.span);
        if decl.kind != kind {
            cx.err(E::WrongKind {
                span: path.span,
                name: decl.name.name.clone(),
                expected: kind.word().into(),
                found: decl.kind.word().into(),
                help: format!("name {} here", kind.word()),
            });
            return None;
        }
        Some(decl.index)
    }

    /// The declaration of a standard item, used for plan defaults.
    pub(crate) fn std_item(&self, module: &str, name: &str, kind: Kind) -> Option<usize> {
        let m = self.program.std_module(module)?;
        self.decls
            .iter()
            .find(|d| d.module == m && d.kind == kind && d.name.name == name)
            .map(|d| d.index)
    }

    /// Lowers every declaration, in declaration order per kind.
    fn lower(&self, diags: &mut Diagnostics, index: &mut SourceIndex) -> Model {
        let mut model = Model::default();
        for d in &self.decls {
            let mut cx = Cx {
                diags,
                index,
                file: d.file,
                unit_mm: None,
            };
            match (d.kind, d.item) {
                (Kind::Part, ast::Item::Part(p)) => model.parts.push(part::lower(self, &mut cx, p)),
                (Kind::Hierarchy, ast::Item::Hierarchy(h)) => {
                    model.hierarchies.push(hierarchy::lower(&mut cx, h))
                }
                (Kind::Plan, ast::Item::Plan(_)) => {}
                (_, ast::Item::Block(b)) => {
                    catalogue::lower(self, &mut cx, d.module, d.kind, b, &mut model)
                }
                _ => unreachable!("declaration kinds match their items"),
            }
        }
        // Plans last: their checks read the CMMs, heads and parts they name.
        for d in self.decls.iter().filter(|d| d.kind == Kind::Plan) {
            let ast::Item::Plan(p) = d.item else { continue };
            let mut cx = Cx {
                diags,
                index,
                file: d.file,
                unit_mm: None,
            };
            if let Some(plan) = plan::lower(self, &mut cx, d.module, p, &model) {
                model.plans.push(plan);
            }
        }
        model
    }
}
