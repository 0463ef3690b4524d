//! The file access the front end needs, behind a trait.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Why a file could not be read: the system's reason.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WorldError(pub String);

/// What a file is read as: it decides how large the file may be.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileKind {
    /// An `.insp` spec.
    Spec,
    /// A mesh (STL, OBJ).
    Mesh,
    /// A DMIS program.
    Dmis,
}

impl FileKind {
    /// The largest file of this kind inspc reads (bytes). Real specs are kilobytes, real
    /// meshes of the NIST parts a few megabytes, real programs well under a megabyte.
    pub const fn limit(self) -> u64 {
        match self {
            FileKind::Spec => 8 << 20,
            FileKind::Mesh => 256 << 20,
            FileKind::Dmis => 64 << 20,
        }
    }

    /// The kind in words.
    pub fn word(self) -> &'static str {
        match self {
            FileKind::Spec => "spec",
            FileKind::Mesh => "mesh",
            FileKind::Dmis => "DMIS",
        }
    }
}

/// Where source and data files come from.
pub trait World {
    /// The bytes of a file of `kind`: only a regular file, and only up to the kind's
    /// [`FileKind::limit`]; anything else is an error that says why.
    fn read(&self, path: &Path, kind: FileKind) -> Result<Vec<u8>, WorldError>;
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
    fn read(&self, path: &Path, kind: FileKind) -> Result<Vec<u8>, WorldError> {
        use std::io::Read;
        let err = |e: std::io::Error| WorldError(e.to_string());
        // Checked before opening: a FIFO would block the open, a device never end.
        let meta = std::fs::metadata(path).map_err(err)?;
        if meta.is_dir() {
            return Err(WorldError("is a directory".into()));
        }
        if !meta.is_file() {
            return Err(WorldError(
                "is not a regular file (a device, a pipe or a socket)".into(),
            ));
        }
        too_large(meta.len(), kind)?;
        let mut bytes = Vec::new();
        std::fs::File::open(path)
            .map_err(err)?
            .take(kind.limit() + 1)
            .read_to_end(&mut bytes)
            .map_err(err)?;
        // The file may have grown since its size was read.
        too_large(bytes.len() as u64, kind)?;
        Ok(bytes)
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
    fn read(&self, path: &Path, kind: FileKind) -> Result<Vec<u8>, WorldError> {
        let bytes = self
            .files
            .get(&normalize(path))
            .ok_or_else(|| WorldError("No such file or directory".into()))?;
        too_large(bytes.len() as u64, kind)?;
        Ok(bytes.clone())
    }

    fn exists(&self, path: &Path) -> bool {
        self.files.contains_key(&normalize(path))
    }

    fn canonical(&self, path: &Path) -> PathBuf {
        normalize(path)
    }
}

/// The error for a file over its kind's limit.
pub(crate) fn too_large(len: u64, kind: FileKind) -> Result<(), WorldError> {
    if len > kind.limit() {
        return Err(WorldError(format!(
            "it is larger than the {} MiB inspc reads for a {} file",
            kind.limit() >> 20,
            kind.word()
        )));
    }
    Ok(())
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
