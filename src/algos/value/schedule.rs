//! Exploration and hysteresis schedules, functions of the completed-episode count E (a float, as
//! in the reference). The trainer recomputes them only at training iterations (quirk Q8): h before
//! the gradient step, epsilon after it.

use serde::{Deserialize, Serialize};

/// Why a schedule's parameters were refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ScheduleError {
    /// A duration (in episodes) that must be positive and finite.
    #[error("`{name}` must be > 0, got {value}")]
    NotPositive {
        /// The parameter.
        name: &'static str,
        /// The value given.
        value: f64,
    },
    /// A probability outside [0, 1].
    #[error("`{name}` must be in [0, 1], got {value}")]
    OutOfUnitRange {
        /// The parameter.
        name: &'static str,
        /// The value given.
        value: f64,
    },
}

/// Linear epsilon decay (`--eps_l_d`, `docs/ALGORITHMS.md` §4.1): from 1.0 to `eps_end` over `eps_l_d_steps`
/// episodes, then constant: `1 + min(E / eps_l_d_steps, 1) * (eps_end - 1)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EpsilonSchedule {
    eps_end: f64,
    eps_l_d_steps: f64,
}

impl EpsilonSchedule {
    /// Paper runs: `eps_end = 0.1`, `eps_l_d_steps = 6000`.
    pub fn new(eps_end: f64, eps_l_d_steps: f64) -> Result<Self, ScheduleError> {
        if !(0.0..=1.0).contains(&eps_end) {
            return Err(ScheduleError::OutOfUnitRange {
                name: "eps_end",
                value: eps_end,
            });
        }
        if !(eps_l_d_steps > 0.0 && eps_l_d_steps.is_finite()) {
            return Err(ScheduleError::NotPositive {
                name: "eps_l_d_steps",
                value: eps_l_d_steps,
            });
        }
        Ok(Self {
            eps_end,
            eps_l_d_steps,
        })
    }

    /// Epsilon after `episodes` completed episodes. Before the first training iteration the
    /// trainer keeps the start value 1.0 (`docs/ALGORITHMS.md` §4.1).
    pub fn at(&self, episodes: f64) -> f64 {
        1.0 + (episodes / self.eps_l_d_steps).min(1.0) * (self.eps_end - 1.0)
    }
}

/// Hysteresis value (`--dynamic_h`, `docs/ALGORITHMS.md` §5.6):
/// `min(end_h, init_h + (end_h - init_h) * E / h_stable_at)`; h = init_h before the first update.
/// With init_h = end_h = 1 (every method but Dec-HDDRQN) it is 1 throughout.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HysteresisSchedule {
    init_h: f64,
    end_h: f64,
    h_stable_at: f64,
}

impl HysteresisSchedule {
    /// Dec-HDDRQN: `(0.2, 0.4, 6000)`; the others `(1.0, 1.0, any)`. The reference's `min` caps
    /// correctly only when `end_h >= init_h`; other values are accepted and follow the formula.
    pub fn new(init_h: f64, end_h: f64, h_stable_at: f64) -> Result<Self, ScheduleError> {
        if !(h_stable_at > 0.0 && h_stable_at.is_finite()) {
            return Err(ScheduleError::NotPositive {
                name: "h_stable_at",
                value: h_stable_at,
            });
        }
        Ok(Self {
            init_h,
            end_h,
            h_stable_at,
        })
    }

    /// The start value, used until the first training iteration.
    pub fn initial(&self) -> f64 {
        self.init_h
    }

    /// h after `episodes` completed episodes.
    pub fn at(&self, episodes: f64) -> f64 {
        self.end_h
            .min(self.init_h + (self.end_h - self.init_h) * episodes / self.h_stable_at)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    #[test]
    fn epsilon_matches_the_spec_values() {
        let s = EpsilonSchedule::new(0.1, 6000.0).unwrap();
        assert!(close(s.at(0.0), 1.0));
        assert!(close(s.at(2.0), 0.9997));
        assert!(close(s.at(3000.0), 0.55));
        assert!(close(s.at(6000.0), 0.1));
        assert!(close(s.at(15000.0), 0.1));
        let head = EpsilonSchedule::new(0.1, 4000.0).unwrap();
        assert!(close(head.at(2.0), 0.99955));
    }

    #[test]
    fn hysteresis_grows_from_init_to_end_then_stays() {
        let h = HysteresisSchedule::new(0.2, 0.4, 6000.0).unwrap();
        assert!(close(h.initial(), 0.2));
        assert!(close(h.at(0.0), 0.2));
        assert!(close(h.at(3000.0), 0.3));
        assert!(close(h.at(6000.0), 0.4));
        assert!(close(h.at(12000.0), 0.4));
        let none = HysteresisSchedule::new(1.0, 1.0, 6000.0).unwrap();
        assert!([0.0, 2.0, 5000.0, 40000.0]
            .iter()
            .all(|&e| none.at(e) == 1.0));
    }

    #[test]
    fn schedules_refuse_non_positive_spans() {
        assert!(EpsilonSchedule::new(0.1, 0.0).is_err());
        assert!(EpsilonSchedule::new(1.5, 10.0).is_err());
        assert!(HysteresisSchedule::new(0.2, 0.4, 0.0).is_err());
        assert!(HysteresisSchedule::new(0.2, 0.4, f64::NAN).is_err());
    }
}
