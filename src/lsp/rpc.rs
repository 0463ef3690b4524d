//! JSON-RPC 2.0 messages: a body read by the transport → a request, a notification, a
//! response, or the error response that an invalid message gets.
//!
//! **Decision: every request gets an answer, no notification does.** JSON-RPC 2.0
//! (<https://www.jsonrpc.org/specification>, §4–5.1): a body that is not JSON gets
//! -32700 Parse error, a JSON value that is not a request object -32600 Invalid
//! Request, both with id `null` when the id cannot be read; an unknown method -32601,
//! parameters of the wrong shape -32602. A notification (a valid request object
//! without `id`) is never answered: what the server cannot do with one it logs
//! (`window/logMessage`). LSP 3.17 adds -32002 (a request before `initialize`) and
//! -32803 RequestFailed ("the method name was known and the parameters were valid",
//! but the server refuses, as a rename onto a name in use). LSP sends no batches, so a
//! JSON array is an invalid request; `"params": null` counts as no params (the form in
//! which clients send `shutdown` and `exit`). Ids are numbers or strings (`null` is refused, as
//! LSP's `integer | string` does) and are echoed back as they came.

use serde_json::{json, Map, Value};

/// The error codes the server answers with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Code {
    ParseError = -32700,
    InvalidRequest = -32600,
    MethodNotFound = -32601,
    InvalidParams = -32602,
    InternalError = -32603,
    ServerNotInitialized = -32002,
    RequestFailed = -32803,
}

/// A request's failure: its code and a sentence.
pub(crate) type Failure = (Code, String);

/// One message from the client.
#[derive(Debug, PartialEq)]
pub(crate) enum Incoming {
    /// A request, to be answered.
    Request {
        id: Value,
        method: String,
        params: Value,
    },
    /// A notification, never answered.
    Notification { method: String, params: Value },
    /// A response to a request of the server's (it sends none).
    Response,
    /// Not a message: the error response it gets.
    Invalid(Value),
}

/// The message a body holds.
pub(crate) fn classify(body: &[u8]) -> Incoming {
    let value: Value = match serde_json::from_slice(body) {
        Ok(v) => v,
        Err(e) => {
            let why = format!("the message is not JSON: {e}");
            return Incoming::Invalid(error(Value::Null, Code::ParseError, why));
        }
    };
    let Value::Object(mut object) = value else {
        let why = "a message is one JSON object (LSP sends no batches)";
        return Incoming::Invalid(error(Value::Null, Code::InvalidRequest, why));
    };
    let id = object.remove("id");
    let id_ok = matches!(id, None | Some(Value::Number(_) | Value::String(_)));
    // The id to answer with: `null` when there is none or it is not one.
    let reply = || id.clone().filter(|_| id_ok).unwrap_or(Value::Null);
    let invalid = |why: &str| Incoming::Invalid(error(reply(), Code::InvalidRequest, why));
    if object.get("jsonrpc").and_then(Value::as_str) != Some("2.0") {
        return invalid("a message has `\"jsonrpc\": \"2.0\"`");
    }
    if !id_ok {
        return invalid("an id is a number or a string");
    }
    let method = match object.remove("method") {
        Some(Value::String(m)) => m,
        Some(_) => return invalid("a method is a string"),
        None if id.is_some() && is_response(&object) => return Incoming::Response,
        None => return invalid("a message has a `method` (or is a response)"),
    };
    let params = match object.remove("params") {
        // `null` as no params: LSP's own `shutdown` and `exit` have none, and clients
        // write them so.
        None | Some(Value::Null) => Value::Null,
        Some(p @ (Value::Object(_) | Value::Array(_))) => p,
        Some(_) => return invalid("`params` is an object or an array"),
    };
    match id {
        Some(id) => Incoming::Request { id, method, params },
        None => Incoming::Notification { method, params },
    }
}

/// Whether an object (its id removed) is a response: `result` or `error`, not both.
fn is_response(object: &Map<String, Value>) -> bool {
    object.contains_key("result") != object.contains_key("error")
}

/// A response with a result.
pub(crate) fn result(id: Value, result: Value) -> Value {
    json!({ "jsonrpc": "2.0", "id": id, "result": result })
}

/// A response with an error.
pub(crate) fn error(id: Value, code: Code, message: impl Into<String>) -> Value {
    let error = json!({ "code": code as i32, "message": message.into() });
    json!({ "jsonrpc": "2.0", "id": id, "error": error })
}

/// A notification.
pub(crate) fn notification(method: &str, params: Value) -> Value {
    json!({ "jsonrpc": "2.0", "method": method, "params": params })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn code(m: Incoming) -> (i64, Value) {
        match m {
            Incoming::Invalid(e) => (e["error"]["code"].as_i64().unwrap(), e["id"].clone()),
            other => panic!("valid: {other:?}"),
        }
    }

    #[test]
    fn invalid_messages_get_their_codes() {
        let parse = Code::ParseError as i64;
        let invalid = Code::InvalidRequest as i64;
        let cases: [(&str, i64, Value); 10] = [
            ("{", parse, Value::Null),
            ("\u{feff}{}", parse, Value::Null),
            ("[]", invalid, Value::Null),
            (
                "[{\"jsonrpc\":\"2.0\",\"method\":\"x\"}]",
                invalid,
                Value::Null,
            ),
            ("17", invalid, Value::Null),
            (r#"{"jsonrpc":"2.0","id":3}"#, invalid, json!(3)),
            (
                r#"{"jsonrpc":"1.0","id":"a","method":"m"}"#,
                invalid,
                json!("a"),
            ),
            (
                r#"{"jsonrpc":"2.0","id":[1],"method":"m"}"#,
                invalid,
                Value::Null,
            ),
            (r#"{"jsonrpc":"2.0","method":7}"#, invalid, Value::Null),
            (
                r#"{"jsonrpc":"2.0","id":1,"method":"m","params":3}"#,
                invalid,
                json!(1),
            ),
        ];
        for (body, want, id) in cases {
            assert_eq!(code(classify(body.as_bytes())), (want, id), "{body}");
        }
        assert_eq!(code(classify(&[0xff, 0xfe])).0, parse);
    }

    #[test]
    fn requests_notifications_and_responses() {
        let r = classify(br#"{"jsonrpc":"2.0","id":"x","method":"shutdown"}"#);
        assert_eq!(
            r,
            Incoming::Request {
                id: json!("x"),
                method: "shutdown".into(),
                params: Value::Null
            }
        );
        let n = classify(br#"{"jsonrpc":"2.0","method":"exit","params":[]}"#);
        assert!(matches!(n, Incoming::Notification { .. }));
        let r = classify(br#"{"jsonrpc":"2.0","id":1,"result":null}"#);
        assert_eq!(r, Incoming::Response);
    }
}
