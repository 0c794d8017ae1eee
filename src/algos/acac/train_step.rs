//! One update of any of ACAC's three methods: the one place their objectives are told apart
//! ([`Objective`]): PPO with macro-level GAE ([`super::update`]) or the vanilla policy gradient
//! with n-step returns ([`super::vanilla`]).

use super::batch::AcacBatch;
use super::update::{
    ppo_update, AcacNets, DropoutSource, Objective, UpdateError, UpdateParams, UpdateTrace,
};
use super::vanilla::{self, VanillaParams};
use crate::autograd::Tape;

/// One update of `nets` on `batch` by `p.objective`, dropout masks from `dropout`, every
/// forward on `tape` (a learner keeps one, so its buffers are reused).
pub fn update(
    nets: &mut AcacNets,
    batch: &AcacBatch,
    p: &UpdateParams,
    dropout: DropoutSource<'_>,
    tape: &mut Tape,
) -> Result<UpdateTrace, UpdateError> {
    let n = nets.actors.len();
    if batch.n_agents() != n {
        return Err(UpdateError::Agents {
            batch: batch.n_agents(),
            nets: n,
        });
    }
    match p.objective {
        Objective::Ppo(gae_lambda) => ppo_update(nets, batch, p, gae_lambda, dropout, tape),
        Objective::Vanilla {
            n_step,
            critic_iterations,
            entropy_weight,
        } => {
            let v = VanillaParams {
                n_step,
                critic_iterations,
                entropy_weight,
            };
            vanilla::update(nets, batch, p, &v, dropout, tape)
        }
    }
}
