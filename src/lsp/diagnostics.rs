//! Diagnostics as the protocol writes them, and their publication.
//!
//! Publication is linear in the number of diagnostics: positions come from one line
//! index per file ([`FileLines`]), and a diagnostic reported by two analyses (the front
//! end's and the plan's) is kept once by a set of its serialised form, not by a search
//! of those kept before. (100,000 diagnostics took over 30 s with both done per
//! diagnostic from the start; see `tests/suite/lsp.rs`.)

use super::text::{self, FileLines};
use super::Server;
use crate::diag::Diagnostic as InspDiagnostic;
use crate::Checked;
use lsp_types as lt;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// A spec's diagnostics as the protocol writes them, per file (user files only).
pub(crate) fn lsp_diagnostics(checked: &Checked) -> BTreeMap<PathBuf, Vec<lt::Diagnostic>> {
    let mut lines = FileLines::new(&checked.sources);
    let mut out: BTreeMap<PathBuf, Vec<lt::Diagnostic>> = BTreeMap::new();
    for d in &checked.diagnostics {
        let Some(path) = &checked.sources.get(d.file).path else {
            continue;
        };
        let diagnostic = lsp_diagnostic(&mut lines, path, d);
        out.entry(path.clone()).or_default().push(diagnostic);
    }
    out
}

/// One diagnostic: its primary label's span, its code, its message with the help line
/// under it, and its other labels as related information.
fn lsp_diagnostic(lines: &mut FileLines, path: &Path, d: &InspDiagnostic) -> lt::Diagnostic {
    let index = lines.of(d.file);
    let labels: Vec<miette::LabeledSpan> = d.inner.labels().into_iter().flatten().collect();
    let range_of = |l: &miette::LabeledSpan| index.range(l.offset()..l.offset() + l.len());
    let range = labels.first().map_or_else(lt::Range::default, range_of);
    let mut message = d.message();
    if let Some(l) = labels.first().and_then(|l| l.label()) {
        message = format!("{message}: {l}");
    }
    if let Some(help) = d.inner.help() {
        message = format!("{message}\nhelp: {help}");
    }
    let uri = text::uri_of(path);
    let related: Vec<lt::DiagnosticRelatedInformation> = labels
        .iter()
        .skip(1)
        .filter_map(|l| {
            Some(lt::DiagnosticRelatedInformation {
                location: lt::Location {
                    uri: uri.clone()?,
                    range: range_of(l),
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

/// Per URI, its diagnostics, each once, in the order they came.
#[derive(Default)]
struct Gathered {
    files: BTreeMap<String, (lt::Uri, Vec<lt::Diagnostic>, BTreeSet<String>)>,
}

impl Gathered {
    /// Adds a file's diagnostics (none: the file is published, cleared).
    fn add(&mut self, uri: lt::Uri, diags: &[lt::Diagnostic]) {
        let entry = self
            .files
            .entry(uri.as_str().to_string())
            .or_insert_with(|| (uri, Vec::new(), BTreeSet::new()));
        for d in diags {
            let key = serde_json::to_string(d).unwrap_or_default();
            if entry.2.insert(key) {
                entry.1.push(d.clone());
            }
        }
    }
}

impl Server {
    /// Publishes every open spec's diagnostics, per file, where they changed.
    pub(super) fn publish(&mut self) {
        let mut all = Gathered::default();
        for (root, a) in &self.analyses {
            let Some(doc) = self.docs.get(root) else {
                continue;
            };
            // An open document under the address the client gave it.
            let uri_of = |path: &Path| {
                self.docs
                    .get(path)
                    .map(|d| d.uri.clone())
                    .or_else(|| text::uri_of(path))
            };
            // The deeper analysis when it is of this version, else the front end's.
            let checked = match &a.deep {
                Some(d) if d.version == doc.version => &d.checked,
                _ => &a.front,
            };
            // An open document is published even without diagnostics (clearing it).
            all.add(doc.uri.clone(), &[]);
            for (path, diags) in lsp_diagnostics(checked) {
                if let Some(uri) = uri_of(&path) {
                    all.add(uri, &diags);
                }
            }
            let plan = a.plan.as_ref().filter(|p| p.text == doc.text.text());
            for (path, diags) in plan.iter().flat_map(|p| &p.diagnostics) {
                if let Some(uri) = uri_of(path) {
                    all.add(uri, diags);
                }
            }
        }
        // Files that had diagnostics and have none now are cleared.
        let stale: Vec<String> = self
            .published
            .keys()
            .filter(|k| !all.files.contains_key(*k))
            .cloned()
            .collect();
        for key in stale {
            if let Ok(uri) = key.parse::<lt::Uri>() {
                all.add(uri, &[]);
            }
        }
        for (key, (uri, diags, _)) in all.files {
            if self.published.get(&key) == Some(&diags) {
                continue;
            }
            let version = text::path_of(&uri)
                .and_then(|p| self.docs.get(&super::canonical_path(self.work, &p)))
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
}
