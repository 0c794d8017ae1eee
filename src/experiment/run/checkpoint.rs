//! The `checkpoint.bin` file format: a versioned header naming the run, a SHA-256 of the payload,
//! and the payload (the whole trainer, bincode).
//!
//! bincode alone reads many corrupted files "successfully" with different numbers, and cannot tell
//! one seed's trainer from another's. So a checkpoint is only resumed when its magic and version
//! are this format's, its length is exact (no trailing bytes), its payload hashes to the recorded
//! digest, and its identity (experiment, method, variant, seed, hash of the resolved config) is
//! the run's. Anything else is refused with a message saying which check failed.
//!
//! Layout (integers little-endian):
//! `b"MACDECCK"`, `u32` version, `u32` identity length, identity (JSON), `u64` payload length,
//! 32-byte SHA-256 of the payload, payload.

use crate::algos::families::AnyLoop;
use crate::algos::families::Method;
use crate::experiment::definition::run_settings::RunSettings;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

/// First bytes of every checkpoint.
pub const MAGIC: &[u8; 8] = b"MACDECCK";
/// The format version this build writes and reads.
/// Version 7: actor-critic learners count the steps of completed training episodes (their
/// `acac_timesteps` column); runs checkpointed by version 6 restart.
/// Version 6: Overcooked kitchens hold up to 11 x 11 cells, 6 foods, 4 plates and 4 knives (ACAC's
/// Overcooked-MA-v0); runs checkpointed by version 5 restart.
/// Version 5: Overcooked environments carry ACAC's variant (numbering, random starts, state) and
/// ACAC's domains joined the built-in list; runs checkpointed by version 4 restart.
/// Version 4: each family's learner holds its own typed config and method (one list of
/// families, issue 40); runs checkpointed by version 3 restart.
/// Version 3: evaluation points and actor-critic recorders carry the undiscounted return.
/// Version 2: the payload is the family-tagged training loop (`AnyLoop`); version 1 held the
/// value-based trainer alone.
pub const VERSION: u32 = 7;
/// Longest identity header accepted (names are at most 200 bytes each).
const MAX_IDENTITY_BYTES: usize = 4096;

/// Which run a checkpoint belongs to.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CheckpointIdentity {
    /// The experiment's name.
    pub experiment: String,
    /// The method's name.
    pub method: String,
    /// The sweep point, empty without a sweep.
    pub variant: String,
    /// The run's seed.
    pub seed: u64,
    /// SHA-256 (hex) of the resolved domain and config ([`RunSettings`]) as JSON.
    pub config_sha256: String,
}

impl CheckpointIdentity {
    /// The identity of a run.
    pub fn new(
        experiment: &str,
        method: Method,
        variant: &str,
        seed: u64,
        c: &RunSettings,
    ) -> Self {
        CheckpointIdentity {
            experiment: experiment.to_string(),
            method: method.name().to_string(),
            variant: variant.to_string(),
            seed,
            config_sha256: config_sha256(c),
        }
    }

    /// The fields in which `self` (the file's) differs from `expected`, for messages.
    fn differences(&self, expected: &CheckpointIdentity) -> String {
        let mut d = Vec::new();
        let mut cmp = |key: &str, a: &str, b: &str| {
            if a != b {
                d.push(format!("{key} {a:?} (this run: {b:?})"));
            }
        };
        cmp("experiment", &self.experiment, &expected.experiment);
        cmp("method", &self.method, &expected.method);
        cmp("variant", &self.variant, &expected.variant);
        cmp("seed", &self.seed.to_string(), &expected.seed.to_string());
        if self.config_sha256 != expected.config_sha256 {
            d.push("a different config".into());
        }
        d.join(", ")
    }
}

/// SHA-256 (hex) of a resolved domain and config, the config part of a checkpoint's identity.
pub fn config_sha256(c: &RunSettings) -> String {
    let json = serde_json::to_vec(c).expect("RunSettings serializes to JSON");
    hex(&Sha256::digest(json))
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// Why checkpoint bytes were refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CheckpointError {
    /// The file does not start with macdec's checkpoint header.
    #[error("no macdec checkpoint header: written by an older macdec (or not a checkpoint); delete it to restart the run")]
    NoHeader,
    /// A checkpoint format version this build does not read.
    #[error("checkpoint format version {found}, this macdec reads version {VERSION}; delete it to restart the run")]
    Version {
        /// The version in the file.
        found: u32,
    },
    /// The file ends early; holds which part is missing.
    #[error("truncated: {0}")]
    Truncated(&'static str),
    /// Bytes after the payload; holds their count.
    #[error("{0} trailing bytes after the payload")]
    Trailing(u64),
    /// The identity header does not parse; holds why.
    #[error("bad identity header: {0}")]
    Identity(String),
    /// The payload's checksum does not match.
    #[error("payload checksum mismatch (the file is corrupted)")]
    Checksum,
    /// The checkpoint is another run's; holds how the identities differ.
    #[error("belongs to another run: {0}")]
    OtherRun(String),
    /// The payload does not decode into the run's state; holds why.
    #[error("payload does not decode: {0}")]
    Decode(String),
}

/// Encode `trainer` as a checkpoint of the run `identity`.
pub fn encode(identity: &CheckpointIdentity, trainer: &AnyLoop) -> Result<Vec<u8>, String> {
    let header = serde_json::to_vec(identity).map_err(|e| e.to_string())?;
    let payload = bincode::serialize(trainer).map_err(|e| e.to_string())?;
    let mut out = Vec::with_capacity(8 + 4 + 4 + header.len() + 8 + 32 + payload.len());
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.extend_from_slice(&(header.len() as u32).to_le_bytes());
    out.extend_from_slice(&header);
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&Sha256::digest(&payload));
    out.extend_from_slice(&payload);
    Ok(out)
}

/// Split checkpoint bytes into the identity and the verified payload.
pub fn read_header(bytes: &[u8]) -> Result<(CheckpointIdentity, &[u8]), CheckpointError> {
    let mut rest = bytes;
    let mut take = |n: usize, what: &'static str| -> Result<&[u8], CheckpointError> {
        if rest.len() < n {
            return Err(CheckpointError::Truncated(what));
        }
        let (head, tail) = rest.split_at(n);
        rest = tail;
        Ok(head)
    };
    if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
        return Err(CheckpointError::NoHeader);
    }
    take(MAGIC.len(), "magic")?;
    let version = u32::from_le_bytes(take(4, "version")?.try_into().expect("4 bytes"));
    if version != VERSION {
        return Err(CheckpointError::Version { found: version });
    }
    let header_len = u32::from_le_bytes(take(4, "identity length")?.try_into().expect("4 bytes"));
    if header_len as usize > MAX_IDENTITY_BYTES {
        return Err(CheckpointError::Identity(format!(
            "{header_len} bytes, at most {MAX_IDENTITY_BYTES}"
        )));
    }
    let header = take(header_len as usize, "identity")?;
    let identity: CheckpointIdentity =
        serde_json::from_slice(header).map_err(|e| CheckpointError::Identity(e.to_string()))?;
    let payload_len = u64::from_le_bytes(take(8, "payload length")?.try_into().expect("8 bytes"));
    let digest: [u8; 32] = take(32, "checksum")?.try_into().expect("32 bytes");
    let remaining = rest.len() as u64;
    if remaining < payload_len {
        return Err(CheckpointError::Truncated("payload"));
    }
    if remaining > payload_len {
        return Err(CheckpointError::Trailing(remaining - payload_len));
    }
    if Sha256::digest(rest).as_slice() != digest {
        return Err(CheckpointError::Checksum);
    }
    Ok((identity, rest))
}

/// Decode checkpoint bytes, refusing anything that is not exactly a checkpoint of `expected`
/// (or, with `None`, of the run the loop inside says it is: method and seed).
pub fn decode(
    bytes: &[u8],
    expected: Option<&CheckpointIdentity>,
) -> Result<AnyLoop, CheckpointError> {
    let (identity, payload) = read_header(bytes)?;
    if let Some(expected) = expected {
        if &identity != expected {
            return Err(CheckpointError::OtherRun(identity.differences(expected)));
        }
    }
    let trainer: AnyLoop =
        bincode::deserialize(payload).map_err(|e| CheckpointError::Decode(e.to_string()))?;
    // The payload must be the run its header names (a defect otherwise, but cheap to check).
    let inner = CheckpointIdentity {
        method: trainer.method().name().to_string(),
        seed: trainer.seed(),
        ..identity.clone()
    };
    if inner != identity {
        return Err(CheckpointError::OtherRun(format!(
            "the header says {}, the trainer inside differs",
            identity.method
        )));
    }
    Ok(trainer)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algos::value::method::ValueMethod;

    use crate::experiment::run::train_run::run_rngs;

    fn tiny() -> (CheckpointIdentity, AnyLoop) {
        let mut c = RunSettings::paper(
            crate::envs::box_pushing::paper_spec(8),
            Method::Value(ValueMethod::Our1),
        );
        let v = c.config.of_mut::<ValueMethod>().unwrap();
        v.batch_size = 4;
        v.replay_buffer_size = 50;
        let env = c.env.clone();
        let t = AnyLoop::new(
            &c.config,
            Method::Value(ValueMethod::Our1),
            3,
            run_rngs(3),
            || env.build(),
        )
        .unwrap();
        (
            CheckpointIdentity::new("e", Method::Value(ValueMethod::Our1), "", 3, &c),
            t,
        )
    }

    #[test]
    fn a_checkpoint_round_trips_and_any_other_run_is_refused() {
        let (id, t) = tiny();
        let bytes = encode(&id, &t).unwrap();
        let back = decode(&bytes, Some(&id)).unwrap();
        assert_eq!(
            bincode::serialize(&back).unwrap(),
            bincode::serialize(&t).unwrap()
        );
        decode(&bytes, None).unwrap();
        for other in [
            CheckpointIdentity {
                seed: 4,
                ..id.clone()
            },
            CheckpointIdentity {
                experiment: "f".into(),
                ..id.clone()
            },
            CheckpointIdentity {
                variant: "trace_len=5".into(),
                ..id.clone()
            },
            CheckpointIdentity {
                config_sha256: "00".into(),
                ..id.clone()
            },
        ] {
            let e = decode(&bytes, Some(&other)).unwrap_err();
            assert!(matches!(e, CheckpointError::OtherRun(_)), "{e}");
        }
    }

    #[test]
    fn every_single_byte_flip_and_truncation_is_refused() {
        let (id, t) = tiny();
        let bytes = encode(&id, &t).unwrap();
        // Every byte of the header and a spread of payload bytes, each flipped one bit.
        let step = (bytes.len() / 500).max(1);
        let positions: Vec<usize> = (0..200.min(bytes.len()))
            .chain((200..bytes.len()).step_by(step))
            .collect();
        for &i in &positions {
            let mut b = bytes.clone();
            b[i] ^= 0x10;
            assert!(decode(&b, Some(&id)).is_err(), "flip at byte {i} accepted");
        }
        for len in [0, 7, 8, 20, bytes.len() / 2, bytes.len() - 1] {
            assert!(
                decode(&bytes[..len], Some(&id)).is_err(),
                "truncated to {len}"
            );
        }
        let mut longer = bytes.clone();
        longer.extend_from_slice(b"junk");
        assert_eq!(
            decode(&longer, Some(&id)).unwrap_err(),
            CheckpointError::Trailing(4)
        );
    }

    #[test]
    fn the_old_headerless_format_is_refused_with_advice() {
        let (_, t) = tiny();
        let old = bincode::serialize(&t).unwrap();
        let e = decode(&old, None).unwrap_err();
        assert_eq!(e, CheckpointError::NoHeader);
        assert!(e.to_string().contains("older macdec"), "{e}");
        assert!(e.to_string().contains("delete it"), "{e}");
        // Versions 1 (the value-based trainer before the learner seam), 2 (before the
        // undiscounted return), 3 (before the one list of families) and 4 (before ACAC's
        // Overcooked), 5 (before ACAC's Large kitchen), 6 (before the actor-critic learners
        // counted completed episodes' steps), and any future version.
        for found in [1, 2, 3, 4, 5, 6, 8] {
            let mut other = encode(&tiny().0, &t).unwrap();
            other[8] = found as u8;
            assert_eq!(
                decode(&other, None).unwrap_err(),
                CheckpointError::Version { found }
            );
        }
    }
}
