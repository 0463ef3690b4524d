//! `inspc lsp` against hostile input, one test per class of the campaign (issue 49):
//! messages that are not JSON-RPC, frames over the limits or without end, planted
//! files where the stdlib copy goes, a server killed during a plan, a flood of
//! diagnostics, renames onto names in use.

use super::{at, diagnostics_of, example, open, pos, Client, HUNG};
use serde_json::{json, Value};
use std::io::{Read, Write};
use std::path::PathBuf;
use std::process::Stdio;
use std::time::{Duration, Instant};

/// The body limit of `src/lsp/transport.rs`: eight times the 8 MiB spec limit.
const BODY_LIMIT: u64 = 64 << 20;

fn code(m: &Value) -> i64 {
    m["error"]["code"]
        .as_i64()
        .unwrap_or_else(|| panic!("no error: {m}"))
}

/// A folder of this test's own under the temp folder.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("inspc-lsp-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// JSON-RPC 2.0 §5.1: each bad message gets its error, the server goes on, and a
/// notification never gets an answer.
#[test]
fn bad_messages_get_json_rpc_errors_and_the_server_goes_on() {
    let mut c = Client::start();
    for body in [
        "{",
        "{\"jsonrpc\":\"2.0\",\"id\":1,\"method\":",
        "\u{1}",
        "[1,",
        "",
    ] {
        c.send_body(body);
        let m = c.response();
        assert_eq!((code(&m), &m["id"]), (-32700, &Value::Null), "{body}: {m}");
    }
    let invalid = [
        ("[]", Value::Null),
        ("42", Value::Null),
        (
            r#"[{"jsonrpc":"2.0","id":5,"method":"shutdown"}]"#,
            Value::Null,
        ),
        (r#"{"jsonrpc":"2.0","id":7}"#, json!(7)),
        (r#"{"jsonrpc":"2.0","id":{},"method":"x"}"#, Value::Null),
        (r#"{"id":"s","method":"textDocument/hover"}"#, json!("s")),
        (r#"{"jsonrpc":"2.0","method":["exit"]}"#, Value::Null),
    ];
    for (body, id) in invalid {
        c.send_body(body);
        let m = c.response();
        assert_eq!((code(&m), &m["id"]), (-32600, &id), "{body}: {m}");
    }
    let unknown = c.call("textDocument/frobnicate", json!({}));
    assert_eq!(code(&unknown), -32601, "{unknown}");
    for params in [json!({}), json!({ "textDocument": 1 }), json!([1, 2])] {
        let m = c.call("textDocument/hover", params);
        assert_eq!(code(&m), -32602, "{m}");
    }
    // Notifications, unknown or with bad params, are not answered: the next answer is
    // the next request's.
    c.notify("textDocument/frobnicated", json!({}));
    c.notify("textDocument/didOpen", json!({ "textDocument": 3 }));
    c.notify("textDocument/didChange", json!({}));
    let symbols = c.call(
        "textDocument/documentSymbol",
        json!({ "textDocument": { "uri": "file:///nowhere.insp" } }),
    );
    assert_eq!(symbols["result"], Value::Null, "{symbols}");
    // A big id comes back as it went.
    c.send_body(r#"{"jsonrpc":"2.0","id":12345678901234,"method":"x/y"}"#);
    assert_eq!(c.response()["id"], json!(12345678901234_i64));
    c.shutdown();
}

/// LSP 3.17's lifecycle: before `initialize` a request gets -32002; after `shutdown`
/// -32600; `exit` then ends the server with 0.
#[test]
fn requests_outside_the_lifecycle_are_refused() {
    let mut c = Client::start();
    let again = c.call("initialize", json!({ "capabilities": {} }));
    assert_eq!(code(&again), -32600, "{again}");
    c.request("shutdown", Value::Null);
    let late = c.call("textDocument/hover", json!({}));
    assert_eq!(code(&late), -32600, "{late}");
    c.notify("exit", Value::Null);
    assert!(c.child.wait().unwrap().success());
}

/// A server whose stderr the test reads, and the stderr's reader.
fn client_with_stderr() -> (Client, std::thread::JoinHandle<String>) {
    let mut c = Client::start_with(|cmd| {
        cmd.stderr(Stdio::piped());
    });
    let mut stderr = c.child.stderr.take().unwrap();
    let read = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = stderr.read_to_string(&mut s);
        s
    });
    (c, read)
}

/// A body over the limit is answered at once and skipped without being kept; the next
/// message is served.
#[test]
fn an_oversized_message_is_answered_and_skipped_unread() {
    let mut c = Client::start();
    let len = BODY_LIMIT + 1;
    write!(c.stdin, "Content-Length: {len}\r\n\r\n").unwrap();
    let m = c.response();
    assert_eq!((code(&m), &m["id"]), (-32600, &Value::Null), "{m}");
    assert!(m["error"]["message"]
        .as_str()
        .unwrap()
        .contains(&len.to_string()));
    let chunk = vec![b' '; 1 << 20];
    let mut left = len as usize;
    while left > 0 {
        let n = left.min(chunk.len());
        c.stdin.write_all(&chunk[..n]).unwrap();
        left -= n;
    }
    #[cfg(target_os = "linux")]
    assert!(peak_rss_mib(c.child.id()) < 60, "the skipped body was kept");
    let symbols = c.call(
        "textDocument/documentSymbol",
        json!({ "textDocument": { "uri": "file:///nowhere.insp" } }),
    );
    assert_eq!(symbols["result"], Value::Null, "{symbols}");
    c.shutdown();
}

/// A length the stream does not deliver: answered at once, nothing allocated for it,
/// and when the stream ends inside it the server exits with 1 and says why (no abort).
#[test]
fn a_huge_length_allocates_nothing_and_a_stream_ending_inside_it_exits_1() {
    for len in ["3000000000", "99999999999999", "18446744073709551615"] {
        let (mut c, stderr) = client_with_stderr();
        write!(
            c.stdin,
            "Content-Length: {len}\r\n\r\n{{\"jsonrpc\":\"2.0\"}}"
        )
        .unwrap();
        c.stdin.flush().unwrap();
        let m = c.response();
        assert_eq!(code(&m), -32600, "{m}");
        #[cfg(target_os = "linux")]
        assert!(peak_rss_mib(c.child.id()) < 200, "{len}: memory grew");
        drop(c.stdin);
        let status = c.child.wait().unwrap();
        assert_eq!(status.code(), Some(1), "{len}: {status}");
        let stderr = stderr.join().unwrap();
        assert!(stderr.contains("ended inside a message body"), "{stderr}");
    }
}

/// Frames that cannot be read end the server with 1 and the reason, without reading
/// on: a header line without end, a length that is not one, no length at all.
#[test]
fn unframeable_streams_end_the_server_with_a_reason() {
    let endless = "x".repeat(1 << 20);
    let cases = [
        (endless.as_str(), "longer than"),
        (
            "Content-Length: 99999999999999999999999\r\n\r\n{}",
            "not a length",
        ),
        ("Content-Length: 0x10\r\n\r\n{}", "not a length"),
        (
            "Content-Type: application/vscode-jsonrpc\r\n\r\n{}",
            "without `Content-Length`",
        ),
    ];
    for (bytes, why) in cases {
        let (mut c, stderr) = client_with_stderr();
        // The server may stop reading before all is written.
        let _ = c.stdin.write_all(bytes.as_bytes());
        let _ = c.stdin.flush();
        let status = c.child.wait().unwrap();
        assert_eq!(status.code(), Some(1), "{why}: {status}");
        let stderr = stderr.join().unwrap();
        assert!(stderr.contains(why), "{stderr}");
    }
}

/// The largest resident size the process has had, in MiB.
#[cfg(target_os = "linux")]
fn peak_rss_mib(pid: u32) -> u64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
    let line = status.lines().find(|l| l.starts_with("VmHWM:")).unwrap();
    let kib: u64 = line.split_whitespace().nth(1).unwrap().parse().unwrap();
    kib >> 10
}

/// Finding 1: the stdlib copy once went to a predictable name under the temp folder and
/// followed what was planted there. Now each server writes its own folder (0700, new
/// name), ignores anything planted, and removes it at the end.
#[cfg(unix)]
#[test]
fn definitions_into_the_stdlib_open_a_private_copy() {
    use std::os::unix::fs::PermissionsExt;
    let tmp = scratch("planted");
    let victim = tmp.join("victim.txt");
    std::fs::write(&victim, "keep").unwrap();
    // Everything the old name could meet: a link to a file, /dev/zero, a FIFO.
    let old = tmp.join(format!("inspc-{}-stdlib", env!("CARGO_PKG_VERSION")));
    std::fs::create_dir(&old).unwrap();
    std::os::unix::fs::symlink(&victim, old.join("heads.insp")).unwrap();
    std::os::unix::fs::symlink("/dev/zero", old.join("probes.insp")).unwrap();
    let fifo = std::process::Command::new("mkfifo")
        .arg(old.join("styli.insp"))
        .status();
    assert!(fifo.is_ok_and(|s| s.success()));
    let mut c = Client::start_with(|cmd| {
        cmd.env("TMPDIR", &tmp);
    });
    let (uri, text) = open(&mut c, &example("f2.insp"));
    c.wait_for(diagnostics_of(&uri));
    let mut copies = Vec::new();
    for name in ["PH6", "TP20_D4_L50", "efficient_accuracy"] {
        let def = c.request("textDocument/definition", at(&uri, pos(&text, name, 1, 0)));
        let path = PathBuf::from(def["uri"].as_str().unwrap().trim_start_matches("file://"));
        assert!(path.starts_with(&tmp) && !path.starts_with(&old), "{def}");
        copies.push(path);
    }
    let dir = copies[0].parent().unwrap().to_path_buf();
    assert!(copies.iter().all(|p| p.parent() == Some(dir.as_path())));
    let mode = std::fs::metadata(&dir).unwrap().permissions().mode();
    assert_eq!(mode & 0o777, 0o700);
    let heads = std::fs::read_to_string(&copies[0]).unwrap();
    assert_eq!(heads, include_str!("../../../stdlib/heads.insp"));
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "keep");
    c.shutdown();
    assert!(!dir.exists(), "the copy outlived its server");
    std::fs::remove_dir_all(&tmp).unwrap();
}

/// The children of `pid` (Linux: `/proc/*/stat`, the field after the command's `)`).
#[cfg(target_os = "linux")]
fn children(pid: u32) -> Vec<u32> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir("/proc").unwrap().flatten() {
        let Ok(child) = entry.file_name().to_string_lossy().parse::<u32>() else {
            continue;
        };
        let Ok(stat) = std::fs::read_to_string(entry.path().join("stat")) else {
            continue;
        };
        let after = &stat[stat.rfind(')').map_or(0, |i| i + 1)..];
        if after.split_whitespace().nth(1) == Some(&pid.to_string()) {
            out.push(child);
        }
    }
    out
}

/// Whether a process runs (not gone, not a zombie waiting to be reaped).
#[cfg(target_os = "linux")]
fn running(pid: u32) -> bool {
    let Ok(stat) = std::fs::read_to_string(format!("/proc/{pid}/stat")) else {
        return false;
    };
    let after = &stat[stat.rfind(')').map_or(0, |i| i + 1)..];
    after.split_whitespace().next() != Some("Z")
}

/// Finding 4: a planner child outlived a server killed with SIGKILL. It now ends by
/// itself when its stdin, the server's pipe, closes.
#[cfg(target_os = "linux")]
#[test]
fn a_planner_ends_when_its_server_is_killed() {
    // The slowest example to plan: tens of seconds, so the plan is still running.
    let mut c = Client::start();
    let (uri, _) = open(&mut c, &example("swiss_sphere_indexed.insp"));
    c.wait_for(diagnostics_of(&uri));
    c.notify(
        "textDocument/didSave",
        json!({ "textDocument": { "uri": uri } }),
    );
    let server = c.child.id();
    let deadline = Instant::now() + HUNG;
    let planner = loop {
        if let Some(&p) = children(server).first() {
            break p;
        }
        assert!(Instant::now() < deadline, "no planner started");
        std::thread::sleep(Duration::from_millis(20));
    };
    c.child.kill().unwrap(); // SIGKILL: the server runs no code of its own
    c.child.wait().unwrap();
    let killed = Instant::now();
    while running(planner) && killed.elapsed() < Duration::from_secs(10) {
        std::thread::sleep(Duration::from_millis(20));
    }
    eprintln!(
        "lsp: the planner ended {:.0} ms after its server was killed",
        killed.elapsed().as_secs_f64() * 1e3
    );
    assert!(!running(planner), "the planner outlived its server");
}

/// Finding 5: publishing was quadratic in the number of diagnostics. 20,000 errors, on
/// 20,000 lines with wide characters between them and on one line, are published
/// whole, at the right UTF-16 columns (the time is printed, not asserted).
#[test]
fn twenty_thousand_diagnostics_are_published() {
    const N: usize = 20_000;
    let mut lines = String::from("part p {\n    units mm\n    stock box(10, 10, 10)\n");
    for i in 0..N {
        lines += &format!("    // ± 𝑥 {i}\n    feature f{i} = stock.topp\n");
    }
    lines += "}\n";
    let one_line = format!(
        "part p {{ units mm; stock box(10, 10, 10); {}}}\n",
        (0..N)
            .map(|i| format!("feature f{i} = stock.topp; "))
            .collect::<String>()
    );
    let dir = scratch("many");
    let mut c = Client::start();
    for (name, text) in [("lines.insp", lines), ("one_line.insp", one_line)] {
        let path = dir.join(name);
        std::fs::write(&path, &text).unwrap();
        let start = Instant::now();
        let (uri, _) = open(&mut c, &path);
        let d = c.wait_for(|m| {
            diagnostics_of(&uri)(m) && m["params"]["diagnostics"].as_array().unwrap().len() == N
        });
        eprintln!(
            "lsp: {N} diagnostics of {name} published {:.0} ms after the open",
            start.elapsed().as_secs_f64() * 1e3
        );
        let last = &d["params"]["diagnostics"][N - 1];
        assert_eq!(last["code"], "insp::resolve::unknown_face", "{last}");
        // The last error is at the last `topp`, in UTF-16 units.
        let at = text.rfind("topp").unwrap();
        let line = text[..at].matches('\n').count();
        let line_start = text[..at].rfind('\n').map_or(0, |i| i + 1);
        let column: usize = text[line_start..at].chars().map(char::len_utf16).sum();
        assert_eq!(
            last["range"]["start"],
            json!({ "line": line, "character": column }),
            "{last}"
        );
        // The server still answers at once.
        let hover = c.call("textDocument/hover", at_text(&uri, &text, "f7 ="));
        assert!(hover.get("error").is_none(), "{hover}");
    }
    c.shutdown();
    std::fs::remove_dir_all(&dir).unwrap();
}

fn at_text(uri: &str, text: &str, needle: &str) -> Value {
    at(uri, pos(text, needle, 0, 0))
}

/// Finding 6: a rename onto a name in use (the same scope, or one the new name would
/// capture) is refused with the declaration in the way; a non-name or keyword too.
#[test]
fn renames_onto_names_in_use_are_refused() {
    let path = example("f2.insp");
    let mut c = Client::start();
    let (uri, text) = open(&mut c, &path);
    c.wait_for(diagnostics_of(&uri));
    let rename = |c: &mut Client, needle: &str, nth: usize, new: &str| {
        let mut p = at(&uri, pos(&text, needle, nth, 0));
        p["newName"] = json!(new);
        c.call("textDocument/rename", p)
    };
    let refusals = [
        ("large_slot", 0, "small_slot", "feature `small_slot` at "),
        ("A = top", 0, "top", "feature `top` at "),
        ("T1", 0, "T2", "tolerance `T2` at "),
        ("large {", 0, "small", "operation `small` at "),
        ("p1:", 0, "p2", "label `p2` at "),
        ("lab {", 0, "f2_plan", "plan `f2_plan` at "),
        ("lab {", 0, "f2", "part `f2` at "),
        // Own items shadow imports: `PH6` would then name the cmm.
        ("lab {", 0, "PH6", "head `PH6` at <std>/heads.insp"),
    ];
    for (needle, nth, new, existing) in refusals {
        let m = rename(&mut c, needle, nth, new);
        assert_eq!(code(&m), -32803, "{needle} → {new}: {m}");
        let message = m["error"]["message"].as_str().unwrap();
        assert!(message.contains(existing), "{needle} → {new}: {message}");
    }
    for new in ["part", "stock", "feature", "2a", "a-b", "a b", "", "é"] {
        let m = rename(&mut c, "large_slot", 0, new);
        assert_eq!(code(&m), -32602, "{new}: {m}");
        assert!(m["error"]["message"]
            .as_str()
            .unwrap()
            .contains("not a name"));
    }
    // A free name is still fine, everywhere the name is written.
    let ok = rename(&mut c, "p1:", 0, "big");
    assert_eq!(
        ok["result"]["changes"][&uri].as_array().map(Vec::len),
        Some(1)
    );
    c.shutdown();
}
