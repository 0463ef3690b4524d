//! Rendering diagnostics for people (miette's graphical handler) and for editors (JSON).

use super::Diagnostic;
use crate::source::SourceMap;
use miette::{GraphicalReportHandler, GraphicalTheme, NamedSource, Severity};
use serde_json::json;
use std::borrow::Cow;
use std::fmt;

/// Text from a user's files as a terminal may show it: control characters other than a
/// newline, a carriage return or a tab become `?`, and bidirectional controls (which can
/// reorder what a reader sees, U+202A–U+202E, U+2066–U+2069) become U+FFFD. Both keep
/// their UTF-8 length, so spans into the text still point at the same characters.
pub(crate) fn terminal_safe(s: &str) -> Cow<'_, str> {
    let bad = |c: char| {
        (c.is_control() && !matches!(c, '\n' | '\r' | '\t'))
            || matches!(c, '\u{202A}'..='\u{202E}' | '\u{2066}'..='\u{2069}')
    };
    if !s.chars().any(bad) {
        return Cow::Borrowed(s);
    }
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        if !bad(c) {
            out.push(c);
        } else if c.len_utf8() == 3 {
            out.push('\u{FFFD}');
        } else {
            // Controls other than the bidirectional ones: one byte (C0, DEL) or two
            // (C1); keep the length with as many `?`.
            out.extend(std::iter::repeat_n('?', c.len_utf8()));
        }
    }
    Cow::Owned(out)
}

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

/// Renders one diagnostic as miette's graphical report. Only the lines around its
/// labels are quoted, and of a long line only [`QUOTE_WIDTH`] bytes around the label.
pub fn render_human(map: &SourceMap, d: &Diagnostic, opts: RenderOptions) -> String {
    let file = map.get(d.file);
    let spans: Vec<(usize, usize)> = d
        .inner
        .labels()
        .into_iter()
        .flatten()
        .map(|l| (l.offset(), l.len()))
        .collect();
    let located = Located {
        inner: d.inner.as_ref(),
        src: Excerpt::of(file, &spans),
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

/// The most bytes of one source line a report quotes.
pub(crate) const QUOTE_WIDTH: usize = 240;

/// Lines quoted before the first label's line and after the last's.
const CONTEXT_LINES: usize = 2;

/// One quoted line: where it starts in the file and in the excerpt, and the window of
/// it that was kept (the whole line unless it is longer than [`QUOTE_WIDTH`]).
struct QuotedLine {
    start: usize,
    keep: std::ops::Range<usize>,
    at: usize,
}

/// The part of a file a report quotes: the lines around its labels, long lines cut to
/// a window around the label, made terminal-safe; line numbers stay the file's.
struct Excerpt {
    src: NamedSource<String>,
    first_line: usize,
    lines: Vec<QuotedLine>,
}

impl Excerpt {
    fn of(file: &crate::source::SourceFile, spans: &[(usize, usize)]) -> Excerpt {
        let text = &file.text;
        let (lo, hi) = spans.iter().fold((usize::MAX, 0), |(lo, hi), &(o, l)| {
            (lo.min(o), hi.max(o + l))
        });
        let (lo, hi) = if lo == usize::MAX { (0, 0) } else { (lo, hi) };
        let first = file.line_of(lo).saturating_sub(CONTEXT_LINES);
        let last = (file.line_of(hi) + CONTEXT_LINES).min(file.line_count() - 1);
        let mut out = String::new();
        let mut lines = Vec::new();
        for line in first..=last {
            let range = file.line_range(line);
            let keep = if range.len() <= QUOTE_WIDTH {
                range.clone()
            } else {
                // The window starts a little before the first label on the line.
                let on_line = spans
                    .iter()
                    .map(|&(o, _)| o)
                    .filter(|o| range.contains(o))
                    .min()
                    .unwrap_or(range.start);
                let mut a = on_line.saturating_sub(QUOTE_WIDTH / 4).max(range.start);
                let mut b = (a + QUOTE_WIDTH).min(range.end);
                while !text.is_char_boundary(a) {
                    a -= 1;
                }
                while !text.is_char_boundary(b) {
                    b -= 1;
                }
                a..b
            };
            let lead = if keep.start > range.start { "…" } else { "" };
            let at = out.len() + lead.len();
            out.push_str(lead);
            out.push_str(&terminal_safe(&text[keep.clone()]));
            if keep.end < range.end {
                out.push('…');
            }
            if line < last {
                out.push('\n');
            }
            lines.push(QuotedLine {
                start: range.start,
                keep,
                at,
            });
        }
        Excerpt {
            src: NamedSource::new(terminal_safe(&file.name), out),
            first_line: first,
            lines,
        }
    }

    /// Where file offset `o` falls in the excerpt (clamped into its line's window).
    fn map(&self, o: usize) -> usize {
        let k = self
            .lines
            .partition_point(|l| l.start <= o)
            .saturating_sub(1);
        let Some(l) = self.lines.get(k) else {
            return 0;
        };
        l.at + o.clamp(l.keep.start, l.keep.end) - l.keep.start
    }
}

impl miette::SourceCode for Excerpt {
    fn read_span<'a>(
        &'a self,
        span: &miette::SourceSpan,
        before: usize,
        after: usize,
    ) -> Result<Box<dyn miette::SpanContents<'a> + 'a>, miette::MietteError> {
        let c = self.src.read_span(span, before, after)?;
        Ok(Box::new(miette::MietteSpanContents::new_named(
            c.name().unwrap_or_default().to_owned(),
            c.data(),
            *c.span(),
            c.line() + self.first_line,
            c.column(),
            c.line_count(),
        )))
    }
}

/// A diagnostic together with the source its labels point into.
struct Located<'a> {
    inner: &'a (dyn miette::Diagnostic + Send + Sync),
    src: Excerpt,
}

impl fmt::Debug for Located<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self.inner, f)
    }
}

impl fmt::Display for Located<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&terminal_safe(&self.inner.to_string()))
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
        let help = self.inner.help()?.to_string();
        Some(Box::new(terminal_safe(&help).into_owned()))
    }
    fn labels(&self) -> Option<Box<dyn Iterator<Item = miette::LabeledSpan> + '_>> {
        let labels = self.inner.labels()?.map(|l| {
            let text = l.label().map(|t| terminal_safe(t).into_owned());
            let (a, b) = (self.src.map(l.offset()), self.src.map(l.offset() + l.len()));
            let span = (a, b - a);
            if l.primary() {
                miette::LabeledSpan::new_primary_with_span(text, span)
            } else {
                miette::LabeledSpan::new_with_span(text, span)
            }
        });
        Some(Box::new(labels))
    }
    fn source_code(&self) -> Option<&dyn miette::SourceCode> {
        Some(&self.src)
    }
}
