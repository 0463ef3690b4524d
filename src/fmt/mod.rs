//! `inspc fmt`: one canonical layout for `.insp` files — entry [`format`].
//!
//! The formatter works on tokens, not on the syntax tree, so that every comment stays
//! where it was and a statement never moves to another line (a newline ends a statement,
//! so joining or splitting lines could change what a spec says). What it decides:
//! - indentation: four spaces per open `{`, `(` or `[` before the line's first token, one
//!   level less for a line that starts by closing one;
//! - spacing inside a line: one space where the source had any, none where it had none,
//!   except around the punctuation whose spacing never changes the meaning — `=` and `{`
//!   get one space before, `,` `;` `:` none before and one after, `(` `[` none after,
//!   `)` `]` none before, `}` one before (an import's `{…}` is tight);
//! - alignment: the `=` of consecutive `feature`, `datum`, `tolerance`… lines of one
//!   keyword, a face expression's `+ …` continuation lines under its first term, and
//!   trailing comments of consecutive lines, one space past the longest line;
//! - lines: no trailing blanks, at most one empty line in a row, none at the start or
//!   end, and one newline at the end; a `/* */` comment is kept as written, and what
//!   follows it stays on its last line.
//!
//! The caller formats only a file that parses (`inspc fmt` checks first), and the result
//! parses to the same spec (`tests/suite/fmt.rs` checks every `.insp` of the repository
//! for that and for idempotence).

/// One token of a line.
#[derive(Debug, Clone, PartialEq)]
enum Tok<'a> {
    /// Anything else: a name, a number, a path with its `::`, `.` and indices, `..`, `±`.
    Word(&'a str),
    /// One of `{ } ( ) [ ] , ; = :`.
    Punct(char),
    /// A string literal with its quotes.
    Str(&'a str),
    /// A `//` comment, or a `/* */` one (over several lines, kept as written).
    Comment(&'a str),
}

/// A source line as tokens, each with whether whitespace preceded it.
type Line<'a> = Vec<(Tok<'a>, bool)>;

fn is_punct(c: char) -> bool {
    matches!(c, '{' | '}' | '(' | ')' | '[' | ']' | ',' | ';' | '=' | ':')
}

/// Whether the `:` at byte `k` of `rest` closes a `::` (the one before it opens it).
fn colon_pair(rest: &str, k: usize) -> bool {
    k > 0 && rest[..k].ends_with(':') && !rest[..k - 1].ends_with(':')
}

/// Splits the source into lines of tokens.
fn lex(src: &str) -> Vec<Line<'_>> {
    let mut lines = vec![Vec::new()];
    let bytes = src.as_bytes();
    let mut i = 0;
    let mut space = false;
    while i < bytes.len() {
        let rest = &src[i..];
        let c = rest.chars().next().unwrap_or(' ');
        let cur = lines.len() - 1;
        if c == '\n' {
            lines.push(Vec::new());
            space = false;
            i += 1;
        } else if c == ' ' || c == '\t' || c == '\r' || c == '\u{FEFF}' {
            space = true;
            i += c.len_utf8();
        } else if rest.starts_with("//") {
            let end = rest.find('\n').unwrap_or(rest.len());
            lines[cur].push((Tok::Comment(rest[..end].trim_end()), space));
            i += end;
        } else if rest.starts_with("/*") {
            // Kept as written, newlines and all: they are inside the comment, so the
            // tokens after it stay on its line.
            let end = rest.find("*/").map_or(rest.len(), |e| e + 2);
            lines[cur].push((Tok::Comment(&rest[..end]), space));
            i += end;
            space = false;
        } else if c == '"' {
            let mut j = 1;
            let b = rest.as_bytes();
            while j < b.len() && b[j] != b'"' && b[j] != b'\n' {
                j += if b[j] == b'\\' { 2 } else { 1 };
            }
            let end = (j + 1).min(rest.len());
            lines[cur].push((Tok::Str(&rest[..end]), space));
            i += end;
            space = false;
        } else if is_punct(c) && !rest.starts_with("::") {
            lines[cur].push((Tok::Punct(c), space));
            i += 1;
            space = false;
        } else {
            // A word: up to whitespace, a comment, a string or punctuation (`::` stays in).
            let mut j = 0;
            for (k, ch) in rest.char_indices() {
                let at = &rest[k..];
                if ch.is_whitespace()
                    || ch == '\u{FEFF}'
                    || ch == '"'
                    || at.starts_with("//")
                    || at.starts_with("/*")
                    || (is_punct(ch)
                        && !(ch == ':' && (at.starts_with("::") || colon_pair(rest, k))))
                {
                    break;
                }
                j = k + ch.len_utf8();
            }
            let j = j.max(c.len_utf8());
            lines[cur].push((Tok::Word(&rest[..j]), space));
            i += j;
            space = false;
        }
    }
    lines
}

/// One output line before alignment.
struct Out {
    indent: usize,
    /// The code; for a `kw name = …` line, only `kw name`.
    code: String,
    /// For a `kw name = …` line, what follows the `=`.
    rest: Option<String>,
    /// A trailing `//` comment.
    comment: Option<String>,
    /// Whether the line continues a face expression (`+ …`).
    cont: bool,
}

/// The canonical layout of `src`, checked: `None` when `src` does not parse or when the
/// layout would change its parse tree ([`crate::syntax::outline`]) — a formatter bug, and
/// then nothing may be written.
pub fn format_checked(src: &str) -> Option<String> {
    let before = crate::syntax::outline(src)?;
    let formatted = format(src);
    (crate::syntax::outline(&formatted).as_ref() == Some(&before)).then_some(formatted)
}

/// The canonical layout of `src`, which should parse.
pub fn format(src: &str) -> String {
    let mut outs: Vec<Option<Out>> = Vec::new();
    let mut depth: i64 = 0;
    // Whether each open bracket is an import selection (`use a::{…}`), written tight.
    let mut tight: Vec<bool> = Vec::new();
    for line in &lex(src) {
        if line.is_empty() {
            if matches!(outs.last(), Some(Some(_))) {
                outs.push(None);
            }
            continue;
        }
        let closing = line
            .iter()
            .take_while(|(t, _)| matches!(t, Tok::Punct('}' | ')' | ']')))
            .count() as i64;
        let indent = 4 * (depth - closing).max(0) as usize;
        let mut toks: &[(Tok, bool)] = line;
        let mut comment = None;
        if let [before @ .., (Tok::Comment(c), _)] = toks {
            if !before.is_empty() && c.starts_with("//") {
                comment = Some(c.to_string());
                toks = before;
            }
        }
        let head = matches!(
            toks,
            [
                (Tok::Word(_), _),
                (Tok::Word(_), _),
                (Tok::Punct('='), _),
                _,
                ..
            ]
        );
        let (mut code, mut rest) = (String::new(), None::<String>);
        let mut prev: Option<&Tok> = None;
        for (k, (tok, spaced)) in toks.iter().enumerate() {
            if head && k == 2 {
                // The `=` of a `kw name =` head: what follows is laid out apart.
                rest = Some(String::new());
                prev = Some(tok);
                continue;
            }
            let in_tight = tight.last().copied().unwrap_or(false);
            let target = rest.as_mut().unwrap_or(&mut code);
            if let Some(p) = prev {
                let space = match (p, tok) {
                    (Tok::Punct('{'), _) if in_tight => false,
                    (_, Tok::Punct('}')) if in_tight => false,
                    _ => space_between(p, tok, *spaced),
                };
                if space && !(head && k == 3) {
                    target.push(' ');
                }
            }
            match tok {
                Tok::Word(w) | Tok::Str(w) | Tok::Comment(w) => target.push_str(w),
                Tok::Punct(c) => target.push(*c),
            }
            match tok {
                Tok::Punct('{') => {
                    tight.push(matches!(prev, Some(Tok::Word(w)) if w.ends_with("::")));
                    depth += 1;
                }
                Tok::Punct('(' | '[') => {
                    tight.push(false);
                    depth += 1;
                }
                Tok::Punct('}' | ')' | ']') => {
                    tight.pop();
                    depth -= 1;
                }
                _ => {}
            }
            prev = Some(tok);
        }
        let cont = matches!(toks.first(), Some((Tok::Word("+"), _)));
        outs.push(Some(Out {
            indent,
            code,
            rest,
            comment,
            cont,
        }));
    }
    while matches!(outs.last(), Some(None)) {
        outs.pop();
    }
    let lines = align(outs);
    let mut text = String::with_capacity(src.len());
    for l in lines {
        text.push_str(&l);
        text.push('\n');
    }
    text
}

/// Lays out the lines: `kw name = …` heads aligned in runs of such lines with one
/// keyword at one indent,
/// a continuation line under the start of its statement's expression, and trailing
/// comments aligned in runs of lines that have one.
fn align(outs: Vec<Option<Out>>) -> Vec<String> {
    let width = |s: &str| s.chars().count();
    // The width each head is padded to: the widest of its run.
    let mut pad_to: Vec<usize> = vec![0; outs.len()];
    let mut k = 0;
    while k < outs.len() {
        // A run: consecutive heads with one keyword at one indent.
        let key = |o: &Option<Out>| {
            o.as_ref().filter(|o| o.rest.is_some()).map(|o| {
                let kw = o.code.split(' ').next().unwrap_or("").to_string();
                (o.indent, kw)
            })
        };
        let Some(first) = key(&outs[k]) else {
            k += 1;
            continue;
        };
        let mut end = k;
        while end < outs.len() && key(&outs[end]).as_ref() == Some(&first) {
            end += 1;
        }
        let widest = outs[k..end]
            .iter()
            .flatten()
            .map(|o| width(&o.code))
            .max()
            .unwrap_or(0);
        pad_to[k..end].fill(widest);
        k = end;
    }
    // Lines without their comments; where each statement's expression starts.
    let mut code: Vec<Option<(String, Option<String>)>> = Vec::with_capacity(outs.len());
    let mut expr_col: Option<usize> = None;
    for (o, &pad) in outs.into_iter().zip(&pad_to) {
        let Some(o) = o else {
            code.push(None);
            continue;
        };
        let line = if let Some(rest) = &o.rest {
            let filled = pad - width(&o.code);
            expr_col = Some(o.indent + pad + 3);
            format!(
                "{}{}{} = {rest}",
                " ".repeat(o.indent),
                o.code,
                " ".repeat(filled)
            )
        } else if o.cont {
            let col = expr_col.unwrap_or(o.indent + 4);
            format!("{}{}", " ".repeat(col), o.code)
        } else {
            expr_col = None;
            format!("{}{}", " ".repeat(o.indent), o.code)
        };
        code.push(Some((line, o.comment)));
    }
    // Trailing comments, aligned in runs.
    let mut out: Vec<String> = Vec::with_capacity(code.len());
    let mut k = 0;
    while k < code.len() {
        let has = |c: &Option<(String, Option<String>)>| matches!(c, Some((_, Some(_))));
        let mut end = k;
        while end < code.len() && has(&code[end]) {
            end += 1;
        }
        if end == k {
            out.push(code[k].as_ref().map_or(String::new(), |(l, _)| l.clone()));
            k += 1;
            continue;
        }
        let col = code[k..end]
            .iter()
            .flatten()
            .map(|(l, _)| width(l))
            .max()
            .unwrap_or(0)
            + 1;
        for (l, c) in code[k..end].iter().flatten() {
            let c = c.as_deref().unwrap_or("");
            out.push(format!("{l}{}{c}", " ".repeat(col - width(l))));
        }
        k = end;
    }
    out
}

/// Whether one space separates `a` and the following `b` on a line; `spaced`: whether
/// the source had whitespace there.
fn space_between(a: &Tok, b: &Tok, spaced: bool) -> bool {
    use Tok::*;
    match (a, b) {
        (_, Comment(_)) => true,
        // `use std::probes::{…}`: the selection stays on its `::`.
        (Word(w), Punct('{')) if w.ends_with("::") => false,
        (_, Punct(',' | ';' | ':' | ')' | ']')) => false,
        (Punct('(' | '['), _) => false,
        (Punct(',' | ';' | ':' | '='), _) => true,
        (_, Punct('=' | '{' | '}')) => true,
        (Punct('{'), _) => true,
        _ => spaced,
    }
}
