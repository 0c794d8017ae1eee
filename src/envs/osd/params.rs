//! The keyword arguments of MacroMARL's Warehouse environments, typed and checked.

use super::layout::{Layout, N_WORK_STEPS};
use crate::envs::EnvError;

/// Largest horizon, human step time and Fetch duration accepted: far beyond any published
/// setting (300, 48, 6), small enough that an episode stays cheap.
pub const MAX_STEPS: usize = 100_000;
/// Largest Turtlebot speed and movement noise accepted (m per step; the floor is 9 m wide).
pub const MAX_SPEED: f64 = 100.0;

/// Every parameter of one Warehouse environment (the reference's kwargs, plus the runner's
/// horizon).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct OsdParams {
    /// The runner's horizon (`env_terminate_step`): the episode is cut after this many steps.
    pub horizon: usize,
    /// The env's own `terminate_step`; only OSD-F-v0 reads it (terminal at that step).
    pub terminate_step: usize,
    /// `human_speed_per_step`: each human's time (primitive steps) for each work step.
    pub human_speeds: Vec<[f64; N_WORK_STEPS]>,
    /// `TB_move_speed`: metres a Turtlebot travels per step.
    pub tb_move_speed: f64,
    /// `TB_move_noisy`: std of the normal noise added to each coordinate of a travel step.
    pub tb_move_noisy: f64,
    /// `TB_move_cost`: reward added on every travel step and on arrival.
    pub tb_move_cost: f64,
    /// `fetch_pass_obj_tc`: steps of Pass_Obj.
    pub fetch_pass_obj_tc: usize,
    /// `fetch_look_for_obj_tc`: steps of Look_For_obj.
    pub fetch_look_for_obj_tc: usize,
    /// `fetch_manip_noisy`: when not 0, each Fetch macro-action lasts -1, 0, 1 or 2 steps longer
    /// (uniformly; the reference's `np.random.choice([-1, 0, 1, 2])`).
    pub fetch_manip_noisy: f64,
    /// `fetch_drop_obj_penalty`: reward of a failed pass.
    pub fetch_drop_obj_penalty: f64,
    /// `delay_delivery_penalty`: added to the +100 of a delivery to a human already waiting
    /// (only when not 0, as the reference tests it).
    pub delay_delivery_penalty: f64,
    /// `obs_human_wait`: Turtlebots (and in OSD-D-v7 the Fetch) observe which humans wait.
    pub obs_human_wait: bool,
}

impl OsdParams {
    /// The published settings of `layout` (Warehouse A for OSD-D-v7; the experiments' scripts).
    pub fn published(layout: &Layout) -> Self {
        OsdParams {
            horizon: layout.default_horizon,
            terminate_step: layout.default_horizon,
            human_speeds: layout
                .default_human_speeds
                .iter()
                .map(|s| s.map(|v| v as f64))
                .collect(),
            tb_move_speed: 0.8,
            tb_move_noisy: 0.0,
            tb_move_cost: 0.0,
            fetch_pass_obj_tc: 4,
            fetch_look_for_obj_tc: 6,
            fetch_manip_noisy: 0.0,
            fetch_drop_obj_penalty: -10.0,
            delay_delivery_penalty: -20.0,
            obs_human_wait: false,
        }
    }

    /// Steps a Turtlebot waits at the table before Get_Tool gives up (`get_tool_wait`).
    pub fn get_tool_wait(&self) -> f64 {
        (self.fetch_pass_obj_tc + self.fetch_look_for_obj_tc) as f64
    }

    /// Whether any step draws from the random stream.
    pub fn noisy(&self) -> bool {
        self.tb_move_noisy != 0.0 || self.fetch_manip_noisy != 0.0
    }

    /// Refuse values the reference would crash on or that have no meaning, naming the kwarg.
    pub fn validate(&self, layout: &Layout) -> Result<(), EnvError> {
        let bad =
            |name: &'static str, reason: String| Err(EnvError::InvalidParameter { name, reason });
        for (name, v) in [
            ("env_terminate_step", self.horizon),
            ("terminate_step", self.terminate_step),
        ] {
            if !(1..=MAX_STEPS).contains(&v) {
                return bad(name, format!("must be in 1..={MAX_STEPS}, got {v}"));
            }
        }
        for (name, v) in [
            ("fetch_pass_obj_tc", self.fetch_pass_obj_tc),
            ("fetch_look_for_obj_tc", self.fetch_look_for_obj_tc),
        ] {
            if !(1..=MAX_STEPS).contains(&v) {
                return bad(name, format!("must be in 1..={MAX_STEPS}, got {v}"));
            }
        }
        if self.human_speeds.len() != layout.n_humans() {
            return bad(
                "human_speed_per_step",
                format!(
                    "{} has {} humans, so it needs {} lists, got {}",
                    layout.gym_id,
                    layout.n_humans(),
                    layout.n_humans(),
                    self.human_speeds.len()
                ),
            );
        }
        for speeds in &self.human_speeds {
            if speeds
                .iter()
                .any(|&s| !(s >= 1.0 && s <= MAX_STEPS as f64 && s.fract() == 0.0))
            {
                return bad(
                    "human_speed_per_step",
                    format!("step times must be integers in 1..={MAX_STEPS}, got {speeds:?}"),
                );
            }
        }
        if !(self.tb_move_speed > 0.0 && self.tb_move_speed <= MAX_SPEED) {
            return bad(
                "TB_move_speed",
                format!("must be in (0, {MAX_SPEED}], got {}", self.tb_move_speed),
            );
        }
        if !(0.0..=MAX_SPEED).contains(&self.tb_move_noisy) {
            return bad(
                "TB_move_noisy",
                format!("must be in [0, {MAX_SPEED}], got {}", self.tb_move_noisy),
            );
        }
        for (name, v) in [
            ("TB_move_cost", self.tb_move_cost),
            ("fetch_manip_noisy", self.fetch_manip_noisy),
            ("fetch_drop_obj_penalty", self.fetch_drop_obj_penalty),
            ("delay_delivery_penalty", self.delay_delivery_penalty),
        ] {
            if !v.is_finite() {
                return bad(name, format!("must be finite, got {v}"));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::osd::layout::{D7, LAYOUTS};

    fn name_of(p: &OsdParams) -> &'static str {
        match p.validate(&LAYOUTS[D7]) {
            Err(EnvError::InvalidParameter { name, .. }) => name,
            other => panic!("expected a refusal, got {other:?}"),
        }
    }

    #[test]
    fn bad_values_are_refused_by_name() {
        let ok = OsdParams::published(&LAYOUTS[D7]);
        ok.validate(&LAYOUTS[D7]).unwrap();
        type Spoil = fn(&mut OsdParams);
        let cases: [(Spoil, &str); 8] = [
            (|p| p.horizon = 0, "env_terminate_step"),
            (
                |p| p.human_speeds.pop().map(|_| ()).unwrap(),
                "human_speed_per_step",
            ),
            (|p| p.human_speeds[1][2] = 0.0, "human_speed_per_step"),
            (|p| p.human_speeds[0][0] = 2.5, "human_speed_per_step"),
            (|p| p.tb_move_speed = 0.0, "TB_move_speed"),
            (|p| p.tb_move_noisy = -1.0, "TB_move_noisy"),
            (|p| p.fetch_pass_obj_tc = 0, "fetch_pass_obj_tc"),
            (
                |p| p.fetch_look_for_obj_tc = MAX_STEPS + 1,
                "fetch_look_for_obj_tc",
            ),
        ];
        for (spoil, key) in cases {
            let mut p = ok.clone();
            spoil(&mut p);
            assert_eq!(name_of(&p), key);
        }
    }
}
