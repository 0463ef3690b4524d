//! The server in memory ([`super::serve`] with [`Work::FrontEnd`]), as the fuzz target
//! drives it: a whole session answered, and every prefix of it served without a panic.

use super::{serve, Work};
use serde_json::{json, Value};

/// A session framed as the base protocol frames it.
fn session() -> Vec<u8> {
    let text = include_str!("../../examples/f2.insp");
    let uri = "file:///mem/f2.insp";
    let at = |line: u32, character: u32| json!({ "textDocument": { "uri": uri }, "position": { "line": line, "character": character } });
    let mut rename = at(15, 14);
    rename["newName"] = json!("wide_slot");
    let messages = [
        json!({ "id": 1, "method": "initialize", "params": { "capabilities": {} } }),
        json!({ "method": "initialized", "params": {} }),
        json!({ "method": "textDocument/didOpen", "params": { "textDocument": {
            "uri": uri, "languageId": "insp", "version": 1, "text": text } } }),
        json!({ "id": 2, "method": "textDocument/hover", "params": at(15, 14) }),
        json!({ "id": 3, "method": "textDocument/definition", "params": at(25, 10) }),
        json!({ "id": 4, "method": "textDocument/rename", "params": rename }),
        json!({ "id": 5, "method": "textDocument/completion", "params": at(12, 4) }),
        json!({ "method": "textDocument/didSave", "params": { "textDocument": { "uri": uri } } }),
        json!({ "id": 6, "method": "shutdown" }),
        json!({ "method": "exit" }),
    ];
    let mut bytes = Vec::new();
    for mut m in messages {
        m["jsonrpc"] = json!("2.0");
        let body = m.to_string();
        bytes.extend(format!("Content-Length: {}\r\n\r\n{body}", body.len()).into_bytes());
        if m["id"] == json!(2) {
            bytes.extend(b"Content-Length: 1\r\n\r\n{");
        }
    }
    bytes
}

/// The messages a server wrote.
fn written(out: &[u8]) -> Vec<Value> {
    let mut r = out;
    let mut messages = Vec::new();
    while let Ok(Some(len)) = super::transport::read_header(&mut r) {
        let (body, rest) = r.split_at(len as usize);
        messages.push(serde_json::from_slice(body).unwrap());
        r = rest;
    }
    messages
}

#[test]
fn a_session_in_memory_is_answered() {
    let mut out = Vec::new();
    let ended = serve(std::io::Cursor::new(session()), &mut out, Work::FrontEnd);
    assert_eq!(ended, Ok(()));
    let answers: Vec<Value> = written(&out)
        .into_iter()
        .filter(|m| m.get("method").is_none())
        .collect();
    let ids: Vec<&Value> = answers.iter().map(|m| &m["id"]).collect();
    assert_eq!(
        ids,
        [
            &json!(1),
            &json!(2),
            &Value::Null,
            &json!(3),
            &json!(4),
            &json!(5),
            &json!(6)
        ]
    );
    assert_eq!(answers[2]["error"]["code"], -32700);
    assert!(answers[1]["result"]["contents"]["value"]
        .as_str()
        .unwrap()
        .contains("feature large_slot"));
    let def = answers[3]["result"]["uri"].as_str().unwrap();
    assert!(def.ends_with("/heads.insp"), "{def}");
    let edits = &answers[4]["result"]["changes"]["file:///mem/f2.insp"];
    assert_eq!(edits.as_array().map(Vec::len), Some(2), "{edits}");
}

#[test]
fn every_prefix_of_a_session_is_served_without_a_panic() {
    let bytes = session();
    for cut in (0..bytes.len()).step_by(61) {
        let input = std::io::Cursor::new(bytes[..cut].to_vec());
        assert!(serve(input, std::io::sink(), Work::FrontEnd).is_err());
    }
}
