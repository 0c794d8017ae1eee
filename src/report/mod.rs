//! Aggregate statistics of a results tree, as Gorsane et al. (*Towards a Standardised
//! Performance Evaluation Protocol for Cooperative MARL*, NeurIPS 2022) ask and rliable
//! (Agarwal et al., *Deep RL at the Edge of the Statistical Precipice*, NeurIPS 2021) computes
//! them: `macdec report`. Where `plot` gives a learning curve's mean and standard error and
//! Welch tests, a report gives, per block (experiment directory) and method, point estimates
//! that a few runs cannot sway and intervals that assume no normal distribution.
//!
//! `block` scores each method's runs by their final return (as the summary tables do),
//! `scores` holds the point estimates, `bootstrap` their intervals, `aggregate`,
//! `improvement`, `profile` and `sample_efficiency` the four analyses, `figures` draws them
//! with `plot`'s renderer, and `marl_eval_json` exports the raw runs for marl-eval.
//! [`report_results`] runs it all.

pub mod aggregate;
pub mod block;
pub mod bootstrap;
pub mod error;
pub mod figures;
pub mod grid;
pub mod improvement;
pub mod marl_eval_json;
pub mod profile;
pub mod sample_efficiency;
pub mod scores;

pub use crate::plot::axis::XAxis;
pub use error::ReportError;

use crate::plot::discover::{discover_along, ExperimentData, EVAL_RETURN};
use crate::plot::summary::{format_number, write_csv};
use crate::plot::PlotError;
use aggregate::AggregateRow;
use improvement::ImprovementRow;
use std::path::{Path, PathBuf};

/// What [`report_results`] computes and how.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReportOptions {
    /// Bootstrap resamples per interval, 1..=[`bootstrap::MAX_RESAMPLES`].
    pub resamples: usize,
    /// The seed every interval's stream derives from ([`bootstrap::stream`]).
    pub seed: u64,
    /// The x axis of the sample-efficiency curves.
    pub x_axis: XAxis,
    /// The blocks to report, by directory name; empty for all.
    pub blocks: Vec<String>,
}

impl Default for ReportOptions {
    /// 2000 resamples, seed 0, against episodes, every block.
    fn default() -> Self {
        ReportOptions {
            resamples: bootstrap::DEFAULT_RESAMPLES,
            seed: 0,
            x_axis: XAxis::Episode,
            blocks: Vec::new(),
        }
    }
}

/// The files written for one block and the numbers in them.
#[derive(Debug, Clone)]
pub struct BlockReport {
    /// The block's name.
    pub block: String,
    /// The figure title (block and domain setting).
    pub title: String,
    /// `<block>_aggregate.csv`.
    pub aggregate_csv: PathBuf,
    /// Its rows.
    pub aggregate: Vec<AggregateRow>,
    /// `<block>_improvement.csv`.
    pub improvement_csv: PathBuf,
    /// Its rows.
    pub improvement: Vec<ImprovementRow>,
    /// The figures: `<block>_profile.{png,svg}` and `<block>_sample_efficiency.{png,svg}`.
    pub figures: Vec<PathBuf>,
    /// `<block>_marl_eval.json`.
    pub marl_eval_json: PathBuf,
}

/// What [`report_results`] did, and what it left out (`notes`, for the user to read).
#[derive(Debug, Clone)]
pub struct Report {
    /// One per block reported.
    pub blocks: Vec<BlockReport>,
    /// What was left out and why.
    pub notes: Vec<String>,
}

impl Report {
    /// A Markdown table per block: each method's runs and its metrics with their intervals.
    pub fn markdown(&self) -> String {
        self.blocks
            .iter()
            .map(markdown_table)
            .collect::<Vec<_>>()
            .join("\n")
    }
}

/// Report every block under `results` (or those `options.blocks` names) into `out`: per block
/// `<block>_aggregate.csv`, `<block>_improvement.csv`, `<block>_profile.{png,svg}`,
/// `<block>_sample_efficiency.{png,svg}` and `<block>_marl_eval.json`, each written atomically.
pub fn report_results(
    results: &Path,
    out: &Path,
    options: &ReportOptions,
) -> Result<Report, ReportError> {
    let max = bootstrap::MAX_RESAMPLES;
    if !(1..=max).contains(&options.resamples) {
        return Err(ReportError::Resamples {
            got: options.resamples,
            max,
        });
    }
    let found = discover_along(results, EVAL_RETURN, options.x_axis.steps_column())?;
    let mut notes = found.notes;
    let chosen = choose(&found.experiments, &options.blocks)?;
    std::fs::create_dir_all(out).map_err(|source| PlotError::Write {
        path: out.to_path_buf(),
        source,
    })?;
    let mut blocks = Vec::new();
    for exp in chosen {
        blocks.push(report_block(exp, out, options, &mut notes)?);
    }
    Ok(Report { blocks, notes })
}

/// The experiments `names` asks for, in its order (all, in discovery order, when empty).
fn choose<'a>(
    experiments: &'a [ExperimentData],
    names: &[String],
) -> Result<Vec<&'a ExperimentData>, ReportError> {
    if names.is_empty() {
        return Ok(experiments.iter().collect());
    }
    names
        .iter()
        .map(|name| {
            experiments
                .iter()
                .find(|e| &e.name == name)
                .ok_or_else(|| ReportError::NoSuchBlock {
                    name: name.clone(),
                    found: experiments
                        .iter()
                        .map(|e| e.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", "),
                })
        })
        .collect()
}

fn report_block(
    exp: &ExperimentData,
    out: &Path,
    options: &ReportOptions,
    notes: &mut Vec<String>,
) -> Result<BlockReport, ReportError> {
    let ReportOptions {
        resamples, seed, ..
    } = *options;
    let block = block::score(exp, notes);
    let name = &block.name;

    let aggregate = aggregate::rows(&block, resamples, seed);
    let aggregate_csv = out.join(format!("{name}_aggregate.csv"));
    write_csv(&aggregate_csv, &aggregate)?;

    let scored: Vec<(String, Vec<f64>)> = block
        .methods
        .iter()
        .map(|m| (m.curve.name.clone(), m.scores.clone()))
        .collect();
    let improvement = improvement::pairwise(name, &scored, resamples, seed);
    let improvement_csv = out.join(format!("{name}_improvement.csv"));
    write_csv(&improvement_csv, &improvement)?;

    let mut figures = Vec::new();
    let profile = figures::profile_figure(&block, resamples, seed);
    figures.extend(draw(&profile, out, &format!("{name}_profile"))?);
    let (curves, missing) =
        figures::sample_efficiency_figure(&block, options.x_axis, resamples, seed);
    for method in missing {
        notes.push(format!(
            "{name}/{method}: its runs share no range of {}; no sample-efficiency curve",
            options.x_axis.label()
        ));
    }
    figures.extend(draw(&curves, out, &format!("{name}_sample_efficiency"))?);

    let json = marl_eval_json::build(&block, notes);
    let marl_eval_json = out.join(format!("{name}_marl_eval.json"));
    let mut text = serde_json::to_vec(&json).map_err(|e| PlotError::Write {
        path: marl_eval_json.clone(),
        source: std::io::Error::other(e),
    })?;
    text.push(b'\n');
    crate::files::atomic::write_atomic(&marl_eval_json, &text).map_err(|source| {
        PlotError::Write {
            path: marl_eval_json.clone(),
            source,
        }
    })?;

    Ok(BlockReport {
        block: name.clone(),
        title: block.title.clone(),
        aggregate_csv,
        aggregate,
        improvement_csv,
        improvement,
        figures,
        marl_eval_json,
    })
}

/// Draw `figure` as `<stem>.png` and `<stem>.svg` in `out`; the two paths.
fn draw(
    figure: &crate::plot::figure::Figure,
    out: &Path,
    stem: &str,
) -> Result<[PathBuf; 2], PlotError> {
    let png = out.join(format!("{stem}.png"));
    let svg = out.join(format!("{stem}.svg"));
    crate::plot::render::render_files(figure, &png, &svg)?;
    Ok([png, svg])
}

/// One block's Markdown table: a row per method, a column per metric.
fn markdown_table(b: &BlockReport) -> String {
    let metrics: Vec<&str> = aggregate::Metric::ALL
        .iter()
        .map(|m| m.name())
        .filter(|m| b.aggregate.iter().any(|r| r.metric == *m))
        .collect();
    let mut s = format!("### {}\n\n| method | runs |", b.title);
    for m in &metrics {
        s.push_str(&format!(" {m} [95% CI] |"));
    }
    s.push_str(&format!("\n|---|---|{}\n", "---|".repeat(metrics.len())));
    let mut methods: Vec<&str> = b.aggregate.iter().map(|r| r.method.as_str()).collect();
    methods.dedup();
    for method in methods {
        let rows: Vec<&AggregateRow> = b.aggregate.iter().filter(|r| r.method == method).collect();
        s.push_str(&format!("| {method} | {} |", rows[0].n_runs));
        for m in &metrics {
            let cell = rows
                .iter()
                .find(|r| r.metric == *m)
                .map_or("-".to_string(), |r| {
                    let two = |v| format_number(v, 2);
                    format!("{} [{}, {}]", two(r.value), two(r.ci_low), two(r.ci_high))
                });
            s.push_str(&format!(" {cell} |"));
        }
        s.push('\n');
    }
    s
}
