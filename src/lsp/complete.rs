//! Completion: what may be written at the cursor, from the text before it (which need
//! not parse while one types) and the names and keys of the last spec that did.

use super::face_names;
use super::symbols::{contains, decls, Decl, DeclKind};
use super::Deep;
use crate::source::FileId;
use crate::syntax::ast;
use crate::Checked;
use lsp_types::{CompletionItem, CompletionItemKind};

/// Keywords that start a top-level item.
const ITEM_KEYWORDS: &[&str] = &[
    "use",
    "part",
    "cmm",
    "head",
    "probe",
    "stylus",
    "body",
    "extension",
    "sampling",
    "fixture",
    "scanner",
    "hierarchy",
    "plan",
];

/// Keywords that start a statement inside a part.
const PART_KEYWORDS: &[&str] = &[
    "units",
    "stock",
    "mesh",
    "cut",
    "add",
    "face",
    "feature",
    "datum",
    "frame",
    "tolerance",
];

/// Statements of a plan besides its properties.
const PLAN_KEYWORDS: &[&str] = &["prefer", "forbid", "sample"];

/// The completions at byte `offset` of `text`, the current text of `file`; `checked` is
/// the last front end of the spec that parsed (its names and keys), `deep` the last
/// geometry stage (the faces of a mesh).
pub fn complete(
    checked: &Checked,
    deep: Option<&Deep>,
    file: FileId,
    text: &str,
    offset: usize,
) -> Vec<CompletionItem> {
    let before = &text[..offset.min(text.len())];
    let line = &before[before.rfind('\n').map_or(0, |i| i + 1)..];
    let head = &line[..word_start(line)];
    let trimmed = head.trim_start();

    // `use std::…`
    if let Some(path) = trimmed.strip_prefix("use ") {
        return use_items(checked, path.trim());
    }
    // A number then a unit.
    let number_then_space = head.ends_with(' ')
        && head
            .trim_end()
            .chars()
            .last()
            .is_some_and(|c| c.is_ascii_digit() || c == '.');
    if number_then_space {
        return crate::resolve::units()
            .map(|(u, what)| item(u, CompletionItemKind::UNIT, what))
            .collect();
    }
    let at_statement_start = trimmed.is_empty() || trimmed.ends_with([';', ',', '{']);
    let all = decls(checked);
    let container = enclosing(before);
    match container.first().map(String::as_str) {
        None if at_statement_start => keywords(ITEM_KEYWORDS),
        Some("part") => {
            if at_statement_start {
                return keywords(PART_KEYWORDS);
            }
            if let Some(part) = face_names::part_at(&checked.model, file, offset) {
                let offers = |o: Vec<face_names::Offer>, kind| {
                    o.iter().map(|(l, d)| item(l, kind, d)).collect()
                };
                if let Some(roles) = face_names::roles_after_dot(part, head) {
                    return offers(roles, CompletionItemKind::ENUM_MEMBER);
                }
                if let Some(faces) = face_names::groups(part, head, deep) {
                    return offers(faces, CompletionItemKind::VALUE);
                }
            }
            if trimmed.starts_with("tolerance") && trimmed.trim_end().ends_with('=') {
                return crate::resolve::tolerance_keywords()
                    .map(|k| item(k, CompletionItemKind::FUNCTION, "tolerance type"))
                    .collect();
            }
            part_names(&all, file, offset)
        }
        Some(_) if at_statement_start => {
            let mut out = block_keys(checked, &all, file, offset);
            if container.first().map(String::as_str) == Some("plan") && container.len() == 1 {
                out.extend(keywords(PLAN_KEYWORDS));
            }
            out
        }
        Some("plan") if rack_value(trimmed).is_some() => {
            // `prefer probe …`, `forbid probe …`, `fixtures [ …`: the labels of the plan's
            // machine's rack, not the catalogue's items.
            let model = &checked.model;
            let plan = model
                .plans
                .iter()
                .filter(|p| p.span.file == file && p.span.start as usize <= offset)
                .max_by_key(|p| p.span.start);
            let Some(cmm) = plan.map(|p| &model.cmms[p.cmm.0]) else {
                return Vec::new();
            };
            let labels: Vec<&str> = if rack_value(trimmed) == Some(true) {
                cmm.probes.iter().map(|(l, _)| l.as_str()).collect()
            } else {
                cmm.fixtures.iter().map(|(l, _)| l.as_str()).collect()
            };
            let what = format!("in cmm {}'s rack", cmm.name);
            labels
                .into_iter()
                .map(|l| item(l, CompletionItemKind::REFERENCE, &what))
                .collect()
        }
        _ => {
            // A value: the names of the kind the key asks for, else every visible name.
            let key = trimmed.split_whitespace().next().unwrap_or("");
            let kind = kind_of_key(key);
            visible(checked, &all, file)
                .into_iter()
                .filter(|d| kind.is_none_or(|k| d.kind == k))
                .map(|d| name_item(&d))
                .collect()
        }
    }
}

fn item(label: &str, kind: CompletionItemKind, detail: &str) -> CompletionItem {
    CompletionItem {
        label: label.to_string(),
        kind: Some(kind),
        detail: Some(detail.to_string()),
        ..CompletionItem::default()
    }
}

/// A declared item's name, its kind as the detail.
fn name_item(d: &Decl) -> CompletionItem {
    item(
        &d.name.name,
        CompletionItemKind::REFERENCE,
        d.kind.keyword(),
    )
}

/// Where the word being typed at the end of `line` starts (a byte offset): after the last
/// character that cannot be part of a name, whatever its length in bytes (`±`, `°`).
fn word_start(line: &str) -> usize {
    line.char_indices()
        .rev()
        .find(|&(_, c)| !(c.is_ascii_alphanumeric() || c == '_'))
        .map_or(0, |(i, c)| i + c.len_utf8())
}

fn keywords(words: &[&str]) -> Vec<CompletionItem> {
    words
        .iter()
        .map(|w| item(w, CompletionItemKind::KEYWORD, "keyword"))
        .collect()
}

/// Whether a plan statement's value is a rack label: Some(true) for a probe's
/// (`prefer probe `, `forbid probe `), Some(false) for a fixture's (`fixtures [`).
fn rack_value(statement: &str) -> Option<bool> {
    let words: Vec<&str> = statement.split_whitespace().collect();
    match words.as_slice() {
        ["prefer" | "forbid", "probe"] => Some(true),
        [w, ..] if w.starts_with("fixtures") => Some(false),
        _ => None,
    }
}

/// The kind of name a property key takes (`head PH6`, `probes [p1: TP20]`, `part f2`).
fn kind_of_key(key: &str) -> Option<DeclKind> {
    Some(match key {
        "head" => DeclKind::Block(ast::BlockKind::Head),
        "probes" | "probe" => DeclKind::Block(ast::BlockKind::Probe),
        "stylus" => DeclKind::Block(ast::BlockKind::Stylus),
        "body" => DeclKind::Block(ast::BlockKind::Body),
        "extensions" => DeclKind::Block(ast::BlockKind::Extension),
        "sampling" => DeclKind::Block(ast::BlockKind::Sampling),
        "fixtures" => DeclKind::Block(ast::BlockKind::Fixture),
        "scanners" => DeclKind::Block(ast::BlockKind::Scanner),
        "cmm" => DeclKind::Block(ast::BlockKind::Cmm),
        "part" => DeclKind::Part,
        "hierarchy" => DeclKind::Hierarchy,
        _ => return None,
    })
}

/// The headers of the blocks the cursor is in, innermost first: for each open `{`, the
/// words of its statement before it (`part f2`, `table`, `cut slot large`). Strings and
/// comments are skipped.
fn enclosing(before: &str) -> Vec<String> {
    let mut stack: Vec<String> = Vec::new();
    let mut statement = String::new();
    let mut chars = before.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' => {
                while let Some(c) = chars.next() {
                    match c {
                        '\\' => {
                            chars.next();
                        }
                        '"' => break,
                        _ => {}
                    }
                }
            }
            '/' if chars.peek() == Some(&'/') => {
                for c in chars.by_ref() {
                    if c == '\n' {
                        statement.clear();
                        break;
                    }
                }
            }
            '/' if chars.peek() == Some(&'*') => {
                let mut last = ' ';
                for c in chars.by_ref() {
                    if last == '*' && c == '/' {
                        break;
                    }
                    last = c;
                }
            }
            '{' => {
                stack.push(statement.trim().to_string());
                statement.clear();
            }
            '}' => {
                stack.pop();
                statement.clear();
            }
            '\n' | ';' | ',' => statement.clear(),
            _ => statement.push(c),
        }
    }
    stack.reverse();
    // `part f2` → `part`, the keyword; nested blocks keep their key (`table`).
    stack
        .into_iter()
        .map(|h| h.split_whitespace().next().unwrap_or("").to_string())
        .collect()
}

/// `use std::` → the standard modules; `use std::probes::` or `use std::probes::{A, ` →
/// that module's items.
fn use_items(checked: &Checked, path: &str) -> Vec<CompletionItem> {
    let path = path.trim_end_matches(['{', ' ']);
    let path = path.split('{').next().unwrap_or(path).trim_end();
    if path.is_empty() {
        return vec![item(
            "std",
            CompletionItemKind::MODULE,
            "the standard library",
        )];
    }
    if path == "std::" {
        return crate::load::std_module_names()
            .map(|m| item(&m["std::".len()..], CompletionItemKind::MODULE, m))
            .collect();
    }
    let module = path.trim_end_matches("::");
    let Some(m) = checked
        .program
        .modules
        .iter()
        .find(|m| m.std_name.as_deref() == Some(module))
    else {
        return Vec::new();
    };
    decls(checked)
        .into_iter()
        .filter(|d| d.name.span.file == m.file && d.is_item())
        .map(|d| name_item(&d))
        .collect()
}

/// The names declared in the part the cursor is in: the last part of the file that starts
/// before it (the names may come from an earlier text, whose part ended sooner).
fn part_names(all: &[Decl], file: FileId, offset: usize) -> Vec<CompletionItem> {
    let part = all
        .iter()
        .filter(|d| d.kind == DeclKind::Part && d.full.file == file)
        .filter(|d| d.full.start as usize <= offset)
        .max_by_key(|d| d.full.start);
    let mut out: Vec<CompletionItem> = all
        .iter()
        .filter(|d| part.is_some_and(|p| d.part.is_some_and(|q| q.name.span == p.name.span)))
        .map(|d| item(&d.name.name, CompletionItemKind::FIELD, d.kind.keyword()))
        .collect();
    out.push(item("stock", CompletionItemKind::FIELD, "the stock"));
    out
}

/// The keys the innermost block around the cursor accepts, as the resolver asked them.
fn block_keys(checked: &Checked, all: &[Decl], file: FileId, offset: usize) -> Vec<CompletionItem> {
    let keys = &checked.model.index.keys;
    let inside = |s: crate::source::Span| contains(s, file, offset);
    // A nested block (`table { … }`) is its own owner; an item is owned by its name.
    let nested = keys
        .iter()
        .filter(|k| inside(k.owner))
        .min_by_key(|k| k.owner.end - k.owner.start);
    let set = nested.or_else(|| {
        all.iter()
            .filter(|d| inside(d.full))
            .min_by_key(|d| d.full.end - d.full.start)
            .and_then(|d| keys.iter().find(|k| k.owner == d.name.span))
    });
    set.map_or(Vec::new(), |k| {
        k.keys
            .iter()
            .map(|key| item(key, CompletionItemKind::PROPERTY, "property"))
            .collect()
    })
}

/// The top-level names visible in `file`: its own and those its `use` statements import.
fn visible<'a>(checked: &'a Checked, all: &[Decl<'a>], file: FileId) -> Vec<Decl<'a>> {
    let mut out: Vec<Decl> = all
        .iter()
        .filter(|d| d.is_item())
        .filter(|d| d.name.span.file == file)
        .cloned()
        .collect();
    let Some(module) = checked.program.modules.iter().find(|m| m.file == file) else {
        return out;
    };
    for &(item, target) in &module.imports {
        let ast::Item::Use(u) = &module.ast.items[item] else {
            continue;
        };
        let target_file = checked.program.modules[target.0].file;
        let from_target = all
            .iter()
            .filter(|d| d.is_item())
            .filter(|d| d.name.span.file == target_file);
        let wanted: Vec<&str> = match (&u.select, &u.source) {
            (ast::UseSelect::Names(names), _) => names.iter().map(|n| n.name.as_str()).collect(),
            (ast::UseSelect::Implicit, ast::UseSource::Module(segs)) => {
                segs.last().map(|s| s.name.as_str()).into_iter().collect()
            }
            _ => {
                out.extend(from_target.cloned());
                continue;
            }
        };
        out.extend(
            from_target
                .filter(|d| wanted.contains(&d.name.name.as_str()))
                .cloned(),
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::word_start;

    #[test]
    fn a_word_starts_after_any_character_that_is_no_part_of_a_name() {
        assert_eq!(word_start("  probe p1"), 8);
        assert_eq!(word_start("x ±1"), "x ±".len());
        assert_eq!(word_start("angle 90°"), "angle 90°".len());
        assert_eq!(word_start("tip"), 0);
    }
}
