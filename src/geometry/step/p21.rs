//! ISO 10303-21 ("Part 21") exchange files: the clear-text encoding every STEP file uses.
//!
//! The reader keeps the DATA section as a table of entity instances, `#id = NAME(...)` or
//! the complex form `#id = (A(...) B(...))`, with their parameters as a small tree. It
//! knows nothing of any schema: what a `PLANE` or an `EDGE_CURVE` means is `brep.rs`'s
//! business. Errors carry the line they were found on.

use std::collections::HashMap;

/// One parameter of an entity instance. Kept small (24 bytes): a file's memory is
/// mostly its parameters, so strings and lists are boxed slices and names interned.
#[derive(Debug, Clone, PartialEq)]
pub enum Param {
    /// `$`: not given.
    Null,
    /// `*`: derived by the schema.
    Derived,
    /// An integer.
    Int(i64),
    /// A real.
    Real(f64),
    /// A string, with `''` and `\X\..` escapes left as written.
    Str(Box<str>),
    /// An enumeration or boolean, `.T.` → `T`.
    Enum(Name),
    /// A reference `#id`.
    Ref(u64),
    /// A list `( ... )`.
    List(Box<[Param]>),
    /// A typed value such as `LENGTH_MEASURE(2.5)`.
    Typed(Box<Typed>),
    /// A binary `"..."`.
    Binary,
}

/// A typed parameter `NAME(params)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Typed {
    /// The type, upper case.
    pub name: Name,
    /// Its parameters.
    pub params: Box<[Param]>,
}

/// An upper-case name (entity type, enumeration value), interned per file: the same
/// name costs one allocation however often the file writes it.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Name(std::sync::Arc<str>);

impl Name {
    /// A name not interned (one of a kind).
    pub(crate) fn new(text: &str) -> Name {
        Name(text.into())
    }

    /// The name's text.
    pub fn as_str(&self) -> &str {
        &self.0
    }
}

impl std::ops::Deref for Name {
    type Target = str;
    fn deref(&self) -> &str {
        &self.0
    }
}

impl std::borrow::Borrow<str> for Name {
    fn borrow(&self) -> &str {
        &self.0
    }
}

impl PartialEq<str> for Name {
    fn eq(&self, other: &str) -> bool {
        &*self.0 == other
    }
}

impl PartialEq<&str> for Name {
    fn eq(&self, other: &&str) -> bool {
        &*self.0 == *other
    }
}

impl std::fmt::Display for Name {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl Param {
    /// The number, for an integer or a real.
    pub fn real(&self) -> Option<f64> {
        match self {
            Param::Real(x) => Some(*x),
            Param::Int(i) => Some(*i as f64),
            Param::Typed(t) if t.params.len() == 1 => t.params[0].real(),
            _ => None,
        }
    }

    /// The referenced instance.
    pub fn reference(&self) -> Option<u64> {
        match self {
            Param::Ref(r) => Some(*r),
            _ => None,
        }
    }

    /// The items of a list.
    pub fn list(&self) -> Option<&[Param]> {
        match self {
            Param::List(v) => Some(v),
            _ => None,
        }
    }

    /// A boolean or logical: `.T.` is true, `.F.` false.
    pub(crate) fn boolean(&self) -> Option<bool> {
        match self {
            Param::Enum(e) if *e == "T" => Some(true),
            Param::Enum(e) if *e == "F" => Some(false),
            _ => None,
        }
    }

    /// The enumeration's value.
    pub(crate) fn enumeration(&self) -> Option<&str> {
        match self {
            Param::Enum(e) => Some(e),
            _ => None,
        }
    }

    /// The string's text.
    pub fn string(&self) -> Option<&str> {
        match self {
            Param::Str(s) => Some(s),
            _ => None,
        }
    }
}

/// One `NAME(params)` record: a whole simple instance, or one part of a complex one.
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    /// The entity type, upper case.
    pub name: Name,
    /// Its parameters.
    pub params: Box<[Param]>,
}

/// An entity instance: one record, or the several records of a complex instance.
#[derive(Debug, Clone, PartialEq)]
pub struct Instance {
    /// The records; one for a simple instance.
    pub records: Box<[Record]>,
    /// The line its `#id` stands on (1-based).
    pub line: usize,
}

impl Instance {
    /// The record of type `name`, if the instance has one.
    pub fn record(&self, name: &str) -> Option<&Record> {
        self.records.iter().find(|r| r.name == name)
    }

    /// Whether the instance has a record of type `name` (simple or complex).
    pub fn is(&self, name: &str) -> bool {
        self.record(name).is_some()
    }

    /// The first record's type (for messages).
    pub(crate) fn type_name(&self) -> String {
        if self.records.len() == 1 {
            self.records[0].name.to_string()
        } else {
            let names: Vec<&str> = self.records.iter().map(|r| r.name.as_str()).collect();
            format!("({})", names.join(" "))
        }
    }
}

/// A parsed exchange file.
#[derive(Debug, Default)]
pub struct P21 {
    /// The schemas FILE_SCHEMA names.
    pub schemas: Vec<String>,
    /// The DATA section's instances by id.
    pub instances: HashMap<u64, Instance>,
    /// Instance ids in the file's order.
    pub order: Vec<u64>,
}

/// A syntax error at a line.
#[derive(Debug, Clone, PartialEq)]
pub struct SyntaxError {
    /// 1-based line.
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

/// How deep parameter lists may nest: deeper than any schema's aggregates (a B-spline
/// surface's weights are two deep), shallow enough that the recursive descent below
/// and the drop of the tree cannot exhaust the stack.
pub(crate) const MAX_NESTING: usize = 32;

struct Lexer<'a> {
    s: &'a [u8],
    i: usize,
    line: usize,
    /// How many lists the parser is inside.
    depth: usize,
    /// The names read so far, each stored once.
    names: std::collections::HashSet<Name>,
}

type Res<T> = Result<T, SyntaxError>;

impl<'a> Lexer<'a> {
    fn err<T>(&self, message: impl Into<String>) -> Res<T> {
        Err(SyntaxError {
            line: self.line,
            message: message.into(),
        })
    }

    /// Skips white space and `/* comments */`.
    fn skip(&mut self) -> Res<()> {
        loop {
            match self.s.get(self.i) {
                Some(b'\n') => {
                    self.line += 1;
                    self.i += 1;
                }
                Some(c) if c.is_ascii_whitespace() => self.i += 1,
                Some(b'/') if self.s.get(self.i + 1) == Some(&b'*') => {
                    let start = self.line;
                    self.i += 2;
                    loop {
                        match self.s.get(self.i) {
                            None => {
                                self.line = start;
                                return self.err("a comment is never closed");
                            }
                            Some(b'*') if self.s.get(self.i + 1) == Some(&b'/') => {
                                self.i += 2;
                                break;
                            }
                            Some(b'\n') => {
                                self.line += 1;
                                self.i += 1;
                            }
                            _ => self.i += 1,
                        }
                    }
                }
                _ => return Ok(()),
            }
        }
    }

    fn peek(&mut self) -> Res<Option<u8>> {
        self.skip()?;
        Ok(self.s.get(self.i).copied())
    }

    fn expect(&mut self, c: u8) -> Res<()> {
        match self.peek()? {
            Some(x) if x == c => {
                self.i += 1;
                Ok(())
            }
            Some(x) => self.err(format!("expected `{}`, found `{}`", c as char, x as char)),
            None => self.err(format!(
                "expected `{}`, found the end of the file (is it truncated?)",
                c as char
            )),
        }
    }

    fn keyword(&mut self) -> Res<Name> {
        self.skip()?;
        let start = self.i;
        while let Some(c) = self.s.get(self.i) {
            if c.is_ascii_alphanumeric() || *c == b'_' || *c == b'-' {
                self.i += 1;
            } else {
                break;
            }
        }
        if start == self.i {
            return match self.s.get(self.i) {
                Some(c) => self.err(format!("expected a name, found `{}`", *c as char)),
                None => self.err("expected a name, found the end of the file (is it truncated?)"),
            };
        }
        // Only ASCII letters, digits, `_` and `-`: the bytes are UTF-8.
        let text = std::str::from_utf8(&self.s[start..self.i]).unwrap_or_default();
        let upper = text.to_ascii_uppercase();
        if let Some(n) = self.names.get(upper.as_str()) {
            return Ok(n.clone());
        }
        let n = Name(upper.into());
        self.names.insert(n.clone());
        Ok(n)
    }

    fn integer(&mut self) -> Res<u64> {
        let start = self.i;
        while self.s.get(self.i).is_some_and(|c| c.is_ascii_digit()) {
            self.i += 1;
        }
        std::str::from_utf8(&self.s[start..self.i])
            .ok()
            .and_then(|t| t.parse().ok())
            .map_or_else(|| self.err("expected an instance number after `#`"), Ok)
    }

    fn number(&mut self) -> Res<Param> {
        let start = self.i;
        if matches!(self.s.get(self.i), Some(b'+' | b'-')) {
            self.i += 1;
        }
        let mut real = false;
        while let Some(&c) = self.s.get(self.i) {
            match c {
                b'0'..=b'9' => self.i += 1,
                b'.' => {
                    real = true;
                    self.i += 1;
                }
                b'E' | b'e' => {
                    real = true;
                    self.i += 1;
                    if matches!(self.s.get(self.i), Some(b'+' | b'-')) {
                        self.i += 1;
                    }
                }
                _ => break,
            }
        }
        let text = std::str::from_utf8(&self.s[start..self.i]).unwrap_or("");
        let bad = || SyntaxError {
            line: self.line,
            message: format!("`{text}` is not a number"),
        };
        if real {
            let x: f64 = text.parse().map_err(|_| bad())?;
            if !x.is_finite() {
                return Err(bad());
            }
            Ok(Param::Real(x))
        } else {
            text.parse().map(Param::Int).map_err(|_| bad())
        }
    }

    fn string(&mut self) -> Res<Box<str>> {
        let start_line = self.line;
        self.i += 1;
        let mut out = Vec::new();
        loop {
            match self.s.get(self.i) {
                None => {
                    self.line = start_line;
                    return self.err("a string is never closed (is the file truncated?)");
                }
                Some(b'\'') if self.s.get(self.i + 1) == Some(&b'\'') => {
                    out.push(b'\'');
                    self.i += 2;
                }
                Some(b'\'') => {
                    self.i += 1;
                    break;
                }
                Some(&c) => {
                    if c == b'\n' {
                        self.line += 1;
                    }
                    out.push(c);
                    self.i += 1;
                }
            }
        }
        Ok(String::from_utf8_lossy(&out).into())
    }

    fn param(&mut self) -> Res<Param> {
        match self.peek()? {
            Some(b'$') => {
                self.i += 1;
                Ok(Param::Null)
            }
            Some(b'*') => {
                self.i += 1;
                Ok(Param::Derived)
            }
            Some(b'#') => {
                self.i += 1;
                Ok(Param::Ref(self.integer()?))
            }
            Some(b'\'') => Ok(Param::Str(self.string()?)),
            Some(b'"') => {
                self.i += 1;
                while self.s.get(self.i).is_some_and(|&c| c != b'"') {
                    self.i += 1;
                }
                self.expect(b'"')?;
                Ok(Param::Binary)
            }
            Some(b'.') => {
                self.i += 1;
                let e = self.keyword()?;
                self.expect(b'.')?;
                Ok(Param::Enum(e))
            }
            Some(b'(') => Ok(Param::List(self.list()?)),
            Some(c) if c.is_ascii_digit() || c == b'-' || c == b'+' => self.number(),
            Some(c) if c.is_ascii_alphabetic() || c == b'_' => {
                let name = self.keyword()?;
                let params = self.list()?;
                Ok(Param::Typed(Box::new(Typed { name, params })))
            }
            Some(c) => self.err(format!("unexpected `{}` in a parameter list", c as char)),
            None => self.err("the file ends inside a parameter list (is it truncated?)"),
        }
    }

    /// A parenthesised list, at most [`MAX_NESTING`] deep.
    fn list(&mut self) -> Res<Box<[Param]>> {
        self.expect(b'(')?;
        if self.depth >= MAX_NESTING {
            return self.err(format!("parameter lists nest deeper than {MAX_NESTING}"));
        }
        self.depth += 1;
        let items = self.items();
        self.depth -= 1;
        Ok(items?.into_boxed_slice())
    }

    /// A list's items after its `(`, up to and with its `)`.
    fn items(&mut self) -> Res<Vec<Param>> {
        let mut items = Vec::new();
        if self.peek()? == Some(b')') {
            self.i += 1;
            return Ok(items);
        }
        loop {
            items.push(self.param()?);
            match self.peek()? {
                Some(b',') => self.i += 1,
                Some(b')') => {
                    self.i += 1;
                    return Ok(items);
                }
                Some(c) => return self.err(format!("expected `,` or `)`, found `{}`", c as char)),
                None => {
                    return self.err("the file ends inside a parameter list (is it truncated?)")
                }
            }
        }
    }

    fn record(&mut self) -> Res<Record> {
        let name = self.keyword()?;
        let params = self.list()?;
        Ok(Record { name, params })
    }

    fn at_keyword(&mut self, kw: &str) -> Res<bool> {
        self.skip()?;
        Ok(self.s[self.i..].starts_with(kw.as_bytes())
            && !self
                .s
                .get(self.i + kw.len())
                .is_some_and(|c| c.is_ascii_alphanumeric() || *c == b'_'))
    }
}

/// Parses an exchange file.
pub fn parse(bytes: &[u8]) -> Result<P21, SyntaxError> {
    let mut lx = Lexer {
        s: bytes,
        i: 0,
        line: 1,
        depth: 0,
        names: std::collections::HashSet::new(),
    };
    if !lx.at_keyword("ISO-10303-21")? {
        return lx.err("not a STEP file: it does not start with `ISO-10303-21;`");
    }
    lx.keyword()?;
    lx.expect(b';')?;
    let mut out = P21::default();
    // HEADER: keep FILE_SCHEMA.
    if !lx.at_keyword("HEADER")? {
        return lx.err("expected `HEADER;`");
    }
    lx.keyword()?;
    lx.expect(b';')?;
    while !lx.at_keyword("ENDSEC")? {
        let r = lx.record()?;
        lx.expect(b';')?;
        if r.name == "FILE_SCHEMA" {
            if let Some(Param::List(v)) = r.params.first() {
                out.schemas = v
                    .iter()
                    .filter_map(|p| p.string().map(String::from))
                    .collect();
            }
        }
    }
    lx.keyword()?;
    lx.expect(b';')?;
    let mut data = false;
    loop {
        if lx.at_keyword("DATA")? {
            lx.keyword()?;
            // DATA may carry a name and schema in later editions: DATA('x',('S'));
            if lx.peek()? == Some(b'(') {
                lx.list()?;
            }
            lx.expect(b';')?;
            data = true;
            read_data(&mut lx, &mut out)?;
        } else if lx.at_keyword("END-ISO-10303-21")? {
            break;
        } else if lx.peek()?.is_none() {
            return lx.err("the file ends without `END-ISO-10303-21;` (is it truncated?)");
        } else {
            return lx.err("expected `DATA;` or `END-ISO-10303-21;`");
        }
    }
    if !data {
        return lx.err("the file has no DATA section");
    }
    Ok(out)
}

fn read_data(lx: &mut Lexer, out: &mut P21) -> Res<()> {
    loop {
        match lx.peek()? {
            Some(b'#') => {
                let line = lx.line;
                lx.i += 1;
                let id = lx.integer()?;
                lx.expect(b'=')?;
                let records = if lx.peek()? == Some(b'(') {
                    lx.i += 1;
                    let mut rs = Vec::new();
                    while lx.peek()? != Some(b')') {
                        rs.push(lx.record()?);
                    }
                    lx.i += 1;
                    rs.into_boxed_slice()
                } else {
                    Box::new([lx.record()?])
                };
                lx.expect(b';')?;
                if out
                    .instances
                    .insert(id, Instance { records, line })
                    .is_some()
                {
                    lx.line = line;
                    return lx.err(format!("instance #{id} is defined twice"));
                }
                out.order.push(id);
            }
            _ if lx.at_keyword("ENDSEC")? => {
                lx.keyword()?;
                lx.expect(b';')?;
                return Ok(());
            }
            None => return lx.err("the DATA section never ends (is the file truncated?)"),
            Some(c) => return lx.err(format!("expected `#` or `ENDSEC;`, found `{}`", c as char)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SMALL: &str = "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'2;1');\n\
        FILE_SCHEMA(('AP242_MANAGED_MODEL_BASED_3D_ENGINEERING_MIM_LF'));\nENDSEC;\nDATA;\n\
        #1=CARTESIAN_POINT('',(0.,-1.5E1,2));\n/* note */ #2=(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.MILLI.,.METRE.));\n\
        #3=X('it''s',(),$,#1,LENGTH_MEASURE(2.5));\nENDSEC;\nEND-ISO-10303-21;\n";

    #[test]
    fn reads_simple_complex_and_empty_lists() {
        let f = parse(SMALL.as_bytes()).unwrap();
        assert_eq!(f.order, vec![1, 2, 3]);
        assert_eq!(
            f.schemas[0],
            "AP242_MANAGED_MODEL_BASED_3D_ENGINEERING_MIM_LF"
        );
        let p = &f.instances[&1].records[0].params[1];
        assert_eq!(p.list().unwrap()[1].real(), Some(-15.0));
        assert_eq!(p.list().unwrap()[2], Param::Int(2));
        let u = &f.instances[&2];
        assert_eq!(u.line, 8);
        assert_eq!(
            u.record("SI_UNIT").unwrap().params[0].enumeration(),
            Some("MILLI")
        );
        let x = &f.instances[&3].records[0].params;
        assert_eq!(x[0].string(), Some("it's"));
        assert_eq!(x[1], Param::List(Box::new([])));
        assert_eq!(x[2], Param::Null);
        assert_eq!(x[4].real(), Some(2.5));
    }

    #[test]
    fn truncation_is_an_error_with_its_line() {
        let cut = &SMALL[..SMALL.find("#3").unwrap() + 10];
        let e = parse(cut.as_bytes()).unwrap_err();
        assert_eq!(e.line, 9);
        assert!(e.message.contains("truncated"), "{}", e.message);
        assert!(parse(b"solid x\n").is_err());
    }
}
