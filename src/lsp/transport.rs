//! The LSP base protocol's framing over any byte stream: a header section
//! (`Content-Length: N`, other headers, a blank line), then N bytes of body.
//!
//! **Decision: bounded framing, and a broken frame ends the server.** The base protocol
//! (LSP 3.17, "Base Protocol",
//! <https://microsoft.github.io/language-server-protocol/specifications/lsp/3.17/specification/#baseProtocol>)
//! gives no other way to find where a message ends than its `Content-Length`, so:
//! - A header section is read in at most [`HEADER_LIMIT`] bytes. Longer (a line without
//!   end), without a `Content-Length`, with one that is not a decimal count of bytes or
//!   two that disagree, a line that is not `name: value`, or the stream ending inside a
//!   message: the end of the message is unknowable and no later byte can be trusted to
//!   start one, so the stream is [`Broken`] — the server writes why on stderr and exits
//!   with code 1 (its client is no longer speaking the protocol).
//! - A body longer than [`BODY_LIMIT`] is still framed by its length: it is announced as
//!   [`Frame::TooLarge`] (the server answers it with an error, its id unknowable) and
//!   its bytes are read into nothing, 8 KiB at a time, never allocated; the next message
//!   is read after it. A body within the limit is read as it arrives, never allocated
//!   ahead of its bytes.
//!
//! Lines may end in `\r\n` (the protocol) or `\n` alone; header names are
//! case-insensitive (as HTTP's, whose format the protocol borrows); headers other than
//! `Content-Length` (`Content-Type`) are read and not needed.

use crate::source::FileKind;
use crossbeam_channel::Sender;
use std::io::{BufRead, Read, Write};

/// The most bytes a message's header section may take: real ones are under 100.
pub(crate) const HEADER_LIMIT: u64 = 8 << 10;

/// The largest message body read: a `didOpen` or `didChange` carries a whole spec, at
/// most [`FileKind::Spec`]'s limit (8 MiB), and JSON may escape each byte of it in up to
/// six (`\u0000`); eight times the spec limit holds that and the message around it.
pub(crate) const BODY_LIMIT: u64 = 8 * FileKind::Spec.limit();

/// What the reader finds next in the stream.
#[derive(Debug, PartialEq, Eq)]
pub(crate) enum Frame {
    /// A message's body.
    Body(Vec<u8>),
    /// A message of this many bytes, over [`BODY_LIMIT`]: skipped unread.
    TooLarge(u64),
    /// The stream ended between two messages.
    End,
    /// The stream no longer follows the base protocol.
    Broken(Broken),
}

/// Why the stream cannot be read on: a sentence for stderr.
#[derive(Debug, PartialEq, Eq)]
pub(crate) struct Broken(pub String);

/// Reads frames from `input` and sends each to `frames` until the stream ends or breaks
/// (or nobody listens). A too-large body is announced before it is skipped, so the
/// answer does not wait for its bytes.
pub(crate) fn pump(mut input: impl BufRead, frames: &Sender<Frame>) {
    loop {
        let frame = match read_header(&mut input) {
            Ok(None) => Frame::End,
            Ok(Some(len)) if len > BODY_LIMIT => {
                if frames.send(Frame::TooLarge(len)).is_err() {
                    return;
                }
                match skip(&mut input, len) {
                    Ok(()) => continue,
                    Err(b) => Frame::Broken(b),
                }
            }
            Ok(Some(len)) => read_body(&mut input, len).map_or_else(Frame::Broken, Frame::Body),
            Err(b) => Frame::Broken(b),
        };
        let last = matches!(frame, Frame::End | Frame::Broken(_));
        if frames.send(frame).is_err() || last {
            return;
        }
    }
}

/// Reads one header section: the body's length, or `None` at the end of the stream
/// before any byte of a message.
pub(crate) fn read_header(input: &mut impl BufRead) -> Result<Option<u64>, Broken> {
    let mut length: Option<u64> = None;
    let mut used = 0u64;
    loop {
        let mut line = Vec::new();
        let left = HEADER_LIMIT - used;
        let n = input
            .by_ref()
            .take(left)
            .read_until(b'\n', &mut line)
            .map_err(io_broken)? as u64;
        used += n;
        if line.last() != Some(&b'\n') {
            return match (n, used) {
                (0, 0) => Ok(None),
                _ if n == left => Err(Broken(format!(
                    "a message header longer than {HEADER_LIMIT} bytes (a line without end?)"
                ))),
                _ => Err(Broken("the stream ended inside a message header".into())),
            };
        }
        let line = line.strip_suffix(b"\n").unwrap_or(&line);
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        if line.is_empty() {
            return match length {
                Some(len) => Ok(Some(len)),
                None => Err(Broken("a message header without `Content-Length`".into())),
            };
        }
        if let Some(len) = content_length(line)? {
            if length.is_some_and(|l| l != len) {
                return Err(Broken("two different `Content-Length` headers".into()));
            }
            length = Some(len);
        }
    }
}

/// The length a header line gives, if it is `Content-Length`.
fn content_length(line: &[u8]) -> Result<Option<u64>, Broken> {
    let shown = || String::from_utf8_lossy(&line[..line.len().min(80)]).into_owned();
    let Some(colon) = line.iter().position(|&b| b == b':') else {
        return Err(Broken(format!(
            "a header line that is not `name: value`: `{}`",
            shown()
        )));
    };
    let (name, value) = (&line[..colon], line[colon + 1..].trim_ascii());
    if !name.trim_ascii().eq_ignore_ascii_case(b"content-length") {
        return Ok(None);
    }
    let digits = !value.is_empty() && value.iter().all(u8::is_ascii_digit);
    let len = std::str::from_utf8(value).ok().and_then(|v| v.parse().ok());
    match len {
        Some(len) if digits => Ok(Some(len)),
        _ => Err(Broken(format!(
            "`{}` is not a length in bytes (at most {})",
            shown(),
            u64::MAX
        ))),
    }
}

/// A body of `len` bytes (at most [`BODY_LIMIT`]), grown as its bytes arrive.
fn read_body(input: &mut impl BufRead, len: u64) -> Result<Vec<u8>, Broken> {
    let mut body = Vec::new();
    input
        .by_ref()
        .take(len)
        .read_to_end(&mut body)
        .map_err(io_broken)?;
    if body.len() as u64 != len {
        return Err(ended_inside(body.len() as u64, len));
    }
    Ok(body)
}

/// Reads `len` bytes into nothing.
fn skip(input: &mut impl BufRead, len: u64) -> Result<(), Broken> {
    let read =
        std::io::copy(&mut input.by_ref().take(len), &mut std::io::sink()).map_err(io_broken)?;
    if read != len {
        return Err(ended_inside(read, len));
    }
    Ok(())
}

fn ended_inside(read: u64, len: u64) -> Broken {
    Broken(format!(
        "the stream ended inside a message body ({read} of its {len} bytes)"
    ))
}

fn io_broken(e: std::io::Error) -> Broken {
    Broken(format!("reading the client's messages failed: {e}"))
}

/// Writes one message with its header.
pub(crate) fn write(output: &mut impl Write, message: &serde_json::Value) -> std::io::Result<()> {
    let body = serde_json::to_vec(message)?;
    write!(output, "Content-Length: {}\r\n\r\n", body.len())?;
    output.write_all(&body)?;
    output.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every frame of a stream, as the reader thread sends them.
    fn frames(bytes: &[u8]) -> Vec<Frame> {
        let (tx, rx) = crossbeam_channel::unbounded();
        pump(bytes, &tx);
        drop(tx);
        rx.iter().collect()
    }

    fn broken(f: &Frame) -> &str {
        match f {
            Frame::Broken(Broken(why)) => why,
            other => panic!("not broken: {other:?}"),
        }
    }

    #[test]
    fn messages_are_framed_by_their_length() {
        let got = frames(b"Content-Length: 2\r\n\r\n{}content-length:3\nContent-Type: x\n\n[1]");
        assert_eq!(
            got,
            [
                Frame::Body(b"{}".to_vec()),
                Frame::Body(b"[1]".to_vec()),
                Frame::End
            ]
        );
    }

    #[test]
    fn a_body_over_the_limit_is_skipped_and_the_next_read() {
        let len = BODY_LIMIT + 1;
        let mut bytes = format!("Content-Length: {len}\r\n\r\n").into_bytes();
        bytes.resize(bytes.len() + len as usize, b' ');
        bytes.extend(b"Content-Length: 2\r\n\r\n{}");
        let got = frames(&bytes);
        assert_eq!(got[0], Frame::TooLarge(len));
        assert_eq!(got[1..], [Frame::Body(b"{}".to_vec()), Frame::End]);
    }

    #[test]
    fn a_length_the_stream_does_not_hold_breaks_it_without_allocating() {
        for len in ["99999999999999", "3000000000", "18446744073709551615"] {
            let got = frames(format!("Content-Length: {len}\r\n\r\n{{}}").as_bytes());
            assert_eq!(got[0], Frame::TooLarge(len.parse().unwrap()));
            assert!(broken(&got[1]).contains("ended inside a message body"));
        }
    }

    #[test]
    fn headers_that_cannot_be_framed_break_the_stream() {
        let endless = vec![b'x'; 1 << 20];
        assert!(broken(&frames(&endless)[0]).contains("longer than"));
        let cases: [(&[u8], &str); 7] = [
            (
                b"Content-Length: 18446744073709551616\r\n\r\n",
                "not a length",
            ),
            (b"Content-Length: -1\r\n\r\n", "not a length"),
            (b"Content-Length: +1\r\n\r\n", "not a length"),
            (
                b"Content-Length: 1\r\nContent-Length: 2\r\n\r\n",
                "two different",
            ),
            (b"Content-Type: x\r\n\r\n", "without `Content-Length`"),
            (b"hello\r\n\r\n", "not `name: value`"),
            (b"Content-Length: 2\r\n", "inside a message header"),
        ];
        for (bytes, why) in cases {
            let got = frames(bytes);
            assert!(broken(&got[0]).contains(why), "{got:?}");
            assert_eq!(got.len(), 1);
        }
        assert_eq!(frames(b""), [Frame::End]);
    }
}
