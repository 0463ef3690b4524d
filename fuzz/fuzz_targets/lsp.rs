//! The language server on any bytes as its input stream, in process: the base
//! protocol's framing, JSON-RPC, the lifecycle and every request and notification on
//! the front end (no worker thread, no planner, no file read; the stdlib copy goes to a
//! private temp folder removed at the end). No panic, whatever the bytes; each input's
//! work is bounded by its size.
#![no_main]

use inspc::lsp::{serve, Work};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let input = std::io::Cursor::new(data.to_vec());
    let _ = serve(input, std::io::sink(), Work::FrontEnd);
});
