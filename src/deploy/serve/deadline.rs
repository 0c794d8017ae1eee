//! A TCP read side with two clocks: an idle timeout between request lines, and a deadline for
//! each line once its first byte arrived. The idle timeout alone lets a client that sends one byte
//! per second hold a connection slot forever; the line deadline closes it.

use std::io::{self, Read};
use std::net::TcpStream;
use std::time::{Duration, Instant};

/// Reads from a TCP stream, setting the socket timeout before each read from the two clocks.
pub struct DeadlineStream {
    stream: TcpStream,
    idle: Option<Duration>,
    line: Duration,
    /// When the current unfinished line's first byte arrived.
    line_started: Option<Instant>,
}

impl DeadlineStream {
    /// `idle`: longest silence between lines (`None`: wait forever); `line`: longest time one
    /// line may take to arrive once started.
    pub fn new(stream: TcpStream, idle: Option<Duration>, line: Duration) -> Self {
        DeadlineStream {
            stream,
            idle,
            line,
            line_started: None,
        }
    }
}

impl Read for DeadlineStream {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let timeout = match self.line_started {
            Some(t0) => {
                let left = self
                    .line
                    .checked_sub(t0.elapsed())
                    .filter(|d| !d.is_zero())
                    .ok_or_else(|| {
                        io::Error::new(io::ErrorKind::TimedOut, "request line deadline passed")
                    })?;
                Some(self.idle.map_or(left, |idle| idle.min(left)))
            }
            None => self.idle,
        };
        self.stream.set_read_timeout(timeout)?;
        let n = self.stream.read(buf)?;
        if n > 0 {
            match buf[..n].iter().rposition(|&b| b == b'\n') {
                // Bytes after the last newline start the next line now.
                Some(p) => self.line_started = (p + 1 < n).then(Instant::now),
                None => {
                    self.line_started.get_or_insert_with(Instant::now);
                }
            }
        }
        Ok(n)
    }
}
