//! A block's raw per-run data in the JSON schema of marl-eval (instadeepai/marl-eval, the tool
//! of Gorsane et al. 2022), so its `data_process_pipeline` and `create_matrices_for_rliable`
//! read `<block>_marl_eval.json` as written:
//!
//! ```text
//! { env: { task: { algorithm: { run: {
//!     "step_0": {"step_count": <env steps>, "return": [<evaluation return>]}, ...
//!     "step_<K-1>": {...},
//!     "absolute_metrics": {"return": [<final return>]} } } } } }
//! ```
//!
//! env is the domain (`box-pushing`), task the block, algorithm the method's directory name,
//! run `seed_<k>` as marl-eval's `JsonLogger` names it. marl-eval indexes every algorithm by
//! the first one's run and step names, so the file holds the seeds every method of the block
//! has, and K steps per run, K the fewest evaluations of those runs; a run with more is thinned
//! evenly to K ([`even_indices`], first and last kept). Each step's `return` holds the one
//! evaluation return the metrics file records (the mean over that evaluation's episodes, which
//! the schema allows: "either 1 element ... or as many elements as evaluation episodes").
//! `absolute_metrics` holds the run's final return as the summary tables define it (the mean of
//! its last 10% of evaluations), not Gorsane et al.'s absolute metric (the best checkpoint
//! re-evaluated on 10 times the episodes), which a metrics file cannot give.

use super::block::Block;
use super::grid::even_indices;
use serde::ser::{Serialize, SerializeMap, Serializer};
use std::collections::BTreeSet;

/// The metric name marl-eval's examples normalise (`METRICS_TO_NORMALIZE = ["return"]`).
pub const RETURN: &str = "return";

/// A JSON object that keeps its keys in insertion order (serde_json's own map sorts them,
/// which would put `step_10` before `step_2`, and marl-eval reads steps in file order).
#[derive(Debug, Clone, PartialEq)]
pub struct Object<V>(pub Vec<(String, V)>);

impl<V: Serialize> Serialize for Object<V> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut map = serializer.serialize_map(Some(self.0.len()))?;
        for (k, v) in &self.0 {
            map.serialize_entry(k, v)?;
        }
        map.end()
    }
}

/// One entry of a run: a logged step or the absolute metrics.
#[derive(Debug, Clone, PartialEq)]
pub enum RunEntry {
    /// `{"step_count": .., "return": [..]}`.
    Step {
        /// Environment steps when the evaluation ran.
        step_count: u64,
        /// The evaluation return.
        value: f64,
    },
    /// `{"return": [..]}`: the run's final return.
    Absolute {
        /// The final return.
        value: f64,
    },
}

impl Serialize for RunEntry {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            RunEntry::Step { step_count, value } => {
                let mut map = serializer.serialize_map(Some(2))?;
                map.serialize_entry("step_count", step_count)?;
                map.serialize_entry(RETURN, &[value])?;
                map.end()
            }
            RunEntry::Absolute { value } => {
                let mut map = serializer.serialize_map(Some(1))?;
                map.serialize_entry(RETURN, &[value])?;
                map.end()
            }
        }
    }
}

/// The whole file: env -> task -> algorithm -> run -> entries.
pub type MarlEvalJson = Object<Object<Object<Object<Object<RunEntry>>>>>;

/// The block in marl-eval's schema, and notes on the runs left out and the steps thinned.
pub fn build(block: &Block, notes: &mut Vec<String>) -> MarlEvalJson {
    let seeds_of = |m: &super::block::MethodScores| -> BTreeSet<u64> {
        m.runs.iter().map(|r| r.seed).collect()
    };
    let mut shared: Option<BTreeSet<u64>> = None;
    for m in &block.methods {
        let own = seeds_of(m);
        shared = Some(match shared {
            None => own,
            Some(s) => s.intersection(&own).copied().collect(),
        });
    }
    let shared = shared.unwrap_or_default();
    for m in &block.methods {
        let left: Vec<String> = seeds_of(m)
            .difference(&shared)
            .map(|s| s.to_string())
            .collect();
        if !left.is_empty() {
            notes.push(format!(
                "{}/{}: seed(s) {} left out of the marl-eval JSON (marl-eval needs the same runs for every method)",
                block.name,
                m.curve.name,
                left.join(", ")
            ));
        }
    }
    let kept = |m: &super::block::MethodScores| -> Vec<(usize, u64)> {
        m.runs
            .iter()
            .enumerate()
            .filter(|(_, r)| shared.contains(&r.seed))
            .map(|(i, r)| (i, r.seed))
            .collect()
    };
    let steps = block
        .methods
        .iter()
        .flat_map(|m| kept(m).into_iter().map(|(i, _)| m.runs[i].points.len()))
        .min()
        .unwrap_or(0);
    let mut thinned = Vec::new();
    let algorithms = block
        .methods
        .iter()
        .map(|m| {
            let runs = kept(m)
                .into_iter()
                .map(|(i, seed)| {
                    let run = m.runs[i];
                    if run.points.len() > steps {
                        thinned.push(format!("{}/seed-{seed}", m.curve.name));
                    }
                    let mut entries: Vec<(String, RunEntry)> =
                        even_indices(run.points.len(), steps)
                            .into_iter()
                            .enumerate()
                            .map(|(k, at)| {
                                let entry = RunEntry::Step {
                                    step_count: run.steps[at],
                                    value: run.points[at].1,
                                };
                                (format!("step_{k}"), entry)
                            })
                            .collect();
                    entries.push((
                        "absolute_metrics".to_string(),
                        RunEntry::Absolute { value: m.scores[i] },
                    ));
                    (format!("seed_{seed}"), Object(entries))
                })
                .collect();
            (algorithm_name(&m.curve.name), Object(runs))
        })
        .collect();
    if !thinned.is_empty() {
        notes.push(format!(
            "{}: marl-eval JSON has {steps} steps per run; {} run(s) with more evaluations thinned evenly to that ({})",
            block.name,
            thinned.len(),
            summarise(&thinned)
        ));
    }
    Object(vec![(
        block.env.clone(),
        Object(vec![(block.name.clone(), Object(algorithms))]),
    )])
}

/// The method's directory name as a marl-eval algorithm: marl-eval refuses commas (they
/// separate pairs in its probability-of-improvement plots), which a sweep point's name holds
/// (`our1@trace_len=10,l_rate=0.001`), so they become `;`.
pub fn algorithm_name(curve: &str) -> String {
    curve.replace(',', ";")
}

/// The first few names and how many more.
fn summarise(names: &[String]) -> String {
    const SHOWN: usize = 3;
    if names.len() <= SHOWN {
        names.join(", ")
    } else {
        format!(
            "{}, and {} more",
            names[..SHOWN].join(", "),
            names.len() - SHOWN
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::discover::{discover, tests::write_run};
    use crate::report::block::score;

    #[test]
    fn the_json_nests_env_task_algorithm_run_steps_in_order() {
        let t = tempfile::tempdir().unwrap();
        let bp10 = crate::envs::box_pushing::paper_spec(10);
        // our1: 12 evaluations (seeds 0 and 1), dec-hddrqn: 11 (seeds 0, 1 and 2).
        let pts = |n: u64, base: f64| -> Vec<(u64, f64)> {
            (0..n).map(|i| (i * 10, base + i as f64)).collect()
        };
        for seed in 0..2 {
            write_run(
                t.path(),
                "b",
                "our1",
                seed,
                &pts(12, 0.0),
                bp10.clone(),
                true,
            );
        }
        for seed in 0..3 {
            write_run(
                t.path(),
                "b",
                "dec-hddrqn",
                seed,
                &pts(11, 100.0),
                bp10.clone(),
                true,
            );
        }
        let d = discover(t.path()).unwrap();
        let mut notes = Vec::new();
        let block = score(&d.experiments[0], &mut notes);
        let json = serde_json::to_value(build(&block, &mut notes)).unwrap();
        let task = &json["box-pushing"]["b"];
        let algos: Vec<&String> = task.as_object().unwrap().keys().collect();
        assert_eq!(algos.len(), 2);
        // Seed 2 of Dec-HDDRQN has no Our-1 partner.
        let runs = task["dec-hddrqn"].as_object().unwrap();
        assert_eq!(runs.keys().collect::<Vec<_>>(), ["seed_0", "seed_1"]);
        assert!(
            notes
                .iter()
                .any(|n| n.contains("b/dec-hddrqn: seed(s) 2 left out")),
            "{notes:?}"
        );
        // Eleven steps each; Our-1's twelve thinned, keeping the first and last.
        let text = serde_json::to_string(&build(&block, &mut Vec::new())).unwrap();
        let our1 = &task["our1"]["seed_1"];
        assert_eq!(our1.as_object().unwrap().len(), 12);
        assert_eq!(our1["step_0"]["step_count"], 0);
        assert_eq!(our1["step_0"]["return"], serde_json::json!([0.0]));
        assert_eq!(our1["step_10"]["return"], serde_json::json!([11.0]));
        // write_run: env_steps = 50 x episode; the last evaluation is at episode 110.
        assert_eq!(our1["step_10"]["step_count"], 5500);
        // Final return: ceil(12 / 10) = 2 last evaluations, (10 + 11) / 2.
        assert_eq!(
            our1["absolute_metrics"]["return"],
            serde_json::json!([10.5])
        );
        let dec = &task["dec-hddrqn"]["seed_0"];
        assert_eq!(dec["step_10"]["return"], serde_json::json!([110.0]));
        assert!(
            notes.iter().any(|n| n.contains("11 steps per run")),
            "{notes:?}"
        );
        // Written in order: step_2 before step_10, absolute_metrics last.
        let (s2, s10, abs) = (
            text.find("\"step_2\"").unwrap(),
            text.find("\"step_10\"").unwrap(),
            text.find("\"absolute_metrics\"").unwrap(),
        );
        assert!(s2 < s10 && s10 < abs, "{text}");
    }

    #[test]
    fn sweep_points_lose_their_commas() {
        assert_eq!(
            algorithm_name("our1@trace_len=10,l_rate=0.001"),
            "our1@trace_len=10;l_rate=0.001"
        );
        assert_eq!(algorithm_name("mac-iac"), "mac-iac");
    }
}
