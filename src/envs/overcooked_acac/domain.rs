//! ACAC's Overcooked-MA-v1 as configs, runs and replays know it: `env_name =
//! "ACAC-Overcooked-MA-v1"` (alias `overcooked-acac`), the keyword arguments ACAC's
//! `scripts/params/utils.py get_env_params` passes (`grid_dim`, `map_type`, `n_agent`, `task`,
//! `rewardList`, `debug`, `rand_start`) and the runner's `env_terminate_step`.
//!
//! Two more keys exist for replaying ACAC's random starts and are never recorded unless given:
//! `np_seed` (numpy's seed before the reset; the starts are then numpy's draws) and `start_map`
//! (the grid the reset produced), see [`OvercookedParams`].

use crate::envs::domain::{fill_keys, key_table, Domain, KeyError, HORIZON_KEY};
use crate::envs::overcooked::domain_keys::{default_rewards, key_of, params};
use crate::envs::overcooked::world::Numbering;
use crate::envs::overcooked::{Overcooked, OvercookedParams};

/// The keys that exist only when given (replaying a random start).
pub const REPLAY_KEYS: [&str; 2] = ["np_seed", "start_map"];

/// ACAC's Overcooked-MA-v1 domain.
pub struct OvercookedAcacDomain;

/// The parameters of checked keys: gym-macro-overcooked's keys read the same way, ACAC's
/// numbering and state, and the random-start keys (which ACAC's Large kitchen reads the same
/// way, `crate::envs::overcooked_large`).
pub(crate) fn acac_params(keys: &toml::Table) -> Result<OvercookedParams, KeyError> {
    let mut p = params(keys)?;
    p.numbering = Numbering::ColumnMajor;
    p.vector_state = true;
    p.rand_start = match keys.get("rand_start") {
        Some(toml::Value::Boolean(b)) => *b,
        Some(v) => {
            return Err(KeyError::new(
                "rand_start",
                format!("expected a boolean, got {v}"),
            ))
        }
        None => false,
    };
    p.np_seed = match keys.get("np_seed") {
        None => None,
        Some(toml::Value::Integer(i)) => Some(u32::try_from(*i).map_err(|_| {
            KeyError::new(
                "np_seed",
                format!("numpy seeds are 0..=4294967295, got {i}"),
            )
        })?),
        Some(v) => {
            return Err(KeyError::new(
                "np_seed",
                format!("expected an integer, got {v}"),
            ))
        }
    };
    p.start_map = keys.get("start_map").map(start_map_rows).transpose()?;
    Ok(p)
}

/// `start_map` as rows of codes.
fn start_map_rows(v: &toml::Value) -> Result<Vec<Vec<u8>>, KeyError> {
    let bad = || {
        KeyError::new(
            "start_map",
            format!("expected a list of rows of the reference's codes, got {v}"),
        )
    };
    let rows = v.as_array().ok_or_else(bad)?;
    rows.iter()
        .map(|row| {
            row.as_array()
                .ok_or_else(bad)?
                .iter()
                .map(|c| {
                    c.as_integer()
                        .and_then(|i| u8::try_from(i).ok())
                        .ok_or_else(bad)
                })
                .collect()
        })
        .collect()
}

impl Domain for OvercookedAcacDomain {
    type Env = Overcooked;

    fn name(&self) -> &'static str {
        "ACAC-Overcooked-MA-v1"
    }

    fn aliases(&self) -> &'static [&'static str] {
        &["overcooked-acac"]
    }

    /// ACAC's `ovcA7` settings (`scripts/params/default.json` + `env/ovcA7.json`): `grid_dim`
    /// [7, 7], `map_type` "A", `n_agent` 3, `task` the full salad, `rewardList` (step penalty
    /// -0.1), `debug` false (ignored), `rand_start` false, `env_terminate_step` 200.
    fn keys(&self, given: &toml::Table) -> Result<toml::Table, KeyError> {
        let p = OvercookedParams::default();
        let mut rest = given.clone();
        let replay: Vec<(String, toml::Value)> = REPLAY_KEYS
            .iter()
            .filter_map(|k| rest.remove(*k).map(|v| (k.to_string(), v)))
            .collect();
        let mut keys = fill_keys(
            &rest,
            key_table([
                ("grid_dim", toml::Value::Array(vec![7.into(), 7.into()])),
                ("map_type", p.map.letter().into()),
                ("n_agent", 3.into()),
                ("task", p.task.clone().into()),
                ("rewardList", toml::Value::Table(default_rewards())),
                ("debug", false.into()),
                ("rand_start", false.into()),
                (HORIZON_KEY, (p.horizon as i64).into()),
            ]),
        )?;
        keys.extend(replay);
        // Building checks what the keys alone cannot (a start map against the draws).
        Overcooked::new(acac_params(&keys)?).map_err(key_of)?;
        Ok(keys)
    }

    fn build(&self, keys: &toml::Table) -> Result<Overcooked, KeyError> {
        Overcooked::new(acac_params(keys)?).map_err(key_of)
    }

    /// ACAC's Overcooked runs discount by 0.99 per primitive step (`default.json`).
    fn paper_discount(&self, _keys: &toml::Table) -> Option<f64> {
        Some(0.99)
    }

    /// `acac-overcooked-a`, `-r` for random starts (ACAC's `ovcAR7`), with the agent count and
    /// grid when not ACAC's (`acac-overcooked-b-r-n2`).
    fn short_name(&self, keys: &toml::Table) -> String {
        let Ok(p) = acac_params(keys) else {
            return "acac-overcooked".into();
        };
        let mut s = format!("acac-overcooked-{}", p.map.letter().to_lowercase());
        if p.rand_start {
            s += "-r";
        }
        if p.n_agent != 3 {
            s += &format!("-n{}", p.n_agent);
        }
        if p.side != 7 {
            s += &format!("-{0}x{0}", p.side);
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::MacroEnv;

    #[test]
    fn defaults_are_acacs_ovc_a7_with_a_state() {
        let d = OvercookedAcacDomain;
        let keys = Domain::keys(&d, &toml::Table::new()).unwrap();
        let names: Vec<&str> = keys.keys().map(String::as_str).collect();
        assert_eq!(
            names,
            [
                "grid_dim",
                "map_type",
                "n_agent",
                "task",
                "rewardList",
                "debug",
                "rand_start",
                HORIZON_KEY
            ]
        );
        let env = Domain::build(&d, &keys).unwrap();
        assert_eq!(env.n_agents(), 3);
        assert_eq!(env.obs_sizes(), &[32, 32, 32]);
        assert_eq!(env.state_size(), 25);
        assert_eq!(Domain::short_name(&d, &keys), "acac-overcooked-a");
        let r = Domain::keys(&d, &toml::toml! { rand_start = true  map_type = "B" }).unwrap();
        assert_eq!(Domain::short_name(&d, &r), "acac-overcooked-b-r");
    }

    /// Training draws random starts from the run's environment stream: the same seed gives the
    /// same starts, another seed others, and successive resets differ.
    #[test]
    fn training_starts_come_from_the_runs_stream() {
        use crate::envs::EnvRng;
        use rand::SeedableRng;
        let d = OvercookedAcacDomain;
        let keys = Domain::keys(&d, &toml::toml! { rand_start = true }).unwrap();
        let starts = |seed: u64| {
            let mut env = Domain::build(&d, &keys).unwrap();
            let mut rng = EnvRng::seed_from_u64(seed);
            (0..4)
                .map(|_| {
                    env.reset(&mut rng);
                    env.render_ascii()
                })
                .collect::<Vec<_>>()
        };
        let a = starts(1);
        assert_eq!(a, starts(1));
        assert_ne!(a, starts(2));
        assert_ne!(a[0], a[1]);
    }

    #[test]
    fn bad_keys_are_named() {
        let d = OvercookedAcacDomain;
        for (given, key) in [
            (toml::toml! { n_agent = 4 }, "n_agent"),
            (toml::toml! { rand_start = 1 }, "rand_start"),
            (toml::toml! { np_seed = 3 }, "np_seed"),
            (toml::toml! { rand_start = true  np_seed = -1 }, "np_seed"),
            (
                toml::toml! { rand_start = true  np_seed = 5_000_000_000_i64 },
                "np_seed",
            ),
            (
                toml::toml! { rand_start = true  start_map = [[1, 2]] },
                "start_map",
            ),
            (
                toml::toml! { rand_start = true  start_map = "A" },
                "start_map",
            ),
            (toml::toml! { obj = ["A"] }, "obj"),
        ] {
            assert_eq!(Domain::keys(&d, &given).unwrap_err().key, key, "{given}");
        }
    }
}
