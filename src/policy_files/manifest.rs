//! `policy.json`, the description of a policy directory, and the one writer and loader of the
//! directory (see the module doc of [`crate::policy_files`] for the JSON shape).

use super::architecture::{Architecture, ACAC_ACTOR, DDRQN, GRU_ACTOR, LEAKY_RELU_SLOPE};
use super::directory::check_only_policy_files;
use super::error::PolicyError;
use super::policy_env::{CustomEnv, PolicyEnv};
use crate::envs::{EnvSpec, MacroEnv};
use crate::files::atomic::write_atomic;
use crate::files::bounded_read::read_regular_file;
use crate::files::dir_swap::replace_dir;
use crate::nn::safetensors_io::{named_to_safetensors_bytes, to_safetensors_bytes};
use crate::nn::{ActingNet, GruActor, QNet, QNetConfig, TimedAcacActor};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

pub use super::format::{FORMAT, FORMAT_VERSION, POLICY_FILE};
/// Widest hidden layer a policy file may declare: the limit configs have, so a hand-edited file
/// cannot make a reader allocate more than any trained net needs.
pub use crate::nn::MAX_NET_WIDTH;

/// Largest `policy.json` read (one is a few kilobytes, most of it the run's config).
pub(crate) const MAX_DESCRIPTION_BYTES: u64 = 1 << 20;
/// Most rows a time table may have (one per primitive step of an episode, plus ACAC's five).
const MAX_TIME_ROWS: usize = 1 << 20;

/// Room for a weight file's JSON header beyond its tensor data.
const MAX_SAFETENSORS_HEADER_BYTES: u64 = 1 << 16;

/// What a net computes: Q-values (the ICRA methods) or a policy's log-probabilities (MacroMARL's
/// actors); a critic would be another kind with the same entries.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum NetKind {
    /// Q-values, one per macro-action (per joint macro-action for a centralized net).
    Q,
    /// A policy's log-probabilities, one per macro-action (per joint macro-action for a
    /// centralized actor): MacroMARL's actors.
    Actor,
}

impl NetKind {
    /// What `net` computes.
    pub fn of(net: &ActingNet) -> NetKind {
        match net {
            ActingNet::Q(_) => NetKind::Q,
            ActingNet::Actor(_) | ActingNet::Acac(_) => NetKind::Actor,
        }
    }

    /// The words for a centralized net of this kind, for messages: `centralized Q-net`,
    /// `centralized actor`.
    pub fn centralized_name(self) -> &'static str {
        match self {
            NetKind::Q => "centralized Q-net",
            NetKind::Actor => "centralized actor",
        }
    }

    /// What a net of `architecture` computes: an actor for [`GRU_ACTOR`] and [`ACAC_ACTOR`],
    /// else Q-values.
    pub fn of_architecture(architecture: &Architecture) -> NetKind {
        if architecture.kind == GRU_ACTOR || architecture.kind == ACAC_ACTOR {
            NetKind::Actor
        } else {
            NetKind::Q
        }
    }
}

/// Whose input a net reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum NetRole {
    /// One agent's decentralized net (input: its own macro-observation).
    Dec,
    /// The centralized net (input: the joint macro-observation).
    Cen,
}

/// Where a policy came from: the run's experiment, method, variant and seed, how far it trained,
/// and its resolved config (kept as JSON, so reading a policy never depends on the config types
/// of the build that trained it). Written at the top level of `policy.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunInfo {
    /// The experiment's name.
    pub experiment: String,
    /// The method's name as in configs (`our1`, `cen-ddrqn`, ...).
    pub method: String,
    /// The sweep point (`key=value,...`), empty without a sweep.
    pub variant: String,
    /// The run's seed.
    pub seed: u64,
    /// Training episodes completed when the nets were written.
    pub episodes_trained: u64,
    /// The run's resolved config (every hyperparameter).
    pub config: serde_json::Value,
}

/// One agent's observation and action layout: what a robot needs besides its net.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AgentLayout {
    /// The agent's index in the domain (equals its position in `agents`).
    pub index: usize,
    /// Length of its macro-observation.
    pub obs_size: usize,
    /// Name of each observation element, in layout order.
    pub obs_names: Vec<String>,
    /// Number of its macro-actions.
    pub n_actions: usize,
    /// Name of each macro-action, by index.
    pub action_names: Vec<String>,
}

impl AgentLayout {
    /// Every agent's layout, read from `domain` through its [`MacroEnv`] methods.
    pub fn of_domain(domain: &impl MacroEnv) -> Vec<AgentLayout> {
        (0..domain.n_agents())
            .map(|index| AgentLayout {
                index,
                obs_size: domain.obs_sizes()[index],
                obs_names: domain.obs_names(index),
                n_actions: domain.n_actions()[index],
                action_names: domain
                    .action_names(index)
                    .iter()
                    .map(|s| s.to_string())
                    .collect(),
            })
            .collect()
    }
}

/// One net's file: what it is (kind, role, agent), where and what it holds (file, checksum) and
/// its shape (input and output lengths, architecture). Nothing here is specific to Q-nets.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NetEntry {
    /// What the net computes (Q-values or action log-probabilities).
    pub kind: NetKind,
    /// Decentralized (one agent's) or centralized.
    pub role: NetRole,
    /// The agent of a decentralized net; absent for a centralized one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub agent: Option<usize>,
    /// File name inside the policy directory (no directories).
    pub file: String,
    /// Lowercase hex SHA-256 of the file.
    pub sha256: String,
    /// Length of the net's input vector.
    pub input: usize,
    /// Length of the net's output vector.
    pub output: usize,
    /// Its hidden layers.
    pub architecture: Architecture,
}

impl NetEntry {
    /// The Q-net sizes this entry declares.
    pub fn qnet_config(&self) -> QNetConfig {
        self.architecture.qnet_config(self.input, self.output)
    }
}

/// `policy.json`: the domain and its layout, the nets and where they came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// Always [`FORMAT`].
    pub format: String,
    /// [`FORMAT_VERSION`] (files of older versions are converted on read).
    pub format_version: u32,
    /// The domain: a built-in one and its parameters, as in configs and replay files, or a
    /// custom one (`{"env": "custom", "name": ..., "horizon": ...}`) whose layout only `agents`
    /// records (see [`PolicyEnv`]).
    pub env: PolicyEnv,
    /// Discount per primitive step of the reported (evaluation) return (quirks Q5, Q13).
    pub discount: f64,
    /// The nets the paper evaluates for the method (`docs/ALGORITHMS.md` §7.1): the decentralized ones, or the
    /// centralized one for Cen-DDRQN.
    pub evaluated: NetRole,
    /// Every agent's layout, in agent order.
    pub agents: Vec<AgentLayout>,
    /// The nets in the directory.
    pub nets: Vec<NetEntry>,
    /// Which run the nets come from.
    #[serde(flatten)]
    pub run: RunInfo,
}

/// One net to write: its entry (without the checksum, computed here) and its safetensors bytes.
#[derive(Debug, Clone, PartialEq)]
pub struct NetFile {
    /// As [`NetEntry::kind`].
    pub kind: NetKind,
    /// As [`NetEntry::role`].
    pub role: NetRole,
    /// As [`NetEntry::agent`].
    pub agent: Option<usize>,
    /// File name inside the policy directory.
    pub file: String,
    /// Input length.
    pub input: usize,
    /// Output length (one per (joint) macro-action).
    pub output: usize,
    /// Layer widths, as [`NetEntry`] records them.
    pub architecture: Architecture,
    /// The safetensors bytes to write.
    pub bytes: Vec<u8>,
}

impl NetFile {
    /// A Q-net as the file `file`.
    pub fn qnet(role: NetRole, agent: Option<usize>, file: String, net: &QNet) -> NetFile {
        let c = net.config();
        NetFile {
            kind: NetKind::Q,
            role,
            agent,
            file,
            input: c.input,
            output: c.output,
            architecture: Architecture::ddrqn(c.mlp, c.hidden),
            bytes: to_safetensors_bytes(&net.params),
        }
    }

    /// The file of an acting net of either kind ([`Self::qnet`], [`Self::actor`]).
    pub fn acting(role: NetRole, agent: Option<usize>, file: String, net: &ActingNet) -> NetFile {
        match net {
            ActingNet::Q(q) => NetFile::qnet(role, agent, file, q),
            ActingNet::Actor(a) => NetFile::actor(role, agent, file, a),
            ActingNet::Acac(a) => NetFile::acac_actor(agent, file, a),
        }
    }

    /// The entry and weights of agent `agent`'s ACAC actor with its time table, under ACAC's
    /// `state_dict` names (`time_embedding.weight` included). ACAC acts only through its
    /// agents' actors, so the role is always `dec`.
    pub fn acac_actor(agent: Option<usize>, file: String, net: &TimedAcacActor) -> NetFile {
        NetFile {
            kind: NetKind::Actor,
            role: NetRole::Dec,
            agent,
            file,
            input: net.obs_len(),
            output: net.n_actions(),
            architecture: Architecture::acac_actor(net),
            bytes: named_to_safetensors_bytes(&net.named()),
        }
    }

    /// The entry and weights of a trained MacroMARL actor: agent `agent`'s (role `dec`) or the
    /// centralized one over joint macro-actions (role `cen`, Mac-CAC), under its `state_dict`
    /// names.
    pub fn actor(role: NetRole, agent: Option<usize>, file: String, net: &GruActor) -> NetFile {
        let c = net.config();
        NetFile {
            kind: NetKind::Actor,
            role,
            agent,
            file,
            input: c.input,
            output: c.output,
            architecture: Architecture::gru_actor(c.mlp, c.hidden),
            bytes: named_to_safetensors_bytes(&net.named()),
        }
    }
}

/// One agent's decentralized Q-net file, read once and checked against its checksum and entry;
/// build the net from these bytes (not from a second read of the file).
#[derive(Debug, Clone, PartialEq)]
pub struct VerifiedAgent {
    /// The agent.
    pub index: usize,
    /// The safetensors bytes, as read and checked.
    pub weights: Vec<u8>,
}

/// Lowercase hex SHA-256 of `bytes`.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// The file name of agent `agent`'s decentralized net in an export (the name exports have
/// always used, which robot tooling opens).
pub fn weights_file_name(agent: usize) -> String {
    format!("agent-{agent}.safetensors")
}

impl Manifest {
    /// The one constructor: the description of `nets` (checksums computed, each file checked
    /// against its entry with nn's loader), validated. Nothing is written.
    pub fn new(
        env: PolicyEnv,
        agents: Vec<AgentLayout>,
        discount: f64,
        evaluated: NetRole,
        run: RunInfo,
        nets: &[NetFile],
    ) -> Result<Manifest, PolicyError> {
        let mut entries = Vec::with_capacity(nets.len());
        for n in nets {
            n.architecture
                .check_weights(&n.bytes, n.input, n.output)
                .map_err(|source| PolicyError::Weights {
                    path: PathBuf::from(&n.file),
                    source,
                })?;
            entries.push(NetEntry {
                kind: n.kind,
                role: n.role,
                agent: n.agent,
                file: n.file.clone(),
                sha256: sha256_hex(&n.bytes),
                input: n.input,
                output: n.output,
                architecture: n.architecture.clone(),
            });
        }
        let manifest = Manifest {
            format: FORMAT.to_string(),
            format_version: FORMAT_VERSION,
            env,
            discount,
            evaluated,
            agents,
            nets: entries,
            run,
        };
        manifest.validate(Path::new(POLICY_FILE))?;
        Ok(manifest)
    }

    /// The one writer: [`Self::new`], then every net's file and `policy.json` written into a
    /// new generation of `dir` that replaces the old one in one atomic step
    /// ([`crate::files::dir_swap`]): a kill at any moment leaves the complete old set or the
    /// complete new one, and a reader never sees a description beside another set's weights.
    /// An existing `dir` must hold only a policy directory's files (an earlier export, import or
    /// run policy), so nobody's other files are replaced.
    pub fn write_new(
        dir: &Path,
        env: PolicyEnv,
        agents: Vec<AgentLayout>,
        discount: f64,
        evaluated: NetRole,
        run: RunInfo,
        nets: &[NetFile],
    ) -> Result<Manifest, PolicyError> {
        let manifest = Manifest::new(env, agents, discount, evaluated, run, nets)?;
        check_only_policy_files(dir)?;
        let text = serde_json::to_string_pretty(&manifest)
            .map_err(|e| PolicyError::io(&dir.join(POLICY_FILE), e))?;
        replace_dir(dir, |new| {
            for n in nets {
                write_atomic(&new.join(&n.file), &n.bytes)?;
            }
            write_atomic(&new.join(POLICY_FILE), text.as_bytes())
        })
        .map_err(|e| PolicyError::io(dir, e))?;
        Ok(manifest)
    }

    /// An export's description: agent i's decentralized Q-net weights `weights[i]` (safetensors,
    /// checked against `architecture`) as `agent-<i>.safetensors`, with the built-in domain
    /// `env`'s layout. Nothing is written.
    pub fn build(
        env: EnvSpec,
        discount: f64,
        architecture: Architecture,
        run: RunInfo,
        weights: &[Vec<u8>],
    ) -> Result<Manifest, PolicyError> {
        let built = env.build().map_err(|e| PolicyError::Env {
            path: PathBuf::from(POLICY_FILE),
            message: e.to_string(),
        })?;
        Manifest::build_for(env.into(), &built, discount, architecture, run, weights)
    }

    /// [`Self::build`] for any domain: the layout is read from `domain` through its
    /// [`MacroEnv`] methods, and `env` says which domain the description names (a built-in
    /// `env` is still checked against its own layout).
    pub fn build_for(
        env: PolicyEnv,
        domain: &impl MacroEnv,
        discount: f64,
        architecture: Architecture,
        run: RunInfo,
        weights: &[Vec<u8>],
    ) -> Result<Manifest, PolicyError> {
        let nets = export_net_files(domain, &architecture, weights)?;
        Manifest::new(
            env,
            AgentLayout::of_domain(domain),
            discount,
            NetRole::Dec,
            run,
            &nets,
        )
    }

    /// Write an export of [`Self::build`] to `dir`.
    pub fn write_policy(
        dir: &Path,
        env: EnvSpec,
        discount: f64,
        architecture: Architecture,
        run: RunInfo,
        weights: &[Vec<u8>],
    ) -> Result<Manifest, PolicyError> {
        let built = env.build().map_err(|e| PolicyError::Env {
            path: dir.join(POLICY_FILE),
            message: e.to_string(),
        })?;
        Manifest::write_policy_for(
            dir,
            env.into(),
            &built,
            discount,
            architecture,
            run,
            weights,
        )
    }

    /// Write an export of [`Self::build_for`] to `dir`: any domain, custom ones included.
    pub fn write_policy_for(
        dir: &Path,
        env: PolicyEnv,
        domain: &impl MacroEnv,
        discount: f64,
        architecture: Architecture,
        run: RunInfo,
        weights: &[Vec<u8>],
    ) -> Result<Manifest, PolicyError> {
        let nets = export_net_files(domain, &architecture, weights)?;
        let agents = AgentLayout::of_domain(domain);
        Manifest::write_new(dir, env, agents, discount, NetRole::Dec, run, &nets)
    }

    /// Check the description against itself and its domain: format and version, discount,
    /// every agent's layout equal to the built-in domain's (a custom domain's only consistent
    /// with itself), every net's file name, checksum text, architecture, role, agent and sizes,
    /// and the evaluated nets present. `path` names the file in errors.
    pub fn validate(&self, path: &Path) -> Result<(), PolicyError> {
        let invalid = |key: String, reason: String| PolicyError::invalid(path, key, reason);
        if self.format != FORMAT {
            return Err(PolicyError::Format {
                path: path.to_path_buf(),
                found: self.format.clone(),
            });
        }
        if self.format_version != FORMAT_VERSION {
            return Err(PolicyError::Version {
                path: path.to_path_buf(),
                found: self.format_version.into(),
            });
        }
        if !(self.discount > 0.0 && self.discount <= 1.0) {
            return Err(invalid(
                "discount".into(),
                format!("must be in (0, 1], got {}", self.discount),
            ));
        }
        match &self.env {
            PolicyEnv::Known(spec) => self.check_layout_against(spec, path)?,
            PolicyEnv::Custom(custom) => self.check_custom_layout(custom, path)?,
        }
        let mut seen = std::collections::BTreeSet::new();
        for (i, net) in self.nets.iter().enumerate() {
            let key = |field: &str| format!("nets[{i}].{field}");
            if !is_plain_file_name(&net.file) {
                return Err(invalid(
                    key("file"),
                    format!(
                        "`{}` must be a plain file name inside the policy directory",
                        net.file
                    ),
                ));
            }
            if let Some(first) = self.nets[..i].iter().position(|n| n.file == net.file) {
                return Err(invalid(
                    key("file"),
                    format!("nets {first} and {i} share the file `{}`", net.file),
                ));
            }
            let hex = |c: char| c.is_ascii_digit() || ('a'..='f').contains(&c);
            if net.sha256.len() != 64 || !net.sha256.chars().all(hex) {
                return Err(invalid(
                    key("sha256"),
                    format!("`{}` is not 64 lowercase hex digits", net.sha256),
                ));
            }
            check_architecture(&net.architecture, i, path)?;
            match (net.role, net.agent) {
                (NetRole::Dec, Some(a)) if a < self.agents.len() => {}
                (NetRole::Dec, _) => {
                    return Err(invalid(
                        key("agent"),
                        format!(
                            "a decentralized net needs the agent it belongs to, in 0..{}",
                            self.agents.len()
                        ),
                    ))
                }
                (NetRole::Cen, None) => {}
                (NetRole::Cen, Some(_)) => {
                    return Err(invalid(
                        key("agent"),
                        "a centralized net belongs to no one agent".into(),
                    ))
                }
            }
            if !seen.insert((net.kind, net.role, net.agent)) {
                return Err(invalid(
                    key("role"),
                    format!(
                        "a second {:?} {:?} net{}",
                        net.kind,
                        net.role,
                        net.agent
                            .map_or(String::new(), |a| format!(" for agent {a}"))
                    ),
                ));
            }
            let (input, output) = self.q_net_sizes(net.role, net.agent);
            let sizes = match net.kind {
                NetKind::Q | NetKind::Actor => Some((input, output)),
            };
            if NetKind::of_architecture(&net.architecture) != net.kind {
                return Err(invalid(
                    key("architecture.kind"),
                    format!(
                        "a net of kind `{}` is not a `{}` (Q-nets are `{DDRQN}`, actors `{GRU_ACTOR}` or `{ACAC_ACTOR}`)",
                        match net.kind {
                            NetKind::Q => "q",
                            NetKind::Actor => "actor",
                        },
                        net.architecture.kind
                    ),
                ));
            }
            if net.architecture.kind == ACAC_ACTOR && net.role != NetRole::Dec {
                return Err(invalid(
                    key("role"),
                    format!("an `{ACAC_ACTOR}` is one agent's net (role `dec`)"),
                ));
            }
            if let Some((input, output)) = sizes {
                if (Some(net.input), Some(net.output)) != (input, output) {
                    return Err(invalid(
                        key("input"),
                        format!(
                            "the net reads {} and writes {} values; the layout says {} and {}",
                            net.input,
                            net.output,
                            input.map_or("(too many)".into(), |v| v.to_string()),
                            output.map_or("(too many)".into(), |v| v.to_string()),
                        ),
                    ));
                }
            }
        }
        if !self.nets.iter().any(|n| n.role == self.evaluated) {
            return Err(invalid(
                "evaluated".into(),
                format!("is {:?} but no such net is listed", self.evaluated),
            ));
        }
        Ok(())
    }

    /// A Q-net's input and output lengths by the layout: agent a's observation and macro-actions,
    /// or the joint observation and joint macro-actions (`None` if that overflows).
    fn q_net_sizes(&self, role: NetRole, agent: Option<usize>) -> (Option<usize>, Option<usize>) {
        match (role, agent) {
            (NetRole::Dec, Some(a)) => (
                Some(self.agents[a].obs_size),
                Some(self.agents[a].n_actions),
            ),
            _ => (
                self.agents
                    .iter()
                    .try_fold(0usize, |s, a| s.checked_add(a.obs_size)),
                self.agents
                    .iter()
                    .try_fold(1usize, |p, a| p.checked_mul(a.n_actions)),
            ),
        }
    }

    /// A built-in domain's agents must be listed in order with exactly its layout.
    fn check_layout_against(&self, spec: &EnvSpec, path: &Path) -> Result<(), PolicyError> {
        let env = spec.build().map_err(|e| PolicyError::Env {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        if self.agents.len() != env.n_agents() {
            return Err(PolicyError::AgentCount {
                path: path.to_path_buf(),
                env: spec.name().to_string(),
                expected: env.n_agents(),
                got: self.agents.len(),
            });
        }
        for (expected, got) in AgentLayout::of_domain(&env).iter().zip(&self.agents) {
            let position = expected.index;
            if got.index != position {
                return Err(PolicyError::AgentIndex {
                    path: path.to_path_buf(),
                    position,
                    index: got.index,
                });
            }
            let layout = |field, expected: String, got: String| {
                if expected == got {
                    Ok(())
                } else {
                    Err(PolicyError::Layout {
                        path: path.to_path_buf(),
                        agent: position,
                        field,
                        expected,
                        got,
                    })
                }
            };
            let show = |v: &[String]| format!("{v:?}");
            layout(
                "obs_size",
                expected.obs_size.to_string(),
                got.obs_size.to_string(),
            )?;
            layout("obs_names", show(&expected.obs_names), show(&got.obs_names))?;
            layout(
                "n_actions",
                expected.n_actions.to_string(),
                got.n_actions.to_string(),
            )?;
            layout(
                "action_names",
                show(&expected.action_names),
                show(&got.action_names),
            )?;
        }
        Ok(())
    }

    /// A custom domain is not here to compare with: its agent entries must be consistent among
    /// themselves (in order, at least one observation element and one macro-action, one name
    /// for each).
    fn check_custom_layout(&self, custom: &CustomEnv, path: &Path) -> Result<(), PolicyError> {
        custom
            .validate()
            .map_err(|(key, reason)| PolicyError::invalid(path, key, reason))?;
        if self.agents.is_empty() {
            return Err(PolicyError::invalid(
                path,
                "agents",
                format!("the custom domain `{}` lists no agents", custom.name),
            ));
        }
        for (position, a) in self.agents.iter().enumerate() {
            if a.index != position {
                return Err(PolicyError::AgentIndex {
                    path: path.to_path_buf(),
                    position,
                    index: a.index,
                });
            }
            for (field, size, names) in [
                ("obs_names", a.obs_size, a.obs_names.len()),
                ("action_names", a.n_actions, a.action_names.len()),
            ] {
                if size == 0 || names != size {
                    return Err(PolicyError::Layout {
                        path: path.to_path_buf(),
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

    /// Read net `index`'s file from `dir`: refused before reading if it is not a regular file or
    /// is larger than its architecture allows, then checked against its SHA-256 and its entry
    /// (every tensor present, F32, of the declared shape, nothing else). Returns the checked
    /// bytes.
    ///
    /// Panics if `index` is not an index of `nets`.
    pub fn read_net(&self, dir: &Path, index: usize) -> Result<Vec<u8>, PolicyError> {
        let entry = &self.nets[index];
        let path = dir.join(&entry.file);
        // Saturating: a hand-edited size cannot overflow the bound, only make it unreachable.
        let floats = entry
            .architecture
            .tensors(entry.input, entry.output)
            .iter()
            .map(|(_, shape)| shape.iter().fold(1u64, |n, &d| n.saturating_mul(d as u64)))
            .fold(0u64, u64::saturating_add);
        let max = floats
            .saturating_mul(4)
            .saturating_add(MAX_SAFETENSORS_HEADER_BYTES);
        let bytes = read_regular_file(&path, max).map_err(|e| PolicyError::io(&path, e))?;
        let got = sha256_hex(&bytes);
        if got != entry.sha256 {
            return Err(PolicyError::Checksum {
                path,
                expected: entry.sha256.clone(),
                got,
            });
        }
        entry
            .architecture
            .check_weights(&bytes, entry.input, entry.output)
            .map_err(|source| PolicyError::Weights { path, source })?;
        Ok(bytes)
    }

    /// Net `index` read from `dir` and checked ([`Self::read_net`]) as a Q-net.
    ///
    /// Panics if `index` is not an index of `nets`.
    pub fn load_qnet(&self, dir: &Path, index: usize) -> Result<QNet, PolicyError> {
        let bytes = self.read_net(dir, index)?;
        self.qnet_from_bytes(dir, index, &bytes)
    }

    /// Build net `index`'s Q-net from its bytes, checked against its entry (the bytes may come
    /// from elsewhere than [`Self::read_net`], e.g. a [`VerifiedAgent`] built by a caller).
    fn qnet_from_bytes(&self, dir: &Path, index: usize, bytes: &[u8]) -> Result<QNet, PolicyError> {
        let entry = &self.nets[index];
        entry
            .architecture
            .qnet(bytes, entry.input, entry.output)
            .map_err(|source| PolicyError::Weights {
                path: dir.join(&entry.file),
                source,
            })
    }

    /// Net `index` read from `dir` and checked ([`Self::read_net`]), as the net it is: a Q-net
    /// or an actor.
    ///
    /// Panics if `index` is not an index of `nets`.
    pub fn load_acting_net(&self, dir: &Path, index: usize) -> Result<ActingNet, PolicyError> {
        let bytes = self.read_net(dir, index)?;
        let entry = &self.nets[index];
        entry
            .architecture
            .acting_net(&bytes, entry.input, entry.output)
            .map_err(|source| PolicyError::Weights {
                path: dir.join(&entry.file),
                source,
            })
    }

    /// The index in `nets` of the centralized net that acts (a Q-net or Mac-CAC's actor; not a
    /// critic), if the policy has one.
    pub fn cen_net(&self) -> Option<usize> {
        self.nets
            .iter()
            .position(|n| matches!(n.kind, NetKind::Q | NetKind::Actor) && n.role == NetRole::Cen)
    }

    /// The index in `nets` of agent `agent`'s decentralized net (a Q-net or an actor): the net a
    /// robot runs. A policy that acts only centrally is refused, naming its centralized net.
    pub fn agent_net(&self, agent: usize) -> Result<usize, PolicyError> {
        if agent >= self.agents.len() {
            return Err(PolicyError::AgentOutOfRange {
                agent,
                n_agents: self.agents.len(),
            });
        }
        self.nets
            .iter()
            .position(|n| {
                matches!(n.kind, NetKind::Q | NetKind::Actor)
                    && n.role == NetRole::Dec
                    && n.agent == Some(agent)
            })
            .ok_or_else(|| PolicyError::NoAgentNet {
                path: PathBuf::from(POLICY_FILE),
                agent,
                method: self.run.method.clone(),
                centralized: self.cen_net().map(|i| self.nets[i].kind.centralized_name()),
            })
    }

    /// Read agent `agent`'s decentralized Q-net file from `dir`, checked. A robot needs only its
    /// own file.
    pub fn verify_agent(&self, dir: &Path, agent: usize) -> Result<VerifiedAgent, PolicyError> {
        let index = self.agent_net(agent)?;
        Ok(VerifiedAgent {
            index: agent,
            weights: self.read_net(dir, index)?,
        })
    }

    /// Agent `verified.index`'s net (a Q-net or an actor) from its verified bytes.
    pub fn agent_acting_net(&self, verified: &VerifiedAgent) -> Result<ActingNet, PolicyError> {
        let index = self.agent_net(verified.index)?;
        let entry = &self.nets[index];
        entry
            .architecture
            .acting_net(&verified.weights, entry.input, entry.output)
            .map_err(|source| PolicyError::Weights {
                path: PathBuf::from(&entry.file),
                source,
            })
    }

    /// The names of agent `agent`'s macro-actions. Panics if `agent` is out of range (the
    /// description was validated against the agent count).
    pub fn action_names(&self, agent: usize) -> &[String] {
        &self.agents[agent].action_names
    }
}

/// Agent i's decentralized net file of an export from its weights `weights[i]` (a Q-net or an
/// actor, as the architecture says).
fn export_net_files(
    domain: &impl MacroEnv,
    architecture: &Architecture,
    weights: &[Vec<u8>],
) -> Result<Vec<NetFile>, PolicyError> {
    if weights.len() != domain.n_agents() {
        return Err(PolicyError::invalid(
            Path::new(POLICY_FILE),
            "nets",
            format!(
                "expected one weight file per agent ({}), got {}",
                domain.n_agents(),
                weights.len()
            ),
        ));
    }
    Ok(weights
        .iter()
        .enumerate()
        .map(|(agent, bytes)| NetFile {
            kind: NetKind::of_architecture(architecture),
            role: NetRole::Dec,
            agent: Some(agent),
            file: weights_file_name(agent),
            input: domain.obs_sizes()[agent],
            output: domain.n_actions()[agent],
            architecture: architecture.clone(),
            bytes: bytes.clone(),
        })
        .collect())
}

/// The architecture is one this build runs, with widths a config could have asked for.
fn check_architecture(arch: &Architecture, i: usize, path: &Path) -> Result<(), PolicyError> {
    let key = |field: &str| format!("nets[{i}].architecture.{field}");
    if ![DDRQN, GRU_ACTOR, ACAC_ACTOR].contains(&arch.kind.as_str()) {
        return Err(PolicyError::invalid(
            path,
            key("kind"),
            format!(
                "unknown architecture `{}` (this build knows `{DDRQN}`, `{GRU_ACTOR}` and `{ACAC_ACTOR}`)",
                arch.kind
            ),
        ));
    }
    if arch.kind != ACAC_ACTOR {
        for (field, set) in [
            ("layer_norm", arch.layer_norm.is_some()),
            ("time_embedding", arch.time_embedding.is_some()),
        ] {
            if set {
                return Err(PolicyError::invalid(
                    path,
                    key(field),
                    format!("is for `{ACAC_ACTOR}`, not a `{}`", arch.kind),
                ));
            }
        }
    }
    if let Some([rows, dim]) = arch.time_embedding {
        if rows == 0 || rows > MAX_TIME_ROWS || dim == 0 || dim > MAX_NET_WIDTH {
            return Err(PolicyError::invalid(
                path,
                key("time_embedding"),
                format!(
                    "rows must be in 1..={MAX_TIME_ROWS} and width in 1..={MAX_NET_WIDTH}, got [{rows}, {dim}]"
                ),
            ));
        }
    }
    if arch.kind == DDRQN && arch.mlp_out_size.is_some() {
        return Err(PolicyError::invalid(
            path,
            key("mlp_out_size"),
            format!("is for `{GRU_ACTOR}`; a `{DDRQN}` has fc3 as wide as fc1"),
        ));
    }
    if arch.leaky_relu_slope != LEAKY_RELU_SLOPE {
        return Err(PolicyError::invalid(
            path,
            key("leaky_relu_slope"),
            format!(
                "the nets here use {LEAKY_RELU_SLOPE}, the file says {}",
                arch.leaky_relu_slope
            ),
        ));
    }
    for (field, value) in [
        ("mlp_layer_size", arch.mlp_layer_size),
        ("rnn_h_size", arch.rnn_h_size),
        (
            "mlp_out_size",
            arch.mlp_out_size.unwrap_or(arch.mlp_layer_size),
        ),
    ] {
        if value == 0 || value > MAX_NET_WIDTH {
            return Err(PolicyError::invalid(
                path,
                key(field),
                format!("must be in 1..={MAX_NET_WIDTH}, got {value}"),
            ));
        }
    }
    Ok(())
}

/// Load the description and one agent's verified weights: what `macdec robot --agent I` needs.
pub fn load_agent(dir: &Path, agent: usize) -> Result<(Manifest, VerifiedAgent), PolicyError> {
    let manifest = Manifest::read(dir)?;
    let verified = manifest.verify_agent(dir, agent)?;
    Ok((manifest, verified))
}

/// Load the description and every agent's verified weights.
pub fn load_all(dir: &Path) -> Result<(Manifest, Vec<VerifiedAgent>), PolicyError> {
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

    use crate::policy_files::architecture::synthetic_weights;

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
        let path = dir.join(POLICY_FILE);
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
        assert_eq!(read.nets[1].file, "agent-1.safetensors");
        assert_eq!(read.nets[1].agent, Some(1));
        assert_eq!((read.nets[1].input, read.nets[1].output), (5, 8));
        assert_eq!(read.agents[0].action_names.len(), 8);
        assert_eq!(read.agents[0].obs_names.len(), 5);
        assert_eq!(read.run.seed, 7);
        let on_disk = std::fs::read(dir.path().join("agent-1.safetensors")).unwrap();
        assert_eq!(agents[1].weights, on_disk);
        assert_eq!(read.nets[1].sha256, sha256_hex(&on_disk));
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
        assert!(matches!(err, PolicyError::Checksum { .. }), "{err}");
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
        assert!(matches!(err, PolicyError::Checksum { .. }), "{err}");
    }

    #[test]
    fn missing_weight_file_names_the_path() {
        let dir = tempfile::tempdir().unwrap();
        export(dir.path());
        std::fs::remove_file(dir.path().join("agent-0.safetensors")).unwrap();
        let err = load_agent(dir.path(), 0).unwrap_err();
        assert!(matches!(err, PolicyError::Io { .. }), "{err}");
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
                PolicyError::AgentCount {
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
                Box::new(|v| v["format_version"] = 3.into()),
                "format_version 3",
            ),
            (Box::new(|v| v["discount"] = 1.5.into()), "discount"),
            (Box::new(|v| v["agents"][0]["index"] = 1.into()), "index 1"),
            (
                Box::new(|v| v["nets"][0]["file"] = "../agent-0.safetensors".into()),
                "plain file name",
            ),
            (
                Box::new(|v| v["nets"][1]["file"] = "agent-0.safetensors".into()),
                "share",
            ),
            (Box::new(|v| v["nets"][0]["sha256"] = "abc".into()), "hex"),
            (
                Box::new(|v| v["agents"][0]["colour"] = "red".into()),
                "colour",
            ),
            (
                Box::new(|v| v["nets"][0]["architecture"]["rnn_h_size"] = 0.into()),
                "rnn_h_size",
            ),
            (
                Box::new(|v| v["nets"][1]["architecture"]["mlp_layer_size"] = u64::MAX.into()),
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
        assert!(
            err.to_string()
                .contains("one weight file per agent (2), got 1"),
            "{err}"
        );

        // A consistent checksum over wrong tensors is still refused on load.
        export(dir.path());
        std::fs::write(dir.path().join("agent-0.safetensors"), &wrong).unwrap();
        let sum = sha256_hex(&wrong);
        rewrite_manifest(dir.path(), |v| v["nets"][0]["sha256"] = sum.into());
        let err = load_agent(dir.path(), 0).unwrap_err();
        assert!(matches!(err, PolicyError::Weights { .. }), "{err}");
    }

    #[test]
    fn a_built_in_domain_is_written_as_before_custom_domains_and_rewrites_byte_for_byte() {
        let dir = tempfile::tempdir().unwrap();
        export(dir.path());
        let text = std::fs::read_to_string(dir.path().join(POLICY_FILE)).unwrap();
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
        let text = std::fs::read_to_string(dir.path().join(POLICY_FILE)).unwrap();
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
        // A net entry must fit the layout, and its file must fit the entry.
        export_custom(dir.path());
        let shrink = |v: &mut serde_json::Value| {
            v["agents"][0]["obs_size"] = 4.into();
            v["agents"][0]["obs_names"].as_array_mut().unwrap().pop();
        };
        rewrite_manifest(dir.path(), shrink);
        let err = load_agent(dir.path(), 0).unwrap_err().to_string();
        assert!(
            err.contains("nets[0].input") && err.contains("says 4"),
            "{err}"
        );
        export_custom(dir.path());
        rewrite_manifest(dir.path(), |v| {
            shrink(v);
            v["nets"][0]["input"] = 4.into();
        });
        let err = load_agent(dir.path(), 0).unwrap_err();
        assert!(matches!(err, PolicyError::Weights { .. }), "{err}");
    }

    #[test]
    fn agent_out_of_range_is_an_error_not_a_panic() {
        let dir = tempfile::tempdir().unwrap();
        export(dir.path());
        let err = load_agent(dir.path(), 2).unwrap_err();
        assert!(
            matches!(
                err,
                PolicyError::AgentOutOfRange {
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
            v["nets"][0]["architecture"]["leaky_relu_slope"] = 0.2.into()
        });
        let err = Manifest::read(dir.path()).unwrap_err().to_string();
        assert!(err.contains("leaky_relu_slope"), "{err}");
    }

    #[test]
    fn net_entries_must_say_whose_they_are_once_each() {
        let dir = tempfile::tempdir().unwrap();
        type Edit = Box<dyn Fn(&mut serde_json::Value)>;
        let cases: Vec<(Edit, &str)> = vec![
            (
                Box::new(|v| {
                    v["nets"][0].as_object_mut().unwrap().remove("agent");
                }),
                "nets[0].agent",
            ),
            (Box::new(|v| v["nets"][1]["agent"] = 2.into()), "in 0..2"),
            (
                Box::new(|v| v["nets"][1]["role"] = "cen".into()),
                "nets[1].agent",
            ),
            (
                Box::new(|v| v["nets"][1]["agent"] = 0.into()),
                "a second Q Dec net for agent 0",
            ),
            (Box::new(|v| v["evaluated"] = "cen".into()), "`evaluated`"),
            (Box::new(|v| v["nets"][0]["kind"] = "actor".into()), "actor"),
            (
                Box::new(|v| v["nets"][0]["output"] = 7.into()),
                "nets[0].input",
            ),
            (
                Box::new(|v| v["nets"][0]["architecture"]["kind"] = "transformer".into()),
                "unknown architecture `transformer`",
            ),
        ];
        for (edit, needle) in cases {
            export(dir.path());
            rewrite_manifest(dir.path(), edit);
            let err = Manifest::read(dir.path()).unwrap_err().to_string();
            assert!(err.contains(needle), "expected `{needle}` in: {err}");
            assert!(err.contains(POLICY_FILE), "the file is named: {err}");
        }
    }

    /// Keys a later build adds at the top level or to a net entry are ignored (as a run's
    /// policy.json always allowed); the layout and architectures still refuse typos.
    #[test]
    fn unknown_keys_are_ignored_at_the_top_and_in_nets_but_not_in_the_layout() {
        let dir = tempfile::tempdir().unwrap();
        let written = export(dir.path());
        rewrite_manifest(dir.path(), |v| {
            v["a_key_from_the_future"] = serde_json::json!([1, 2]);
            v["nets"][0]["another"] = "x".into();
        });
        assert_eq!(Manifest::read(dir.path()).unwrap(), written);
        rewrite_manifest(dir.path(), |v| {
            v["nets"][0]["architecture"]["dropout"] = 0.5.into()
        });
        let err = Manifest::read(dir.path()).unwrap_err().to_string();
        assert!(err.contains("dropout"), "{err}");
    }

    #[test]
    fn a_directory_without_a_description_says_what_it_looked_for() {
        let dir = tempfile::tempdir().unwrap();
        let err = Manifest::read(dir.path()).unwrap_err().to_string();
        assert!(
            err.contains("policy.json") && err.contains("manifest.json"),
            "{err}"
        );
    }
}
