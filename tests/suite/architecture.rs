//! The map's invariants, measured on the source (ARCHITECTURE.md, "Architecture
//! Invariant"): a stage imports earlier stages only; no two files of a folder import each
//! other round a circle; functions over 120 lines stay at most 1 % of all; the map itself
//! stays a map (at most 400 lines).
//!
//! Imports are read from the text: every `crate::…` and `super::…` path, `use` trees
//! expanded, resolved to the longest module that exists. A file's use of its own
//! folder's door (or an ancestor's) is how a folder shares its types and is no edge.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// The stage order: a folder may import only folders before it. `model` is what the
/// front end lowers into, so it comes before `resolve`; the driver (`lib.rs`, named
/// ""), the language server, the viewer and the binary come last.
const ORDER: &[&str] = &[
    "source", "diag", "syntax", "load", "model", "resolve", "geometry", "sample", "graph",
    "access", "plan", "path", "dmis", "simulate", "verify", "fmt", "import", "", "lsp", "view",
    "cli", "<main>",
];

/// Every source file as (module path, text), `a::b` for `src/a/b.rs` and `src/a/b/mod.rs`.
fn modules() -> BTreeMap<String, String> {
    fn walk(dir: &Path, out: &mut BTreeMap<String, String>) {
        let mut entries: Vec<_> = std::fs::read_dir(dir).unwrap().flatten().collect();
        entries.sort_by_key(|e| e.path());
        for e in entries {
            let p = e.path();
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|x| x == "rs") {
                let rel = p.strip_prefix("src").unwrap().with_extension("");
                let mut parts: Vec<String> = rel
                    .iter()
                    .map(|s| s.to_string_lossy().into_owned())
                    .collect();
                if parts.last().is_some_and(|l| l == "mod") {
                    parts.pop();
                }
                let name = match parts.as_slice() {
                    [one] if one == "lib" => String::new(),
                    [one] if one == "main" => "<main>".to_string(),
                    _ => parts.join("::"),
                };
                out.insert(name, std::fs::read_to_string(&p).unwrap());
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(Path::new("src"), &mut out);
    out
}

/// The text without line comments (doc links name modules without importing them) and
/// without its unit tests (`#[cfg(test)] mod tests`, whose `super` is the file itself).
fn code(text: &str) -> String {
    let text = text.split("#[cfg(test)]\nmod tests").next().unwrap_or(text);
    text.lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The paths of a `use` tree's body (`a::{b, c::{d}}` → `a::b`, `a::c::d`).
fn expand(prefix: &str, body: &str, out: &mut Vec<String>) {
    let mut depth = 0;
    let mut item = String::new();
    let mut items = Vec::new();
    for ch in body.chars() {
        match ch {
            '{' => depth += 1,
            '}' => depth -= 1,
            _ => {}
        }
        if ch == ',' && depth == 0 {
            items.push(std::mem::take(&mut item));
        } else {
            item.push(ch);
        }
    }
    items.push(item);
    for it in items {
        let it = it.trim();
        if it.is_empty() {
            continue;
        }
        if let Some(open) = it.find('{') {
            let head = it[..open].trim_end_matches("::");
            let inner = &it[open + 1..it.rfind('}').unwrap_or(it.len())];
            expand(&format!("{prefix}::{head}"), inner, out);
        } else {
            let name = it.split(" as ").next().unwrap_or(it).trim();
            out.push(format!("{prefix}::{name}"));
        }
    }
}

/// Every `crate::`/`super::` path a file names.
fn paths(text: &str) -> Vec<String> {
    let text = code(text);
    let mut out = Vec::new();
    let bytes = text.as_bytes();
    let word = |i: usize| i > 0 && (bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_');
    for start in ["crate::", "super::"] {
        for (i, _) in text.match_indices(start) {
            if word(i) || (i > 0 && bytes[i - 1] == b'$') {
                continue;
            }
            let rest = &text[i..];
            let end = rest
                .find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                .unwrap_or(rest.len());
            let path = rest[..end].trim_end_matches(':');
            if rest[end..].starts_with('{') && rest[..end].ends_with("::") {
                let body = &rest[end + 1..];
                let mut depth = 1;
                let close = body
                    .char_indices()
                    .find(|&(_, c)| {
                        match c {
                            '{' => depth += 1,
                            '}' => depth -= 1,
                            _ => {}
                        }
                        depth == 0
                    })
                    .map_or(body.len(), |(k, _)| k);
                expand(path, &body[..close], &mut out);
            } else {
                out.push(path.to_string());
            }
        }
    }
    out
}

/// The module a path names, from module `from`: the longest prefix that is a module.
fn target(from: &str, path: &str, modules: &BTreeMap<String, String>) -> String {
    let mut segs: Vec<&str> = path.split("::").collect();
    let mut base: Vec<&str> = if from.is_empty() || from == "<main>" {
        vec![]
    } else {
        from.split("::").collect()
    };
    if segs[0] == "crate" {
        base.clear();
        segs.remove(0);
    } else {
        while segs.first() == Some(&"super") {
            base.pop();
            segs.remove(0);
        }
    }
    let full: Vec<&str> = base
        .into_iter()
        .chain(segs.into_iter().filter(|s| *s != "self"))
        .collect();
    (0..=full.len())
        .rev()
        .map(|k| full[..k].join("::"))
        .find(|m| modules.contains_key(m))
        .unwrap_or_default()
}

/// The import edges: module → modules it names (its own doors excluded).
fn edges(modules: &BTreeMap<String, String>) -> BTreeMap<String, BTreeSet<String>> {
    let mut out: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (m, text) in modules {
        let entry = out.entry(m.clone()).or_default();
        for p in paths(text) {
            let t = target(m, &p, modules);
            let own_door = !t.is_empty() && m.starts_with(&format!("{t}::"));
            if &t != m && !own_door {
                entry.insert(t);
            }
        }
        // A door names its children without `super` or `crate`.
        let children = modules.keys().filter(|c| {
            !m.is_empty()
                && c.strip_prefix(&format!("{m}::"))
                    .is_some_and(|r| !r.contains("::"))
        });
        for c in children {
            let leaf = c.rsplit("::").next().unwrap();
            if code(text).contains(&format!("{leaf}::")) {
                entry.insert(c.clone());
            }
        }
    }
    out
}

fn stage(m: &str) -> &str {
    m.split("::").next().unwrap_or("")
}

#[test]
fn stages_import_only_earlier_stages() {
    let modules = modules();
    let mut up = Vec::new();
    for (m, targets) in edges(&modules) {
        let from = ORDER.iter().position(|s| *s == stage(&m));
        assert!(
            from.is_some(),
            "stage `{}` of {m} is not in ORDER",
            stage(&m)
        );
        for t in targets {
            let to = ORDER.iter().position(|s| *s == stage(&t));
            if to > from {
                up.push(format!("{m} -> {t}"));
            }
        }
    }
    assert!(
        up.is_empty(),
        "imports up the stage order:\n{}",
        up.join("\n")
    );
}

#[test]
fn no_files_of_a_folder_import_each_other_round_a_circle() {
    let modules = modules();
    let edges = edges(&modules);
    // Tarjan's strongly connected components over the files of each folder.
    let mut circles = Vec::new();
    for folder in ORDER.iter().filter(|s| !s.is_empty()) {
        let nodes: Vec<&String> = modules
            .keys()
            .filter(|m| m.starts_with(&format!("{folder}::")))
            .collect();
        let index_of: BTreeMap<&String, usize> =
            nodes.iter().enumerate().map(|(i, m)| (*m, i)).collect();
        let adj: Vec<Vec<usize>> = nodes
            .iter()
            .map(|m| {
                edges[*m]
                    .iter()
                    .filter_map(|t| index_of.get(t).copied())
                    .collect()
            })
            .collect();
        for comp in strongly_connected(&adj) {
            if comp.len() > 1 {
                let names: Vec<&str> = comp.iter().map(|&i| nodes[i].as_str()).collect();
                circles.push(names.join(" ↔ "));
            }
        }
    }
    assert!(
        circles.is_empty(),
        "import circles:\n{}",
        circles.join("\n")
    );
}

/// The strongly connected components of a graph (Tarjan), each as node indices.
fn strongly_connected(adj: &[Vec<usize>]) -> Vec<Vec<usize>> {
    struct State<'a> {
        adj: &'a [Vec<usize>],
        index: Vec<Option<usize>>,
        low: Vec<usize>,
        stack: Vec<usize>,
        on: Vec<bool>,
        next: usize,
        out: Vec<Vec<usize>>,
    }
    fn visit(s: &mut State, v: usize) {
        s.index[v] = Some(s.next);
        s.low[v] = s.next;
        s.next += 1;
        s.stack.push(v);
        s.on[v] = true;
        for &w in &s.adj[v] {
            match s.index[w] {
                None => {
                    visit(s, w);
                    s.low[v] = s.low[v].min(s.low[w]);
                }
                Some(i) if s.on[w] => s.low[v] = s.low[v].min(i),
                Some(_) => {}
            }
        }
        if Some(s.low[v]) == s.index[v] {
            let mut comp = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on[w] = false;
                comp.push(w);
                if w == v {
                    break;
                }
            }
            s.out.push(comp);
        }
    }
    let n = adj.len();
    let mut s = State {
        adj,
        index: vec![None; n],
        low: vec![0; n],
        stack: Vec::new(),
        on: vec![false; n],
        next: 0,
        out: Vec::new(),
    };
    for v in 0..n {
        if s.index[v].is_none() {
            visit(&mut s, v);
        }
    }
    s.out
}

/// Every function's length in lines, from its `fn` line to its closing brace.
fn function_lengths(text: &str) -> Vec<(String, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let t = line.trim_start();
        let is_fn = [
            "fn ",
            "pub fn ",
            "pub(crate) fn ",
            "pub(super) fn ",
            "const fn ",
            "pub const fn ",
        ]
        .iter()
        .any(|p| t.starts_with(p));
        if !is_fn {
            continue;
        }
        let (mut depth, mut started) = (0i32, false);
        for (j, l) in lines.iter().enumerate().skip(i) {
            let l = strip_literals(l);
            if !started && l.trim_end().ends_with(';') && !l.contains('{') {
                break;
            }
            for c in l.chars() {
                match c {
                    '{' => {
                        depth += 1;
                        started = true;
                    }
                    '}' => depth -= 1,
                    _ => {}
                }
            }
            if started && depth == 0 {
                let name = t
                    .split("fn ")
                    .nth(1)
                    .unwrap_or("")
                    .split(['(', '<'])
                    .next()
                    .unwrap_or("");
                out.push((name.to_string(), j - i + 1));
                break;
            }
        }
    }
    out
}

/// A line without its comment, string and character literals (their braces are text).
fn strip_literals(line: &str) -> String {
    let mut out = String::new();
    let mut chars = line.chars().peekable();
    let mut in_str = false;
    while let Some(c) = chars.next() {
        if in_str {
            match c {
                '\\' => {
                    chars.next();
                }
                '"' => in_str = false,
                _ => {}
            }
            continue;
        }
        match c {
            '"' => in_str = true,
            '/' if chars.peek() == Some(&'/') => break,
            '\'' => {
                // A char literal ('{', '\n'), not a lifetime ('a).
                let rest: String = chars.clone().take(3).collect();
                if let Some(escaped) = rest.strip_prefix('\\') {
                    let close = escaped.find('\'').map(|k| k + 2);
                    for _ in 0..close.unwrap_or(0) {
                        chars.next();
                    }
                } else if rest.chars().nth(1) == Some('\'') {
                    chars.next();
                    chars.next();
                }
            }
            _ => out.push(c),
        }
    }
    out
}

#[test]
fn functions_over_120_lines_stay_at_most_one_percent() {
    let mut all = 0;
    let mut long = Vec::new();
    for (m, text) in modules() {
        for (name, len) in function_lengths(&text) {
            all += 1;
            if len > 120 {
                long.push(format!("{len:4} {m}::{name}"));
            }
        }
    }
    long.sort();
    eprintln!(
        "{} of {all} functions are over 120 lines:\n{}",
        long.len(),
        long.join("\n")
    );
    assert!(
        all > 1000,
        "only {all} functions found: the count is broken"
    );
    assert!(
        long.len() * 100 <= all,
        "{} of {all} functions are over 120 lines",
        long.len()
    );
}

#[test]
fn the_map_is_at_most_400_lines() {
    let map = std::fs::read_to_string("ARCHITECTURE.md").unwrap();
    let lines = map.lines().count();
    assert!(
        lines <= 400,
        "ARCHITECTURE.md is {lines} lines: a map, not a diary"
    );
}
