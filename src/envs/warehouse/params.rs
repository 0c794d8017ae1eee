//! Constructor parameters of Warehouse Tool Delivery (`docs/WAREHOUSE.md` §2) and the fixed
//! geometry of the world (section 1).

use serde::{Deserialize, Serialize};

use crate::envs::EnvError;

/// Number of tool types. The observation layout (13/13/4) and the Fetch's 6 actions depend on it,
/// so only the paper's value is supported (`docs/WAREHOUSE.md` §2: only the paper values are in scope).
pub const N_TOOLS: usize = 3;

/// Turtlebot waypoint targets by macro-action index / location code (`docs/WAREHOUSE.md` §1):
/// workshop, tool-room wait point, own table spot. Indexed `[robot][code]`, each `(x, y)` in m.
pub const WAYPOINTS: [[[f64; 2]; 3]; 2] = [
    [[6.0, 3.0], [2.5, 3.5], [0.8, 3.0]],
    [[6.0, 3.0], [2.5, 3.5], [1.2, 3.0]],
];

/// Turtlebot positions at every reset (`docs/WAREHOUSE.md` §1).
pub const TURTLEBOT_STARTS: [[f64; 2]; 2] = [[3.0, 1.5], [3.0, 2.5]];

/// The Fetch's fixed position (it never moves; only the renderer uses it).
pub const FETCH_POS: [f64; 2] = [0.9, 1.8];

/// `ObjSearchDelivery_v4`'s constructor arguments. Defaults are the paper's values (spec
/// section 2), under which the domain is fully deterministic.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WarehouseParams {
    /// Number of tool types; also fixes the human's task length (n_objs + 1 work steps). Only 3.
    pub n_objs: usize,
    /// Copies of each tool the Fetch can ever find in one episode (`docs/WAREHOUSE.md` Q7 with 1).
    pub n_each_obj: usize,
    /// Horizon H in primitive steps; `done` is raised at step H (`docs/WAREHOUSE.md` Q2).
    #[serde(alias = "horizon")]
    pub terminate_step: usize,
    /// Duration of each of the human's work steps, in primitive steps.
    pub human_speed_per_step: f64,
    /// Turtlebot distance per primitive step (m).
    #[serde(alias = "TB_move_speed")]
    pub tb_move_speed: f64,
    /// Std of the Gaussian added to each Turtlebot move component (0 = deterministic, the paper).
    #[serde(alias = "TB_move_noisy")]
    pub tb_move_noisy: f64,
    /// Duration of Pass-to-M (steps). Also half of the Get-Tool wait limit.
    pub fetch_pass_obj_tc: u32,
    /// Duration of Search-Tool (steps). Also half of the Get-Tool wait limit.
    pub fetch_look_for_obj_tc: u32,
    /// If true, a delivery while the human is already waiting (htl < 0) is worth 20, not 100.
    pub delay_delivery_penalty: bool,
}

impl Default for WarehouseParams {
    fn default() -> Self {
        Self {
            n_objs: N_TOOLS,
            n_each_obj: 1,
            terminate_step: 150,
            human_speed_per_step: 18.0,
            tb_move_speed: 0.6,
            tb_move_noisy: 0.0,
            fetch_pass_obj_tc: 4,
            fetch_look_for_obj_tc: 6,
            delay_delivery_penalty: false,
        }
    }
}

impl WarehouseParams {
    /// The paper's settings with the given horizon (the paper uses 150).
    pub fn paper(horizon: usize) -> Self {
        Self {
            terminate_step: horizon,
            ..Self::default()
        }
    }

    /// Get-Tool's wait limit W = pass + search durations (`docs/WAREHOUSE.md` §2; 10 in the paper).
    pub fn get_tool_wait(&self) -> f64 {
        f64::from(self.fetch_pass_obj_tc) + f64::from(self.fetch_look_for_obj_tc)
    }

    /// Reject values the dynamics are not defined for, or that the fixed layout cannot hold.
    pub fn validate(&self) -> Result<(), EnvError> {
        let bad =
            |name: &'static str, reason: String| Err(EnvError::InvalidParameter { name, reason });
        if self.n_objs != N_TOOLS {
            return bad(
                "n_objs",
                format!(
                    "only {N_TOOLS} tool types are supported (fixed 13/13/4 observation layout), got {}",
                    self.n_objs
                ),
            );
        }
        if self.n_each_obj == 0 {
            return bad("n_each_obj", "must be >= 1, got 0".into());
        }
        if self.terminate_step == 0 {
            return bad("terminate_step", "the horizon must be >= 1, got 0".into());
        }
        if !(self.human_speed_per_step.is_finite() && self.human_speed_per_step > 0.0) {
            return bad(
                "human_speed_per_step",
                format!("must be finite and > 0, got {}", self.human_speed_per_step),
            );
        }
        if !(self.tb_move_speed.is_finite() && self.tb_move_speed > 0.0) {
            return bad(
                "tb_move_speed",
                format!("must be finite and > 0, got {}", self.tb_move_speed),
            );
        }
        if !(self.tb_move_noisy.is_finite() && self.tb_move_noisy >= 0.0) {
            return bad(
                "tb_move_noisy",
                format!("must be finite and >= 0, got {}", self.tb_move_noisy),
            );
        }
        if self.fetch_pass_obj_tc == 0 {
            return bad("fetch_pass_obj_tc", "must be >= 1, got 0".into());
        }
        if self.fetch_look_for_obj_tc == 0 {
            return bad("fetch_look_for_obj_tc", "must be >= 1, got 0".into());
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rejects(p: WarehouseParams, name: &str) {
        match p.validate() {
            Err(EnvError::InvalidParameter { name: n, .. }) => assert_eq!(n, name),
            other => panic!("expected InvalidParameter({name}), got {other:?}"),
        }
    }

    #[test]
    fn defaults_are_the_paper_values() {
        let p = WarehouseParams::default();
        assert_eq!(p, WarehouseParams::paper(150));
        assert_eq!((p.n_objs, p.n_each_obj, p.terminate_step), (3, 1, 150));
        assert_eq!(
            (p.human_speed_per_step, p.tb_move_speed, p.tb_move_noisy),
            (18.0, 0.6, 0.0)
        );
        assert_eq!((p.fetch_pass_obj_tc, p.fetch_look_for_obj_tc), (4, 6));
        assert!(!p.delay_delivery_penalty);
        assert_eq!(p.get_tool_wait(), 10.0);
        assert!(p.validate().is_ok());
    }

    #[test]
    fn invalid_values_are_named_errors() {
        let ok = WarehouseParams::default();
        rejects(
            WarehouseParams {
                terminate_step: 0,
                ..ok.clone()
            },
            "terminate_step",
        );
        rejects(
            WarehouseParams {
                n_objs: 4,
                ..ok.clone()
            },
            "n_objs",
        );
        rejects(
            WarehouseParams {
                n_each_obj: 0,
                ..ok.clone()
            },
            "n_each_obj",
        );
        rejects(
            WarehouseParams {
                tb_move_speed: -0.6,
                ..ok.clone()
            },
            "tb_move_speed",
        );
        rejects(
            WarehouseParams {
                tb_move_speed: f64::NAN,
                ..ok.clone()
            },
            "tb_move_speed",
        );
        rejects(
            WarehouseParams {
                tb_move_noisy: -0.1,
                ..ok.clone()
            },
            "tb_move_noisy",
        );
        rejects(
            WarehouseParams {
                tb_move_noisy: f64::INFINITY,
                ..ok.clone()
            },
            "tb_move_noisy",
        );
        rejects(
            WarehouseParams {
                human_speed_per_step: 0.0,
                ..ok.clone()
            },
            "human_speed_per_step",
        );
        rejects(
            WarehouseParams {
                fetch_pass_obj_tc: 0,
                ..ok.clone()
            },
            "fetch_pass_obj_tc",
        );
        rejects(
            WarehouseParams {
                fetch_look_for_obj_tc: 0,
                ..ok
            },
            "fetch_look_for_obj_tc",
        );
    }

    #[test]
    fn toml_uses_defaults_and_rejects_unknown_keys() {
        let p: WarehouseParams = toml::from_str("horizon = 100\nTB_move_noisy = 0.1").unwrap();
        assert_eq!(p.terminate_step, 100);
        assert_eq!(p.tb_move_noisy, 0.1);
        assert_eq!(p.tb_move_speed, 0.6);
        assert!(toml::from_str::<WarehouseParams>("horizn = 100").is_err());
    }
}
