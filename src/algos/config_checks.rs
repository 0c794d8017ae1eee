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
/// Copies of an output-width array one update keeps per sequence step: the logits or Q-values,
/// their softmax, log-softmax and masks, and each one's gradient (measured: Mac-CAC on Overcooked
/// B, 3375 joint macro-actions, needs about 15 per element of train_freq x horizon x 3375).
pub const OUTPUT_COPIES: u128 = 16;
/// Copies of a hidden-width array per sequence step: a recurrent cell's gates (4 for an LSTM).
pub const HIDDEN_COPIES: u128 = 4;

/// The widths one update's activations are made of, per sequence step of one batch sequence.
#[derive(Debug, Clone, Copy)]
pub struct NetWidths {
    /// The widest hidden layer of any net.
    pub hidden: u128,
    /// The widest input of any net (a centralized net's joint observation).
    pub input: u128,
    /// The widest output of any net (a centralized actor's or Q-net's joint macro-actions).
    pub output: u128,
}

/// One update's batch activations, `sequences` x `seq_len` steps of `widths` (hidden layers
/// [`HIDDEN_COPIES`] times, outputs [`OUTPUT_COPIES`] times, so a joint-action output counts for
/// what it costs), must stay within [`MAX_BATCH_ELEMENTS`]. `key` and `seq_key` name the two
/// factors in the message.
pub fn check_batch_activations(
    (key, sequences): (&'static str, usize),
    (seq_key, seq_len): (&'static str, usize),
    widths: NetWidths,
) -> Result<(), (&'static str, String)> {
    let per_step = (HIDDEN_COPIES * widths.hidden)
        .saturating_add(widths.input)
        .saturating_add(OUTPUT_COPIES.saturating_mul(widths.output));
    let elements = (sequences as u128)
        .saturating_mul(seq_len as u128)
        .saturating_mul(per_step);
    if elements > MAX_BATCH_ELEMENTS {
        return Err((
            key,
            format!(
                "{key} x {seq_key} x the nets' widths per step = {sequences} x {seq_len} x {per_step} \
                 = {elements} activations in one update, at most {MAX_BATCH_ELEMENTS} (widths per \
                 step: {HIDDEN_COPIES} x the widest hidden layer {}, the widest input {}, \
                 {OUTPUT_COPIES} x the widest output {}, a centralized net's joint macro-actions)",
                widths.hidden, widths.input, widths.output
            ),
        ));
    }
    Ok(())
}

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

/// Every value named must be a finite number >= 0 (weights, clips, coefficients).
pub fn check_non_negative(values: &[(&'static str, f64)]) -> Result<(), (&'static str, String)> {
    match values.iter().find(|(_, v)| !(v.is_finite() && *v >= 0.0)) {
        Some((key, v)) => Err((key, format!("must be a finite number >= 0, got {v}"))),
        None => Ok(()),
    }
}

/// Every list named must be an MLP's two layer widths, [before, after] the recurrent layer,
/// each 1..=[`MAX_NET_WIDTH`] (the references' `*mlp_layer_size` keys).
pub fn check_mlp_widths(lists: &[(&'static str, &[usize])]) -> Result<(), (&'static str, String)> {
    match lists
        .iter()
        .find(|(_, sizes)| sizes.len() != 2 || sizes.iter().any(|&s| s == 0 || s > MAX_NET_WIDTH))
    {
        Some((key, sizes)) => Err((
            key,
            format!(
                "must be two widths [before, after] the recurrent layer, each 1..={MAX_NET_WIDTH}, got {sizes:?}"
            ),
        )),
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

/// An update runs every `train_freq` main-loop steps (the value families), and a run takes at
/// most total_epi x horizon of them: a larger `train_freq` would "finish" without a single
/// update. (Shorter episodes can still leave a run without one; the runner refuses to call such a
/// run finished.)
pub fn check_train_freq_steps(
    train_freq: usize,
    total_epi: usize,
    horizon: usize,
) -> Result<(), (&'static str, String)> {
    let most_steps = (total_epi as u128).saturating_mul(horizon as u128);
    if train_freq as u128 > most_steps {
        return Err((
            "train_freq",
            format!(
                "must be at most total_epi x env_terminate_step = {most_steps} main-loop steps, got \
                 {train_freq}: an update runs every train_freq steps, so none would"
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
        assert_eq!(
            check_non_negative(&[("a", 0.0), ("b", -1e-9)]).unwrap_err(),
            ("b", "must be a finite number >= 0, got -0.000000001".into())
        );
        assert_eq!(
            check_non_negative(&[("a", f64::INFINITY)]).unwrap_err().0,
            "a"
        );
        assert!(check_non_negative(&[("a", 0.0), ("b", 3.5)]).is_ok());
        let ok: &[usize] = &[64, MAX_NET_WIDTH];
        assert!(check_mlp_widths(&[("a", ok)]).is_ok());
        for bad in [&[64][..], &[64, 64, 64], &[0, 64], &[64, MAX_NET_WIDTH + 1]] {
            let (key, why) = check_mlp_widths(&[("a", ok), ("b", bad)]).unwrap_err();
            assert_eq!(key, "b");
            assert!(why.contains("two widths [before, after]"), "{why}");
        }
    }
}
