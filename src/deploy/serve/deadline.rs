//! A TCP stream with deadlines instead of bare socket timeouts. A socket timeout bounds one
//! `read` or `write` call, and every byte that arrives renews it: a peer sending one byte per
//! second holds a connection with a 10 s timeout forever. Here the socket timeout is recomputed
//! before every call from the time left on the clocks that apply:
//!
//! - an idle timeout between lines (the robot server: a silent client is closed);
//! - a line deadline once a line's first byte arrived (the robot server: a client trickling a
//!   request line is closed);
//! - a reply deadline started when a request is sent ([`ReplyClock`], the driver's side: a robot
//!   trickling its reply fails the deployment at the deadline, issue 29 class 7).
//!
//! One type, so the server and the driver share the arithmetic.

use std::io::{self, Read, Write};
use std::net::TcpStream;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// The deadline of the reply being awaited on one connection, shared by its read and write
/// halves (two [`DeadlineStream`]s over clones of one socket): the request must be written and
/// its whole reply line read before it.
#[derive(Debug, Clone, Default)]
pub struct ReplyClock(Arc<Mutex<Option<Instant>>>);

impl ReplyClock {
    /// A clock that is not running: no reply deadline applies.
    pub fn new() -> Self {
        Self::default()
    }

    /// A request is about to be sent: its reply must be complete within `timeout` from now.
    pub fn start(&self, timeout: Duration) {
        *self.lock() = Some(Instant::now() + timeout);
    }

    /// When the awaited reply is due, if one is.
    pub fn deadline(&self) -> Option<Instant> {
        *self.lock()
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Option<Instant>> {
        // The guarded value is a plain Option<Instant>: a panic elsewhere cannot leave it torn.
        self.0.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// Reads from (and writes to) a TCP stream, setting the socket timeout before each call from
/// the clocks that apply. A passed deadline is an [`io::ErrorKind::TimedOut`] error; a socket
/// timeout firing is the usual `WouldBlock`/`TimedOut` error.
pub struct DeadlineStream {
    stream: TcpStream,
    idle: Option<Duration>,
    line: Duration,
    /// When the current unfinished line's first byte arrived.
    line_started: Option<Instant>,
    reply: Option<ReplyClock>,
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
            reply: None,
        }
    }

    /// The driver's side of a connection: every read and write must end before the deadline
    /// of `clock` (when it is running), however the peer paces its bytes. No idle timeout; a
    /// line once started also ends within `line`.
    pub fn with_reply_clock(stream: TcpStream, line: Duration, clock: ReplyClock) -> Self {
        DeadlineStream {
            reply: Some(clock),
            ..DeadlineStream::new(stream, None, line)
        }
    }

    /// The socket timeout for the next call: the shortest time left on any clock, or an error
    /// if a deadline has passed.
    fn timeout(&self) -> io::Result<Option<Duration>> {
        let mut timeout = self.idle;
        if let Some(t0) = self.line_started {
            let left = time_left(t0 + self.line, "line deadline passed")?;
            timeout = Some(timeout.map_or(left, |t| t.min(left)));
        }
        if let Some(due) = self.reply.as_ref().and_then(ReplyClock::deadline) {
            let left = time_left(due, "reply deadline passed")?;
            timeout = Some(timeout.map_or(left, |t| t.min(left)));
        }
        Ok(timeout)
    }
}

/// Time until `deadline`, or a `TimedOut` error saying `what` once none is left (a zero
/// socket timeout would mean "wait forever").
fn time_left(deadline: Instant, what: &'static str) -> io::Result<Duration> {
    deadline
        .checked_duration_since(Instant::now())
        .filter(|d| !d.is_zero())
        .ok_or_else(|| io::Error::new(io::ErrorKind::TimedOut, what))
}

impl Read for DeadlineStream {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        self.stream.set_read_timeout(self.timeout()?)?;
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

impl Write for DeadlineStream {
    /// With a running reply clock, the write must end before its deadline; otherwise the
    /// stream's own write timeout applies, untouched.
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        if let Some(due) = self.reply.as_ref().and_then(ReplyClock::deadline) {
            let left = time_left(due, "reply deadline passed")?;
            self.stream.set_write_timeout(Some(left))?;
        }
        self.stream.write(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.stream.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::net::TcpListener;

    /// A connected pair: (our end, the peer's end).
    fn pair() -> (TcpStream, TcpStream) {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let ours = TcpStream::connect(listener.local_addr().unwrap()).unwrap();
        let (theirs, _) = listener.accept().unwrap();
        (ours, theirs)
    }

    #[test]
    fn a_reply_trickled_byte_by_byte_fails_at_the_reply_deadline() {
        let (ours, mut theirs) = pair();
        let clock = ReplyClock::new();
        let mut reader =
            DeadlineStream::with_reply_clock(ours, Duration::from_secs(60), clock.clone());
        // One byte every 100 ms, never a newline: each byte would renew a 300 ms socket timeout.
        let peer = std::thread::spawn(move || {
            for _ in 0..40 {
                if theirs.write_all(b" ").is_err() {
                    return;
                }
                std::thread::sleep(Duration::from_millis(100));
            }
        });
        let t0 = Instant::now();
        clock.start(Duration::from_millis(300));
        let mut buf = [0u8; 16];
        let err = loop {
            match reader.read(&mut buf) {
                Ok(n) => assert!(n > 0, "the peer closed early"),
                Err(e) => break e,
            }
        };
        let waited = t0.elapsed();
        assert!(
            matches!(
                err.kind(),
                io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock
            ),
            "{err}"
        );
        assert!(
            waited >= Duration::from_millis(250) && waited < Duration::from_millis(1500),
            "failed after {waited:?}, the deadline was 300 ms"
        );
        drop(reader);
        peer.join().unwrap();
    }

    #[test]
    fn without_a_running_clock_reads_wait_and_a_restarted_clock_gives_new_time() {
        let (ours, mut theirs) = pair();
        let clock = ReplyClock::new();
        let mut reader =
            DeadlineStream::with_reply_clock(ours, Duration::from_secs(60), clock.clone());
        assert_eq!(clock.deadline(), None);
        theirs.write_all(b"a\n").unwrap();
        let mut buf = [0u8; 16];
        assert_eq!(reader.read(&mut buf).unwrap(), 2);
        clock.start(Duration::from_millis(50));
        std::thread::sleep(Duration::from_millis(80));
        let err = reader.read(&mut buf).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::TimedOut);
        clock.start(Duration::from_secs(5));
        theirs.write_all(b"b\n").unwrap();
        assert_eq!(reader.read(&mut buf).unwrap(), 2);
    }
}
