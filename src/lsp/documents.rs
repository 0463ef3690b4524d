//! The open documents: what the editor's notifications change, and the background
//! work (graphs, plans) each change or save starts and whose answers come back here.

use super::planner::{self, PlanOutput};
use super::text::LineIndex;
use super::{Analysis, Doc, Event, GraphJob, PlanResult, Server, Work};
use lsp_types as lt;
use serde_json::Value;
use std::path::Path;
use std::sync::Arc;

impl Server {
    /// Handles a notification; `Err` says why it was not acted on.
    pub(super) fn notification(&mut self, method: &str, params: Value) -> Result<(), String> {
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
                version,
                parsed: None,
                deep: None,
                plan: None,
            });
        if root_parsed {
            a.parsed = Some(front.clone());
        }
        a.front = front;
        a.version = version;
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

    pub(super) fn event(&mut self, ev: Event) {
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
