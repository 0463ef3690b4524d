//! The lexical rules of the DMIS we write, in one place: the number formatter, labels,
//! quoted text and comments, and line continuation. The reader checks the same rules.
//!
//! [`num`] writes 4 decimals without trailing zeros or `-0`, and [`real`] the same with
//! its decimal point, for every DMIS real; labels are legal `[A-Z][A-Z0-9_]{0,15}` and
//! unique per namespace whatever the spec's names (`Labels::fresh`); quoted text is
//! printable ASCII, drawing signs as words (`plain`); lines stay within 80 characters,
//! broken after a comma with a trailing `$` (`wrap`).

use std::collections::BTreeSet;

/// The longest line (characters).
pub(crate) const LINE_MAX: usize = 80;

/// The longest label.
pub(crate) const LABEL_MAX: usize = 16;

/// The one number formatter: at most 4 decimals (0.1 µm), no trailing zeros, no `-0`.
pub fn num(x: f64) -> String {
    if !x.is_finite() {
        return "0".into();
    }
    let s = format!("{x:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" || s.is_empty() {
        "0".into()
    } else {
        s.into()
    }
}

/// A real number as a DMIS parameter: [`num`] with its decimal point always written
/// (`50.0`, `-40.0`, `0.0`), as NIST's programs write reals, so that no reader takes a
/// real for an integer.
pub fn real(x: f64) -> String {
    let s = num(x);
    if s.contains('.') {
        s
    } else {
        s + ".0"
    }
}

/// Whether `s` is a legal label: `[A-Z][A-Z0-9_]{0,15}`.
pub(crate) fn is_label(s: &str) -> bool {
    let b = s.as_bytes();
    !b.is_empty()
        && b.len() <= LABEL_MAX
        && b[0].is_ascii_uppercase()
        && b.iter()
            .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || *c == b'_')
}

/// Text made safe for a quoted string or a comment: printable ASCII without the quote,
/// upper case, cut to `max` characters. The signs a drawing uses become the words an
/// operator reads (`30°` → `30 DEG`, `Ø8` → `DIA 8`, `±` → `+/-`, `µm` → `UM`); any
/// other character outside ASCII becomes `?`.
pub fn plain(s: &str, max: usize) -> String {
    ascii(s, max).to_ascii_uppercase()
}

/// [`plain`] without the upper case: quoted text as a person wrote it (a results file's
/// `FILNAM`, which NIST's `output.dms` keeps as its program wrote it).
pub fn ascii(s: &str, max: usize) -> String {
    let mut out = String::new();
    for c in s.chars() {
        match c {
            '\'' => out.push('"'),
            '°' => out.push_str(" DEG"),
            'Ø' | 'ø' | '⌀' => out.push_str("DIA "),
            '±' => out.push_str("+/-"),
            'µ' | 'μ' => out.push('U'),
            '×' => out.push('X'),
            '–' | '—' => out.push('-'),
            '→' => out.push_str("->"),
            c if (' '..='~').contains(&c) => out.push(c),
            _ => out.push('?'),
        }
    }
    out.chars().take(max).collect()
}

/// Labels per namespace (`F`, `S`, `T`, `DAT`, `D`): derived from spec names, legal and
/// unique whatever the names are.
#[derive(Debug, Default)]
pub struct Labels {
    used: BTreeSet<(String, String)>,
}

impl Labels {
    /// A fresh label in namespace `kind` derived from `name`.
    pub fn fresh(&mut self, kind: &str, name: &str) -> String {
        let mut base: String = name
            .chars()
            .map(|c| {
                let c = c.to_ascii_uppercase();
                if c.is_ascii_uppercase() || c.is_ascii_digit() {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        while base.contains("__") {
            base = base.replace("__", "_");
        }
        let mut base = base.trim_matches('_').to_string();
        if !base.starts_with(|c: char| c.is_ascii_uppercase()) {
            base.insert(0, 'X');
        }
        base.truncate(LABEL_MAX);
        let base = base.trim_end_matches('_').to_string();
        let mut label = base.clone();
        let mut k = 2;
        while self.used.contains(&(kind.to_string(), label.clone())) {
            let suffix = format!("_{k}");
            let keep = LABEL_MAX - suffix.len();
            let stem: String = base.chars().take(keep).collect();
            label = format!("{}{suffix}", stem.trim_end_matches('_'));
            k += 1;
        }
        debug_assert!(is_label(&label), "{label}");
        self.used.insert((kind.to_string(), label.clone()));
        label
    }
}

/// Splits a statement's text at commas outside quotes.
pub(crate) fn split_params(s: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut quoted = false;
    let mut start = 0;
    for (i, c) in s.char_indices() {
        match c {
            '\'' => quoted = !quoted,
            ',' if !quoted => {
                out.push(&s[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    out.push(&s[start..]);
    out
}

/// A statement as lines of at most [`LINE_MAX`] characters: broken after a comma
/// outside quotes, each broken line ending in `$`.
pub fn wrap(stmt: &str) -> Vec<String> {
    if stmt.chars().count() <= LINE_MAX {
        return vec![stmt.to_string()];
    }
    let parts = split_params(stmt);
    let mut lines = Vec::new();
    let mut cur = String::new();
    for (k, p) in parts.iter().enumerate() {
        let last = k + 1 == parts.len();
        let piece = if last { p.to_string() } else { format!("{p},") };
        // A broken line carries a trailing `$`.
        if !cur.is_empty() && cur.len() + piece.len() + usize::from(!last) > LINE_MAX {
            lines.push(format!("{cur}$"));
            cur.clear();
        }
        cur.push_str(&piece);
    }
    lines.push(cur);
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers() {
        assert_eq!(num(1.0), "1");
        assert_eq!(num(-0.00001), "0");
        assert_eq!(num(2.5), "2.5");
        assert_eq!(num(1.23456), "1.2346");
        assert_eq!(num(-40.0), "-40");
        assert_eq!(real(-40.0), "-40.0");
        assert_eq!(real(-0.00001), "0.0");
        assert_eq!(real(2.5), "2.5");
    }

    #[test]
    fn labels_are_legal_and_unique() {
        let mut l = Labels::default();
        assert_eq!(l.fresh("F", "top"), "TOP");
        assert_eq!(l.fresh("F", "top"), "TOP_2");
        assert_eq!(l.fresh("F", "3 holes/ø8 'x'"), "X3_HOLES_8_X");
        assert_eq!(
            l.fresh("F", "a_very_long_feature_name_indeed"),
            "A_VERY_LONG_FEAT"
        );
        assert_eq!(
            l.fresh("F", "a_very_long_feature_name_indeed"),
            "A_VERY_LONG_FE_2"
        );
        assert_eq!(l.fresh("F", ""), "X");
        assert_eq!(l.fresh("T", "top"), "TOP");
        for s in ["TOP_2", "X3_HOLES_8_X", "A_VERY_LONG_FE_2"] {
            assert!(is_label(s));
        }
        assert!(!is_label("3A") && !is_label("a") && !is_label("ABCDEFGHIJKLMNOPQ"));
    }

    #[test]
    fn long_statements_wrap_after_commas() {
        let s = format!("F(X)=FEAT/PLANE,{}", vec!["123.4567"; 20].join(","));
        let lines = wrap(&s);
        assert!(lines.len() > 1);
        for l in &lines[..lines.len() - 1] {
            assert!(l.ends_with(",$") && l.len() <= LINE_MAX, "{l}");
        }
        let joined: String = lines.iter().map(|l| l.trim_end_matches('$')).collect();
        assert_eq!(joined, s);
        assert_eq!(
            plain("it's ø8, tilted 30°", 80),
            "IT\"S DIA 8, TILTED 30 DEG"
        );
        assert_eq!(plain("a ☃", 80), "A ?");
    }
}
