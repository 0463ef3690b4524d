//! DMIS text into statements: the lexical rules of ANSI/DMIS 105.2 part 1 (5.3) §3 as
//! programs from other writers use them, not only ours.
//!
//! - A statement ends at the end of its line unless the line ends in `$` (outside a
//!   quoted string), which continues it on the next (NIST's `output.dms` breaks
//!   `FA(A_CIRCLE) = FEAT/CIRCLE, INNER, CART,  $`).
//! - `$$` starts a comment that runs to the end of the line, on a line of its own or
//!   after a statement.
//! - Blanks and tabs between tokens carry no meaning (`D(START) = DATSET/MCS`,
//!   `GOTO/50.0, 50.0, 175.0` in NIST's `simple_in.dms`), and neither does case outside
//!   quoted text: statements are kept in upper case without blanks, quoted text as
//!   written.
//! - A statement is `[KIND(label)=]MAJOR[/param,param,…]`; parameters split at commas
//!   outside quotes and parentheses (`ASSIGN/V(X)=SQRT(V(A)*V(A)+V(B)*V(B))`).

/// A logical statement before parsing: its text (continuations joined, the comment
/// cut) and the byte offset of its first line.
#[derive(Debug, PartialEq)]
pub(super) enum Line {
    /// A whole-line comment's text, without `$$` and one blank after it.
    Comment { text: String, at: usize },
    /// A statement's text, and where it starts.
    Statement { text: String, at: usize },
    /// A statement still continued (`$`) when the text ended.
    Unfinished { at: usize },
}

/// Where `$$` starts outside quotes, if it does.
fn comment_start(line: &str) -> Option<usize> {
    let mut quoted = false;
    let b = line.as_bytes();
    for i in 0..b.len() {
        match b[i] {
            b'\'' => quoted = !quoted,
            b'$' if !quoted && b.get(i + 1) == Some(&b'$') => return Some(i),
            _ => {}
        }
    }
    None
}

/// The physical lines of `text` as logical statements.
pub(super) fn lines(text: &str) -> Vec<Line> {
    let mut out = Vec::new();
    let mut offset = 0;
    let mut pending: Option<(usize, String)> = None;
    for raw in text.split_inclusive('\n') {
        let at = offset;
        offset += raw.len();
        let line = raw.trim_end_matches(['\n', '\r']);
        let (body, comment) = match comment_start(line) {
            Some(c) => (&line[..c], Some(&line[c + 2..])),
            None => (line, None),
        };
        let body = body.trim_end();
        if pending.is_none() && body.trim().is_empty() {
            if let Some(c) = comment {
                out.push(Line::Comment {
                    text: c.strip_prefix(' ').unwrap_or(c).to_string(),
                    at,
                });
            }
            continue;
        }
        let (start, mut acc) = pending.take().unwrap_or((at, String::new()));
        match body.strip_suffix('$') {
            Some(head) => {
                acc.push_str(head);
                pending = Some((start, acc));
            }
            None => {
                acc.push_str(body);
                out.push(Line::Statement {
                    text: acc,
                    at: start,
                });
            }
        }
    }
    if let Some((at, _)) = pending {
        out.push(Line::Unfinished { at });
    }
    out
}

/// The statement in canonical form: upper case and no blanks outside quoted text;
/// `None` when a quote is left open.
pub(super) fn canonical(s: &str) -> Option<String> {
    let mut out = String::with_capacity(s.len());
    let mut quoted = false;
    for c in s.chars() {
        match c {
            '\'' => {
                quoted = !quoted;
                out.push(c);
            }
            c if quoted => out.push(c),
            c if c.is_whitespace() => {}
            c => out.push(c.to_ascii_uppercase()),
        }
    }
    (!quoted).then_some(out)
}

/// Splits at commas outside quotes and parentheses.
pub(super) fn split(s: &str) -> Vec<String> {
    let mut out = Vec::new();
    let (mut quoted, mut depth, mut start) = (false, 0usize, 0);
    for (i, c) in s.char_indices() {
        match c {
            '\'' => quoted = !quoted,
            '(' if !quoted => depth += 1,
            ')' if !quoted => depth = depth.saturating_sub(1),
            ',' if !quoted && depth == 0 => {
                out.push(s[start..i].to_string());
                start = i + 1;
            }
            _ => {}
        }
    }
    out.push(s[start..].to_string());
    out
}

/// A statement's label (`KIND`, name), major word and parameters.
pub(super) type Parsed = (Option<(String, String)>, String, Vec<String>);

/// A statement in canonical form as its label, major word and parameters; `None` when
/// it has no legal major word.
pub(super) fn parse(s: &str) -> Option<Parsed> {
    let slash = s.find('/');
    let head = &s[..slash.unwrap_or(s.len())];
    let (label, major) = match head.split_once('=') {
        Some((l, m)) => {
            let (kind, name) = l.strip_suffix(')')?.split_once('(')?;
            let word = |w: &str| {
                !w.is_empty()
                    && w.starts_with(|c: char| c.is_ascii_uppercase())
                    && w.bytes()
                        .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == b'_')
            };
            if !word(kind) || name.is_empty() || name.contains(['(', ')', '\'']) {
                return None;
            }
            (Some((kind.to_string(), name.to_string())), m)
        }
        None => (None, head),
    };
    let legal = major.starts_with(|c: char| c.is_ascii_uppercase())
        && major
            .bytes()
            .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == b'_');
    if !legal {
        return None;
    }
    let params = match slash {
        Some(k) => split(&s[k + 1..]),
        None => Vec::new(),
    };
    Some((label, major.to_string(), params))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blanks_case_and_continuation_carry_no_meaning() {
        let text = "  d(start) = datset/mcs\nGOTO/50.0, 50.0, $\n   175.0 $$ high\n$$ a note\n";
        let ls = lines(text);
        assert_eq!(ls.len(), 3);
        let Line::Statement { text: t, .. } = &ls[1] else {
            panic!()
        };
        assert_eq!(canonical(t).unwrap(), "GOTO/50.0,50.0,175.0");
        let Line::Statement { text: t, .. } = &ls[0] else {
            panic!()
        };
        let (label, major, params) = parse(&canonical(t).unwrap()).unwrap();
        assert_eq!(label, Some(("D".into(), "START".into())));
        assert_eq!(
            (major.as_str(), params),
            ("DATSET", vec!["MCS".to_string()])
        );
        assert_eq!(
            ls[2],
            Line::Comment {
                text: "a note".into(),
                at: text.find("$$ a").unwrap()
            }
        );
    }

    #[test]
    fn quoted_text_keeps_its_case_blanks_and_dollars() {
        let c = canonical("TEXT/OPER, 'Place it $$ here, now'").unwrap();
        assert_eq!(c, "TEXT/OPER,'Place it $$ here, now'");
        assert_eq!(comment_start("TEXT/OPER,'a $$ b' $$ c"), Some(19));
        assert_eq!(parse(&c).unwrap().2.len(), 2);
        assert!(canonical("TEXT/OPER,'open").is_none());
    }

    #[test]
    fn parameters_split_outside_parentheses() {
        assert_eq!(
            split("V(X)=MAX(V(A),V(B)),'a,b',3"),
            ["V(X)=MAX(V(A),V(B))", "'a,b'", "3"]
        );
        assert!(parse("1GOTO/1,2,3").is_none());
        assert!(parse("F()=FEAT/POINT").is_none());
        assert_eq!(parse("ENDMES").unwrap().1, "ENDMES");
    }
}
