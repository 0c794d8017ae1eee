//! The statistics behind a learning curve (`docs/ALGORITHMS.md` §7.2): the mean over runs at each
//! evaluation point, its standard error, and the centred moving average the paper calls
//! "smoothed by 20 neighbors". Pure functions on numbers; no files, no drawing. Shared by the
//! figures (`plot`) and the terminal report after training (`experiment::run::report`), and
//! below both.

use std::collections::BTreeMap;

/// Points on each side of the centre in the paper's smoothing: window 21 = the point plus 10
/// neighbours on each side (`docs/ALGORITHMS.md` §7.2, open question O1). The widest window [`Smoothing::Auto`]
/// chooses.
pub const SMOOTH_HALF_WINDOW: usize = 10;

/// [`Smoothing::Auto`]'s half window is the curve's evaluation count divided by this (at most
/// [`SMOOTH_HALF_WINDOW`]): a curve of fewer than 80 points moves by at most one evaluation
/// spacing, one of 400 or more (every committed figure) gets the paper's 21 points.
pub const AUTO_POINTS_PER_HALF_WINDOW: usize = 40;

/// The widest window a user may ask for, in evaluation points or episodes (far beyond any run;
/// a bound so a typo cannot make the moving average quadratic in a huge number).
pub const MAX_SMOOTH_WINDOW: u64 = 1_000_001;

/// How a curve is smoothed before it is drawn and read for "95% of optimal first at"
/// (`macdec plot --smooth`). A centred moving average can move the point where a curve crosses
/// a level by up to its half window, so short or coarsely evaluated curves need a narrow one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Smoothing {
    /// Half window = evaluation points / [`AUTO_POINTS_PER_HALF_WINDOW`], at most
    /// [`SMOOTH_HALF_WINDOW`] (`auto`, the default).
    #[default]
    Auto,
    /// A centred window of this many evaluation points, odd; 1 is no smoothing (`0` and `1`
    /// on the command line, or `<n>`).
    Points(u64),
    /// A centred window spanning about this many training episodes (`<n>ep`): the half window
    /// is n / 2 divided by the curve's evaluation spacing (its median), rounded down.
    Episodes(u64),
}

impl Smoothing {
    /// No smoothing.
    pub const NONE: Smoothing = Smoothing::Points(1);

    /// Parse `auto`, `0` (none), an odd number of evaluation points, or `<n>ep` episodes.
    pub fn parse(text: &str) -> Result<Smoothing, String> {
        let text = text.trim();
        if text == "auto" {
            return Ok(Smoothing::Auto);
        }
        let (digits, episodes) = match text.strip_suffix("ep") {
            Some(d) => (d, true),
            None => (text, false),
        };
        let n: u64 = digits.parse().map_err(|_| {
            format!(
                "`{text}` is not a smoothing: give `auto`, `0` (none), an odd number of \
                 evaluation points such as `21`, or a number of training episodes such as `2000ep`"
            )
        })?;
        if n > MAX_SMOOTH_WINDOW {
            return Err(format!(
                "a smoothing window of {n} is beyond the limit {MAX_SMOOTH_WINDOW}"
            ));
        }
        if episodes {
            return Ok(Smoothing::Episodes(n));
        }
        match n {
            0 | 1 => Ok(Smoothing::NONE),
            n if n % 2 == 0 => Err(format!(
                "a centred window has an odd number of points: `{n}` is even (use {} or {})",
                n - 1,
                n + 1
            )),
            n => Ok(Smoothing::Points(n)),
        }
    }

    /// The half window for a curve evaluated at `episodes` (sorted): points on each side of the
    /// centre that [`smooth`] averages.
    pub fn half_window(&self, episodes: &[u64]) -> usize {
        let at_most_len = |h: u64| h.min(episodes.len() as u64) as usize;
        match *self {
            Smoothing::Auto => {
                (episodes.len() / AUTO_POINTS_PER_HALF_WINDOW).min(SMOOTH_HALF_WINDOW)
            }
            Smoothing::Points(n) => at_most_len(n.saturating_sub(1) / 2),
            Smoothing::Episodes(n) => match median_spacing(episodes) {
                Some(spacing) => at_most_len(n / 2 / spacing),
                None => 0,
            },
        }
    }
}

impl std::fmt::Display for Smoothing {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Smoothing::Auto => write!(f, "auto"),
            Smoothing::Points(n) if *n <= 1 => write!(f, "0"),
            Smoothing::Points(n) => write!(f, "{n}"),
            Smoothing::Episodes(n) => write!(f, "{n}ep"),
        }
    }
}

/// The median gap between consecutive evaluation episodes (the lower middle of an even count);
/// `None` for fewer than two points.
fn median_spacing(episodes: &[u64]) -> Option<u64> {
    let mut gaps: Vec<u64> = episodes
        .windows(2)
        .map(|w| w[1].saturating_sub(w[0]).max(1))
        .collect();
    if gaps.is_empty() {
        return None;
    }
    gaps.sort_unstable();
    Some(gaps[(gaps.len() - 1) / 2])
}

/// One evaluation point of a curve aggregated over runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurvePoint {
    /// Training episodes completed (the metrics' `episode` column); environment steps for a
    /// curve drawn against them ([`aggregate_interpolated`]).
    pub episode: u64,
    /// Mean over the runs that have this point.
    pub mean: f64,
    /// Standard error of that mean: sample std (ddof 1) / sqrt(n); 0 when n = 1.
    pub se: f64,
    /// How many runs have this point (fewer at the tail when runs are unfinished).
    pub n: usize,
}

/// Mean and standard error (sample std with ddof 1, over sqrt(n)) of `values`.
/// The error is 0 for a single value, since one run says nothing about the spread.
/// Returns `None` for no values.
pub fn mean_and_se(values: &[f64]) -> Option<(f64, f64)> {
    let n = values.len();
    if n == 0 {
        return None;
    }
    let mean = values.iter().sum::<f64>() / n as f64;
    if n == 1 {
        return Some((mean, 0.0));
    }
    let ss: f64 = values.iter().map(|v| (v - mean) * (v - mean)).sum();
    let std = (ss / (n - 1) as f64).sqrt();
    Some((mean, std / (n as f64).sqrt()))
}

/// Aggregate runs into one curve: at every episode any run evaluated at, the mean and standard
/// error over the runs that have that episode. Runs of different lengths (unfinished runs) thus
/// contribute where they have data, and `n` says how many did. Each run is a list of
/// `(episode, return)` with distinct episodes. The result is sorted by episode.
pub fn aggregate(runs: &[&[(u64, f64)]]) -> Vec<CurvePoint> {
    let mut by_episode: BTreeMap<u64, Vec<f64>> = BTreeMap::new();
    for run in runs {
        for &(episode, value) in run.iter() {
            by_episode.entry(episode).or_default().push(value);
        }
    }
    by_episode
        .into_iter()
        .filter_map(|(episode, values)| {
            let (mean, se) = mean_and_se(&values)?;
            Some(CurvePoint {
                episode,
                mean,
                se,
                n: values.len(),
            })
        })
        .collect()
}

/// A run's value at `at` by linear interpolation between its evaluations either side (the
/// first evaluation at `at` itself when there is one; the end values outside the run's range,
/// as `numpy.interp` does). `run` is `(x, value)` with x non-decreasing and not empty.
pub fn interpolate(run: &[(f64, f64)], at: f64) -> f64 {
    let after = run.partition_point(|p| p.0 < at);
    if after == run.len() {
        return run[run.len() - 1].1;
    }
    let (x1, y1) = run[after];
    if after == 0 || x1 == at {
        return y1;
    }
    let (x0, y0) = run[after - 1];
    y0 + (y1 - y0) * (at - x0) / (x1 - x0)
}

/// Aggregate runs evaluated at different x (environment steps, which differ between seeds) into
/// one curve of `points` evenly spaced integer x from the earliest first evaluation to the latest
/// last one: at each x, the mean and standard error over the runs whose own range holds x, each
/// linearly interpolated between its evaluations either side ([`interpolate`]). So, as in
/// [`aggregate`], an unfinished run contributes where it has data and `n` says how many did.
/// Each run is `(x, value)` with x non-decreasing; empty runs are ignored.
pub fn aggregate_interpolated(runs: &[Vec<(u64, f64)>], points: usize) -> Vec<CurvePoint> {
    let runs: Vec<Vec<(f64, f64)>> = runs
        .iter()
        .filter(|r| !r.is_empty())
        .map(|r| r.iter().map(|&(x, v)| (x as f64, v)).collect())
        .collect();
    let (Some(lo), Some(hi)) = (
        runs.iter().map(|r| r[0].0).reduce(f64::min),
        runs.iter().map(|r| r[r.len() - 1].0).reduce(f64::max),
    ) else {
        return Vec::new();
    };
    let xs: Vec<u64> = match points {
        0 => Vec::new(),
        _ if points == 1 || hi == lo => vec![hi as u64],
        _ => {
            let mut xs: Vec<u64> = (0..points)
                .map(|i| (lo + (hi - lo) * i as f64 / (points - 1) as f64).round() as u64)
                .collect();
            xs.dedup();
            xs
        }
    };
    xs.into_iter()
        .filter_map(|x| {
            let at = x as f64;
            let values: Vec<f64> = runs
                .iter()
                .filter(|r| r[0].0 <= at && at <= r[r.len() - 1].0)
                .map(|r| interpolate(r, at))
                .collect();
            let (mean, se) = mean_and_se(&values)?;
            Some(CurvePoint {
                episode: x,
                mean,
                se,
                n: values.len(),
            })
        })
        .collect()
}

/// Centred moving average: point i becomes the mean of points i-h ..= i+h that exist, so the
/// window is truncated (not padded) at both ends.
pub fn moving_average(xs: &[f64], half_window: usize) -> Vec<f64> {
    (0..xs.len())
        .map(|i| {
            let lo = i.saturating_sub(half_window);
            let hi = (i + half_window + 1).min(xs.len());
            xs[lo..hi].iter().sum::<f64>() / (hi - lo) as f64
        })
        .collect()
}

/// The paper's smoothing of a curve: the moving average applied separately to the mean and to
/// the standard error (`docs/ALGORITHMS.md` §7.2). Episodes and counts are kept.
pub fn smooth(points: &[CurvePoint], half_window: usize) -> Vec<CurvePoint> {
    let means: Vec<f64> = points.iter().map(|p| p.mean).collect();
    let ses: Vec<f64> = points.iter().map(|p| p.se).collect();
    let means = moving_average(&means, half_window);
    let ses = moving_average(&ses, half_window);
    points
        .iter()
        .zip(means.into_iter().zip(ses))
        .map(|(p, (mean, se))| CurvePoint { mean, se, ..*p })
        .collect()
}

/// Fraction of a run's last evaluations averaged into its final return.
pub const FINAL_FRACTION: f64 = 0.1;

/// How many of a run's `n` evaluations are its "last 10%": ceil(n / 10), at least one, in
/// integers (`scripts/late_snapshots.py` takes the same count).
pub fn final_count(n: usize) -> usize {
    n.div_ceil(10).max(1)
}

/// A run's final return: the mean of its last 10% of evaluations (at least one), which is what
/// the tables and tests compare (one late evaluation is too noisy on its own).
pub fn final_return(points: &[(u64, f64)]) -> Option<f64> {
    if points.is_empty() {
        return None;
    }
    let k = final_count(points.len());
    let tail = &points[points.len() - k..];
    Some(tail.iter().map(|p| p.1).sum::<f64>() / k as f64)
}

/// A run's best single evaluation: the return of the policy the reference keeps (it saves the
/// decentralized nets whenever an evaluation matches the best so far, so the trained policies it
/// ships are best-evaluation snapshots, not final ones).
pub fn best_return(points: &[(u64, f64)]) -> Option<f64> {
    points.iter().map(|p| p.1).reduce(f64::max)
}

/// The first episode at which a (smoothed) curve's mean reaches `threshold`, if it ever does.
pub fn first_reaching(points: &[CurvePoint], threshold: f64) -> Option<u64> {
    points
        .iter()
        .find(|p| p.mean >= threshold)
        .map(|p| p.episode)
}

/// The area under a mean curve divided by its episode span (trapezoids): the curve's average
/// height over training, so curves of one length compare directly. A single point is its value.
pub fn mean_over_training(points: &[CurvePoint]) -> Option<f64> {
    let heights: Vec<(u64, f64)> = points.iter().map(|p| (p.episode, p.mean)).collect();
    run_mean_over_training(&heights)
}

/// One run's own average height over training (the area under its curve over its span, by the
/// same trapezoids): the per-seed measure of how early a method learns, which the tests between
/// curves compare the way they compare final returns.
pub fn run_mean_over_training(points: &[(u64, f64)]) -> Option<f64> {
    let (first, last) = (points.first()?, points.last()?);
    let span = (last.0 - first.0) as f64;
    if span == 0.0 {
        return Some(first.1);
    }
    let area: f64 = points
        .windows(2)
        .map(|w| (w[1].0 - w[0].0) as f64 * (w[0].1 + w[1].1) / 2.0)
        .sum();
    Some(area / span)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_of_different_step_counts_are_interpolated_onto_a_shared_step_grid() {
        // Run a: 0 at step 0, 10 at step 100. Run b: 0 at 0, 20 at 200 (it stops later).
        let a = vec![(0, 0.0), (100, 10.0)];
        let b = vec![(0, 0.0), (200, 20.0)];
        let curve = aggregate_interpolated(&[a, b], 5);
        let x: Vec<u64> = curve.iter().map(|p| p.episode).collect();
        assert_eq!(x, [0, 50, 100, 150, 200]);
        // Both runs give x / 10 where both have data; past step 100 only b does.
        let means: Vec<f64> = curve.iter().map(|p| p.mean).collect();
        assert_eq!(means, [0.0, 5.0, 10.0, 15.0, 20.0]);
        let n: Vec<usize> = curve.iter().map(|p| p.n).collect();
        assert_eq!(n, [2, 2, 2, 1, 1]);
        assert!(
            curve.iter().all(|p| p.se == 0.0),
            "the runs agree where they overlap"
        );
        // Unequal runs: the mean and its standard error over the two interpolated values.
        let c =
            aggregate_interpolated(&[vec![(0, 0.0), (10, 10.0)], vec![(0, 0.0), (10, 30.0)]], 3);
        assert_eq!(c[1].episode, 5);
        assert_eq!((c[1].mean, c[1].n), (10.0, 2));
        assert_eq!(c[1].se, mean_and_se(&[5.0, 15.0]).unwrap().1);
        assert!(aggregate_interpolated(&[], 5).is_empty());
        assert_eq!(aggregate_interpolated(&[vec![(7, 1.0)]], 5)[0].episode, 7);
    }

    #[test]
    fn interpolation_holds_the_ends_and_joins_neighbours_linearly() {
        let run = [(10.0, 1.0), (20.0, 3.0), (20.0, 5.0), (30.0, 7.0)];
        assert_eq!(interpolate(&run, 0.0), 1.0);
        assert_eq!(interpolate(&run, 15.0), 2.0);
        // The first evaluation at a repeated x.
        assert_eq!(interpolate(&run, 20.0), 3.0);
        assert_eq!(interpolate(&run, 25.0), 6.0);
        assert_eq!(interpolate(&run, 99.0), 7.0);
    }

    fn pt(episode: u64, mean: f64) -> CurvePoint {
        CurvePoint {
            episode,
            mean,
            se: 0.0,
            n: 1,
        }
    }

    #[test]
    fn final_return_averages_the_last_tenth_of_evaluations() {
        // 25 points: ceil(2.5) = 3 last points, values 22, 23, 24.
        let pts: Vec<(u64, f64)> = (0..25).map(|i| (i * 10, i as f64)).collect();
        assert_eq!(final_return(&pts), Some(23.0));
        assert_eq!(final_return(&pts[..1]), Some(0.0));
        assert_eq!(final_return(&[]), None);
    }

    #[test]
    fn the_last_tenth_rounds_up_and_keeps_one() {
        let counts: Vec<usize> = [0, 1, 9, 10, 11, 30, 400, 417, 1501, 4001]
            .iter()
            .map(|&n| final_count(n))
            .collect();
        assert_eq!(counts, vec![1, 1, 1, 1, 2, 3, 40, 42, 151, 401]);
        // The same as the fraction's ceiling wherever floating point would round it.
        for n in 1..5000 {
            assert_eq!(final_count(n), (n as f64 * FINAL_FRACTION).ceil() as usize);
        }
    }

    #[test]
    fn smoothing_parses_auto_none_points_and_episodes() {
        assert_eq!(Smoothing::parse("auto"), Ok(Smoothing::Auto));
        assert_eq!(Smoothing::parse("0"), Ok(Smoothing::NONE));
        assert_eq!(Smoothing::parse("1"), Ok(Smoothing::NONE));
        assert_eq!(Smoothing::parse("21"), Ok(Smoothing::Points(21)));
        assert_eq!(Smoothing::parse("2000ep"), Ok(Smoothing::Episodes(2000)));
        let even = Smoothing::parse("20").unwrap_err();
        assert!(even.contains("odd") && even.contains("19 or 21"), "{even}");
        for bad in ["", "-3", "ep", "1.5", "lots", "99999999999999999999"] {
            assert!(Smoothing::parse(bad).is_err(), "{bad}");
        }
        assert!(Smoothing::parse("2000000").unwrap_err().contains("limit"));
        for s in ["auto", "0", "21", "2000ep"] {
            assert_eq!(Smoothing::parse(s).unwrap().to_string(), s);
        }
    }

    #[test]
    fn auto_smoothing_keeps_short_curves_within_one_evaluation() {
        let episodes = |n: u64| (0..n).map(|i| i * 200).collect::<Vec<u64>>();
        let auto = |n| Smoothing::Auto.half_window(&episodes(n));
        // The custom-domain example: 16 points, not smoothed at all.
        assert_eq!(auto(16), 0);
        assert_eq!(auto(39), 0);
        assert_eq!(auto(40), 1);
        assert_eq!(auto(79), 1);
        // MacroMARL's 400-point runs and the paper's 1501 and 4001 get the paper's 21 points.
        assert_eq!(auto(400), SMOOTH_HALF_WINDOW);
        assert_eq!(auto(4001), SMOOTH_HALF_WINDOW);
        assert_eq!(Smoothing::NONE.half_window(&episodes(100)), 0);
        assert_eq!(Smoothing::Points(21).half_window(&episodes(100)), 10);
        assert_eq!(Smoothing::Points(999).half_window(&episodes(5)), 5);
        // 2000 episodes at a spacing of 200: 5 points each side.
        assert_eq!(Smoothing::Episodes(2000).half_window(&episodes(100)), 5);
        assert_eq!(Smoothing::Episodes(2000).half_window(&episodes(1)), 0);
        // The median spacing ignores one short last gap (a run's final evaluation).
        let mut e = episodes(10);
        e.push(1801);
        assert_eq!(Smoothing::Episodes(1000).half_window(&e), 2);
    }

    #[test]
    fn auto_smoothing_moves_a_short_curves_reach_by_at_most_one_evaluation() {
        // A step from 0 to 10 at every possible point of curves of 2..80 points: the smoothed
        // curve first reaches 9.5 within one evaluation of the step.
        for n in 2..80usize {
            for step in 1..n {
                let pts: Vec<CurvePoint> = (0..n)
                    .map(|i| pt(i as u64 * 100, if i >= step { 10.0 } else { 0.0 }))
                    .collect();
                let eps: Vec<u64> = pts.iter().map(|p| p.episode).collect();
                let s = smooth(&pts, Smoothing::Auto.half_window(&eps));
                let at = first_reaching(&s, 9.5).map_or(n as u64 * 100, |e| e);
                let true_at = step as u64 * 100;
                assert!(
                    at.abs_diff(true_at) <= 100,
                    "n {n} step {step}: {at} vs {true_at}"
                );
            }
        }
    }

    #[test]
    fn best_return_is_the_highest_evaluation_of_a_run() {
        assert_eq!(
            best_return(&[(0, -150.0), (10, 259.0), (20, 178.0)]),
            Some(259.0)
        );
        assert_eq!(best_return(&[]), None);
    }

    #[test]
    fn reaching_and_area_follow_the_curve() {
        let c = [pt(0, 0.0), pt(10, 50.0), pt(30, 100.0)];
        assert_eq!(first_reaching(&c, 50.0), Some(10));
        assert_eq!(first_reaching(&c, 100.5), None);
        // Trapezoids: 10 * 25 + 20 * 75 = 1750 over 30 episodes.
        assert!(close(mean_over_training(&c).unwrap(), 1750.0 / 30.0));
        assert_eq!(mean_over_training(&c[..1]), Some(0.0));
        assert_eq!(mean_over_training(&[]), None);
        let run: Vec<(u64, f64)> = c.iter().map(|p| (p.episode, p.mean)).collect();
        assert_eq!(run_mean_over_training(&run), mean_over_training(&c));
        assert_eq!(run_mean_over_training(&[(5, 3.0)]), Some(3.0));
        assert_eq!(run_mean_over_training(&[]), None);
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    #[test]
    fn se_uses_the_sample_std_with_ddof_one() {
        // values 1, 2, 3, 6: mean 3; squared deviations 4 + 1 + 0 + 9 = 14;
        // sample variance 14 / 3; SE = sqrt(14/3) / sqrt(4) = sqrt(14/3) / 2.
        let (mean, se) = mean_and_se(&[1.0, 2.0, 3.0, 6.0]).unwrap();
        assert!(close(mean, 3.0));
        assert!(close(se, (14.0f64 / 3.0).sqrt() / 2.0));
        assert!(close(se, 1.0801234497346435));
    }

    #[test]
    fn se_of_one_run_is_zero_and_of_none_is_undefined() {
        assert_eq!(mean_and_se(&[7.5]), Some((7.5, 0.0)));
        assert_eq!(mean_and_se(&[]), None);
    }

    #[test]
    fn moving_average_truncates_the_window_at_the_ends() {
        // half window 1: [1, 2, 4, 8, 16] ->
        // (1+2)/2, (1+2+4)/3, (2+4+8)/3, (4+8+16)/3, (8+16)/2
        let got = moving_average(&[1.0, 2.0, 4.0, 8.0, 16.0], 1);
        let want = [1.5, 7.0 / 3.0, 14.0 / 3.0, 28.0 / 3.0, 12.0];
        assert_eq!(got.len(), want.len());
        for (g, w) in got.iter().zip(want) {
            assert!(close(*g, w), "{got:?}");
        }
    }

    #[test]
    fn paper_window_averages_21_points_in_the_middle_and_11_at_the_ends() {
        // xs = 0..30: the centred mean of a linear series is the centre itself in the middle;
        // at index 0 the window is 0..=10 (mean 5), at index 29 it is 19..=29 (mean 24).
        let xs: Vec<f64> = (0..30).map(|i| i as f64).collect();
        let got = moving_average(&xs, SMOOTH_HALF_WINDOW);
        assert!(close(got[0], 5.0));
        assert!(close(got[3], (0..=13).sum::<i32>() as f64 / 14.0));
        assert!(close(got[15], 15.0));
        assert!(close(got[29], 24.0));
        // A spike of 21 in the middle spreads to 1 over exactly 21 points.
        let mut spike = vec![0.0; 41];
        spike[20] = 21.0;
        let s = moving_average(&spike, SMOOTH_HALF_WINDOW);
        assert!(s[10..=30].iter().all(|v| close(*v, 1.0)));
        assert!(close(s[9], 0.0) && close(s[31], 0.0));
    }

    #[test]
    fn moving_average_of_short_series_averages_what_exists() {
        assert!(moving_average(&[], 10).is_empty());
        let got = moving_average(&[2.0, 4.0, 9.0], 10);
        assert!(got.iter().all(|v| close(*v, 5.0)));
    }

    #[test]
    fn mixed_length_runs_average_over_the_runs_that_have_each_point() {
        let a: &[(u64, f64)] = &[(0, 1.0), (10, 3.0), (20, 5.0)];
        let b: &[(u64, f64)] = &[(0, 3.0), (10, 7.0)];
        let c: &[(u64, f64)] = &[(0, 5.0)];
        let got = aggregate(&[a, b, c]);
        assert_eq!(got.len(), 3);
        // episode 0: 1, 3, 5 -> mean 3, sample var 4, SE 2 / sqrt 3
        assert_eq!((got[0].episode, got[0].n), (0, 3));
        assert!(close(got[0].mean, 3.0));
        assert!(close(got[0].se, 2.0 / 3f64.sqrt()));
        // episode 10: 3, 7 -> mean 5, sample var 8, SE sqrt(8)/sqrt(2) = 2
        assert_eq!((got[1].episode, got[1].n), (10, 2));
        assert!(close(got[1].mean, 5.0));
        assert!(close(got[1].se, 2.0));
        // episode 20: only run a
        assert_eq!((got[2].episode, got[2].n), (20, 1));
        assert_eq!((got[2].mean, got[2].se), (5.0, 0.0));
    }

    #[test]
    fn aggregate_sorts_by_episode_whatever_the_run_order() {
        let a: &[(u64, f64)] = &[(20, 2.0)];
        let b: &[(u64, f64)] = &[(0, 1.0), (10, 1.5)];
        let eps: Vec<u64> = aggregate(&[a, b]).iter().map(|p| p.episode).collect();
        assert_eq!(eps, vec![0, 10, 20]);
    }

    #[test]
    fn smoothing_applies_to_mean_and_se_separately_and_keeps_counts() {
        let pts = [
            CurvePoint {
                episode: 0,
                mean: 0.0,
                se: 3.0,
                n: 2,
            },
            CurvePoint {
                episode: 10,
                mean: 6.0,
                se: 0.0,
                n: 2,
            },
            CurvePoint {
                episode: 20,
                mean: 9.0,
                se: 0.0,
                n: 1,
            },
        ];
        let s = smooth(&pts, 1);
        assert!(close(s[0].mean, 3.0) && close(s[0].se, 1.5));
        assert!(close(s[1].mean, 5.0) && close(s[1].se, 1.0));
        assert!(close(s[2].mean, 7.5) && close(s[2].se, 0.0));
        assert_eq!(s.iter().map(|p| p.n).collect::<Vec<_>>(), vec![2, 2, 1]);
        assert_eq!(s[2].episode, 20);
    }
}
