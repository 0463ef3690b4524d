//! Stage 2, load: root files → every module the spec needs, parsed.
//!
//! Reads the files named on the command line, follows their `use` statements (the
//! embedded standard library for `std::…`, files relative to the importing file for
//! quoted paths), parses each module once and reports import cycles, missing modules and
//! unreadable or non-UTF-8 files.
//!
//! **Architecture Invariant:** every file is read through the [`World`]; modules are
//! numbered in the order they are first reached, so everything downstream is
//! deterministic.

mod stdlib;

pub use stdlib::{std_module_names, STD_MODULES};

use crate::diag::{suggest, Diagnostics};
use crate::source::{FileId, FileKind, SourceMap, Span, World};
use crate::syntax::{self, ast};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Identifies a module of a [`Program`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct ModuleId(pub usize);

/// One parsed file.
#[derive(Debug)]
pub struct Module {
    /// Its file.
    pub file: FileId,
    /// The tree; empty when the file did not parse.
    pub ast: ast::File,
    /// For each `use` item (by index into `ast.items`), the module it imports, if found.
    pub imports: Vec<(usize, ModuleId)>,
    /// `Some("std::heads")` for a standard library module.
    pub std_name: Option<String>,
    /// Whether the file was named on the command line.
    pub root: bool,
}

/// Every module of a run.
#[derive(Debug, Default)]
pub struct Program {
    /// Modules in the order they were first reached.
    pub modules: Vec<Module>,
}

impl Program {
    /// The module of a standard-library name such as `std::hierarchies`, if loaded.
    pub fn std_module(&self, name: &str) -> Option<ModuleId> {
        self.modules
            .iter()
            .position(|m| m.std_name.as_deref() == Some(name))
            .map(ModuleId)
    }
}

/// A problem found while loading.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
pub(crate) enum LoadError {
    /// A file could not be read.
    #[error("cannot read `{path}`: {reason}")]
    #[diagnostic(
        code(insp::load::unreadable),
        help("check the path; relative imports are resolved against the importing file's folder")
    )]
    Unreadable {
        /// The `use` or mesh path that named it, if any.
        #[label("imported here")]
        span: Option<Span>,
        /// The file it is filed under: the importing file, or for a root file the
        /// (empty) source registered under its own name.
        file: FileId,
        /// The path.
        path: String,
        /// The system's reason.
        reason: String,
    },
    /// A file that is not a spec, named where a spec belongs.
    #[error("`{path}` is not an `.insp` spec")]
    #[diagnostic(
        code(insp::load::not_a_spec),
        help("specs and the files they `use` end in `.insp`; meshes are named by `mesh \"…\"` in a part")
    )]
    NotASpec {
        /// The `use` that named it, if any.
        #[label("not a spec")]
        span: Option<Span>,
        /// The file it is filed under (see `Unreadable`).
        file: FileId,
        /// The path.
        path: String,
    },
    /// A file is not UTF-8.
    #[error("`{path}` is not UTF-8 text")]
    #[diagnostic(code(insp::load::not_utf8), help("save the file as UTF-8"))]
    NotUtf8 {
        /// The first bad byte.
        #[label("invalid UTF-8 starts here")]
        span: Span,
        /// The path.
        path: String,
    },
    /// `use` of something that is not a standard module.
    #[error("unknown module `{name}`")]
    #[diagnostic(code(insp::load::unknown_module))]
    UnknownModule {
        /// The module path.
        #[label("no such module")]
        span: Span,
        /// The module path as written.
        name: String,
        /// A suggestion.
        #[help]
        help: String,
    },
    /// `use std::heads` without naming items.
    #[error("`use {name}` imports a module, not items")]
    #[diagnostic(code(insp::load::module_import))]
    ModuleImport {
        /// The statement.
        #[label("names no item")]
        span: Span,
        /// The module.
        name: String,
        /// The remedy.
        #[help]
        help: String,
    },
    /// Files that import each other.
    #[error("import cycle: {cycle}")]
    #[diagnostic(
        code(insp::load::import_cycle),
        help("move what both files need into a third file that imports neither")
    )]
    ImportCycle {
        /// The `use` that closes the cycle.
        #[label("this import closes the cycle")]
        span: Span,
        /// The files in the cycle, joined by arrows.
        cycle: String,
    },
}

impl crate::diag::Located for LoadError {
    fn file(&self) -> FileId {
        match self {
            LoadError::Unreadable { file, .. } | LoadError::NotASpec { file, .. } => *file,
            LoadError::NotUtf8 { span, .. }
            | LoadError::UnknownModule { span, .. }
            | LoadError::ModuleImport { span, .. }
            | LoadError::ImportCycle { span, .. } => span.file,
        }
    }
}

/// Loads the root files and everything they import. The entry point of the load stage.
pub fn load(
    world: &dyn World,
    roots: &[PathBuf],
    sources: &mut SourceMap,
    diags: &mut Diagnostics,
) -> Program {
    let mut l = Loader {
        world,
        sources,
        diags,
        program: Program::default(),
        by_key: HashMap::new(),
        stack: Vec::new(),
    };
    for root in roots {
        l.load_file(root, &root.to_string_lossy(), None, true);
    }
    // The standard library is always there: plans default to its hierarchy and
    // sampling, and any item can be named by its full path `std::module::item`.
    for name in std_module_names() {
        l.load_std(name);
    }
    l.program
}

struct Loader<'a> {
    world: &'a dyn World,
    sources: &'a mut SourceMap,
    diags: &'a mut Diagnostics,
    program: Program,
    /// Canonical path or std name → module.
    by_key: HashMap<String, ModuleId>,
    /// Modules being loaded, innermost last, for cycle detection.
    stack: Vec<ModuleId>,
}

impl Loader<'_> {
    /// Loads a user file; `from` is the `use` that named it and the importing file.
    fn load_file(
        &mut self,
        path: &Path,
        shown: &str,
        from: Option<(FileId, Span)>,
        root: bool,
    ) -> Option<ModuleId> {
        let canonical = self.world.canonical(path);
        let key = canonical.to_string_lossy().into_owned();
        if let Some(&id) = self.by_key.get(&key) {
            self.program.modules[id.0].root |= root;
            return Some(id);
        }
        let shown = shown.to_string();
        // Only specs are read as source (and quoted in messages): a `use` of any other
        // file is refused before it is opened.
        if path.extension().is_none_or(|e| e != "insp") {
            let file = from.map_or_else(
                || {
                    self.sources
                        .add(shown.clone(), Some(canonical.clone()), String::new())
                },
                |f| f.0,
            );
            self.diags.push(LoadError::NotASpec {
                span: from.map(|f| f.1),
                file,
                path: shown,
            });
            return None;
        }
        let bytes = match self.world.read(path, FileKind::Spec) {
            Ok(b) => b,
            Err(e) => {
                let file = from.map_or_else(
                    || {
                        self.sources
                            .add(shown.clone(), Some(canonical.clone()), String::new())
                    },
                    |f| f.0,
                );
                self.diags.push(LoadError::Unreadable {
                    span: from.map(|f| f.1),
                    file,
                    path: shown,
                    reason: e.0,
                });
                return None;
            }
        };
        let (text, bad) = match String::from_utf8(bytes) {
            Ok(t) => (t, None),
            Err(e) => {
                let at = e.utf8_error().valid_up_to();
                (String::from_utf8_lossy(e.as_bytes()).into_owned(), Some(at))
            }
        };
        let file = self.sources.add(shown.clone(), Some(canonical), text);
        if let Some(at) = bad {
            // The lossy text holds U+FFFD (3 bytes) where the bad byte was.
            self.diags.push(LoadError::NotUtf8 {
                span: Span::new(file, at, at + 3),
                path: shown,
            });
            return None;
        }
        Some(self.add_module(key, file, None, root))
    }

    fn load_std(&mut self, name: &str) -> Option<ModuleId> {
        if let Some(&id) = self.by_key.get(name) {
            return Some(id);
        }
        let (_, text) = STD_MODULES.iter().find(|(n, _)| *n == name)?;
        let short = name.trim_start_matches("std::");
        let file = self
            .sources
            .add(format!("<std>/{short}.insp"), None, text.to_string());
        Some(self.add_module(name.to_string(), file, Some(name.to_string()), false))
    }

    fn add_module(
        &mut self,
        key: String,
        file: FileId,
        std_name: Option<String>,
        root: bool,
    ) -> ModuleId {
        let ast = match syntax::parse(file, &self.sources.get(file).text) {
            Ok(ast) => ast,
            Err(e) => {
                self.diags.push(e);
                ast::File::default()
            }
        };
        let id = ModuleId(self.program.modules.len());
        self.program.modules.push(Module {
            file,
            ast,
            imports: Vec::new(),
            std_name,
            root,
        });
        self.by_key.insert(key, id);
        self.stack.push(id);
        let uses: Vec<(usize, ast::Use)> = self.program.modules[id.0]
            .ast
            .items
            .iter()
            .enumerate()
            .filter_map(|(i, it)| match it {
                ast::Item::Use(u) => Some((i, u.clone())),
                _ => None,
            })
            .collect();
        for (index, u) in uses {
            if let Some(target) = self.import(file, &u) {
                if let Some(pos) = self.stack.iter().position(|&m| m == target) {
                    let mut names: Vec<String> = self.stack[pos..]
                        .iter()
                        .map(|m| self.module_name(*m))
                        .collect();
                    names.push(self.module_name(target));
                    self.diags.push(LoadError::ImportCycle {
                        span: u.span,
                        cycle: names.join(" → "),
                    });
                    continue;
                }
                self.program.modules[id.0].imports.push((index, target));
            }
        }
        self.stack.pop();
        id
    }

    fn module_name(&self, id: ModuleId) -> String {
        let m = &self.program.modules[id.0];
        m.std_name
            .clone()
            .unwrap_or_else(|| self.sources.get(m.file).name.clone())
    }

    fn import(&mut self, file: FileId, u: &ast::Use) -> Option<ModuleId> {
        match &u.source {
            ast::UseSource::File(s) => {
                let importer = self.sources.get(file);
                let base = importer.dir().map(Path::to_path_buf).unwrap_or_default();
                let shown_base = Path::new(&importer.name)
                    .parent()
                    .map(Path::to_path_buf)
                    .unwrap_or_default();
                let shown = crate::source::normalize_path(&shown_base.join(&s.value))
                    .to_string_lossy()
                    .into_owned();
                self.load_file(&base.join(&s.value), &shown, Some((file, s.span)), false)
            }
            ast::UseSource::Module(segs) => {
                let names: Vec<&str> = segs.iter().map(|s| s.name.as_str()).collect();
                let module_len = match u.select {
                    ast::UseSelect::Implicit => names.len().saturating_sub(1),
                    _ => names.len(),
                };
                let module = names[..module_len].join("::");
                let span = segs[0].span.join(segs[module_len.max(1) - 1].span);
                if matches!(u.select, ast::UseSelect::Implicit)
                    && STD_MODULES.iter().any(|(n, _)| *n == names.join("::"))
                {
                    let full = names.join("::");
                    self.diags.push(LoadError::ModuleImport {
                        span: u.span,
                        help: format!(
                            "name the items: `use {full}::{{…}}`, or all of them: `use {full}::*`"
                        ),
                        name: full,
                    });
                    return None;
                }
                match self.load_std(&module) {
                    Some(id) => Some(id),
                    None => {
                        let help = match suggest::did_you_mean(&module, std_module_names()) {
                            Some(s) => format!("did you mean `{s}`?"),
                            None => format!(
                                "the standard modules are {}; import a file with `use \"path.insp\"`",
                                std_module_names().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
                            ),
                        };
                        self.diags.push(LoadError::UnknownModule {
                            span,
                            name: module,
                            help,
                        });
                        None
                    }
                }
            }
        }
    }
}
