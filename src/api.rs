//! The library entry point: train a method on any domain implementing [`MacroEnv`] and get its
//! learning curve back ([`train`]), or the curve and the trained nets ([`train_policy`]), without
//! the command line, result directories or checkpoints. [`TrainedPolicy::export`] writes the
//! decentralized nets as a policy directory `macdec robot` serves, whatever the domain.
//!
//! The command line's `macdec train` drives the same training loop ([`AnyLoop`]) with the same
//! per-seed random streams, so a run through [`train`] on Box Pushing or Warehouse gives exactly
//! the numbers of `macdec train` with that config, method and seed.

use crate::algos::families::AnyLoop;
use crate::algos::families::Method;
use crate::algos::families::RunConfig;
use crate::algos::training_loop::{Advance, EvalPoint, TrainError};
use crate::deploy::policy::export::{export_nets, ExportError};
use crate::envs::{EnvError, EnvShape, MacroEnv};
use crate::experiment::definition::run_settings::RunSettings;
use crate::experiment::run::train_run::run_rngs;
use crate::nn::ActingNet;
use crate::policy_files::policy_env::PolicyEnv;
use crate::policy_files::{Manifest, NetKind, NetRole, RunInfo};
use std::path::Path;

/// The `experiment` an exported library policy names in its `policy.json`.
pub const LIBRARY_EXPERIMENT: &str = "library";

/// Why [`train`] refused or stopped.
#[derive(Debug, thiserror::Error)]
pub enum LibraryTrainError {
    /// A config key is out of range; the message names it and the allowed values.
    #[error("config key `{key}`: {message}")]
    Config {
        /// The config key.
        key: &'static str,
        /// What was wrong and what is allowed.
        message: String,
    },
    /// The domain, the replay or an update failed, or training diverged.
    #[error(transparent)]
    Train(#[from] TrainError),
}

/// Train `method` with seed `seed` on the domain `make_env` builds and return every evaluation
/// point (the rows `metrics.csv` would hold; write them with
/// [`crate::experiment::run::metrics::write`] to plot them with `macdec plot`).
///
/// `make_env` is called once to check the config against the domain's horizon, then once per
/// environment the method needs (evaluation, training, Our-2's second training env); each call
/// must build the same domain. What the learner needs to know about the domain comes from its
/// [`MacroEnv`] implementation, horizon included; the config names no domain and is validated
/// like a config file's (every key named on error). `on_episode` is called after every training
/// episode with the loop, e.g. for progress output. [`train_policy`] also gives back the nets.
pub fn train<E: MacroEnv>(
    make_env: impl Fn() -> Result<E, EnvError>,
    config: &RunConfig,
    method: Method,
    seed: u64,
    on_episode: impl FnMut(&AnyLoop<E>),
) -> Result<Vec<EvalPoint>, LibraryTrainError> {
    train_policy(make_env, config, method, seed, on_episode).map(|p| p.evals)
}

/// What [`train_policy`] gives back: the learning curve, the trained nets and what they were
/// trained with, enough to put the policy on robots ([`Self::export`]).
#[derive(Debug, Clone)]
pub struct TrainedPolicy {
    /// The method trained.
    pub method: Method,
    /// The run's seed.
    pub seed: u64,
    /// Training episodes completed (the config's `total_epi`).
    pub episodes_trained: u64,
    /// The hyperparameters it trained with.
    pub config: RunConfig,
    /// Every evaluation point, as [`train`] returns them.
    pub evals: Vec<EvalPoint>,
    /// The names of the evaluation points' family columns ([`EvalPoint::family`]).
    pub metric_columns: &'static [&'static str],
    /// Agent i's decentralized net is `agents[i]`, whatever the family: a Q-net (the ICRA
    /// methods) or an actor (the decentralized actor-critic methods). Empty for the methods
    /// that act only centrally (Cen-DDRQN, Mac-CAC).
    pub agents: Vec<ActingNet>,
    /// The centralized net that can act for the whole team, when the method trains one: the
    /// Q-net of Cen-DDRQN, Our-1, Our-1-R and Our-2, or Mac-CAC's actor (critics are not kept).
    pub team: Option<ActingNet>,
}

/// [`train`], keeping the trained nets: the same trainer, the same numbers.
pub fn train_policy<E: MacroEnv>(
    make_env: impl Fn() -> Result<E, EnvError>,
    config: &RunConfig,
    method: Method,
    seed: u64,
    mut on_episode: impl FnMut(&AnyLoop<E>),
) -> Result<TrainedPolicy, LibraryTrainError> {
    // The domain's sizes (horizon, observation and macro-action counts) bound the nets and
    // batches: ask one instance.
    let shape = EnvShape::of_env(&make_env().map_err(TrainError::from)?);
    method
        .check(config, &shape)
        .map_err(|(key, message)| LibraryTrainError::Config { key, message })?;
    let mut trainer = AnyLoop::new(config, method, seed, run_rngs(seed), make_env)?;
    while trainer.advance()? != Advance::Finished {
        on_episode(&trainer);
    }
    // Agent i's net at i, the team's centralized net beside them: read off the learner's list.
    let nets = trainer.saved_nets();
    let mut agents: Vec<(usize, ActingNet)> = nets
        .iter()
        .filter_map(|n| n.agent.map(|a| (a, n.net.to_net())))
        .collect();
    agents.sort_by_key(|(a, _)| *a);
    let agents = agents.into_iter().map(|(_, net)| net).collect();
    let team = nets
        .iter()
        .find(|n| n.role == NetRole::Cen)
        .map(|n| n.net.to_net());
    Ok(TrainedPolicy {
        method,
        seed,
        episodes_trained: trainer.episodes(),
        config: config.clone(),
        evals: trainer.evals().to_vec(),
        metric_columns: trainer.metric_columns(),
        agents,
        team,
    })
}

impl TrainedPolicy {
    /// Write the decentralized nets (Q-nets or actors) as an exported policy directory `out` (`policy.json` and
    /// `agent-<i>.safetensors`) that `macdec robot --policy OUT --agent I` serves. The layout
    /// (observation sizes and names, macro-action names) comes from `env` through its
    /// [`MacroEnv`] methods; `domain` names it: [`PolicyEnv::custom`] for a domain of your own
    /// (`macdec eval`, `deploy`, `domain` and `render` then refuse the policy, since this binary
    /// cannot simulate it), or a built-in [`crate::EnvSpec`] (`.into()`) if `env` is one.
    /// `out` must be new, empty or an earlier export.
    pub fn export<E: MacroEnv>(
        &self,
        out: &Path,
        env: &E,
        domain: PolicyEnv,
    ) -> Result<Manifest, ExportError> {
        // A built-in domain is recorded as a run's config.toml records it; a custom one by the
        // description's `env` alone.
        let config = match &domain {
            PolicyEnv::Known(spec) => serde_json::to_value(RunSettings {
                env: spec.clone(),
                config: self.config.clone(),
            }),
            PolicyEnv::Custom(_) => serde_json::to_value(self.config.to_table()),
        }
        .expect("a config serializes to JSON");
        let run = RunInfo {
            experiment: LIBRARY_EXPERIMENT.to_string(),
            method: self.method.name().to_string(),
            variant: String::new(),
            seed: self.seed,
            episodes_trained: self.episodes_trained,
            config,
        };
        if self.agents.is_empty() {
            // A policy that acts only centrally: say which net it is.
            return Err(ExportError::NotDecentralized {
                dir: out.to_path_buf(),
                method: run.method,
                centralized: self
                    .team
                    .as_ref()
                    .map(|t| NetKind::of(t).centralized_name()),
            });
        }
        let agents: Vec<&ActingNet> = self.agents.iter().collect();
        export_nets(out, domain, env, self.config.discount(), run, &agents)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algos::actor_critic::method::AcMethod;
    use crate::algos::family::FamilyMethod;
    use crate::algos::value::method::ValueMethod;
    use crate::envs::{AnyEnv, EnvSpec};

    /// The library trains on BP 10x10 here.
    fn spec() -> EnvSpec {
        crate::envs::box_pushing::spec(10, 100)
    }

    fn short(method: ValueMethod) -> RunConfig {
        let mut c = method.defaults(&spec());
        c.total_epi = 12;
        c.eval_freq = 4;
        c.into()
    }

    #[test]
    fn library_training_gives_the_numbers_of_the_command_lines_trainer() {
        for value_method in [ValueMethod::Our1, ValueMethod::DecHddrqn] {
            let c = short(value_method);
            let method = Method::from(value_method);
            let evals = train(|| spec().build(), &c, method, 5, |_| {}).unwrap();
            let mut t: AnyLoop<AnyEnv> =
                AnyLoop::new(&c, method, 5, run_rngs(5), || spec().build()).unwrap();
            while t.advance().unwrap() != Advance::Finished {}
            assert_eq!(evals.len(), 4);
            for (a, b) in evals.iter().zip(t.evals()) {
                assert_eq!(
                    (a.episode, a.env_steps, a.updates, a.eval_return.to_bits()),
                    (b.episode, b.env_steps, b.updates, b.eval_return.to_bits())
                );
                let bits = |p: &EvalPoint| -> Vec<Option<u64>> {
                    p.family.iter().map(|v| v.map(f64::to_bits)).collect()
                };
                assert_eq!(bits(a), bits(b));
            }
        }
    }

    #[test]
    fn an_exported_library_policy_holds_the_trained_nets_for_either_kind_of_domain() {
        use crate::deploy::policy::net_policy::load_net;
        use crate::policy_files::load_agent;
        let c = short(ValueMethod::Our1);
        let spec = spec();
        let trained = train_policy(
            || spec.build(),
            &c,
            Method::Value(ValueMethod::Our1),
            3,
            |_| {},
        )
        .unwrap();
        let evals = train(
            || spec.build(),
            &c,
            Method::Value(ValueMethod::Our1),
            3,
            |_| {},
        )
        .unwrap();
        let no_wall = |e: &[EvalPoint]| -> Vec<EvalPoint> {
            e.iter()
                .map(|p| EvalPoint {
                    wall_seconds: 0.0,
                    ..p.clone()
                })
                .collect()
        };
        assert_eq!(no_wall(&trained.evals), no_wall(&evals));
        assert_eq!((trained.agents.len(), trained.episodes_trained), (2, 12));
        assert!(matches!(trained.team, Some(ActingNet::Q(_))));
        let env = spec.build().unwrap();
        let dir = tempfile::tempdir().unwrap();
        for (sub, domain) in [
            ("built-in", PolicyEnv::from(spec.clone())),
            ("custom", PolicyEnv::custom("my-pushing", &env)),
        ] {
            let out = dir.path().join(sub);
            let written = trained.export(&out, &env, domain.clone()).unwrap();
            assert_eq!(written.env, domain);
            assert_eq!(written.run.method, "our1");
            let has_domain_keys = written.run.config.get("env_name").is_some();
            assert_eq!(has_domain_keys, sub == "built-in");
            for agent in 0..2 {
                let (manifest, verified) = load_agent(&out, agent).unwrap();
                assert_eq!(manifest, written);
                assert_eq!(
                    load_net(&manifest, &verified).unwrap(),
                    trained.agents[agent]
                );
            }
        }
        let cen = train_policy(
            || spec.build(),
            &short(ValueMethod::CenDdrqn),
            Method::Value(ValueMethod::CenDdrqn),
            3,
            |_| {},
        )
        .unwrap();
        let err = cen
            .export(&dir.path().join("cen"), &env, spec.into())
            .unwrap_err();
        let err = err.to_string();
        assert!(
            err.contains("no decentralized nets") && err.contains("its centralized Q-net"),
            "{err}"
        );
    }

    #[test]
    fn an_actor_critic_policy_keeps_its_actors_and_exports_the_decentralized_ones() {
        use crate::deploy::policy::net_policy::load_net;
        use crate::policy_files::load_agent;
        let spec = crate::envs::bp_ma_v0::spec(4, 20);
        let short = |method: AcMethod| -> RunConfig {
            let mut c = method.defaults(&spec);
            c.total_epi = 8;
            c.n_env = 4;
            c.train_freq = 4;
            c.eval_freq = 4;
            c.eval_num_epi = 2;
            c.into()
        };
        let iac = train_policy(
            || spec.build(),
            &short(AcMethod::MacIac),
            Method::ActorCritic(AcMethod::MacIac),
            1,
            |_| {},
        )
        .unwrap();
        assert_eq!(iac.agents.len(), 2);
        assert!(iac.agents.iter().all(|a| matches!(a, ActingNet::Actor(_))));
        assert!(iac.team.is_none());
        let env = spec.build().unwrap();
        let dir = tempfile::tempdir().unwrap();
        iac.export(dir.path(), &env, spec.clone().into()).unwrap();
        for agent in 0..2 {
            let (manifest, verified) = load_agent(dir.path(), agent).unwrap();
            assert_eq!(load_net(&manifest, &verified).unwrap(), iac.agents[agent]);
        }
        let cac = train_policy(
            || spec.build(),
            &short(AcMethod::MacCac),
            Method::ActorCritic(AcMethod::MacCac),
            1,
            |_| {},
        )
        .unwrap();
        assert!(cac.agents.is_empty());
        let team = cac.team.as_ref().expect("the centralized actor");
        assert_eq!(team.obs_len(), env.joint_obs_size());
        assert_eq!(team.n_actions(), env.n_joint_actions());
        let err = cac
            .export(&dir.path().join("cac"), &env, spec.into())
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("no decentralized nets") && err.contains("its centralized actor"),
            "{err}"
        );
    }

    #[test]
    fn a_bad_config_key_is_named_before_training() {
        let mut c = short(ValueMethod::Our1);
        c.of_mut::<ValueMethod>().unwrap().batch_size = 0;
        let spec = spec();
        let err = train(
            || spec.build(),
            &c,
            Method::Value(ValueMethod::Our1),
            0,
            |_| {},
        )
        .unwrap_err();
        assert!(err.to_string().contains("batch_size"), "{err}");
    }

    #[test]
    fn a_failing_env_factory_is_reported() {
        let c = short(ValueMethod::Our1);
        let bad = || crate::envs::box_pushing::BoxPushing::new(3, 100);
        let err = train(bad, &c, Method::Value(ValueMethod::Our1), 0, |_| {}).unwrap_err();
        assert!(err.to_string().contains("grid"), "{err}");
    }
}
