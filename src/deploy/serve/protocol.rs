//! The robot message protocol: one JSON object per line each way (JSON lines), UTF-8, `\n`
//! terminated. Every non-blank request line gets exactly one reply line, in order.
//!
//! Requests (`type` selects the message; unknown fields are refused):
//! - `{"type": "reset"}`: a new episode; zeroes the hidden state. Reply `{"ok": "reset"}`.
//! - `{"type": "observe", "obs": [..], "macro_action_done": true}`: the agent's current
//!   macro-observation (exactly `obs_size` finite numbers). When `macro_action_done` is true the
//!   robot must pick its next macro-action: the policy reads `obs`, advances its hidden state and
//!   replies `{"action": k, "name": "...", "q": [..]}` (greedy, ties to the lowest index, quirk
//!   Q14). When false the running macro-action continues, the state is untouched (the policy only
//!   reads observations at macro-action boundaries, `docs/ALGORITHMS.md` §4.2), and the reply is
//!   `{"ok": "continue"}`. An optional `"step": t` says the observation was made after t
//!   primitive steps of the episode (0 right after reset); a policy that reads the time (ACAC's
//!   actors, whose time embedding is part of their input) refuses a decision without it, every
//!   other policy ignores it. `macdec deploy` always sends it.
//! - `{"type": "info"}`: reply `{"agent": i, "manifest": {..}}` (the policy's manifest).
//!
//! Any bad request gets `{"error": "..."}` naming what was wrong and leaves the state unchanged.

use crate::policy_files::Manifest;
use serde::{Deserialize, Serialize};

/// A validated request.
#[derive(Debug, Clone, PartialEq)]
pub enum Request {
    /// `{"type": "reset"}`: start a new episode.
    Reset,
    /// `{"type": "observe", ...}`: the agent's current macro-observation.
    Observe {
        /// The macro-observation, `obs_size` finite values.
        obs: Vec<f32>,
        /// True when the robot must pick its next macro-action.
        macro_action_done: bool,
        /// Primitive steps of the episode before this observation, if the sender says.
        step: Option<usize>,
    },
    /// `{"type": "info"}`: ask for the agent index and the manifest.
    Info,
}

/// The wire form: numbers read as f64 (so values outside f32 are caught, not rounded to
/// infinity), written as f32.
#[derive(Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
enum Wire<T> {
    Reset {},
    Observe {
        obs: Vec<T>,
        macro_action_done: bool,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        step: Option<usize>,
    },
    Info {},
}

/// A reply line. Clients tell them apart by their key: `action`, `ok`, `manifest` or `error`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Reply {
    /// A new macro-action: its index, its name and the Q-values it was chosen from.
    Decision {
        /// Index of the chosen macro-action.
        action: usize,
        /// Its name in the domain.
        name: String,
        /// The agent's Q-values (or actor scores), one per macro-action.
        q: Vec<f32>,
    },
    /// Acknowledgement of a reset or of an observation without a decision.
    Ack {
        /// What was done.
        ok: Ack,
    },
    /// Which agent this robot runs and its policy's manifest.
    Info {
        /// The agent index this server acts for.
        agent: usize,
        /// The policy's manifest.
        manifest: Box<Manifest>,
    },
    /// The request was refused; the text says why.
    Error {
        /// What was wrong with the request.
        error: String,
    },
}

/// What an acknowledgement confirms.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Ack {
    /// The hidden state was zeroed.
    Reset,
    /// The observation was read; the running macro-action continues.
    Continue,
}

/// Why a request line was refused. The message goes back to the client as `{"error": ...}`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProtocolError {
    /// A line beyond the reader's limit.
    #[error("line longer than {limit} bytes; it was discarded up to its newline")]
    LineTooLong {
        /// The limit, in bytes.
        limit: usize,
    },
    /// The line is not JSON.
    #[error("malformed JSON: {detail}{hint}")]
    MalformedJson {
        /// The parser's reason.
        detail: String,
        /// Extra advice (e.g. that JSON has no NaN); may be empty.
        hint: &'static str,
    },
    /// Valid JSON but not a known request; holds the parser's reason.
    #[error("bad message: {0} (expected {{\"type\": \"reset\"}}, {{\"type\": \"observe\", \"obs\": [...], \"macro_action_done\": true|false, \"step\": t (optional)}} or {{\"type\": \"info\"}})")]
    BadMessage(String),
    /// `obs` has the wrong number of values for this agent.
    #[error("obs has {got} values, agent {agent} expects {expected}")]
    ObsLength {
        /// The agent.
        agent: usize,
        /// Its `obs_size`.
        expected: usize,
        /// Values received.
        got: usize,
    },
    /// An observation value is NaN, infinite or beyond f32.
    #[error("obs[{index}] = {value} is not a finite 32-bit number")]
    NonFiniteObs {
        /// Position in `obs`.
        index: usize,
        /// The value received.
        value: f64,
    },
    /// A decision was asked of a policy that reads the time without saying when the
    /// observation was made.
    #[error("this policy reads when the observation was made (ACAC's time embedding): send \"step\": the primitive steps of the episode before this observation (0 right after reset)")]
    MissingStep,
    /// The net produced a non-finite value; the hidden state is left unchanged.
    #[error("the policy produced a non-finite Q-value ({value} for macro-action {action}) for this observation (values too large for the net?); the hidden state is unchanged")]
    NonFiniteQ {
        /// The macro-action whose value is non-finite.
        action: usize,
        /// The value.
        value: f32,
    },
}

const NON_FINITE_HINT: &str = " (JSON has no NaN or Infinity; observations must be finite numbers)";

impl Request {
    /// Parse and validate one line (without its newline) for agent `agent`, whose observations
    /// have `obs_len` values.
    pub fn parse(line: &[u8], agent: usize, obs_len: usize) -> Result<Request, ProtocolError> {
        let wire: Wire<f64> = serde_json::from_slice(line).map_err(|e| {
            use serde_json::error::Category;
            match e.classify() {
                Category::Syntax | Category::Eof | Category::Io => {
                    let mentions = |word: &[u8]| line.windows(word.len()).any(|w| w == word);
                    let hint = if mentions(b"NaN") || mentions(b"Infinity") {
                        NON_FINITE_HINT
                    } else {
                        ""
                    };
                    ProtocolError::MalformedJson {
                        detail: e.to_string(),
                        hint,
                    }
                }
                Category::Data => {
                    let first = line.iter().find(|b| !b.is_ascii_whitespace());
                    if first == Some(&b'{') {
                        ProtocolError::BadMessage(e.to_string())
                    } else {
                        ProtocolError::BadMessage("a message must be a JSON object".into())
                    }
                }
            }
        })?;
        match wire {
            Wire::Reset {} => Ok(Request::Reset),
            Wire::Info {} => Ok(Request::Info),
            Wire::Observe {
                obs,
                macro_action_done,
                step,
            } => {
                if obs.len() != obs_len {
                    return Err(ProtocolError::ObsLength {
                        agent,
                        expected: obs_len,
                        got: obs.len(),
                    });
                }
                let obs = obs
                    .iter()
                    .enumerate()
                    .map(|(index, &value)| {
                        let v = value as f32;
                        if v.is_finite() {
                            Ok(v)
                        } else {
                            Err(ProtocolError::NonFiniteObs { index, value })
                        }
                    })
                    .collect::<Result<Vec<f32>, _>>()?;
                Ok(Request::Observe {
                    obs,
                    macro_action_done,
                    step,
                })
            }
        }
    }

    /// The request as one line, without the newline (what a client sends).
    pub fn to_line(&self) -> String {
        let wire: Wire<f32> = match self {
            Request::Reset => Wire::Reset {},
            Request::Info => Wire::Info {},
            Request::Observe {
                obs,
                macro_action_done,
                step,
            } => Wire::Observe {
                obs: obs.clone(),
                macro_action_done: *macro_action_done,
                step: *step,
            },
        };
        serde_json::to_string(&wire).expect("requests hold only finite numbers and strings")
    }
}

impl Reply {
    /// The reply as one line, without the newline.
    pub fn to_line(&self) -> String {
        serde_json::to_string(self).expect("replies hold only finite numbers and strings")
    }

    /// An error reply carrying `e`'s message.
    pub fn error(e: impl std::fmt::Display) -> Reply {
        Reply::Error {
            error: e.to_string(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(s: &str) -> Result<Request, ProtocolError> {
        Request::parse(s.as_bytes(), 0, 3)
    }

    #[test]
    fn the_three_message_types_parse() {
        assert_eq!(parse(r#"{"type": "reset"}"#), Ok(Request::Reset));
        assert_eq!(parse(r#"{"type":"info"}"#), Ok(Request::Info));
        assert_eq!(
            parse(r#"{"type": "observe", "obs": [0, 1.5, -2e-3], "macro_action_done": false}"#),
            Ok(Request::Observe {
                obs: vec![0.0, 1.5, -0.002],
                macro_action_done: false,
                step: None,
            })
        );
        assert_eq!(
            parse(r#"{"type": "observe", "obs": [0, 0, 0], "macro_action_done": true, "step": 7}"#),
            Ok(Request::Observe {
                obs: vec![0.0; 3],
                macro_action_done: true,
                step: Some(7),
            })
        );
        let err = parse(
            r#"{"type": "observe", "obs": [0, 0, 0], "macro_action_done": true, "step": -1}"#,
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("bad message") && err.contains("step"), "{err}");
    }

    #[test]
    fn requests_round_trip_through_their_line() {
        for r in [
            Request::Reset,
            Request::Info,
            Request::Observe {
                obs: vec![0.1, 1.0 / 3.0, -7.25e-9],
                macro_action_done: true,
                step: None,
            },
            Request::Observe {
                obs: vec![0.5, 0.0, 1.0],
                macro_action_done: false,
                step: Some(199),
            },
        ] {
            assert_eq!(parse(&r.to_line()), Ok(r));
        }
    }

    #[test]
    fn wrong_obs_length_names_both_lengths() {
        let err = parse(r#"{"type":"observe","obs":[1,2],"macro_action_done":true}"#).unwrap_err();
        assert_eq!(
            err,
            ProtocolError::ObsLength {
                agent: 0,
                expected: 3,
                got: 2
            }
        );
        assert_eq!(err.to_string(), "obs has 2 values, agent 0 expects 3");
    }

    #[test]
    fn nan_infinity_and_f32_overflow_are_refused() {
        let err = parse(r#"{"type":"observe","obs":[1,NaN,2],"macro_action_done":true}"#)
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with("malformed JSON") && err.contains("NaN or Infinity"),
            "{err}"
        );
        let err = parse(r#"{"type":"observe","obs":[1,-Infinity,2],"macro_action_done":true}"#)
            .unwrap_err()
            .to_string();
        assert!(err.contains("NaN or Infinity"), "{err}");
        let err =
            parse(r#"{"type":"observe","obs":[1,2,1e39],"macro_action_done":true}"#).unwrap_err();
        assert_eq!(
            err,
            ProtocolError::NonFiniteObs {
                index: 2,
                value: 1e39
            }
        );
        assert!(parse(r#"{"type":"observe","obs":[1,2,1e400],"macro_action_done":true}"#).is_err());
    }

    #[test]
    fn unknown_types_fields_and_missing_fields_are_named() {
        let err = parse(r#"{"type": "dance"}"#).unwrap_err().to_string();
        assert!(
            err.starts_with("bad message") && err.contains("dance") && err.contains("observe"),
            "{err}"
        );
        let err = parse(r#"{"type":"observe","obs":[1,2,3],"macro_action_don":true}"#)
            .unwrap_err()
            .to_string();
        assert!(err.contains("macro_action_don"), "{err}");
        let err = parse(r#"{"type":"observe","obs":[1,2,3]}"#)
            .unwrap_err()
            .to_string();
        assert!(err.contains("missing field `macro_action_done`"), "{err}");
        let err = parse("[1, 2]").unwrap_err().to_string();
        assert!(err.contains("must be a JSON object"), "{err}");
        let err = parse(r#"{"obs":[1,2,3]}"#).unwrap_err().to_string();
        assert!(err.contains("type"), "{err}");
        let err = parse(r#"{"type":"reset","extra":1}"#)
            .unwrap_err()
            .to_string();
        assert!(err.contains("extra"), "{err}");
        let err = parse(r#"{"type":"observe","obs":[1,"2",3],"macro_action_done":true}"#)
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("bad message"), "{err}");
    }

    #[test]
    fn garbage_is_malformed_json_not_a_panic() {
        for line in [
            &b""[..],
            b"{",
            b"\xff\xfe\x00",
            b"[1,2,3]",
            b"null",
            b"{\"type\":",
        ] {
            assert!(Request::parse(line, 0, 3).is_err());
        }
    }

    #[test]
    fn replies_serialize_to_the_documented_shapes_and_parse_back() {
        let d = Reply::Decision {
            action: 2,
            name: "Push".into(),
            q: vec![0.5, -1.0, 2.0],
        };
        assert_eq!(
            d.to_line(),
            r#"{"action":2,"name":"Push","q":[0.5,-1.0,2.0]}"#
        );
        assert_eq!(
            Reply::Ack { ok: Ack::Continue }.to_line(),
            r#"{"ok":"continue"}"#
        );
        assert_eq!(Reply::Ack { ok: Ack::Reset }.to_line(), r#"{"ok":"reset"}"#);
        let e = Reply::error("obs has 2 values");
        assert_eq!(e.to_line(), r#"{"error":"obs has 2 values"}"#);
        for r in [d, e, Reply::Ack { ok: Ack::Reset }] {
            assert_eq!(serde_json::from_str::<Reply>(&r.to_line()).unwrap(), r);
        }
    }
}
