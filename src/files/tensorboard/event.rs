//! The `Event` protocol buffer TensorBoard reads from an event file (tensorboard's
//! `compat/proto/event.proto` and `summary.proto`), only the fields macdec writes: `wall_time`
//! (1, double), `step` (2, int64), and one of `file_version` (3, string), `summary` (5: a
//! `Summary` of repeated `Value { tag = 1; simple_value = 2 (float) }`) or `session_log` (7: a
//! `SessionLog { status = 1 }`).
//!
//! Encoded as proto3 does (a zero `wall_time` or `step` is left out), so the bytes equal those
//! of TensorBoard's own `Event.SerializeToString()`.

use super::protobuf::{fields, put_bytes, put_f32, put_f64, put_varint_field, Field};

/// The `file_version` of the first event of every file: in a version-2 file TensorBoard takes
/// a `SessionLog.START` as a restart (and no longer guesses restarts from steps going back).
pub const FILE_VERSION: &str = "brain.Event:2";

/// `SessionLog.START`: the program (re)started at this step. TensorBoard's reader then drops
/// every event of this run it read earlier at this step or later, so a resumed run's events
/// replace what a killed process wrote after its last checkpoint.
const SESSION_START: u64 = 1;

/// One named value at a step.
#[derive(Debug, Clone, PartialEq)]
pub struct Scalar {
    /// The name TensorBoard shows (and groups by the part before the first `/`).
    pub tag: String,
    /// The value; TensorBoard's `simple_value` is a 32-bit float.
    pub value: f32,
}

/// What an event carries besides its time and step.
#[derive(Debug, Clone, PartialEq)]
pub enum What {
    /// The format version, first in every file ([`FILE_VERSION`]).
    FileVersion(String),
    /// `SessionLog.START`: the writing program (re)started here; TensorBoard drops the run's
    /// events it read before at this step or later.
    SessionStart,
    /// Scalars at this step, one `Summary.Value` each.
    Scalars(Vec<Scalar>),
}

/// One record of an event file.
#[derive(Debug, Clone, PartialEq)]
pub struct Event {
    /// Seconds since the Unix epoch.
    pub wall_time: f64,
    /// The x axis TensorBoard plots against.
    pub step: i64,
    /// The payload.
    pub what: What,
}

impl Event {
    /// The protobuf bytes (one TFRecord's data).
    pub fn encode(&self) -> Vec<u8> {
        let mut out = Vec::new();
        if self.wall_time.to_bits() != 0 {
            put_f64(&mut out, 1, self.wall_time);
        }
        if self.step != 0 {
            // int64 on the wire is the two's complement as a varint.
            put_varint_field(&mut out, 2, self.step as u64);
        }
        match &self.what {
            What::FileVersion(v) => put_bytes(&mut out, 3, v.as_bytes()),
            What::SessionStart => {
                let mut log = Vec::new();
                put_varint_field(&mut log, 1, SESSION_START);
                put_bytes(&mut out, 7, &log);
            }
            What::Scalars(scalars) => {
                let mut summary = Vec::new();
                for s in scalars {
                    let mut value = Vec::new();
                    put_bytes(&mut value, 1, s.tag.as_bytes());
                    put_f32(&mut value, 2, s.value);
                    put_bytes(&mut summary, 1, &value);
                }
                put_bytes(&mut out, 5, &summary);
            }
        }
        out
    }

    /// Read an event back from its protobuf bytes: what [`Event::encode`] writes (for tests and
    /// checks; TensorBoard is the reader that matters). Fields of other kinds are refused by name.
    pub fn decode(bytes: &[u8]) -> Result<Event, String> {
        let mut event = Event {
            wall_time: 0.0,
            step: 0,
            what: What::Scalars(Vec::new()),
        };
        let mut what = None;
        for field in fields(bytes)? {
            match field {
                Field::Fixed64(1, bits) => event.wall_time = f64::from_bits(bits),
                Field::Varint(2, v) => event.step = v as i64,
                Field::Len(3, v) => {
                    let v = std::str::from_utf8(v).map_err(|e| format!("file_version: {e}"))?;
                    what = Some(What::FileVersion(v.to_string()));
                }
                Field::Len(5, summary) => what = Some(What::Scalars(decode_summary(summary)?)),
                Field::Len(7, log) => {
                    let status = fields(log)?.into_iter().find_map(|f| match f {
                        Field::Varint(1, s) => Some(s),
                        _ => None,
                    });
                    if status != Some(SESSION_START) {
                        return Err(format!("session_log status {status:?} is not START"));
                    }
                    what = Some(What::SessionStart);
                }
                other => return Err(format!("unexpected Event field {other:?}")),
            }
        }
        event.what = what.ok_or("an Event without file_version, summary or session_log")?;
        Ok(event)
    }
}

/// The scalars of a `Summary` message.
fn decode_summary(bytes: &[u8]) -> Result<Vec<Scalar>, String> {
    let mut out = Vec::new();
    for field in fields(bytes)? {
        let Field::Len(1, value) = field else {
            return Err(format!("unexpected Summary field {field:?}"));
        };
        let (mut tag, mut simple) = (None, None);
        for f in fields(value)? {
            match f {
                Field::Len(1, t) => {
                    tag = Some(std::str::from_utf8(t).map_err(|e| format!("tag: {e}"))?)
                }
                Field::Fixed32(2, bits) => simple = Some(f32::from_bits(bits)),
                other => return Err(format!("unexpected Summary.Value field {other:?}")),
            }
        }
        out.push(Scalar {
            tag: tag.ok_or("a Summary.Value without a tag")?.to_string(),
            value: simple.ok_or("a Summary.Value without simple_value")?,
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hex(s: &str) -> Vec<u8> {
        (0..s.len())
            .step_by(2)
            .map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap())
            .collect()
    }

    // The expected bytes below are TensorBoard's own (tensorboard 2.21,
    // `tensorboard.compat.proto.event_pb2.Event(...).SerializeToString().hex()`).

    #[test]
    fn the_first_event_is_byte_for_byte_tensorboards() {
        let e = Event {
            wall_time: 1.5,
            step: 0,
            what: What::FileVersion(FILE_VERSION.into()),
        };
        // 09 + 1.5 as a little-endian double; 1a 0d + "brain.Event:2" (step 0 is left out).
        assert_eq!(
            e.encode(),
            hex("09000000000000f83f1a0d627261696e2e4576656e743a32")
        );
        assert_eq!(Event::decode(&e.encode()).unwrap(), e);
    }

    #[test]
    fn a_scalar_event_is_byte_for_byte_tensorboards() {
        let e = Event {
            wall_time: 1_700_000_000.25,
            step: 40,
            what: What::Scalars(vec![
                Scalar {
                    tag: "eval_return".into(),
                    value: -3.5,
                },
                Scalar {
                    tag: "loss".into(),
                    value: 0.125,
                },
            ]),
        };
        // 10 28: step 40; 2a 21: the 33-byte Summary of two Values, each 0a <len> (0a <tag>
        // 15 <float>).
        assert_eq!(
            e.encode(),
            hex(concat!(
                "0900001040fc54d941",
                "1028",
                "2a21",
                "0a120a0b6576616c5f72657475726e15000060c0",
                "0a0b0a046c6f7373150000003e"
            ))
        );
        assert_eq!(Event::decode(&e.encode()).unwrap(), e);
    }

    #[test]
    fn a_session_start_is_byte_for_byte_tensorboards() {
        let e = Event {
            wall_time: 2.0,
            step: 7,
            what: What::SessionStart,
        };
        // 3a: field 7, length-delimited (field 6 is the deprecated `log_message`); 02 08 01: a
        // two-byte SessionLog whose status (1, varint) is START (1).
        assert_eq!(e.encode(), hex("09000000000000004010073a020801"));
        assert_eq!(Event::decode(&e.encode()).unwrap(), e);
    }

    #[test]
    fn an_event_of_another_kind_is_refused_by_name() {
        // Event.graph_def (4, bytes) is not something macdec writes or reads.
        let mut bytes = Vec::new();
        put_bytes(&mut bytes, 4, b"graph");
        let e = Event::decode(&bytes).unwrap_err();
        assert!(e.contains("unexpected Event field"), "{e}");
        assert!(Event::decode(&[]).is_err());
    }
}
