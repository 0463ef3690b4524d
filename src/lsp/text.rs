//! Positions and addresses as the protocol writes them: lines and UTF-16 columns,
//! `file://` URIs.
//!
//! **Decision: one line index per text, built once.** LSP 3.17 counts a position's
//! `character` in UTF-16 code units ("Position" in the base types; we offer no other
//! `positionEncoding`). [`LineIndex`] is the one place a byte offset becomes a position
//! and back: it keeps each line's start and every character wider in UTF-8 than in
//! UTF-16 with a running sum of the difference, so either way is two binary searches
//! and no walk over the text — a file with 100,000 diagnostics, even on one line, is
//! converted in linear time (rust-analyzer's `line-index` crate works the same way).
//! An open document keeps its index for its version (`Doc`); a file read
//! through the source map gets one per request or publication ([`FileLines`]).

use crate::source::{FileId, SourceMap, Span};
use lsp_types::{Position, Range, Uri};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// A text with the index of its lines and of its characters wider than one UTF-16 unit
/// per UTF-8 byte.
#[derive(Debug, Clone)]
pub(crate) struct LineIndex<T> {
    text: T,
    /// The byte offset where each line starts (after each `\n`); the first is 0.
    starts: Vec<usize>,
    /// Every non-ASCII character: its byte offset, its UTF-16 length and how many more
    /// bytes than UTF-16 units it takes.
    wide: Vec<Wide>,
    /// `extra[i]`: the sum of `Wide::extra` over `wide[..i]` (one more entry than `wide`).
    extra: Vec<usize>,
}

#[derive(Debug, Clone, Copy)]
struct Wide {
    at: usize,
    utf16: usize,
    extra: usize,
}

impl<T: AsRef<str>> LineIndex<T> {
    /// Indexes `text` (one pass).
    pub(crate) fn new(text: T) -> Self {
        let s = text.as_ref();
        let mut starts = vec![0];
        let mut wide = Vec::new();
        let mut extra = vec![0];
        for (i, c) in s.char_indices() {
            if c == '\n' {
                starts.push(i + 1);
            } else if !c.is_ascii() {
                let w = Wide {
                    at: i,
                    utf16: c.len_utf16(),
                    extra: c.len_utf8() - c.len_utf16(),
                };
                wide.push(w);
                extra.push(extra[extra.len() - 1] + w.extra);
            }
        }
        LineIndex {
            text,
            starts,
            wide,
            extra,
        }
    }

    /// The text indexed.
    pub(crate) fn text(&self) -> &str {
        self.text.as_ref()
    }

    /// The index of the first wide character at or after byte `offset`.
    fn wide_from(&self, offset: usize) -> usize {
        self.wide.partition_point(|w| w.at < offset)
    }

    /// The byte range of line `line`, without its `\n`.
    fn line(&self, line: usize) -> std::ops::Range<usize> {
        let start = self.starts[line];
        let end = self
            .starts
            .get(line + 1)
            .map_or(self.text().len(), |next| next - 1);
        start..end
    }

    /// The byte offset of a protocol position (clamped to the line's end and the text's
    /// end; a column inside a character lands on its start).
    pub(crate) fn offset(&self, pos: Position) -> usize {
        let Some(line) = usize::try_from(pos.line)
            .ok()
            .filter(|&l| l < self.starts.len())
        else {
            return self.text().len();
        };
        let line = self.line(line);
        let column = pos.character as usize;
        let first = self.wide_from(line.start);
        // The UTF-16 column where the line's wide character `j` starts.
        let column_of =
            |j: usize| self.wide[j].at - line.start - (self.extra[j] - self.extra[first]);
        // `k`: the first wide character of the line at or after the column.
        let (mut k, mut end) = (first, self.wide_from(line.end));
        while k < end {
            let mid = k + (end - k) / 2;
            if column_of(mid) < column {
                k = mid + 1;
            } else {
                end = mid;
            }
        }
        if k > first && column < column_of(k - 1) + self.wide[k - 1].utf16 {
            return self.wide[k - 1].at;
        }
        (line.start + column + (self.extra[k] - self.extra[first])).min(line.end)
    }

    /// The protocol position of byte `offset` (clamped to the text, and back to the start
    /// of a character it falls inside).
    pub(crate) fn position(&self, offset: usize) -> Position {
        let text = self.text();
        let mut offset = offset.min(text.len());
        while !text.is_char_boundary(offset) {
            offset -= 1;
        }
        let line = self.starts.partition_point(|&s| s <= offset) - 1;
        let start = self.starts[line];
        let narrower = self.extra[self.wide_from(offset)] - self.extra[self.wide_from(start)];
        Position {
            line: saturate(line),
            character: saturate(offset - start - narrower),
        }
    }

    /// The protocol range of bytes `r`.
    pub(crate) fn range(&self, r: std::ops::Range<usize>) -> Range {
        Range {
            start: self.position(r.start),
            end: self.position(r.end),
        }
    }
}

/// A count as the protocol's `uinteger` (a text past 4 GiB is not served).
fn saturate(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}

/// The line indexes of a source map's files, each built the first time a span in it is
/// asked for: one request or publication converts any number of spans in linear time.
pub(crate) struct FileLines<'a> {
    sources: &'a SourceMap,
    built: BTreeMap<FileId, LineIndex<&'a str>>,
}

impl<'a> FileLines<'a> {
    /// No index built yet.
    pub(crate) fn new(sources: &'a SourceMap) -> Self {
        FileLines {
            sources,
            built: BTreeMap::new(),
        }
    }

    /// The index of `file`.
    pub(crate) fn of(&mut self, file: FileId) -> &LineIndex<&'a str> {
        let sources = self.sources;
        self.built
            .entry(file)
            .or_insert_with(|| LineIndex::new(&sources.get(file).text))
    }

    /// The protocol range of a span.
    pub(crate) fn range(&mut self, span: Span) -> Range {
        self.of(span.file).range(span.range())
    }
}

/// The path a `file://` URI names; `None` for any other scheme.
pub(crate) fn path_of(uri: &Uri) -> Option<PathBuf> {
    let s = uri.as_str();
    let rest = s.strip_prefix("file://")?;
    // `file:///a/b` has an empty authority; `file://localhost/a/b` names this machine.
    let rest = rest.strip_prefix("localhost").unwrap_or(rest);
    if !rest.starts_with('/') {
        return None;
    }
    let bytes = rest.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            let hex = std::str::from_utf8(&bytes[i + 1..i + 3]).ok();
            if let Some(b) = hex.and_then(|h| u8::from_str_radix(h, 16).ok()) {
                out.push(b);
                i += 3;
                continue;
            }
        }
        out.push(bytes[i]);
        i += 1;
    }
    Some(PathBuf::from(String::from_utf8(out).ok()?))
}

/// The `file://` URI of an absolute path, percent-encoding what a URI path may not hold.
pub(crate) fn uri_of(path: &Path) -> Option<Uri> {
    let mut s = String::from("file://");
    for b in path.to_str()?.bytes() {
        match b {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'.' | b'_' | b'~' | b'/' => {
                s.push(b as char)
            }
            _ => s.push_str(&format!("%{b:02X}")),
        }
    }
    Uri::from_str(&s).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_count_utf16_units() {
        let text = "part p {\n  // Ø 𝑥\n  units mm\n}";
        let lines = LineIndex::new(text);
        for off in [0, 5, 9, 14, text.len()] {
            if text.is_char_boundary(off) {
                assert_eq!(lines.offset(lines.position(off)), off);
            }
        }
        // `Ø` is one UTF-16 unit, `𝑥` two: the space after `𝑥` is column 9.
        let after = text.find("𝑥").unwrap() + "𝑥".len();
        assert_eq!(lines.position(after), Position::new(1, 9));
        // Inside `𝑥`'s surrogate pair: its start.
        assert_eq!(lines.offset(Position::new(1, 8)), text.find("𝑥").unwrap());
        // Past the line's end: the end of the line; past the last line: the end.
        assert_eq!(lines.offset(Position::new(0, 99)), 8);
        assert_eq!(lines.offset(Position::new(9, 0)), text.len());
        assert_eq!(lines.offset(Position::new(u32::MAX, u32::MAX)), text.len());
        assert_eq!(lines.position(usize::MAX), Position::new(3, 1));
    }

    /// The walk from the text's start that the index replaces, as the reference.
    fn walked_position(text: &str, offset: usize) -> Position {
        let before = &text[..offset];
        let start = before.rfind('\n').map_or(0, |i| i + 1);
        let character = before[start..].chars().map(char::len_utf16).sum::<usize>();
        Position::new(before.matches('\n').count() as u32, character as u32)
    }

    fn walked_offset(text: &str, pos: Position) -> usize {
        let mut start = 0;
        for _ in 0..pos.line {
            match text[start..].find('\n') {
                Some(i) => start += i + 1,
                None => return text.len(),
            }
        }
        let end = text[start..].find('\n').map_or(text.len(), |i| start + i);
        let mut units = 0;
        for (i, c) in text[start..end].char_indices() {
            units += c.len_utf16();
            if units > pos.character as usize {
                return start + i;
            }
        }
        end
    }

    proptest::proptest! {
        /// The index agrees with the walk at every offset and position of texts mixing
        /// ASCII, two-, three- and four-byte characters and line breaks.
        #[test]
        fn the_index_agrees_with_a_walk(text in "[a\n\r±°Ø€𝑥😀 ]{0,40}") {
            let lines = LineIndex::new(text.as_str());
            for off in (0..=text.len()).filter(|&o| text.is_char_boundary(o)) {
                proptest::prop_assert_eq!(lines.position(off), walked_position(&text, off));
            }
            for line in 0..6 {
                for character in 0..45 {
                    let pos = Position::new(line, character);
                    proptest::prop_assert_eq!(lines.offset(pos), walked_offset(&text, pos));
                }
            }
        }
    }

    #[test]
    fn file_uris_round_trip() {
        let p = Path::new("/tmp/a dir/spec #1.insp");
        let uri = uri_of(p).unwrap();
        assert_eq!(uri.as_str(), "file:///tmp/a%20dir/spec%20%231.insp");
        assert_eq!(path_of(&uri).unwrap(), p);
        let other = Uri::from_str("untitled:Untitled-1").unwrap();
        assert_eq!(path_of(&other), None);
    }
}
