//! The robot stub over TCP (`macdec robot --listen ADDR`): one thread and one [`Session`] (own
//! hidden state) per connection, a bounded number of connections, bounded lines. A client that
//! misbehaves or vanishes affects only its own connection.

use crate::deploy::serve::deadline::DeadlineStream;
use crate::deploy::serve::line_reader::MAX_LINE_BYTES;
use crate::deploy::serve::protocol::Reply;
use crate::deploy::serve::robot::{serve_stream, RobotError, RobotSpec, Session};
use crate::deploy::AgentPolicy;
use std::io::{BufReader, Write};
use std::net::{Shutdown, SocketAddr, TcpListener, TcpStream};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

/// Makes a fresh policy (zero hidden state) for each new connection, e.g. a clone of the loaded
/// net.
pub type PolicyFactory = Arc<dyn Fn() -> Box<dyn AgentPolicy> + Send + Sync>;

/// Default idle timeout of a TCP robot connection, in seconds.
pub const DEFAULT_IDLE_TIMEOUT_SECS: u64 = 300;

/// Resource bounds of a robot server.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limits {
    /// Longest request line in bytes before its newline ([`MAX_LINE_BYTES`] = 64 KiB).
    pub max_line_bytes: usize,
    /// Connections served at once; one more gets an error reply and is closed (default 16).
    pub max_connections: usize,
    /// Close a connection that sends nothing between lines for this long (default 300 s, so
    /// silent clients cannot hold every slot; `None`: never).
    pub idle_timeout: Option<Duration>,
    /// Close a connection whose request line, once started, takes longer than this to arrive
    /// (default 10 s), so a trickling client cannot hold a slot either.
    pub line_timeout: Duration,
    /// Close a connection whose client stops reading replies for this long (default 10 s).
    pub write_timeout: Option<Duration>,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_line_bytes: MAX_LINE_BYTES,
            max_connections: 16,
            idle_timeout: Some(Duration::from_secs(DEFAULT_IDLE_TIMEOUT_SECS)),
            line_timeout: Duration::from_secs(10),
            write_timeout: Some(Duration::from_secs(10)),
        }
    }
}

/// A running server (see [`spawn_server`]). Dropping it stops accepting; open connections finish
/// on their own.
pub struct RobotServer {
    addr: SocketAddr,
    stop: Arc<AtomicBool>,
    active: Arc<AtomicUsize>,
    accept: Option<JoinHandle<()>>,
}

impl RobotServer {
    /// The address the server listens on (with the real port when bound to port 0).
    pub fn local_addr(&self) -> SocketAddr {
        self.addr
    }

    /// Connections being served right now.
    pub fn active_connections(&self) -> usize {
        self.active.load(Ordering::SeqCst)
    }

    /// Stop accepting and wait for the accept loop to end.
    pub fn shutdown(mut self) {
        self.stop_accepting();
    }

    fn stop_accepting(&mut self) {
        if let Some(handle) = self.accept.take() {
            self.stop.store(true, Ordering::SeqCst);
            // Wake the blocking accept with a connection of our own.
            let _ = TcpStream::connect_timeout(&self.addr, Duration::from_secs(1));
            let _ = handle.join();
        }
    }
}

impl Drop for RobotServer {
    fn drop(&mut self) {
        self.stop_accepting();
    }
}

/// Serve `listener` forever on this thread (`macdec robot --listen`). Fails only at start, when
/// the factory's policy does not fit `spec`.
pub fn serve_tcp(
    listener: TcpListener,
    factory: PolicyFactory,
    spec: Arc<RobotSpec>,
    limits: Limits,
) -> Result<(), RobotError> {
    spec.check_policy(factory().as_ref())?;
    accept_loop(
        listener,
        factory,
        spec,
        limits,
        Arc::new(AtomicBool::new(false)),
        Arc::new(AtomicUsize::new(0)),
    );
    Ok(())
}

/// Serve `listener` on a background thread; the returned handle stops it (tests, in-process
/// deployment).
pub fn spawn_server(
    listener: TcpListener,
    factory: PolicyFactory,
    spec: Arc<RobotSpec>,
    limits: Limits,
) -> Result<RobotServer, RobotError> {
    spec.check_policy(factory().as_ref())?;
    let addr = listener
        .local_addr()
        .expect("a bound TCP listener has a local address");
    let stop = Arc::new(AtomicBool::new(false));
    let active = Arc::new(AtomicUsize::new(0));
    let (s, a) = (stop.clone(), active.clone());
    let accept = std::thread::Builder::new()
        .name(format!("robot-{}-accept", spec.agent))
        .spawn(move || accept_loop(listener, factory, spec, limits, s, a))
        .expect("spawning the accept thread (out of threads at start)");
    Ok(RobotServer {
        addr,
        stop,
        active,
        accept: Some(accept),
    })
}

/// Decrements the active-connection count when a connection's thread ends, however it ends.
struct ActiveGuard(Arc<AtomicUsize>);

impl Drop for ActiveGuard {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::SeqCst);
    }
}

fn accept_loop(
    listener: TcpListener,
    factory: PolicyFactory,
    spec: Arc<RobotSpec>,
    limits: Limits,
    stop: Arc<AtomicBool>,
    active: Arc<AtomicUsize>,
) {
    for conn in listener.incoming() {
        if stop.load(Ordering::SeqCst) {
            return;
        }
        let stream = match conn {
            Ok(s) => s,
            Err(e) => {
                // Out of file descriptors or an aborted handshake: keep serving the others.
                eprintln!("robot {}: accept failed: {e}", spec.agent);
                std::thread::sleep(Duration::from_millis(20));
                continue;
            }
        };
        if active.load(Ordering::SeqCst) >= limits.max_connections {
            refuse(
                stream,
                &format!(
                    "too many connections: this robot serves at most {} at a time",
                    limits.max_connections
                ),
            );
            continue;
        }
        active.fetch_add(1, Ordering::SeqCst);
        let guard = ActiveGuard(active.clone());
        let (factory, spec) = (factory.clone(), spec.clone());
        let spawned = std::thread::Builder::new()
            .name(format!("robot-{}-conn", spec.agent))
            .spawn(move || {
                let _guard = guard;
                serve_connection(stream, factory, spec, limits);
            });
        if let Err(e) = spawned {
            // The closure (stream and guard) was dropped: the client sees a closed connection.
            eprintln!("robot: cannot start a connection thread: {e}");
        }
    }
}

/// Best effort: tell the client why, then close.
fn refuse(stream: TcpStream, why: &str) {
    let _ = stream.set_write_timeout(Some(Duration::from_millis(200)));
    let line = Reply::error(why).to_line() + "\n";
    let _ = (&stream).write_all(line.as_bytes());
    let _ = stream.shutdown(Shutdown::Both);
}

fn serve_connection(
    stream: TcpStream,
    factory: PolicyFactory,
    spec: Arc<RobotSpec>,
    limits: Limits,
) {
    // Replies are small and awaited one by one: send them at once (no Nagle delay).
    let _ = stream.set_nodelay(true);
    let _ = stream.set_write_timeout(limits.write_timeout);
    let reader = match stream.try_clone() {
        Ok(s) => BufReader::new(DeadlineStream::new(
            s,
            limits.idle_timeout,
            limits.line_timeout,
        )),
        Err(e) => return refuse(stream, &format!("robot cannot serve this connection: {e}")),
    };
    let mut session = match Session::new(factory(), spec) {
        Ok(s) => s,
        Err(e) => return refuse(stream, &e.to_string()),
    };
    let served = catch_unwind(AssertUnwindSafe(|| {
        serve_stream(&mut session, reader, &stream, limits.max_line_bytes)
    }));
    if served.is_err() {
        refuse(
            stream,
            "internal error: the policy panicked; connection closed",
        );
        return;
    }
    let _ = stream.shutdown(Shutdown::Both);
}
