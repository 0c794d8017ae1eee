//! The environments: one built domain with its random stream ([`Env`], behind the PettingZoo
//! `ParallelEnv` of `macdec/_parallel.py`) and N copies stepped in one call ([`VectorEnv`]).
//! Domains are built by [`EnvSpec::new`] from the id and keys, exactly as configs and `macdec
//! replay` build them.

use crate::guarded;
use macdec::envs::{registry, AnyEnv, EnvError, EnvRng, EnvSpec, MacroEnv, StepOutcome};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyReadonlyArray2};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rand::SeedableRng;

use crate::params;

/// The spec of `env_id` with `params` (a dict of the domain's keys), errors as ValueError.
pub fn spec_of(env_id: &str, params: Option<&Bound<'_, PyDict>>) -> PyResult<EnvSpec> {
    let given = match params {
        Some(p) => params::to_table(p, None)?,
        None => toml::Table::new(),
    };
    EnvSpec::new(env_id, &given).map_err(|e| PyValueError::new_err(format!("{env_id}: {e}")))
}

/// Build `spec`'s environment, errors as ValueError.
pub fn build(spec: &EnvSpec) -> PyResult<AnyEnv> {
    spec.build()
        .map_err(|e| PyValueError::new_err(format!("{}: {e}", spec.env_name())))
}

/// A step refused by the environment, as the Python exception it is.
fn step_error(e: EnvError) -> PyErr {
    match e {
        EnvError::EpisodeOver => {
            PyRuntimeError::new_err("step called after the episode ended; call reset() first")
        }
        other => PyValueError::new_err(other.to_string()),
    }
}

/// The random stream of a seed; `None` draws a seed from the operating system.
fn rng_of(seed: Option<u64>) -> EnvRng {
    match seed {
        Some(s) => EnvRng::seed_from_u64(s),
        None => EnvRng::from_entropy(),
    }
}

/// How an episode ended, as PettingZoo reports it: the horizon is a truncation (also in the
/// ICRA domains, whose reference treats it as terminal), a terminal state a termination.
fn end_flags(out: &StepOutcome, t: usize, horizon: usize) -> (bool, bool) {
    let truncated = out.done && (out.truncated || t >= horizon);
    (out.done && !truncated, truncated)
}

/// Which macro-actions each agent's entry can start: all of a free agent's, only the running
/// one of a busy agent (whatever it is sent, it keeps that one). Row i has `n_actions[i]`
/// meaningful entries, the rest false.
fn write_mask<E: MacroEnv>(env: &E, width: usize, out: &mut [bool]) {
    for (agent, row) in out.chunks_mut(width).enumerate().take(env.n_agents()) {
        row.fill(false);
        if env.is_free(agent) {
            row[..env.n_actions()[agent]].fill(true);
        } else {
            row[env.executed()[agent]] = true;
        }
    }
}

/// Copy every agent's observation into `out` ([n_agents, width], zero-padded).
fn write_obs<E: MacroEnv>(env: &E, width: usize, out: &mut [f32]) {
    for (agent, row) in out.chunks_mut(width).enumerate().take(env.n_agents()) {
        let o = env.obs(agent);
        row[..o.len()].copy_from_slice(o);
        row[o.len()..].fill(0.0);
    }
}

/// One environment of a domain and its random stream: the core of `macdec.parallel_env`.
#[pyclass(module = "macdec._macdec")]
pub struct Env {
    spec: EnvSpec,
    env: AnyEnv,
    rng: EnvRng,
    actions: Vec<usize>,
    /// Whether an episode is running (reset called, not yet done).
    running: bool,
}

#[pymethods]
impl Env {
    /// Build the domain `env_id` (`"BP_MA"`, `"OSD-D-v7"`, ...) with its keys `params`.
    #[new]
    #[pyo3(signature = (env_id, params=None))]
    fn new(env_id: &str, params: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        guarded(|| {
            let spec = spec_of(env_id, params)?;
            let env = build(&spec)?;
            let n = env.n_agents();
            Ok(Env {
                spec,
                env,
                rng: rng_of(None),
                actions: vec![0; n],
                running: false,
            })
        })
    }

    /// The domain's `env_name` (`BP_MA`, `OSD_S_4`, `BP-MA-v0`, ...).
    #[getter]
    fn env_name(&self) -> &'static str {
        self.spec.env_name()
    }

    /// Every key of the domain with its value (the given ones and the defaults).
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> Bound<'py, PyDict> {
        params::table_to_py(py, self.spec.keys())
    }

    /// Number of agents.
    #[getter]
    fn n_agents(&self) -> usize {
        self.env.n_agents()
    }

    /// Each agent's observation length.
    #[getter]
    fn obs_sizes(&self) -> Vec<usize> {
        self.env.obs_sizes().to_vec()
    }

    /// Each agent's number of macro-actions.
    #[getter]
    fn n_actions(&self) -> Vec<usize> {
        self.env.n_actions().to_vec()
    }

    /// The horizon in primitive steps.
    #[getter]
    fn horizon(&self) -> usize {
        self.env.horizon()
    }

    /// Length of the global state (0 when the domain has none).
    #[getter]
    fn state_size(&self) -> usize {
        self.env.state_size()
    }

    /// Primitive steps since reset.
    #[getter]
    fn t(&self) -> usize {
        self.env.t()
    }

    /// A short description (`Box Pushing 10x10, horizon 100`).
    fn describe(&self) -> PyResult<String> {
        guarded(|| Ok(self.env.describe()))
    }

    /// The names of agent `agent`'s macro-actions.
    fn action_names(&self, agent: usize) -> PyResult<Vec<&'static str>> {
        self.check_agent(agent)?;
        Ok(self.env.action_names(agent).to_vec())
    }

    /// The names of agent `agent`'s observation entries.
    fn obs_names(&self, agent: usize) -> PyResult<Vec<String>> {
        guarded(|| {
            self.check_agent(agent)?;
            Ok(self.env.obs_names(agent))
        })
    }

    /// Start an episode; `seed` restarts the random stream (`None` continues it).
    #[pyo3(signature = (seed=None))]
    fn reset(&mut self, seed: Option<u64>) -> PyResult<()> {
        guarded(|| {
            if let Some(s) = seed {
                self.rng = rng_of(Some(s));
            }
            self.env.reset(&mut self.rng);
            self.running = true;
            Ok(())
        })
    }

    /// One primitive step. `actions[i]` is agent i's macro-action, used only if it is free; a
    /// busy agent's entry is ignored (pass -1). Returns `(reward, terminated, truncated)`.
    fn step(&mut self, actions: Vec<i64>) -> PyResult<(f64, bool, bool)> {
        guarded(|| {
            if !self.running {
                return Err(step_error(EnvError::EpisodeOver));
            }
            let n = self.env.n_agents();
            if actions.len() != n {
                return Err(step_error(EnvError::WrongActionCount {
                    expected: n,
                    got: actions.len(),
                }));
            }
            for (agent, &a) in actions.iter().enumerate() {
                self.actions[agent] = if self.env.is_free(agent) {
                    let n_actions = self.env.n_actions()[agent];
                    usize::try_from(a)
                        .ok()
                        .filter(|&a| a < n_actions)
                        .ok_or_else(|| {
                            PyValueError::new_err(format!(
                                "agent {agent} may choose now and needs a macro-action in 0..{n_actions}, got {a}"
                            ))
                        })?
                } else {
                    0
                };
            }
            let out = self
                .env
                .step(&self.actions, &mut self.rng)
                .map_err(step_error)?;
            if out.done {
                self.running = false;
            }
            let (terminated, truncated) = end_flags(&out, self.env.t(), self.env.horizon());
            Ok((out.reward, terminated, truncated))
        })
    }

    /// Agent `agent`'s current (held) macro-observation, float32.
    fn obs<'py>(&self, py: Python<'py>, agent: usize) -> PyResult<Bound<'py, PyArray1<f32>>> {
        self.check_agent(agent)?;
        Ok(PyArray1::from_slice_bound(py, self.env.obs(agent)))
    }

    /// Whether each agent's macro-action ended in the last step (it may choose now).
    fn mac_done(&self) -> Vec<bool> {
        self.env.mac_done().to_vec()
    }

    /// The macro-action each agent ran in the last step.
    fn executed(&self) -> Vec<usize> {
        self.env.executed().to_vec()
    }

    /// Agent `agent`'s action mask: all of a free agent's macro-actions, a busy agent's running one.
    fn action_mask<'py>(
        &self,
        py: Python<'py>,
        agent: usize,
    ) -> PyResult<Bound<'py, PyArray1<i8>>> {
        self.check_agent(agent)?;
        let n = self.env.n_actions()[agent];
        let mask: Vec<i8> = if self.env.is_free(agent) {
            vec![1; n]
        } else {
            (0..n)
                .map(|a| i8::from(a == self.env.executed()[agent]))
                .collect()
        };
        Ok(mask.into_pyarray_bound(py))
    }

    /// The global state (float32), or `None` for a domain without one.
    fn state<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray1<f32>>>> {
        guarded(|| {
            let n = self.env.state_size();
            Ok((n > 0).then(|| {
                let mut s = vec![0.0; n];
                self.env.write_state(&mut s);
                s.into_pyarray_bound(py)
            }))
        })
    }

    /// The picture `macdec render` draws, as an RGB array [height, width, 3] of uint8, with the
    /// status bar showing `team_return`; `None` for a domain that draws none.
    #[pyo3(signature = (team_return=0.0))]
    fn render_rgb<'py>(
        &self,
        py: Python<'py>,
        team_return: f64,
    ) -> PyResult<Option<Bound<'py, PyArray3<u8>>>> {
        guarded(|| {
            let Some(canvas) = macdec::render::draw_frame(&self.env, team_return) else {
                return Ok(None);
            };
            let palette = macdec::draw::palette::gif_palette();
            let mut rgb = Vec::with_capacity(canvas.pixels().len() * 3);
            for &p in canvas.pixels() {
                let at = 3 * p as usize;
                rgb.extend_from_slice(palette.get(at..at + 3).unwrap_or(&[0, 0, 0]));
            }
            let image = ndarray::Array3::from_shape_vec((canvas.height(), canvas.width(), 3), rgb)
                .expect("one RGB triple per pixel");
            Ok(Some(image.into_pyarray_bound(py)))
        })
    }

    /// A text picture of the state.
    fn render_ascii(&self) -> PyResult<String> {
        guarded(|| Ok(self.env.render_ascii()))
    }
}

impl Env {
    fn check_agent(&self, agent: usize) -> PyResult<()> {
        let n = self.env.n_agents();
        if agent >= n {
            return Err(PyValueError::new_err(format!(
                "agent {agent} is out of range: the domain has {n} agents"
            )));
        }
        Ok(())
    }
}

/// N copies of one domain stepped in one call, NumPy arrays in and out: the core of
/// `macdec.vector_env`. Copy k draws from the stream of seed `seed + k`; an episode that ends
/// is reset in the same call (its last observation is in `final_obs`).
#[pyclass(module = "macdec._macdec")]
pub struct VectorEnv {
    spec: EnvSpec,
    envs: Vec<AnyEnv>,
    rngs: Vec<EnvRng>,
    n_agents: usize,
    obs_width: usize,
    act_width: usize,
    actions: Vec<usize>,
    reset_done: bool,
}

/// What one vector step fills, per copy: observations after any reset, last observations,
/// rewards, end flags, macro-action flags, executed macro-actions and masks.
struct Outputs {
    obs: Vec<f32>,
    final_obs: Vec<f32>,
    rewards: Vec<f64>,
    terminated: Vec<bool>,
    truncated: Vec<bool>,
    /// Who chooses at the next step: the step's flags, or every agent of a copy just reset.
    mac_done: Vec<bool>,
    /// The step's own flags, also for a copy that ended and was reset.
    final_mac_done: Vec<bool>,
    executed: Vec<i64>,
    mask: Vec<bool>,
}

/// Copies one vector environment may hold (checked at 65 536; every copy is a whole
/// environment, so the bound keeps `vector_env(id, 10**7)` a ValueError instead of an abort).
pub const MAX_NUM_ENVS: usize = 65_536;

#[pymethods]
impl VectorEnv {
    /// `num_envs` copies of the domain `env_id` with its keys `params`.
    #[new]
    #[pyo3(signature = (env_id, num_envs, params=None))]
    fn new(env_id: &str, num_envs: usize, params: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        guarded(|| {
            if num_envs == 0 || num_envs > MAX_NUM_ENVS {
                return Err(PyValueError::new_err(format!(
                    "num_envs must be 1..={MAX_NUM_ENVS}, got {num_envs}"
                )));
            }
            let spec = spec_of(env_id, params)?;
            let first = build(&spec)?;
            let n_agents = first.n_agents();
            let obs_width = first.obs_sizes().iter().copied().max().unwrap_or(0);
            let act_width = first.n_actions().iter().copied().max().unwrap_or(0);
            let envs = vec![first; num_envs];
            Ok(VectorEnv {
                spec,
                rngs: (0..num_envs).map(|_| rng_of(None)).collect(),
                envs,
                n_agents,
                obs_width,
                act_width,
                actions: vec![0; n_agents],
                reset_done: false,
            })
        })
    }

    /// Number of copies.
    #[getter]
    fn num_envs(&self) -> usize {
        self.envs.len()
    }

    /// The domain's `env_name`.
    #[getter]
    fn env_name(&self) -> &'static str {
        self.spec.env_name()
    }

    /// Every key of the domain with its value.
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> Bound<'py, PyDict> {
        params::table_to_py(py, self.spec.keys())
    }

    /// Number of agents.
    #[getter]
    fn n_agents(&self) -> usize {
        self.n_agents
    }

    /// Each agent's observation length (observations are padded with zeros to the longest).
    #[getter]
    fn obs_sizes(&self) -> Vec<usize> {
        self.envs[0].obs_sizes().to_vec()
    }

    /// Each agent's number of macro-actions (masks are padded with false to the most).
    #[getter]
    fn n_actions(&self) -> Vec<usize> {
        self.envs[0].n_actions().to_vec()
    }

    /// The horizon in primitive steps.
    #[getter]
    fn horizon(&self) -> usize {
        self.envs[0].horizon()
    }

    /// Reset every copy; copy k restarts its stream at `seed + k` (`None`: fresh OS seeds).
    /// Returns `(obs [N, n_agents, max_obs] float32, action_mask [N, n_agents, max_actions] bool)`.
    #[pyo3(signature = (seed=None))]
    #[allow(clippy::type_complexity)]
    fn reset<'py>(
        &mut self,
        py: Python<'py>,
        seed: Option<u64>,
    ) -> PyResult<(Bound<'py, PyArray3<f32>>, Bound<'py, PyArray3<bool>>)> {
        guarded(|| {
            let (n, a, w, m) = (
                self.envs.len(),
                self.n_agents,
                self.obs_width,
                self.act_width,
            );
            let mut obs = vec![0.0f32; n * a * w];
            let mut mask = vec![false; n * a * m];
            let envs = &mut self.envs;
            let rngs = &mut self.rngs;
            py.allow_threads(|| {
                for (k, (env, rng)) in envs.iter_mut().zip(rngs.iter_mut()).enumerate() {
                    if let Some(s) = seed {
                        *rng = rng_of(Some(s.wrapping_add(k as u64)));
                    }
                    env.reset(rng);
                    write_obs(env, w, &mut obs[k * a * w..(k + 1) * a * w]);
                    write_mask(env, m, &mut mask[k * a * m..(k + 1) * a * m]);
                }
            });
            self.reset_done = true;
            Ok((array3(py, obs, (n, a, w)), array3(py, mask, (n, a, m))))
        })
    }

    /// One primitive step of every copy. `actions`: int64 [N, n_agents], a busy agent's entry
    /// ignored (pass -1). Returns `(obs, rewards [N] float64, terminations [N] bool,
    /// truncations [N] bool, infos)` where `infos` holds `mac_done` [N, n_agents] bool (who
    /// chooses at the next step: all agents of a copy that ended and was reset),
    /// `final_mac_done` (the step's own flags, before any reset), `executed` [N, n_agents]
    /// int64, `action_mask` and `final_obs` (the observations at the end of this step, before
    /// an ended copy was reset).
    #[allow(clippy::type_complexity)]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        actions: PyReadonlyArray2<'py, i64>,
    ) -> PyResult<(
        Bound<'py, PyArray3<f32>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyDict>,
    )> {
        guarded(|| {
            if !self.reset_done {
                return Err(PyRuntimeError::new_err("call reset() before step()"));
            }
            let (n, a, w, m) = (
                self.envs.len(),
                self.n_agents,
                self.obs_width,
                self.act_width,
            );
            let view = actions.as_array();
            if view.shape() != [n, a] {
                return Err(PyValueError::new_err(format!(
                    "actions must have shape (num_envs, n_agents) = ({n}, {a}), got {:?}",
                    view.shape()
                )));
            }
            let flat: Vec<i64> = view.iter().copied().collect();
            let mut out = Outputs {
                obs: vec![0.0; n * a * w],
                final_obs: vec![0.0; n * a * w],
                rewards: vec![0.0; n],
                terminated: vec![false; n],
                truncated: vec![false; n],
                mac_done: vec![false; n * a],
                final_mac_done: vec![false; n * a],
                executed: vec![0; n * a],
                mask: vec![false; n * a * m],
            };
            let envs = &mut self.envs;
            let rngs = &mut self.rngs;
            let scratch = &mut self.actions;
            py.allow_threads(|| step_all(envs, rngs, scratch, &flat, (a, w, m), &mut out))?;
            let infos = PyDict::new_bound(py);
            infos.set_item("mac_done", array2(py, out.mac_done, (n, a)))?;
            infos.set_item("final_mac_done", array2(py, out.final_mac_done, (n, a)))?;
            infos.set_item("executed", array2(py, out.executed, (n, a)))?;
            infos.set_item("action_mask", array3(py, out.mask, (n, a, m)))?;
            infos.set_item("final_obs", array3(py, out.final_obs, (n, a, w)))?;
            Ok((
                array3(py, out.obs, (n, a, w)),
                out.rewards.into_pyarray_bound(py),
                out.terminated.into_pyarray_bound(py),
                out.truncated.into_pyarray_bound(py),
                infos,
            ))
        })
    }
}

/// Step every copy with its row of `flat` (agents' entries, [N * a]), resetting ended copies.
fn step_all(
    envs: &mut [AnyEnv],
    rngs: &mut [EnvRng],
    scratch: &mut [usize],
    flat: &[i64],
    (a, w, m): (usize, usize, usize),
    out: &mut Outputs,
) -> PyResult<()> {
    // Every free agent's entry is checked before any copy steps, so a bad one changes nothing.
    for (k, env) in envs.iter().enumerate() {
        for agent in (0..a).filter(|&i| env.is_free(i)) {
            let entry = flat[k * a + agent];
            let n_actions = env.n_actions()[agent];
            if usize::try_from(entry).map_or(true, |x| x >= n_actions) {
                return Err(PyValueError::new_err(format!(
                    "env {k}, agent {agent} may choose now and needs a macro-action in 0..{n_actions}, got {entry}"
                )));
            }
        }
    }
    for (k, (env, rng)) in envs.iter_mut().zip(rngs.iter_mut()).enumerate() {
        for agent in 0..a {
            let entry = flat[k * a + agent];
            scratch[agent] = if env.is_free(agent) {
                entry as usize
            } else {
                0
            };
        }
        let step = env.step(scratch, rng).map_err(step_error)?;
        let (terminated, truncated) = end_flags(&step, env.t(), env.horizon());
        out.rewards[k] = step.reward;
        out.terminated[k] = terminated;
        out.truncated[k] = truncated;
        for agent in 0..a {
            out.final_mac_done[k * a + agent] = env.mac_done()[agent];
            out.executed[k * a + agent] = env.executed()[agent] as i64;
        }
        let rows = k * a * w..(k + 1) * a * w;
        write_obs(env, w, &mut out.final_obs[rows.clone()]);
        if step.done {
            env.reset(rng);
            write_obs(env, w, &mut out.obs[rows]);
        } else {
            out.obs[rows.clone()].copy_from_slice(&out.final_obs[rows]);
        }
        // After a reset every agent of the new episode chooses; a learner acting for the
        // `mac_done` agents must not see the terminal step's flags here (`final_mac_done`).
        for agent in 0..a {
            out.mac_done[k * a + agent] = env.mac_done()[agent];
        }
        write_mask(env, m, &mut out.mask[k * a * m..(k + 1) * a * m]);
    }
    Ok(())
}

fn array2<T: numpy::Element>(
    py: Python<'_>,
    v: Vec<T>,
    shape: (usize, usize),
) -> Bound<'_, PyArray2<T>> {
    ndarray::Array2::from_shape_vec(shape, v)
        .expect("buffer sized for its shape")
        .into_pyarray_bound(py)
}

fn array3<T: numpy::Element>(
    py: Python<'_>,
    v: Vec<T>,
    shape: (usize, usize, usize),
) -> Bound<'_, PyArray3<T>> {
    ndarray::Array3::from_shape_vec(shape, v)
        .expect("buffer sized for its shape")
        .into_pyarray_bound(py)
}

/// Every known domain as `name (tag)`.
#[pyfunction]
pub fn env_ids() -> Vec<&'static str> {
    registry::BUILT_IN.iter().map(|d| d.name()).collect()
}
