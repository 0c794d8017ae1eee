//! An environment of a domain that is not built in (a user's own [`super::domain::Domain`]), held
//! behind a trait object so the pipeline can keep it in an [`super::AnyEnv`], clone it and save it
//! in a checkpoint. Saving writes the domain's name and the environment's bincode; loading (in
//! [`super::registry`]) finds the domain and asks it to rebuild the environment, so a checkpoint
//! of a domain the running binary does not have is refused by name.

use serde::{Deserialize, Serialize, Serializer};

use super::{EnvError, EnvRng, FirstRecordObs, MacroEnv, StepOutcome};

/// What [`CustomEnv`] asks of an environment besides [`MacroEnv`]: to be cloned and saved.
/// Implemented for every `MacroEnv + Clone + Serialize + Send`.
pub trait ErasedEnv: MacroEnv + Send {
    /// A boxed copy.
    fn clone_box(&self) -> Box<dyn ErasedEnv>;
    /// The environment's bincode, for checkpoints.
    fn save(&self) -> Result<Vec<u8>, String>;
}

impl<E: MacroEnv + Clone + Serialize + Send + 'static> ErasedEnv for E {
    fn clone_box(&self) -> Box<dyn ErasedEnv> {
        Box::new(self.clone())
    }
    fn save(&self) -> Result<Vec<u8>, String> {
        bincode::serialize(self).map_err(|e| e.to_string())
    }
}

/// A custom domain's environment and the name of its domain.
pub struct CustomEnv {
    domain: &'static str,
    env: Box<dyn ErasedEnv>,
}

impl CustomEnv {
    /// Hold `env` of the domain named `domain` ([`super::domain::Domain::name`]).
    pub fn new(domain: &'static str, env: impl ErasedEnv + 'static) -> Self {
        CustomEnv {
            domain,
            env: Box::new(env),
        }
    }

    /// The name of the environment's domain.
    pub fn domain(&self) -> &'static str {
        self.domain
    }
}

impl Clone for CustomEnv {
    fn clone(&self) -> Self {
        CustomEnv {
            domain: self.domain,
            env: self.env.clone_box(),
        }
    }
}

impl std::fmt::Debug for CustomEnv {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "CustomEnv({}, t = {})", self.domain, self.env.t())
    }
}

/// The saved form: the domain's name, then the environment's bytes (read back by the
/// registry, which finds the domain: `impl Deserialize for CustomEnv` is in `registry.rs`).
#[derive(Serialize, Deserialize)]
pub(crate) struct SavedEnv {
    pub(crate) domain: String,
    pub(crate) env: Vec<u8>,
}

impl Serialize for CustomEnv {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let env = self.env.save().map_err(serde::ser::Error::custom)?;
        SavedEnv {
            domain: self.domain.to_string(),
            env,
        }
        .serialize(s)
    }
}

impl MacroEnv for CustomEnv {
    fn n_agents(&self) -> usize {
        self.env.n_agents()
    }
    fn obs_sizes(&self) -> &[usize] {
        self.env.obs_sizes()
    }
    fn n_actions(&self) -> &[usize] {
        self.env.n_actions()
    }
    fn action_names(&self, agent: usize) -> &'static [&'static str] {
        self.env.action_names(agent)
    }
    fn obs_names(&self, agent: usize) -> Vec<String> {
        self.env.obs_names(agent)
    }
    fn horizon(&self) -> usize {
        self.env.horizon()
    }
    fn reset(&mut self, rng: &mut EnvRng) {
        self.env.reset(rng)
    }
    fn step(&mut self, actions: &[usize], rng: &mut EnvRng) -> Result<StepOutcome, EnvError> {
        self.env.step(actions, rng)
    }
    fn obs(&self, agent: usize) -> &[f32] {
        self.env.obs(agent)
    }
    fn executed(&self) -> &[usize] {
        self.env.executed()
    }
    fn mac_done(&self) -> &[bool] {
        self.env.mac_done()
    }
    fn is_free(&self, agent: usize) -> bool {
        self.env.is_free(agent)
    }
    fn t(&self) -> usize {
        self.env.t()
    }
    fn render_ascii(&self) -> String {
        self.env.render_ascii()
    }
    fn first_record_obs(&self) -> FirstRecordObs {
        self.env.first_record_obs()
    }
    fn deterministic(&self) -> bool {
        self.env.deterministic()
    }
    fn optimal_return(&self, discount: f64) -> Option<f64> {
        self.env.optimal_return(discount)
    }
    fn describe(&self) -> String {
        self.env.describe()
    }
    fn draw(&self) -> Option<crate::draw::Picture> {
        self.env.draw()
    }
    fn state_size(&self) -> usize {
        self.env.state_size()
    }
    fn write_state(&self, out: &mut [f32]) {
        self.env.write_state(out)
    }
}
