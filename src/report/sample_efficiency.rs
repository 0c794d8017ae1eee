//! Sample-efficiency curves (rliable, Agarwal et al. 2021, Fig. 9; Gorsane et al. 2022): the
//! interquartile mean across a method's runs at each evaluation, with a bootstrap band, against
//! training episodes or environment steps. Where `macdec plot` draws the mean and its standard
//! error, this is the robust aggregate with an interval that does not assume normality.

use super::bootstrap::{percentile_intervals, stream};
use super::grid::{common_grid, Grid};
use super::scores::iqm;
use crate::plot::axis::XAxis;
use crate::plot::discover::RunData;
use crate::plot::figure::BandPoint;

/// A method's curve: the IQM across `runs` at each shared x ([`common_grid`]) and its 95%
/// interval over resampled runs (stream `sample_efficiency/<block>/<method>/<axis>`), plus
/// whether the runs had to be interpolated. `None` when the runs share no x range.
pub fn iqm_curve(
    block: &str,
    method: &str,
    runs: &[&RunData],
    axis: XAxis,
    resamples: usize,
    seed: u64,
) -> Option<(Vec<BandPoint>, bool)> {
    let along: Vec<Vec<(f64, f64)>> = runs.iter().map(|r| axis.points(r)).collect();
    let Grid {
        x,
        values,
        interpolated,
    } = common_grid(&along)?;
    let iqm_at = |runs: &mut dyn Iterator<Item = &Vec<f64>>, point: usize| {
        let column: Vec<f64> = runs.map(|r| r[point]).collect();
        iqm(&column).expect("a grid has at least one run")
    };
    let key = format!("sample_efficiency/{block}/{method}/{}", axis.name());
    let intervals =
        percentile_intervals(&[values.len()], resamples, &mut stream(seed, &key), |idx| {
            (0..x.len())
                .map(|point| iqm_at(&mut idx[0].iter().map(|&i| &values[i]), point))
                .collect()
        });
    let points = x
        .iter()
        .zip(intervals)
        .enumerate()
        .map(|(point, (&x, ci))| BandPoint {
            x,
            y: iqm_at(&mut values.iter(), point),
            low: ci.low,
            high: ci.high,
        })
        .collect();
    Some((points, interpolated))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn run(seed: u64, points: &[(u64, f64)], steps_per_episode: u64) -> RunData {
        RunData {
            seed,
            dir: PathBuf::from(format!("seed-{seed}")),
            points: points.to_vec(),
            steps: points.iter().map(|p| p.0 * steps_per_episode).collect(),
            finished: true,
            wall_seconds: Some(0.0),
            setting: None,
            provenance: None,
        }
    }

    #[test]
    fn the_curve_is_the_iqm_of_the_runs_at_each_evaluation() {
        // Four runs at episodes 0 and 10; at episode 10 the values 1, 2, 3, 100: IQM cuts one
        // each end, (2 + 3) / 2 = 2.5.
        let runs: Vec<RunData> = [1.0, 2.0, 3.0, 100.0]
            .iter()
            .enumerate()
            .map(|(i, &v)| run(i as u64, &[(0, 0.0), (10, v)], 5))
            .collect();
        let refs: Vec<&RunData> = runs.iter().collect();
        let (curve, interpolated) = iqm_curve("b", "m", &refs, XAxis::Episode, 300, 0).unwrap();
        assert!(!interpolated);
        assert_eq!(curve.len(), 2);
        assert_eq!(
            curve[0],
            BandPoint {
                x: 0.0,
                y: 0.0,
                low: 0.0,
                high: 0.0
            }
        );
        assert_eq!((curve[1].x, curve[1].y), (10.0, 2.5));
        assert!(
            curve[1].low <= 2.5 && 2.5 <= curve[1].high,
            "{:?}",
            curve[1]
        );
        // A resample can hold the outlier twice or more: the band reaches far above.
        assert!(curve[1].high > 3.0, "{:?}", curve[1]);
    }

    #[test]
    fn against_env_steps_runs_of_different_speeds_are_interpolated() {
        let a = run(0, &[(0, 0.0), (10, 10.0)], 10);
        let b = run(1, &[(0, 0.0), (10, 10.0)], 20);
        let (curve, interpolated) = iqm_curve("b", "m", &[&a, &b], XAxis::EnvSteps, 50, 0).unwrap();
        assert!(interpolated);
        // Shared range 0..=100 steps; at 100 steps a is at 10, b halfway to its 10: 5.
        let last = curve.last().unwrap();
        assert_eq!((last.x, last.y), (100.0, 7.5));
        // The same runs against episodes need no interpolation.
        let (_, interpolated) = iqm_curve("b", "m", &[&a, &b], XAxis::Episode, 50, 0).unwrap();
        assert!(!interpolated);
    }
}
