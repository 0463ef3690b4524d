//! LSP 3.17's lifecycle over the messages the transport and JSON-RPC layer hand up:
//! `initialize`, the requests and notifications of a running server, `shutdown`, `exit`.
//!
//! Before `initialize` a request gets -32002 ServerNotInitialized and a notification is
//! dropped; a second `initialize` gets -32600; after `shutdown` a request gets -32600
//! and only `exit` is expected ("Lifecycle Messages", LSP 3.17). `exit` ends the server
//! with code 0 after `shutdown`, 1 without. A body over the size limit is answered with
//! -32600 and id `null` (its id was never read); a stream that ends before `shutdown`
//! and `exit`, or that breaks (`transport.rs`), ends the server with code 1.

use super::rpc::{self, Code, Incoming};
use super::transport::{self, Frame};
use super::Server;
use lsp_types as lt;
use serde_json::Value;

/// Where the server is in LSP's lifecycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Phase {
    Starting,
    Running,
    ShuttingDown,
}

impl Server {
    /// Handles what the reader found; `Some` ends the server.
    pub(super) fn frame(&mut self, frame: Frame, phase: &mut Phase) -> Option<Result<(), String>> {
        match frame {
            Frame::Body(body) => self.message(rpc::classify(&body), phase),
            Frame::TooLarge(len) => {
                let why = format!(
                    "a message of {len} bytes is over the {} MiB inspc reads; it was skipped unread",
                    transport::BODY_LIMIT >> 20
                );
                eprintln!("inspc lsp: {why}");
                // Its id was never read: JSON-RPC answers such a message with id null.
                let answer = rpc::error(Value::Null, Code::InvalidRequest, why);
                self.outbox.push(answer);
                None
            }
            Frame::End if *phase == Phase::ShuttingDown => Some(Ok(())),
            Frame::End => Some(Err(
                "the client closed the stream without `shutdown` and `exit`".into(),
            )),
            Frame::Broken(transport::Broken(why)) => Some(Err(format!(
                "{why}: the stream cannot be resynchronised, so the server stops"
            ))),
        }
    }

    /// Handles one message as LSP's lifecycle allows; `Some` ends the server.
    fn message(&mut self, message: Incoming, phase: &mut Phase) -> Option<Result<(), String>> {
        match message {
            Incoming::Invalid(answer) => self.outbox.push(answer),
            Incoming::Response => self.log("inspc: a response came, to no request".into()),
            Incoming::Notification { method, .. } if method == "exit" => {
                return Some(match phase {
                    Phase::ShuttingDown => Ok(()),
                    _ => Err("the client sent `exit` without `shutdown`".into()),
                });
            }
            // Before `initialize` and after `shutdown`, notifications are dropped.
            Incoming::Notification { method, params } if *phase == Phase::Running => {
                if let Err(why) = self.notification(&method, params) {
                    self.log(format!("inspc: ignored `{method}`: {why}"));
                }
            }
            Incoming::Notification { .. } => {}
            Incoming::Request { id, method, params } => {
                let answer = match (*phase, method.as_str()) {
                    (Phase::Starting, "initialize") => {
                        *phase = Phase::Running;
                        initialize_result()
                    }
                    (Phase::Starting, _) => Err((
                        Code::ServerNotInitialized,
                        "the server has not been initialized".into(),
                    )),
                    (Phase::Running, "initialize") => Err((
                        Code::InvalidRequest,
                        "`initialize` was already received".into(),
                    )),
                    (Phase::Running, "shutdown") => {
                        *phase = Phase::ShuttingDown;
                        Ok(Value::Null)
                    }
                    (Phase::Running, _) => self.answer(&method, params),
                    (Phase::ShuttingDown, _) => Err((
                        Code::InvalidRequest,
                        "the server is shutting down: only `exit` is expected".into(),
                    )),
                };
                self.outbox.push(match answer {
                    Ok(v) => rpc::result(id, v),
                    Err((code, why)) => rpc::error(id, code, why),
                });
            }
        }
        None
    }
}

fn capabilities() -> lt::ServerCapabilities {
    lt::ServerCapabilities {
        text_document_sync: Some(lt::TextDocumentSyncCapability::Options(
            lt::TextDocumentSyncOptions {
                open_close: Some(true),
                change: Some(lt::TextDocumentSyncKind::FULL),
                save: Some(lt::TextDocumentSyncSaveOptions::SaveOptions(
                    lt::SaveOptions {
                        include_text: Some(false),
                    },
                )),
                ..Default::default()
            },
        )),
        hover_provider: Some(lt::HoverProviderCapability::Simple(true)),
        definition_provider: Some(lt::OneOf::Left(true)),
        references_provider: Some(lt::OneOf::Left(true)),
        document_symbol_provider: Some(lt::OneOf::Left(true)),
        rename_provider: Some(lt::OneOf::Left(true)),
        document_formatting_provider: Some(lt::OneOf::Left(true)),
        completion_provider: Some(lt::CompletionOptions {
            trigger_characters: Some(vec![":".into(), " ".into(), ".".into(), "\"".into()]),
            ..Default::default()
        }),
        ..Default::default()
    }
}

/// The answer to `initialize`: what the server can do, and who it is.
fn initialize_result() -> Result<Value, rpc::Failure> {
    let result = lt::InitializeResult {
        capabilities: capabilities(),
        server_info: Some(lt::ServerInfo {
            name: "inspc".into(),
            version: Some(env!("CARGO_PKG_VERSION").into()),
        }),
    };
    serde_json::to_value(result).map_err(|e| (Code::InternalError, e.to_string()))
}
