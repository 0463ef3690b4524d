//! The requests the server answers: hover, definition, references, symbols,
//! completion, rename (`rename.rs` decides), formatting.
//!
//! Parameters of the wrong shape get -32602 Invalid params, an unknown method -32601
//! (JSON-RPC 2.0 §5.1); a position outside an open document's text is clamped to it
//! (`text.rs`), a document that is not open answers `null`.

use super::rpc::{Code, Failure};
use super::text::{self, FileLines};
use super::{complete, hover, rename, symbols, Analysis, Server};
use crate::source::{FileId, Span};
use crate::Checked;
use lsp_types as lt;
use serde_json::Value;

/// Parameters as their type, or -32602.
fn params<P: serde::de::DeserializeOwned>(v: Value) -> Result<P, Failure> {
    serde_json::from_value(v).map_err(|e| (Code::InvalidParams, format!("invalid params: {e}")))
}

/// A result as JSON, or an internal error where it cannot be written.
fn json<T: serde::Serialize>(v: T) -> Result<Value, Failure> {
    serde_json::to_value(v).map_err(|e| (Code::InternalError, e.to_string()))
}

impl Server {
    /// The answer to a request while the server runs.
    pub(super) fn answer(&mut self, method: &str, p: Value) -> Result<Value, Failure> {
        use lt::request::*;
        match method {
            HoverRequest::METHOD => json(self.on_hover(params(p)?)?),
            GotoDefinition::METHOD => json(
                self.on_definition(params(p)?)?
                    .map(lt::GotoDefinitionResponse::Scalar),
            ),
            References::METHOD => json(self.on_references(params(p)?)?),
            DocumentSymbolRequest::METHOD => json(self.on_document_symbols(params(p)?)),
            Completion::METHOD => json(self.on_completion(params(p)?)),
            Rename::METHOD => json(self.on_rename(params(p)?)?),
            Formatting::METHOD => json(self.on_formatting(params(p)?)),
            _ => Err((
                Code::MethodNotFound,
                format!("inspc lsp does not answer `{method}`"),
            )),
        }
    }

    /// The hover at a position: what the name there is, in Markdown.
    fn on_hover(&self, p: lt::HoverParams) -> Result<Option<lt::Hover>, Failure> {
        let at = &p.text_document_position_params;
        let Some((a, file, offset)) = self.at(&at.text_document.uri, at.position) else {
            return Ok(None);
        };
        let Some((span, md)) = hover::hover(a, file, offset) else {
            return Ok(None);
        };
        Ok(Some(lt::Hover {
            contents: lt::HoverContents::Markup(lt::MarkupContent {
                kind: lt::MarkupKind::Markdown,
                value: md,
            }),
            range: Some(FileLines::new(&a.front.sources).range(span)),
        }))
    }

    /// Where the name at a position is declared.
    fn on_definition(&self, p: lt::GotoDefinitionParams) -> Result<Option<lt::Location>, Failure> {
        let at = &p.text_document_position_params;
        let Some((a, file, offset)) = self.at(&at.text_document.uri, at.position) else {
            return Ok(None);
        };
        let Some((_, decl)) = symbols::target(&a.front, file, offset) else {
            return Ok(None);
        };
        let mut lines = FileLines::new(&a.front.sources);
        self.location(&a.front, &mut lines, decl).map(Some)
    }

    /// Every use of the name at a position, its declaration too when asked.
    fn on_references(&self, p: lt::ReferenceParams) -> Result<Option<Vec<lt::Location>>, Failure> {
        let at = &p.text_document_position;
        let include = p.context.include_declaration;
        let Some((a, file, offset)) = self.at(&at.text_document.uri, at.position) else {
            return Ok(None);
        };
        let Some((_, decl)) = symbols::target(&a.front, file, offset) else {
            return Ok(Some(Vec::new()));
        };
        let mut lines = FileLines::new(&a.front.sources);
        symbols::references(&a.front, decl)
            .into_iter()
            .filter(|s| include || *s != decl)
            .map(|s| self.location(&a.front, &mut lines, s))
            .collect::<Result<Vec<_>, _>>()
            .map(Some)
    }

    /// A document's outline.
    fn on_document_symbols(
        &self,
        p: lt::DocumentSymbolParams,
    ) -> Option<lt::DocumentSymbolResponse> {
        self.at(&p.text_document.uri, lt::Position::default())
            .map(|(a, file, _)| lt::DocumentSymbolResponse::Nested(document_symbols(a, file)))
    }

    /// The completions at a position, from the document's last parsed analysis.
    fn on_completion(&self, p: lt::CompletionParams) -> Option<lt::CompletionResponse> {
        let at = &p.text_document_position;
        let path = self.canonical(&at.text_document.uri).ok()?;
        let (doc, a) = (self.docs.get(&path)?, self.analyses.get(&path)?);
        let offset = doc.text.offset(at.position);
        let checked = a.parsed.as_deref().unwrap_or(&a.front);
        let file = checked
            .sources
            .find_path(&path)
            .unwrap_or(crate::source::FileId(u32::MAX));
        let items = complete::complete(checked, a.deep.as_ref(), file, doc.text.text(), offset);
        Some(lt::CompletionResponse::Array(items))
    }

    /// The edits that rename the name at a position, wherever it is used, or why not.
    fn on_rename(&self, p: lt::RenameParams) -> Result<Option<lt::WorkspaceEdit>, Failure> {
        let at = &p.text_document_position;
        let Some((a, file, offset)) = self.at(&at.text_document.uri, at.position) else {
            return Ok(None);
        };
        let spans = rename::rename(&a.front, &self.overlay(), file, offset, &p.new_name)?;
        let mut lines = FileLines::new(&a.front.sources);
        // `WorkspaceEdit` keys its edits by `Uri`, which clippy thinks mutable.
        #[allow(clippy::mutable_key_type)]
        let mut changes: std::collections::HashMap<lt::Uri, Vec<lt::TextEdit>> =
            std::collections::HashMap::new();
        for s in spans {
            let loc = self.location(&a.front, &mut lines, s)?;
            changes.entry(loc.uri).or_default().push(lt::TextEdit {
                range: loc.range,
                new_text: p.new_name.clone(),
            });
        }
        Ok(Some(lt::WorkspaceEdit {
            changes: Some(changes),
            ..Default::default()
        }))
    }

    /// The edit that formats a document, when formatting changes its layout only.
    fn on_formatting(&self, p: lt::DocumentFormattingParams) -> Option<Vec<lt::TextEdit>> {
        let path = self.canonical(&p.text_document.uri).ok()?;
        let doc = self.docs.get(&path)?;
        let text = doc.text.text();
        // Only a layout change that keeps the parse tree (as `inspc fmt`).
        Some(match crate::fmt::format_checked(text) {
            Some(formatted) if formatted != text => vec![lt::TextEdit {
                range: doc.text.range(0..text.len()),
                new_text: formatted,
            }],
            _ => Vec::new(),
        })
    }

    /// The analysis of an open document, its file id there and the byte offset of a
    /// position.
    fn at(&self, uri: &lt::Uri, pos: lt::Position) -> Option<(&Analysis, FileId, usize)> {
        let path = self.canonical(uri).ok()?;
        let a = self.analyses.get(&path)?;
        let doc = self.docs.get(&path)?;
        let file = a.front.sources.find_path(&path)?;
        Some((a, file, doc.text.offset(pos)))
    }

    /// Where a span is, for the client: a user file by its path, a standard-library file
    /// by the server's copy.
    fn location(
        &self,
        checked: &Checked,
        lines: &mut FileLines,
        span: Span,
    ) -> Result<lt::Location, Failure> {
        let f = checked.sources.get(span.file);
        let failed = |why: String| (Code::RequestFailed, why);
        let path = match &f.path {
            Some(p) => p.clone(),
            None => {
                let copy = self.stdlib.get_or_init(super::stdlib::StdlibCopy::write);
                let copy = copy.as_ref().map_err(|e| failed(e.clone()))?;
                copy.path_of(&f.name)
                    .ok_or_else(|| failed(format!("`{}` is no stdlib file", f.name)))?
            }
        };
        let uri = text::uri_of(&path)
            .ok_or_else(|| failed(format!("{} has no `file://` URI", path.display())))?;
        Ok(lt::Location {
            uri,
            range: lines.range(span),
        })
    }
}

/// The outline of a file: its items, and in a part its operations, faces, features,
/// datums, frames and tolerances.
#[allow(deprecated)] // `DocumentSymbol::deprecated` must still be written
fn document_symbols(a: &Analysis, file: FileId) -> Vec<lt::DocumentSymbol> {
    let checked = &a.front;
    let lines = text::LineIndex::new(checked.sources.get(file).text.as_str());
    let all = symbols::decls(checked);
    let kind_of = |k: symbols::DeclKind| match k {
        symbols::DeclKind::Part => lt::SymbolKind::CLASS,
        symbols::DeclKind::Plan => lt::SymbolKind::FUNCTION,
        symbols::DeclKind::Hierarchy => lt::SymbolKind::ENUM,
        symbols::DeclKind::Block(_) => lt::SymbolKind::STRUCT,
        symbols::DeclKind::Tolerance => lt::SymbolKind::PROPERTY,
        symbols::DeclKind::Datum | symbols::DeclKind::Frame => lt::SymbolKind::CONSTANT,
        symbols::DeclKind::Label => lt::SymbolKind::KEY,
        _ => lt::SymbolKind::FIELD,
    };
    let symbol =
        |d: &symbols::Decl, children: Option<Vec<lt::DocumentSymbol>>| lt::DocumentSymbol {
            name: d.name.name.clone(),
            detail: Some(d.kind.keyword().to_string()),
            kind: kind_of(d.kind),
            tags: None,
            deprecated: None,
            range: lines.range(d.full.range()),
            selection_range: lines.range(d.name.span.range()),
            children,
        };
    all.iter()
        .filter(|d| d.name.span.file == file && d.is_item())
        .map(|d| {
            let children = match d.kind {
                symbols::DeclKind::Part => Some(
                    all.iter()
                        .filter(|c| c.part.is_some_and(|p| p.name.span == d.name.span))
                        .map(|c| symbol(c, None))
                        .collect(),
                ),
                symbols::DeclKind::Block(crate::syntax::ast::BlockKind::Cmm) => Some(
                    all.iter()
                        .filter(|c| c.kind == symbols::DeclKind::Label)
                        .filter(|c| symbols::within(c.full, d.full))
                        .map(|c| symbol(c, None))
                        .collect(),
                ),
                _ => None,
            };
            symbol(d, children)
        })
        .collect()
}
