//! The robot stub: one agent's policy answering protocol messages, keeping its LSTM hidden state
//! between them (issue 7). [`Session`] is one client's conversation; [`serve_stream`] runs it over
//! any byte stream (stdin/stdout, one TCP connection) with the bounded line reader.

use crate::deploy::serve::line_reader::{LineEvent, LineReader};
use crate::deploy::serve::protocol::{Ack, ProtocolError, Reply, Request};
use crate::deploy::{greedy_action, AgentPolicy};
use crate::policy_files::Manifest;
use std::io::{self, BufRead, Write};
use std::sync::Arc;

/// What a robot serves, fixed at start: its agent, observation size, macro-action names and the
/// precomputed `info` reply. Shared by every connection.
#[derive(Debug)]
pub struct RobotSpec {
    /// The agent this robot acts for.
    pub agent: usize,
    /// Length of its macro-observation.
    pub obs_len: usize,
    /// Its macro-actions' names, by index.
    pub action_names: Vec<String>,
    /// The policy's manifest, sent in the `info` reply.
    pub manifest: Manifest,
    info_line: String,
}

/// Why a robot could not start.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RobotError {
    /// The agent is not one of the policy's.
    #[error("agent {agent} is out of range: the policy has agents 0..{n_agents}")]
    AgentOutOfRange {
        /// Agent asked for.
        agent: usize,
        /// Agents the policy has.
        n_agents: usize,
    },
    /// The loaded net's sizes differ from the manifest's.
    #[error("agent {agent}: the policy has {got} {what}, the manifest says {expected}")]
    PolicyMismatch {
        /// The agent.
        agent: usize,
        /// `observation values` or `macro-actions`.
        what: &'static str,
        /// What the manifest says.
        expected: usize,
        /// What the net has.
        got: usize,
    },
}

impl RobotSpec {
    /// The spec of agent `agent` of `manifest`.
    pub fn new(manifest: &Manifest, agent: usize) -> Result<RobotSpec, RobotError> {
        let entry = manifest
            .agents
            .get(agent)
            .ok_or(RobotError::AgentOutOfRange {
                agent,
                n_agents: manifest.agents.len(),
            })?;
        let info_line = Reply::Info {
            agent,
            manifest: Box::new(manifest.clone()),
        }
        .to_line();
        Ok(RobotSpec {
            agent,
            obs_len: entry.obs_size,
            action_names: entry.action_names.clone(),
            manifest: manifest.clone(),
            info_line,
        })
    }

    /// Check that `policy` reads and writes the sizes the manifest promises.
    pub fn check_policy(&self, policy: &dyn AgentPolicy) -> Result<(), RobotError> {
        let mismatch = |what, expected, got| RobotError::PolicyMismatch {
            agent: self.agent,
            what,
            expected,
            got,
        };
        if policy.obs_len() != self.obs_len {
            return Err(mismatch(
                "observation values",
                self.obs_len,
                policy.obs_len(),
            ));
        }
        if policy.n_actions() != self.action_names.len() {
            return Err(mismatch(
                "macro-actions",
                self.action_names.len(),
                policy.n_actions(),
            ));
        }
        Ok(())
    }
}

/// One client's conversation with a robot: the policy with its hidden state.
pub struct Session {
    policy: Box<dyn AgentPolicy>,
    spec: Arc<RobotSpec>,
    q: Vec<f32>,
}

impl Session {
    /// A session starting from a zero hidden state.
    pub fn new(mut policy: Box<dyn AgentPolicy>, spec: Arc<RobotSpec>) -> Result<Self, RobotError> {
        spec.check_policy(policy.as_ref())?;
        policy.reset();
        let q = vec![0.0; spec.action_names.len()];
        Ok(Session { policy, spec, q })
    }

    /// Answer one request line (without its newline). `None` for a blank line, which is ignored.
    /// A refused request leaves the hidden state as it was.
    pub fn handle_line(&mut self, line: &[u8]) -> Option<String> {
        if line.iter().all(u8::is_ascii_whitespace) {
            return None;
        }
        let reply = match Request::parse(line, self.spec.agent, self.spec.obs_len) {
            Ok(Request::Info) => return Some(self.spec.info_line.clone()),
            Ok(request) => self.handle(request),
            Err(e) => Reply::error(e),
        };
        Some(reply.to_line())
    }

    /// Answer one validated request.
    pub fn handle(&mut self, request: Request) -> Reply {
        match request {
            Request::Reset => {
                self.policy.reset();
                Reply::Ack { ok: Ack::Reset }
            }
            Request::Observe {
                macro_action_done: false,
                ..
            } => Reply::Ack { ok: Ack::Continue },
            Request::Observe {
                obs,
                macro_action_done: true,
                step,
            } => {
                let step = match step {
                    Some(step) => step,
                    None if self.policy.reads_step() => {
                        return Reply::error(ProtocolError::MissingStep)
                    }
                    // Read by no policy that gets here.
                    None => 0,
                };
                self.policy.q_values(&obs, step, &mut self.q);
                if let Some((action, &value)) =
                    self.q.iter().enumerate().find(|(_, v)| !v.is_finite())
                {
                    return Reply::error(ProtocolError::NonFiniteQ { action, value });
                }
                let action = greedy_action(&self.q);
                Reply::Decision {
                    action,
                    name: self.spec.action_names[action].clone(),
                    q: self.q.clone(),
                }
            }
            Request::Info => Reply::Info {
                agent: self.spec.agent,
                manifest: Box::new(self.spec.manifest.clone()),
            },
        }
    }
}

/// How a served stream ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StreamEnd {
    /// The client closed after a complete line.
    Closed,
    /// The client closed in the middle of a line, which was dropped.
    ClosedMidLine,
    /// Reading or writing failed (connection reset, timeout); the stream was abandoned.
    Failed,
}

/// Serve `session` over a byte stream until it ends: one reply line per non-blank request line,
/// flushed at once; lines longer than `max_line_bytes` get an error reply and are skipped.
/// Never panics on input; I/O failures end the stream (reported as [`StreamEnd::Failed`]).
pub fn serve_stream(
    session: &mut Session,
    reader: impl BufRead,
    mut writer: impl Write,
    max_line_bytes: usize,
) -> StreamEnd {
    let mut lines = LineReader::new(reader, max_line_bytes);
    loop {
        let reply = match lines.next_line() {
            Ok(LineEvent::Line(line)) => match session.handle_line(&line) {
                Some(reply) => reply,
                None => continue,
            },
            Ok(LineEvent::TooLong) => Reply::error(ProtocolError::LineTooLong {
                limit: max_line_bytes,
            })
            .to_line(),
            Ok(LineEvent::Eof { partial: false }) => return StreamEnd::Closed,
            Ok(LineEvent::Eof { partial: true }) => return StreamEnd::ClosedMidLine,
            Err(_) => return StreamEnd::Failed,
        };
        let sent = writer
            .write_all(reply.as_bytes())
            .and_then(|()| writer.write_all(b"\n"))
            .and_then(|()| writer.flush());
        if sent.is_err() {
            return StreamEnd::Failed;
        }
    }
}

/// Serve one session over this process's stdin and stdout (`macdec robot` without `--listen`).
pub fn serve_stdio(
    policy: Box<dyn AgentPolicy>,
    spec: Arc<RobotSpec>,
    max_line_bytes: usize,
) -> Result<StreamEnd, RobotError> {
    let mut session = Session::new(policy, spec)?;
    let stdin = io::stdin();
    let stdout = io::stdout();
    Ok(serve_stream(
        &mut session,
        stdin.lock(),
        stdout.lock(),
        max_line_bytes,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::deploy::policy::mock::{mock_manifest, MockPolicy};
    use crate::deploy::serve::line_reader::MAX_LINE_BYTES;

    fn bp_spec(agent: usize) -> (Manifest, Arc<RobotSpec>) {
        let manifest = mock_manifest(crate::envs::box_pushing::spec(10, 100));
        let spec = Arc::new(RobotSpec::new(&manifest, agent).unwrap());
        (manifest, spec)
    }

    fn session(agent: usize) -> Session {
        let (_, spec) = bp_spec(agent);
        Session::new(Box::new(MockPolicy::new(5, 8, agent as u64)), spec).unwrap()
    }

    fn observe(obs: &[f32], done: bool) -> String {
        Request::Observe {
            obs: obs.to_vec(),
            macro_action_done: done,
            step: None,
        }
        .to_line()
    }

    fn reply(s: &mut Session, line: &str) -> Reply {
        serde_json::from_str(&s.handle_line(line.as_bytes()).unwrap()).unwrap()
    }

    /// The reference: the mock policy driven directly.
    fn expected_q(history: &[[f32; 5]], agent: u64) -> Vec<f32> {
        let mut p = MockPolicy::new(5, 8, agent);
        let mut q = vec![0.0; 8];
        for obs in history {
            p.q_values(obs, 0, &mut q);
        }
        q
    }

    #[test]
    fn decisions_carry_the_policy_q_its_argmax_and_the_action_name() {
        let mut s = session(1);
        let obs = [[1.0, 0.0, 0.0, 1.0, 0.0], [0.0, 1.0, 0.0, 0.0, 0.0]];
        for (t, o) in obs.iter().enumerate() {
            let Reply::Decision { action, name, q } = reply(&mut s, &observe(o, true)) else {
                panic!("expected a decision")
            };
            let want = expected_q(&obs[..=t], 1);
            assert_eq!(q, want);
            assert_eq!(action, greedy_action(&want));
            assert_eq!(name, s.spec.action_names[action]);
        }
    }

    #[test]
    fn hidden_state_advances_only_at_macro_action_boundaries_and_resets() {
        let mut s = session(0);
        let a = [1.0, 0.0, 0.0, 0.0, 1.0];
        let b = [0.0, 0.0, 1.0, 0.0, 0.0];
        reply(&mut s, &observe(&a, true));
        // Busy steps: acknowledged, no state change.
        for _ in 0..3 {
            assert_eq!(
                reply(&mut s, &observe(&b, false)),
                Reply::Ack { ok: Ack::Continue }
            );
        }
        let Reply::Decision { q, .. } = reply(&mut s, &observe(&b, true)) else {
            panic!()
        };
        assert_eq!(q, expected_q(&[a, b], 0));
        assert_ne!(
            q,
            expected_q(&[b], 0),
            "the mock's Q must depend on history"
        );
        assert_eq!(
            reply(&mut s, r#"{"type":"reset"}"#),
            Reply::Ack { ok: Ack::Reset }
        );
        let Reply::Decision { q, .. } = reply(&mut s, &observe(&b, true)) else {
            panic!()
        };
        assert_eq!(q, expected_q(&[b], 0));
    }

    #[test]
    fn refused_requests_leave_the_state_untouched() {
        let mut s = session(0);
        let a = [0.0, 1.0, 0.0, 0.0, 1.0];
        reply(&mut s, &observe(&a, true));
        for bad in [
            r#"{"type":"observe","obs":[1,2,3],"macro_action_done":true}"#,
            r#"{"type":"observe","obs":[1,2,NaN,4,5],"macro_action_done":true}"#,
            r#"{"type":"observe","obs":[1,2,1e39,4,5],"macro_action_done":true}"#,
            r#"{"type":"teleport"}"#,
            "{not json",
        ] {
            let Reply::Error { error } = reply(&mut s, bad) else {
                panic!("{bad} must be refused")
            };
            assert!(!error.is_empty());
        }
        let Reply::Decision { q, .. } = reply(&mut s, &observe(&a, true)) else {
            panic!()
        };
        assert_eq!(q, expected_q(&[a, a], 0));
    }

    #[test]
    fn info_returns_the_agent_and_its_manifest() {
        let (manifest, _) = bp_spec(1);
        let mut s = session(1);
        assert_eq!(
            reply(&mut s, r#"{"type":"info"}"#),
            Reply::Info {
                agent: 1,
                manifest: Box::new(manifest.clone())
            }
        );
        assert_eq!(
            s.handle(Request::Info),
            Reply::Info {
                agent: 1,
                manifest: Box::new(manifest)
            }
        );
    }

    #[test]
    fn a_policy_of_the_wrong_size_is_refused_at_start() {
        let (_, spec) = bp_spec(0);
        let err = Session::new(Box::new(MockPolicy::new(4, 8, 0)), spec.clone())
            .err()
            .unwrap();
        assert!(err.to_string().contains("4 observation values"), "{err}");
        assert!(Session::new(Box::new(MockPolicy::new(5, 7, 0)), spec).is_err());
    }

    #[test]
    fn broken_weights_give_an_error_reply_not_nan() {
        struct NanPolicy;
        impl AgentPolicy for NanPolicy {
            fn obs_len(&self) -> usize {
                5
            }
            fn n_actions(&self) -> usize {
                8
            }
            fn reset(&mut self) {}
            fn q_values(&mut self, _: &[f32], _: usize, q: &mut [f32]) {
                q.fill(f32::NAN)
            }
        }
        let (_, spec) = bp_spec(0);
        let mut s = Session::new(Box::new(NanPolicy), spec).unwrap();
        let Reply::Error { error } = reply(&mut s, &observe(&[0.0; 5], true)) else {
            panic!()
        };
        assert!(error.contains("non-finite Q"), "{error}");
    }

    #[test]
    fn a_policy_that_reads_the_time_needs_the_step_and_answers_by_it() {
        /// Scores the step it is given, as a net with a time embedding would.
        struct Clock;
        impl AgentPolicy for Clock {
            fn obs_len(&self) -> usize {
                5
            }
            fn n_actions(&self) -> usize {
                8
            }
            fn reset(&mut self) {}
            fn reads_step(&self) -> bool {
                true
            }
            fn q_values(&mut self, _: &[f32], step: usize, q: &mut [f32]) {
                q.fill(0.0);
                q[step % 8] = 1.0;
            }
        }
        let (_, spec) = bp_spec(0);
        let mut s = Session::new(Box::new(Clock), spec).unwrap();
        let Reply::Error { error } = reply(&mut s, &observe(&[0.0; 5], true)) else {
            panic!("a decision without a step")
        };
        assert!(error.contains("\"step\""), "{error}");
        // Continuing needs no decision, so no step either.
        assert_eq!(
            reply(&mut s, &observe(&[0.0; 5], false)),
            Reply::Ack { ok: Ack::Continue }
        );
        let line = Request::Observe {
            obs: vec![0.0; 5],
            macro_action_done: true,
            step: Some(13),
        }
        .to_line();
        let Reply::Decision { action, .. } = reply(&mut s, &line) else {
            panic!("a decision with a step")
        };
        assert_eq!(action, 5);
    }

    #[test]
    fn stream_answers_every_non_blank_line_in_order_and_drops_a_partial_last_line() {
        let mut s = session(0);
        let mut input = String::new();
        input.push_str("{\"type\":\"reset\"}\n\n   \n");
        input.push_str(&observe(&[1.0, 0.0, 0.0, 0.0, 0.0], true));
        input.push('\n');
        input.push_str(&"x".repeat(MAX_LINE_BYTES + 1));
        input.push_str("\n{\"type\":\"observe\"");
        let mut out = Vec::new();
        let end = serve_stream(&mut s, input.as_bytes(), &mut out, MAX_LINE_BYTES);
        assert_eq!(end, StreamEnd::ClosedMidLine);
        let replies: Vec<Reply> = String::from_utf8(out)
            .unwrap()
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        assert_eq!(replies.len(), 3);
        assert_eq!(replies[0], Reply::Ack { ok: Ack::Reset });
        assert!(matches!(replies[1], Reply::Decision { .. }));
        assert_eq!(
            replies[2],
            Reply::error(format!(
                "line longer than {MAX_LINE_BYTES} bytes; it was discarded up to its newline"
            ))
        );
    }
}
