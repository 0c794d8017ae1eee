//! A deterministic stand-in for a trained Q-net, for tests and the CLI's hidden `--mock` flag:
//! a tiny recurrent function whose Q-values depend on the whole observation history since the
//! last reset, so any bug that loses, shares or wrongly advances a robot's hidden state changes
//! its answers.

use crate::deploy::AgentPolicy;
use crate::envs::{EnvSpec, MacroEnv};
use crate::policy_files::architecture::{synthetic_weights, Architecture};
use crate::policy_files::{Manifest, PolicyError, RunInfo, POLICY_FILE};
use std::path::Path;

/// `state_k <- 0.5 state_k + b_k + sum_j w_kj obs_j + 2 ((calls (k + 1)) mod 5)`,
/// `q_k = state_k`, with weights in [-1, 1) from a hash of (salt, k, j). Only exact float
/// operations in a fixed order, so two processes on one machine agree bit for bit.
#[derive(Debug, Clone)]
pub struct MockPolicy {
    obs_len: usize,
    n_actions: usize,
    salt: u64,
    state: Vec<f32>,
    calls: u64,
}

impl MockPolicy {
    /// A mock for observations of `obs_len` values and `n_actions` macro-actions; different
    /// `salt`s (use the agent index) give different policies.
    pub fn new(obs_len: usize, n_actions: usize, salt: u64) -> Self {
        MockPolicy {
            obs_len,
            n_actions,
            salt,
            state: vec![0.0; n_actions],
            calls: 0,
        }
    }
}

/// A weight in [-1, 1) from (salt, k, j) (splitmix64 finalizer).
fn weight(salt: u64, k: usize, j: usize) -> f32 {
    let mut z = salt
        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .wrapping_add((k as u64) << 32)
        .wrapping_add(j as u64 + 1);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 40) as f32 / (1u64 << 23) as f32 - 1.0
}

impl AgentPolicy for MockPolicy {
    fn obs_len(&self) -> usize {
        self.obs_len
    }
    fn n_actions(&self) -> usize {
        self.n_actions
    }
    fn reset(&mut self) {
        self.state.fill(0.0);
        self.calls = 0;
    }
    fn q_values(&mut self, obs: &[f32], _step: usize, q: &mut [f32]) {
        assert_eq!(
            obs.len(),
            self.obs_len,
            "mock policy: wrong observation length"
        );
        assert_eq!(q.len(), self.n_actions, "mock policy: wrong Q length");
        let calls = self.calls + 1;
        for (k, (state, q)) in self.state.iter().zip(q.iter_mut()).enumerate() {
            let mut drive = weight(self.salt, k, 0);
            for (j, &x) in obs.iter().enumerate() {
                drive += weight(self.salt, k, j + 1) * x;
            }
            let beat = 2.0 * ((calls * (k as u64 + 1)) % 5) as f32;
            *q = 0.5 * *state + drive + beat;
        }
        // As the trait asks: a non-finite step leaves the state as it was.
        if q.iter().all(|v| v.is_finite()) {
            self.calls = calls;
            self.state.copy_from_slice(q);
        }
    }
}

/// The small architecture mock exports declare (M = 4, H = 2): real, checkable weight files
/// of a few hundred bytes.
pub fn mock_architecture() -> Architecture {
    Architecture::ddrqn(4, 2)
}

fn mock_run() -> RunInfo {
    RunInfo {
        experiment: "mock".into(),
        method: "mock".into(),
        variant: String::new(),
        seed: 0,
        episodes_trained: 0,
        config: serde_json::json!({"note": "placeholder weights for the mock policy"}),
    }
}

/// Placeholder weights (zeros) for every agent of `env`, in the mock architecture.
fn mock_weights(env: EnvSpec) -> Result<Vec<Vec<u8>>, PolicyError> {
    let built = env.build().map_err(|e| PolicyError::Env {
        path: POLICY_FILE.into(),
        message: e.to_string(),
    })?;
    let arch = mock_architecture();
    Ok((0..built.n_agents())
        .map(|i| {
            synthetic_weights(&arch, built.obs_sizes()[i], built.n_actions()[i], |_, _| {
                0.0
            })
        })
        .collect())
}

/// Write a complete, verifiable policy directory for `env` with placeholder weights (zeros):
/// `macdec robot --mock` and `macdec deploy --mock` load it, check it, and run [`MockPolicy`]
/// instead of the weights.
pub fn write_mock_policy(dir: &Path, env: EnvSpec) -> Result<Manifest, PolicyError> {
    let weights = mock_weights(env.clone())?;
    Manifest::write_policy(dir, env, 0.98, mock_architecture(), mock_run(), &weights)
}

/// The manifest [`write_mock_policy`] writes, without touching the disk. Panics if `env` has
/// invalid parameters.
pub fn mock_manifest(env: EnvSpec) -> Manifest {
    let weights = mock_weights(env.clone()).expect("valid env spec for a mock manifest");
    Manifest::build(env, 0.98, mock_architecture(), mock_run(), &weights)
        .expect("mock weights fit the mock architecture")
}

/// Mock policies for every agent of `manifest`, salted by agent index (what the `--mock` robots
/// of a deployment run).
pub fn mock_policies(manifest: &Manifest) -> Vec<MockPolicy> {
    manifest
        .agents
        .iter()
        .map(|a| MockPolicy::new(a.obs_size, a.n_actions, a.index as u64))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_are_in_range_and_vary() {
        let ws: Vec<f32> = (0..4)
            .flat_map(|k| (0..4).map(move |j| (k, j)))
            .map(|(k, j)| weight(1, k, j))
            .collect();
        assert!(ws.iter().all(|w| (-1.0..1.0).contains(w)));
        let mut distinct = ws.clone();
        distinct.sort_by(f32::total_cmp);
        distinct.dedup();
        assert_eq!(distinct.len(), ws.len());
        assert_ne!(weight(1, 0, 0), weight(2, 0, 0));
    }

    #[test]
    fn q_depends_on_history_and_reset_restores_the_start() {
        let mut p = MockPolicy::new(2, 3, 0);
        let mut q1 = vec![0.0; 3];
        let mut q2 = vec![0.0; 3];
        p.q_values(&[1.0, 0.0], 0, &mut q1);
        p.q_values(&[1.0, 0.0], 0, &mut q2);
        assert_ne!(q1, q2);
        p.reset();
        p.q_values(&[1.0, 0.0], 0, &mut q2);
        assert_eq!(q1, q2);
    }

    #[test]
    fn mock_policy_dir_loads_and_verifies() {
        let dir = tempfile::tempdir().unwrap();
        let env = crate::envs::warehouse::spec(150, 0.0);
        let written = write_mock_policy(dir.path(), env.clone()).unwrap();
        let (read, agents) = crate::policy_files::load_all(dir.path()).unwrap();
        assert_eq!(read, written);
        assert_eq!(agents.len(), 3);
        assert_eq!(mock_manifest(env.clone()), written);
        let sizes: Vec<(usize, usize)> = mock_policies(&read)
            .iter()
            .map(|p| (p.obs_len(), p.n_actions()))
            .collect();
        assert_eq!(sizes, vec![(13, 3), (13, 3), (4, 6)]);
    }
}
