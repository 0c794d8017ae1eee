//! `macdec.Policy`: a policy directory (a run's `policy/`, an export, an import) loaded and
//! checked by the one loader ([`Manifest::read`], [`Manifest::verify_agent`]), stepped as
//! `macdec eval` steps it: with the nets its evaluations used (each agent's own, or one
//! centralized net for the team when the policy acts only centrally: Cen-DDRQN's Q-net,
//! Mac-CAC's actor), each agent deciding only when its macro-action is done. Greedy by default
//! (the highest score, ties to the lowest index); an actor may sample instead, from the streams
//! `macdec eval --sample` draws from (the run seed's evaluation stream).

use crate::guarded;
use macdec::deploy::drive::link::choose_action;
use macdec::deploy::drive::local_eval::{agent_sampler, Choice};
use macdec::deploy::drive::team::CentralPolicy;
use macdec::deploy::policy::net_policy::NetPolicy;
use macdec::deploy::AgentPolicy;
use macdec::envs::EnvRng;
use macdec::experiment::definition::seeds::{stream, Role};
use macdec::nn::ActingNet;
use macdec::policy_files::{
    Manifest, NetKind, NetRole, PolicyEnv, PolicyError, POLICY_DIR, POLICY_FILE,
};
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::exceptions::{PyFileNotFoundError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::params;

/// One agent's own net, its hidden state and (for an actor) its sampling stream.
struct AgentNet {
    policy: NetPolicy,
    sampler: Option<EnvRng>,
}

/// Who acts: each agent with its own net, or one centralized net for the team.
enum Acting {
    Agents(Vec<AgentNet>),
    Team(Box<CentralPolicy>),
}

/// A loaded policy: the nets its evaluations used, with their hidden states.
#[pyclass(module = "macdec._macdec")]
pub struct Policy {
    manifest: Manifest,
    dir: PathBuf,
    acting: Acting,
    /// Each agent's last decided macro-action (`None` before its first decision).
    last: Vec<Option<usize>>,
    /// The kind of net each agent acts with (the team's for a centralized policy).
    kinds: Vec<&'static str>,
    probs: Vec<f64>,
    /// `act` calls since `reset`: the primitive step an observation was made at, which ACAC's
    /// actors read (their time embedding).
    steps: usize,
}

/// `q` or `actor`, as Python reports a net's kind.
fn kind_name(net: &ActingNet) -> &'static str {
    match NetKind::of(net) {
        NetKind::Q => "q",
        NetKind::Actor => "actor",
    }
}

/// The evaluated nets of the policy in `dir`, checked, with samplers from the evaluation stream
/// of the run's seed (the streams `macdec eval --sample` uses).
fn load_acting(dir: &Path) -> Result<(Manifest, Acting, Vec<&'static str>), PolicyError> {
    let manifest = Manifest::read(dir)?;
    let rng = stream(manifest.run.seed, Role::EvalEnv);
    let n = manifest.agents.len();
    match manifest.evaluated {
        NetRole::Dec => {
            let mut agents = Vec::with_capacity(n);
            let mut kinds = Vec::with_capacity(n);
            for agent in 0..n {
                let verified = manifest.verify_agent(dir, agent)?;
                let net = manifest.agent_acting_net(&verified)?;
                kinds.push(kind_name(&net));
                // Every actor samples (MacroMARL's and ACAC's); a Q-net has no sampler.
                let sampler =
                    (NetKind::of(&net) == NetKind::Actor).then(|| agent_sampler(&rng, agent));
                agents.push(AgentNet {
                    policy: NetPolicy::new(Arc::new(net)),
                    sampler,
                });
            }
            Ok((manifest, Acting::Agents(agents), kinds))
        }
        NetRole::Cen => {
            let index = manifest
                .cen_net()
                .ok_or_else(|| PolicyError::NoCentralNet {
                    method: manifest.run.method.clone(),
                })?;
            let net = manifest.load_acting_net(dir, index)?;
            let kinds = vec![kind_name(&net); n];
            let n_actions = manifest.agents.iter().map(|a| a.n_actions).collect();
            let team = CentralPolicy::new(net, n_actions, Choice::Greedy, &rng)?;
            Ok((manifest, Acting::Team(Box::new(team)), kinds))
        }
    }
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
        guarded(|| {
            if !dir.is_dir() {
                return Err(PyFileNotFoundError::new_err(format!(
                    "{}: no such policy directory",
                    dir.display()
                )));
            }
            let dir = policy_dir(&dir);
            let loaded = py.allow_threads(|| load_acting(&dir).map_err(|e| e.to_string()));
            let (manifest, acting, kinds) = loaded
                .map_err(|e| PyValueError::new_err(format!("loading {}: {e}", dir.display())))?;
            Ok(Policy {
                last: vec![None; manifest.agents.len()],
                manifest,
                dir,
                acting,
                kinds,
                probs: Vec::new(),
                steps: 0,
            })
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
        self.manifest.agents.len()
    }

    /// Each agent's observation length.
    #[getter]
    fn obs_sizes(&self) -> Vec<usize> {
        self.manifest.agents.iter().map(|a| a.obs_size).collect()
    }

    /// Each agent's number of macro-actions.
    #[getter]
    fn n_actions(&self) -> Vec<usize> {
        self.manifest.agents.iter().map(|a| a.n_actions).collect()
    }

    /// The kind of net each agent acts with: `"q"` (scores are Q-values) or `"actor"`
    /// (log-probabilities); for a centralized policy, the team's net's kind for every agent.
    #[getter]
    fn kinds(&self) -> Vec<&'static str> {
        self.kinds.clone()
    }

    /// Whether the policy acts through one centralized net for the whole team (Cen-DDRQN,
    /// Mac-CAC): no robot can serve one agent of it.
    #[getter]
    fn centralized(&self) -> bool {
        matches!(self.acting, Acting::Team(_))
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

    /// Zero every hidden state, as at an episode's start (sampling streams go on, as across
    /// `macdec eval --sample`'s episodes).
    fn reset(&mut self) -> PyResult<()> {
        guarded(|| {
            match &mut self.acting {
                Acting::Agents(agents) => agents.iter_mut().for_each(|a| a.policy.reset()),
                Acting::Team(team) => team.reset(),
            }
            self.last.fill(None);
            self.steps = 0;
            Ok(())
        })
    }

    /// One primitive step (the policy counts them from `reset`: ACAC's actors read that count
    /// as the time of the observation): each agent whose `mac_done[i]` is true decides (greedy, or with
    /// `sample` drawn from its actor's distribution; a Q-net refuses to sample), the others keep
    /// their macro-actions. Agents with their own nets read `obs[i]` (their hidden states
    /// advance); a centralized net reads every agent's observation, concatenated in agent
    /// order, and keeps the busy agents' running macro-actions. Returns `(actions, scores)`:
    /// each agent's current macro-action (`None` before its first decision) and the raw scores
    /// of the decision: one entry per agent (`None` for those that did not decide), or for a
    /// centralized policy one entry, the team's scores over joint macro-actions (`None` when
    /// no agent decided).
    #[pyo3(signature = (obs, mac_done, sample=false))]
    #[allow(clippy::type_complexity)]
    fn act<'py>(
        &mut self,
        py: Python<'py>,
        obs: Vec<PyReadonlyArray1<'py, f32>>,
        mac_done: Vec<bool>,
        sample: bool,
    ) -> PyResult<(Vec<Option<usize>>, Vec<Option<Bound<'py, PyArray1<f32>>>>)> {
        guarded(|| {
            let n = self.manifest.agents.len();
            if obs.len() != n || mac_done.len() != n {
                return Err(PyValueError::new_err(format!(
                    "expected one observation and one mac_done flag per agent ({n}), got {} and {}",
                    obs.len(),
                    mac_done.len()
                )));
            }
            let centralized = matches!(self.acting, Acting::Team(_));
            for (i, (o, layout)) in obs.iter().zip(&self.manifest.agents).enumerate() {
                if (mac_done[i] || centralized) && o.len()? != layout.obs_size {
                    return Err(PyValueError::new_err(format!(
                        "agent {i}: observation has {} values, the policy expects {}",
                        o.len()?,
                        layout.obs_size
                    )));
                }
            }
            if sample {
                if let Some(i) = self.kinds.iter().position(|&k| k == "q") {
                    let whose = if centralized {
                        "the centralized net".to_string()
                    } else {
                        format!("agent {i}'s net")
                    };
                    return Err(PyValueError::new_err(format!(
                        "sample=True: {whose} is a Q-net, whose scores are Q-values, not log-probabilities to sample from; Q-net policies act greedily (sample=False)"
                    )));
                }
            }
            let choice = if sample {
                Choice::Sampled
            } else {
                Choice::Greedy
            };
            match &mut self.acting {
                Acting::Agents(agents) => {
                    // All or nothing: every deciding agent's step is computed first; one
                    // non-finite answer leaves every hidden state, sampling stream and last
                    // action as they were (as a robot's error reply does).
                    let mut proposed = Vec::with_capacity(n);
                    for (i, agent) in agents.iter_mut().enumerate() {
                        if !mac_done[i] {
                            proposed.push(None);
                            continue;
                        }
                        let mut q = vec![0.0f32; agent.policy.n_actions()];
                        if !agent.policy.propose(obs[i].as_slice()?, self.steps, &mut q) {
                            let bad = q.iter().find(|v| !v.is_finite()).copied();
                            let what = match bad {
                                Some(v) => format!("a non-finite score ({v})"),
                                None => "a non-finite hidden state".into(),
                            };
                            return Err(PyRuntimeError::new_err(format!(
                                "agent {i}: the net answered {what}; the observation is out of the range it was trained on (no agent's state changed)"
                            )));
                        }
                        proposed.push(Some(q));
                    }
                    let mut scores = Vec::with_capacity(n);
                    for (i, (agent, q)) in agents.iter_mut().zip(proposed).enumerate() {
                        let Some(q) = q else {
                            scores.push(None);
                            continue;
                        };
                        agent.policy.commit();
                        let sampler = if sample { agent.sampler.as_mut() } else { None };
                        self.last[i] = Some(choose_action(&q, sampler, &mut self.probs));
                        scores.push(Some(q.into_pyarray_bound(py)));
                    }
                    self.steps += 1;
                    Ok((self.last.clone(), scores))
                }
                Acting::Team(team) => {
                    let free = &mac_done;
                    let mut running = Vec::with_capacity(n);
                    for (i, last) in self.last.iter().enumerate() {
                        match (free[i], last) {
                            (false, None) if free.iter().any(|&f| f) => {
                                return Err(PyValueError::new_err(format!(
                                    "agent {i} is not done but has no macro-action yet: every agent decides at an episode's start (call reset() between episodes)"
                                )))
                            }
                            (_, last) => running.push(last.unwrap_or(0)),
                        }
                    }
                    let mut joint_obs = Vec::with_capacity(team.net().obs_len());
                    for o in &obs {
                        joint_obs.extend_from_slice(o.as_slice()?);
                    }
                    let mut actions = running.clone();
                    let scores = team
                        .decide_joint(&joint_obs, free, &running, choice, &mut actions)
                        .map_err(PyRuntimeError::new_err)?
                        .map(|s| s.to_vec().into_pyarray_bound(py));
                    if scores.is_some() {
                        for (i, &a) in actions.iter().enumerate() {
                            if free[i] {
                                self.last[i] = Some(a);
                            }
                        }
                    }
                    self.steps += 1;
                    Ok((self.last.clone(), vec![scores]))
                }
            }
        })
    }
}
