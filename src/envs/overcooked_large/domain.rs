//! ACAC's Overcooked-MA-v0 as configs, runs and replays know it: `env_name =
//! "ACAC-Overcooked-MA-v0"` (alias `overcooked-acac-large`), the keyword arguments ACAC's
//! `scripts/params/utils.py get_env_params` passes for it (`grid_dim`, `map_type`, `n_agent`,
//! `task`, `rewardList`, `debug`, `rand_start`, `n_knife`, `n_plate`, `obj`) and the runner's
//! `env_terminate_step`, plus the replay keys `np_seed` and `start_map` of ACAC-Overcooked-MA-v1.
//!
//! `task` is read, checked to be one of `TASKLIST` (ACAC's runner passes `TASKLIST[task]`; its
//! settings give 6, the full salad) and ignored, as ACAC's `Overcooked_V0` ignores it (`self.task =
//! obj`: the dish is all the objects).

use crate::envs::domain::{fill_keys, key_table, key_usize, Domain, KeyError, HORIZON_KEY};
use crate::envs::overcooked::domain_keys::{default_rewards, key_of};
use crate::envs::overcooked::world::Numbering;
use crate::envs::overcooked::{LargeKitchen, Overcooked, OvercookedParams};
use crate::envs::overcooked_acac::domain::{acac_params, REPLAY_KEYS};

/// The horizon of ACAC's `ovc{A,B,C}{,R}11_N6` settings (`env_terminate_step`).
pub const ACAC_HORIZON: usize = 400;

/// ACAC's Overcooked-MA-v0 (Overcooked-Large) domain.
pub struct OvercookedLargeDomain;

/// The parameters of checked keys: ACAC's Overcooked-MA-v1 keys read the same way, then the
/// Large kitchen's (`obj`, `n_plate`, `n_knife`), row-major numbering and no state.
fn large_params(keys: &toml::Table) -> Result<OvercookedParams, KeyError> {
    let mut p = acac_params(keys)?;
    p.numbering = Numbering::RowMajor;
    p.vector_state = false;
    let bad_obj = |v: &toml::Value| {
        KeyError::new(
            "obj",
            format!("expected a list of object names (ACAC's: [\"A\", ..., \"F\"]), got {v}"),
        )
    };
    let obj = match keys.get("obj") {
        Some(v @ toml::Value::Array(a)) => a
            .iter()
            .map(|o| o.as_str().map(str::to_string).ok_or_else(|| bad_obj(v)))
            .collect::<Result<Vec<_>, _>>()?,
        Some(v) => return Err(bad_obj(v)),
        None => return Err(KeyError::new("obj", "missing")),
    };
    p.large = Some(LargeKitchen {
        obj,
        n_plate: key_usize(keys, "n_plate")?,
        n_knife: key_usize(keys, "n_knife")?,
    });
    Ok(p)
}

impl Domain for OvercookedLargeDomain {
    type Env = Overcooked;

    fn name(&self) -> &'static str {
        "ACAC-Overcooked-MA-v0"
    }

    fn aliases(&self) -> &'static [&'static str] {
        &["overcooked-acac-large"]
    }

    /// ACAC's `ovcA11_N6` settings (`scripts/params/default.json` + `env/ovcA11_N6.json`):
    /// `grid_dim` [11, 11], `map_type` "A", `n_agent` 6, `task` the full salad (ignored),
    /// `rewardList` (step penalty -0.1), `debug` false (ignored), `rand_start` false, `n_knife`
    /// 4, `n_plate` 4, `obj` ["A", ..., "F"], `env_terminate_step` 400.
    fn keys(&self, given: &toml::Table) -> Result<toml::Table, KeyError> {
        let v1 = OvercookedParams::default();
        let large = LargeKitchen::default();
        let mut rest = given.clone();
        let replay: Vec<(String, toml::Value)> = REPLAY_KEYS
            .iter()
            .filter_map(|k| rest.remove(*k).map(|v| (k.to_string(), v)))
            .collect();
        let obj: Vec<toml::Value> = large.obj.iter().map(|o| o.as_str().into()).collect();
        let mut keys = fill_keys(
            &rest,
            key_table([
                ("grid_dim", toml::Value::Array(vec![11.into(), 11.into()])),
                ("map_type", "A".into()),
                ("n_agent", 6.into()),
                ("task", v1.task.clone().into()),
                ("rewardList", toml::Value::Table(default_rewards())),
                ("debug", false.into()),
                ("rand_start", false.into()),
                ("n_knife", (large.n_knife as i64).into()),
                ("n_plate", (large.n_plate as i64).into()),
                ("obj", toml::Value::Array(obj)),
                (HORIZON_KEY, (ACAC_HORIZON as i64).into()),
            ]),
        )?;
        keys.extend(replay);
        // Building checks what the keys alone cannot (a start map against the draws).
        Overcooked::new(large_params(&keys)?).map_err(key_of)?;
        Ok(keys)
    }

    fn build(&self, keys: &toml::Table) -> Result<Overcooked, KeyError> {
        Overcooked::new(large_params(keys)?).map_err(key_of)
    }

    /// ACAC's `ovc*11_N6` settings discount by 0.995 per primitive step (their `gamma`).
    fn paper_discount(&self, _keys: &toml::Table) -> Option<f64> {
        Some(0.995)
    }

    /// `acac-overcooked-large-a`, `-r` for random starts (ACAC's `ovcAR11_N6`), with the agent
    /// count when not 6.
    fn short_name(&self, keys: &toml::Table) -> String {
        let Ok(p) = large_params(keys) else {
            return "acac-overcooked-large".into();
        };
        let mut s = format!("acac-overcooked-large-{}", p.map.letter().to_lowercase());
        if p.rand_start {
            s += "-r";
        }
        if p.n_agent != 6 {
            s += &format!("-n{}", p.n_agent);
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::MacroEnv;

    #[test]
    fn defaults_are_acacs_ovc_a11_n6() {
        let d = OvercookedLargeDomain;
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
                "n_knife",
                "n_plate",
                "obj",
                HORIZON_KEY
            ]
        );
        let env = Domain::build(&d, &keys).unwrap();
        assert_eq!(env.n_agents(), 6);
        assert_eq!(env.obs_sizes(), &[48; 6]);
        assert_eq!(env.n_actions(), &[21; 6]);
        assert_eq!(env.state_size(), 0);
        assert_eq!(env.horizon(), 400);
        assert_eq!(env.action_names(0)[15], "delivery");
        assert_eq!(Domain::short_name(&d, &keys), "acac-overcooked-large-a");
        let b = Domain::keys(&d, &toml::toml! { map_type = "B"  rand_start = true }).unwrap();
        let env = Domain::build(&d, &b).unwrap();
        assert_eq!(env.n_actions(), &[22; 6]);
        assert_eq!(env.action_names(0)[17], "go to counter");
        assert_eq!(Domain::short_name(&d, &b), "acac-overcooked-large-b-r");
    }

    /// Agents in row-major order (ACAC's `np.where`): (1,4), (1,6), (2,4), (2,6), (9,4), (9,6);
    /// plates (8,10), (9,10), (10,8), (10,9); the objects start chopped, chop 0.
    #[test]
    fn the_kitchen_is_numbered_row_by_row() {
        use crate::envs::overcooked::world::Cell;
        let d = OvercookedLargeDomain;
        let env = Domain::build(&d, &Domain::keys(&d, &toml::Table::new()).unwrap()).unwrap();
        let w = env.world();
        let cooks: Vec<Cell> = w.cooks.iter().map(|c| c.at).collect();
        let cell = |x, y| Cell::new(x, y);
        assert_eq!(
            cooks,
            [
                cell(1, 4),
                cell(1, 6),
                cell(2, 4),
                cell(2, 6),
                cell(9, 4),
                cell(9, 6)
            ]
        );
        let plates: Vec<Cell> = w.plates[..4].iter().map(|p| p.at).collect();
        assert_eq!(plates, [cell(8, 10), cell(9, 10), cell(10, 8), cell(10, 9)]);
        assert!(w.foods[..6].iter().all(|f| f.chopped && f.chops == 0));
        assert_eq!(w.foods[1].at, cell(0, 9));
        assert_eq!(w.delivery.at, cell(5, 0));
    }

    #[test]
    fn bad_keys_are_named() {
        let d = OvercookedLargeDomain;
        for (given, key) in [
            (toml::toml! { n_agent = 7 }, "n_agent"),
            (toml::toml! { n_agent = 1 }, "n_agent"),
            (toml::toml! { grid_dim = [9, 9] }, "grid_dim"),
            (toml::toml! { grid_dim = [11, 9] }, "grid_dim"),
            (toml::toml! { obj = ["A", "A"] }, "obj"),
            (toml::toml! { obj = ["lettuce"] }, "obj"),
            (toml::toml! { obj = [] }, "obj"),
            (toml::toml! { obj = "A" }, "obj"),
            (toml::toml! { obj = [1] }, "obj"),
            (toml::toml! { n_plate = 5 }, "n_plate"),
            (toml::toml! { n_knife = 0 }, "n_knife"),
            (toml::toml! { task = "pizza" }, "task"),
            (toml::toml! { map_type = "D" }, "map_type"),
            (toml::toml! { np_seed = 3 }, "np_seed"),
            (toml::toml! { colour = 3 }, "colour"),
        ] {
            assert_eq!(Domain::keys(&d, &given).unwrap_err().key, key, "{given}");
        }
    }
}
