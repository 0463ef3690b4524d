//! Grammar rules in words, for syntax errors.

use super::{Rule, SyntaxError};
use crate::source::{FileId, Span};

/// What a rule is called in an error message, or `None` for rules that never appear
/// there on their own. The match is exhaustive on purpose: a new grammar rule does not
/// compile until it has a word.
pub(crate) fn word(rule: Rule) -> Option<&'static str> {
    Some(match rule {
        Rule::EOI => "end of file",
        Rule::WHITESPACE | Rule::COMMENT | Rule::ident_char | Rule::nl | Rule::string_inner | Rule::unsigned => return None,
        Rule::NL => "a new line",
        Rule::sep => "a new line, `;` or `,`",
        Rule::ident | Rule::list_label => "a name",
        Rule::kw_use => "`use`",
        Rule::kw_part => "`part`",
        Rule::kw_plan => "`plan`",
        Rule::kw_hierarchy => "`hierarchy`",
        Rule::kw_required => "`required`",
        Rule::kw_units => "`units`",
        Rule::kw_stock => "`stock`",
        Rule::kw_mesh => "`mesh`",
        Rule::kw_cut => "`cut`",
        Rule::kw_add => "`add`",
        Rule::kw_face => "`face`",
        Rule::kw_feature => "`feature`",
        Rule::kw_datum => "`datum`",
        Rule::kw_frame => "`frame`",
        Rule::kw_tolerance => "`tolerance`",
        Rule::kw_group => "`group`",
        Rule::kw_segment => "`segment`",
        Rule::kw_step_face => "`step_face`",
        Rule::kw_qif_face => "`qif_face`",
        Rule::kw_select => "`select`",
        Rule::kw_prefer => "`prefer`",
        Rule::kw_forbid => "`forbid`",
        Rule::kw_sample => "`sample`",
        Rule::kw_with => "`with`",
        Rule::block_kw => "`cmm`, `head`, `probe`, `stylus`, `body`, `extension`, `sampling` or `fixture`",
        Rule::file | Rule::item => "an item (`use`, `part`, `cmm`, `plan`, …)",
        Rule::use_item => "a `use` statement",
        Rule::module_path => "a module path such as `std::probes`",
        Rule::use_select => "`*` or `{ names }`",
        Rule::glob => "`*`",
        // Whole items only ever fail part-way; what was expected there is named instead.
        Rule::block_item | Rule::part_item | Rule::hierarchy_item | Rule::plan_item => return None,
        Rule::block => "`{`",
        Rule::prop => "a property (`name value`)",
        Rule::part_stmt
        | Rule::units_stmt
        | Rule::stock_stmt
        | Rule::mesh_stmt
        | Rule::cut_stmt
        | Rule::face_stmt
        | Rule::feature_stmt
        | Rule::datum_stmt
        | Rule::frame_stmt
        | Rule::tolerance_stmt => "a part statement (`units`, `stock`, `mesh`, `cut`, `add`, `face`, `feature`, `datum`, `frame`, `tolerance`)",
        Rule::face_expr | Rule::face_term => "a face (a name, `group \"…\"`, `segment N`, `step_face N` or `select(…)`)",
        Rule::group_ref => "`group \"…\"`",
        Rule::segment_ref => "`segment N`",
        Rule::file_face_ref => "`step_face N` or `qif_face N`",
        Rule::select_ref => "`select(…)`",
        Rule::level => "a level (`required approachability` or `same_setup(T, *)`)",
        Rule::required_level => "`required approachability`",
        Rule::same_level => "a level such as `same_setup(T, *)`",
        Rule::group_part => "`T`, `F` or `*`",
        Rule::plan_stmt => "a plan statement",
        Rule::pref_stmt => "`prefer` or `forbid`",
        Rule::sample_stmt => "`sample FEATURE with STRATEGY`",
        Rule::value | Rule::arg | Rule::list_entry => "a value",
        Rule::list => "a list `[…]`",
        Rule::tuple => "a tuple `(…)`",
        Rule::range => "a range `a .. b`",
        Rule::limits => "limits such as `10 mm ± 0.1 mm`",
        Rule::pm => "`±`",
        Rule::quantity | Rule::number => "a number",
        Rule::signed_quantity | Rule::signed_number => "a signed number such as `+0.1 mm`",
        Rule::unit => "a unit",
        Rule::integer => "a whole number",
        Rule::direction => "a direction such as `+z`",
        Rule::string => "a string",
        Rule::call => "a call such as `box(…)`",
        Rule::args => "arguments",
        Rule::named_arg => "a named argument",
        Rule::path => "a name",
    })
}

/// Turns pest's error into ours, naming expectations in words.
pub(crate) fn syntax_error(file: FileId, text: &str, e: pest::error::Error<Rule>) -> SyntaxError {
    let pos = match e.location {
        pest::error::InputLocation::Pos(p) => p,
        pest::error::InputLocation::Span((s, _)) => s,
    };
    let mut expected: Vec<String> = match &e.variant {
        pest::error::ErrorVariant::ParsingError { positives, .. } => positives
            .iter()
            .filter_map(|r| word(*r))
            .map(String::from)
            .collect(),
        pest::error::ErrorVariant::CustomError { .. } => vec![],
    };
    // Token-level attempts see literals (`=`, `)`, `,`) that rule positives miss, and
    // the farthest position the parser reached.
    let mut pos = pos;
    // Where an item was expected, "an item" says it. At the file's start pest names the
    // `file` rule; after a comment it names each item keyword, and its attempts run into
    // a misspelt keyword's prefix (`probe` of `probee`): either way, an item.
    let item_expected = match &e.variant {
        pest::error::ErrorVariant::ParsingError { positives, .. } => {
            positives
                .iter()
                .any(|r| matches!(r, Rule::item | Rule::file))
                || [Rule::kw_use, Rule::kw_part, Rule::kw_plan]
                    .iter()
                    .all(|k| positives.contains(k))
        }
        pest::error::ErrorVariant::CustomError { .. } => false,
    };
    if item_expected {
        expected = vec![word(Rule::item).unwrap_or("an item").to_string()];
    }
    if let Some(att) = e.parse_attempts().filter(|_| !item_expected) {
        if att.max_position >= pos {
            let mut words: Vec<String> = Vec::new();
            // pest 2.9 does not re-export `ParseAttempt` and `ParsingToken`; their
            // `Debug` forms (`Rule(name)`, `Sensitive { .. }`) are read instead.
            for stack in att.call_stacks() {
                let deepest = format!("{:?}", stack.deepest);
                let rule = deepest
                    .strip_prefix("Rule(")
                    .and_then(|n| n.strip_suffix(')'))
                    .and_then(rule_named);
                if let Some(w) = rule.and_then(|r| word(r).or_else(|| stack.parent.and_then(word)))
                {
                    words.push(w.to_string());
                }
            }
            for t in att.expected_tokens() {
                if !format!("{t:?}").starts_with("Sensitive") {
                    continue;
                }
                let token = t.to_string();
                if is_noise(&token) {
                    continue;
                }
                words.push(if token == "\n" {
                    "a new line".to_string()
                } else {
                    format!("`{token}`")
                });
            }
            if !words.is_empty() {
                pos = att.max_position;
                expected = words;
            }
        }
    }
    // Continuations of a complete value (`10 mm` could go on as limits or a range) only
    // matter when nothing else was expected.
    let continuation = |w: &String| {
        matches!(
            w.as_str(),
            "`±`" | "a range `a .. b`" | "a signed number such as `+0.1 mm`" | "a unit"
        )
    };
    if expected.iter().any(|w| !continuation(w)) {
        expected.retain(|w| !continuation(w));
    }
    expected.sort_unstable();
    expected.dedup();
    if expected.len() > 8 {
        expected.truncate(7);
        expected.push("…".into());
    }
    let expected = match expected.as_slice() {
        [] => "something else".to_string(),
        [one] => one.to_string(),
        [init @ .., last] => format!("{} or {last}", init.join(", ")),
    };
    let (found, len) = found_at(text, pos);
    let help = if found == "end of file" {
        "the file ends in the middle of a statement: is a `}` or `)` missing?".to_string()
    } else if expected.contains("a new line") || expected.contains("`;`") {
        "statements end at a new line, `;` or `,`".to_string()
    } else {
        format!("write {expected} here")
    };
    SyntaxError::Unexpected {
        span: Span::new(file, pos, pos + len),
        expected,
        found,
        help,
    }
}

/// The grammar rule of a name, as pest's `Debug` writes it.
fn rule_named(name: &str) -> Option<Rule> {
    Rule::all_rules()
        .iter()
        .find(|r| format!("{r:?}") == name)
        .copied()
}

/// Whitespace, comments, optional suffixes of numbers and paths, and keywords (which the
/// rule words already name): tokens that would only bury the real expectation.
fn is_noise(token: &str) -> bool {
    matches!(
        token,
        "\r" | " "
            | "\t"
            | "\u{feff}"
            | "//"
            | "/*"
            | "*/"
            | "%"
            | "+-"
            | "+/-"
            | "±"
            | "+"
            | "-"
            | ".."
            | "."
            | "::"
            | "["
            | "e"
            | "E"
    ) || token.chars().all(|c| c.is_ascii_alphabetic() || c == '_')
}

/// What sits at `pos`, in words, and its length in bytes.
fn found_at(text: &str, pos: usize) -> (String, usize) {
    let rest = text.get(pos..).unwrap_or("");
    let Some(c) = rest.chars().next() else {
        return ("end of file".into(), 0);
    };
    if c == '\n' || c == '\r' {
        return ("end of line".into(), 0);
    }
    let word_len = |pred: fn(char) -> bool| {
        rest.char_indices()
            .find(|&(_, ch)| !pred(ch))
            .map_or(rest.len(), |(i, _)| i)
    };
    let len = if c.is_alphanumeric() || c == '_' {
        word_len(|ch| ch.is_alphanumeric() || ch == '_' || ch == '.')
    } else {
        c.len_utf8()
    };
    let tok = &rest[..len];
    let shown: String = tok.chars().take(40).collect();
    (format!("`{shown}`"), len)
}
