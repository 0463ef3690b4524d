//! `inspc lsp`: the language server. Entry points: [`stdio`], and [`serve`] over any
//! byte streams (the fuzz target drives it in memory).
//!
//! One thread reads the client's bytes into messages (`transport.rs`, bounded framing;
//! `rpc.rs`, JSON-RPC 2.0 with an error answer for every bad request); the message
//! thread answers each from what it knows of the open specs (`Analysis`). The front end
//! (parse, load, resolve) runs on that thread at every change — milliseconds, so a
//! typo's diagnostic comes back at once. The geometry and measurement graph (up to half
//! a second on a real part) run on one background thread that always takes the newest
//! version of each spec, and their diagnostics replace the front end's when they
//! arrive. Planning (seconds) runs on save in a child process (`planner.rs`), killed
//! when the next save or a close comes first, or the server ends: a slow plan never
//! blocks typing and a stale one never lands. Its diagnostics show while the text is
//! the one planned; hovers show its results.
//!
//! **Decision: our own synchronous loop over `lsp-types`.** A synchronous message loop
//! fits stages that are pure functions, with no async runtime to carry. The transport
//! and the JSON-RPC layer are ours (a few hundred lines) because the server must decide
//! what a hostile stream gets: size limits before any allocation, an error answer per
//! bad message and never a shutdown for one (`transport.rs` and `rpc.rs` say how and
//! cite the specifications). Planning in a child process is cancellation without
//! threading a flag through the planner, and a planner that can never take the server
//! down. Hovers read the plan's JSON (per face: setup, probe, orientation, points; per
//! tolerance: the setups that record it). Definitions into the stdlib open a copy in a
//! folder private to the server (`stdlib.rs`).
//!
//! The lifecycle is LSP 3.17's: before `initialize` a request gets -32002 and a
//! notification is dropped; after `shutdown` a request gets -32600; `exit` ends the
//! server with code 0 after `shutdown` and 1 without it. A stream that ends without
//! `exit`, or that breaks, ends it with code 1 and the reason on stderr.

mod complete;
mod diagnostics;
mod documents;
mod face_names;
mod hover;
mod lifecycle;
mod planner;
mod rename;
mod requests;
mod rpc;
#[cfg(test)]
mod session_tests;
mod stdlib;
mod symbols;
mod text;
mod transport;

pub use planner::plan_file;

use crate::source::{FileKind, FsWorld, World, WorldError};
use crate::Checked;
use crossbeam_channel::{select, Receiver, Sender};
use lsp_types as lt;
use planner::PlanRun;
use serde_json::Value;
use std::collections::BTreeMap;
use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use text::LineIndex;
use transport::Frame;

/// What the server runs besides the front end.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Work {
    /// Everything an editor gets: geometry and graphs on a worker thread, plans in child
    /// processes on save, imports read from disk.
    Full,
    /// The front end only, on the open documents only: no thread but the reader, no
    /// child process, no file read; files written only into the private stdlib copy.
    /// Each message's work is bounded by its size (the fuzz target).
    FrontEnd,
}

/// Serves the protocol over standard input and output until the client exits.
pub fn stdio() -> Result<(), String> {
    let input = std::io::BufReader::new(std::io::stdin());
    serve(input, std::io::stdout().lock(), Work::Full)
}

/// Serves the protocol over a byte stream until the client says `exit` or the stream
/// ends; `Err` says why the server ended without the `shutdown` then `exit` it expects.
pub fn serve<R, W>(input: R, mut output: W, work: Work) -> Result<(), String>
where
    R: BufRead + Send + 'static,
    W: Write,
{
    // One frame at a time: a fast client waits for the server, not its memory.
    let (frames_tx, frames) = crossbeam_channel::bounded(1);
    let reader = std::thread::spawn(move || transport::pump(input, &frames_tx));
    let mut server = Server::new(work);
    let events = server.events.clone();
    let mut phase = lifecycle::Phase::Starting;
    let outcome = loop {
        let end = select! {
            recv(frames) -> frame => server.frame(frame.unwrap_or(Frame::End), &mut phase),
            recv(events) -> ev => {
                if let Ok(ev) = ev {
                    server.event(ev);
                }
                None
            }
        };
        for message in std::mem::take(&mut server.outbox) {
            transport::write(&mut output, &message)
                .map_err(|e| format!("writing to the client failed: {e}"))?;
        }
        if let Some(outcome) = end {
            break outcome;
        }
    };
    // Dropping the server kills its planners and removes its stdlib copy.
    drop(server);
    // The reader ends at its next frame once nobody receives. An in-memory stream's
    // next frame comes at once, so it is joined and no thread outlives the call; a
    // stdio server's may never come (stdin left open), so it is left to the process's end.
    drop(frames);
    if work == Work::FrontEnd || reader.is_finished() {
        let _ = reader.join();
    }
    outcome
}

/// An open document.
struct Doc {
    uri: lt::Uri,
    /// Its text, with the line index of this version.
    text: LineIndex<String>,
    version: i32,
}

/// What the server knows of one open spec.
pub(crate) struct Analysis {
    /// The front end of the current text.
    pub front: Arc<Checked>,
    /// The document version `front` is of.
    pub version: i32,
    /// The last front end whose root parsed: names and keys for completion while the
    /// text is broken.
    pub parsed: Option<Arc<Checked>>,
    /// Geometry and measurement graphs, of the current or an earlier version.
    pub deep: Option<Deep>,
    /// The last plan, run on save.
    pub plan: Option<PlanResult>,
}

/// The geometry stage and measurement graphs of one version of a spec.
pub(crate) struct Deep {
    /// The version analysed.
    pub version: i32,
    /// Every diagnostic up to the measurement graph.
    pub checked: Checked,
    /// Per part, its geometry.
    pub parts: Vec<Option<crate::PartData>>,
    /// The measurement graphs.
    pub graphs: Vec<crate::Graphed>,
}

/// What a plan run (`inspc lsp --plan`) reported.
pub(crate) struct PlanResult {
    /// The text it planned (diagnostics show only while the document still reads so).
    pub text: String,
    /// Per file, its diagnostics.
    pub diagnostics: BTreeMap<PathBuf, Vec<lt::Diagnostic>>,
    /// Each plan as `inspc build --plan-json` writes it.
    pub plans: Vec<serde_json::Value>,
}

/// What the background work reports.
enum Event {
    Graphed {
        root: PathBuf,
        deep: Box<Deep>,
    },
    Planned {
        root: PathBuf,
        id: u64,
        text: String,
        output: Result<String, String>,
        seconds: f64,
    },
}

struct Server {
    work: Work,
    /// Messages to write, in order.
    outbox: Vec<Value>,
    /// Open documents by canonical path.
    docs: BTreeMap<PathBuf, Doc>,
    analyses: BTreeMap<PathBuf, Analysis>,
    /// Per URI, the diagnostics last published.
    published: BTreeMap<String, Vec<lt::Diagnostic>>,
    /// The graph worker (none in [`Work::FrontEnd`]).
    graphs: Option<Sender<GraphJob>>,
    events_tx: Sender<Event>,
    events: Receiver<Event>,
    planning: BTreeMap<PathBuf, PlanRun>,
    plan_runs: u64,
    /// The stdlib written out, the first time a definition needs it.
    stdlib: std::cell::OnceCell<Result<stdlib::StdlibCopy, String>>,
}

/// The open documents over the filesystem: what the editor shows is what is read.
#[derive(Clone)]
struct Overlay {
    docs: Arc<BTreeMap<PathBuf, String>>,
    work: Work,
}

impl World for Overlay {
    fn read(&self, path: &Path, kind: FileKind) -> Result<Vec<u8>, WorldError> {
        match self.docs.get(&self.canonical(path)) {
            Some(text) => {
                crate::source::too_large(text.len() as u64, kind)?;
                Ok(text.clone().into_bytes())
            }
            None if self.work == Work::Full => FsWorld.read(path, kind),
            None => Err(WorldError("not open in the editor".into())),
        }
    }
    fn exists(&self, path: &Path) -> bool {
        self.docs.contains_key(&self.canonical(path))
            || (self.work == Work::Full && FsWorld.exists(path))
    }
    fn canonical(&self, path: &Path) -> PathBuf {
        canonical_path(self.work, path)
    }
}

/// A path as the server keys it: the filesystem's canonical form, or in
/// [`Work::FrontEnd`] (which reads no file) the lexical one.
fn canonical_path(work: Work, path: &Path) -> PathBuf {
    match work {
        Work::Full => FsWorld.canonical(path),
        Work::FrontEnd => crate::source::normalize_path(path),
    }
}

struct GraphJob {
    root: PathBuf,
    version: i32,
    world: Overlay,
}

/// The thread that builds geometry and measurement graphs, newest version first.
fn spawn_graph_worker(events: Sender<Event>) -> Sender<GraphJob> {
    let (tx, rx): (Sender<GraphJob>, Receiver<GraphJob>) = crossbeam_channel::unbounded();
    std::thread::spawn(move || {
        while let Ok(first) = rx.recv() {
            let mut jobs: BTreeMap<PathBuf, GraphJob> = BTreeMap::new();
            jobs.insert(first.root.clone(), first);
            while let Ok(next) = rx.try_recv() {
                jobs.insert(next.root.clone(), next);
            }
            for (root, job) in jobs {
                let (checked, parts, graphs) =
                    crate::measurement_graphs(&job.world, std::slice::from_ref(&root));
                let deep = Box::new(Deep {
                    version: job.version,
                    checked,
                    parts,
                    graphs,
                });
                let ev = Event::Graphed { root, deep };
                if events.send(ev).is_err() {
                    return;
                }
            }
        }
    });
    tx
}

impl Server {
    fn new(work: Work) -> Server {
        let (events_tx, events) = crossbeam_channel::unbounded();
        Server {
            work,
            outbox: Vec::new(),
            docs: BTreeMap::new(),
            analyses: BTreeMap::new(),
            published: BTreeMap::new(),
            graphs: (work == Work::Full).then(|| spawn_graph_worker(events_tx.clone())),
            events_tx,
            events,
            planning: BTreeMap::new(),
            plan_runs: 0,
            stdlib: std::cell::OnceCell::new(),
        }
    }

    fn overlay(&self) -> Overlay {
        Overlay {
            docs: Arc::new(
                self.docs
                    .iter()
                    .map(|(p, d)| (p.clone(), d.text.text().to_string()))
                    .collect(),
            ),
            work: self.work,
        }
    }

    fn notify<N: lt::notification::Notification>(&mut self, params: N::Params) {
        let params = serde_json::to_value(params).unwrap_or(Value::Null);
        self.outbox.push(rpc::notification(N::METHOD, params));
    }

    fn log(&mut self, message: String) {
        self.notify::<lt::notification::LogMessage>(lt::LogMessageParams {
            typ: lt::MessageType::INFO,
            message,
        });
    }

    /// The canonical path of a `file://` URI.
    fn canonical(&self, uri: &lt::Uri) -> Result<PathBuf, String> {
        text::path_of(uri)
            .map(|p| canonical_path(self.work, &p))
            .ok_or_else(|| format!("`{}` is not a `file://` URI", uri.as_str()))
    }
}
