//! Value parsers for numeric flags with bounds, shared by several subcommands: counts in
//! 1..=max (so a size from a flag is bounded like one from a config) and the per-reply timeout
//! of the commands that talk to robots.

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
/// ([`MAX_EVAL_NUM_EPI`](crate::experiment::limits::MAX_EVAL_NUM_EPI)), so a flag cannot ask
/// for more than a config could.
pub(super) fn episode_count(text: &str) -> Result<usize, String> {
    bounded_count(text, crate::experiment::limits::MAX_EVAL_NUM_EPI)
}

/// A count flag in 1..=`max`: a size from a flag is bounded like one from a config.
pub(super) fn bounded_count(text: &str, max: usize) -> Result<usize, String> {
    match at_least_one(text)? {
        n if n > max => Err(format!("must be at most {max}, got {n}")),
        n => Ok(n),
    }
}
