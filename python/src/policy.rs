//! `macdec.Policy`: a policy directory (a run's `policy/`, an export, an import) loaded and
//! checked by the one loader ([`macdec::policy_files::load_all`]), each agent's net stepped as
//! `macdec eval` steps it: the hidden state advances only when that agent's macro-action is
//! done, and the greedy macro-action is the highest score (ties to the lowest index).

use macdec::deploy::policy::net_policy::{load_net, NetPolicy};
use macdec::deploy::{greedy_action, AgentPolicy};
use macdec::policy_files::{load_all, Manifest, PolicyEnv, POLICY_DIR, POLICY_FILE};
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::exceptions::{PyFileNotFoundError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::params;

/// A loaded policy: every agent's net with its hidden state.
#[pyclass(module = "macdec._macdec")]
pub struct Policy {
    manifest: Manifest,
    dir: PathBuf,
    agents: Vec<NetPolicy>,
    /// Each agent's last decided macro-action (`None` before its first decision).
    last: Vec<Option<usize>>,
    kinds: Vec<&'static str>,
}

/// The policy directory `dir` names: itself, or a run directory's `policy/`.
fn policy_dir(dir: &Path) -> PathBuf {
    let run_policy = dir.join(POLICY_DIR);
    if !dir.join(POLICY_FILE).exists() && run_policy.join(POLICY_FILE).exists() {
        run_policy
    } else {
        dir.to_path_buf()
    }
}

#[pymethods]
impl Policy {
    /// Load the policy directory `dir` (or a run directory, whose `policy/` is read).
    #[staticmethod]
    fn load(py: Python<'_>, dir: PathBuf) -> PyResult<Self> {
        if !dir.is_dir() {
            return Err(PyFileNotFoundError::new_err(format!(
                "{}: no such policy directory",
                dir.display()
            )));
        }
        let dir = policy_dir(&dir);
        let loaded = py.allow_threads(|| {
            let (manifest, verified) = load_all(&dir).map_err(|e| e.to_string())?;
            let nets = verified
                .iter()
                .map(|v| load_net(&manifest, v).map_err(|e| e.to_string()))
                .collect::<Result<Vec<_>, _>>()?;
            Ok::<_, String>((manifest, nets))
        });
        let (manifest, nets) =
            loaded.map_err(|e| PyValueError::new_err(format!("loading {}: {e}", dir.display())))?;
        let kinds = nets
            .iter()
            .map(|n| if n.as_q().is_some() { "q" } else { "actor" })
            .collect();
        let agents: Vec<NetPolicy> = nets
            .into_iter()
            .map(|n| NetPolicy::new(Arc::new(n)))
            .collect();
        Ok(Policy {
            last: vec![None; agents.len()],
            manifest,
            dir,
            agents,
            kinds,
        })
    }

    /// The policy directory read.
    #[getter]
    fn dir(&self) -> PathBuf {
        self.dir.clone()
    }

    /// Number of agents.
    #[getter]
    fn n_agents(&self) -> usize {
        self.agents.len()
    }

    /// Each agent's observation length.
    #[getter]
    fn obs_sizes(&self) -> Vec<usize> {
        self.agents.iter().map(|a| a.obs_len()).collect()
    }

    /// Each agent's number of macro-actions.
    #[getter]
    fn n_actions(&self) -> Vec<usize> {
        self.agents.iter().map(|a| a.n_actions()).collect()
    }

    /// Each agent's net: `"q"` (scores are Q-values) or `"actor"` (log-probabilities).
    #[getter]
    fn kinds(&self) -> Vec<&'static str> {
        self.kinds.clone()
    }

    /// The discount per primitive step the policy was trained and evaluated under.
    #[getter]
    fn discount(&self) -> f64 {
        self.manifest.discount
    }

    /// The run it came from: experiment, method, variant, seed, episodes_trained.
    #[getter]
    fn run<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let r = &self.manifest.run;
        let d = PyDict::new_bound(py);
        d.set_item("experiment", &r.experiment)?;
        d.set_item("method", &r.method)?;
        d.set_item("variant", &r.variant)?;
        d.set_item("seed", r.seed)?;
        d.set_item("episodes_trained", r.episodes_trained)?;
        Ok(d)
    }

    /// The domain's `env_name` and its keys, to build its environment: `(env_id, params)`;
    /// `None` for a domain this build does not have.
    fn env_spec<'py>(&self, py: Python<'py>) -> Option<(&'static str, Bound<'py, PyDict>)> {
        match &self.manifest.env {
            PolicyEnv::Known(spec) => Some((spec.env_name(), params::table_to_py(py, spec.keys()))),
            _ => None,
        }
    }

    /// Each agent's macro-action names.
    fn action_names(&self) -> Vec<Vec<String>> {
        self.manifest
            .agents
            .iter()
            .map(|a| a.action_names.clone())
            .collect()
    }

    /// Zero every agent's hidden state, as at an episode's start.
    fn reset(&mut self) {
        for a in &mut self.agents {
            a.reset();
        }
        self.last.fill(None);
    }

    /// One primitive step: each agent whose `mac_done[i]` is true reads `obs[i]` and picks its
    /// greedy macro-action (its hidden state advances); the others keep theirs. Returns
    /// `(actions, scores)`: each agent's current macro-action (`None` before its first
    /// decision) and, for the agents that decided, their scores (`None` for the others).
    #[allow(clippy::type_complexity)]
    fn act<'py>(
        &mut self,
        py: Python<'py>,
        obs: Vec<PyReadonlyArray1<'py, f32>>,
        mac_done: Vec<bool>,
    ) -> PyResult<(Vec<Option<usize>>, Vec<Option<Bound<'py, PyArray1<f32>>>>)> {
        let n = self.agents.len();
        if obs.len() != n || mac_done.len() != n {
            return Err(PyValueError::new_err(format!(
                "expected one observation and one mac_done flag per agent ({n}), got {} and {}",
                obs.len(),
                mac_done.len()
            )));
        }
        for (i, (o, agent)) in obs.iter().zip(&self.agents).enumerate() {
            if mac_done[i] && o.len()? != agent.obs_len() {
                return Err(PyValueError::new_err(format!(
                    "agent {i}: observation has {} values, the policy expects {}",
                    o.len()?,
                    agent.obs_len()
                )));
            }
        }
        let mut scores = Vec::with_capacity(n);
        for (i, agent) in self.agents.iter_mut().enumerate() {
            if !mac_done[i] {
                scores.push(None);
                continue;
            }
            let o = obs[i].as_slice()?;
            let mut q = vec![0.0f32; agent.n_actions()];
            agent.q_values(o, &mut q);
            if let Some(bad) = q.iter().find(|v| !v.is_finite()) {
                return Err(PyRuntimeError::new_err(format!(
                    "agent {i}: the net answered a non-finite score ({bad}); the observation is out of the range it was trained on"
                )));
            }
            self.last[i] = Some(greedy_action(&q));
            scores.push(Some(q.into_pyarray_bound(py)));
        }
        Ok((self.last.clone(), scores))
    }
}
