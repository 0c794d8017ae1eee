//! Choosing a domain by value: [`EnvSpec`] says which environment and with which parameters (as it
//! appears in configs and replay files), and [`AnyEnv`] holds any built domain behind one
//! [`MacroEnv`] implementation, dispatched by `match` (no trait objects, `Clone`).

use serde::{Deserialize, Serialize};

use super::box_pushing::BoxPushing;
use super::warehouse::{Warehouse, WarehouseParams};
use super::{EnvError, EnvRng, FirstRecordObs, MacroEnv, StepOutcome};

/// Which domain, with its parameters. Serialized with the tag `env`:
/// `{"env": "box-pushing", "grid": 10, "horizon": 100}` or `{"env": "warehouse", "horizon": 150}`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "env", deny_unknown_fields)]
pub enum EnvSpec {
    /// Box Pushing on a `grid` x `grid` grid (spec `box_pushing.md`; paper: 10/100 and 30/200).
    #[serde(rename = "box-pushing")]
    BoxPushing { grid: usize, horizon: usize },
    /// Warehouse Tool Delivery (spec `warehouse.md`; paper: horizon 150, no movement noise).
    #[serde(rename = "warehouse")]
    Warehouse {
        horizon: usize,
        /// Std of the Turtlebots' movement noise (`TB_move_noisy`; paper 0).
        #[serde(default)]
        tb_m_noisy: f64,
    },
}

impl EnvSpec {
    /// The `env` tag of this spec.
    pub fn name(&self) -> &'static str {
        match self {
            EnvSpec::BoxPushing { .. } => "box-pushing",
            EnvSpec::Warehouse { .. } => "warehouse",
        }
    }

    /// Box Pushing at the paper's horizon for its grid: 100 steps below 30 x 30 (Figure 4a's 10 x
    /// 10), 200 from 30 x 30 on (Figure 4b) (spec `algorithms.md` 10.1, 10.2).
    pub fn paper_box_pushing(grid: usize) -> EnvSpec {
        EnvSpec::BoxPushing {
            grid,
            horizon: if grid >= 30 { 200 } else { 100 },
        }
    }

    /// Warehouse Tool Delivery as in Figure 5: horizon 150, no movement noise (spec 10.3).
    pub fn paper_warehouse() -> EnvSpec {
        let p = WarehouseParams::default();
        EnvSpec::Warehouse {
            horizon: p.terminate_step,
            tb_m_noisy: p.tb_move_noisy,
        }
    }

    /// The horizon in primitive steps (the `env_terminate_step` key).
    pub fn horizon(&self) -> usize {
        match *self {
            EnvSpec::BoxPushing { horizon, .. } | EnvSpec::Warehouse { horizon, .. } => horizon,
        }
    }

    /// A short label for tables, benchmarks and file names: `bp<grid>` (e.g. `bp10`) or `wtd`.
    pub fn short_name(&self) -> String {
        match self {
            EnvSpec::BoxPushing { grid, .. } => format!("bp{grid}"),
            EnvSpec::Warehouse { .. } => "wtd".into(),
        }
    }

    /// The discount per primitive step the paper trains and evaluates this domain under (Box
    /// Pushing 0.98, Warehouse 1.0; spec 10), the discount its known optimum is stated for.
    pub fn paper_discount(&self) -> f64 {
        match self {
            EnvSpec::BoxPushing { .. } => 0.98,
            EnvSpec::Warehouse { .. } => 1.0,
        }
    }

    /// Check the parameters as [`Self::build`] would, without building: configs are validated
    /// before any run starts. Errors name the bad parameter (`grid`, `horizon`, ...).
    pub fn validate(&self) -> Result<(), EnvError> {
        match *self {
            EnvSpec::BoxPushing { grid, horizon } => BoxPushing::check_params(grid, horizon),
            EnvSpec::Warehouse {
                horizon,
                tb_m_noisy,
            } => warehouse_params(horizon, tb_m_noisy).validate(),
        }
    }

    /// Build the environment, in its reset state. Errors name the bad parameter.
    pub fn build(&self) -> Result<AnyEnv, EnvError> {
        match *self {
            EnvSpec::BoxPushing { grid, horizon } => {
                Ok(AnyEnv::BoxPushing(BoxPushing::new(grid, horizon)?))
            }
            EnvSpec::Warehouse {
                horizon,
                tb_m_noisy,
            } => Ok(AnyEnv::Warehouse(Warehouse::new(warehouse_params(
                horizon, tb_m_noisy,
            ))?)),
        }
    }
}

/// Warehouse's full parameter set: a spec's horizon and noise, the paper's values for the rest.
fn warehouse_params(horizon: usize, tb_m_noisy: f64) -> WarehouseParams {
    WarehouseParams {
        terminate_step: horizon,
        tb_move_noisy: tb_m_noisy,
        ..WarehouseParams::default()
    }
}

/// Any built domain. Each method is one `match`, so the trainer pays no dynamic dispatch.
///
/// The variants differ in size (Warehouse is larger); a run holds one `AnyEnv`, so boxing would
/// only add a pointer chase to every step of the hot loop.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub enum AnyEnv {
    BoxPushing(BoxPushing),
    Warehouse(Warehouse),
}

/// Forward a method call to the variant's environment.
macro_rules! dispatch {
    ($self:expr, $env:ident => $call:expr) => {
        match $self {
            AnyEnv::BoxPushing($env) => $call,
            AnyEnv::Warehouse($env) => $call,
        }
    };
}

impl MacroEnv for AnyEnv {
    fn n_agents(&self) -> usize {
        dispatch!(self, e => e.n_agents())
    }
    fn obs_sizes(&self) -> &[usize] {
        dispatch!(self, e => e.obs_sizes())
    }
    fn n_actions(&self) -> &[usize] {
        dispatch!(self, e => e.n_actions())
    }
    fn action_names(&self, agent: usize) -> &'static [&'static str] {
        dispatch!(self, e => e.action_names(agent))
    }
    fn obs_names(&self, agent: usize) -> Vec<String> {
        dispatch!(self, e => e.obs_names(agent))
    }
    fn horizon(&self) -> usize {
        dispatch!(self, e => e.horizon())
    }
    fn reset(&mut self, rng: &mut EnvRng) {
        dispatch!(self, e => e.reset(rng))
    }
    #[inline]
    fn step(&mut self, actions: &[usize], rng: &mut EnvRng) -> Result<StepOutcome, EnvError> {
        dispatch!(self, e => e.step(actions, rng))
    }
    #[inline]
    fn obs(&self, agent: usize) -> &[f32] {
        dispatch!(self, e => e.obs(agent))
    }
    fn executed(&self) -> &[usize] {
        dispatch!(self, e => e.executed())
    }
    #[inline]
    fn mac_done(&self) -> &[bool] {
        dispatch!(self, e => e.mac_done())
    }
    #[inline]
    fn is_free(&self, agent: usize) -> bool {
        dispatch!(self, e => e.is_free(agent))
    }
    fn t(&self) -> usize {
        dispatch!(self, e => e.t())
    }
    fn render_ascii(&self) -> String {
        dispatch!(self, e => e.render_ascii())
    }
    fn first_record_obs(&self) -> FirstRecordObs {
        dispatch!(self, e => e.first_record_obs())
    }
    fn deterministic(&self) -> bool {
        dispatch!(self, e => e.deterministic())
    }
    fn optimal_return(&self, discount: f64) -> Option<f64> {
        dispatch!(self, e => e.optimal_return(discount))
    }
    fn describe(&self) -> String {
        dispatch!(self, e => e.describe())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_pushing_spec_parses_from_its_tagged_form() {
        let spec: EnvSpec =
            serde_json::from_str(r#"{"env": "box-pushing", "grid": 30, "horizon": 200}"#).unwrap();
        assert_eq!(
            spec,
            EnvSpec::BoxPushing {
                grid: 30,
                horizon: 200
            }
        );
        let env = spec.build().unwrap();
        assert_eq!(env.horizon(), 200);
        assert_eq!(env.n_joint_actions(), 64);
    }

    #[test]
    fn warehouse_spec_parses_with_paper_noise_by_default() {
        let spec: EnvSpec =
            serde_json::from_str(r#"{"env": "warehouse", "horizon": 150}"#).unwrap();
        assert_eq!(
            spec,
            EnvSpec::Warehouse {
                horizon: 150,
                tb_m_noisy: 0.0
            }
        );
        let env = spec.build().unwrap();
        assert_eq!(env.obs_sizes(), &[13, 13, 4]);
        assert_eq!(env.n_joint_actions(), 54);
    }

    #[test]
    fn unknown_env_and_missing_grid_are_named() {
        let err = serde_json::from_str::<EnvSpec>(r#"{"env": "boxpushing", "horizon": 1}"#)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("boxpushing") && err.contains("box-pushing"),
            "{err}"
        );
        let err = serde_json::from_str::<EnvSpec>(r#"{"env": "box-pushing", "horizon": 1}"#)
            .unwrap_err()
            .to_string();
        assert!(err.contains("grid"), "{err}");
        let err = serde_json::from_str::<EnvSpec>(
            r#"{"env": "box-pushing", "grid": 10, "horizon": 1, "gird": 3}"#,
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("gird"), "{err}");
    }

    #[test]
    fn any_env_steps_like_the_wrapped_env() {
        let mut rng = <EnvRng as rand::SeedableRng>::seed_from_u64(0);
        let mut any = EnvSpec::BoxPushing {
            grid: 10,
            horizon: 100,
        }
        .build()
        .unwrap();
        let mut bp = BoxPushing::new(10, 100).unwrap();
        for _ in 0..7 {
            let a = any.step(&[2, 3], &mut rng).unwrap();
            let b = bp.step(&[2, 3], &mut rng).unwrap();
            assert_eq!(a, b);
        }
        assert_eq!(any.obs(0), bp.obs(0));
        assert_eq!(any.mac_done(), &[true, true]);
    }
}
