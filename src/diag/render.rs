//! Rendering diagnostics for people (miette's graphical handler) and for editors (JSON).

use super::Diagnostic;
use crate::source::SourceMap;
use miette::{GraphicalReportHandler, GraphicalTheme, NamedSource, Severity};
use serde_json::json;
use std::fmt;

/// How to draw a human-readable report.
#[derive(Debug, Clone, Copy)]
pub struct RenderOptions {
    /// Terminal width to wrap at.
    pub width: usize,
    /// ANSI colours and Unicode box drawing.
    pub color: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 100,
            color: false,
        }
    }
}

/// Renders one diagnostic as miette's graphical report.
pub fn render_human(map: &SourceMap, d: &Diagnostic, opts: RenderOptions) -> String {
    let file = map.get(d.file);
    let located = Located {
        inner: d.inner.as_ref(),
        src: NamedSource::new(file.name.clone(), file.text.clone()),
    };
    let theme = if opts.color {
        GraphicalTheme::unicode()
    } else {
        GraphicalTheme::unicode_nocolor()
    };
    let handler = GraphicalReportHandler::new_themed(theme)
        .with_width(opts.width)
        .with_links(false);
    let mut out = String::new();
    if handler.render_report(&mut out, &located).is_err() {
        out = format!("{}: {}\n", d.code(), d.message());
    }
    out
}

/// Renders one diagnostic as a JSON object (one line when serialized).
pub fn to_json(map: &SourceMap, d: &Diagnostic) -> serde_json::Value {
    let file = map.get(d.file);
    let pos = |offset: usize, len: usize| {
        let (line, column) = file.line_col(offset);
        let (end_line, end_column) = file.line_col(offset + len);
        (line, column, end_line, end_column)
    };
    let labels: Vec<serde_json::Value> = d
        .inner
        .labels()
        .into_iter()
        .flatten()
        .map(|l| {
            let (line, column, end_line, end_column) = pos(l.offset(), l.len());
            json!({
                "message": l.label(),
                "file": file.name,
                "line": line, "column": column, "end_line": end_line, "end_column": end_column,
            })
        })
        .collect();
    let (line, column, end_line, end_column) = d
        .inner
        .labels()
        .and_then(|mut l| l.next())
        .map_or((1, 1, 1, 1), |l| pos(l.offset(), l.len()));
    json!({
        "severity": match d.severity() { Severity::Error => "error", Severity::Warning => "warning", Severity::Advice => "advice" },
        "code": d.code(),
        "message": d.message(),
        "file": file.name,
        "line": line, "column": column, "end_line": end_line, "end_column": end_column,
        "labels": labels,
        "help": d.inner.help().map(|h| h.to_string()),
    })
}

/// A diagnostic together with the source its labels point into.
struct Located<'a> {
    inner: &'a (dyn miette::Diagnostic + Send + Sync),
    src: NamedSource<String>,
}

impl fmt::Debug for Located<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self.inner, f)
    }
}

impl fmt::Display for Located<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self.inner, f)
    }
}

impl std::error::Error for Located<'_> {}

impl miette::Diagnostic for Located<'_> {
    fn code<'b>(&'b self) -> Option<Box<dyn fmt::Display + 'b>> {
        self.inner.code()
    }
    fn severity(&self) -> Option<Severity> {
        self.inner.severity()
    }
    fn help<'b>(&'b self) -> Option<Box<dyn fmt::Display + 'b>> {
        self.inner.help()
    }
    fn labels(&self) -> Option<Box<dyn Iterator<Item = miette::LabeledSpan> + '_>> {
        self.inner.labels()
    }
    fn source_code(&self) -> Option<&dyn miette::SourceCode> {
        Some(&self.src)
    }
}
