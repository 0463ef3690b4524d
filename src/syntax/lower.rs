//! Lowering pest pairs into the typed AST.
//!
//! The grammar guarantees the shape of every pair, so the `expect`s here state grammar
//! facts; the fuzz property test (`tests/suite/no_panic.rs`) holds us to them.

use super::ast::*;
use super::{Rule, SyntaxError};
use crate::source::{FileId, Span};
use pest::iterators::{Pair, Pairs};

type P<'a> = Pair<'a, Rule>;
type R<T> = Result<T, SyntaxError>;

struct L {
    file: FileId,
}

/// The character of a `\u{…}` escape (1 to 6 hex digits, a Unicode scalar value) at
/// the start of `after` (what follows `\u`), and the escape's length there.
fn unicode_escape(after: &str) -> Option<(char, usize)> {
    let digits = after.strip_prefix('{')?.split_once('}')?.0;
    if digits.is_empty() || digits.len() > 6 || !digits.bytes().all(|b| b.is_ascii_hexdigit()) {
        return None;
    }
    let c = char::from_u32(u32::from_str_radix(digits, 16).ok()?)?;
    Some((c, digits.len() + 2))
}

impl L {
    /// A pair's span without the blanks pest's implicit whitespace leaves at its end (a
    /// bare number's optional unit consumes the space after it), so that labels
    /// underline what was written.
    fn span(&self, p: &P) -> Span {
        let s = p.as_span();
        let kept = s.as_str().trim_end_matches([' ', '\t']).len();
        Span::new(self.file, s.start(), s.start() + kept)
    }

    fn ident(&self, p: P) -> Ident {
        Ident {
            name: p.as_str().to_string(),
            span: self.span(&p),
        }
    }

    fn string(&self, p: P) -> R<Str> {
        let span = self.span(&p);
        let inner = p.into_inner().next().expect("string has an inner part");
        let raw = inner.as_str();
        let mut value = String::with_capacity(raw.len());
        let mut chars = raw.char_indices();
        while let Some((i, c)) = chars.next() {
            if c != '\\' {
                value.push(c);
                continue;
            }
            let escape = match chars.next() {
                Some((_, '\\')) => Some('\\'),
                Some((_, '"')) => Some('"'),
                Some((_, 'n')) => Some('\n'),
                Some((_, 't')) => Some('\t'),
                Some((j, 'u')) => unicode_escape(&raw[j + 1..]).map(|(c, len)| {
                    // Past `{`, the digits and `}`, all ASCII.
                    for _ in 0..len {
                        chars.next();
                    }
                    c
                }),
                Some(_) => None,
                None => Some('\\'),
            };
            match escape {
                Some(c) => value.push(c),
                None => {
                    let other = raw[i + 1..].chars().next().unwrap_or('\\');
                    let start = inner.as_span().start() + i;
                    let end = start + 1 + other.len_utf8();
                    return Err(SyntaxError::InvalidEscape {
                        span: Span::new(self.file, start, end),
                        text: format!("\\{other}"),
                    });
                }
            }
        }
        Ok(Str { value, span })
    }

    fn number(&self, p: &P) -> R<f64> {
        let text = p.as_str();
        match text.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(SyntaxError::InvalidNumber {
                span: self.span(p),
                text: text.to_string(),
            }),
        }
    }

    fn integer(&self, p: &P) -> R<u32> {
        p.as_str()
            .parse::<u32>()
            .map_err(|_| SyntaxError::InvalidNumber {
                span: self.span(p),
                text: p.as_str().to_string(),
            })
    }

    fn quantity(&self, p: P) -> R<Quantity> {
        let span = self.span(&p);
        let mut inner = p.into_inner();
        let num = inner.next().expect("quantity has a number");
        let value = self.number(&num)?;
        let unit = inner.next().map(|u| self.ident(u));
        Ok(Quantity { value, unit, span })
    }

    fn path(&self, p: P) -> R<Path> {
        let span = self.span(&p);
        let text = p.as_str().to_string();
        let mut segs = Vec::new();
        for s in p.into_inner() {
            match s.as_rule() {
                Rule::ident => segs.push(PathSeg::Name(self.ident(s))),
                Rule::integer => segs.push(PathSeg::Index(self.integer(&s)?, self.span(&s))),
                r => unreachable!("path segment {r:?}"),
            }
        }
        Ok(Path { segs, text, span })
    }

    fn value(&self, p: P) -> R<Value> {
        let span = self.span(&p);
        let inner = if p.as_rule() == Rule::value {
            p.into_inner().next().expect("value has one child")
        } else {
            p
        };
        let kind = match inner.as_rule() {
            Rule::quantity => ValueKind::Quantity(self.quantity(inner)?),
            Rule::limits => {
                let mut it = inner.into_inner();
                let nominal = self.quantity(it.next().expect("nominal"))?;
                let second = it.next().expect("limits has a second part");
                if second.as_rule() == Rule::pm {
                    let plus = self.quantity(it.next().expect("deviation"))?;
                    let minus = Quantity {
                        value: -plus.value,
                        ..plus.clone()
                    };
                    ValueKind::Limits {
                        nominal,
                        plus,
                        minus,
                    }
                } else {
                    let a = self.quantity(second)?;
                    let b = self.quantity(it.next().expect("second deviation"))?;
                    // Written in either order: the larger is the upper deviation.
                    let (plus, minus) = if a.value >= b.value { (a, b) } else { (b, a) };
                    ValueKind::Limits {
                        nominal,
                        plus,
                        minus,
                    }
                }
            }
            Rule::range => {
                let mut it = inner.into_inner();
                let a = self.quantity(it.next().expect("range start"))?;
                let b = self.quantity(it.next().expect("range end"))?;
                ValueKind::Range(a, b)
            }
            Rule::direction => {
                let s = inner.as_str();
                let axis = match &s[1..2] {
                    "x" => 0,
                    "y" => 1,
                    _ => 2,
                };
                ValueKind::Direction {
                    axis,
                    negative: s.starts_with('-'),
                }
            }
            Rule::string => ValueKind::Str(self.string(inner)?),
            Rule::tuple => ValueKind::Tuple(
                inner
                    .into_inner()
                    .map(|v| self.value(v))
                    .collect::<R<_>>()?,
            ),
            Rule::list => ValueKind::List(self.list(inner)?),
            Rule::block => ValueKind::Block(self.props(inner.into_inner())?),
            Rule::call => ValueKind::Call(self.call(inner)?),
            Rule::path => ValueKind::Path(self.path(inner)?),
            r => unreachable!("value form {r:?}"),
        };
        Ok(Value { kind, span })
    }

    fn list(&self, p: P) -> R<Vec<ListEntry>> {
        p.into_inner()
            .map(|e| {
                let mut it = e.into_inner();
                let first = it.next().expect("list entry has a value");
                if first.as_rule() == Rule::list_label {
                    let label = self.ident(first.into_inner().next().expect("label name"));
                    let value = self.value(it.next().expect("labelled value"))?;
                    Ok(ListEntry {
                        label: Some(label),
                        value,
                    })
                } else {
                    Ok(ListEntry {
                        label: None,
                        value: self.value(first)?,
                    })
                }
            })
            .collect()
    }

    fn args(&self, pairs: Pairs<Rule>) -> R<Vec<Arg>> {
        let mut out = Vec::new();
        for a in pairs {
            match a.as_rule() {
                Rule::args => out.extend(self.args(a.into_inner())?),
                Rule::named_arg => {
                    let mut it = a.into_inner();
                    let name = self.ident(it.next().expect("name"));
                    out.push(Arg::Named(name, self.value(it.next().expect("value"))?));
                }
                _ => out.push(Arg::Positional(self.value(a)?)),
            }
        }
        Ok(out)
    }

    fn call(&self, p: P) -> R<Call> {
        let span = self.span(&p);
        let mut it = p.into_inner();
        let callee = self.path(it.next().expect("callee"))?;
        Ok(Call {
            callee,
            args: self.args(it)?,
            span,
        })
    }

    fn props(&self, pairs: Pairs<Rule>) -> R<Vec<Prop>> {
        pairs.map(|p| self.prop(p)).collect()
    }

    fn prop(&self, p: P) -> R<Prop> {
        let span = self.span(&p);
        let mut it = p.into_inner();
        let key = self.ident(it.next().expect("key"));
        let value = self.value(it.next().expect("value"))?;
        Ok(Prop { key, value, span })
    }

    fn item(&self, p: P) -> R<Option<Item>> {
        let span = self.span(&p);
        Ok(Some(match p.as_rule() {
            Rule::use_item => Item::Use(self.use_item(p, span)?),
            Rule::block_item => {
                let mut it = p.into_inner();
                let kw = it.next().expect("keyword");
                let kind = match kw.as_str() {
                    "cmm" => BlockKind::Cmm,
                    "head" => BlockKind::Head,
                    "probe" => BlockKind::Probe,
                    "stylus" => BlockKind::Stylus,
                    "body" => BlockKind::Body,
                    "extension" => BlockKind::Extension,
                    "fixture" => BlockKind::Fixture,
                    "scanner" => BlockKind::Scanner,
                    _ => BlockKind::Sampling,
                };
                let name = self.ident(it.next().expect("name"));
                let props = self.props(it.next().expect("block").into_inner())?;
                Item::Block(BlockItem {
                    kind,
                    name,
                    props,
                    span,
                })
            }
            Rule::part_item => Item::Part(self.part(p, span)?),
            Rule::hierarchy_item => {
                let mut it = p.into_inner();
                it.next();
                let name = self.ident(it.next().expect("name"));
                let levels = it.map(|l| self.level(l)).collect();
                Item::Hierarchy(Hierarchy { name, levels, span })
            }
            Rule::plan_item => Item::Plan(self.plan(p, span)?),
            Rule::EOI => return Ok(None),
            r => unreachable!("item {r:?}"),
        }))
    }

    fn use_item(&self, p: P, span: Span) -> R<Use> {
        let mut it = p.into_inner();
        it.next();
        let src = it.next().expect("use source");
        let source = match src.as_rule() {
            Rule::string => UseSource::File(self.string(src)?),
            _ => UseSource::Module(src.into_inner().map(|i| self.ident(i)).collect()),
        };
        let select = match it.next() {
            None => UseSelect::Implicit,
            Some(sel) => {
                let sel_span = self.span(&sel);
                let mut inner = sel.into_inner().peekable();
                match inner.peek().map(|p| p.as_rule()) {
                    Some(Rule::glob) => UseSelect::Glob(sel_span),
                    _ => UseSelect::Names(inner.map(|i| self.ident(i)).collect()),
                }
            }
        };
        Ok(Use {
            source,
            select,
            span,
        })
    }

    fn part(&self, p: P, span: Span) -> R<Part> {
        let mut it = p.into_inner();
        it.next();
        let name = self.ident(it.next().expect("part name"));
        let stmts = it.map(|s| self.part_stmt(s)).collect::<R<_>>()?;
        Ok(Part { name, stmts, span })
    }

    fn part_stmt(&self, p: P) -> R<PartStmt> {
        let span = self.span(&p);
        let rule = p.as_rule();
        let mut it = p.into_inner();
        let kw = it.next().expect("statement keyword");
        Ok(match rule {
            Rule::units_stmt => PartStmt::Units(self.ident(it.next().expect("unit"))),
            Rule::stock_stmt => PartStmt::Stock(self.call(it.next().expect("stock call"))?),
            Rule::mesh_stmt => {
                let path = self.string(it.next().expect("mesh path"))?;
                let props = match it.next() {
                    Some(b) => self.props(b.into_inner())?,
                    None => vec![],
                };
                PartStmt::Mesh { path, props, span }
            }
            Rule::cut_stmt => {
                let add = kw.as_str() == "add";
                let kind = self.ident(it.next().expect("cut kind"));
                let name = self.ident(it.next().expect("cut name"));
                let props = self.props(it.next().expect("block").into_inner())?;
                PartStmt::Cut {
                    add,
                    kind,
                    name,
                    props,
                    span,
                }
            }
            Rule::face_stmt | Rule::feature_stmt | Rule::datum_stmt => {
                let what = match rule {
                    Rule::face_stmt => NamedKind::Face,
                    Rule::feature_stmt => NamedKind::Feature,
                    _ => NamedKind::Datum,
                };
                let name = self.ident(it.next().expect("name"));
                let expr = it.next().map(|e| self.face_expr(e)).transpose()?;
                PartStmt::Named {
                    what,
                    name,
                    expr,
                    span,
                }
            }
            Rule::frame_stmt => {
                let name = self.ident(it.next().expect("name"));
                let refs = self.list(it.next().expect("list"))?;
                PartStmt::Frame { name, refs, span }
            }
            Rule::tolerance_stmt => {
                let name = self.ident(it.next().expect("name"));
                let call = self.call(it.next().expect("call"))?;
                PartStmt::Tolerance { name, call, span }
            }
            r => unreachable!("part statement {r:?}"),
        })
    }

    fn face_expr(&self, p: P) -> R<FaceExpr> {
        let span = self.span(&p);
        let mut terms = Vec::new();
        for t in p.into_inner() {
            let tspan = self.span(&t);
            terms.push(match t.as_rule() {
                Rule::path => FaceTerm::Path(self.path(t)?),
                Rule::group_ref => {
                    FaceTerm::Group(self.string(t.into_inner().nth(1).expect("group name"))?)
                }
                Rule::segment_ref => FaceTerm::Segment(
                    self.integer(&t.into_inner().nth(1).expect("segment id"))?,
                    tspan,
                ),
                Rule::file_face_ref => {
                    let mut it = t.into_inner();
                    let kind = match it.next().expect("keyword").as_rule() {
                        Rule::kw_qif_face => CadKind::Qif,
                        _ => CadKind::Step,
                    };
                    FaceTerm::FileFace(kind, self.integer(&it.next().expect("face id"))?, tspan)
                }
                Rule::select_ref => {
                    let mut it = t.into_inner();
                    it.next();
                    FaceTerm::Select(self.args(it)?, tspan)
                }
                r => unreachable!("face term {r:?}"),
            });
        }
        Ok(FaceExpr { terms, span })
    }

    fn level(&self, p: P) -> Level {
        let span = self.span(&p);
        let rule = p.as_rule();
        let mut it = p.into_inner();
        match rule {
            Rule::required_level => {
                it.next();
                Level::Required(self.ident(it.next().expect("constraint")), span)
            }
            _ => {
                let constraint = self.ident(it.next().expect("constraint"));
                let group = it
                    .map(|g| Ident {
                        name: g.as_str().to_string(),
                        span: self.span(&g),
                    })
                    .collect();
                Level::Same {
                    constraint,
                    group,
                    span,
                }
            }
        }
    }

    fn plan(&self, p: P, span: Span) -> R<Plan> {
        let mut it = p.into_inner();
        it.next();
        let name = self.ident(it.next().expect("plan name"));
        let mut stmts = Vec::new();
        for s in it {
            let sspan = self.span(&s);
            stmts.push(match s.as_rule() {
                Rule::prop => PlanStmt::Prop(self.prop(s)?),
                Rule::pref_stmt => {
                    let mut si = s.into_inner();
                    let forbid = si.next().expect("verb").as_str() == "forbid";
                    let kind = self.ident(si.next().expect("kind"));
                    let value = self.value(si.next().expect("value"))?;
                    let mut opts = Vec::new();
                    while let Some(k) = si.next() {
                        let key = self.ident(k);
                        let v = self.value(si.next().expect("option value"))?;
                        let pspan = key.span.join(v.span);
                        opts.push(Prop {
                            key,
                            value: v,
                            span: pspan,
                        });
                    }
                    PlanStmt::Pref {
                        forbid,
                        kind,
                        value,
                        opts,
                        span: sspan,
                    }
                }
                Rule::sample_stmt => {
                    let mut si = s.into_inner();
                    si.next();
                    let feature = self.path(si.next().expect("feature"))?;
                    si.next();
                    let strategy = self.value(si.next().expect("strategy"))?;
                    PlanStmt::Sample {
                        feature,
                        strategy,
                        span: sspan,
                    }
                }
                r => unreachable!("plan statement {r:?}"),
            });
        }
        Ok(Plan { name, stmts, span })
    }
}

/// Lowers the `file` pair.
pub(super) fn file(file: FileId, root: P) -> R<File> {
    let l = L { file };
    let mut items = Vec::new();
    for p in root.into_inner() {
        if let Some(item) = l.item(p)? {
            items.push(item);
        }
    }
    Ok(File { items })
}
