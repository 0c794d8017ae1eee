//! `BP-MA-v0` as configs, runs and policy files know it: `env_name = "BP-MA-v0"` and the
//! reference's keyword arguments as keys (`grid_dim`, `big_box_reward`, `small_box_reward`,
//! `penalty`, `n_agent`), plus the runner's horizon `env_terminate_step`.

use crate::envs::box_pushing::domain::key_of;
use crate::envs::box_pushing::{BoxPushing, Rules, MAX_GRID_DIM};
use crate::envs::domain::{
    fill_keys, key_f64, key_table, key_usize, Domain, KeyError, HORIZON_KEY,
};
use crate::envs::macromarl::refuse_ignored_kwargs;

/// The `BP-MA-v0` domain.
pub struct BpMaV0Domain;

/// The published experiments' runner horizon (every Box Pushing block of the actor-critic
/// scripts: 100).
pub const DEFAULT_HORIZON: usize = 100;

/// The default grid side: 10, the middle of the published sizes 6 to 14.
pub const DEFAULT_GRID: usize = 10;

/// The keys this domain reads; every other key the reference's script passes to all BP/OSD
/// environments is accepted and dropped.
const USED: [&str; 5] = [
    "grid_dim",
    "big_box_reward",
    "small_box_reward",
    "penalty",
    "n_agent",
];

/// The grid side of `grid_dim`: an integer N or the reference's pair `[N, N]`.
/// The grid side of a setting's checked keys (the default grid's when `grid_dim` is unreadable,
/// which checked keys never are): what MacroMARL's published settings are chosen by.
pub fn grid_of(keys: &toml::Table) -> usize {
    keys.get("grid_dim")
        .and_then(|v| grid_side(v).ok())
        .unwrap_or(DEFAULT_GRID)
}

fn grid_side(value: &toml::Value) -> Result<usize, KeyError> {
    let bad = |why: String| KeyError::new("grid_dim", why);
    let side = |v: &toml::Value| {
        v.as_integer()
            .and_then(|i| usize::try_from(i).ok())
            .ok_or_else(|| bad(format!("expected a non-negative integer side, got {v}")))
    };
    match value {
        toml::Value::Array(pair) if pair.len() == 2 => {
            let (x, y) = (side(&pair[0])?, side(&pair[1])?);
            if x != y {
                return Err(bad(format!(
                    "only square grids are supported (the published ones are), got [{x}, {y}]; \
                     to sweep grids in a config, write a list of pairs: [[6, 6], [8, 8]]"
                )));
            }
            Ok(x)
        }
        toml::Value::Array(_) => Err(bad(format!("expected [N, N], got {value}"))),
        v => side(v),
    }
}

/// The rules of `keys`: MacroMARL's with the keys' rewards.
fn rules(keys: &toml::Table) -> Result<Rules, KeyError> {
    Ok(Rules {
        big_box_reward: key_f64(keys, "big_box_reward")?,
        small_box_reward: key_f64(keys, "small_box_reward")?,
        penalty: key_f64(keys, "penalty")?,
        ..Rules::MACROMARL
    })
}

impl Domain for BpMaV0Domain {
    type Env = BoxPushing;

    fn name(&self) -> &'static str {
        "BP-MA-v0"
    }

    /// `grid_dim` (`[10, 10]`; an integer N is taken as `[N, N]`), the published rewards
    /// `big_box_reward` 300, `small_box_reward` 20, `penalty` -10, `n_agent` 2 (the reference's
    /// optional third robot is unused by every experiment and not provided) and the runner's
    /// `env_terminate_step` 100.
    fn keys(&self, given: &toml::Table) -> Result<toml::Table, KeyError> {
        refuse_ignored_kwargs(given, &USED)?;
        let mut given = given.clone();
        if let Some(value) = given.get("grid_dim") {
            let n = grid_side(value)? as i64;
            given.insert(
                "grid_dim".into(),
                toml::Value::Array(vec![n.into(), n.into()]),
            );
        }
        let n = DEFAULT_GRID as i64;
        let keys = fill_keys(
            &given,
            key_table([
                ("grid_dim", toml::Value::Array(vec![n.into(), n.into()])),
                ("big_box_reward", Rules::MACROMARL.big_box_reward.into()),
                ("small_box_reward", Rules::MACROMARL.small_box_reward.into()),
                ("penalty", Rules::MACROMARL.penalty.into()),
                ("n_agent", 2.into()),
                (HORIZON_KEY, (DEFAULT_HORIZON as i64).into()),
            ]),
        )?;
        let grid = grid_side(&keys["grid_dim"])?;
        if grid > MAX_GRID_DIM {
            return Err(KeyError::new(
                "grid_dim",
                format!("must be at most {MAX_GRID_DIM}, got {grid}"),
            ));
        }
        let n_agent = key_usize(&keys, "n_agent")?;
        if n_agent != 2 {
            return Err(KeyError::new(
                "n_agent",
                format!(
                    "BP-MA-v0 has 2 robots (the reference's optional third one is used by no experiment), got {n_agent}"
                ),
            ));
        }
        BoxPushing::check_params(grid, key_usize(&keys, HORIZON_KEY)?, &rules(&keys)?)
            .map_err(key_of)?;
        Ok(keys)
    }

    fn build(&self, keys: &toml::Table) -> Result<BoxPushing, KeyError> {
        BoxPushing::with_rules(
            grid_side(&keys["grid_dim"])?,
            key_usize(keys, HORIZON_KEY)?,
            rules(keys)?,
        )
        .map_err(key_of)
    }

    /// MacroMARL's Box Pushing runs discount by 0.98 per primitive step (every published
    /// block, actor-critic and value-based alike).
    fn paper_discount(&self, _keys: &toml::Table) -> Option<f64> {
        Some(0.98)
    }

    fn short_name(&self, keys: &toml::Table) -> String {
        format!(
            "bpma{}",
            grid_side(&keys["grid_dim"]).unwrap_or(DEFAULT_GRID)
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::{EnvSpec, MacroEnv};

    #[test]
    fn defaults_are_the_published_ones() {
        let keys = Domain::keys(&BpMaV0Domain, &toml::Table::new()).unwrap();
        assert_eq!(
            keys.to_string(),
            "grid_dim = [10, 10]\nbig_box_reward = 300.0\nsmall_box_reward = 20.0\npenalty = -10.0\nn_agent = 2\nenv_terminate_step = 100\n"
        );
        let env = super::super::spec(14, 100).build().unwrap();
        assert_eq!(env.state_size(), 18);
        assert_eq!(env.n_agents(), 2);
        assert_eq!(
            env.describe(),
            "Box Pushing 14x14, rewards 300/20/-10, horizon 100"
        );
    }

    #[test]
    fn kwargs_box_pushing_does_not_read_are_refused_and_others_named() {
        let spec = EnvSpec::new("BP-MA-v0", &toml::toml! { grid_dim = 6 }).unwrap();
        assert_eq!(spec.short_name(), "bpma6");
        for (given, key) in [
            // MacroMARL's script passes these to every env; Box Pushing does not read them.
            (toml::toml! { terminate_step = 100 }, "terminate_step"),
            (toml::toml! { TB_move_speed = 0.6 }, "TB_move_speed"),
            (toml::toml! { obs_human_wait = false }, "obs_human_wait"),
            (toml::toml! { grid_size = 6 }, "grid_size"),
            (toml::toml! { grid_dim = [6, 8] }, "grid_dim"),
            (toml::toml! { grid_dim = 7 }, "grid_dim"),
            (toml::toml! { grid_dim = 2 }, "grid_dim"),
            (toml::toml! { grid_dim = [6] }, "grid_dim"),
            (toml::toml! { n_agent = 3 }, "n_agent"),
            (toml::toml! { penalty = "high" }, "penalty"),
            (toml::toml! { env_terminate_step = 0 }, "env_terminate_step"),
        ] {
            let err = EnvSpec::new("BP-MA-v0", &given).unwrap_err();
            assert_eq!(err.key(), key, "{given}: {err}");
        }
    }

    #[test]
    fn the_optimum_is_the_spec_table_at_published_rewards_only() {
        // `docs/MACROMARL.md` §3.1: the scripted plan's discounted return, gamma 0.98.
        for (grid, optimum) in [
            (6, 270.6055),
            (8, 259.6915),
            (10, 244.1255),
            (12, 229.4749),
            (14, 215.6859),
        ] {
            let env = super::super::spec(grid, 100).build().unwrap();
            let got = env.optimal_return(0.98).unwrap();
            assert!((got - optimum).abs() < 5e-5, "{grid}: {got}");
            assert_eq!(env.optimal_return(0.99), None);
        }
        let other = EnvSpec::new("BP-MA-v0", &toml::toml! { big_box_reward = 50 }).unwrap();
        assert_eq!(other.build().unwrap().optimal_return(0.98), None);
        let far = EnvSpec::new("BP-MA-v0", &toml::toml! { grid_dim = 16 }).unwrap();
        assert_eq!(far.build().unwrap().optimal_return(0.98), None);
    }
}
