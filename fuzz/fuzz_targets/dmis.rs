//! The DMIS reader on any text: no panic; what reads prints back.
#![no_main]

use inspc::source::FileId;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Ok(p) = inspc::dmis::read(FileId(0), &text) {
        let _ = p.to_text();
    }
});
