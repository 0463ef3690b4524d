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
mod hover;
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
use planner::{PlanOutput, PlanRun};
use rpc::{Code, Incoming};
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
    std::thread::spawn(move || transport::pump(input, &frames_tx));
    let mut server = Server::new(work);
    let events = server.events.clone();
    let mut phase = Phase::Starting;
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
    outcome
}

/// Where the server is in LSP's lifecycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    Starting,
    Running,
    ShuttingDown,
}

fn capabilities() -> lt::ServerCapabilities {
    lt::ServerCapabilities {
        text_document_sync: Some(lt::TextDocumentSyncCapability::Options(
            lt::TextDocumentSyncOptions {
                open_close: Some(true),
                change: Some(lt::TextDocumentSyncKind::FULL),
                save: Some(lt::TextDocumentSyncSaveOptions::SaveOptions(
                    lt::SaveOptions {
                        include_text: Some(false),
                    },
                )),
                ..Default::default()
            },
        )),
        hover_provider: Some(lt::HoverProviderCapability::Simple(true)),
        definition_provider: Some(lt::OneOf::Left(true)),
        references_provider: Some(lt::OneOf::Left(true)),
        document_symbol_provider: Some(lt::OneOf::Left(true)),
        rename_provider: Some(lt::OneOf::Left(true)),
        document_formatting_provider: Some(lt::OneOf::Left(true)),
        completion_provider: Some(lt::CompletionOptions {
            trigger_characters: Some(vec![":".into(), " ".into()]),
            ..Default::default()
        }),
        ..Default::default()
    }
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
    /// Each plan as `inspc plan --format json` writes it.
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

    /// Handles what the reader found; `Some` ends the server.
    fn frame(&mut self, frame: Frame, phase: &mut Phase) -> Option<Result<(), String>> {
        match frame {
            Frame::Body(body) => self.message(rpc::classify(&body), phase),
            Frame::TooLarge(len) => {
                let why = format!(
                    "a message of {len} bytes is over the {} MiB inspc reads; it was skipped unread",
                    transport::BODY_LIMIT >> 20
                );
                eprintln!("inspc lsp: {why}");
                // Its id was never read: JSON-RPC answers such a message with id null.
                let answer = rpc::error(Value::Null, Code::InvalidRequest, why);
                self.outbox.push(answer);
                None
            }
            Frame::End if *phase == Phase::ShuttingDown => Some(Ok(())),
            Frame::End => Some(Err(
                "the client closed the stream without `shutdown` and `exit`".into(),
            )),
            Frame::Broken(transport::Broken(why)) => Some(Err(format!(
                "{why}: the stream cannot be resynchronised, so the server stops"
            ))),
        }
    }

    /// Handles one message as LSP's lifecycle allows; `Some` ends the server.
    fn message(&mut self, message: Incoming, phase: &mut Phase) -> Option<Result<(), String>> {
        match message {
            Incoming::Invalid(answer) => self.outbox.push(answer),
            Incoming::Response => self.log("inspc: a response came, to no request".into()),
            Incoming::Notification { method, .. } if method == "exit" => {
                return Some(match phase {
                    Phase::ShuttingDown => Ok(()),
                    _ => Err("the client sent `exit` without `shutdown`".into()),
                });
            }
            // Before `initialize` and after `shutdown`, notifications are dropped.
            Incoming::Notification { method, params } if *phase == Phase::Running => {
                if let Err(why) = self.notification(&method, params) {
                    self.log(format!("inspc: ignored `{method}`: {why}"));
                }
            }
            Incoming::Notification { .. } => {}
            Incoming::Request { id, method, params } => {
                let answer = match (*phase, method.as_str()) {
                    (Phase::Starting, "initialize") => {
                        *phase = Phase::Running;
                        initialize_result()
                    }
                    (Phase::Starting, _) => Err((
                        Code::ServerNotInitialized,
                        "the server has not been initialized".into(),
                    )),
                    (Phase::Running, "initialize") => Err((
                        Code::InvalidRequest,
                        "`initialize` was already received".into(),
                    )),
                    (Phase::Running, "shutdown") => {
                        *phase = Phase::ShuttingDown;
                        Ok(Value::Null)
                    }
                    (Phase::Running, _) => self.answer(&method, params),
                    (Phase::ShuttingDown, _) => Err((
                        Code::InvalidRequest,
                        "the server is shutting down: only `exit` is expected".into(),
                    )),
                };
                self.outbox.push(match answer {
                    Ok(v) => rpc::result(id, v),
                    Err((code, why)) => rpc::error(id, code, why),
                });
            }
        }
        None
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

    /// Handles a notification; `Err` says why it was not acted on.
    fn notification(&mut self, method: &str, params: Value) -> Result<(), String> {
        use lt::notification::*;
        match method {
            DidOpenTextDocument::METHOD => {
                let p: lt::DidOpenTextDocumentParams = parse(params)?;
                let path = self.canonical(&p.text_document.uri)?;
                let doc = Doc {
                    uri: p.text_document.uri,
                    text: LineIndex::new(p.text_document.text),
                    version: p.text_document.version,
                };
                self.docs.insert(path.clone(), doc);
                self.changed(&path);
            }
            DidChangeTextDocument::METHOD => {
                let p: lt::DidChangeTextDocumentParams = parse(params)?;
                let path = self.canonical(&p.text_document.uri)?;
                let doc = self.docs.get_mut(&path).ok_or("the document is not open")?;
                // Full sync: the last change is the whole text.
                if let Some(c) = p.content_changes.into_iter().last() {
                    doc.text = LineIndex::new(c.text);
                }
                doc.version = p.text_document.version;
                self.changed(&path);
            }
            DidSaveTextDocument::METHOD => {
                let p: lt::DidSaveTextDocumentParams = parse(params)?;
                let path = self.canonical(&p.text_document.uri)?;
                self.plan(&path)?;
            }
            DidCloseTextDocument::METHOD => {
                let p: lt::DidCloseTextDocumentParams = parse(params)?;
                let path = self.canonical(&p.text_document.uri)?;
                self.docs.remove(&path);
                self.analyses.remove(&path);
                self.planning.remove(&path);
                self.publish();
            }
            "initialized" => {}
            // LSP 3.17: `$/` notifications may be ignored.
            m if m.starts_with("$/") => {}
            _ => return Err("inspc lsp does not handle it".into()),
        }
        Ok(())
    }

    /// A document's text changed: the front end now, the graphs in the background.
    fn changed(&mut self, path: &Path) {
        let world = self.overlay();
        let front = Arc::new(crate::check(&world, &[path.to_path_buf()]));
        let version = self.docs[path].version;
        let root_parsed = !front
            .diagnostics
            .iter()
            .any(|d| d.code().starts_with("insp::syntax::") && front.roots.contains(&d.file));
        let a = self
            .analyses
            .entry(path.to_path_buf())
            .or_insert_with(|| Analysis {
                front: front.clone(),
                parsed: None,
                deep: None,
                plan: None,
            });
        if root_parsed {
            a.parsed = Some(front.clone());
        }
        a.front = front;
        self.publish();
        if let Some(graphs) = &self.graphs {
            let _ = graphs.send(GraphJob {
                root: path.to_path_buf(),
                version,
                world,
            });
        }
    }

    /// Starts planning a saved spec in a child process, stopping the one before.
    fn plan(&mut self, path: &Path) -> Result<(), String> {
        self.planning.remove(path);
        let a = self.analyses.get(path).ok_or("the document is not open")?;
        if a.front.has_errors() || a.front.model.plans.is_empty() || self.work != Work::Full {
            return Ok(()); // nothing to plan
        }
        self.plan_runs += 1;
        let text = self.docs[path].text.text().to_string();
        let run = planner::start(path, text, self.plan_runs, self.events_tx.clone())
            .map_err(|e| format!("could not start the planner: {e}"))?;
        self.planning.insert(path.to_path_buf(), run);
        Ok(())
    }

    fn event(&mut self, ev: Event) {
        match ev {
            Event::Graphed { root, deep } => {
                let Some(a) = self.analyses.get_mut(&root) else {
                    return;
                };
                if a.deep.as_ref().is_some_and(|d| d.version > deep.version) {
                    return;
                }
                a.deep = Some(*deep);
                self.publish();
            }
            Event::Planned {
                root,
                id,
                text,
                output,
                seconds,
            } => {
                if self.planning.get(&root).map(|r| r.id) != Some(id) {
                    return; // a newer save started another plan
                }
                self.planning.remove(&root);
                let parsed = output.and_then(|o| {
                    serde_json::from_str::<PlanOutput>(&o).map_err(|e| e.to_string())
                });
                self.planned(&root, text, parsed, seconds);
            }
        }
    }

    /// A plan's answer: logged, kept for hovers, its diagnostics published.
    fn planned(
        &mut self,
        root: &Path,
        text: String,
        out: Result<PlanOutput, String>,
        seconds: f64,
    ) {
        let name = root
            .file_name()
            .map_or(String::new(), |n| n.to_string_lossy().into_owned());
        let out = match out {
            Ok(out) => out,
            Err(e) => return self.log(format!("inspc: planning {name} failed: {e}")),
        };
        let measured: Vec<String> = out
            .plans
            .iter()
            .map(|p| {
                format!(
                    "{}: {}/{} tolerances measured",
                    p["plan"].as_str().unwrap_or("?"),
                    p["summary"]["tolerances_measured"],
                    p["summary"]["tolerances"]
                )
            })
            .collect();
        let measured = match measured.is_empty() {
            true => "no plan".to_string(),
            false => measured.join(", "),
        };
        self.log(format!(
            "inspc: planned {name} in {seconds:.2} s; {measured}"
        ));
        if let Some(a) = self.analyses.get_mut(root) {
            a.plan = Some(PlanResult {
                text,
                diagnostics: out.diagnostics,
                plans: out.plans,
            });
        }
        self.publish();
    }
}

/// Notification parameters as their type.
fn parse<P: serde::de::DeserializeOwned>(params: Value) -> Result<P, String> {
    serde_json::from_value(params).map_err(|e| format!("invalid params: {e}"))
}

/// The answer to `initialize`: what the server can do, and who it is.
fn initialize_result() -> Result<Value, rpc::Failure> {
    let result = lt::InitializeResult {
        capabilities: capabilities(),
        server_info: Some(lt::ServerInfo {
            name: "inspc".into(),
            version: Some(env!("CARGO_PKG_VERSION").into()),
        }),
    };
    serde_json::to_value(result).map_err(|e| (Code::InternalError, e.to_string()))
}
