//! The long learning check (ignored by default; `cargo test --release --test learning -- --ignored
//! --nocapture`): on Box Pushing 10x10 with the paper's hyperparameters (Figure 4a's config),
//! Our-1, Cen-DDRQN and Dec-HDDRQN each reach a final greedy return within 5% of the optimal
//! 80.71 in at least 4 of 5 seeds. Runs are resumable and kept in `target/learning-check/`.

use macdec::algos::families::Method;
use macdec::algos::value::method::ValueMethod;
use macdec::experiment::definition::config::{Experiment, Overrides};
use macdec::experiment::run::metrics::{read, METRICS_FILE};
use macdec::experiment::run::runner::{run_all, RunStatus, RunnerOptions};
use macdec::experiment::run::train_run::train_run;
use std::path::Path;

const OPTIMAL_BP10: f64 = 80.71093744250365;

#[test]
#[ignore = "trains 15 full runs (about an hour on two cores); run it explicitly"]
fn bp10_methods_reach_the_optimum_in_four_of_five_seeds() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let overrides = Overrides {
        methods: Some(vec![
            Method::Value(ValueMethod::Our1),
            Method::Value(ValueMethod::CenDdrqn),
            Method::Value(ValueMethod::DecHddrqn),
        ]),
        seeds: Some((0..5).collect()),
        set: Vec::new(),
    };
    let experiment =
        Experiment::load(&root.join("experiments/fig4a_bp10.toml"), &overrides).unwrap();
    let runs = experiment.runs().unwrap();
    let opts = RunnerOptions {
        out: root.join("target/learning-check"),
        jobs: std::thread::available_parallelism().map_or(1, |n| n.get()),
        force: false,
        quiet: true,
        tensorboard: None,
    };
    let statuses = run_all(&runs, &opts, |spec, dir, progress| {
        train_run(spec, dir, progress, false).map_err(|e| e.to_string())
    });
    assert!(
        statuses.iter().all(|s| !matches!(s, RunStatus::Failed(_))),
        "{statuses:?}"
    );
    for method in [
        Method::Value(ValueMethod::Our1),
        Method::Value(ValueMethod::CenDdrqn),
        Method::Value(ValueMethod::DecHddrqn),
    ] {
        let finals: Vec<f64> = runs
            .iter()
            .filter(|r| r.method == method)
            .map(|r| {
                let rows = read(&r.dir(&opts.out).join(METRICS_FILE)).unwrap().rows;
                rows.last().unwrap().eval_return
            })
            .collect();
        let good = finals.iter().filter(|&&g| g >= 0.95 * OPTIMAL_BP10).count();
        println!("{method}: final greedy returns {finals:?} ({good} of 5 within 5% of {OPTIMAL_BP10:.2})");
        assert!(
            good >= 4,
            "{method}: only {good} of 5 seeds within 5% of the optimum: {finals:?}"
        );
    }
}
