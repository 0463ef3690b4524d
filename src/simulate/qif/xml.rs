//! The document's text: an indenting XML writer, escaping, the forms QIF's simple
//! types take (`xs:decimal`, `xs:NMTOKEN`, a relative URI), the document's ids and its
//! `QPId`.

/// QIF ids, numbered from 1 in the order they are handed out.
pub(super) struct Ids(pub(super) u32);

impl Ids {
    pub(super) fn take(&mut self) -> u32 {
        self.0 += 1;
        self.0
    }
}

/// The XML text being written, indented two spaces a level (the root's children one).
#[derive(Default)]
pub(super) struct Xml {
    pub(super) out: String,
    depth: usize,
}

impl Xml {
    fn start(&mut self, tag: &str, attrs: &[(&str, &str)]) {
        self.out.push_str(&"  ".repeat(self.depth + 1));
        self.out.push('<');
        self.out.push_str(tag);
        for (k, v) in attrs {
            self.out.push_str(&format!(" {k}=\"{}\"", escape(v)));
        }
    }

    /// `<tag attrs>` … `</tag>` around what `body` writes (`<tag attrs/>` when it
    /// writes nothing).
    pub(super) fn el(&mut self, tag: &str, attrs: &[(&str, &str)], body: impl FnOnce(&mut Xml)) {
        self.start(tag, attrs);
        let open = self.out.len();
        self.out.push_str(">\n");
        self.depth += 1;
        body(self);
        self.depth -= 1;
        if self.out.len() == open + 2 {
            self.out.truncate(open);
            self.out.push_str("/>\n");
            return;
        }
        self.out.push_str(&"  ".repeat(self.depth + 1));
        self.out.push_str(&format!("</{tag}>\n"));
    }

    /// An element with `n` children (the schema's `n` attribute).
    pub(super) fn list(&mut self, tag: &str, n: usize, body: impl FnOnce(&mut Xml)) {
        self.el(tag, &[("n", &n.to_string())], body);
    }

    /// A list of id references, none when `ids` is empty.
    pub(super) fn ids(&mut self, tag: &str, ids: &[u32]) {
        if !ids.is_empty() {
            self.list(tag, ids.len(), |x| {
                ids.iter().for_each(|id| x.text("Id", &id.to_string()))
            });
        }
    }

    pub(super) fn empty(&mut self, tag: &str, attrs: &[(&str, &str)]) {
        self.start(tag, attrs);
        self.out.push_str("/>\n");
    }

    /// `<tag>text</tag>`, the text escaped.
    pub(super) fn text(&mut self, tag: &str, text: &str) {
        self.start(tag, &[]);
        self.out.push_str(&format!(">{}</{tag}>\n", escape(text)));
    }

    /// `<outer><inner>text</inner></outer>`.
    pub(super) fn wrap(&mut self, outer: &str, inner: &str, text: &str) {
        self.el(outer, &[], |x| x.text(inner, text));
    }

    /// A comment: no `--` inside it, nor a `-` at its end, as XML asks.
    pub(super) fn comment(&mut self, text: &str) {
        let mut t = xml_chars(text);
        while t.contains("--") {
            t = t.replace("--", "- -");
        }
        self.out.push_str(&"  ".repeat(self.depth + 1));
        self.out
            .push_str(&format!("<!-- {} -->\n", t.trim_end_matches('-')));
    }
}

/// Characters XML 1.0 allows (a control character becomes `?`).
fn xml_chars(s: &str) -> String {
    s.chars()
        .map(|c| match c {
            '\t' | '\n' | '\r' => c,
            c if (c as u32) < 0x20 || c == '\u{FFFE}' || c == '\u{FFFF}' => '?',
            c => c,
        })
        .collect()
}

/// Text safe in an element or attribute.
fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in xml_chars(s).chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\t' => out.push_str("&#9;"),
            '\n' => out.push_str("&#10;"),
            '\r' => out.push_str("&#13;"),
            c => out.push(c),
        }
    }
    out
}

/// A label as an `xs:NMTOKEN` (letters, digits, `.-_:`; anything else `_`).
pub(super) fn nmtoken(s: &str) -> String {
    let t: String = s
        .chars()
        .map(|c| {
            if c.is_alphanumeric() || matches!(c, '.' | '-' | '_' | ':') {
                c
            } else {
                '_'
            }
        })
        .collect();
    if t.is_empty() {
        "_".into()
    } else {
        t
    }
}

/// A file name as a relative URI (percent-encoded but for unreserved characters).
pub(super) fn uri(name: &str) -> String {
    let mut out = String::new();
    for b in name.bytes() {
        if b.is_ascii_alphanumeric() || matches!(b, b'-' | b'.' | b'_' | b'~' | b'/') {
            out.push(b as char);
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out
}

/// A number as an `xs:decimal`: to the nanometre (or nano-degree), no exponent, no
/// `-0`; not-a-number is written as 0 (callers leave such values out).
pub(super) fn dec(x: f64) -> String {
    if !x.is_finite() {
        return "0".into();
    }
    let s = format!("{x:.9}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" || s.is_empty() {
        "0".into()
    } else {
        s.into()
    }
}

/// A vector as three decimals.
pub(super) fn v3(v: [f64; 3]) -> String {
    format!("{} {} {}", dec(v[0]), dec(v[1]), dec(v[2]))
}

/// A UUID (version 8, RFC 9562) from a 128-bit FNV-1a hash of `text`.
pub(super) fn qpid(text: &str) -> String {
    const PRIME: u128 = 0x0000000001000000000000000000013B;
    let mut h: u128 = 0x6c62272e07bb014262b821756295c58d;
    for b in text.bytes() {
        h ^= b as u128;
        h = h.wrapping_mul(PRIME);
    }
    let mut b = h.to_be_bytes();
    b[6] = (b[6] & 0x0f) | 0x80;
    b[8] = (b[8] & 0x3f) | 0x80;
    let hex: String = b.iter().map(|x| format!("{x:02x}")).collect();
    format!(
        "{}-{}-{}-{}-{}",
        &hex[0..8],
        &hex[8..12],
        &hex[12..16],
        &hex[16..20],
        &hex[20..32]
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_decimals_without_exponent_or_negative_zero() {
        assert_eq!(dec(-0.0), "0");
        assert_eq!(dec(-1e-12), "0");
        assert_eq!(dec(1e-7), "0.0000001");
        assert_eq!(dec(1e21), "1000000000000000000000");
        assert_eq!(dec(0.1 + 0.2), "0.3");
        assert_eq!(dec(f64::NAN), "0");
        assert_eq!(nmtoken("A B<1>"), "A_B_1_");
    }
}
