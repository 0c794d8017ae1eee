//! How the deployment driver reaches one robot: [`RobotLink`] is the transport-free contract
//! (reset; observe and maybe get a macro-action), [`JsonLink`] speaks the protocol over any byte
//! stream (a TCP connection to a robot process or thread), and [`LocalLink`] calls a policy
//! directly (in-process greedy execution, the reference the protocol path must equal).

use crate::deploy::serve::deadline::{DeadlineStream, ReplyClock};
use crate::deploy::serve::line_reader::{LineEvent, LineReader};
use crate::deploy::serve::protocol::{Ack, ProtocolError, Reply, Request};
use crate::deploy::{greedy_action, AgentPolicy};
use crate::policy_files::Manifest;
use std::io::{BufRead, BufReader, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::Duration;

/// A [`JsonLink`] over TCP, as [`JsonLink::connect`] opens it: both halves of the connection
/// keep the deadline of the reply being awaited.
pub type TcpLink = JsonLink<BufReader<DeadlineStream>, DeadlineStream>;

/// Longest reply line a client accepts (the `info` reply carries the whole manifest).
pub const MAX_REPLY_BYTES: usize = 16 * 1024 * 1024;

/// One robot as the driver sees it.
pub trait RobotLink {
    /// A new episode: the robot zeroes its hidden state.
    fn reset(&mut self) -> Result<(), LinkError>;
    /// The agent's current macro-observation, made after `step` primitive steps of the episode.
    /// `Some(action)` exactly when `macro_action_done` (a new macro-action is due), `None`
    /// otherwise.
    fn observe(
        &mut self,
        obs: &[f32],
        step: usize,
        macro_action_done: bool,
    ) -> Result<Option<usize>, LinkError>;
}

impl<L: RobotLink + ?Sized> RobotLink for Box<L> {
    fn reset(&mut self) -> Result<(), LinkError> {
        (**self).reset()
    }
    fn observe(
        &mut self,
        obs: &[f32],
        step: usize,
        macro_action_done: bool,
    ) -> Result<Option<usize>, LinkError> {
        (**self).observe(obs, step, macro_action_done)
    }
}

/// Why talking to a robot failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LinkError {
    /// Connecting, reading or writing failed; the text names the address or error.
    #[error("connection to the robot failed: {0}")]
    Io(String),
    /// The whole reply did not arrive within the timeout from when its request was sent (a
    /// deadline per reply: a robot trickling bytes does not extend it).
    #[error("no complete reply from {peer} within {} s of the request", timeout.as_secs_f64())]
    Timeout {
        /// The robot's address.
        peer: String,
        /// The deadline per reply.
        timeout: Duration,
    },
    /// The robot closed the connection before replying.
    #[error("the robot closed the connection")]
    Closed,
    /// A reply line longer than `MAX_REPLY_BYTES`.
    #[error("the robot sent a reply longer than {MAX_REPLY_BYTES} bytes")]
    ReplyTooLong,
    /// A reply that is not a known reply line.
    #[error("the robot sent an unreadable reply ({reason}): {line}")]
    BadReply {
        /// The line received.
        line: String,
        /// The parser's reason.
        reason: String,
    },
    /// The robot answered `{"error": ...}`; holds its text.
    #[error("the robot refused the request: {0}")]
    Refused(String),
    /// A valid reply of the wrong kind for the request.
    #[error("expected {expected} from the robot, got: {got}")]
    Unexpected {
        /// The reply kind expected.
        expected: &'static str,
        /// The line received.
        got: String,
    },
    /// The robot chose a macro-action the domain does not have.
    #[error("the robot chose macro-action {action}, out of range 0..{n_actions}")]
    ActionOutOfRange {
        /// The index it sent.
        action: usize,
        /// Macro-actions the agent has.
        n_actions: usize,
    },
    /// The robot serves another agent than the one this link drives.
    #[error("the robot serves agent {got}, expected agent {expected}")]
    WrongAgent {
        /// The agent this link drives.
        expected: usize,
        /// The agent the robot serves.
        got: usize,
    },
    /// The robot's manifest differs from the driver's.
    #[error("the robot runs a different policy (its manifest differs from ours)")]
    WrongPolicy,
}

/// The protocol over a byte stream: one request line out, one reply line back.
pub struct JsonLink<R, W> {
    reader: LineReader<R>,
    writer: W,
    n_actions: usize,
    /// Who answers, for error messages: the address, or "the robot".
    peer: String,
    /// The clock the stream's deadlines read and the time each reply gets, if any.
    deadline: Option<(ReplyClock, Duration)>,
}

impl TcpLink {
    /// Connect to the robot serving agent `agent` of `manifest` at `addr` and check, with an
    /// `info` request, that it runs that agent of that policy. Connecting, and each request
    /// with its whole reply, must take at most `timeout` (a deadline per reply, not per read: a
    /// hung or trickling robot must not hang the deployment).
    pub fn connect(
        addr: SocketAddr,
        agent: usize,
        manifest: &Manifest,
        timeout: Duration,
    ) -> Result<Self, LinkError> {
        let io = |e: std::io::Error| LinkError::Io(format!("{addr}: {e}"));
        let stream = TcpStream::connect_timeout(&addr, timeout).map_err(io)?;
        stream.set_nodelay(true).map_err(io)?;
        let clock = ReplyClock::new();
        let reader = DeadlineStream::with_reply_clock(
            stream.try_clone().map_err(io)?,
            timeout,
            clock.clone(),
        );
        let writer = DeadlineStream::with_reply_clock(stream, timeout, clock.clone());
        JsonLink::open_as(
            BufReader::new(reader),
            writer,
            agent,
            manifest,
            addr.to_string(),
            Some((clock, timeout)),
        )
    }
}

impl<R: BufRead, W: Write> JsonLink<R, W> {
    /// Wrap a stream to a robot and check that it serves agent `agent` of `manifest`. The
    /// streams' own timeouts, if any, bound each read and write.
    pub fn open(
        reader: R,
        writer: W,
        agent: usize,
        manifest: &Manifest,
    ) -> Result<Self, LinkError> {
        Self::open_as(reader, writer, agent, manifest, "the robot".into(), None)
    }

    /// [`JsonLink::open`] naming the robot `peer`, with a deadline per reply when `deadline`
    /// holds the clock the streams read.
    fn open_as(
        reader: R,
        writer: W,
        agent: usize,
        manifest: &Manifest,
        peer: String,
        deadline: Option<(ReplyClock, Duration)>,
    ) -> Result<Self, LinkError> {
        let mut link = JsonLink {
            reader: LineReader::new(reader, MAX_REPLY_BYTES),
            writer,
            n_actions: 0,
            peer,
            deadline,
        };
        match link.request(&Request::Info)? {
            Reply::Info {
                agent: got,
                manifest: theirs,
            } => {
                if got != agent {
                    return Err(LinkError::WrongAgent {
                        expected: agent,
                        got,
                    });
                }
                if *theirs != *manifest {
                    return Err(LinkError::WrongPolicy);
                }
            }
            other => return Err(unexpected("the info reply", &other)),
        }
        link.n_actions = manifest.agents[agent].n_actions;
        Ok(link)
    }

    /// Send one request and read its reply. An `{"error": ...}` reply becomes
    /// [`LinkError::Refused`].
    /// With a deadline (a link from [`JsonLink::connect`]), writing the request and reading its
    /// whole reply must end within the timeout, or [`LinkError::Timeout`].
    pub fn request(&mut self, request: &Request) -> Result<Reply, LinkError> {
        let line = request.to_line() + "\n";
        if let Some((clock, timeout)) = &self.deadline {
            clock.start(*timeout);
        }
        self.writer
            .write_all(line.as_bytes())
            .and_then(|()| self.writer.flush())
            .map_err(|e| self.io_error(e))?;
        let reply = match self.reader.next_line() {
            Ok(LineEvent::Line(bytes)) => bytes,
            Ok(LineEvent::TooLong) => return Err(LinkError::ReplyTooLong),
            Ok(LineEvent::Eof { .. }) => return Err(LinkError::Closed),
            Err(e) => return Err(self.io_error(e)),
        };
        match serde_json::from_slice::<Reply>(&reply) {
            Ok(Reply::Error { error }) => Err(LinkError::Refused(error)),
            Ok(r) => Ok(r),
            Err(e) => Err(LinkError::BadReply {
                line: String::from_utf8_lossy(&reply).chars().take(200).collect(),
                reason: e.to_string(),
            }),
        }
    }
}

impl<R, W> JsonLink<R, W> {
    /// A failed read or write: past the reply's deadline it is a [`LinkError::Timeout`] (a
    /// socket timeout set from the deadline fires as `WouldBlock` on Linux, `TimedOut` elsewhere).
    fn io_error(&self, e: std::io::Error) -> LinkError {
        use std::io::ErrorKind::{TimedOut, WouldBlock};
        match &self.deadline {
            Some((_, timeout)) if matches!(e.kind(), TimedOut | WouldBlock) => LinkError::Timeout {
                peer: self.peer.clone(),
                timeout: *timeout,
            },
            _ => LinkError::Io(format!("{}: {e}", self.peer)),
        }
    }
}

fn unexpected(expected: &'static str, got: &Reply) -> LinkError {
    LinkError::Unexpected {
        expected,
        got: got.to_line().chars().take(200).collect(),
    }
}

impl<R: BufRead, W: Write> RobotLink for JsonLink<R, W> {
    fn reset(&mut self) -> Result<(), LinkError> {
        match self.request(&Request::Reset)? {
            Reply::Ack { ok: Ack::Reset } => Ok(()),
            other => Err(unexpected("{\"ok\": \"reset\"}", &other)),
        }
    }

    fn observe(
        &mut self,
        obs: &[f32],
        step: usize,
        macro_action_done: bool,
    ) -> Result<Option<usize>, LinkError> {
        let reply = self.request(&Request::Observe {
            obs: obs.to_vec(),
            macro_action_done,
            step: Some(step),
        })?;
        match (macro_action_done, reply) {
            (true, Reply::Decision { action, .. }) if action < self.n_actions => Ok(Some(action)),
            (true, Reply::Decision { action, .. }) => Err(LinkError::ActionOutOfRange {
                action,
                n_actions: self.n_actions,
            }),
            (false, Reply::Ack { ok: Ack::Continue }) => Ok(None),
            (true, other) => Err(unexpected("a decision", &other)),
            (false, other) => Err(unexpected("{\"ok\": \"continue\"}", &other)),
        }
    }
}

/// A policy called in-process: decentralized execution without any transport, greedy or (for an
/// actor, whose scores are log-probabilities) sampled.
pub struct LocalLink<P> {
    policy: P,
    q: Vec<f32>,
    sampler: Option<rand_chacha::ChaCha8Rng>,
    probs: Vec<f64>,
}

impl<P: AgentPolicy> LocalLink<P> {
    /// A greedy link.
    pub fn new(policy: P) -> Self {
        Self::with_sampler(policy, None)
    }

    /// A link that samples from exp(score) with `sampler` when given, else greedy.
    pub fn with_sampler(policy: P, sampler: Option<rand_chacha::ChaCha8Rng>) -> Self {
        let q = vec![0.0; policy.n_actions()];
        LocalLink {
            policy,
            q,
            sampler,
            probs: Vec::new(),
        }
    }
}

impl<P: AgentPolicy> RobotLink for LocalLink<P> {
    fn reset(&mut self) -> Result<(), LinkError> {
        self.policy.reset();
        Ok(())
    }

    fn observe(
        &mut self,
        obs: &[f32],
        step: usize,
        macro_action_done: bool,
    ) -> Result<Option<usize>, LinkError> {
        if obs.len() != self.policy.obs_len() {
            return Err(LinkError::Refused(format!(
                "obs has {} values, the policy expects {}",
                obs.len(),
                self.policy.obs_len()
            )));
        }
        if !macro_action_done {
            return Ok(None);
        }
        self.policy.q_values(obs, step, &mut self.q);
        // Refused exactly as a robot refuses it (`robot::Session`), so in-process and deployed
        // runs of a broken policy fail alike.
        if let Some((action, &value)) = self.q.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(LinkError::Refused(
                ProtocolError::NonFiniteQ { action, value }.to_string(),
            ));
        }
        Ok(Some(choose_action(
            &self.q,
            self.sampler.as_mut(),
            &mut self.probs,
        )))
    }
}

/// An agent's macro-action from its net's `scores`: the greedy one, or with `sampler` a draw from
/// the distribution exp(score) (an actor's log-probabilities; MacroMARL's evaluation), as
/// `macdec eval` and `eval --sample` choose. `probs` is scratch space.
pub fn choose_action(
    scores: &[f32],
    sampler: Option<&mut rand_chacha::ChaCha8Rng>,
    probs: &mut Vec<f64>,
) -> usize {
    match sampler {
        None => greedy_action(scores),
        Some(rng) => {
            crate::nn::sampling::mixture(scores, None, probs);
            crate::nn::sampling::sample_weighted(probs, rng)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Q = [0, value] whatever the observation.
    struct Fixed(f32);

    impl AgentPolicy for Fixed {
        fn obs_len(&self) -> usize {
            1
        }
        fn n_actions(&self) -> usize {
            2
        }
        fn reset(&mut self) {}
        fn q_values(&mut self, _obs: &[f32], _step: usize, q: &mut [f32]) {
            q.copy_from_slice(&[0.0, self.0]);
        }
    }

    #[test]
    fn local_link_refuses_non_finite_q_as_a_robot_does() {
        assert_eq!(
            LocalLink::new(Fixed(1.0)).observe(&[0.0], 0, true),
            Ok(Some(1))
        );
        let err = LocalLink::new(Fixed(f32::NAN))
            .observe(&[0.0], 0, true)
            .unwrap_err();
        let robot = ProtocolError::NonFiniteQ {
            action: 1,
            value: f32::NAN,
        };
        assert_eq!(err, LinkError::Refused(robot.to_string()));
        assert_eq!(
            LocalLink::new(Fixed(f32::NAN)).observe(&[0.0], 0, false),
            Ok(None)
        );
    }
}
