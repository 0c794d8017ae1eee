//! Macro-actions from a script instead of the actors: the seam through which a recorded run of
//! the reference drives our training loop (`tests/ac_runner_reference.rs`, issue 42 item 6).
//!
//! With a script set ([`super::learner::AcLearner::set_action_script`]), the loop collects,
//! records, trains, syncs targets and evaluates exactly as it always does; only the free agents'
//! choice comes from the script, which replaces the actors' forward pass and sampling (no net
//! runs, nothing is drawn). Busy agents keep their running macro-actions, as always.

use std::sync::Arc;

/// What the acting path knows when it asks for one environment's next macro-actions.
#[derive(Debug, Clone, Copy)]
pub struct ActingCall<'a> {
    /// The batch's exploration weight while training; `None` when evaluating.
    pub eps: Option<f64>,
    /// Which agents choose now (their macro-action ended at the last step, or the episode began).
    pub free: &'a [bool],
    /// Every agent's running macro-action (`env.executed()`), which a busy agent keeps.
    pub running: &'a [usize],
}

/// What a script runs for one call: it writes the free agents' entries of `actions` (one per
/// agent).
type Choose = dyn Fn(ActingCall<'_>, &mut [usize]) + Send + Sync;

/// A source of macro-actions, called once per environment and primitive step in the loop's
/// order.
#[derive(Clone)]
pub struct ActionScript(Arc<Choose>);

impl ActionScript {
    /// A script from a closure (which keeps its own position, behind a lock if it moves on).
    pub fn new(choose: impl Fn(ActingCall<'_>, &mut [usize]) + Send + Sync + 'static) -> Self {
        ActionScript(Arc::new(choose))
    }

    /// The script's choice for `call`; busy agents' entries are then their running
    /// macro-actions.
    pub(crate) fn act(&self, call: ActingCall<'_>, actions: &mut [usize]) {
        (self.0)(call, actions);
        for (i, a) in actions.iter_mut().enumerate() {
            if !call.free[i] {
                *a = call.running[i];
            }
        }
    }
}

impl std::fmt::Debug for ActionScript {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("ActionScript(..)")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_script_decides_only_the_free_agents() {
        let script = ActionScript::new(|call, actions| {
            assert_eq!(call.eps, Some(0.5));
            actions.fill(7);
        });
        let mut actions = [0; 3];
        let call = ActingCall {
            eps: Some(0.5),
            free: &[true, false, true],
            running: &[1, 2, 3],
        };
        script.act(call, &mut actions);
        assert_eq!(
            actions,
            [7, 2, 7],
            "a busy agent keeps its running macro-action"
        );
    }
}
