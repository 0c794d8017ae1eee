//! Reading request lines with a bounded buffer, so a client cannot make a robot hold an
//! arbitrarily long line in memory: a line longer than the limit is reported once and the rest of
//! it is skipped up to its newline, without being stored.

use std::io::{self, BufRead};

/// The default longest request line, in bytes before the newline: 64 KiB. An observation of a
/// few hundred numbers takes a few kilobytes, so the limit only stops garbage.
pub const MAX_LINE_BYTES: usize = 64 * 1024;

/// What the next read produced.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum LineEvent {
    /// A complete line, without its `\n` (and without a trailing `\r`).
    Line(Vec<u8>),
    /// The current line passed the limit; its rest is being discarded. Reported once per line.
    TooLong,
    /// End of input. `partial` when it ended inside an unterminated line, which is dropped (a
    /// message is complete only with its newline).
    Eof {
        /// Input ended inside an unterminated line (dropped).
        partial: bool,
    },
}

/// Splits a byte stream into lines of at most `max_bytes` bytes.
pub struct LineReader<R> {
    inner: R,
    max_bytes: usize,
    buf: Vec<u8>,
    discarding: bool,
}

impl<R: BufRead> LineReader<R> {
    /// Read lines from `inner`, each at most `max_bytes` bytes long.
    pub fn new(inner: R, max_bytes: usize) -> Self {
        LineReader {
            inner,
            max_bytes,
            buf: Vec::new(),
            discarding: false,
        }
    }

    /// The next line, a too-long report, or the end. I/O errors (a reset connection, a read
    /// timeout) are returned as they are; the caller closes the stream.
    pub fn next_line(&mut self) -> io::Result<LineEvent> {
        loop {
            let available = match self.inner.fill_buf() {
                Ok(b) => b,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(e),
            };
            if available.is_empty() {
                let partial = !self.buf.is_empty() || self.discarding;
                self.buf.clear();
                self.discarding = false;
                return Ok(LineEvent::Eof { partial });
            }
            match available.iter().position(|&b| b == b'\n') {
                Some(end) => {
                    let too_long = !self.discarding && self.buf.len() + end > self.max_bytes;
                    let keep = !self.discarding && !too_long;
                    if keep {
                        self.buf.extend_from_slice(&available[..end]);
                    }
                    self.inner.consume(end + 1);
                    let was_discarding = std::mem::replace(&mut self.discarding, false);
                    if too_long {
                        self.buf.clear();
                        return Ok(LineEvent::TooLong);
                    }
                    if was_discarding {
                        continue;
                    }
                    let mut line = std::mem::take(&mut self.buf);
                    if line.last() == Some(&b'\r') {
                        line.pop();
                    }
                    return Ok(LineEvent::Line(line));
                }
                None => {
                    let n = available.len();
                    if self.discarding {
                        self.inner.consume(n);
                    } else if self.buf.len() + n > self.max_bytes {
                        self.inner.consume(n);
                        self.buf.clear();
                        self.discarding = true;
                        return Ok(LineEvent::TooLong);
                    } else {
                        self.buf.extend_from_slice(available);
                        self.inner.consume(n);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::BufReader;

    /// All events of `input` read through a tiny internal buffer (so lines span many reads).
    fn events(input: &[u8], max: usize) -> Vec<LineEvent> {
        let mut r = LineReader::new(BufReader::with_capacity(3, input), max);
        let mut out = Vec::new();
        loop {
            let e = r.next_line().unwrap();
            let end = matches!(e, LineEvent::Eof { .. });
            out.push(e);
            if end {
                return out;
            }
        }
    }

    fn line(s: &str) -> LineEvent {
        LineEvent::Line(s.as_bytes().to_vec())
    }

    #[test]
    fn splits_lines_and_strips_carriage_returns() {
        assert_eq!(
            events(b"ab\r\n\ncdef\n", 8),
            vec![
                line("ab"),
                line(""),
                line("cdef"),
                LineEvent::Eof { partial: false }
            ]
        );
    }

    #[test]
    fn a_line_at_the_limit_passes_and_one_byte_more_is_discarded_whole() {
        assert_eq!(
            events(b"12345\n", 5),
            vec![line("12345"), LineEvent::Eof { partial: false }]
        );
        assert_eq!(
            events(b"123456789012345\nok\n", 5),
            vec![
                LineEvent::TooLong,
                line("ok"),
                LineEvent::Eof { partial: false }
            ]
        );
        assert_eq!(
            events(b"123456\nok\n", 5),
            vec![
                LineEvent::TooLong,
                line("ok"),
                LineEvent::Eof { partial: false }
            ]
        );
    }

    #[test]
    fn an_unterminated_last_line_is_reported_partial_and_dropped() {
        assert_eq!(
            events(b"ok\n{\"type\":", 64),
            vec![line("ok"), LineEvent::Eof { partial: true }]
        );
        assert_eq!(
            events(b"1234567890", 4),
            vec![LineEvent::TooLong, LineEvent::Eof { partial: true }]
        );
    }

    #[test]
    fn a_huge_line_is_never_stored() {
        let mut input = vec![b'x'; 10 * MAX_LINE_BYTES];
        input.extend_from_slice(b"\nend\n");
        let mut r = LineReader::new(BufReader::new(&input[..]), MAX_LINE_BYTES);
        assert_eq!(r.next_line().unwrap(), LineEvent::TooLong);
        assert!(r.buf.capacity() <= MAX_LINE_BYTES + 8 * 1024);
        assert_eq!(r.next_line().unwrap(), line("end"));
    }
}
