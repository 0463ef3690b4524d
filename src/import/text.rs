//! Text from a STEP or QIF file into the written spec, through one function,
//! [`source`]: a datum letter, a tolerance's or label's name, a unit, a note, the file's
//! own path all come from outside and must not change what the spec says.
//!
//! **Decision** (per place, from `grammar/insp.pest`):
//! - an **identifier** (`ident`: an ASCII letter or `_`, then letters, digits and `_`)
//!   keeps its valid characters and has each other one replaced by `_`, a leading
//!   digit or an empty name prefixed by `x_`, and a keyword (a `kw_` rule or
//!   `block_kw` word of the grammar) suffixed by `_`. The map is deterministic; where
//!   two names map to one, the caller's namer keeps them apart (`_2`, `_3`, …), so no
//!   two items collide. A datum letter has stricter rules and its own namer
//!   ([`DatumLetters`]).
//! - a **string literal** (`string_inner`) escapes `\` and `"`, a newline and a tab with
//!   the escapes the lowering knows, and every other character a reader would not see
//!   — a control character, U+2028/U+2029 (line ends in some editors) and the
//!   bidirectional overrides ("Trojan Source", CVE-2021-42574) — as `\u{…}`, so the
//!   value reads back exactly.
//! - a **comment** (`//` to the end of the line) cannot end its line early: the same
//!   characters become the text `\u{…}`, so what the file says still shows.

use std::collections::{BTreeMap, BTreeSet};

/// Where file text is written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Place {
    /// A name the grammar reads as `ident`.
    Identifier,
    /// The inside of a `"…"` string.
    Literal,
    /// The text of a `//` comment.
    Comment,
}

/// `raw`, from a file, as source text at `place` (see the module's decision).
pub(super) fn source(raw: &str, place: Place) -> String {
    match place {
        Place::Identifier => identifier(raw),
        Place::Literal => escaped(raw, true),
        Place::Comment => escaped(raw, false),
    }
}

fn identifier(raw: &str) -> String {
    let mut id: String = raw
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if !id.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_') {
        id.insert_str(0, "x_");
    }
    if crate::syntax::KEYWORDS.contains(&id.as_str()) {
        id.push('_');
    }
    id
}

/// A character no reader sees for what it is: a control character, a line or
/// paragraph separator, a bidirectional embedding, override or isolate.
fn unseen(c: char) -> bool {
    c.is_control()
        || matches!(
            c,
            '\u{2028}' | '\u{2029}' | '\u{200E}' | '\u{200F}' | '\u{202A}'..='\u{202E}'
                | '\u{2066}'..='\u{2069}'
        )
}

/// `raw` with what would end a line or hide itself written as escapes; in a literal,
/// also `\` and `"`, and newline and tab as `\n` and `\t`.
fn escaped(raw: &str, literal: bool) -> String {
    let mut out = String::with_capacity(raw.len());
    for c in raw.chars() {
        match c {
            '\\' if literal => out.push_str("\\\\"),
            '"' if literal => out.push_str("\\\""),
            '\n' if literal => out.push_str("\\n"),
            '\t' if literal => out.push_str("\\t"),
            c if unseen(c) => out.push_str(&format!("\\u{{{:x}}}", c as u32)),
            c => out.push(c),
        }
    }
    out
}

/// Datum letters as the spec writes them: ASME Y14.5 names datums with one or two
/// capital letters other than I, O and Q (what `resolve` warns about otherwise). A
/// file's letter that is one is kept; any other is written as its capitals if those
/// are a free letter, else as the first free letter (`A`, `B`, … `Z`, `AA`, …). The
/// file's valid letters are taken first, so a renamed datum never takes one of them.
pub(super) struct DatumLetters {
    by_file: BTreeMap<String, String>,
}

/// Whether `s` is a datum letter as ASME Y14.5 names datums.
fn is_datum_letter(s: &str) -> bool {
    (1..=2).contains(&s.len())
        && s.chars()
            .all(|c| c.is_ascii_uppercase() && !matches!(c, 'I' | 'O' | 'Q'))
}

impl DatumLetters {
    /// The letters for every letter of the file, in the order given.
    pub(super) fn new<'a>(file_letters: impl IntoIterator<Item = &'a str>) -> DatumLetters {
        let letters: Vec<&str> = file_letters.into_iter().collect();
        let mut taken: BTreeSet<String> = letters
            .iter()
            .filter(|l| is_datum_letter(l))
            .map(|l| l.to_string())
            .collect();
        let singles = ('A'..='Z').filter(|c| !matches!(c, 'I' | 'O' | 'Q'));
        let mut fresh = singles.clone().map(String::from).chain(
            singles
                .clone()
                .flat_map(move |a| singles.clone().map(move |b| format!("{a}{b}"))),
        );
        let mut by_file = BTreeMap::new();
        for l in letters {
            if by_file.contains_key(l) {
                continue;
            }
            let written = if is_datum_letter(l) {
                l.to_string()
            } else {
                let caps: String = l
                    .chars()
                    .filter(char::is_ascii_alphabetic)
                    .map(|c| c.to_ascii_uppercase())
                    .collect();
                let name = if is_datum_letter(&caps) && !taken.contains(&caps) {
                    caps
                } else {
                    // 23 + 23² letters: a file holds fewer datums than that.
                    fresh
                        .by_ref()
                        .find(|f| !taken.contains(f))
                        .unwrap_or_else(|| format!("D{}", by_file.len()))
                };
                taken.insert(name.clone());
                name
            };
            by_file.insert(l.to_string(), written);
        }
        DatumLetters { by_file }
    }

    /// The spec's letter for the file's.
    pub(super) fn of(&self, file_letter: &str) -> String {
        self.by_file
            .get(file_letter)
            .cloned()
            .unwrap_or_else(|| source(file_letter, Place::Identifier))
    }

    /// The file's letters written otherwise, as (file's, spec's), in the file's order.
    pub(super) fn renamed(&self) -> impl Iterator<Item = (&String, &String)> {
        self.by_file.iter().filter(|(f, w)| f != w)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identifiers_are_valid_and_not_keywords() {
        assert_eq!(source("datum_a", Place::Identifier), "datum_a");
        assert_eq!(source("}\npart evil {", Place::Identifier), "__part_evil__");
        assert_eq!(source("", Place::Identifier), "x_");
        assert_eq!(source("9lives", Place::Identifier), "x_9lives");
        assert_eq!(source("part", Place::Identifier), "part_");
        assert_eq!(source("Ø", Place::Identifier), "_");
    }

    #[test]
    fn literals_and_comments_escape_what_ends_them() {
        assert_eq!(
            source("a\"b\\c\nd\te\r\u{202E}", Place::Literal),
            "a\\\"b\\\\c\\nd\\te\\u{d}\\u{202e}"
        );
        assert_eq!(
            source("x\n}\npart evil {\r\u{2028}", Place::Comment),
            "x\\u{a}}\\u{a}part evil {\\u{d}\\u{2028}"
        );
        assert_eq!(source("Ø 5 \"mm\"", Place::Comment), "Ø 5 \"mm\"");
    }

    #[test]
    fn datum_letters_are_kept_or_renamed_without_clashes() {
        let l = DatumLetters::new(["A", "b", "\"}", "B", "I", ""]);
        assert_eq!(l.of("A"), "A");
        assert_eq!(l.of("B"), "B");
        // `b`'s capitals are taken by the file's `B`.
        assert_eq!(l.of("b"), "C");
        assert_eq!(l.of("\"}"), "D");
        assert_eq!(l.of("I"), "E");
        assert_eq!(l.of(""), "F");
    }
}
