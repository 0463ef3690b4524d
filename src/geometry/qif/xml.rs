//! A small element tree over quick-xml: names without their namespace prefix,
//! attributes, text and the line each element starts on. QIF files are a few MB; the
//! whole tree is kept, and elements are found by their `id` attribute.

use quick_xml::events::Event;
use quick_xml::Reader;
use std::collections::HashMap;

/// An element.
#[derive(Debug, Clone, Default)]
pub struct Node {
    /// Local name (`Face`, not `q:Face`).
    pub name: String,
    /// Attributes by local name, in file order.
    pub attrs: Vec<(String, String)>,
    /// Child elements.
    pub children: Vec<Node>,
    /// The text directly inside it, trimmed.
    pub text: String,
    /// 1-based line of its start tag.
    pub line: usize,
}

impl Node {
    /// An attribute's value.
    pub(crate) fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
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
        self.at(path).map(|n| n.text.as_str())
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

/// Parses a document into its root element.
pub fn parse(bytes: &[u8]) -> Result<Node, XmlError> {
    let line_starts: Vec<usize> = std::iter::once(0)
        .chain(
            bytes
                .iter()
                .enumerate()
                .filter(|(_, b)| **b == b'\n')
                .map(|(i, _)| i + 1),
        )
        .collect();
    let line_of = |pos: u64| line_starts.partition_point(|s| *s as u64 <= pos).max(1);
    let mut reader = Reader::from_reader(bytes);
    reader.config_mut().trim_text(false);
    let mut stack: Vec<Node> = vec![Node::default()];
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
                stack.push(element(&e, line_of(start)).map_err(|m| err(&reader, m))?);
            }
            Event::Empty(e) => {
                let node = element(&e, line_of(start)).map_err(|m| err(&reader, m))?;
                if let Some(top) = stack.last_mut() {
                    top.children.push(node);
                }
            }
            Event::End(_) => {
                let mut node = stack.pop().unwrap_or_default();
                node.text = node.text.trim().to_string();
                match stack.last_mut() {
                    Some(top) => top.children.push(node),
                    None => return Err(err(&reader, "an end tag closes nothing".into())),
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
        let open = stack.last().map(|n| n.name.clone()).unwrap_or_default();
        return Err(XmlError {
            line: line_starts.len(),
            message: format!("the file ends inside <{open}>: it is cut short"),
        });
    }
    let mut doc = stack.pop().unwrap_or_default();
    match doc.children.len() {
        1 => Ok(doc.children.remove(0)),
        0 => Err(XmlError {
            line: 1,
            message: "it holds no element".into(),
        }),
        _ => Err(XmlError {
            line: doc.children[1].line,
            message: "it has more than one root element".into(),
        }),
    }
}

fn element(e: &quick_xml::events::BytesStart, line: usize) -> Result<Node, String> {
    let local = |q: &[u8]| {
        let s = String::from_utf8_lossy(q);
        s.rsplit(':').next().unwrap_or_default().to_string()
    };
    let mut attrs = Vec::new();
    for a in e.attributes() {
        let a = a.map_err(|e| e.to_string())?;
        let v = a.unescape_value().map_err(|e| e.to_string())?;
        attrs.push((local(a.key.as_ref()), v.into_owned()));
    }
    Ok(Node {
        name: local(e.name().as_ref()),
        attrs,
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
        assert_eq!((b.text.as_str(), b.line, b.id()), ("1 2 & 3", 3, Some(7)));
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
