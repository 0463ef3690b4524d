//! inspc: a compiler for CMM inspection.
//!
//! `.insp` specs in, DMIS programs out. See `ARCHITECTURE.md` for the pipeline; each
//! stage is a module with one documented entry point:
//! [`syntax::parse`] → [`load::load`] → [`resolve::resolve`] → [`model::Model`].
#![warn(missing_docs)]

pub mod diag;
pub mod geometry;
pub mod load;
pub mod model;
pub mod resolve;
pub mod source;
pub mod syntax;

use std::path::PathBuf;

/// The result of checking a spec: the model (meaningful only without errors), every
/// diagnostic, and the sources they point into.
pub struct Checked {
    /// The resolved model.
    pub model: model::Model,
    /// Every diagnostic, in a stable order.
    pub diagnostics: Vec<diag::Diagnostic>,
    /// The files read.
    pub sources: source::SourceMap,
    /// The files named as roots (that loaded).
    pub roots: Vec<source::FileId>,
}

impl Checked {
    /// Whether any diagnostic is an error.
    pub fn has_errors(&self) -> bool {
        self.diagnostics.iter().any(|d| d.severity() == miette::Severity::Error)
    }

    /// The model as text, showing what the root files declare and use.
    pub fn summary(&self) -> String {
        self.model.summary(&|f| self.roots.contains(&f))
    }
}

/// Runs the front end and then evaluates the geometry of every part the root files
/// declare, resolving each feature's faces; geometry diagnostics join the front end's.
/// A part whose geometry fails (or every part, when the front end failed) gets `None`.
pub fn check_geometry(world: &dyn source::World, roots: &[PathBuf]) -> (Checked, Vec<Option<geometry::PartGeometry>>) {
    let mut checked = check(world, roots);
    let mut out = vec![None; checked.model.parts.len()];
    if checked.has_errors() {
        return (checked, out);
    }
    let mut diags = diag::Diagnostics::new();
    for (k, part) in checked.model.parts.iter().enumerate() {
        if !checked.roots.contains(&part.span.file) {
            continue;
        }
        let Some(g) = geometry::build(part, world, part.span.file, &mut diags) else { continue };
        for f in &part.features {
            for r in &f.faces {
                geometry::resolve_faces(&g, r, part.span.file, &mut diags);
            }
        }
        out[k] = Some(g);
    }
    let mut all = diag::Diagnostics::new();
    for d in std::mem::take(&mut checked.diagnostics) {
        all.push_boxed(d);
    }
    all.extend(diags);
    checked.diagnostics = all.sorted();
    (checked, out)
}

/// Runs the front end (load, parse, resolve) over root files.
pub fn check(world: &dyn source::World, roots: &[PathBuf]) -> Checked {
    let mut sources = source::SourceMap::new();
    let mut diags = diag::Diagnostics::new();
    let program = load::load(world, roots, &mut sources, &mut diags);
    let model = resolve::resolve(&program, &sources, world, &mut diags);
    let roots = program.modules.iter().filter(|m| m.root).map(|m| m.file).collect();
    Checked { model, diagnostics: diags.sorted(), sources, roots }
}
