//! The bounds and range checks every family's config check shares (README "Limits and
//! guarantees"). Each bound is far above the papers' settings and low enough that a run cannot
//! abort the process on allocation: a value beyond one is a config error naming the key, found
//! before any run starts, instead of an out-of-memory abort that takes every parallel run down
//! with it.

/// Episode horizon in primitive steps, `env_terminate_step` (paper: 100 to 200); every domain
/// spec is held to it (`envs::domain`).
pub use crate::envs::domain::MAX_HORIZON;
/// Width of any net layer (paper: 32 and 64); policy files are held to it too.
pub use crate::nn::MAX_NET_WIDTH;

/// Elements of one batch activation: batch x sequence length x widest layer (2^28 f32 = 1 GiB;
/// paper: about 1.5e5).
pub const MAX_BATCH_ELEMENTS: u128 = 1 << 28;
/// Training episodes, `total_epi` (paper: 40000).
pub const MAX_TOTAL_EPI: usize = 100_000_000;
/// Evaluation rows a run keeps, total_epi / eval_freq (paper: 4000).
pub const MAX_EVAL_ROWS: usize = 1_000_000;
/// Episodes per evaluation, `eval_num_epi` (paper: 1, 10 and 20).
pub const MAX_EVAL_NUM_EPI: usize = 100_000;

/// Every count named must be at least 1.
pub fn check_positive(counts: &[(&'static str, usize)]) -> Result<(), (&'static str, String)> {
    match counts.iter().find(|(_, v)| *v == 0) {
        Some((key, _)) => Err((key, "must be > 0, got 0".into())),
        None => Ok(()),
    }
}

/// Every value named must lie in [0, 1].
pub fn check_unit(values: &[(&'static str, f64)]) -> Result<(), (&'static str, String)> {
    match values.iter().find(|(_, v)| !(0.0..=1.0).contains(v)) {
        Some((key, v)) => Err((key, format!("must be in [0, 1], got {v}"))),
        None => Ok(()),
    }
}

/// Every learning rate named must be a positive number.
pub fn check_rates(rates: &[(&'static str, f64)]) -> Result<(), (&'static str, String)> {
    match rates.iter().find(|(_, lr)| !(*lr > 0.0 && lr.is_finite())) {
        Some((key, lr)) => Err((key, format!("must be a positive number, got {lr}"))),
        None => Ok(()),
    }
}

/// Every value named must be at most its bound.
pub fn check_at_most(
    values: &[(&'static str, usize, usize)],
) -> Result<(), (&'static str, String)> {
    match values.iter().find(|(_, v, max)| v > max) {
        Some((key, v, max)) => Err((key, format!("must be at most {max}, got {v}"))),
        None => Ok(()),
    }
}

/// The discount must be in (0, 1]: evaluation returns and exported policies need a positive one.
pub fn check_discount(key: &'static str, discount: f64) -> Result<(), (&'static str, String)> {
    check_unit(&[(key, discount)])?;
    if discount == 0.0 {
        return Err((key, "must be in (0, 1], got 0".into()));
    }
    Ok(())
}

/// Evaluation rows a run would keep, total_epi / eval_freq, within [`MAX_EVAL_ROWS`].
pub fn check_eval_rows(total_epi: usize, eval_freq: usize) -> Result<(), (&'static str, String)> {
    let rows = total_epi / eval_freq.max(1);
    if rows > MAX_EVAL_ROWS {
        return Err((
            "eval_freq",
            format!(
                "total_epi / eval_freq = {rows} evaluation rows, at most {MAX_EVAL_ROWS}: evaluate less often"
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_check_names_the_first_bad_key() {
        assert_eq!(check_positive(&[("a", 1), ("b", 0)]).unwrap_err().0, "b");
        assert_eq!(check_unit(&[("a", 0.5), ("b", 1.5)]).unwrap_err().0, "b");
        assert_eq!(check_rates(&[("a", f64::NAN)]).unwrap_err().0, "a");
        assert_eq!(
            check_at_most(&[("a", 3, 2)]).unwrap_err().1,
            "must be at most 2, got 3"
        );
        assert!(check_discount("gamma", 0.0)
            .unwrap_err()
            .1
            .contains("(0, 1]"));
        assert!(check_discount("gamma", 1.0).is_ok());
        assert!(check_eval_rows(MAX_EVAL_ROWS * 10, 1).is_err());
        assert!(check_eval_rows(40_000, 10).is_ok());
    }
}
