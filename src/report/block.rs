//! What a block of the results tree (an experiment directory: one task, several methods) is
//! scored on: per method, the runs the summary tables count and each run's final return, the
//! domain's optimum when known, and the names the figures and marl-eval's JSON use.

use crate::curve_stats::final_return;
use crate::plot::discover::{CurveData, ExperimentData, RunData};
use crate::plot::figure::{common_setting, complete_runs, curve_colours, partial_mark, title, Rgb};

/// One method of a block: its runs and their scores.
#[derive(Debug, Clone)]
pub struct MethodScores<'a> {
    /// The curve as discovered (directory name, method, all runs).
    pub curve: &'a CurveData,
    /// The runs scored: those reaching the curve's last evaluation
    /// ([`complete_runs`]), seeds ascending.
    pub runs: Vec<&'a RunData>,
    /// Each scored run's final return ([`final_return`]: the mean of its last 10% of
    /// evaluations), the number `<block>_summary.csv` averages.
    pub scores: Vec<f64>,
    /// The scores divided by the block's optimum, when it is known and positive.
    pub normalised: Option<Vec<f64>>,
    /// The method's colour, as in `macdec plot`'s figures.
    pub colour: Rgb,
}

/// A block ready for the statistics.
#[derive(Debug, Clone)]
pub struct Block<'a> {
    /// The experiment directory's name (`bp6`, `wh_a`).
    pub name: String,
    /// The figure title: name and domain setting.
    pub title: String,
    /// The domain's name for marl-eval's `env` level: the domain's tag (`box-pushing` for the
    /// ICRA Box Pushing, `BP-MA-v0` and `OSD-D-v7` for MacroMARL's), a domain this binary
    /// lacks by its `env_name`, `unknown` without a readable config.
    pub env: String,
    /// The optimal return of the block's setting, when known and positive (the scale scores
    /// are normalised by).
    pub optimum: Option<f64>,
    /// The methods with at least one scored run, in the paper's order.
    pub methods: Vec<MethodScores<'a>>,
    /// "partial: m of n runs unfinished", when some are.
    pub partial: Option<String>,
}

impl Block<'_> {
    /// The runs scored, over all methods.
    pub fn n_runs(&self) -> usize {
        self.methods.iter().map(|m| m.runs.len()).sum()
    }
}

/// Score the block `exp`, noting in `notes` what was left out and why.
pub fn score<'a>(exp: &'a ExperimentData, notes: &mut Vec<String>) -> Block<'a> {
    let (optimal, setting_text) = common_setting(exp, notes);
    let optimum = match optimal {
        Some(o) if o > 0.0 && o.is_finite() => Some(o),
        Some(o) => {
            notes.push(format!(
                "{}: the optimum {o} is not positive; scores are not normalised",
                exp.name
            ));
            None
        }
        None => None,
    };
    if optimum.is_none() {
        notes.push(format!(
            "{}: no known optimum, so no optimality_gap rows and the profile is over raw returns",
            exp.name
        ));
    }
    let mut methods = Vec::new();
    for (curve, colour) in exp.curves.iter().zip(curve_colours(exp)) {
        let runs = complete_runs(curve);
        let left_out = curve.runs.len() - runs.len();
        if left_out > 0 {
            notes.push(format!(
                "{}/{}: {left_out} run(s) stop before the curve's last evaluation and are not scored",
                exp.name, curve.name
            ));
        }
        let scores: Vec<f64> = runs
            .iter()
            .map(|r| {
                final_return(&r.points).expect("discover keeps runs with at least one evaluation")
            })
            .collect();
        let normalised = optimum.map(|o| scores.iter().map(|s| s / o).collect());
        methods.push(MethodScores {
            curve,
            runs,
            scores,
            normalised,
            colour,
        });
    }
    Block {
        name: exp.name.clone(),
        title: title(exp, setting_text),
        env: env_name(exp),
        optimum,
        methods,
        partial: partial_mark(exp),
    }
}

/// The domain the block's runs name: the first readable setting's (domain settings that differ
/// between runs are noted by [`common_setting`]).
fn env_name(exp: &ExperimentData) -> String {
    let setting = exp
        .curves
        .iter()
        .flat_map(|c| &c.runs)
        .find_map(|r| r.setting.as_ref());
    match setting.map(|s| &s.env) {
        Some(Ok(spec)) => spec.name().to_string(),
        Some(Err(env_name)) => env_name.clone(),
        None => "unknown".to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::discover::{discover, tests::write_run};

    #[test]
    fn a_block_scores_complete_runs_by_final_return_normalised_by_the_optimum() {
        let t = tempfile::tempdir().unwrap();
        let bp10 = crate::envs::box_pushing::paper_spec(10);
        let opt = crate::plot::setting::BP10_OPTIMAL;
        // 10 evaluations: the final return is the last one (ceil(10 / 10) = 1).
        let pts = |last: f64| -> Vec<(u64, f64)> {
            (0..10)
                .map(|i| (i * 10, if i == 9 { last } else { 0.0 }))
                .collect()
        };
        write_run(t.path(), "b", "our1", 0, &pts(40.0), bp10.clone(), true);
        write_run(t.path(), "b", "our1", 1, &pts(opt), bp10.clone(), true);
        // Stopped at episode 50: not scored.
        write_run(
            t.path(),
            "b",
            "our1",
            2,
            &pts(1.0)[..6],
            bp10.clone(),
            false,
        );
        let d = discover(t.path()).unwrap();
        let mut notes = Vec::new();
        let block = score(&d.experiments[0], &mut notes);
        assert_eq!(block.env, "box-pushing");
        assert_eq!(block.optimum, Some(opt));
        let m = &block.methods[0];
        assert_eq!(m.scores, [40.0, opt]);
        assert_eq!(m.normalised.as_deref(), Some(&[40.0 / opt, 1.0][..]));
        assert_eq!(m.runs.iter().map(|r| r.seed).collect::<Vec<_>>(), [0, 1]);
        assert_eq!(block.n_runs(), 2);
        assert_eq!(
            block.partial.as_deref(),
            Some("partial: 1 of 3 runs unfinished")
        );
        assert!(
            notes
                .iter()
                .any(|n| n.contains("b/our1: 1 run(s) stop before")),
            "{notes:?}"
        );
    }

    #[test]
    fn without_a_known_optimum_nothing_is_normalised_and_a_note_says_so() {
        let t = tempfile::tempdir().unwrap();
        // Box Pushing 10x10 at horizon 50: no verified optimum (only the paper's settings).
        let short = crate::envs::box_pushing::spec(10, 50);
        write_run(t.path(), "w", "our1", 0, &[(0, 1.0)], short, true);
        let d = discover(t.path()).unwrap();
        let mut notes = Vec::new();
        let block = score(&d.experiments[0], &mut notes);
        assert_eq!(block.optimum, None);
        assert_eq!(block.methods[0].normalised, None);
        assert!(
            notes.iter().any(|n| n.contains("no known optimum")),
            "{notes:?}"
        );
    }
}
