//! Run seeds: the `--seeds` syntax, and one random stream per role derived from a run's seed.

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
    #[error("seeds `{0}`: expected a range `a..b` (end exclusive) or a comma list like `0,3,7`")]
    Syntax(String),
    #[error("seeds `{0}`: the range is empty")]
    Empty(String),
    #[error("seeds `{0}`: seed {1} appears twice")]
    Duplicate(String, u64),
}

/// Parse `a..b` (Rust range, end exclusive), `a..=b`, a single seed, or a comma list.
pub fn parse_seeds(text: &str) -> Result<Vec<u64>, SeedsError> {
    let t = text.trim();
    let num = |s: &str| {
        s.trim()
            .parse::<u64>()
            .map_err(|_| SeedsError::Syntax(text.to_string()))
    };
    let seeds: Vec<u64> = if let Some((a, b)) = t.split_once("..=") {
        (num(a)?..=num(b)?).collect()
    } else if let Some((a, b)) = t.split_once("..") {
        (num(a)?..num(b)?).collect()
    } else {
        t.split(',').map(num).collect::<Result<_, _>>()?
    };
    if seeds.is_empty() {
        return Err(SeedsError::Empty(text.to_string()));
    }
    let mut sorted = seeds.clone();
    sorted.sort_unstable();
    if let Some(w) = sorted.windows(2).find(|w| w[0] == w[1]) {
        return Err(SeedsError::Duplicate(text.to_string(), w[0]));
    }
    Ok(seeds)
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
    fn role_streams_differ_and_repeat() {
        let a = stream(3, Role::Explore).next_u64();
        assert_eq!(a, stream(3, Role::Explore).next_u64());
        assert_ne!(a, stream(3, Role::Replay).next_u64());
        assert_ne!(a, stream(4, Role::Explore).next_u64());
    }
}
