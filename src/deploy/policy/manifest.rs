//! An exported policy directory: one safetensors file per agent and `manifest.json` describing
//! them (issue 7). The manifest names the domain and its parameters, each agent's index,
//! observation layout and macro-action names, the architecture and sizes, the run's config and
//! seed, and a SHA-256 of every weight file. Loading checks all of it against the domain and the
//! files, so a robot never runs weights that are corrupt, truncated, swapped between agents or
//! exported for another domain.
//!
//! ```json
//! {"format": "macdec-policy", "format_version": 1,
//!  "env": {"env": "box-pushing", "grid": 10, "horizon": 100}, "discount": 0.98,
//!  "architecture": {"kind": "ddrqn", "mlp_layer_size": 32, "rnn_h_size": 32, "leaky_relu_slope": 0.01},
//!  "run": {"experiment": "fig4a", "method": "our1", "variant": "", "seed": 3,
//!          "episodes_trained": 15000, "config": {...}},
//!  "agents": [{"index": 0, "weights": "agent-0.safetensors", "sha256": "9f86...",
//!              "obs_size": 5, "obs_names": [...], "n_actions": 8, "action_names": [...]}, ...]}
//! ```
//!
//! A policy of a domain defined outside this binary names it as
//! `"env": {"env": "custom", "name": "rendezvous", "horizon": 20}`; its layout is then checked
//! only for consistency (there is no domain here to compare it with). Built-in domains are written
//! exactly as before, so `format_version` stays 1: an older build reading a custom manifest
//! refuses it (unknown variant `custom`) rather than misreading it.

use crate::deploy::architecture::LEAKY_RELU_SLOPE;
use crate::deploy::architecture::{Architecture, WeightsError};
use crate::deploy::policy_env::{CustomEnv, PolicyEnv};
use crate::envs::{EnvSpec, MacroEnv};
use crate::experiment::limits::MAX_NET_WIDTH;
use crate::files::atomic::write_atomic;
use crate::files::bounded_read::read_regular_file;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// The manifest's file name inside a policy directory.
pub const MANIFEST_FILE: &str = "manifest.json";
/// The `format` tag every manifest carries.
pub const FORMAT: &str = "macdec-policy";
/// The manifest layout this version reads and writes (unchanged by custom domains, see above).
pub const FORMAT_VERSION: u32 = 1;

/// `manifest.json`: everything a robot needs besides its weights.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// Always [`FORMAT`].
    pub format: String,
    /// [`FORMAT_VERSION`] when written by this version.
    pub format_version: u32,
    /// The domain: a built-in one and its parameters, as in configs and replay files, or a
    /// custom one (`{"env": "custom", "name": ..., "horizon": ...}`) whose layout only the agent
    /// entries record (see [`PolicyEnv`]).
    pub env: PolicyEnv,
    /// Discount per primitive step of the reported (evaluation) return (quirks Q5, Q13).
    pub discount: f64,
    /// Layer sizes shared by every agent's net.
    pub architecture: Architecture,
    /// Which run the policy comes from.
    pub run: RunInfo,
    /// One entry per agent, in agent order.
    pub agents: Vec<AgentEntry>,
}

/// Where an exported policy came from: the run's experiment, method, variant and seed, how far it
/// trained, and its resolved config (kept as JSON, so loading a policy does not depend on the
/// config types of the version that trained it).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunInfo {
    pub experiment: String,
    pub method: String,
    pub variant: String,
    pub seed: u64,
    /// Training episodes completed when the checkpoint was taken.
    pub episodes_trained: u64,
    /// The run's `RunConfig` (every hyperparameter).
    pub config: serde_json::Value,
}

/// One agent's part of the policy.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AgentEntry {
    /// The agent's index in the domain (equals its position in `agents`).
    pub index: usize,
    /// File name of its weights inside the policy directory (no directories).
    pub weights: String,
    /// Lowercase hex SHA-256 of the weight file.
    pub sha256: String,
    /// Length of its macro-observation.
    pub obs_size: usize,
    /// Name of each observation element, in layout order.
    pub obs_names: Vec<String>,
    /// Number of its macro-actions.
    pub n_actions: usize,
    /// Name of each macro-action, by index.
    pub action_names: Vec<String>,
}

/// One agent's weight file, read once and checked against its checksum and the architecture;
/// build the net from these bytes (not from a second read of the file).
#[derive(Debug, Clone, PartialEq)]
pub struct VerifiedAgent {
    pub index: usize,
    pub weights: Vec<u8>,
}

/// Why a policy directory could not be written or loaded. Messages name the file or field and
/// what was expected.
#[derive(Debug, thiserror::Error)]
pub enum ManifestError {
    #[error("{path}: {message}")]
    Io { path: PathBuf, message: String },
    #[error("{path}: not a valid manifest: {message}")]
    Parse { path: PathBuf, message: String },
    #[error("manifest format is `{found}`, expected `{FORMAT}`")]
    Format { found: String },
    #[error(
        "manifest format_version {found} is not supported (this version reads {FORMAT_VERSION})"
    )]
    Version { found: u32 },
    #[error("manifest `{key}`: {reason}")]
    InvalidValue { key: &'static str, reason: String },
    #[error("manifest environment cannot be built: {0}")]
    Env(String),
    #[error("manifest lists {got} agents, the {env} domain has {expected}")]
    AgentCount {
        env: &'static str,
        expected: usize,
        got: usize,
    },
    #[error(
        "manifest agents[{position}] has index {index}; agents must be listed in order 0, 1, ..."
    )]
    AgentIndex { position: usize, index: usize },
    #[error("agent {agent}: `{field}` is {got}, the domain has {expected}")]
    Layout {
        agent: usize,
        field: &'static str,
        expected: String,
        got: String,
    },
    #[error("agent {agent}: weights file name `{name}` must be a plain file name inside the policy directory")]
    WeightsName { agent: usize, name: String },
    #[error("agents {first} and {second} share the weights file `{name}`")]
    SharedWeights {
        first: usize,
        second: usize,
        name: String,
    },
    #[error("agent {agent}: sha256 `{value}` is not 64 lowercase hex digits")]
    ChecksumText { agent: usize, value: String },
    #[error("{path}: SHA-256 is {got}, the manifest says {expected}; the file is corrupt or from another export")]
    Checksum {
        path: PathBuf,
        expected: String,
        got: String,
    },
    #[error("{path}: does not match the manifest's architecture: {source}")]
    Weights {
        path: PathBuf,
        #[source]
        source: WeightsError,
    },
    #[error("agent {agent} is out of range: the policy has agents 0..{n_agents}")]
    AgentOutOfRange { agent: usize, n_agents: usize },
    #[error("weights do not load into the Q-net: {0}")]
    Net(String),
    #[error("expected one weight file per agent ({expected}), got {got}")]
    WeightsCount { expected: usize, got: usize },
}

/// Lowercase hex SHA-256 of `bytes`.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// Largest manifest.json read (a manifest is a few kilobytes).
const MAX_MANIFEST_BYTES: u64 = 1 << 20;
/// Room for a weight file's JSON header beyond its tensor data.
const MAX_SAFETENSORS_HEADER_BYTES: u64 = 1 << 16;

fn io_err(path: &Path, e: impl std::fmt::Display) -> ManifestError {
    ManifestError::Io {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// The weight file name of agent `agent` in an export.
pub fn weights_file_name(agent: usize) -> String {
    format!("agent-{agent}.safetensors")
}

impl Manifest {
    /// The manifest of an export: each agent's weights (`weights[i]`, a safetensors file checked
    /// against `architecture`) named `agent-<i>.safetensors`, with their checksums and the
    /// domain's layout. Nothing is written.
    pub fn build(
        env: EnvSpec,
        discount: f64,
        architecture: Architecture,
        run: RunInfo,
        weights: &[Vec<u8>],
    ) -> Result<Manifest, ManifestError> {
        let built = env.build().map_err(|e| ManifestError::Env(e.to_string()))?;
        Manifest::build_for(env.into(), &built, discount, architecture, run, weights)
    }

    /// [`Self::build`] for any domain: the layout (observation sizes and names, macro-action
    /// names) is read from `domain` through its [`MacroEnv`] methods, and `env` says which domain
    /// the manifest names. A built-in `env` is still checked against its own layout.
    pub fn build_for(
        env: PolicyEnv,
        domain: &impl MacroEnv,
        discount: f64,
        architecture: Architecture,
        run: RunInfo,
        weights: &[Vec<u8>],
    ) -> Result<Manifest, ManifestError> {
        if weights.len() != domain.n_agents() {
            return Err(ManifestError::WeightsCount {
                expected: domain.n_agents(),
                got: weights.len(),
            });
        }
        let mut agents = Vec::with_capacity(weights.len());
        for (index, bytes) in weights.iter().enumerate() {
            let name = weights_file_name(index);
            let (obs_size, n_actions) = (domain.obs_sizes()[index], domain.n_actions()[index]);
            architecture
                .check_weights(bytes, obs_size, n_actions)
                .map_err(|source| ManifestError::Weights {
                    path: PathBuf::from(&name),
                    source,
                })?;
            agents.push(AgentEntry {
                index,
                weights: name,
                sha256: sha256_hex(bytes),
                obs_size,
                obs_names: domain.obs_names(index),
                n_actions,
                action_names: domain
                    .action_names(index)
                    .iter()
                    .map(|s| s.to_string())
                    .collect(),
            });
        }
        let manifest = Manifest {
            format: FORMAT.to_string(),
            format_version: FORMAT_VERSION,
            env,
            discount,
            architecture,
            run,
            agents,
        };
        manifest.validate()?;
        Ok(manifest)
    }

    /// Write a policy directory: the weight files of [`Self::build`], then `manifest.json`.
    /// Every file is written atomically, the manifest last, so a reader never sees a manifest
    /// without its weights.
    pub fn write_policy(
        dir: &Path,
        env: EnvSpec,
        discount: f64,
        architecture: Architecture,
        run: RunInfo,
        weights: &[Vec<u8>],
    ) -> Result<Manifest, ManifestError> {
        let manifest = Manifest::build(env, discount, architecture, run, weights)?;
        manifest.write(dir, weights)?;
        Ok(manifest)
    }

    /// Write a policy directory of [`Self::build_for`]: any domain, custom ones included.
    pub fn write_policy_for(
        dir: &Path,
        env: PolicyEnv,
        domain: &impl MacroEnv,
        discount: f64,
        architecture: Architecture,
        run: RunInfo,
        weights: &[Vec<u8>],
    ) -> Result<Manifest, ManifestError> {
        let manifest = Manifest::build_for(env, domain, discount, architecture, run, weights)?;
        manifest.write(dir, weights)?;
        Ok(manifest)
    }

    /// Write `weights` (in agent order) under this manifest's file names, then the manifest.
    fn write(&self, dir: &Path, weights: &[Vec<u8>]) -> Result<(), ManifestError> {
        for (entry, bytes) in self.agents.iter().zip(weights) {
            let path = dir.join(&entry.weights);
            write_atomic(&path, bytes).map_err(|e| io_err(&path, e))?;
        }
        let path = dir.join(MANIFEST_FILE);
        let text = serde_json::to_string_pretty(self).map_err(|e| io_err(&path, e))?;
        write_atomic(&path, text.as_bytes()).map_err(|e| io_err(&path, e))
    }

    /// Read and validate `dir/manifest.json` (structure and layout; weight files are checked by
    /// [`Self::verify_agent`]).
    pub fn read(dir: &Path) -> Result<Manifest, ManifestError> {
        let path = dir.join(MANIFEST_FILE);
        let bytes = read_regular_file(&path, MAX_MANIFEST_BYTES).map_err(|e| io_err(&path, e))?;
        let text = String::from_utf8(bytes).map_err(|e| io_err(&path, e))?;
        let manifest: Manifest = serde_json::from_str(&text).map_err(|e| ManifestError::Parse {
            path: path.clone(),
            message: e.to_string(),
        })?;
        manifest.validate()?;
        Ok(manifest)
    }

    /// Check the manifest against itself and its domain: format and version, sizes, agent order,
    /// each agent's observation and action layout equal to the domain's (a custom domain's only
    /// consistent with itself), safe file names, and well-formed checksums.
    pub fn validate(&self) -> Result<(), ManifestError> {
        if self.format != FORMAT {
            return Err(ManifestError::Format {
                found: self.format.clone(),
            });
        }
        if self.format_version != FORMAT_VERSION {
            return Err(ManifestError::Version {
                found: self.format_version,
            });
        }
        if !(self.discount > 0.0 && self.discount <= 1.0) {
            return Err(ManifestError::InvalidValue {
                key: "discount",
                reason: format!("must be in (0, 1], got {}", self.discount),
            });
        }
        if self.architecture.leaky_relu_slope != LEAKY_RELU_SLOPE {
            return Err(ManifestError::InvalidValue {
                key: "architecture.leaky_relu_slope",
                reason: format!(
                    "the nets here use {LEAKY_RELU_SLOPE}, the manifest says {}",
                    self.architecture.leaky_relu_slope
                ),
            });
        }
        for (key, value) in [
            (
                "architecture.mlp_layer_size",
                self.architecture.mlp_layer_size,
            ),
            ("architecture.rnn_h_size", self.architecture.rnn_h_size),
        ] {
            if value == 0 || value > MAX_NET_WIDTH {
                return Err(ManifestError::InvalidValue {
                    key,
                    reason: format!("must be in 1..={MAX_NET_WIDTH}, got {value}"),
                });
            }
        }
        match &self.env {
            PolicyEnv::BuiltIn(spec) => self.check_layout_against(spec)?,
            PolicyEnv::Custom(custom) => self.check_custom_layout(custom)?,
        }
        for (position, a) in self.agents.iter().enumerate() {
            if !is_plain_file_name(&a.weights) {
                return Err(ManifestError::WeightsName {
                    agent: position,
                    name: a.weights.clone(),
                });
            }
            if let Some(first) = self.agents[..position]
                .iter()
                .position(|b| b.weights == a.weights)
            {
                return Err(ManifestError::SharedWeights {
                    first,
                    second: position,
                    name: a.weights.clone(),
                });
            }
            let hex = |c: char| c.is_ascii_digit() || ('a'..='f').contains(&c);
            if a.sha256.len() != 64 || !a.sha256.chars().all(hex) {
                return Err(ManifestError::ChecksumText {
                    agent: position,
                    value: a.sha256.clone(),
                });
            }
        }
        Ok(())
    }

    /// A built-in domain's agents must be listed in order with exactly its layout.
    fn check_layout_against(&self, spec: &EnvSpec) -> Result<(), ManifestError> {
        let env = spec
            .build()
            .map_err(|e| ManifestError::Env(e.to_string()))?;
        if self.agents.len() != env.n_agents() {
            return Err(ManifestError::AgentCount {
                env: spec.name(),
                expected: env.n_agents(),
                got: self.agents.len(),
            });
        }
        for (position, a) in self.agents.iter().enumerate() {
            if a.index != position {
                return Err(ManifestError::AgentIndex {
                    position,
                    index: a.index,
                });
            }
            let layout = |field, expected: String, got: String| {
                if expected == got {
                    Ok(())
                } else {
                    Err(ManifestError::Layout {
                        agent: position,
                        field,
                        expected,
                        got,
                    })
                }
            };
            layout(
                "obs_size",
                env.obs_sizes()[position].to_string(),
                a.obs_size.to_string(),
            )?;
            layout(
                "obs_names",
                format!("{:?}", env.obs_names(position)),
                format!("{:?}", a.obs_names),
            )?;
            layout(
                "n_actions",
                env.n_actions()[position].to_string(),
                a.n_actions.to_string(),
            )?;
            layout(
                "action_names",
                format!("{:?}", env.action_names(position)),
                format!("{:?}", a.action_names),
            )?;
        }
        Ok(())
    }

    /// A custom domain is not here to compare with: its agent entries must be consistent among
    /// themselves (in order, at least one observation element and one macro-action, one name
    /// for each).
    fn check_custom_layout(&self, custom: &CustomEnv) -> Result<(), ManifestError> {
        custom
            .validate()
            .map_err(|(key, reason)| ManifestError::InvalidValue { key, reason })?;
        if self.agents.is_empty() {
            return Err(ManifestError::InvalidValue {
                key: "agents",
                reason: format!("the custom domain `{}` lists no agents", custom.name),
            });
        }
        for (position, a) in self.agents.iter().enumerate() {
            if a.index != position {
                return Err(ManifestError::AgentIndex {
                    position,
                    index: a.index,
                });
            }
            for (field, size, names) in [
                ("obs_names", a.obs_size, a.obs_names.len()),
                ("action_names", a.n_actions, a.action_names.len()),
            ] {
                if size == 0 || names != size {
                    return Err(ManifestError::Layout {
                        agent: position,
                        field,
                        expected: format!("{size} name(s), one per element (and at least one)"),
                        got: format!("{names} name(s)"),
                    });
                }
            }
        }
        Ok(())
    }

    /// Read agent `agent`'s weight file from `dir`, check its SHA-256 and its tensors against the
    /// architecture, and return the verified bytes. A robot needs only its own file.
    pub fn verify_agent(&self, dir: &Path, agent: usize) -> Result<VerifiedAgent, ManifestError> {
        let entry = self
            .agents
            .get(agent)
            .ok_or(ManifestError::AgentOutOfRange {
                agent,
                n_agents: self.agents.len(),
            })?;
        let path = dir.join(&entry.weights);
        // Refuse a FIFO, a device or an oversized file before reading it: the architecture says
        // how big the file can be.
        // Saturating: a hand-edited layout cannot overflow the bound, only make it unreachable.
        let floats = self
            .architecture
            .tensors(entry.obs_size, entry.n_actions)
            .iter()
            .map(|(_, shape)| shape.iter().fold(1u64, |n, &d| n.saturating_mul(d as u64)))
            .fold(0u64, u64::saturating_add);
        let max = floats
            .saturating_mul(4)
            .saturating_add(MAX_SAFETENSORS_HEADER_BYTES);
        let bytes = read_regular_file(&path, max).map_err(|e| io_err(&path, e))?;
        let got = sha256_hex(&bytes);
        if got != entry.sha256 {
            return Err(ManifestError::Checksum {
                path,
                expected: entry.sha256.clone(),
                got,
            });
        }
        self.architecture
            .check_weights(&bytes, entry.obs_size, entry.n_actions)
            .map_err(|source| ManifestError::Weights { path, source })?;
        Ok(VerifiedAgent {
            index: agent,
            weights: bytes,
        })
    }

    /// The names of agent `agent`'s macro-actions. Panics if `agent` is out of range (the
    /// manifest was validated against the agent count).
    pub fn action_names(&self, agent: usize) -> &[String] {
        &self.agents[agent].action_names
    }
}

/// Load the manifest and one agent's verified weights: what `macdec robot --agent I` needs.
pub fn load_agent(dir: &Path, agent: usize) -> Result<(Manifest, VerifiedAgent), ManifestError> {
    let manifest = Manifest::read(dir)?;
    let verified = manifest.verify_agent(dir, agent)?;
    Ok((manifest, verified))
}

/// Load the manifest and every agent's verified weights.
pub fn load_all(dir: &Path) -> Result<(Manifest, Vec<VerifiedAgent>), ManifestError> {
    let manifest = Manifest::read(dir)?;
    let verified = (0..manifest.agents.len())
        .map(|i| manifest.verify_agent(dir, i))
        .collect::<Result<Vec<_>, _>>()?;
    Ok((manifest, verified))
}

/// A name that stays inside the policy directory: no separators, not empty, not `.`/`..`, no
/// leading dot (hidden and temp files).
fn is_plain_file_name(name: &str) -> bool {
    !name.is_empty()
        && !name.starts_with('.')
        && !name.contains(['/', '\\', '\0'])
        && Path::new(name).file_name() == Some(std::ffi::OsStr::new(name))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::deploy::architecture::synthetic_weights;

    fn bp10() -> EnvSpec {
        crate::envs::box_pushing::spec(10, 100)
    }

    fn run_info() -> RunInfo {
        RunInfo {
            experiment: "test".into(),
            method: "our1".into(),
            variant: String::new(),
            seed: 7,
            episodes_trained: 100,
            config: serde_json::json!({"discount": 0.98, "dec_mlp_layer_size": 32}),
        }
    }

    /// A Box Pushing 10x10 export with M = 8, H = 4 and agent-specific weights.
    fn export(dir: &Path) -> Manifest {
        let arch = Architecture::ddrqn(8, 4);
        let weights: Vec<Vec<u8>> = (0..2)
            .map(|a| synthetic_weights(&arch, 5, 8, |_, i| (i + 100 * a) as f32 * 0.01))
            .collect();
        Manifest::write_policy(dir, bp10(), 0.98, arch, run_info(), &weights).unwrap()
    }

    fn rewrite_manifest(dir: &Path, edit: impl FnOnce(&mut serde_json::Value)) {
        let path = dir.join(MANIFEST_FILE);
        let mut v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        edit(&mut v);
        std::fs::write(&path, serde_json::to_string(&v).unwrap()).unwrap();
    }

    #[test]
    fn sha256_matches_the_standard_test_vector() {
        assert_eq!(
            sha256_hex(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }

    #[test]
    fn written_policy_reads_back_and_verifies_every_agent() {
        let dir = tempfile::tempdir().unwrap();
        let written = export(dir.path());
        let (read, agents) = load_all(dir.path()).unwrap();
        assert_eq!(read, written);
        assert_eq!(agents.len(), 2);
        assert_eq!(read.agents[1].weights, "agent-1.safetensors");
        assert_eq!(read.agents[0].action_names.len(), 8);
        assert_eq!(read.agents[0].obs_names.len(), 5);
        assert_eq!(read.run.seed, 7);
        let on_disk = std::fs::read(dir.path().join("agent-1.safetensors")).unwrap();
        assert_eq!(agents[1].weights, on_disk);
        assert_eq!(read.agents[1].sha256, sha256_hex(&on_disk));
    }

    #[test]
    fn one_flipped_byte_fails_the_checksum_of_that_agent_only() {
        let dir = tempfile::tempdir().unwrap();
        let manifest = export(dir.path());
        let path = dir.path().join("agent-1.safetensors");
        let mut bytes = std::fs::read(&path).unwrap();
        let last = bytes.len() - 1;
        bytes[last] ^= 1;
        std::fs::write(&path, bytes).unwrap();
        manifest.verify_agent(dir.path(), 0).unwrap();
        let err = manifest.verify_agent(dir.path(), 1).unwrap_err();
        assert!(matches!(err, ManifestError::Checksum { .. }), "{err}");
        assert!(err.to_string().contains("agent-1.safetensors"), "{err}");
        assert!(load_all(dir.path()).is_err());
        assert!(load_agent(dir.path(), 0).is_ok());
    }

    #[test]
    fn swapped_weight_files_are_caught_by_the_checksums() {
        let dir = tempfile::tempdir().unwrap();
        export(dir.path());
        let (a, b) = (
            dir.path().join("agent-0.safetensors"),
            dir.path().join("agent-1.safetensors"),
        );
        let tmp = dir.path().join("tmp");
        std::fs::rename(&a, &tmp).unwrap();
        std::fs::rename(&b, &a).unwrap();
        std::fs::rename(&tmp, &b).unwrap();
        let err = load_agent(dir.path(), 0).unwrap_err();
        assert!(matches!(err, ManifestError::Checksum { .. }), "{err}");
    }

    #[test]
    fn missing_weight_file_names_the_path() {
        let dir = tempfile::tempdir().unwrap();
        export(dir.path());
        std::fs::remove_file(dir.path().join("agent-0.safetensors")).unwrap();
        let err = load_agent(dir.path(), 0).unwrap_err();
        assert!(matches!(err, ManifestError::Io { .. }), "{err}");
        assert!(err.to_string().contains("agent-0.safetensors"), "{err}");
    }

    #[test]
    fn manifest_for_another_layout_is_refused_with_the_field_named() {
        let dir = tempfile::tempdir().unwrap();
        export(dir.path());
        rewrite_manifest(dir.path(), |v| {
            v["env"] = serde_json::json!({"env": "warehouse", "horizon": 150})
        });
        let err = Manifest::read(dir.path()).unwrap_err();
        assert!(
            matches!(
                err,
                ManifestError::AgentCount {
                    expected: 3,
                    got: 2,
                    ..
                }
            ),
            "{err}"
        );
        export(dir.path());
        rewrite_manifest(dir.path(), |v| {
            v["agents"][1]["action_names"][0] = "Fly".into()
        });
        let err = Manifest::read(dir.path()).unwrap_err().to_string();
        assert!(
            err.contains("agent 1") && err.contains("action_names") && err.contains("Fly"),
            "{err}"
        );
        export(dir.path());
        rewrite_manifest(dir.path(), |v| v["agents"][0]["obs_size"] = 6.into());
        let err = Manifest::read(dir.path()).unwrap_err().to_string();
        assert!(err.contains("`obs_size` is 6"), "{err}");
    }

    #[test]
    fn format_version_typos_and_bad_values_are_named() {
        let dir = tempfile::tempdir().unwrap();
        type Edit = Box<dyn Fn(&mut serde_json::Value)>;
        let cases: Vec<(Edit, &str)> = vec![
            (Box::new(|v| v["format"] = "onnx".into()), "onnx"),
            (
                Box::new(|v| v["format_version"] = 2.into()),
                "format_version 2",
            ),
            (Box::new(|v| v["discount"] = 1.5.into()), "discount"),
            (Box::new(|v| v["agents"][0]["index"] = 1.into()), "index 1"),
            (
                Box::new(|v| v["agents"][0]["weights"] = "../agent-0.safetensors".into()),
                "plain file name",
            ),
            (
                Box::new(|v| v["agents"][1]["weights"] = "agent-0.safetensors".into()),
                "share",
            ),
            (Box::new(|v| v["agents"][0]["sha256"] = "abc".into()), "hex"),
            (
                Box::new(|v| v["agents"][0]["colour"] = "red".into()),
                "colour",
            ),
            (
                Box::new(|v| v["architecture"]["rnn_h_size"] = 0.into()),
                "rnn_h_size",
            ),
            (
                Box::new(|v| v["architecture"]["mlp_layer_size"] = u64::MAX.into()),
                "mlp_layer_size",
            ),
        ];
        for (edit, needle) in cases {
            export(dir.path());
            rewrite_manifest(dir.path(), edit);
            let err = Manifest::read(dir.path()).unwrap_err().to_string();
            assert!(err.contains(needle), "expected `{needle}` in: {err}");
        }
    }

    #[test]
    fn weights_of_the_wrong_shape_are_refused_on_write_and_on_load() {
        let dir = tempfile::tempdir().unwrap();
        let arch = Architecture::ddrqn(8, 4);
        let wrong = synthetic_weights(&Architecture::ddrqn(8, 6), 5, 8, |_, _| 0.0);
        let right = synthetic_weights(&arch, 5, 8, |_, _| 0.0);
        let err = Manifest::write_policy(
            dir.path(),
            bp10(),
            0.98,
            arch.clone(),
            run_info(),
            &[right.clone(), wrong.clone()],
        )
        .unwrap_err();
        assert!(err.to_string().contains("fc2.weight"), "{err}");
        let err = Manifest::write_policy(
            dir.path(),
            bp10(),
            0.98,
            arch,
            run_info(),
            std::slice::from_ref(&right),
        )
        .unwrap_err();
        assert!(matches!(
            err,
            ManifestError::WeightsCount {
                expected: 2,
                got: 1
            }
        ));

        // A consistent checksum over wrong tensors is still refused on load.
        export(dir.path());
        std::fs::write(dir.path().join("agent-0.safetensors"), &wrong).unwrap();
        let sum = sha256_hex(&wrong);
        rewrite_manifest(dir.path(), |v| v["agents"][0]["sha256"] = sum.into());
        let err = load_agent(dir.path(), 0).unwrap_err();
        assert!(matches!(err, ManifestError::Weights { .. }), "{err}");
    }

    #[test]
    fn a_built_in_domain_is_written_as_before_custom_domains_and_rewrites_byte_for_byte() {
        let dir = tempfile::tempdir().unwrap();
        export(dir.path());
        let text = std::fs::read_to_string(dir.path().join(MANIFEST_FILE)).unwrap();
        let env = "  \"env\": {\n    \"env\": \"box-pushing\",\n    \"grid\": 10,\n    \"horizon\": 100\n  },\n";
        assert!(text.contains(env), "{text}");
        let read = Manifest::read(dir.path()).unwrap();
        assert_eq!(read.env, bp10());
        assert_eq!(serde_json::to_string_pretty(&read).unwrap(), text);
    }

    /// Box Pushing 10x10's layout exported as a custom domain named `corridor`.
    fn export_custom(dir: &Path) -> Manifest {
        let arch = Architecture::ddrqn(8, 4);
        let domain = bp10().build().unwrap();
        let weights: Vec<Vec<u8>> = (0..2)
            .map(|a| synthetic_weights(&arch, 5, 8, |_, i| (i + a) as f32 * 0.01))
            .collect();
        let env = PolicyEnv::custom("corridor", &domain);
        Manifest::write_policy_for(dir, env, &domain, 0.95, arch, run_info(), &weights).unwrap()
    }

    #[test]
    fn a_custom_domain_policy_reads_back_with_its_layout_from_the_env_object() {
        let dir = tempfile::tempdir().unwrap();
        let written = export_custom(dir.path());
        let text = std::fs::read_to_string(dir.path().join(MANIFEST_FILE)).unwrap();
        assert!(
            text.contains("\"env\": \"custom\"") && text.contains("\"name\": \"corridor\""),
            "{text}"
        );
        let (read, agents) = load_all(dir.path()).unwrap();
        assert_eq!(read, written);
        assert_eq!(agents.len(), 2);
        assert_eq!((read.env.name(), read.env.horizon()), ("corridor", 100));
        assert_eq!(read.agents[1].action_names.len(), 8);
        assert_eq!(
            read.agents[0].obs_names,
            bp10().build().unwrap().obs_names(0)
        );
    }

    #[test]
    fn a_custom_domain_policy_must_be_consistent_with_itself() {
        let dir = tempfile::tempdir().unwrap();
        type Edit = Box<dyn Fn(&mut serde_json::Value)>;
        let cases: Vec<(Edit, &str)> = vec![
            (
                Box::new(|v| {
                    v["agents"][0]["obs_names"].as_array_mut().unwrap().pop();
                }),
                "agent 0: `obs_names`",
            ),
            (
                Box::new(|v| v["agents"][1]["n_actions"] = 9.into()),
                "agent 1: `action_names`",
            ),
            (
                Box::new(|v| v["agents"] = serde_json::json!([])),
                "lists no agents",
            ),
            (Box::new(|v| v["env"]["name"] = "".into()), "env.name"),
            (Box::new(|v| v["env"]["horizon"] = 0.into()), "env.horizon"),
            (Box::new(|v| v["agents"][1]["index"] = 0.into()), "index 0"),
        ];
        for (edit, needle) in cases {
            export_custom(dir.path());
            rewrite_manifest(dir.path(), edit);
            let err = Manifest::read(dir.path()).unwrap_err().to_string();
            assert!(err.contains(needle), "expected `{needle}` in: {err}");
        }
        // The weights are still checked against the manifest's own layout.
        export_custom(dir.path());
        rewrite_manifest(dir.path(), |v| {
            v["agents"][0]["obs_size"] = 4.into();
            v["agents"][0]["obs_names"].as_array_mut().unwrap().pop();
        });
        let err = load_agent(dir.path(), 0).unwrap_err();
        assert!(matches!(err, ManifestError::Weights { .. }), "{err}");
    }

    #[test]
    fn agent_out_of_range_is_an_error_not_a_panic() {
        let dir = tempfile::tempdir().unwrap();
        export(dir.path());
        let err = load_agent(dir.path(), 2).unwrap_err();
        assert!(
            matches!(
                err,
                ManifestError::AgentOutOfRange {
                    agent: 2,
                    n_agents: 2
                }
            ),
            "{err}"
        );
    }

    #[test]
    fn weight_files_that_are_not_regular_or_too_big_are_refused_before_reading() {
        let dir = tempfile::tempdir().unwrap();
        export(dir.path());
        let manifest = Manifest::read(dir.path()).unwrap();
        let weights = dir.path().join("agent-0.safetensors");
        let mut bytes = std::fs::read(&weights).unwrap();
        bytes.resize(bytes.len() + (1 << 20), 0);
        std::fs::write(&weights, &bytes).unwrap();
        let err = manifest
            .verify_agent(dir.path(), 0)
            .unwrap_err()
            .to_string();
        assert!(err.contains("at most"), "{err}");
        std::fs::remove_file(&weights).unwrap();
        let made = std::process::Command::new("mkfifo").arg(&weights).status();
        if made.is_ok_and(|s| s.success()) {
            let err = manifest
                .verify_agent(dir.path(), 0)
                .unwrap_err()
                .to_string();
            assert!(err.contains("not a regular file"), "{err}");
        }
    }

    #[test]
    fn a_leaky_relu_slope_other_than_the_nets_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        export(dir.path());
        rewrite_manifest(dir.path(), |v| {
            v["architecture"]["leaky_relu_slope"] = 0.2.into()
        });
        let err = Manifest::read(dir.path()).unwrap_err().to_string();
        assert!(err.contains("leaky_relu_slope"), "{err}");
    }
}
