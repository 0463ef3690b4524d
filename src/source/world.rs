//! The file access the front end needs, behind a trait.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Why a file could not be read: the system's reason.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WorldError(pub String);

/// Where source and data files come from.
pub trait World {
    /// The bytes of a file.
    fn read(&self, path: &Path) -> Result<Vec<u8>, WorldError>;
    /// Whether a (data) file exists and is a regular file.
    fn exists(&self, path: &Path) -> bool;
    /// The canonical form of a path, so one file read under two spellings is one file.
    fn canonical(&self, path: &Path) -> PathBuf {
        path.to_path_buf()
    }
}

/// The real filesystem.
#[derive(Debug, Default, Clone, Copy)]
pub struct FsWorld;

impl World for FsWorld {
    fn read(&self, path: &Path) -> Result<Vec<u8>, WorldError> {
        if path.is_dir() {
            return Err(WorldError("is a directory".into()));
        }
        std::fs::read(path).map_err(|e| WorldError(e.to_string()))
    }

    fn exists(&self, path: &Path) -> bool {
        path.is_file()
    }

    fn canonical(&self, path: &Path) -> PathBuf {
        std::fs::canonicalize(path).unwrap_or_else(|_| normalize(path))
    }
}

/// Files held in memory, for tests and tools. Paths are normalized lexically.
#[derive(Debug, Default, Clone)]
pub struct MemoryWorld {
    files: BTreeMap<PathBuf, Vec<u8>>,
}

impl MemoryWorld {
    /// An empty world.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds (or replaces) a file.
    pub fn insert(&mut self, path: impl AsRef<Path>, contents: impl Into<Vec<u8>>) -> &mut Self {
        self.files.insert(normalize(path.as_ref()), contents.into());
        self
    }
}

impl World for MemoryWorld {
    fn read(&self, path: &Path) -> Result<Vec<u8>, WorldError> {
        self.files
            .get(&normalize(path))
            .cloned()
            .ok_or_else(|| WorldError("No such file or directory".into()))
    }

    fn exists(&self, path: &Path) -> bool {
        self.files.contains_key(&normalize(path))
    }

    fn canonical(&self, path: &Path) -> PathBuf {
        normalize(path)
    }
}

/// Removes `.` and folds `..` without touching the filesystem.
pub(crate) fn normalize(path: &Path) -> PathBuf {
    use std::path::Component;
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                if matches!(out.components().next_back(), Some(Component::Normal(_))) {
                    out.pop();
                } else {
                    out.push("..");
                }
            }
            other => out.push(other.as_os_str()),
        }
    }
    out
}
