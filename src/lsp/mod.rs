//! `inspc lsp`: the language server. Entry point: [`stdio`] (`serve` over any
//! connection).
//!
//! One thread reads the client's messages and answers each from what it knows of the
//! open specs (`Analysis`). The front end (parse, load, resolve) runs on that thread
//! at every change — milliseconds, so a typo's diagnostic comes back at once. The
//! geometry and measurement graph (up to half a second on a real part) run on one
//! background thread that always takes the newest version of each spec, and their
//! diagnostics replace the front end's when they arrive. Planning (seconds) runs on
//! save in a child process (`inspc lsp --plan FILE`), killed when the next save or a
//! close comes first: a slow plan never blocks typing and a stale one never lands.
//! Its diagnostics show while the text is the one planned; hovers show its results.
//!
//! **Decision: rust-analyzer's `lsp-server` and `lsp-types`.** A synchronous message
//! loop fits stages that are pure functions, with no async runtime to carry. Planning
//! in a child process that the next save or a close kills is cancellation without
//! threading a flag through the planner, and a planner that can never take the server
//! down. Hovers read the plan's JSON (per face: setup, probe, orientation, points; per
//! tolerance: the setups that record it). Definitions into the stdlib open a read-only
//! copy written once per version under the temp directory.

mod complete;
mod hover;
mod symbols;
mod text;

use crate::diag::Diagnostic as InspDiagnostic;
use crate::source::{FileKind, FsWorld, World, WorldError};
use crate::Checked;
use crossbeam_channel::{select, Receiver, Sender};
use lsp_server::{Connection, Message, Notification, Request, Response};
use lsp_types as lt;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::Arc;

/// Serves the protocol over standard input and output until the client exits.
pub fn stdio() -> Result<(), String> {
    let (connection, io) = Connection::stdio();
    serve(&connection)?;
    drop(connection);
    io.join().map_err(|e| e.to_string())
}

/// Serves the protocol over a connection until the client says `exit`.
pub(crate) fn serve(connection: &Connection) -> Result<(), String> {
    let caps = capabilities();
    let caps = serde_json::to_value(caps).map_err(|e| e.to_string())?;
    connection.initialize(caps).map_err(|e| e.to_string())?;
    let (events_tx, events) = crossbeam_channel::unbounded();
    let mut server = Server {
        sender: connection.sender.clone(),
        docs: BTreeMap::new(),
        analyses: BTreeMap::new(),
        published: BTreeMap::new(),
        graphs: spawn_graph_worker(events_tx.clone()),
        events_tx,
        planning: BTreeMap::new(),
        plan_runs: 0,
    };
    // The protocol's `exit` without `shutdown` before it ends the server with code 1
    // (LSP 3.17, "Exit Notification"); `handle_shutdown` answers `shutdown` and waits for
    // the `exit` after it.
    let mut outcome = Ok(());
    loop {
        select! {
            recv(connection.receiver) -> msg => {
                let Ok(msg) = msg else { break };
                match msg {
                    Message::Request(req) => {
                        if connection.handle_shutdown(&req).map_err(|e| e.to_string())? {
                            break;
                        }
                        server.request(req);
                    }
                    Message::Notification(n) if n.method == "exit" => {
                        outcome = Err("the client sent `exit` without `shutdown`".to_string());
                        break;
                    }
                    Message::Notification(n) => server.notification(n),
                    Message::Response(_) => {}
                }
            }
            recv(events) -> ev => {
                if let Ok(ev) = ev {
                    server.event(ev);
                }
            }
        }
    }
    for (_, mut run) in std::mem::take(&mut server.planning) {
        let _ = run.child.kill();
        let _ = run.child.wait();
    }
    outcome
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
    text: String,
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

/// A plan in progress.
struct PlanRun {
    child: Child,
    id: u64,
}

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
    sender: Sender<Message>,
    /// Open documents by canonical path.
    docs: BTreeMap<PathBuf, Doc>,
    analyses: BTreeMap<PathBuf, Analysis>,
    /// Per URI, the diagnostics last published.
    published: BTreeMap<String, Vec<lt::Diagnostic>>,
    graphs: Sender<GraphJob>,
    events_tx: Sender<Event>,
    planning: BTreeMap<PathBuf, PlanRun>,
    plan_runs: u64,
}

/// The open documents over the filesystem: what the editor shows is what is read.
#[derive(Clone)]
struct Overlay {
    docs: Arc<BTreeMap<PathBuf, String>>,
}

impl World for Overlay {
    fn read(&self, path: &Path, kind: FileKind) -> Result<Vec<u8>, WorldError> {
        match self.docs.get(&FsWorld.canonical(path)) {
            Some(text) => Ok(text.clone().into_bytes()),
            None => FsWorld.read(path, kind),
        }
    }
    fn exists(&self, path: &Path) -> bool {
        self.docs.contains_key(&FsWorld.canonical(path)) || FsWorld.exists(path)
    }
    fn canonical(&self, path: &Path) -> PathBuf {
        FsWorld.canonical(path)
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
    fn overlay(&self) -> Overlay {
        Overlay {
            docs: Arc::new(
                self.docs
                    .iter()
                    .map(|(p, d)| (p.clone(), d.text.clone()))
                    .collect(),
            ),
        }
    }

    fn notify<N: lt::notification::Notification>(&self, params: N::Params) {
        let n = Notification::new(N::METHOD.to_string(), params);
        let _ = self.sender.send(Message::Notification(n));
    }

    fn log(&self, message: String) {
        self.notify::<lt::notification::LogMessage>(lt::LogMessageParams {
            typ: lt::MessageType::INFO,
            message,
        });
    }

    fn notification(&mut self, n: Notification) {
        use lt::notification::*;
        match n.method.as_str() {
            DidOpenTextDocument::METHOD => {
                let Ok(p) = n.extract::<lt::DidOpenTextDocumentParams>(DidOpenTextDocument::METHOD)
                else {
                    return;
                };
                let Some(path) = canonical(&p.text_document.uri) else {
                    return;
                };
                self.docs.insert(
                    path.clone(),
                    Doc {
                        uri: p.text_document.uri,
                        text: p.text_document.text,
                        version: p.text_document.version,
                    },
                );
                self.changed(&path);
            }
            DidChangeTextDocument::METHOD => {
                let Ok(p) =
                    n.extract::<lt::DidChangeTextDocumentParams>(DidChangeTextDocument::METHOD)
                else {
                    return;
                };
                let Some(path) = canonical(&p.text_document.uri) else {
                    return;
                };
                let Some(doc) = self.docs.get_mut(&path) else {
                    return;
                };
                // Full sync: the last change is the whole text.
                if let Some(c) = p.content_changes.into_iter().last() {
                    doc.text = c.text;
                }
                doc.version = p.text_document.version;
                self.changed(&path);
            }
            DidSaveTextDocument::METHOD => {
                let Ok(p) = n.extract::<lt::DidSaveTextDocumentParams>(DidSaveTextDocument::METHOD)
                else {
                    return;
                };
                if let Some(path) = canonical(&p.text_document.uri) {
                    self.plan(&path);
                }
            }
            DidCloseTextDocument::METHOD => {
                let Ok(p) =
                    n.extract::<lt::DidCloseTextDocumentParams>(DidCloseTextDocument::METHOD)
                else {
                    return;
                };
                let Some(path) = canonical(&p.text_document.uri) else {
                    return;
                };
                self.docs.remove(&path);
                self.analyses.remove(&path);
                if let Some(mut run) = self.planning.remove(&path) {
                    let _ = run.child.kill();
                    let _ = run.child.wait();
                }
                self.publish();
            }
            _ => {}
        }
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
        let _ = self.graphs.send(GraphJob {
            root: path.to_path_buf(),
            version,
            world,
        });
    }

    /// Starts planning a saved spec in a child process, stopping the one before.
    fn plan(&mut self, path: &Path) {
        if let Some(mut old) = self.planning.remove(path) {
            let _ = old.child.kill();
            let _ = old.child.wait();
        }
        let Some(a) = self.analyses.get(path) else {
            return;
        };
        if a.front.has_errors() || a.front.model.plans.is_empty() {
            return;
        }
        let Ok(exe) = std::env::current_exe() else {
            return;
        };
        let child = Command::new(exe)
            .arg("lsp")
            .arg("--plan")
            .arg(path)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn();
        let Ok(mut child) = child else {
            self.log("inspc: could not start the planner".into());
            return;
        };
        self.plan_runs += 1;
        let id = self.plan_runs;
        let stdout = child.stdout.take();
        let text = self.docs[path].text.clone();
        let events = self.events_tx.clone();
        let root = path.to_path_buf();
        let start = std::time::Instant::now();
        std::thread::spawn(move || {
            use std::io::Read;
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
        self.planning
            .insert(path.to_path_buf(), PlanRun { child, id });
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
                if let Some(mut run) = self.planning.remove(&root) {
                    let _ = run.child.wait();
                }
                let name = root
                    .file_name()
                    .map_or(String::new(), |n| n.to_string_lossy().into_owned());
                let parsed = output.and_then(|o| {
                    serde_json::from_str::<PlanOutput>(&o).map_err(|e| e.to_string())
                });
                match parsed {
                    Ok(out) => {
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
                        self.log(format!(
                            "inspc: planned {name} in {seconds:.2} s; {}",
                            if measured.is_empty() {
                                "no plan".to_string()
                            } else {
                                measured.join(", ")
                            }
                        ));
                        if let Some(a) = self.analyses.get_mut(&root) {
                            a.plan = Some(PlanResult {
                                text,
                                diagnostics: out.diagnostics,
                                plans: out.plans,
                            });
                        }
                        self.publish();
                    }
                    Err(e) => self.log(format!("inspc: planning {name} failed: {e}")),
                }
            }
        }
    }

    /// Publishes every open spec's diagnostics, per file, where they changed.
    fn publish(&mut self) {
        let mut all: BTreeMap<String, (lt::Uri, Vec<lt::Diagnostic>)> = BTreeMap::new();
        let docs = &self.docs;
        let mut merge = |path: &Path, diags: &[lt::Diagnostic]| {
            // An open document under the address the client gave it.
            let Some(uri) = docs
                .get(path)
                .map(|d| d.uri.clone())
                .or_else(|| text::uri_of(path))
            else {
                return;
            };
            let entry = all
                .entry(uri.as_str().to_string())
                .or_insert_with(|| (uri, Vec::new()));
            for d in diags {
                if !entry.1.contains(d) {
                    entry.1.push(d.clone());
                }
            }
        };
        for (root, a) in &self.analyses {
            let Some(doc) = self.docs.get(root) else {
                continue;
            };
            // The deeper analysis when it is of this version, else the front end's.
            let checked = match &a.deep {
                Some(d) if d.version == doc.version => &d.checked,
                _ => &a.front,
            };
            // An open document is published even without diagnostics (clearing it).
            merge(root, &[]);
            for (path, diags) in lsp_diagnostics(checked) {
                merge(&path, &diags);
            }
            if let Some(plan) = a.plan.as_ref().filter(|p| p.text == doc.text) {
                for (path, diags) in &plan.diagnostics {
                    merge(path, diags);
                }
            }
        }
        // Files that had diagnostics and have none now are cleared.
        let stale: Vec<String> = self
            .published
            .keys()
            .filter(|k| !all.contains_key(*k))
            .cloned()
            .collect();
        for key in stale {
            if let Ok(uri) = key.parse::<lt::Uri>() {
                all.insert(key, (uri, Vec::new()));
            }
        }
        for (key, (uri, diags)) in all {
            if self.published.get(&key) == Some(&diags) {
                continue;
            }
            let version = text::path_of(&uri)
                .and_then(|p| self.docs.get(&FsWorld.canonical(&p)))
                .map(|d| d.version);
            self.notify::<lt::notification::PublishDiagnostics>(lt::PublishDiagnosticsParams {
                uri,
                diagnostics: diags.clone(),
                version,
            });
            if diags.is_empty() {
                self.published.remove(&key);
            } else {
                self.published.insert(key, diags);
            }
        }
    }

    fn request(&mut self, req: Request) {
        let id = req.id.clone();
        let result = self.answer(req);
        let response = match result {
            Ok(v) => Response::new_ok(id, v),
            Err((code, message)) => Response::new_err(id, code as i32, message),
        };
        let _ = self.sender.send(Message::Response(response));
    }

    fn answer(&mut self, req: Request) -> Result<serde_json::Value, Failure> {
        use lt::request::*;
        match req.method.as_str() {
            HoverRequest::METHOD => json(serde_json::to_value(self.on_hover(extract(req)?))),
            GotoDefinition::METHOD => {
                let loc = self.on_definition(extract(req)?);
                json(serde_json::to_value(
                    loc.map(lt::GotoDefinitionResponse::Scalar),
                ))
            }
            References::METHOD => json(serde_json::to_value(self.on_references(extract(req)?))),
            DocumentSymbolRequest::METHOD => json(serde_json::to_value(
                self.on_document_symbols(extract(req)?),
            )),
            Completion::METHOD => self.on_completion(extract(req)?),
            Rename::METHOD => self.on_rename(extract(req)?),
            Formatting::METHOD => self.on_formatting(extract(req)?),
            _ => Err((
                lsp_server::ErrorCode::MethodNotFound,
                format!("inspc lsp does not answer {}", req.method),
            )),
        }
    }

    /// The hover at a position: what the name there is, in Markdown.
    fn on_hover(&self, p: lt::HoverParams) -> Option<lt::Hover> {
        let at = &p.text_document_position_params;
        self.at(&at.text_document.uri, at.position)
            .and_then(|(a, file, offset)| {
                let (span, md) = hover::hover(a, file, offset)?;
                Some(lt::Hover {
                    contents: lt::HoverContents::Markup(lt::MarkupContent {
                        kind: lt::MarkupKind::Markdown,
                        value: md,
                    }),
                    range: Some(self.range(&a.front, span)?.range),
                })
            })
    }

    /// Where the name at a position is declared.
    fn on_definition(&self, p: lt::GotoDefinitionParams) -> Option<lt::Location> {
        let at = &p.text_document_position_params;
        self.at(&at.text_document.uri, at.position)
            .and_then(|(a, file, offset)| {
                let (_, decl) = symbols::target(&a.front, file, offset)?;
                self.range(&a.front, decl)
            })
    }

    /// Every use of the name at a position, its declaration too when asked.
    fn on_references(&self, p: lt::ReferenceParams) -> Option<Vec<lt::Location>> {
        let at = &p.text_document_position;
        let include = p.context.include_declaration;
        self.at(&at.text_document.uri, at.position)
            .map(|(a, file, offset)| {
                let Some((_, decl)) = symbols::target(&a.front, file, offset) else {
                    return Vec::new();
                };
                symbols::references(&a.front, decl)
                    .into_iter()
                    .filter(|s| include || *s != decl)
                    .filter_map(|s| self.range(&a.front, s))
                    .collect::<Vec<_>>()
            })
    }

    /// A document's outline.
    fn on_document_symbols(
        &self,
        p: lt::DocumentSymbolParams,
    ) -> Option<lt::DocumentSymbolResponse> {
        self.at(&p.text_document.uri, lt::Position::default())
            .map(|(a, file, _)| lt::DocumentSymbolResponse::Nested(document_symbols(a, file)))
    }

    /// The completions at a position, from the document's last parsed analysis.
    fn on_completion(&self, p: lt::CompletionParams) -> Result<serde_json::Value, Failure> {
        let at = &p.text_document_position;
        let Some(path) = canonical(&at.text_document.uri) else {
            return Ok(serde_json::Value::Null);
        };
        let (Some(doc), Some(a)) = (self.docs.get(&path), self.analyses.get(&path)) else {
            return Ok(serde_json::Value::Null);
        };
        let offset = text::offset(&doc.text, at.position);
        let checked = a.parsed.as_deref().unwrap_or(&a.front);
        let file = checked
            .sources
            .find_path(&path)
            .unwrap_or(crate::source::FileId(u32::MAX));
        let items = complete::complete(checked, file, &doc.text, offset);
        json(serde_json::to_value(lt::CompletionResponse::Array(items)))
    }

    /// The edits that rename the name at a position, wherever it is used; an error for a
    /// new name that is not one, no name there, or a standard-library name.
    fn on_rename(&self, p: lt::RenameParams) -> Result<serde_json::Value, Failure> {
        let bad = |e: String| (lsp_server::ErrorCode::InvalidParams, e);
        let at = &p.text_document_position;
        let new_name = p.new_name;
        if !symbols::is_name(&new_name) {
            return Err(bad(format!(
                "`{new_name}` is not a name: a letter or `_`, then letters, digits and `_`, and not a keyword"
            )));
        }
        let Some((a, file, offset)) = self.at(&at.text_document.uri, at.position) else {
            return Ok(serde_json::Value::Null);
        };
        let Some((_, decl)) = symbols::target(&a.front, file, offset) else {
            return Err(bad("no name here to rename".into()));
        };
        if a.front.sources.get(decl.file).path.is_none() {
            return Err(bad("a standard-library name cannot be renamed".into()));
        }
        // `WorkspaceEdit` keys its edits by `Uri`, which clippy thinks mutable.
        #[allow(clippy::mutable_key_type)]
        let mut changes: std::collections::HashMap<lt::Uri, Vec<lt::TextEdit>> =
            std::collections::HashMap::new();
        for s in symbols::references(&a.front, decl) {
            if let Some(loc) = self.range(&a.front, s) {
                changes.entry(loc.uri).or_default().push(lt::TextEdit {
                    range: loc.range,
                    new_text: new_name.clone(),
                });
            }
        }
        json(serde_json::to_value(lt::WorkspaceEdit {
            changes: Some(changes),
            ..Default::default()
        }))
    }

    /// The edit that formats a document, when formatting changes its layout only.
    fn on_formatting(&self, p: lt::DocumentFormattingParams) -> Result<serde_json::Value, Failure> {
        let Some(doc) = canonical(&p.text_document.uri).and_then(|p| self.docs.get(&p)) else {
            return Ok(serde_json::Value::Null);
        };
        // Only a layout change that keeps the parse tree (as `inspc fmt`).
        let edits = match crate::fmt::format_checked(&doc.text) {
            Some(formatted) if formatted != doc.text => vec![lt::TextEdit {
                range: text::range(&doc.text, 0..doc.text.len()),
                new_text: formatted,
            }],
            _ => Vec::new(),
        };
        json(serde_json::to_value(edits))
    }

    /// The analysis of an open document, its file id there and the byte offset of a
    /// position.
    fn at(
        &self,
        uri: &lt::Uri,
        pos: lt::Position,
    ) -> Option<(&Analysis, crate::source::FileId, usize)> {
        let path = canonical(uri)?;
        let a = self.analyses.get(&path)?;
        let doc = self.docs.get(&path)?;
        let file = a.front.sources.find_path(&path)?;
        Some((a, file, text::offset(&doc.text, pos)))
    }

    /// Where a span is, for the client: a user file by its path, a standard-library file
    /// by a copy written for reading.
    fn range(&self, checked: &Checked, span: crate::source::Span) -> Option<lt::Location> {
        let f = checked.sources.get(span.file);
        let path = match &f.path {
            Some(p) => p.clone(),
            None => stdlib_copy(&f.name, &f.text)?,
        };
        Some(lt::Location {
            uri: text::uri_of(&path)?,
            range: text::range(&f.text, span.range()),
        })
    }
}

fn extract<P: serde::de::DeserializeOwned>(
    req: Request,
) -> Result<P, (lsp_server::ErrorCode, String)> {
    serde_json::from_value(req.params)
        .map_err(|e| (lsp_server::ErrorCode::InvalidParams, e.to_string()))
}

/// What a request fails with: an LSP error code and a message.
type Failure = (lsp_server::ErrorCode, String);

/// A result as JSON, or an internal error where it cannot be written.
fn json(v: Result<serde_json::Value, serde_json::Error>) -> Result<serde_json::Value, Failure> {
    v.map_err(|e| (lsp_server::ErrorCode::InternalError, e.to_string()))
}

fn canonical(uri: &lt::Uri) -> Option<PathBuf> {
    text::path_of(uri).map(|p| FsWorld.canonical(&p))
}

/// A standard-library module written out (once per version, read-only) so an editor can
/// open it: `<temp>/inspc-<version>-stdlib/heads.insp`.
fn stdlib_copy(name: &str, text: &str) -> Option<PathBuf> {
    let file = name.strip_prefix("<std>/")?;
    let dir = std::env::temp_dir().join(format!("inspc-{}-stdlib", env!("CARGO_PKG_VERSION")));
    let path = dir.join(file);
    if std::fs::read_to_string(&path).ok().as_deref() != Some(text) {
        std::fs::create_dir_all(&dir).ok()?;
        // Written beside and renamed: a reader never sees half a file.
        let tmp = dir.join(format!(".{file}.{}", std::process::id()));
        std::fs::write(&tmp, text).ok()?;
        std::fs::rename(&tmp, &path).ok()?;
    }
    Some(path)
}

/// A spec's diagnostics as the protocol writes them, per file (user files only).
fn lsp_diagnostics(checked: &Checked) -> BTreeMap<PathBuf, Vec<lt::Diagnostic>> {
    let mut out: BTreeMap<PathBuf, Vec<lt::Diagnostic>> = BTreeMap::new();
    for d in &checked.diagnostics {
        let f = checked.sources.get(d.file);
        let Some(path) = &f.path else { continue };
        out.entry(path.clone())
            .or_default()
            .push(lsp_diagnostic(&f.text, path, d));
    }
    out
}

/// One diagnostic: its primary label's span, its code, its message with the help line
/// under it, and its other labels as related information.
fn lsp_diagnostic(text: &str, path: &Path, d: &InspDiagnostic) -> lt::Diagnostic {
    let labels: Vec<miette::LabeledSpan> = d.inner.labels().into_iter().flatten().collect();
    let range = labels.first().map_or_else(lt::Range::default, |l| {
        text::range(text, l.offset()..l.offset() + l.len())
    });
    let mut message = d.message();
    if let Some(l) = labels.first().and_then(|l| l.label()) {
        message = format!("{message}: {l}");
    }
    if let Some(help) = d.inner.help() {
        message = format!("{message}\nhelp: {help}");
    }
    let related: Vec<lt::DiagnosticRelatedInformation> = labels
        .iter()
        .skip(1)
        .filter_map(|l| {
            Some(lt::DiagnosticRelatedInformation {
                location: lt::Location {
                    uri: text::uri_of(path)?,
                    range: text::range(text, l.offset()..l.offset() + l.len()),
                },
                message: l.label().unwrap_or("here").to_string(),
            })
        })
        .collect();
    lt::Diagnostic {
        range,
        severity: Some(match d.severity() {
            miette::Severity::Error => lt::DiagnosticSeverity::ERROR,
            miette::Severity::Warning => lt::DiagnosticSeverity::WARNING,
            miette::Severity::Advice => lt::DiagnosticSeverity::HINT,
        }),
        code: Some(lt::NumberOrString::String(d.code())),
        source: Some("inspc".into()),
        message,
        related_information: (!related.is_empty()).then_some(related),
        ..Default::default()
    }
}

/// The outline of a file: its items, and in a part its operations, faces, features,
/// datums, frames and tolerances.
#[allow(deprecated)] // `DocumentSymbol::deprecated` must still be written
fn document_symbols(a: &Analysis, file: crate::source::FileId) -> Vec<lt::DocumentSymbol> {
    let checked = &a.front;
    let text = &checked.sources.get(file).text;
    let all = symbols::decls(checked);
    let kind_of = |k: symbols::DeclKind| match k {
        symbols::DeclKind::Part => lt::SymbolKind::CLASS,
        symbols::DeclKind::Plan => lt::SymbolKind::FUNCTION,
        symbols::DeclKind::Hierarchy => lt::SymbolKind::ENUM,
        symbols::DeclKind::Block(_) => lt::SymbolKind::STRUCT,
        symbols::DeclKind::Tolerance => lt::SymbolKind::PROPERTY,
        symbols::DeclKind::Datum | symbols::DeclKind::Frame => lt::SymbolKind::CONSTANT,
        symbols::DeclKind::Label => lt::SymbolKind::KEY,
        _ => lt::SymbolKind::FIELD,
    };
    let symbol =
        |d: &symbols::Decl, children: Option<Vec<lt::DocumentSymbol>>| lt::DocumentSymbol {
            name: d.name.name.clone(),
            detail: Some(d.kind.keyword().to_string()),
            kind: kind_of(d.kind),
            tags: None,
            deprecated: None,
            range: text::range(text, d.full.range()),
            selection_range: text::range(text, d.name.span.range()),
            children,
        };
    all.iter()
        .filter(|d| d.name.span.file == file && d.is_item())
        .map(|d| {
            let children = match d.kind {
                symbols::DeclKind::Part => Some(
                    all.iter()
                        .filter(|c| c.part.is_some_and(|p| p.name.span == d.name.span))
                        .map(|c| symbol(c, None))
                        .collect(),
                ),
                symbols::DeclKind::Block(crate::syntax::ast::BlockKind::Cmm) => Some(
                    all.iter()
                        .filter(|c| c.kind == symbols::DeclKind::Label)
                        .filter(|c| symbols::within(c.full, d.full))
                        .map(|c| symbol(c, None))
                        .collect(),
                ),
                _ => None,
            };
            symbol(d, children)
        })
        .collect()
}

/// What `inspc lsp --plan FILE` writes: every diagnostic of the plan run per file, and
/// every plan as `inspc plan --format json` writes it.
#[derive(serde::Serialize, serde::Deserialize)]
struct PlanOutput {
    diagnostics: BTreeMap<PathBuf, Vec<lt::Diagnostic>>,
    plans: Vec<serde_json::Value>,
}

/// `inspc lsp --plan FILE`: plans a spec from disk and prints [`PlanOutput`] as JSON.
/// The server runs it in a child process so that it can be stopped.
pub fn plan_file(file: &Path) -> String {
    let opts = crate::plan::PlanOptions::default();
    let (checked, parts, _, planned) = crate::plans(&FsWorld, &[file.to_path_buf()], &opts);
    let plans = planned
        .iter()
        .filter_map(|p| {
            let names = crate::plan_names(&checked, &parts, p.plan)?;
            Some(crate::plan::json(p.hlip.as_ref()?, &names))
        })
        .collect();
    let out = PlanOutput {
        diagnostics: lsp_diagnostics(&checked),
        plans,
    };
    serde_json::to_string(&out).unwrap_or_default()
}
