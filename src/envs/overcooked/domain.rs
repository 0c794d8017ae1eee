//! Overcooked as configs, runs and policy files know it: `env_name = "Overcooked-MA-v1"` (the
//! gym id), its keys by the names MacroMARL's `pg_based_main.py` passes them (`grid_dim`,
//! `map_type`, `task`, `rewardList`, `debug`) plus `n_agent` and the runner's
//! `env_terminate_step`.

use super::step::Rewards;
use super::{Overcooked, OvercookedParams};
use crate::envs::domain::{
    fill_keys, key_f64, key_table, key_usize, Domain, KeyError, HORIZON_KEY,
};
use crate::envs::EnvError;

/// The agent count when `n_agent` is not given: the paper's 3.
///
/// The reference's bug (`docs/MACROMARL.md` §5.2 item 1): MacroMARL's scripts never pass
/// `n_agent` (their `--n_agent=3` goes nowhere), so as published they train **2** agents (the
/// environment's own default, [`REFERENCE_N_AGENT`]), while the paper, its figures and the
/// shipped policies use **3**. macdec defaults to the paper's kitchen; `n_agent = 2` gives what
/// the published scripts actually ran.
pub const PAPER_N_AGENT: usize = 3;

/// The reference environment's own default agent count, what the published scripts trained.
pub const REFERENCE_N_AGENT: usize = 2;

/// The entries of `rewardList`, by the reference's names.
const REWARD_KEYS: [&str; 4] = [
    "subtask finished",
    "correct delivery",
    "wrong delivery",
    "step penalty",
];

/// The Overcooked domain.
pub struct OvercookedDomain;

pub(crate) fn default_rewards() -> toml::Table {
    let r = Rewards::default();
    key_table([
        (REWARD_KEYS[0], r.subtask_finished.into()),
        (REWARD_KEYS[1], r.correct_delivery.into()),
        (REWARD_KEYS[2], r.wrong_delivery.into()),
        (REWARD_KEYS[3], r.step_penalty.into()),
    ])
}

/// The rewards of `rewardList`: every entry a number, missing ones MacroMARL's values.
fn reward_list(keys: &toml::Table) -> Result<Rewards, KeyError> {
    let Some(toml::Value::Table(given)) = keys.get("rewardList") else {
        return Err(KeyError::new("rewardList", "expected a table of rewards"));
    };
    let mut table = default_rewards();
    for (k, v) in given {
        if !REWARD_KEYS.contains(&k.as_str()) {
            return Err(KeyError::new(
                "rewardList",
                format!("unknown entry `{k}`; the entries are {REWARD_KEYS:?}"),
            ));
        }
        let f = match v {
            toml::Value::Integer(i) => *i as f64,
            toml::Value::Float(f) if f.is_finite() => *f,
            _ => {
                return Err(KeyError::new(
                    "rewardList",
                    format!("entry `{k}` must be a finite number, got {v}"),
                ))
            }
        };
        table.insert(k.clone(), f.into());
    }
    let get = |k: &str| key_f64(&table, k).map_err(|e| KeyError::new("rewardList", e.to_string()));
    let rewards = Rewards {
        subtask_finished: get(REWARD_KEYS[0])?,
        correct_delivery: get(REWARD_KEYS[1])?,
        wrong_delivery: get(REWARD_KEYS[2])?,
        step_penalty: get(REWARD_KEYS[3])?,
    };
    Ok(rewards)
}

/// The side of `grid_dim`, which must be square (which sides a kitchen has,
/// [`OvercookedParams::validate`] says).
fn side(keys: &toml::Table) -> Result<usize, KeyError> {
    let err = |v: &toml::Value| {
        KeyError::new(
            "grid_dim",
            format!("expected a square grid [n, n] (Overcooked-MA-v1: [7, 7] or [9, 9]; ACAC's Large kitchen: [11, 11]), got {v}"),
        )
    };
    let v = keys
        .get("grid_dim")
        .ok_or_else(|| KeyError::new("grid_dim", "missing"))?;
    let Some(a) = v.as_array() else {
        return Err(err(v));
    };
    match a.as_slice() {
        [toml::Value::Integer(x), toml::Value::Integer(y)] if x == y && (3..=64).contains(x) => {
            Ok(*x as usize)
        }
        _ => Err(err(v)),
    }
}

/// The parameters the keys describe.
/// The map letter (`A`, `B`, `C`, ...) of a setting's checked keys (`A` when unreadable, which
/// checked keys never are): what MacroMARL's published settings are chosen by.
pub fn map_letter(keys: &toml::Table) -> char {
    params(keys).map_or('A', |p| p.map.letter().chars().next().unwrap_or('A'))
}

pub(crate) fn params(keys: &toml::Table) -> Result<OvercookedParams, KeyError> {
    let string = |k: &str| keys.get(k).and_then(|v| v.as_str()).map(str::to_string);
    let map_letter = string("map_type").unwrap_or_default();
    let map = super::layout::MapType::parse(&map_letter).ok_or_else(|| {
        KeyError::new(
            "map_type",
            format!("expected \"A\", \"B\" or \"C\", got {map_letter:?}"),
        )
    })?;
    Ok(OvercookedParams {
        side: side(keys)?,
        map,
        task: string("task").unwrap_or_default(),
        rewards: reward_list(keys)?,
        n_agent: key_usize(keys, "n_agent")?,
        horizon: key_usize(keys, HORIZON_KEY)?,
        ..OvercookedParams::default()
    })
}

/// The config key of a parameter [`OvercookedParams::validate`] names.
pub(crate) fn key_of(e: EnvError) -> KeyError {
    match e {
        EnvError::InvalidParameter { name, reason } => KeyError::new(
            match name {
                "horizon" => HORIZON_KEY,
                other => other,
            },
            reason,
        ),
        other => KeyError::new("env_name", other.to_string()),
    }
}

impl Domain for OvercookedDomain {
    type Env = Overcooked;

    fn name(&self) -> &'static str {
        "Overcooked-MA-v1"
    }

    fn aliases(&self) -> &'static [&'static str] {
        &["overcooked"]
    }

    /// `grid_dim` ([7, 7]), `map_type` ("A"), `task` (the full salad), `rewardList`
    /// (MacroMARL's), `debug` (false; accepted and ignored: it only turns on the reference's
    /// pygame window), `n_agent` (the paper's 3, [`PAPER_N_AGENT`]; the published scripts ran
    /// the reference's 2)
    /// and `env_terminate_step` (200).
    fn keys(&self, given: &toml::Table) -> Result<toml::Table, KeyError> {
        let p = OvercookedParams::default();
        let keys = fill_keys(
            given,
            key_table([
                ("grid_dim", toml::Value::Array(vec![7.into(), 7.into()])),
                ("map_type", p.map.letter().into()),
                ("task", p.task.clone().into()),
                ("rewardList", toml::Value::Table(default_rewards())),
                ("debug", false.into()),
                ("n_agent", (PAPER_N_AGENT as i64).into()),
                (HORIZON_KEY, (p.horizon as i64).into()),
            ]),
        )?;
        // Checked but kept as given (configs record what they were given; missing entries
        // take MacroMARL's values when the environment is built).
        params(&keys)?.validate().map_err(key_of)?;
        Ok(keys)
    }

    fn build(&self, keys: &toml::Table) -> Result<Overcooked, KeyError> {
        Overcooked::new(params(keys)?).map_err(key_of)
    }

    /// MacroMARL's Overcooked runs discount by 0.99 per primitive step (every published block);
    /// the shipped policies' returns are reported so.
    fn paper_discount(&self, _keys: &toml::Table) -> Option<f64> {
        Some(0.99)
    }

    /// `overcooked-a`, with the agent count and grid when not the paper's (`overcooked-b-n2`).
    fn short_name(&self, keys: &toml::Table) -> String {
        let Ok(p) = params(keys) else {
            return "overcooked".into();
        };
        let mut s = format!("overcooked-{}", p.map.letter().to_lowercase());
        if p.n_agent != PAPER_N_AGENT {
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
    fn defaults_are_the_papers_three_agents() {
        let d = OvercookedDomain;
        let keys = Domain::keys(&d, &toml::Table::new()).unwrap();
        assert_eq!(keys["n_agent"].as_integer(), Some(3));
        let names: Vec<&str> = keys.keys().map(String::as_str).collect();
        assert_eq!(
            names,
            [
                "grid_dim",
                "map_type",
                "task",
                "rewardList",
                "debug",
                "n_agent",
                HORIZON_KEY
            ]
        );
        let env = Domain::build(&d, &keys).unwrap();
        assert_eq!(env.n_agents(), 3);
        assert_eq!(env.obs_sizes(), &[32, 32, 32]);
        assert_eq!(env.n_actions(), &[14, 14, 14]);
        assert_eq!(env.horizon(), 200);
        assert_eq!(Domain::short_name(&d, &keys), "overcooked-a");
    }

    #[test]
    fn two_agents_and_map_b_change_sizes() {
        let d = OvercookedDomain;
        let keys = Domain::keys(&d, &toml::toml! { map_type = "B"  n_agent = 2 }).unwrap();
        let env = Domain::build(&d, &keys).unwrap();
        assert_eq!(env.obs_sizes(), &[30, 30]);
        assert_eq!(env.n_actions(), &[15, 15]);
        assert_eq!(Domain::short_name(&d, &keys), "overcooked-b-n2");
    }

    #[test]
    fn bad_keys_are_named() {
        let d = OvercookedDomain;
        for (given, key) in [
            (toml::toml! { colour = "red" }, "colour"),
            (toml::toml! { map_type = "D" }, "map_type"),
            (toml::toml! { task = "pizza" }, "task"),
            (toml::toml! { n_agent = 4 }, "n_agent"),
            (toml::toml! { grid_dim = [8, 8] }, "grid_dim"),
            (toml::toml! { grid_dim = [7, 9] }, "grid_dim"),
            (toml::toml! { env_terminate_step = 0 }, HORIZON_KEY),
            (toml::toml! { debug = 1 }, "debug"),
            (toml::toml! { rewardList = { "tip" = 1 } }, "rewardList"),
            (
                toml::toml! { rewardList = { "step penalty" = "x" } },
                "rewardList",
            ),
        ] {
            assert_eq!(Domain::keys(&d, &given).unwrap_err().key, key, "{given}");
        }
    }

    #[test]
    fn a_partial_reward_list_keeps_the_other_entries() {
        let d = OvercookedDomain;
        let given = toml::toml! { rewardList = { "step penalty" = -1 } };
        let keys = Domain::keys(&d, &given).unwrap();
        // Recorded as given, built with the other entries at MacroMARL's values.
        assert_eq!(keys["rewardList"], given["rewardList"]);
        let r = Domain::build(&d, &keys).unwrap().params().rewards;
        assert_eq!(r.step_penalty, -1.0);
        assert_eq!(r.correct_delivery, 200.0);
        let nine = Domain::keys(&d, &toml::toml! { grid_dim = [9, 9] }).unwrap();
        assert_eq!(Domain::build(&d, &nine).unwrap().params().side, 9);
    }
}
