//! The standard library's modules as files an editor can open, for definitions into
//! them.
//!
//! **Decision: a private folder per server, written once.** A definition answers with
//! a `Location`, whose URI every editor opens when it is a `file://` one; a custom
//! scheme would need each editor's extension to serve it. So the first definition into
//! the stdlib writes every module into a folder made for this server alone: a new,
//! unpredictable name under the temp folder (`inspc-stdlib-<pid>-<random>`), created by
//! one `mkdir` that fails if anything is there already (so never through a link planted
//! there), mode 0700; each file created new (`O_CREAT | O_EXCL`: never through a link,
//! never into a FIFO or device), read-only, written whole from the embedded text.
//! Nothing is ever read back from it. The folder is removed when the server ends; a
//! killed server leaves it behind, private and a few kilobytes.

use crate::load::STD_MODULES;
use std::hash::{BuildHasher, Hasher};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The stdlib written out, removed on drop.
#[derive(Debug)]
pub(crate) struct StdlibCopy {
    dir: PathBuf,
}

impl StdlibCopy {
    /// Writes every standard module into a new private folder under the temp folder.
    pub(crate) fn write() -> Result<StdlibCopy, String> {
        let copy = StdlibCopy {
            dir: private_dir(&std::env::temp_dir())?,
        };
        for (name, text) in STD_MODULES {
            let short = name.trim_start_matches("std::");
            let path = copy.dir.join(format!("{short}.insp"));
            write_new(&path, text)
                .map_err(|e| format!("could not write {}: {e}", path.display()))?;
        }
        Ok(copy)
    }

    /// The copy of the stdlib file the source map names `<std>/<module>.insp`.
    pub(crate) fn path_of(&self, source_name: &str) -> Option<PathBuf> {
        let file = source_name.strip_prefix("<std>/")?;
        let known = STD_MODULES
            .iter()
            .any(|(n, _)| format!("{}.insp", n.trim_start_matches("std::")) == file);
        known.then(|| self.dir.join(file))
    }
}

impl Drop for StdlibCopy {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// A folder under `parent` that did not exist before, only its owner's.
fn private_dir(parent: &Path) -> Result<PathBuf, String> {
    let mut last = String::new();
    for _ in 0..16 {
        let dir = parent.join(format!(
            "inspc-stdlib-{}-{:016x}",
            std::process::id(),
            random()
        ));
        let mut builder = std::fs::DirBuilder::new();
        #[cfg(unix)]
        std::os::unix::fs::DirBuilderExt::mode(&mut builder, 0o700);
        match builder.create(&dir) {
            Ok(()) => return Ok(dir),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => last = e.to_string(),
            Err(e) => return Err(format!("could not create {}: {e}", dir.display())),
        }
    }
    Err(format!(
        "could not create a new folder under {}: {last}",
        parent.display()
    ))
}

/// 64 unpredictable bits: the standard library's per-process random hash keys, mixed
/// with the clock.
fn random() -> u64 {
    let mut h = std::collections::hash_map::RandomState::new().build_hasher();
    let now = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH);
    h.write_u128(now.map_or(0, |d| d.as_nanos()));
    h.finish()
}

/// Creates `path`, which must not exist (not even as a link), read-only, holding `text`.
fn write_new(path: &Path, text: &str) -> std::io::Result<()> {
    let mut options = std::fs::OpenOptions::new();
    options.write(true).create_new(true);
    #[cfg(unix)]
    std::os::unix::fs::OpenOptionsExt::mode(&mut options, 0o444);
    options.open(path)?.write_all(text.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_server_gets_its_own_private_copy() {
        let a = StdlibCopy::write().unwrap();
        let b = StdlibCopy::write().unwrap();
        assert_ne!(a.dir, b.dir);
        let heads = a.path_of("<std>/heads.insp").unwrap();
        let text = std::fs::read_to_string(&heads).unwrap();
        assert_eq!(text, include_str!("../../stdlib/heads.insp"));
        assert_eq!(a.path_of("<std>/../../etc/passwd.insp"), None);
        assert_eq!(a.path_of("main.insp"), None);
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let mode = std::fs::metadata(&a.dir).unwrap().permissions().mode();
            assert_eq!(mode & 0o777, 0o700);
        }
        let dir = a.dir.clone();
        drop(a);
        assert!(!dir.exists());
    }

    /// A link planted where a file would go is never followed: the write fails.
    #[cfg(unix)]
    #[test]
    fn a_planted_link_is_not_followed() {
        let parent = private_dir(&std::env::temp_dir()).unwrap();
        let target = parent.join("target");
        std::fs::write(&target, "keep").unwrap();
        let link = parent.join("heads.insp");
        std::os::unix::fs::symlink(&target, &link).unwrap();
        assert!(write_new(&link, "overwritten").is_err());
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "keep");
        std::fs::remove_dir_all(&parent).unwrap();
    }
}
