//! `inspc lsp` driven over stdio as an editor drives it: initialize, open, change, save,
//! hover, definition, references, completion, symbols, rename, formatting, shutdown.

use serde_json::{json, Value};
use std::io::{BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

mod faces;
mod hostile;

/// How long any one answer may take before the test calls the server hung (not a timing
/// assertion: the real figures are printed).
const HUNG: Duration = Duration::from_secs(60);

/// A language client over the server's stdin and stdout.
struct Client {
    child: Child,
    stdin: ChildStdin,
    messages: Receiver<Value>,
    /// Notifications received while waiting for something else.
    seen: Vec<Value>,
    next_id: i64,
}

impl Client {
    fn start() -> Client {
        Client::start_with(|_| {})
    }

    /// A client of a server whose command `configure` adjusts (its environment, its
    /// stderr), initialized.
    fn start_with(configure: impl FnOnce(&mut Command)) -> Client {
        let mut command = Command::new(env!("CARGO_BIN_EXE_inspc"));
        command
            .arg("lsp")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit());
        configure(&mut command);
        let mut child = command.spawn().expect("start inspc lsp");
        let stdin = child.stdin.take().unwrap();
        let stdout = child.stdout.take().unwrap();
        let (tx, messages) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let mut r = BufReader::new(stdout);
            loop {
                let mut len = None;
                loop {
                    let mut line = String::new();
                    if r.read_line(&mut line).unwrap_or(0) == 0 {
                        return;
                    }
                    let line = line.trim_end();
                    if line.is_empty() {
                        break;
                    }
                    if let Some(v) = line.strip_prefix("Content-Length: ") {
                        len = v.parse::<usize>().ok();
                    }
                }
                let mut body = vec![0; len.expect("a Content-Length header")];
                r.read_exact(&mut body).unwrap();
                if tx.send(serde_json::from_slice(&body).unwrap()).is_err() {
                    return;
                }
            }
        });
        let mut c = Client {
            child,
            stdin,
            messages,
            seen: Vec::new(),
            next_id: 0,
        };
        let init = c.request("initialize", json!({ "capabilities": {} }));
        assert!(init["capabilities"]["hoverProvider"].as_bool().unwrap());
        c.notify("initialized", json!({}));
        c
    }

    fn send(&mut self, v: Value) {
        self.send_body(&v.to_string());
    }

    /// Sends any text as one message's body.
    fn send_body(&mut self, body: &str) {
        write!(self.stdin, "Content-Length: {}\r\n\r\n{body}", body.len()).unwrap();
        self.stdin.flush().unwrap();
    }

    /// The next response, whatever its id (notifications meanwhile are kept).
    fn response(&mut self) -> Value {
        loop {
            let m = self.messages.recv_timeout(HUNG).expect("a response");
            if m.get("method").is_none() {
                return m;
            }
            self.seen.push(m);
        }
    }

    fn notify(&mut self, method: &str, params: Value) {
        self.send(json!({ "jsonrpc": "2.0", "method": method, "params": params }));
    }

    /// The full response to a request (`result` or `error`).
    fn call(&mut self, method: &str, params: Value) -> Value {
        self.next_id += 1;
        let id = self.next_id;
        self.send(json!({ "jsonrpc": "2.0", "id": id, "method": method, "params": params }));
        loop {
            let m = self.messages.recv_timeout(HUNG).expect("an answer");
            if m["id"] == json!(id) && m.get("method").is_none() {
                return m;
            }
            self.seen.push(m);
        }
    }

    fn request(&mut self, method: &str, params: Value) -> Value {
        let m = self.call(method, params);
        assert!(m.get("error").is_none(), "{method}: {m}");
        m["result"].clone()
    }

    /// Waits for a notification that `pred` accepts (earlier ones seen included).
    fn wait_for(&mut self, pred: impl Fn(&Value) -> bool) -> Value {
        if let Some(i) = self.seen.iter().position(&pred) {
            return self.seen.remove(i);
        }
        let deadline = Instant::now() + HUNG;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.messages.recv_timeout(left) {
                Ok(m) if pred(&m) => return m,
                Ok(m) => self.seen.push(m),
                Err(RecvTimeoutError::Timeout) => {
                    panic!("no such notification; saw {:?}", self.seen)
                }
                Err(e) => panic!("the server stopped: {e}"),
            }
        }
    }

    fn shutdown(mut self) {
        self.request("shutdown", Value::Null);
        self.notify("exit", Value::Null);
        let status = self.child.wait().unwrap();
        assert!(status.success(), "inspc lsp exited with {status}");
    }
}

fn uri(path: &Path) -> String {
    format!("file://{}", std::fs::canonicalize(path).unwrap().display())
}

/// The protocol position of the `nth` (from 0) occurrence of `needle` in `text`, `k`
/// bytes in (ASCII specs: columns are bytes).
fn pos(text: &str, needle: &str, nth: usize, k: usize) -> Value {
    let at = text.match_indices(needle).nth(nth).expect(needle).0 + k;
    let line = text[..at].matches('\n').count();
    let col = at - text[..at].rfind('\n').map_or(0, |i| i + 1);
    json!({ "line": line, "character": col })
}

fn at(uri: &str, p: Value) -> Value {
    json!({ "textDocument": { "uri": uri }, "position": p })
}

fn open(c: &mut Client, path: &Path) -> (String, String) {
    let text = std::fs::read_to_string(path).unwrap();
    let uri = uri(path);
    c.notify(
        "textDocument/didOpen",
        json!({ "textDocument": { "uri": uri, "languageId": "insp", "version": 1, "text": text } }),
    );
    (uri, text)
}

fn hover_text(c: &mut Client, uri: &str, p: Value) -> String {
    let h = c.request("textDocument/hover", at(uri, p));
    h["contents"]["value"].as_str().unwrap_or("").to_string()
}

fn diagnostics_of<'a>(uri: &'a str) -> impl Fn(&Value) -> bool + 'a {
    move |m: &Value| {
        m["method"] == "textDocument/publishDiagnostics" && m["params"]["uri"] == json!(uri)
    }
}

fn real(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/real")
        .join(name)
}

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(name)
}

/// LSP 3.17, "Exit Notification": the server exits with 0 after `shutdown`, with 1 when
/// `exit` comes without it.
#[test]
fn exit_without_shutdown_ends_the_server_with_code_1() {
    let mut c = Client::start();
    c.notify("exit", Value::Null);
    let status = c.child.wait().unwrap();
    assert_eq!(status.code(), Some(1), "inspc lsp exited with {status}");
    Client::start().shutdown();
}

#[test]
fn ctc_01_hover_definition_completion_and_a_typo() {
    let path = real("nist_ctc_01.insp");
    crate::common::require_shared_parts();
    let mut c = Client::start();
    let (uri, text) = open(&mut c, &path);
    let first = c.wait_for(diagnostics_of(&uri));
    assert_eq!(first["params"]["diagnostics"], json!([]), "{first}");

    // Hover: a catalogue item, a tolerance's rule, a feature's faces once the geometry
    // is built (the second publication is the geometry stage's).
    let head = hover_text(&mut c, &uri, pos(&text, "head PH10MQ", 0, 6));
    assert!(
        head.contains("head PH10MQ: indexable") && head.contains("720 orientations"),
        "{head}"
    );
    let tol = hover_text(&mut c, &uri, pos(&text, "pos_slot_a", 0, 2));
    assert!(tol.contains("position(slot_a) 0.75 | A, B, C"), "{tol}");
    assert!(tol.contains("datums required"), "{tol}");
    let mut bore = String::new();
    for _ in 0..600 {
        bore = hover_text(&mut c, &uri, pos(&text, "diameter(bore_1", 0, 10));
        if bore.contains("points") {
            break;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    assert!(bore.contains("feature bore_1 = "), "{bore}");
    assert!(
        bore.contains("face_90") && bore.contains("cylinder"),
        "{bore}"
    );
    assert!(bore.contains("points"), "{bore}");

    // Definition: a use of a feature goes to its declaration, a stdlib item to a copy of
    // the stdlib module.
    let def = c.request(
        "textDocument/definition",
        at(&uri, pos(&text, "diameter(bore_1", 0, 10)),
    );
    assert_eq!(def["uri"], json!(uri));
    assert_eq!(def["range"]["start"], pos(&text, "bore_1      =", 0, 0));
    let def = c.request(
        "textDocument/definition",
        at(&uri, pos(&text, "head PH10MQ", 0, 6)),
    );
    let std_path = def["uri"]
        .as_str()
        .unwrap()
        .trim_start_matches("file://")
        .to_string();
    assert!(std_path.ends_with("heads.insp"), "{def}");
    let std_text = std::fs::read_to_string(&std_path).unwrap();
    assert_eq!(std_text, include_str!("../../stdlib/heads.insp"));

    // A rack label: the plan's `fixtures [angle]` goes to the cmm's `angle:` and shows
    // the fixture it names.
    let plan_angle = pos(&text, "fixtures [angle]", 0, "fixtures [".len() + 1);
    let def = c.request("textDocument/definition", at(&uri, plan_angle.clone()));
    assert_eq!(
        def["range"]["start"],
        pos(&text, "angle: ANGLE_PLATE", 0, 0),
        "{def}"
    );
    let angle = hover_text(&mut c, &uri, plan_angle);
    assert!(
        angle.contains("`angle` in the rack") && angle.contains("fixture ANGLE_PLATE: sine_plate"),
        "{angle}"
    );

    // Completion: the properties of a cmm (as the resolver asks for them), units after
    // a number, a stdlib module's items after `use std::probes::`.
    let labels = |v: &Value| -> Vec<String> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|i| i["label"].as_str().unwrap().to_string())
            .collect()
    };
    let cmm_line = pos(&text, "    head PH10MQ", 0, 4);
    let keys = labels(&c.request("textDocument/completion", at(&uri, cmm_line)));
    for k in ["table", "ram", "head", "probes", "fixtures"] {
        assert!(keys.contains(&k.to_string()), "{k} not in {keys:?}");
    }
    let units = labels(&c.request(
        "textDocument/completion",
        at(&uri, pos(&text, "0.75 mm", 0, 5)),
    ));
    assert!(
        units.contains(&"mm".to_string()) && units.contains(&"deg".to_string()),
        "{units:?}"
    );
    let probes = labels(&c.request(
        "textDocument/completion",
        at(
            &uri,
            pos(&text, "use std::probes::{", 0, "use std::probes::{".len()),
        ),
    ));
    assert!(probes.contains(&"TP20_D4_L50".to_string()), "{probes:?}");
    // A plan's `fixtures [` takes the labels of its machine's rack, not catalogue items.
    let rack = labels(&c.request(
        "textDocument/completion",
        at(
            &uri,
            pos(&text, "    fixtures [angle]", 0, "    fixtures [".len()),
        ),
    ));
    assert!(rack.contains(&"angle".to_string()), "{rack:?}");
    assert!(!rack.contains(&"ANGLE_PLATE".to_string()), "{rack:?}");

    // A typo: the unknown name's diagnostic, measured from sending the change.
    let typo = text.replacen("position(slot_a,", "position(slot_q,", 1);
    let start = Instant::now();
    c.notify(
        "textDocument/didChange",
        json!({ "textDocument": { "uri": uri, "version": 2 }, "contentChanges": [{ "text": typo }] }),
    );
    let d = c.wait_for(|m| {
        diagnostics_of(&uri)(m)
            && m["params"]["diagnostics"]
                .as_array()
                .is_some_and(|a| !a.is_empty())
    });
    let latency = start.elapsed();
    eprintln!(
        "lsp: CTC 01 typo diagnostic {:.1} ms after the change",
        latency.as_secs_f64() * 1e3
    );
    let diag = &d["params"]["diagnostics"][0];
    assert_eq!(diag["code"], "insp::resolve::unknown_name", "{diag}");
    assert_eq!(diag["range"]["start"], pos(&typo, "slot_q", 0, 0));
    assert!(
        diag["message"].as_str().unwrap().contains("help: "),
        "{diag}"
    );
    c.shutdown();
}

#[test]
fn save_plans_in_the_background_and_hovers_show_the_plan() {
    let path = example("f2.insp");
    let mut c = Client::start();
    let (uri, text) = open(&mut c, &path);
    c.wait_for(diagnostics_of(&uri));
    let t1 = hover_text(&mut c, &uri, pos(&text, "T1", 0, 1));
    assert!(t1.contains("save to plan"), "{t1}");
    c.notify(
        "textDocument/didSave",
        json!({ "textDocument": { "uri": uri } }),
    );
    let log = c.wait_for(|m| m["method"] == "window/logMessage");
    let message = log["params"]["message"].as_str().unwrap();
    assert!(
        message.contains("f2_plan: 2/2 tolerances measured"),
        "{message}"
    );
    let t1 = hover_text(&mut c, &uri, pos(&text, "T1", 0, 1));
    assert!(t1.contains("Last plan: measured in setup 1."), "{t1}");
    let slot = hover_text(&mut c, &uri, pos(&text, "large_slot, 0.05", 0, 1));
    assert!(
        slot.contains("large.left_wall") && slot.contains("probe p1"),
        "{slot}"
    );
    c.shutdown();
}

#[test]
fn references_symbols_rename_and_formatting() {
    let path = example("f2.insp");
    let mut c = Client::start();
    let (uri, text) = open(&mut c, &path);
    c.wait_for(diagnostics_of(&uri));

    // `top`: declared once, used by datum A.
    let refs = c.request(
        "textDocument/references",
        json!({ "textDocument": { "uri": uri }, "position": pos(&text, "feature top", 0, 9),
                "context": { "includeDeclaration": true } }),
    );
    let refs = refs.as_array().unwrap();
    assert_eq!(refs.len(), 2, "{refs:?}");
    assert_eq!(refs[1]["range"]["start"], pos(&text, "A = top", 0, 4));

    let symbols = c.request(
        "textDocument/documentSymbol",
        json!({ "textDocument": { "uri": uri } }),
    );
    let names: Vec<&str> = symbols
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["f2", "lab", "f2_plan"]);
    let part: Vec<&str> = symbols[0]["children"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(
        part,
        [
            "large",
            "small",
            "top",
            "large_slot",
            "small_slot",
            "A",
            "T1",
            "T2"
        ]
    );
    let rack: Vec<&str> = symbols[1]["children"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["name"].as_str().unwrap())
        .collect();
    assert_eq!(rack, ["p1", "p2"]);

    // Renaming a feature edits its declaration and every use; a keyword is refused.
    let edit = c.request(
        "textDocument/rename",
        json!({ "textDocument": { "uri": uri }, "position": pos(&text, "large_slot", 0, 0), "newName": "wide_slot" }),
    );
    let edits = edit["changes"][&uri].as_array().unwrap();
    assert_eq!(edits.len(), 2, "{edit}");
    assert!(edits.iter().all(|e| e["newText"] == "wide_slot"));
    let bad = c.call(
        "textDocument/rename",
        json!({ "textDocument": { "uri": uri }, "position": pos(&text, "large_slot", 0, 0), "newName": "feature" }),
    );
    assert!(
        bad["error"]["message"]
            .as_str()
            .unwrap()
            .contains("not a name"),
        "{bad}"
    );
    let std = c.call(
        "textDocument/rename",
        json!({ "textDocument": { "uri": uri }, "position": pos(&text, "PH6", 1, 0), "newName": "H" }),
    );
    assert!(
        std["error"]["message"]
            .as_str()
            .unwrap()
            .contains("standard-library"),
        "{std}"
    );

    // Formatting: a badly laid-out text comes back in `inspc fmt`'s layout.
    let messy = text.replace("    units mm", "units    mm");
    c.notify(
        "textDocument/didChange",
        json!({ "textDocument": { "uri": uri, "version": 2 }, "contentChanges": [{ "text": messy }] }),
    );
    let edits = c.request("textDocument/formatting", json!({ "textDocument": { "uri": uri }, "options": { "tabSize": 4, "insertSpaces": true } }));
    assert_eq!(edits[0]["newText"], json!(text));
    c.shutdown();
}

#[test]
fn diagnostics_follow_the_text_and_clear() {
    let mut c = Client::start();
    let dir = std::env::temp_dir().join(format!("inspc-lsp-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("unsaved.insp");
    std::fs::write(&path, "").unwrap();
    let uri = uri(&path);
    let broken =
        "part p {\n    units mm\n    stock box(10, 10, 10)\n    feature top = stock.topp\n}\n";
    c.notify(
        "textDocument/didOpen",
        json!({ "textDocument": { "uri": uri, "languageId": "insp", "version": 1, "text": broken } }),
    );
    let d = c.wait_for(diagnostics_of(&uri));
    let diag = &d["params"]["diagnostics"][0];
    assert_eq!(diag["code"], "insp::resolve::unknown_face", "{d}");
    assert_eq!(diag["severity"], 1);
    let fixed = broken.replace("topp", "top");
    c.notify(
        "textDocument/didChange",
        json!({ "textDocument": { "uri": uri, "version": 2 }, "contentChanges": [{ "text": fixed }] }),
    );
    let d = c.wait_for(|m| diagnostics_of(&uri)(m) && m["params"]["version"] == 2);
    assert_eq!(d["params"]["diagnostics"], json!([]), "{d}");
    // A syntax error, then completion inside the broken part still offers its names.
    let typing = fixed.replace(
        "feature top = stock.top",
        "feature top = stock.top\n    datum A = t",
    );
    let typing = typing.replace("units mm", "units mm +");
    c.notify(
        "textDocument/didChange",
        json!({ "textDocument": { "uri": uri, "version": 3 }, "contentChanges": [{ "text": typing }] }),
    );
    let d = c.wait_for(|m| diagnostics_of(&uri)(m) && m["params"]["version"] == 3);
    assert!(
        d["params"]["diagnostics"][0]["code"]
            .as_str()
            .unwrap()
            .starts_with("insp::syntax::"),
        "{d}"
    );
    let items = c.request(
        "textDocument/completion",
        at(&uri, pos(&typing, "datum A = t", 0, "datum A = t".len())),
    );
    assert!(
        items
            .as_array()
            .unwrap()
            .iter()
            .any(|i| i["label"] == "top"),
        "{items}"
    );
    c.shutdown();
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn typing_during_a_plan_is_answered_and_a_new_save_stops_the_old_plan() {
    let path = real("nist_ctc_01.insp");
    crate::common::require_shared_parts();
    let mut c = Client::start();
    let (uri, text) = open(&mut c, &path);
    c.wait_for(diagnostics_of(&uri));
    let planned = |m: &Value| m["method"] == "window/logMessage";
    // Planning takes seconds; a typo typed meanwhile gets its diagnostic first.
    c.notify(
        "textDocument/didSave",
        json!({ "textDocument": { "uri": uri } }),
    );
    let typo = text.replacen("flatness(top,", "flatness(tpo,", 1);
    c.notify(
        "textDocument/didChange",
        json!({ "textDocument": { "uri": uri, "version": 2 }, "contentChanges": [{ "text": typo }] }),
    );
    c.wait_for(|m| {
        diagnostics_of(&uri)(m)
            && m["params"]["diagnostics"]
                .as_array()
                .is_some_and(|a| !a.is_empty())
    });
    assert!(
        !c.seen.iter().any(planned),
        "the plan answered before the typo: {:?}",
        c.seen
    );
    // Undone and saved again: the first plan is stopped, one plan reports.
    c.notify(
        "textDocument/didChange",
        json!({ "textDocument": { "uri": uri, "version": 3 }, "contentChanges": [{ "text": text }] }),
    );
    c.notify(
        "textDocument/didSave",
        json!({ "textDocument": { "uri": uri } }),
    );
    let log = c.wait_for(planned);
    assert!(
        log["params"]["message"]
            .as_str()
            .unwrap()
            .contains("14/14 tolerances measured"),
        "{log}"
    );
    let flat = hover_text(&mut c, &uri, pos(&text, "flat_a", 0, 1));
    assert!(flat.contains("Last plan: measured in setup"), "{flat}");
    c.request("shutdown", Value::Null);
    assert!(
        !c.seen.iter().any(planned),
        "two plans reported: {:?}",
        c.seen
    );
    c.notify("exit", Value::Null);
    assert!(c.child.wait().unwrap().success());
}

#[test]
fn a_features_hover_says_which_sensor_it_got_and_why() {
    let dir = std::env::temp_dir().join(format!("inspc-lsp-sensor-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("mixed.insp");
    std::fs::write(&path, crate::scan::mixed("")).unwrap();
    let mut c = Client::start();
    let (uri, text) = open(&mut c, &path);
    let mut top = String::new();
    for _ in 0..600 {
        top = hover_text(&mut c, &uri, pos(&text, "feature top", 0, 9));
        if top.contains("sensor in plan") {
            break;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    assert!(
        top.contains("sensor in plan `q`: **laser** (flat 0.2 mm / 0.009 mm = 22.2 ≥ 10)"),
        "{top}"
    );
    let bore = hover_text(&mut c, &uri, pos(&text, "feature bore", 0, 9));
    assert!(
        bore.contains("**touch** (a bore Ø8 mm, 20 mm deep"),
        "{bore}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
