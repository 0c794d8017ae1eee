//! The axes a learning curve can be drawn on: `--x episode|env_steps|acac_timesteps` (both
//! `plot` and `report`) and `--y discounted|undiscounted` (`plot`), so curves compare with papers
//! that report undiscounted returns against environment steps (ACAC, the AVF paper, marl-eval).

use crate::experiment::run::metrics::COMPLETED_EPISODE_STEPS;
use crate::plot::discover::{RunData, ENV_STEPS, EVAL_RETURN};

/// What learning curves are drawn against (`--x` of `plot` and `report`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum XAxis {
    /// Training episodes (the metrics' `episode` column), the default.
    #[default]
    Episode,
    /// Environment steps (`env_steps`), which differ between methods that spend a different
    /// number of steps per episode.
    EnvSteps,
    /// ACAC's `Timesteps` (column `acac_timesteps`): the primitive steps of finished training
    /// episodes only, what ACAC's budget and its published curves count. ACAC's runner drops
    /// the episodes still running when a batch is complete, so on Box Pushing this is 1.4 to 3.1
    /// times fewer than `env_steps`: ACAC's logs compare with our runs only along this axis.
    /// The ACAC and actor-critic families write the column (MacroMARL's runner drops unfinished
    /// episodes too); runs without it (other families, older runs) are skipped with a note.
    AcacTimesteps,
}

impl XAxis {
    /// Parse `--x`: `episode`, `env_steps` or `acac_timesteps`.
    pub fn parse(text: &str) -> Result<XAxis, String> {
        match text.trim() {
            "episode" => Ok(XAxis::Episode),
            "env_steps" => Ok(XAxis::EnvSteps),
            "acac_timesteps" => Ok(XAxis::AcacTimesteps),
            other => Err(format!(
                "`{other}` is not an x axis: give `episode`, `env_steps` or `acac_timesteps`"
            )),
        }
    }

    /// The axis label of the figure.
    pub fn label(self) -> &'static str {
        match self {
            XAxis::Episode => "training episodes",
            XAxis::EnvSteps => "environment steps",
            XAxis::AcacTimesteps => "steps of finished training episodes (ACAC's Timesteps)",
        }
    }

    /// The name `--x` takes, also in stream keys.
    pub fn name(self) -> &'static str {
        match self {
            XAxis::Episode => "episode",
            XAxis::EnvSteps => "env_steps",
            XAxis::AcacTimesteps => "acac_timesteps",
        }
    }

    /// The `metrics.csv` column of step counts runs are read with ([`RunData::steps`]): the
    /// axis's own, `env_steps` along episodes (exports still record the steps).
    pub fn steps_column(self) -> &'static str {
        match self {
            XAxis::Episode | XAxis::EnvSteps => ENV_STEPS,
            XAxis::AcacTimesteps => COMPLETED_EPISODE_STEPS,
        }
    }

    /// Whether curves are drawn against step counts, which differ from seed to seed, rather
    /// than against episodes.
    pub fn is_steps(self) -> bool {
        self != XAxis::Episode
    }

    /// A run's `(x, evaluation return)` points along this axis.
    pub fn points(self, run: &RunData) -> Vec<(f64, f64)> {
        match self {
            XAxis::Episode => run.points.iter().map(|&(e, v)| (e as f64, v)).collect(),
            XAxis::EnvSteps | XAxis::AcacTimesteps => run
                .along_steps()
                .into_iter()
                .map(|(s, v)| (s as f64, v))
                .collect(),
        }
    }
}

/// Which return `plot --y` draws: a name for the evaluation-return column to read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum YAxis {
    /// `eval_return`: the discounted evaluation return the papers' figures show.
    #[default]
    Discounted,
    /// `eval_return_undiscounted`: the evaluation episodes' summed team reward, as ACAC and
    /// later papers report it (runs trained before the column existed lack it).
    Undiscounted,
}

/// The `metrics.csv` column of the undiscounted evaluation return.
pub const EVAL_RETURN_UNDISCOUNTED: &str = "eval_return_undiscounted";

impl YAxis {
    /// Parse `--y`: `discounted` or `undiscounted`.
    pub fn parse(text: &str) -> Result<YAxis, String> {
        match text.trim() {
            "discounted" => Ok(YAxis::Discounted),
            "undiscounted" => Ok(YAxis::Undiscounted),
            other => Err(format!(
                "`{other}` is not a y axis: give `discounted` or `undiscounted`"
            )),
        }
    }

    /// The `metrics.csv` column it reads.
    pub fn column(self) -> &'static str {
        match self {
            YAxis::Discounted => EVAL_RETURN,
            YAxis::Undiscounted => EVAL_RETURN_UNDISCOUNTED,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_axes_parse_from_their_names_only() {
        for axis in [XAxis::Episode, XAxis::EnvSteps, XAxis::AcacTimesteps] {
            assert_eq!(XAxis::parse(axis.name()), Ok(axis));
        }
        assert!(XAxis::parse("steps")
            .unwrap_err()
            .contains("`steps` is not an x axis"));
        assert_eq!(YAxis::parse("undiscounted"), Ok(YAxis::Undiscounted));
        assert_eq!(
            YAxis::parse("discounted").map(YAxis::column),
            Ok("eval_return")
        );
        assert!(YAxis::parse("raw")
            .unwrap_err()
            .contains("`raw` is not a y axis"));
    }
}
