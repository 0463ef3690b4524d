//! Errors of the files the command line reads and writes, outside any spec: a program
//! to check, an output to write. They point at no text (the path is the place), so
//! each is filed under a source registered for its path.

use super::FileId;

/// What went wrong with a file the command line reads or writes.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[allow(missing_docs)]
pub enum IoError {
    #[error("cannot read `{path}`: {reason}")]
    #[diagnostic(
        code(insp::io::unreadable),
        help("name a regular file inspc can read; `README.md` lists the size limits")
    )]
    Unreadable {
        file: FileId,
        path: String,
        reason: String,
    },
    #[error("cannot write `{path}`: {reason}; nothing was written")]
    #[diagnostic(
        code(insp::io::unwritable),
        help("check that the folder exists and can be written; every output is written or none")
    )]
    Unwritable {
        file: FileId,
        path: String,
        reason: String,
    },
    #[error("`{path}` exists and is not a regular file ({what}); nothing was written")]
    #[diagnostic(
        code(insp::io::not_a_file),
        help("inspc replaces files only: name a new file or an existing regular one")
    )]
    NotAFile {
        file: FileId,
        path: String,
        what: String,
    },
    #[error("writing `{path}` would overwrite an input of this run; nothing was written")]
    #[diagnostic(
        code(insp::io::overwrites_input),
        help("name another output file (`-o`, `--plan-json` or `output {{ … }}`)")
    )]
    OverwritesInput { file: FileId, path: String },
    #[error("`{path}` is named for two outputs ({first} and {second}); nothing was written")]
    #[diagnostic(
        code(insp::io::same_output),
        help("give each output a file of its own")
    )]
    SameOutput {
        file: FileId,
        path: String,
        first: String,
        second: String,
    },
}
