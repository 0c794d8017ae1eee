//! Value parsers for numeric flags with bounds, shared by several subcommands: counts in
//! 1..=max (so a size from a flag is bounded like one from a config) and the per-reply timeout
//! of the commands that talk to robots.

use crate::experiment::definition::limits;

/// `--timeout-secs` of `deploy` and `domain`: a deadline per robot reply, 1 s to a day. 0
/// would fail every reply at once (or, as a socket timeout, wait forever).
pub(super) fn parse_timeout_secs(text: &str) -> Result<u64, String> {
    const DAY: u64 = 86_400;
    match text.trim().parse::<u64>() {
        Ok(0) => Err("a timeout of 0 s gives no robot time to answer: use 1 to 86400".into()),
        Ok(s) if s > DAY => Err(format!("at most {DAY} s (one day), got {s}")),
        Ok(s) => Ok(s),
        Err(e) => Err(format!("expected whole seconds from 1 to {DAY}: {e}")),
    }
}

/// A count flag that must be at least 1 (0 would do nothing useful, silently).
pub(super) fn at_least_one(text: &str) -> Result<usize, String> {
    match text.trim().parse::<usize>() {
        Ok(0) => Err("must be at least 1".into()),
        Ok(n) => Ok(n),
        Err(e) => Err(format!("expected a positive integer: {e}")),
    }
}

/// An episode count flag: at least 1 and at most a config's `eval_num_epi` may be
/// ([`MAX_EVAL_NUM_EPI`](limits::MAX_EVAL_NUM_EPI)), so a flag cannot ask for more than a
/// config could.
pub(super) fn episode_count(text: &str) -> Result<usize, String> {
    bounded_count(text, limits::MAX_EVAL_NUM_EPI)
}

/// A count flag in 1..=`max`: a size from a flag is bounded like one from a config.
pub(super) fn bounded_count(text: &str, max: usize) -> Result<usize, String> {
    match at_least_one(text)? {
        n if n > max => Err(format!("must be at most {max}, got {n}")),
        n => Ok(n),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timeout_secs_takes_one_second_to_a_day() {
        assert_eq!(parse_timeout_secs("1"), Ok(1));
        assert_eq!(parse_timeout_secs("86400"), Ok(86_400));
        assert_eq!(
            parse_timeout_secs("0"),
            Err("a timeout of 0 s gives no robot time to answer: use 1 to 86400".to_string())
        );
        assert_eq!(
            parse_timeout_secs("86401"),
            Err("at most 86400 s (one day), got 86401".to_string())
        );
        let e = parse_timeout_secs("1.5").unwrap_err();
        assert!(
            e.starts_with("expected whole seconds from 1 to 86400: "),
            "{e}"
        );
    }

    #[test]
    fn a_count_is_at_least_one() {
        assert_eq!(at_least_one("1"), Ok(1));
        assert_eq!(at_least_one(" 7 "), Ok(7));
        assert_eq!(at_least_one("0"), Err("must be at least 1".to_string()));
        let e = at_least_one("-1").unwrap_err();
        assert!(e.starts_with("expected a positive integer: "), "{e}");
    }

    #[test]
    fn a_bounded_count_takes_its_maximum_and_refuses_one_more() {
        assert_eq!(bounded_count("16", 16), Ok(16));
        assert_eq!(
            bounded_count("17", 16),
            Err("must be at most 16, got 17".to_string())
        );
        assert_eq!(
            bounded_count("0", 16),
            Err("must be at least 1".to_string())
        );
    }

    #[test]
    fn an_episode_count_is_bounded_like_eval_num_epi() {
        let max = limits::MAX_EVAL_NUM_EPI;
        assert_eq!(max, 100_000);
        assert_eq!(episode_count("100000"), Ok(max));
        assert_eq!(
            episode_count("100001"),
            Err("must be at most 100000, got 100001".to_string())
        );
        assert_eq!(episode_count("0"), Err("must be at least 1".to_string()));
    }
}
