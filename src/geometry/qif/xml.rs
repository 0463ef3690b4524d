//! A small element tree over quick-xml: names without their namespace prefix,
//! attributes, text and the line each element starts on. QIF files are a few MB; the
//! whole tree is kept, and elements are found by their `id` attribute.
//!
//! **Decision: a compact tree, bounded elements.** A file may be as large as the input
//! limit, so an element costs a small constant: names are interned (one allocation per
//! distinct name), attributes, children and text are boxed slices sized exactly. An
//! element has at most [`MAX_ATTRIBUTES`] attributes (a QIF element has a handful) and
//! duplicates are found by sorting (XML 1.0 §3.1 forbids them), not by comparing every
//! pair; elements nest at most [`MAX_DEPTH`] deep.

use crate::geometry::step::Name;
use quick_xml::events::Event;
use quick_xml::Reader;
use std::collections::{HashMap, HashSet};

/// An element.
#[derive(Debug, Clone)]
pub struct Node {
    /// Local name (`Face`, not `q:Face`).
    pub name: Name,
    /// Attributes by local name, in file order.
    pub attrs: Box<[(Name, Box<str>)]>,
    /// Child elements.
    pub children: Box<[Node]>,
    /// The text directly inside it, trimmed.
    pub text: Box<str>,
    /// 1-based line of its start tag.
    pub line: usize,
}

impl Node {
    /// An attribute's value.
    pub(crate) fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| *k == name)
            .map(|(_, v)| &**v)
    }

    /// The first child of this name.
    pub fn child(&self, name: &str) -> Option<&Node> {
        self.children.iter().find(|c| c.name == name)
    }

    /// The children of this name.
    pub fn all<'a>(&'a self, name: &'a str) -> impl Iterator<Item = &'a Node> + 'a {
        self.children.iter().filter(move |c| c.name == name)
    }

    /// The element at a path of child names.
    pub fn at(&self, path: &[&str]) -> Option<&Node> {
        path.iter().try_fold(self, |n, p| n.child(p))
    }

    /// The text of the child at `path`.
    pub(crate) fn text_at(&self, path: &[&str]) -> Option<&str> {
        self.at(path).map(|n| &*n.text)
    }

    /// Its `id` attribute as a number.
    pub fn id(&self) -> Option<u64> {
        self.attr("id").and_then(|v| v.trim().parse().ok())
    }

    /// The whitespace-separated numbers of its text; `None` if any is not one.
    pub fn numbers(&self) -> Option<Vec<f64>> {
        self.text
            .split_ascii_whitespace()
            .map(|t| t.parse::<f64>().ok().filter(|x| x.is_finite()))
            .collect()
    }

    /// Every element below it (itself included), depth first in file order.
    pub fn walk<'a>(&'a self, out: &mut Vec<&'a Node>) {
        out.push(self);
        for c in &self.children {
            c.walk(out);
        }
    }
}

/// Why a document could not be read as XML.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct XmlError {
    /// 1-based line.
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

/// Deepest nesting accepted: deeper than any QIF document, shallow enough that the tree
/// cannot exhaust the stack.
const MAX_DEPTH: usize = 200;

/// Most attributes an element may have: a QIF element has a handful (the root a few
/// namespace declarations more).
pub(crate) const MAX_ATTRIBUTES: usize = 64;

/// An element being read: its children and text grow until its end tag.
struct Open {
    name: Name,
    attrs: Box<[(Name, Box<str>)]>,
    children: Vec<Node>,
    text: String,
    line: usize,
}

impl Open {
    fn close(self) -> Node {
        Node {
            name: self.name,
            attrs: self.attrs,
            children: self.children.into_boxed_slice(),
            text: self.text.trim().into(),
            line: self.line,
        }
    }
}

/// The names of a document, each stored once.
#[derive(Default)]
struct Names(HashSet<Name>);

impl Names {
    /// The local name of a qualified one (`q:Face` → `Face`).
    fn local(&mut self, q: &[u8]) -> Name {
        let s = String::from_utf8_lossy(q);
        let local = s.rsplit(':').next().unwrap_or_default();
        if let Some(n) = self.0.get(local) {
            return n.clone();
        }
        let n = Name::new(local);
        self.0.insert(n.clone());
        n
    }
}

/// Parses a document into its root element.
pub fn parse(bytes: &[u8]) -> Result<Node, XmlError> {
    let line_starts: Vec<usize> = std::iter::once(0).chain(line_breaks(bytes)).collect();
    let line_of = |pos: u64| line_starts.partition_point(|s| *s as u64 <= pos).max(1);
    let mut reader = Reader::from_reader(bytes);
    reader.config_mut().trim_text(false);
    let mut names = Names::default();
    let mut stack: Vec<Open> = vec![Open {
        name: names.local(b""),
        attrs: Box::new([]),
        children: Vec::new(),
        text: String::new(),
        line: 1,
    }];
    let mut buf = Vec::new();
    let err = |reader: &Reader<&[u8]>, message: String| XmlError {
        line: line_of(
            reader
                .error_position()
                .max(reader.buffer_position().saturating_sub(1)),
        ),
        message,
    };
    loop {
        let start = reader.buffer_position();
        let event = reader
            .read_event_into(&mut buf)
            .map_err(|e| err(&reader, e.to_string()))?;
        match event {
            Event::Start(e) => {
                if stack.len() > MAX_DEPTH {
                    return Err(err(&reader, "elements nest too deep".into()));
                }
                let open = element(&e, line_of(start), &mut names).map_err(|m| err(&reader, m))?;
                stack.push(open);
            }
            Event::Empty(e) => {
                let node = element(&e, line_of(start), &mut names).map_err(|m| err(&reader, m))?;
                if let Some(top) = stack.last_mut() {
                    top.children.push(node.close());
                }
            }
            Event::End(_) => {
                let node = match stack.pop() {
                    Some(n) if !stack.is_empty() => n.close(),
                    _ => return Err(err(&reader, "an end tag closes nothing".into())),
                };
                if let Some(top) = stack.last_mut() {
                    top.children.push(node);
                }
            }
            Event::Text(t) => {
                let s = t.decode().map_err(|e| err(&reader, e.to_string()))?;
                if let Some(top) = stack.last_mut() {
                    top.text.push_str(&s);
                }
            }
            Event::CData(t) => {
                if let Some(top) = stack.last_mut() {
                    top.text.push_str(&String::from_utf8_lossy(&t));
                }
            }
            Event::GeneralRef(r) => {
                let name = r.decode().map_err(|e| err(&reader, e.to_string()))?;
                let c = match &*name {
                    "amp" => Some('&'),
                    "lt" => Some('<'),
                    "gt" => Some('>'),
                    "quot" => Some('"'),
                    "apos" => Some('\''),
                    _ => r.resolve_char_ref().ok().flatten(),
                };
                match (c, stack.last_mut()) {
                    (Some(c), Some(top)) => top.text.push(c),
                    (None, _) => {
                        return Err(err(&reader, format!("unknown entity `&{name};`")));
                    }
                    _ => {}
                }
            }
            Event::Eof => break,
            _ => {}
        }
        buf.clear();
    }
    if stack.len() > 1 {
        let open = stack.last().map(|n| n.name.to_string()).unwrap_or_default();
        return Err(XmlError {
            line: line_starts.len(),
            message: format!("the file ends inside <{open}>: it is cut short"),
        });
    }
    let mut roots = stack.pop().map(|d| d.children).unwrap_or_default();
    match roots.len() {
        1 => Ok(roots.remove(0)),
        0 => Err(XmlError {
            line: 1,
            message: "it holds no element".into(),
        }),
        _ => Err(XmlError {
            line: roots[1].line,
            message: "it has more than one root element".into(),
        }),
    }
}

/// The offsets where lines after the first start.
fn line_breaks(bytes: &[u8]) -> impl Iterator<Item = usize> + '_ {
    bytes
        .iter()
        .enumerate()
        .filter(|(_, b)| **b == b'\n')
        .map(|(i, _)| i + 1)
}

/// An element's start tag read: its local name and attributes, at most
/// [`MAX_ATTRIBUTES`] of them and none twice.
fn element(
    e: &quick_xml::events::BytesStart,
    line: usize,
    names: &mut Names,
) -> Result<Open, String> {
    let mut attrs = Vec::new();
    // quick-xml's own duplicate check compares each attribute with every earlier one.
    for a in e.attributes().with_checks(false) {
        if attrs.len() == MAX_ATTRIBUTES {
            return Err(format!(
                "an element has more than {MAX_ATTRIBUTES} attributes"
            ));
        }
        let a = a.map_err(|e| e.to_string())?;
        let v = a.unescape_value().map_err(|e| e.to_string())?;
        attrs.push((names.local(a.key.as_ref()), Box::<str>::from(v.as_ref())));
    }
    let mut keys: Vec<&str> = attrs.iter().map(|(k, _)| k.as_str()).collect();
    keys.sort_unstable();
    if let Some(w) = keys.windows(2).find(|w| w[0] == w[1]) {
        return Err(format!("an element has the attribute `{}` twice", w[0]));
    }
    Ok(Open {
        name: names.local(e.name().as_ref()),
        attrs: attrs.into_boxed_slice(),
        children: Vec::new(),
        text: String::new(),
        line,
    })
}

/// Every element with an `id`, by id (the first where a file repeats one).
pub fn index(root: &Node) -> HashMap<u64, &Node> {
    let mut all = Vec::new();
    root.walk(&mut all);
    let mut out = HashMap::new();
    for n in all {
        if let Some(id) = n.id() {
            out.entry(id).or_insert(n);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_elements_attributes_and_text() {
        let d = parse(b"<?xml version=\"1.0\"?>\n<q:A xmlns:q=\"x\" v=\"3\">\n <B id=\"7\">1 2 &amp; 3</B><C/></q:A>")
            .unwrap();
        assert_eq!(d.name, "A");
        assert_eq!(d.attr("v"), Some("3"));
        let b = d.child("B").unwrap();
        assert_eq!((&*b.text, b.line, b.id()), ("1 2 & 3", 3, Some(7)));
        assert!(d.child("C").is_some());
    }

    #[test]
    fn a_cut_short_file_says_so() {
        let e = parse(b"<A>\n<B>\n<C>1</C>").unwrap_err();
        assert!(e.message.contains("cut short"), "{e:?}");
        let e = parse(b"<A><B></C></A>").unwrap_err();
        assert_eq!(e.line, 1);
    }
}
