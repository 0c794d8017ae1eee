//! The actor-critic families' per-row bookkeeping for `metrics.csv`: the mean critic and actor
//! losses of the updates since the previous row, and the mean return of the training episodes
//! completed since then. One implementation for MacroMARL's actor-critic learner and ACAC's.
//!
//! Its fields are the learners' former inline fields in their order, so a checkpoint's bytes do
//! not change (bincode writes a nested struct as its fields in order).

use serde::{Deserialize, Serialize};

/// Sums since the last metrics row (see the module docs).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct UpdateMeans {
    critic_loss_sum: f64,
    actor_loss_sum: f64,
    loss_count: u64,
    return_sum: f64,
    return_count: u64,
}

/// An update's loss was not finite.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NonFiniteLoss;

impl UpdateMeans {
    /// One update's critic and actor losses (each net's, every epoch): their means join the
    /// sums when both lists are non-empty. Refuses (recording nothing) if any is not finite.
    pub fn record_update(&mut self, critic: &[f64], actor: &[f64]) -> Result<(), NonFiniteLoss> {
        if critic.iter().chain(actor).any(|l| !l.is_finite()) {
            return Err(NonFiniteLoss);
        }
        if !critic.is_empty() && !actor.is_empty() {
            self.critic_loss_sum += critic.iter().sum::<f64>() / critic.len() as f64;
            self.actor_loss_sum += actor.iter().sum::<f64>() / actor.len() as f64;
            self.loss_count += 1;
        }
        Ok(())
    }

    /// A completed training episode's return.
    pub fn record_return(&mut self, value: f64) {
        self.return_sum += value;
        self.return_count += 1;
    }

    /// The means since the last row, `[critic loss, actor loss, return]` (None where nothing
    /// was recorded), and a fresh start.
    pub fn take_row(&mut self) -> [Option<f64>; 3] {
        let mean = |sum: f64, n: u64| (n > 0).then(|| sum / n as f64);
        let row = [
            mean(self.critic_loss_sum, self.loss_count),
            mean(self.actor_loss_sum, self.loss_count),
            mean(self.return_sum, self.return_count),
        ];
        *self = UpdateMeans::default();
        row
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_hold_the_means_since_the_last_row() {
        let mut m = UpdateMeans::default();
        assert_eq!(m.take_row(), [None, None, None]);
        m.record_update(&[1.0, 3.0], &[4.0]).unwrap();
        m.record_update(&[4.0], &[2.0, 2.0]).unwrap();
        // A critic-only update (no actor stepped) is left out of both means.
        m.record_update(&[100.0], &[]).unwrap();
        m.record_return(-1.0);
        assert_eq!(m.take_row(), [Some(3.0), Some(3.0), Some(-1.0)]);
        assert_eq!(m.take_row(), [None, None, None]);
        assert_eq!(m.record_update(&[f64::NAN], &[1.0]), Err(NonFiniteLoss));
        assert_eq!(
            m.take_row(),
            [None, None, None],
            "a refused update records nothing"
        );
    }

    #[test]
    fn checkpoints_keep_their_bytes() {
        // The five sums as the learners wrote them inline before this struct.
        let mut m = UpdateMeans::default();
        m.record_update(&[0.5], &[0.25]).unwrap();
        m.record_return(2.0);
        let inline = bincode::serialize(&(0.5f64, 0.25f64, 1u64, 2.0f64, 1u64)).unwrap();
        assert_eq!(bincode::serialize(&m).unwrap(), inline);
    }
}
