//! The report's two figures per block, as [`Figure`]s that `plot`'s renderer draws (the same
//! fonts, colours, legend placement and files as the learning curves): the performance profile
//! and the sample-efficiency curves, each line with its 95% bootstrap band.

use super::block::Block;
use super::profile::{profile, taus};
use super::sample_efficiency::iqm_curve;
use crate::plot::axis::XAxis;
use crate::plot::figure::{BandPoint, Figure, Series};

/// What both figures' captions say about their bands.
fn band_caption(resamples: usize, seed: u64) -> String {
    format!(
        "band: 95% stratified-bootstrap interval over runs ({resamples} resamples, seed {seed})"
    )
}

/// "Mac-IAC (n = 20 runs)".
fn label(method: &super::block::MethodScores) -> String {
    let n = method.runs.len();
    let runs = if n == 1 { "run" } else { "runs" };
    format!("{} (n = {n} {runs})", method.curve.legend())
}

/// The performance profile of every method of `block`: the fraction of its runs whose final
/// return (divided by the optimum, when known) exceeds each threshold.
pub fn profile_figure(block: &Block, resamples: usize, seed: u64) -> Figure {
    let normalised = block.optimum.is_some();
    let of = |m: &super::block::MethodScores| -> Vec<f64> {
        m.normalised.clone().unwrap_or_else(|| m.scores.clone())
    };
    let all: Vec<f64> = block.methods.iter().flat_map(of).collect();
    let thresholds = taus(&all, normalised);
    let series = block
        .methods
        .iter()
        .filter(|m| !m.scores.is_empty())
        .map(|m| {
            let p = profile(
                &block.name,
                &m.curve.name,
                &of(m),
                &thresholds,
                resamples,
                seed,
            );
            let points = thresholds
                .iter()
                .zip(p.fractions.iter().zip(&p.intervals))
                .map(|(&x, (&y, ci))| BandPoint {
                    x,
                    y,
                    low: ci.low,
                    high: ci.high,
                })
                .collect();
            Series {
                label: label(m),
                colour: m.colour,
                points,
            }
        })
        .collect();
    let (score, x_label) = match block.optimum {
        Some(opt) => (
            format!(
                "final return / optimal return ({})",
                crate::plot::summary::format_return(opt)
            ),
            "normalised final return τ".to_string(),
        ),
        None => (
            "final return (no known optimum to normalise by)".to_string(),
            "final return τ".to_string(),
        ),
    };
    Figure {
        title: format!("{}: performance profile", block.title),
        series,
        optimal: None,
        partial: block.partial.clone(),
        caption: format!(
            "Fraction of runs scoring above τ; score: {score}, a run's final return being the mean \
             of its last 10% of evaluations; {}.",
            band_caption(resamples, seed)
        ),
        x_label,
        x_from_zero: false,
        y_label: "fraction of runs with score > τ".to_string(),
    }
}

/// The sample-efficiency curves of `block` against `axis`, and the methods whose runs share no
/// x range (left out).
pub fn sample_efficiency_figure(
    block: &Block,
    axis: XAxis,
    resamples: usize,
    seed: u64,
) -> (Figure, Vec<String>) {
    let mut series = Vec::new();
    let mut missing = Vec::new();
    let mut interpolated = false;
    for m in block.methods.iter().filter(|m| !m.runs.is_empty()) {
        match iqm_curve(&block.name, &m.curve.name, &m.runs, axis, resamples, seed) {
            Some((points, interp)) => {
                interpolated |= interp;
                series.push(Series {
                    label: label(m),
                    colour: m.colour,
                    points,
                });
            }
            None => missing.push(m.curve.name.clone()),
        }
    }
    let at = if interpolated {
        format!(
            "where a method's runs were evaluated at different {}, each run is linearly \
             interpolated onto {} points of the range all its runs cover",
            axis.label(),
            super::grid::CURVE_POINTS
        )
    } else {
        format!(
            "at each evaluation (at most {} per method, evenly spaced)",
            super::grid::CURVE_POINTS
        )
    };
    let figure = Figure {
        title: format!("{}: sample efficiency", block.title),
        series,
        optimal: block.optimum,
        partial: block.partial.clone(),
        caption: format!(
            "Interquartile mean over the scored runs of the evaluation return, {at}; not smoothed; {}.",
            band_caption(resamples, seed)
        ),
        x_label: axis.label().to_string(),
        x_from_zero: true,
        y_label: "IQM of discounted return".to_string(),
    };
    (figure, missing)
}
