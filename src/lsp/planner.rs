//! Planning on save, in a child process (`inspc lsp --plan FILE`) tied to the server's
//! life.
//!
//! **Decision: the child ends with the server, however the server ends.** The server
//! holds the write end of the child's stdin and never writes to it. A [`PlanRun`] kills
//! and reaps its child when dropped (a newer save, a close, the server's exit or
//! unwinding). A server killed outright (SIGKILL) runs no code, but the system closes
//! its files: the child's stdin then reads end of file, and a thread in the child that
//! waits for exactly that ends the child ([`plan_file`]). Portable: no `prctl`, no
//! process groups. Pipes made by `std::process` are close-on-exec, so no other child
//! holds the write end open.

use super::diagnostics::lsp_diagnostics;
use super::Event;
use crate::source::FsWorld;
use lsp_types as lt;
use std::collections::BTreeMap;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, Stdio};

/// A plan in progress: its child process, killed and reaped on drop.
pub(crate) struct PlanRun {
    child: Child,
    /// The child's stdin, held open while the run lives (the child ends at its EOF).
    _lifeline: Option<ChildStdin>,
    /// Which save started it.
    pub id: u64,
}

impl Drop for PlanRun {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Starts planning `path` (saved as `text`) in a child process; its answer comes as
/// [`Event::Planned`] with `id`.
pub(crate) fn start(
    path: &Path,
    text: String,
    id: u64,
    events: crossbeam_channel::Sender<Event>,
) -> Result<PlanRun, String> {
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let mut child = Command::new(exe)
        .arg("lsp")
        .arg("--plan")
        .arg(path)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .map_err(|e| e.to_string())?;
    let stdout = child.stdout.take();
    let root = path.to_path_buf();
    let start = std::time::Instant::now();
    std::thread::spawn(move || {
        let mut out = String::new();
        let output = match stdout.map(|mut s| s.read_to_string(&mut out)) {
            Some(Ok(_)) if !out.is_empty() => Ok(out),
            _ => Err("the planner stopped without an answer".to_string()),
        };
        let _ = events.send(Event::Planned {
            root,
            id,
            text,
            output,
            seconds: start.elapsed().as_secs_f64(),
        });
    });
    Ok(PlanRun {
        _lifeline: child.stdin.take(),
        child,
        id,
    })
}

/// What `inspc lsp --plan FILE` writes: every diagnostic of the build per file, and
/// every plan as `inspc build --plan-json` writes it.
#[derive(serde::Serialize, serde::Deserialize)]
pub(crate) struct PlanOutput {
    pub diagnostics: BTreeMap<PathBuf, Vec<lt::Diagnostic>>,
    pub plans: Vec<serde_json::Value>,
}

/// The exit code of a planner whose server went away before it finished.
const ORPHANED: i32 = 3;

/// `inspc lsp --plan FILE`: plans a spec from disk and gives [`PlanOutput`] as JSON.
/// The server runs it in a child process so that it can be stopped; this process ends
/// (code 3) as soon as its stdin ends, which is when the server is gone.
pub fn plan_file(file: &Path) -> String {
    std::thread::spawn(|| {
        let mut stdin = std::io::stdin();
        let mut buf = [0u8; 256];
        loop {
            match stdin.read(&mut buf) {
                Ok(0) => std::process::exit(ORPHANED),
                Err(e) if e.kind() != std::io::ErrorKind::Interrupted => {
                    std::process::exit(ORPHANED)
                }
                _ => {}
            }
        }
    });
    // The whole build (plans, paths and the program, nothing written): the path
    // stage's warnings (`insp::path::self_aligned`, tight stand-offs) are the plan's too.
    let opts = crate::plan::PlanOptions::default();
    let (checked, built, _) = crate::build(&FsWorld, &[file.to_path_buf()], &opts, &|_, _, _| {});
    let plans = built.into_iter().map(|b| b.json).collect();
    let out = PlanOutput {
        diagnostics: lsp_diagnostics(&checked),
        plans,
    };
    serde_json::to_string(&out).unwrap_or_default()
}
