//! The two formats of format_version 1, converted on read into the one [`Manifest`], so run
//! directories and exports written before the formats were unified keep loading:
//!
//! - a run's `policy/policy.json` (`"format": "macdec-run-policy"`): the run's identity at the
//!   top level, a built-in `env`, and `nets` with `role`, `agent`, `file`, `sha256` and `sizes`
//!   (`{"input", "mlp", "hidden", "output"}`); unknown keys were ignored, as they still are;
//! - an export's `manifest.json` (`"format": "macdec-policy"`): `env` (built-in or custom),
//!   one shared `architecture`, `run`, and `agents` each naming its weights file and checksum
//!   beside its layout; unknown keys were refused, as they still are.
//!
//! Both hold only Q-nets. Nothing is rewritten: the files stay as they were.

use super::architecture::Architecture;
use super::error::PolicyError;
use super::manifest::{
    AgentLayout, Manifest, NetEntry, NetKind, NetRole, RunInfo, FORMAT, FORMAT_VERSION,
};
use super::policy_env::PolicyEnv;
use crate::envs::EnvSpec;
use crate::nn::QNetConfig;
use serde::Deserialize;
use std::path::Path;

/// The `format` tag of a version-1 run `policy.json`.
pub const RUN_FORMAT_V1: &str = "macdec-run-policy";
pub use super::format::MANIFEST_FILE_V1;

/// A version-1 run `policy.json`.
#[derive(Deserialize)]
struct RunPolicyV1 {
    #[serde(flatten)]
    run: RunInfo,
    env: EnvSpec,
    discount: f64,
    evaluated: NetRole,
    nets: Vec<RunNetV1>,
}

#[derive(Deserialize)]
struct RunNetV1 {
    role: NetRole,
    #[serde(default)]
    agent: Option<usize>,
    file: String,
    sha256: String,
    sizes: QNetConfig,
}

/// A version-1 export `manifest.json`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ExportV1 {
    #[allow(dead_code)]
    format: String,
    #[allow(dead_code)]
    format_version: u32,
    env: PolicyEnv,
    discount: f64,
    architecture: Architecture,
    run: ExportRunV1,
    agents: Vec<ExportAgentV1>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ExportRunV1 {
    experiment: String,
    method: String,
    variant: String,
    seed: u64,
    episodes_trained: u64,
    config: serde_json::Value,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ExportAgentV1 {
    index: usize,
    weights: String,
    sha256: String,
    obs_size: usize,
    obs_names: Vec<String>,
    n_actions: usize,
    action_names: Vec<String>,
}

fn parse<T: for<'de> Deserialize<'de>>(
    value: serde_json::Value,
    path: &Path,
) -> Result<T, PolicyError> {
    serde_json::from_value(value).map_err(|e| PolicyError::Parse {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

/// A version-1 run `policy.json` as a [`Manifest`]: its agents' layout from its built-in domain.
pub(crate) fn run_v1(value: serde_json::Value, path: &Path) -> Result<Manifest, PolicyError> {
    let v1: RunPolicyV1 = parse(value, path)?;
    let domain = v1.env.build().map_err(|e| PolicyError::Env {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    let nets = v1
        .nets
        .into_iter()
        .map(|n| NetEntry {
            kind: NetKind::Q,
            role: n.role,
            agent: n.agent,
            file: n.file,
            sha256: n.sha256,
            input: n.sizes.input,
            output: n.sizes.output,
            architecture: Architecture::ddrqn(n.sizes.mlp, n.sizes.hidden),
        })
        .collect();
    Ok(Manifest {
        format: FORMAT.to_string(),
        format_version: FORMAT_VERSION,
        env: v1.env.into(),
        discount: v1.discount,
        evaluated: v1.evaluated,
        agents: AgentLayout::of_domain(&domain),
        nets,
        run: v1.run,
    })
}

/// A version-1 export `manifest.json` as a [`Manifest`]: each agent's weights become its
/// decentralized Q-net entry, with the shared architecture.
pub(crate) fn export_v1(value: serde_json::Value, path: &Path) -> Result<Manifest, PolicyError> {
    let v1: ExportV1 = parse(value, path)?;
    let nets = v1
        .agents
        .iter()
        .map(|a| NetEntry {
            kind: NetKind::Q,
            role: NetRole::Dec,
            agent: Some(a.index),
            file: a.weights.clone(),
            sha256: a.sha256.clone(),
            input: a.obs_size,
            output: a.n_actions,
            architecture: v1.architecture.clone(),
        })
        .collect();
    let agents = v1
        .agents
        .into_iter()
        .map(|a| AgentLayout {
            index: a.index,
            obs_size: a.obs_size,
            obs_names: a.obs_names,
            n_actions: a.n_actions,
            action_names: a.action_names,
        })
        .collect();
    let r = v1.run;
    Ok(Manifest {
        format: FORMAT.to_string(),
        format_version: FORMAT_VERSION,
        env: v1.env,
        discount: v1.discount,
        evaluated: NetRole::Dec,
        agents,
        nets,
        run: RunInfo {
            experiment: r.experiment,
            method: r.method,
            variant: r.variant,
            seed: r.seed,
            episodes_trained: r.episodes_trained,
            config: r.config,
        },
    })
}
