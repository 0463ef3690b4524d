//! Writing a command's outputs: all of them or none, each only where the user meant.
//!
//! - Every target is checked before anything is written: it may not be an input of the
//!   run (the spec, a file it uses, a mesh), two outputs may not name one file, and an
//!   existing target must be a regular file (`-o /dev/full` is refused, not replaced).
//! - Each output is written to a temporary file created exclusively (`O_CREAT|O_EXCL`,
//!   which never follows a link) with a name of its own in the target's folder; only
//!   when every temporary is complete are they renamed over their targets. A failure
//!   before that removes every temporary and leaves every target as it was.

use inspc::source::io::IoError;
use inspc::source::SourceMap;
use std::path::{Path, PathBuf};

/// One output: where, what, and what it is (for messages).
pub struct Output {
    /// The target path.
    pub path: PathBuf,
    /// Its contents.
    pub bytes: Vec<u8>,
    /// What it is: `the program`, `the plan JSON`, ….
    pub what: &'static str,
}

/// A path made absolute and free of `.`/`..` and of links in its folder, so that two
/// spellings of one file compare equal.
fn resolved(path: &Path) -> PathBuf {
    if let Ok(p) = std::fs::canonicalize(path) {
        return p;
    }
    // A file that does not exist yet: resolve its folder.
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty());
    let dir = dir.map_or_else(|| PathBuf::from("."), Path::to_path_buf);
    let dir = std::fs::canonicalize(&dir).unwrap_or(dir);
    match path.file_name() {
        Some(name) => dir.join(name),
        None => dir,
    }
}

/// `target` as a path relative to the folder `from` (both resolved), with `/`
/// separators so that a spec reads the same on any machine; `target` as given when
/// the two share no root.
pub fn relative_to(target: &Path, from: &Path) -> String {
    let t = resolved(target);
    let f = std::fs::canonicalize(from).unwrap_or_else(|_| resolved(from));
    let tc: Vec<_> = t.components().collect();
    let fc: Vec<_> = f.components().collect();
    let common = tc.iter().zip(&fc).take_while(|(a, b)| a == b).count();
    if common == 0 {
        return target.to_string_lossy().replace('\\', "/");
    }
    let mut parts: Vec<String> = vec!["..".to_string(); fc.len() - common];
    parts.extend(
        tc[common..]
            .iter()
            .map(|c| c.as_os_str().to_string_lossy().into_owned()),
    );
    parts.join("/")
}

/// The error for `path`, filed under a source registered for it.
fn filed(
    sources: &mut SourceMap,
    path: &Path,
    make: impl FnOnce(inspc::source::FileId, String) -> IoError,
) -> IoError {
    let shown = path.display().to_string();
    let file = sources.add(shown.clone(), Some(path.to_path_buf()), String::new());
    make(file, shown)
}

/// Creates the folder `dir` (and its parents) that outputs will be written into: a
/// path that cannot be a folder (a file stands there) is `insp::io::unwritable`.
pub fn folder(dir: &Path, sources: &mut SourceMap) -> Result<(), IoError> {
    std::fs::create_dir_all(dir).map_err(|e| {
        filed(sources, dir, |file, path| IoError::Unwritable {
            file,
            path,
            reason: format!("cannot create the folder: {e}"),
        })
    })
}

/// Checks every target, then writes every output or none. `inputs` are the files the
/// run read.
pub fn commit(
    outputs: &[Output],
    inputs: &[PathBuf],
    sources: &mut SourceMap,
) -> Result<(), IoError> {
    let inputs: Vec<PathBuf> = inputs.iter().map(|p| resolved(p)).collect();
    let mut seen: Vec<(PathBuf, &'static str)> = Vec::new();
    for o in outputs {
        let target = resolved(&o.path);
        if inputs.contains(&target) {
            return Err(filed(sources, &o.path, |file, path| {
                IoError::OverwritesInput { file, path }
            }));
        }
        if let Some((_, first)) = seen.iter().find(|(p, _)| *p == target) {
            let first = first.to_string();
            return Err(filed(sources, &o.path, |file, path| IoError::SameOutput {
                file,
                path,
                first,
                second: o.what.to_string(),
            }));
        }
        seen.push((target, o.what));
        // `symlink_metadata`: a link at the target is replaced by the rename, not
        // followed; anything else that is not a regular file is refused.
        if let Ok(meta) = std::fs::symlink_metadata(&o.path) {
            let t = meta.file_type();
            if !(t.is_file() || t.is_symlink()) {
                let what = if t.is_dir() {
                    "a folder"
                } else {
                    "a device, a pipe or a socket"
                };
                return Err(filed(sources, &o.path, |file, path| IoError::NotAFile {
                    file,
                    path,
                    what: what.into(),
                }));
            }
            if t.is_symlink() && std::fs::metadata(&o.path).is_ok_and(|m| !m.is_file()) {
                return Err(filed(sources, &o.path, |file, path| IoError::NotAFile {
                    file,
                    path,
                    what: "a link to something other than a regular file".into(),
                }));
            }
        }
    }
    let mut temps: Vec<PathBuf> = Vec::new();
    let cleanup = |temps: &[PathBuf]| {
        for t in temps {
            let _ = std::fs::remove_file(t);
        }
    };
    for o in outputs {
        match write_temp(&o.path, &o.bytes) {
            Ok(t) => temps.push(t),
            Err(e) => {
                cleanup(&temps);
                let reason = e.to_string();
                return Err(filed(sources, &o.path, |file, path| IoError::Unwritable {
                    file,
                    path,
                    reason,
                }));
            }
        }
    }
    for (k, (o, t)) in outputs.iter().zip(&temps).enumerate() {
        if let Err(e) = std::fs::rename(t, &o.path) {
            cleanup(&temps[k..]);
            let reason = e.to_string();
            return Err(filed(sources, &o.path, |file, path| IoError::Unwritable {
                file,
                path,
                reason,
            }));
        }
    }
    Ok(())
}

/// Writes `bytes` to a new temporary file beside `path`; its path.
fn write_temp(path: &Path, bytes: &[u8]) -> std::io::Result<PathBuf> {
    use std::io::Write;
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let stamp = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    for attempt in 0..100u32 {
        let tmp = dir.join(format!(
            ".{name}.{}.{stamp}.{attempt}.inspc-tmp",
            std::process::id()
        ));
        let file = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp);
        match file {
            Ok(mut f) => {
                let written = f.write_all(bytes).and_then(|_| f.sync_all());
                if let Err(e) = written {
                    let _ = std::fs::remove_file(&tmp);
                    return Err(e);
                }
                return Ok(tmp);
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        }
    }
    Err(std::io::Error::new(
        std::io::ErrorKind::AlreadyExists,
        "no free temporary name beside it",
    ))
}
