//! Run seeds: the `--seeds` syntax, and one random stream per role derived from a run's seed.

use crate::experiment::definition::limits::{MAX_SEED, MAX_SEEDS};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// What a random stream is used for. Each role has its own stream, so an extra exploration draw
/// never shifts replay sampling, and adding evaluation episodes never changes training.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// Network initialisation (policy nets; targets are copies).
    Init = 0,
    /// Epsilon draws and random actions in the training env(s).
    Explore = 1,
    /// Replay sampling.
    Replay = 2,
    /// The training env's own draws (Warehouse movement noise).
    Env = 3,
    /// The evaluation env's own draws.
    EvalEnv = 4,
    /// Our-2's second (centralized-exploring) training env.
    CenEnv = 5,
}

/// The stream of `role` for the run with seed `seed`. Spec `algorithms.md` 8: the reference seeds
/// everything with `10 * seed`; we keep that base and give each role its own ChaCha stream.
pub fn stream(seed: u64, role: Role) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_mul(10));
    rng.set_stream(role as u64);
    rng
}

/// A `--seeds` value that could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SeedsError {
    /// Neither a range nor a list; holds the text.
    #[error("seeds `{0}`: expected a range `a..b` (end exclusive) or a comma list like `0,3,7`")]
    Syntax(String),
    /// A range with no seed; holds the text.
    #[error("seeds `{0}`: the range is empty")]
    Empty(String),
    /// A seed listed twice: the text and the seed.
    #[error("seeds `{0}`: seed {1} appears twice")]
    Duplicate(String, u64),
    /// More seeds than `MAX_SEEDS`: the text and the count.
    #[error("seeds `{0}`: {1} seeds, at most {max} allowed", max = MAX_SEEDS)]
    TooMany(String, u128),
    /// A seed beyond [`MAX_SEED`]: the text and the seed.
    #[error("seeds `{0}`: seed {1} is beyond the largest supported seed, {max} (runs record their seed as a TOML integer)", max = MAX_SEED)]
    OutOfRange(String, u64),
}

/// Parse `a..b` (Rust range, end exclusive), `a..=b`, a single seed, or a comma list.
pub fn parse_seeds(text: &str) -> Result<Vec<u64>, SeedsError> {
    let t = text.trim();
    let num = |s: &str| {
        s.trim()
            .parse::<u64>()
            .map_err(|_| SeedsError::Syntax(text.to_string()))
    };
    // Ranges are counted (in u128, so `0..=u64::MAX` cannot overflow) before anything is built.
    let range = |a: u64, end_exclusive: u128| -> Result<Vec<u64>, SeedsError> {
        let count = end_exclusive.saturating_sub(a as u128);
        if count > MAX_SEEDS as u128 {
            return Err(SeedsError::TooMany(text.to_string(), count));
        }
        Ok((0..count as u64).map(|i| a + i).collect())
    };
    let seeds: Vec<u64> = if let Some((a, b)) = t.split_once("..=") {
        range(num(a)?, num(b)? as u128 + 1)?
    } else if let Some((a, b)) = t.split_once("..") {
        range(num(a)?, num(b)? as u128)?
    } else {
        let items: Vec<&str> = t.split(',').collect();
        if items.len() > MAX_SEEDS {
            return Err(SeedsError::TooMany(text.to_string(), items.len() as u128));
        }
        items.into_iter().map(num).collect::<Result<_, _>>()?
    };
    check_seed_list_named(&seeds, text)?;
    Ok(seeds)
}

/// Check a seed list given as a TOML array: not empty, no repeats, at most
/// [`MAX_SEEDS`].
pub fn check_seed_list(seeds: &[u64]) -> Result<(), SeedsError> {
    let shown = format!("{seeds:?}");
    let shown = if shown.len() > 60 {
        format!("{}...]", &shown[..56])
    } else {
        shown
    };
    check_seed_list_named(seeds, &shown)
}

fn check_seed_list_named(seeds: &[u64], text: &str) -> Result<(), SeedsError> {
    if seeds.is_empty() {
        return Err(SeedsError::Empty(text.to_string()));
    }
    if seeds.len() > MAX_SEEDS {
        return Err(SeedsError::TooMany(text.to_string(), seeds.len() as u128));
    }
    if let Some(&seed) = seeds.iter().find(|&&s| s > MAX_SEED) {
        return Err(SeedsError::OutOfRange(text.to_string(), seed));
    }
    let mut sorted = seeds.to_vec();
    sorted.sort_unstable();
    if let Some(w) = sorted.windows(2).find(|w| w[0] == w[1]) {
        return Err(SeedsError::Duplicate(text.to_string(), w[0]));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngCore;

    #[test]
    fn ranges_are_end_exclusive_and_lists_keep_order() {
        assert_eq!(parse_seeds("0..4").unwrap(), vec![0, 1, 2, 3]);
        assert_eq!(parse_seeds("2..=3").unwrap(), vec![2, 3]);
        assert_eq!(parse_seeds("7, 1,3").unwrap(), vec![7, 1, 3]);
        assert_eq!(parse_seeds("5").unwrap(), vec![5]);
    }

    #[test]
    fn seeds_beyond_the_largest_are_refused_when_parsed() {
        assert_eq!(parse_seeds(&MAX_SEED.to_string()).unwrap(), vec![MAX_SEED]);
        for text in [
            "18446744073709551615",
            "9223372036854775807..=9223372036854775808",
        ] {
            assert!(
                matches!(parse_seeds(text), Err(SeedsError::OutOfRange(_, s)) if s > MAX_SEED),
                "{text}"
            );
        }
        assert!(matches!(
            check_seed_list(&[0, u64::MAX]),
            Err(SeedsError::OutOfRange(_, u64::MAX))
        ));
    }

    #[test]
    fn bad_seed_text_is_an_error_not_a_panic() {
        assert!(matches!(parse_seeds("3..3"), Err(SeedsError::Empty(_))));
        assert!(matches!(parse_seeds("a..b"), Err(SeedsError::Syntax(_))));
        assert!(matches!(parse_seeds("1,,2"), Err(SeedsError::Syntax(_))));
        assert!(matches!(
            parse_seeds("1,2,1"),
            Err(SeedsError::Duplicate(_, 1))
        ));
    }

    #[test]
    fn huge_ranges_are_refused_before_anything_is_allocated() {
        for t in [
            "0..100000000",
            "0..=18446744073709551615",
            "18446744073709551615..=18446744073709551615x",
        ] {
            let r = parse_seeds(t);
            assert!(
                matches!(r, Err(SeedsError::TooMany(..) | SeedsError::Syntax(_))),
                "{t}: {r:?}"
            );
        }
        assert_eq!(
            parse_seeds("9223372036854775807..=9223372036854775807").unwrap(),
            vec![MAX_SEED]
        );
        assert_eq!(
            parse_seeds(&format!("0..{MAX_SEEDS}")).unwrap().len(),
            MAX_SEEDS
        );
        assert!(parse_seeds(&format!("0..={MAX_SEEDS}")).is_err());
        assert!(matches!(parse_seeds("5..2"), Err(SeedsError::Empty(_))));
        assert!(matches!(
            check_seed_list(&[1, 1]),
            Err(SeedsError::Duplicate(_, 1))
        ));
        assert!(matches!(check_seed_list(&[]), Err(SeedsError::Empty(_))));
    }

    #[test]
    fn any_short_text_parses_or_errors_without_panicking() {
        let alphabet = [
            "0",
            "9",
            ".",
            "=",
            ",",
            " ",
            "-",
            "18446744073709551615",
            "x",
        ];
        let mut words = vec![String::new()];
        for _ in 0..4 {
            words = words
                .iter()
                .flat_map(|w| alphabet.iter().map(move |c| format!("{w}{c}")))
                .collect();
            for w in &words {
                if let Ok(seeds) = parse_seeds(w) {
                    assert!(!seeds.is_empty() && seeds.len() <= MAX_SEEDS, "{w}");
                }
            }
        }
    }

    #[test]
    fn role_streams_differ_and_repeat() {
        let a = stream(3, Role::Explore).next_u64();
        assert_eq!(a, stream(3, Role::Explore).next_u64());
        assert_ne!(a, stream(3, Role::Replay).next_u64());
        assert_ne!(a, stream(4, Role::Explore).next_u64());
    }
}
