//! From the runs of one experiment to what is drawn: one smoothed curve per method (or sweep
//! point), its legend with the seed count, the optimal-return line, the partial-results mark, and
//! the summary rows. Decides everything about the figure except pixels (`render` draws it).

use super::axis::{XAxis, EVAL_RETURN_UNDISCOUNTED};
use super::discover::{CurveData, ExperimentData, RunData, EVAL_RETURN};
use super::stats::{
    aggregate, aggregate_interpolated, best_return, final_return, first_reaching, mean_and_se,
    mean_over_training, run_mean_over_training, smooth, CurvePoint, Smoothing,
};
use super::summary::CurveSummary;
use crate::algos::families::{Family, Method};

/// An RGB colour.
pub type Rgb = (u8, u8, u8);

/// One curve as drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend text, e.g. "Our-1 (n = 40 seeds)".
    pub label: String,
    /// The curve's colour (never red, which marks the optimum).
    pub colour: Rgb,
    /// The line and its shaded band, point by point: for learning curves the smoothed mean
    /// and mean ± standard error per evaluation (`docs/ALGORITHMS.md` §7.2); `macdec report`
    /// draws bootstrap intervals, which need not be symmetric.
    pub points: Vec<BandPoint>,
}

/// One point of a drawn curve: the line at `y`, the band from `low` to `high`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BandPoint {
    /// Position on the x axis (training episodes, environment steps, a score threshold).
    pub x: f64,
    /// The line's height.
    pub y: f64,
    /// The band's lower edge.
    pub low: f64,
    /// The band's upper edge.
    pub high: f64,
}

impl From<CurvePoint> for BandPoint {
    /// A learning-curve point: the mean, with a band of one standard error either side.
    fn from(p: CurvePoint) -> Self {
        BandPoint {
            x: p.episode as f64,
            y: p.mean,
            low: p.mean - p.se,
            high: p.mean + p.se,
        }
    }
}

/// Everything a figure shows, independent of the backend.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// The figure's title.
    pub title: String,
    /// One series per curve.
    pub series: Vec<Series>,
    /// The optimal return (red dash-dot line), when the runs' setting has a known one.
    pub optimal: Option<f64>,
    /// "partial: m of n runs unfinished", when any run lacks its `finished` marker.
    pub partial: Option<String>,
    /// What the curves and bands are.
    pub caption: String,
    /// The x axis: `training episodes` for learning curves.
    pub x_label: String,
    /// Whether the x axis starts at 0 whatever the data (training starts there); otherwise
    /// it spans the data (a profile's score thresholds).
    pub x_from_zero: bool,
    /// The y axis: `discounted return`, or the plotted metrics column's name.
    pub y_label: String,
}

/// A figure plus its summary rows and notes (e.g. why no optimal line is drawn).
#[derive(Debug, Clone)]
pub struct Built {
    /// The figure.
    pub figure: Figure,
    /// One summary row per curve.
    pub summary: Vec<CurveSummary>,
    /// What the figure left out and why.
    pub notes: Vec<String>,
}

/// Tableau-like colours without red, which is reserved for the optimal line.
const PALETTE: [Rgb; 9] = [
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (148, 103, 189),
    (23, 190, 207),
    (140, 86, 75),
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
];

/// Build the figure and summary of one experiment's `eval_return` curves, smoothed by default.
pub fn build(exp: &ExperimentData) -> Built {
    build_metric(exp, EVAL_RETURN, Smoothing::Auto, XAxis::Episode)
}

/// Build the figure and summary of one experiment whose runs were read for the `metric` column
/// ([`crate::plot::discover::discover_metric`]), each curve smoothed as `smoothing` says for its
/// own evaluation points, against `x`. Only `eval_return` has an optimal line.
///
/// Against environment steps, which differ from seed to seed, each curve is the mean of its runs
/// interpolated onto as many evenly spaced steps as it has evaluation points
/// ([`aggregate_interpolated`]), smoothed by the same window in points; the summary (final
/// returns, the episode reaching 95% of the optimum, the tests) is the same as against episodes.
pub fn build_metric(exp: &ExperimentData, metric: &str, smoothing: Smoothing, x: XAxis) -> Built {
    let mut notes = Vec::new();
    let (optimal, setting_text) = common_setting(exp, &mut notes);
    let optimal = optimal.filter(|_| metric == EVAL_RETURN);
    let mut series = Vec::new();
    let mut summary = Vec::new();
    for (curve, colour) in exp.curves.iter().zip(curve_colours(exp)) {
        let runs: Vec<&[(u64, f64)]> = curve.runs.iter().map(|r| r.points.as_slice()).collect();
        let mean = aggregate(&runs);
        let episodes: Vec<u64> = mean.iter().map(|p| p.episode).collect();
        let half_window = smoothing.half_window(&episodes);
        let points = smooth(&mean, half_window);
        summary.push(summarize(
            curve,
            &mean,
            &points,
            optimal,
            2 * half_window + 1,
        ));
        let drawn = match x {
            XAxis::Episode => points,
            XAxis::EnvSteps | XAxis::AcacTimesteps => {
                let runs: Vec<Vec<(u64, f64)>> =
                    curve.runs.iter().map(RunData::along_steps).collect();
                smooth(&aggregate_interpolated(&runs, mean.len()), half_window)
            }
        };
        series.push(Series {
            label: label(curve),
            colour,
            points: drawn.into_iter().map(BandPoint::from).collect(),
        });
    }
    let partial = partial_mark(exp);
    let title = title(exp, setting_text);
    let quantity = if metric == EVAL_RETURN {
        // Each family says what its evaluation measures (the ICRA methods act greedily,
        // MacroMARL's actor-critic methods sample, P8); curves of no known method are the
        // first family's.
        let measured: std::collections::BTreeSet<&str> = exp
            .curves
            .iter()
            .map(|c| c.method.map_or(Family::ALL[0], Method::family))
            .map(|f| f.facts().evaluated_return)
            .collect();
        match measured.len() {
            1 => measured.into_iter().next().unwrap_or_default().to_string(),
            _ => "the discounted evaluation return (greedy or sampled by method)".to_string(),
        }
    } else if metric == EVAL_RETURN_UNDISCOUNTED {
        "the undiscounted evaluation return (the summed team reward)".to_string()
    } else {
        format!("`{metric}`")
    };
    let along = match x {
        XAxis::Episode => "",
        XAxis::EnvSteps => ", each run interpolated linearly between its evaluations' env steps",
        XAxis::AcacTimesteps => {
            ", each run interpolated linearly between its evaluations' steps of finished training episodes"
        }
    };
    let mut caption = format!(
        "Mean over seeds of {quantity}{along}; band: standard error (ddof 1); {}.",
        smoothing_caption(&summary)
    );
    if let Some(mix) = provenance_mix(exp) {
        notes.push(format!("{}: {mix}", exp.name));
        caption.push_str(&format!(" Note: {mix}."));
    }
    Built {
        figure: Figure {
            title,
            series,
            optimal,
            partial,
            caption,
            x_label: x.label().into(),
            x_from_zero: true,
            y_label: match metric {
                EVAL_RETURN => "discounted return".into(),
                EVAL_RETURN_UNDISCOUNTED => "undiscounted return".into(),
                _ => metric.to_string(),
            },
        },
        summary,
        notes,
    }
}

/// How the drawn curves were smoothed, from the summary rows' windows: one window for all,
/// none, or one per curve.
fn smoothing_caption(rows: &[CurveSummary]) -> String {
    let mut windows: Vec<usize> = rows.iter().map(|r| r.smoothing_points).collect();
    windows.sort_unstable();
    windows.dedup();
    match windows.as_slice() {
        [] | [1] => "not smoothed".to_string(),
        [w] => format!("both smoothed by a centred moving average over {w} evaluation points"),
        _ => {
            let per_curve: Vec<String> = rows
                .iter()
                .map(|r| format!("{} {}", r.legend, r.smoothing_points))
                .collect();
            format!(
                "both smoothed by a centred moving average over evaluation points ({})",
                per_curve.join(", ")
            )
        }
    }
}

/// "mixes 2 git commits (abc1234 x 3, def5678 x 1)" and the like when the runs of a figure were
/// trained by different builds or arithmetic paths, which may round differently.
fn provenance_mix(exp: &ExperimentData) -> Option<String> {
    use std::collections::BTreeMap;
    let runs: Vec<_> = exp.curves.iter().flat_map(|c| &c.runs).collect();
    let mut commits: BTreeMap<String, usize> = BTreeMap::new();
    let mut paths: BTreeMap<String, usize> = BTreeMap::new();
    for p in runs.iter().filter_map(|r| r.provenance.as_ref()) {
        let short: String = p.git_commit.chars().take(12).collect();
        let short = if p.git_commit.ends_with("-dirty") {
            format!("{short}-dirty")
        } else {
            short
        };
        *commits.entry(short).or_default() += 1;
        *paths.entry(p.kernel_path.clone()).or_default() += 1;
    }
    // Another code's logs (no wall time either) never record a provenance: not worth a note.
    let unknown = runs
        .iter()
        .filter(|r| r.provenance.is_none() && r.wall_seconds.is_some())
        .count();
    let list = |m: &BTreeMap<String, usize>| {
        m.iter()
            .map(|(k, n)| format!("{k} x {n}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut parts = Vec::new();
    if commits.len() > 1 {
        parts.push(format!(
            "mixes {} git commits ({})",
            commits.len(),
            list(&commits)
        ));
    }
    let mut keys = paths.keys();
    let first = keys.next();
    if keys.any(|k| !crate::autograd::kernels::same_arithmetic(k, first.expect("not empty"))) {
        parts.push(format!(
            "mixes kernel paths that round differently ({})",
            list(&paths)
        ));
    }
    if unknown > 0 && !commits.is_empty() {
        parts.push(format!("{unknown} run(s) record no provenance"));
    }
    (!parts.is_empty()).then(|| parts.join("; "))
}

fn method_rank(m: Method) -> usize {
    Method::all().iter().position(|&x| x == m).unwrap_or(0)
}

/// A method's colour in every figure: its place among all methods, round the palette (the five
/// ICRA methods and MacroMARL's six never share a figure's default methods, and each set's
/// colours differ).
fn method_colour(m: Method) -> Rgb {
    PALETTE[method_rank(m) % PALETTE.len()]
}

/// Each curve's colour, in the experiment's curve order: a method keeps its colour across
/// figures (and across `plot` and `report`) unless a sweep puts it on the figure twice, when
/// the curves take the palette in turn.
pub fn curve_colours(exp: &ExperimentData) -> Vec<Rgb> {
    let one_per_method = exp.curves.iter().all(|c| c.method.is_some())
        && exp.curves.windows(2).all(|w| w[0].method != w[1].method);
    exp.curves
        .iter()
        .enumerate()
        .map(|(i, curve)| match curve.method {
            Some(m) if one_per_method => method_colour(m),
            _ => PALETTE[i % PALETTE.len()],
        })
        .collect()
}

/// The figure title: the experiment's name, and the domain setting its runs share, if any.
pub fn title(exp: &ExperimentData, setting_text: Option<String>) -> String {
    match setting_text {
        Some(s) => format!("{}: {s}", exp.name),
        None => exp.name.clone(),
    }
}

/// "partial: m of n runs unfinished" when any run of the experiment lacks its `finished`
/// marker.
pub fn partial_mark(exp: &ExperimentData) -> Option<String> {
    let total: usize = exp.curves.iter().map(|c| c.runs.len()).sum();
    let unfinished: usize = exp
        .curves
        .iter()
        .map(|c| c.runs.iter().filter(|r| !r.finished).count())
        .sum();
    (unfinished > 0).then(|| format!("partial: {unfinished} of {total} runs unfinished"))
}

/// The runs whose final return the summary tables count: those that reach the curve's last
/// evaluation episode (an unfinished run stopped short would be scored on an earlier stage of
/// training). Seeds ascending, as discovered.
pub fn complete_runs(curve: &CurveData) -> Vec<&RunData> {
    let last = curve
        .runs
        .iter()
        .filter_map(|r| r.points.last())
        .map(|p| p.0)
        .max();
    curve
        .runs
        .iter()
        .filter(|r| r.points.last().map(|p| p.0) == last)
        .collect()
}

/// "Our-1 (n = 40 seeds)", or "(n = 3 seeds, 1 unfinished)" for partial curves.
fn label(curve: &CurveData) -> String {
    let n = curve.runs.len();
    let unfinished = curve.runs.iter().filter(|r| !r.finished).count();
    let seeds = if n == 1 { "seed" } else { "seeds" };
    if unfinished > 0 {
        format!(
            "{} (n = {n} {seeds}, {unfinished} unfinished)",
            curve.legend()
        )
    } else {
        format!("{} (n = {n} {seeds})", curve.legend())
    }
}

/// The row of the table: final returns over the runs that reach the last episode, where the
/// smoothed mean (a window of `smoothing_points`) first reaches 95% of the optimum, the mean over
/// training, and run times.
fn summarize(
    curve: &CurveData,
    mean: &[CurvePoint],
    smoothed: &[CurvePoint],
    optimal: Option<f64>,
    smoothing_points: usize,
) -> CurveSummary {
    let final_episode = mean
        .last()
        .expect("discover keeps only runs with at least one evaluation")
        .episode;
    let complete = complete_runs(curve);
    let final_returns: Vec<f64> = complete
        .iter()
        .filter_map(|r| final_return(&r.points))
        .collect();
    let best: Vec<f64> = complete
        .iter()
        .filter_map(|r| best_return(&r.points))
        .collect();
    let training_means: Vec<f64> = complete
        .iter()
        .filter_map(|r| run_mean_over_training(&r.points))
        .collect();
    let (final_mean, final_se) = mean_and_se(&final_returns).unwrap_or((f64::NAN, f64::NAN));
    let finished = curve.runs.iter().filter(|r| r.finished).count();
    let minutes: Vec<f64> = curve
        .runs
        .iter()
        .filter(|r| r.finished)
        .filter_map(|r| r.wall_seconds)
        .collect();
    CurveSummary {
        curve: curve.name.clone(),
        legend: curve.legend(),
        seeds: curve.runs.len(),
        finished,
        final_episode,
        final_mean,
        final_se,
        final_n: final_returns.len(),
        best_mean: mean_and_se(&best).map_or(f64::NAN, |(m, _)| m),
        reach95_episode: optimal.and_then(|o| first_reaching(smoothed, 0.95 * o)),
        smoothing_points,
        mean_over_training: mean_over_training(mean).unwrap_or(f64::NAN),
        optimal,
        run_minutes: (!minutes.is_empty())
            .then(|| minutes.iter().sum::<f64>() / minutes.len() as f64 / 60.0),
        final_returns,
        training_means,
    }
}

/// The optimal return and title description shared by every run that has a readable config.
/// Runs that disagree (e.g. a sweep over grid_dim) get no line and no description; `notes`
/// says why.
pub fn common_setting(
    exp: &ExperimentData,
    notes: &mut Vec<String>,
) -> (Option<f64>, Option<String>) {
    let runs = exp.curves.iter().flat_map(|c| &c.runs);
    let settings: Vec<_> = runs.clone().filter_map(|r| r.setting.clone()).collect();
    let missing = runs.count() - settings.len();
    let Some(first) = settings.first() else {
        notes.push(format!(
            "{}: no readable config.toml; no optimal line",
            exp.name
        ));
        return (None, None);
    };
    if missing > 0 {
        notes.push(format!(
            "{}: {missing} run(s) without a readable config.toml",
            exp.name
        ));
    }
    let optimals: Vec<Option<f64>> = settings.iter().map(|s| s.optimal_return()).collect();
    let optimal = if optimals.iter().all(|o| *o == optimals[0]) {
        optimals[0]
    } else {
        notes.push(format!(
            "{}: runs have different optimal returns; no optimal line",
            exp.name
        ));
        None
    };
    let describe = first.describe();
    let same_text = settings.iter().all(|s| s.describe() == describe);
    (optimal, same_text.then_some(describe))
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_method_has_a_colour_and_each_papers_methods_differ() {
        for &family in Family::ALL {
            let colours: Vec<Rgb> = family.methods().into_iter().map(method_colour).collect();
            for (i, c) in colours.iter().enumerate() {
                assert!(!colours[..i].contains(c), "{family:?}: {colours:?}");
            }
        }
    }

    use super::*;
    use crate::envs::EnvSpec;
    use crate::plot::discover::{discover, tests::write_run};

    fn bp10_spec() -> EnvSpec {
        crate::envs::box_pushing::spec(10, 100)
    }

    #[test]
    fn partial_results_are_marked_and_counted_per_curve() {
        let t = tempfile::tempdir().unwrap();
        let full: Vec<(u64, f64)> = (0..5).map(|i| (i * 10, i as f64)).collect();
        write_run(t.path(), "e", "our1", 0, &full, bp10_spec(), true);
        write_run(t.path(), "e", "our1", 1, &full[..2], bp10_spec(), false);
        write_run(t.path(), "e", "cen-ddrqn", 0, &full, bp10_spec(), true);
        let d = discover(t.path()).unwrap();
        let b = build(&d.experiments[0]);
        let f = &b.figure;
        assert_eq!(f.title, "e: Box Pushing 10x10, horizon 100");
        assert_eq!(
            f.partial.as_deref(),
            Some("partial: 1 of 3 runs unfinished")
        );
        assert_eq!(f.optimal, Some(80.71093744250365));
        assert_eq!(f.series[0].label, "Cen-DDRQN (n = 1 seed)");
        assert_eq!(f.series[1].label, "Our-1 (n = 2 seeds, 1 unfinished)");
        // Fixed per-method colours: Cen-DDRQN second, Our-1 third in the palette.
        assert_eq!(f.series[0].colour, PALETTE[1]);
        assert_eq!(f.series[1].colour, PALETTE[2]);
        let s = &b.summary[1];
        assert_eq!(
            (s.seeds, s.finished, s.final_episode, s.final_n),
            (2, 1, 40, 1)
        );
        // Returns 0, 1, 2, 3, 4: the final return is the mean of the last ceil(10% of 5) = 1
        // evaluation of the one run reaching episode 40; one run, so no spread.
        assert!((s.final_mean - 4.0).abs() < 1e-12);
        assert_eq!(s.final_se, 0.0);
        // Never within 95% of 80.71; average height of the mean curve 0..4 is 2.
        assert_eq!(s.reach95_episode, None);
        assert!((s.mean_over_training - 2.0).abs() < 1e-12);
        // wall_seconds = episode * 0.5 = 20 s for the finished run.
        assert!((s.run_minutes.unwrap() - 20.0 / 60.0).abs() < 1e-12);
    }

    #[test]
    fn figures_say_when_they_mix_commits_or_kernel_paths() {
        let t = tempfile::tempdir().unwrap();
        let stamp = |dir: &std::path::Path, commit: &str, kernel: &str| {
            let path = dir.join("config.toml");
            let mut text = std::fs::read_to_string(&path).unwrap();
            text.push_str(&format!(
                "\n[provenance]\nmacdec_version = \"0.1.0\"\ngit_commit = \"{commit}\"\n\
                 kernel_path = \"{kernel}\"\ncpu_model = \"test\"\n"
            ));
            std::fs::write(path, text).unwrap();
        };
        let a = write_run(t.path(), "e", "our1", 0, &[(0, 1.0)], bp10_spec(), true);
        let b = write_run(t.path(), "e", "our1", 1, &[(0, 1.0)], bp10_spec(), true);
        stamp(&a, &"a".repeat(40), "avx512");
        stamp(&b, &"a".repeat(40), "avx512");
        let built = build(&discover(t.path()).unwrap().experiments[0]);
        assert!(built.notes.is_empty(), "{:?}", built.notes);
        assert!(!built.figure.caption.contains("Note:"));
        // Today's AVX2 path has the AVX-512 path's arithmetic: nothing to say.
        let b = write_run(t.path(), "e", "our1", 1, &[(0, 1.0)], bp10_spec(), true);
        stamp(&b, &"a".repeat(40), "avx2-fma");
        let built = build(&discover(t.path()).unwrap().experiments[0]);
        assert!(built.notes.is_empty(), "{:?}", built.notes);

        let b = write_run(t.path(), "e", "our1", 1, &[(0, 1.0)], bp10_spec(), true);
        stamp(&b, &"b".repeat(40), "avx2");
        write_run(t.path(), "e", "our2", 0, &[(0, 1.0)], bp10_spec(), true);
        let built = build(&discover(t.path()).unwrap().experiments[0]);
        let note = built.notes.join("\n");
        assert!(
            note.contains("mixes 2 git commits (aaaaaaaaaaaa x 1, bbbbbbbbbbbb x 1)"),
            "{note}"
        );
        assert!(
            note.contains("mixes kernel paths that round differently (avx2 x 1, avx512 x 1)"),
            "{note}"
        );
        assert!(note.contains("1 run(s) record no provenance"), "{note}");
        assert!(built.figure.caption.contains("Note: mixes 2 git commits"));
    }

    /// Another code's logs drawn beside ours have no time and no provenance: the summary gives
    /// them no minutes (not 0.0) and the figure no "record no provenance" note.
    #[test]
    fn logs_beside_ours_have_no_minutes_and_no_provenance_note() {
        let t = tempfile::tempdir().unwrap();
        let a = write_run(t.path(), "e", "our1", 0, &[(0, 1.0)], bp10_spec(), true);
        let path = a.join("config.toml");
        let mut text = std::fs::read_to_string(&path).unwrap();
        text.push_str(&format!(
            "\n[provenance]\nmacdec_version = \"0.1.0\"\ngit_commit = \"{}\"\n\
             kernel_path = \"avx512\"\ncpu_model = \"test\"\n",
            "a".repeat(40)
        ));
        std::fs::write(path, text).unwrap();
        let mut exp = discover(t.path()).unwrap().experiments[0].clone();
        let mut theirs = exp.curves[0].clone();
        theirs.name = "theirs".into();
        for r in &mut theirs.runs {
            r.wall_seconds = None;
            r.provenance = None;
        }
        exp.curves.push(theirs);
        let built = build(&exp);
        assert!(built.notes.is_empty(), "{:?}", built.notes);
        let s = &built.summary[1];
        assert_eq!((s.seeds, s.finished, s.run_minutes), (1, 1, None));
        assert!(built.summary[0].run_minutes.is_some());
    }

    #[test]
    fn mixed_settings_have_no_optimal_line() {
        let t = tempfile::tempdir().unwrap();
        write_run(t.path(), "e", "our1", 0, &[(0, 1.0)], bp10_spec(), true);
        write_run(
            t.path(),
            "e",
            "our2",
            0,
            &[(0, 1.0)],
            crate::envs::warehouse::paper_spec(),
            true,
        );
        let d = discover(t.path()).unwrap();
        let b = build(&d.experiments[0]);
        assert_eq!(b.figure.optimal, None);
        assert_eq!(b.figure.title, "e");
        assert!(b.figure.partial.is_none());
        assert!(b.notes.iter().any(|n| n.contains("different optimal")));
    }

    #[test]
    fn sweep_variants_of_one_method_get_distinct_colours() {
        let t = tempfile::tempdir().unwrap();
        write_run(
            t.path(),
            "e",
            "our1@trace_len=10",
            0,
            &[(0, 1.0)],
            bp10_spec(),
            true,
        );
        write_run(
            t.path(),
            "e",
            "our1@trace_len=20",
            0,
            &[(0, 1.0)],
            bp10_spec(),
            true,
        );
        let d = discover(t.path()).unwrap();
        let f = build(&d.experiments[0]).figure;
        assert_ne!(f.series[0].colour, f.series[1].colour);
        assert_eq!(f.series[1].label, "Our-1 @ trace_len=20 (n = 1 seed)");
    }
}
