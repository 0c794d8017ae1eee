//! Raw environment speed: primitive steps per second under uniformly random macro-actions, one
//! thread (issue 4: the target is 100x the reference Python environment, about 6M steps/s).

use std::time::Instant;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::{EnvError, EnvRng, EnvSpec, MacroEnv};

/// One measured environment.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvBench {
    /// What was measured, e.g. "box-pushing 10x10 (horizon 100)".
    pub name: String,
    /// Primitive steps taken.
    pub steps: u64,
    /// Episodes started.
    pub episodes: u64,
    /// Wall-clock time of the measurement.
    pub seconds: f64,
    /// Primitive steps per wall-clock second.
    pub steps_per_second: f64,
}

/// Step `env` with uniformly random macro-actions for free agents (busy agents get 0, which is
/// ignored), resetting at done, until at least `min_steps` primitive steps. Returns
/// `(steps, episodes)`. Action sampling is included in the time, as in a training loop.
pub fn random_macro_steps<E: MacroEnv>(
    env: &mut E,
    min_steps: u64,
    policy_rng: &mut ChaCha8Rng,
    env_rng: &mut EnvRng,
) -> Result<(u64, u64), EnvError> {
    let n_agents = env.n_agents();
    let n_actions = env.n_actions().to_vec();
    let mut actions = vec![0usize; n_agents];
    let (mut steps, mut episodes) = (0u64, 1u64);
    env.reset(env_rng);
    while steps < min_steps {
        for (agent, a) in actions.iter_mut().enumerate() {
            *a = if env.is_free(agent) {
                policy_rng.gen_range(0..n_actions[agent])
            } else {
                0
            };
        }
        let out = env.step(&actions, env_rng)?;
        steps += 1;
        if out.done {
            env.reset(env_rng);
            episodes += 1;
        }
    }
    Ok((steps, episodes))
}

/// Time [`random_macro_steps`] on the environment `spec` describes.
pub fn bench_env(name: &str, spec: EnvSpec, min_steps: u64) -> Result<EnvBench, EnvError> {
    let mut env = spec.build()?;
    let mut policy_rng = ChaCha8Rng::seed_from_u64(1);
    let mut env_rng = EnvRng::seed_from_u64(2);
    let start = Instant::now();
    let (steps, episodes) = random_macro_steps(&mut env, min_steps, &mut policy_rng, &mut env_rng)?;
    let seconds = start.elapsed().as_secs_f64();
    Ok(EnvBench {
        name: name.to_string(),
        steps,
        episodes,
        seconds,
        steps_per_second: steps as f64 / seconds,
    })
}

/// The environments `macdec bench envs` measures, at the papers' settings.
pub fn bench_suite() -> Vec<(&'static str, EnvSpec)> {
    vec![
        (
            "box-pushing 10x10 (horizon 100)",
            crate::envs::box_pushing::spec(10, 100),
        ),
        (
            "box-pushing 30x30 (horizon 200)",
            crate::envs::box_pushing::spec(30, 200),
        ),
        (
            "warehouse (horizon 150)",
            crate::envs::warehouse::spec(150, 0.0),
        ),
        (
            "BP-MA-v0 6x6 (runner horizon 100)",
            crate::envs::bp_ma_v0::spec(6, 100),
        ),
        (
            "BP-MA-v0 10x10 (runner horizon 100)",
            crate::envs::bp_ma_v0::spec(10, 100),
        ),
        (
            "BP-MA-v0 14x14 (runner horizon 100)",
            crate::envs::bp_ma_v0::spec(14, 100),
        ),
        ("OSD-D-v7 Warehouse A (published)", published("OSD-D-v7")),
        ("OSD-T-v0 Warehouse C (published)", published("OSD-T-v0")),
        ("OSD-T-v1 Warehouse D (published)", published("OSD-T-v1")),
        ("OSD-F-v0 Warehouse E (published)", published("OSD-F-v0")),
        (
            "Overcooked-MA-v1 map A, 3 agents",
            published("Overcooked-MA-v1"),
        ),
        ("Overcooked-MA-v1 map B, 3 agents", overcooked("B")),
        ("Overcooked-MA-v1 map C, 3 agents", overcooked("C")),
    ]
}

/// Overcooked on map `map` at the published settings (3 agents).
fn overcooked(map: &str) -> EnvSpec {
    EnvSpec::new(
        "Overcooked-MA-v1",
        &toml::Table::from_iter([("map_type".into(), map.into())]),
    )
    .expect("maps A, B and C exist")
}

/// The domain `name` at its defaults (MacroMARL's domains default to the published settings).
fn published(name: &str) -> EnvSpec {
    EnvSpec::new(name, &toml::Table::new()).expect("a built-in domain's defaults are valid")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn random_stepping_counts_steps_and_restarts_episodes() {
        // Stay-only episodes of BP last the horizon; random ones at most the horizon, so 1000
        // steps with horizon 10 need at least 100 episodes.
        let spec = crate::envs::box_pushing::spec(10, 10);
        let r = bench_env("bp", spec, 1000).unwrap();
        assert_eq!(r.steps, 1000);
        assert!(r.episodes >= 100, "{r:?}");
        assert!(r.steps_per_second > 0.0);
    }
}
