//! A run's trained nets in a form that outlives the trainer (issue 11): `<run>/policy/` holds
//! one safetensors file per net, with the reference's PyTorch state_dict names
//! (`dec_agent_0.safetensors`, ..., `cen.safetensors`), and `policy.json` naming the run, its
//! domain, its resolved config, how far it trained and which nets the paper evaluates.
//!
//! `checkpoint.bin` (the whole trainer) is for resuming only; `export` and `render` read these
//! files, so a run stays usable after the trainer's serialized form changes. This module knows
//! no learner: it takes and returns plain nets.
//!
//! Compatibility: readers ignore keys they do not know, and keys added later are optional (serde
//! defaults), so a newer macdec reads older policy files and an older one reads newer files of
//! the same `format_version`. The version is bumped only for a change an older reader would
//! misread; a reader refuses versions newer than [`FORMAT_VERSION`].
//!
//! ```json
//! {"format": "macdec-run-policy", "format_version": 1,
//!  "experiment": "fig4a", "method": "our1", "variant": "", "seed": 3, "episodes_trained": 15000,
//!  "env": {"env": "box-pushing", "grid": 10, "horizon": 100}, "discount": 0.98,
//!  "evaluated": "dec", "config": {...},
//!  "nets": [{"role": "dec", "agent": 0, "file": "dec_agent_0.safetensors", "sha256": "9f86...",
//!            "sizes": {"input": 5, "mlp": 32, "hidden": 32, "output": 8}}, ...]}
//! ```

use crate::envs::EnvSpec;
use crate::files::atomic::{remove_stale_temp_files, write_atomic};
use crate::files::bounded_read::read_regular_file;
use crate::nn::safetensors_io::{from_safetensors_bytes, to_safetensors_bytes, WeightsError};
use crate::nn::{QNet, QNetConfig};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// The policy directory inside a run directory.
pub use crate::experiment::results_tree::POLICY_DIR;
/// The description file inside [`POLICY_DIR`].
pub const POLICY_FILE: &str = "policy.json";
/// The `format` tag of [`POLICY_FILE`].
pub const FORMAT: &str = "macdec-run-policy";
/// The newest `format_version` this build reads, and the one it writes.
pub const FORMAT_VERSION: u32 = 1;

/// Largest `policy.json` read (it is a few kilobytes).
const MAX_JSON_BYTES: u64 = 16 << 20;
/// Largest weight file read (a net of the largest allowed width is well below this).
const MAX_NET_BYTES: u64 = 1 << 31;

/// Which of the run's nets a file holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum NetRole {
    /// One agent's decentralized Q-net (input: its own macro-observation).
    Dec,
    /// The centralized Q-net (input: the joint macro-observation).
    Cen,
}

/// Who trained the nets: the run's identity, how far it got, and what it was trained on.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunPolicyInfo {
    pub experiment: String,
    /// The method's name as in configs (`our1`, `cen-ddrqn`, ...).
    pub method: String,
    pub variant: String,
    pub seed: u64,
    /// Training episodes completed when the files were written.
    pub episodes_trained: u64,
    /// The domain and its parameters.
    pub env: EnvSpec,
    /// Discount per primitive step of the evaluation return (quirks Q5, Q13).
    pub discount: f64,
    /// The nets the paper evaluates for this method (spec 7.1): the decentralized ones, or the
    /// centralized one for Cen-DDRQN.
    pub evaluated: NetRole,
    /// The run's resolved config, kept as JSON so reading these files never depends on the
    /// config type of the build that trained them.
    pub config: serde_json::Value,
}

/// One net's file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NetEntry {
    pub role: NetRole,
    /// The agent of a decentralized net.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub agent: Option<usize>,
    /// File name inside the policy directory.
    pub file: String,
    /// Lowercase hex SHA-256 of the file.
    pub sha256: String,
    /// Layer sizes of the net.
    pub sizes: QNetConfig,
}

/// `policy.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PolicyDescription {
    /// Always [`FORMAT`].
    pub format: String,
    /// [`FORMAT_VERSION`] when written by this build.
    pub format_version: u32,
    #[serde(flatten)]
    pub run: RunPolicyInfo,
    /// Decentralized nets in agent order, then the centralized net.
    pub nets: Vec<NetEntry>,
}

/// A run's nets as read back, checked.
#[derive(Debug, Clone, PartialEq)]
pub struct RunPolicy {
    pub run: RunPolicyInfo,
    /// Agent i's decentralized net is `dec[i]` (empty for Cen-DDRQN).
    pub dec: Vec<QNet>,
    /// The centralized net, if the method has one.
    pub cen: Option<QNet>,
}

/// Why a run's policy files could not be written or read. Messages name the file.
#[derive(Debug, thiserror::Error)]
pub enum PolicyFilesError {
    #[error("{dir}: the run has no {POLICY_DIR}/{POLICY_FILE} (it was trained by a macdec from before policy files, or has not reached its first checkpoint); rerun its `macdec train` command with a build that writes them")]
    Missing { dir: PathBuf },
    #[error("{path}: {message}")]
    Io { path: PathBuf, message: String },
    #[error("{path}: not a valid policy description: {message}")]
    Parse { path: PathBuf, message: String },
    #[error("{path}: format is `{found}`, expected `{FORMAT}`")]
    Format { path: PathBuf, found: String },
    #[error("{path}: format_version {found} is newer than this build reads ({FORMAT_VERSION}); use a newer macdec")]
    Version { path: PathBuf, found: u32 },
    #[error("{path}: {message}")]
    Invalid { path: PathBuf, message: String },
    #[error("{path}: SHA-256 {found} does not match policy.json's {expected} (corrupt or replaced file)")]
    Checksum {
        path: PathBuf,
        expected: String,
        found: String,
    },
    #[error(transparent)]
    Weights(#[from] WeightsError),
}

fn io_err(path: &Path, e: impl std::fmt::Display) -> PolicyFilesError {
    PolicyFilesError::Io {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// The file name of agent `agent`'s decentralized net.
pub fn dec_file_name(agent: usize) -> String {
    format!("dec_agent_{agent}.safetensors")
}

/// The file name of the centralized net.
pub const CEN_FILE: &str = "cen.safetensors";

/// Write `run_dir/policy/`: every net's file, then `policy.json` last, each atomically, so a
/// reader sees complete files and a description whose checksums tell whether the files beside it
/// are the ones it describes.
pub fn write_policy_files(
    run_dir: &Path,
    run: RunPolicyInfo,
    dec: &[&QNet],
    cen: Option<&QNet>,
) -> Result<PolicyDescription, PolicyFilesError> {
    let dir = run_dir.join(POLICY_DIR);
    std::fs::create_dir_all(&dir).map_err(|e| io_err(&dir, e))?;
    remove_stale_temp_files(&dir).map_err(|e| io_err(&dir, e))?;
    let named = dec
        .iter()
        .enumerate()
        .map(|(i, n)| (NetRole::Dec, Some(i), dec_file_name(i), *n))
        .chain(cen.map(|n| (NetRole::Cen, None, CEN_FILE.to_string(), n)));
    let mut nets = Vec::new();
    for (role, agent, file, net) in named {
        let bytes = to_safetensors_bytes(&net.params);
        let path = dir.join(&file);
        write_atomic(&path, &bytes).map_err(|e| io_err(&path, e))?;
        nets.push(NetEntry {
            role,
            agent,
            file,
            sha256: sha256_hex(&bytes),
            sizes: net.config(),
        });
    }
    let description = PolicyDescription {
        format: FORMAT.to_string(),
        format_version: FORMAT_VERSION,
        run,
        nets,
    };
    let path = dir.join(POLICY_FILE);
    let text = serde_json::to_string_pretty(&description).map_err(|e| io_err(&path, e))?;
    write_atomic(&path, text.as_bytes()).map_err(|e| io_err(&path, e))?;
    Ok(description)
}

/// Read and check `run_dir/policy/policy.json` (not the weight files).
pub fn read_description(run_dir: &Path) -> Result<PolicyDescription, PolicyFilesError> {
    let path = run_dir.join(POLICY_DIR).join(POLICY_FILE);
    if !path.exists() {
        return Err(PolicyFilesError::Missing {
            dir: run_dir.to_path_buf(),
        });
    }
    let bytes = read_regular_file(&path, MAX_JSON_BYTES).map_err(|e| io_err(&path, e))?;
    let parse = |message: String| PolicyFilesError::Parse {
        path: path.clone(),
        message,
    };
    let value: serde_json::Value =
        serde_json::from_slice(&bytes).map_err(|e| parse(e.to_string()))?;
    // Format and version first, so a future layout is named as such, not as a parse error.
    let found = value.get("format").and_then(|v| v.as_str()).unwrap_or("");
    if found != FORMAT {
        return Err(PolicyFilesError::Format {
            path,
            found: found.to_string(),
        });
    }
    match value.get("format_version").and_then(|v| v.as_u64()) {
        Some(v) if v <= FORMAT_VERSION as u64 => {}
        Some(v) => {
            return Err(PolicyFilesError::Version {
                path,
                found: u32::try_from(v).unwrap_or(u32::MAX),
            })
        }
        None => return Err(parse("`format_version` is missing or not a number".into())),
    }
    let d: PolicyDescription = serde_json::from_value(value).map_err(|e| parse(e.to_string()))?;
    d.validate(&path)?;
    Ok(d)
}

impl PolicyDescription {
    /// Structure: plain, distinct file names; decentralized nets listed for agents 0, 1, ... in
    /// order; at most one centralized net; the evaluated nets present.
    fn validate(&self, path: &Path) -> Result<(), PolicyFilesError> {
        let invalid = |message: String| PolicyFilesError::Invalid {
            path: path.to_path_buf(),
            message,
        };
        let mut seen = std::collections::BTreeSet::new();
        let (mut n_dec, mut n_cen) = (0, 0);
        for (i, net) in self.nets.iter().enumerate() {
            let plain = Path::new(&net.file)
                .file_name()
                .is_some_and(|f| f == net.file.as_str());
            if !plain || net.file.starts_with('.') {
                return Err(invalid(format!(
                    "nets[{i}].file `{}` must be a plain file name inside the policy directory",
                    net.file
                )));
            }
            if !seen.insert(net.file.as_str()) {
                return Err(invalid(format!("two nets share the file `{}`", net.file)));
            }
            match (net.role, net.agent) {
                (NetRole::Dec, Some(a)) if a == n_dec && n_cen == 0 => n_dec += 1,
                (NetRole::Dec, _) => {
                    return Err(invalid(format!(
                    "nets[{i}]: decentralized nets must come first, for agents 0, 1, ... in order"
                )))
                }
                (NetRole::Cen, None) if n_cen == 0 => n_cen += 1,
                (NetRole::Cen, _) => {
                    return Err(invalid(format!(
                        "nets[{i}]: at most one centralized net, without an agent"
                    )))
                }
            }
        }
        let evaluated_present = match self.run.evaluated {
            NetRole::Dec => n_dec > 0,
            NetRole::Cen => n_cen > 0,
        };
        if !evaluated_present {
            return Err(invalid(format!(
                "`evaluated` is {:?} but no such net is listed",
                self.run.evaluated
            )));
        }
        Ok(())
    }

    /// The bytes of `entry`'s file, checked against its checksum and parsed by nn's loader
    /// (every tensor present, F32, of the listed sizes, nothing else).
    pub fn load_net(&self, run_dir: &Path, entry: &NetEntry) -> Result<QNet, PolicyFilesError> {
        let path = run_dir.join(POLICY_DIR).join(&entry.file);
        let bytes = read_regular_file(&path, MAX_NET_BYTES).map_err(|e| io_err(&path, e))?;
        let found = sha256_hex(&bytes);
        if found != entry.sha256 {
            return Err(PolicyFilesError::Checksum {
                path,
                expected: entry.sha256.clone(),
                found,
            });
        }
        Ok(QNet {
            params: from_safetensors_bytes(&bytes, entry.sizes, &path)?,
        })
    }
}

/// Read a run's policy files: the description and every net, each checked.
pub fn read_policy_files(run_dir: &Path) -> Result<RunPolicy, PolicyFilesError> {
    let d = read_description(run_dir)?;
    let mut dec = Vec::new();
    let mut cen = None;
    for entry in &d.nets {
        let net = d.load_net(run_dir, entry)?;
        match entry.role {
            NetRole::Dec => dec.push(net),
            NetRole::Cen => cen = Some(net),
        }
    }
    Ok(RunPolicy {
        run: d.run,
        dec,
        cen,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    fn info(evaluated: NetRole) -> RunPolicyInfo {
        RunPolicyInfo {
            experiment: "t".into(),
            method: "our1".into(),
            variant: String::new(),
            seed: 7,
            episodes_trained: 40,
            env: crate::envs::box_pushing::spec(8, 20),
            discount: 0.98,
            evaluated,
            config: serde_json::json!({"lr": 0.001}),
        }
    }

    fn nets() -> (Vec<QNet>, QNet) {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let cfg = |input, output| QNetConfig {
            input,
            mlp: 6,
            hidden: 5,
            output,
        };
        let dec = (0..2).map(|_| QNet::new(cfg(5, 8), &mut rng)).collect();
        (dec, QNet::new(cfg(10, 64), &mut rng))
    }

    #[test]
    fn written_files_read_back_as_the_same_nets() {
        let dir = tempfile::tempdir().unwrap();
        let (dec, cen) = nets();
        let refs: Vec<&QNet> = dec.iter().collect();
        write_policy_files(dir.path(), info(NetRole::Dec), &refs, Some(&cen)).unwrap();
        let p = dir.path().join(POLICY_DIR);
        for f in [
            "dec_agent_0.safetensors",
            "dec_agent_1.safetensors",
            CEN_FILE,
            POLICY_FILE,
        ] {
            assert!(p.join(f).is_file(), "{f}");
        }
        let back = read_policy_files(dir.path()).unwrap();
        assert_eq!(back.dec, dec);
        assert_eq!(back.cen, Some(cen));
        assert_eq!(back.run, info(NetRole::Dec));
    }

    #[test]
    fn a_changed_weight_file_or_a_newer_version_is_refused_by_name() {
        let dir = tempfile::tempdir().unwrap();
        let (dec, _) = nets();
        let refs: Vec<&QNet> = dec.iter().collect();
        write_policy_files(dir.path(), info(NetRole::Dec), &refs, None).unwrap();
        let p = dir.path().join(POLICY_DIR);
        std::fs::copy(p.join(dec_file_name(0)), p.join(dec_file_name(1))).unwrap();
        let err = read_policy_files(dir.path()).unwrap_err().to_string();
        assert!(
            err.contains("dec_agent_1.safetensors") && err.contains("SHA-256"),
            "{err}"
        );

        let json = p.join(POLICY_FILE);
        let text = std::fs::read_to_string(&json).unwrap();
        std::fs::write(
            &json,
            text.replace("\"format_version\": 1", "\"format_version\": 9"),
        )
        .unwrap();
        let err = read_description(dir.path()).unwrap_err().to_string();
        assert!(err.contains("format_version 9"), "{err}");
        std::fs::write(
            &json,
            text.replace("dec_agent_1.safetensors", "../x.safetensors"),
        )
        .unwrap();
        let err = read_description(dir.path()).unwrap_err().to_string();
        assert!(err.contains("plain file name"), "{err}");
    }

    /// Older files lack keys added later and newer files carry keys this build does not know:
    /// both read.
    #[test]
    fn unknown_keys_are_ignored_and_later_keys_are_optional() {
        let dir = tempfile::tempdir().unwrap();
        let (_, cen) = nets();
        write_policy_files(dir.path(), info(NetRole::Cen), &[], Some(&cen)).unwrap();
        let json = dir.path().join(POLICY_DIR).join(POLICY_FILE);
        let mut v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        v["a_key_from_the_future"] = serde_json::json!([1, 2]);
        v["nets"][0]["another"] = serde_json::json!("x");
        std::fs::write(&json, v.to_string()).unwrap();
        let back = read_policy_files(dir.path()).unwrap();
        assert_eq!(back.cen, Some(cen));
        assert!(back.dec.is_empty());
    }

    #[test]
    fn a_run_without_policy_files_gets_an_error_saying_so() {
        let dir = tempfile::tempdir().unwrap();
        let err = read_policy_files(dir.path()).unwrap_err().to_string();
        assert!(err.contains("has no policy/policy.json"), "{err}");
    }
}
