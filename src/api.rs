//! The library entry point: train a method on any domain implementing [`MacroEnv`] and get its
//! learning curve back, without the command line, result directories or checkpoints.
//!
//! The command line's `macdec train` drives the same [`Trainer`] with the same per-seed random
//! streams, so a run through [`train`] on Box Pushing or Warehouse gives exactly the numbers of
//! `macdec train` with that config, method and seed.

use crate::algos::hyper::RunConfig;
use crate::algos::method::Method;
use crate::algos::trainer::{Advance, EvalPoint, TrainError, Trainer};
use crate::envs::{EnvError, MacroEnv};
use crate::experiment::config::validate;
use crate::experiment::limits::check_sizes;
use crate::experiment::train_run::run_rngs;

/// Why [`train`] refused or stopped.
#[derive(Debug, thiserror::Error)]
pub enum LibraryTrainError {
    /// A config key is out of range; the message names it and the allowed values.
    #[error("config key `{key}`: {message}")]
    Config { key: &'static str, message: String },
    /// The domain, the replay or an update failed, or training diverged.
    #[error(transparent)]
    Train(#[from] TrainError),
}

/// Train `method` with seed `seed` on the domain `make_env` builds and return every evaluation
/// point (the rows `metrics.csv` would hold; write them with [`crate::experiment::metrics::write`]
/// to plot them with `macdec plot`).
///
/// `make_env` is called once per environment the method needs (evaluation, training, Our-2's
/// second training env); each call must build the same domain. What the learner needs to know
/// about the domain comes from its [`MacroEnv`] implementation, horizon included; the config's
/// `env` (the spec `macdec train` would build) is not read, only validated like the rest of the
/// config (every key named on error). `on_episode` is called after every training episode with
/// the trainer, e.g. for progress output.
pub fn train<E: MacroEnv>(
    make_env: impl Fn() -> Result<E, EnvError>,
    config: &RunConfig,
    method: Method,
    seed: u64,
    mut on_episode: impl FnMut(&Trainer<E>),
) -> Result<Vec<EvalPoint>, LibraryTrainError> {
    validate(config, method)
        .and_then(|()| check_sizes(config))
        .map_err(|(key, message)| LibraryTrainError::Config { key, message })?;
    let mut trainer = Trainer::with_env(config.clone(), method, seed, run_rngs(seed), make_env)?;
    while trainer.advance()? != Advance::Finished {
        on_episode(&trainer);
    }
    Ok(trainer.evals().to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::{AnyEnv, EnvSpec};
    use crate::experiment::paper::paper_defaults;

    fn short(method: Method) -> RunConfig {
        let mut c = paper_defaults(EnvSpec::paper_box_pushing(10), method);
        c.total_epi = 12;
        c.eval_freq = 4;
        c
    }

    #[test]
    fn library_training_gives_the_numbers_of_the_command_lines_trainer() {
        for method in [Method::Our1, Method::DecHddrqn] {
            let c = short(method);
            let spec = c.env;
            let evals = train(|| spec.build(), &c, method, 5, |_| {}).unwrap();
            let mut t: Trainer<AnyEnv> = Trainer::new(c, method, 5, run_rngs(5)).unwrap();
            while t.advance().unwrap() != Advance::Finished {}
            assert_eq!(evals.len(), 4);
            for (a, b) in evals.iter().zip(t.evals()) {
                assert_eq!(
                    (a.episode, a.env_steps, a.updates, a.eval_return.to_bits()),
                    (b.episode, b.env_steps, b.updates, b.eval_return.to_bits())
                );
                assert_eq!(a.loss.map(f64::to_bits), b.loss.map(f64::to_bits));
            }
        }
    }

    #[test]
    fn a_bad_config_key_is_named_before_training() {
        let mut c = short(Method::Our1);
        c.batch_size = 0;
        let spec = c.env;
        let err = train(|| spec.build(), &c, Method::Our1, 0, |_| {}).unwrap_err();
        assert!(err.to_string().contains("batch_size"), "{err}");
    }

    #[test]
    fn a_failing_env_factory_is_reported() {
        let c = short(Method::Our1);
        let bad = crate::envs::EnvSpec::BoxPushing {
            grid: 3,
            horizon: 100,
        };
        let err = train(|| bad.build(), &c, Method::Our1, 0, |_| {}).unwrap_err();
        assert!(err.to_string().contains("grid"), "{err}");
    }
}
