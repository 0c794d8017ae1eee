//! How actor-critic policies pick macro-actions (`docs/MACROMARL.md` §2.5, `controller.py:
//! select_action`): free agents sample from their actor's distribution with the GRU state
//! carried (P13); while training the distribution is the eps-mixture (1 - eps) pi + eps / |A|,
//! when evaluated the plain pi (P8, sampled, not greedy). Mac-CAC's one actor samples a joint
//! macro-action among those that keep every busy agent's running macro-action (P4).

use rand_chacha::ChaCha8Rng;

use crate::nn::sampling::{conditioned_joint, mixture, sample_weighted, Pick};
use crate::nn::{GruActor, GruActorState};

/// The acting path's reusable buffers: once warm, choosing macro-actions allocates nothing per
/// primitive step. Scratch only: a fresh (empty) one acts identically.
#[derive(Debug, Default)]
pub struct ActBuffers {
    /// The sampling distribution of the agent (or the joint action) being decided.
    pub probs: Vec<f64>,
    /// Mac-CAC's joint observation.
    pub joint: Vec<f32>,
    /// Mac-CAC over the lanes of one lockstep step: the actor outputs before the output layer,
    /// one row per lane with a free agent.
    pub hidden: Vec<f32>,
    /// Their log-probabilities, one row per deciding lane.
    pub logp: Vec<f32>,
}

impl Clone for ActBuffers {
    /// Scratch is not state: a clone starts empty.
    fn clone(&self) -> Self {
        ActBuffers::default()
    }
}

impl ActBuffers {
    /// The joint-observation buffer resized to `len` (its contents are to be overwritten).
    pub fn joint(&mut self, len: usize) -> &mut Vec<f32> {
        self.joint.resize(len, 0.0);
        &mut self.joint
    }
}

/// Decentralized actors: each free agent `i`, in index order, samples from its actor
/// `actor(i)` on its own observation `obs(i)`; busy agents keep their running macro-action
/// (`running[i]`).
#[allow(clippy::too_many_arguments)]
pub fn act_decentralized<'n, 'o>(
    actor: &dyn Fn(usize) -> &'n GruActor,
    states: &mut [GruActorState],
    obs: &dyn Fn(usize) -> &'o [f32],
    free: &[bool],
    running: &[usize],
    eps: Option<f64>,
    rng: &mut ChaCha8Rng,
    probs: &mut Vec<f64>,
    actions: &mut [usize],
) {
    for (i, state) in states.iter_mut().enumerate() {
        if free[i] {
            let logp = actor(i).act_step(obs(i), state);
            mixture(logp, eps, probs);
            actions[i] = sample_weighted(probs, rng);
        } else {
            actions[i] = running[i];
        }
    }
}

/// Mac-CAC's centralized actor: when some agent is free, one step on the joint observation and
/// a joint macro-action sampled among those whose busy agents' parts equal their running
/// macro-actions, unravelled in C order (agent 0 most significant). Nothing runs when every
/// agent is busy.
#[allow(clippy::too_many_arguments)]
pub fn act_centralized(
    actor: &GruActor,
    state: &mut GruActorState,
    joint_obs: &[f32],
    free: &[bool],
    running: &[usize],
    n_actions: &[usize],
    eps: Option<f64>,
    rng: &mut ChaCha8Rng,
    probs: &mut Vec<f64>,
    actions: &mut [usize],
) {
    if !free.iter().any(|&f| f) {
        actions.copy_from_slice(running);
        return;
    }
    let logp = actor.act_step(joint_obs, state);
    conditioned_joint(
        logp,
        eps,
        free,
        running,
        n_actions,
        Pick::Sample(rng),
        probs,
        actions,
    );
}

/// One lane of a lockstep step as [`act_centralized_lanes`] reads it.
pub struct CentralizedLane<'a> {
    /// The actor's recurrent state on this lane.
    pub state: &'a mut GruActorState,
    /// Which agents are free.
    pub free: &'a [bool],
    /// The agents' running macro-actions.
    pub running: &'a [usize],
    /// The joint observation's writer (called only if some agent is free).
    pub write_joint_obs: &'a dyn Fn(&mut [f32]),
    /// Where the lane's actions go.
    pub actions: &'a mut [usize],
}

/// Visits lane `i` of a lockstep step: calls the given function with its [`CentralizedLane`].
pub type VisitLane<'a> = dyn FnMut(usize, &mut dyn FnMut(CentralizedLane<'_>)) + 'a;

/// [`act_centralized`] on every lane of one lockstep step, lane by lane in order, each lane's
/// choice and the stream's draws exactly as there: the lanes with a free agent go through the
/// layers before the output layer one by one, then through the output layer together (read
/// once, [`GruActor::log_probs_rows`]), then draw in lane order. `lane(i, f)` calls `f` with lane
/// i's view; `n_lanes` lanes.
#[allow(clippy::too_many_arguments)]
pub fn act_centralized_lanes(
    actor: &GruActor,
    n_lanes: usize,
    lane: &mut VisitLane<'_>,
    n_actions: &[usize],
    eps: Option<f64>,
    rng: &mut ChaCha8Rng,
    buffers: &mut ActBuffers,
) {
    let ActBuffers {
        probs,
        joint,
        hidden,
        logp,
    } = buffers;
    let cfg = actor.config();
    joint.resize(cfg.input, 0.0);
    hidden.clear();
    let decides = |l: &CentralizedLane<'_>| l.free.iter().any(|&f| f);
    for i in 0..n_lanes {
        lane(i, &mut |l| {
            if decides(&l) {
                (l.write_joint_obs)(joint);
                hidden.extend_from_slice(actor.hidden_step(joint, l.state));
            }
        });
    }
    logp.resize(hidden.len() / cfg.mlp[1] * cfg.output, 0.0);
    actor.log_probs_rows(hidden, logp);
    let mut rows = logp.chunks_exact(cfg.output);
    for i in 0..n_lanes {
        lane(i, &mut |l| {
            if !decides(&l) {
                l.actions.copy_from_slice(l.running);
                return;
            }
            let row = rows.next().expect("one row per deciding lane");
            conditioned_joint(
                row,
                eps,
                l.free,
                l.running,
                n_actions,
                Pick::Sample(rng),
                probs,
                l.actions,
            );
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nn::GruActorConfig;
    use rand::SeedableRng;

    #[test]
    fn all_lanes_at_once_act_exactly_as_lane_by_lane() {
        use rand::Rng;
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let n_actions = [3, 4, 2];
        let cfg = GruActorConfig {
            input: 6,
            mlp: [8, 8],
            hidden: 5,
            output: 24,
        };
        let actor = GruActor::new(cfg, &mut rng);
        let n_lanes = 5;
        let mut states_a = vec![actor.zero_state(); n_lanes];
        let mut states_b = states_a.clone();
        let (mut rng_a, mut rng_b) = (ChaCha8Rng::seed_from_u64(9), ChaCha8Rng::seed_from_u64(9));
        let mut buffers = ActBuffers::default();
        let mut probs = Vec::new();
        for step in 0..30 {
            // Each lane: who is free (sometimes nobody), the running macro-actions, an obs.
            let free: Vec<Vec<bool>> = (0..n_lanes)
                .map(|_| (0..3).map(|_| rng.gen_bool(0.4)).collect())
                .collect();
            let running: Vec<Vec<usize>> = (0..n_lanes)
                .map(|_| n_actions.iter().map(|&n| rng.gen_range(0..n)).collect())
                .collect();
            let obs: Vec<Vec<f32>> = (0..n_lanes)
                .map(|_| (0..6).map(|_| rng.gen_range(-1.0..1.0)).collect())
                .collect();
            let eps = Some(0.1 + 0.01 * step as f64);
            let mut want = vec![[0usize; 3]; n_lanes];
            for l in 0..n_lanes {
                act_centralized(
                    &actor,
                    &mut states_a[l],
                    &obs[l],
                    &free[l],
                    &running[l],
                    &n_actions,
                    eps,
                    &mut rng_a,
                    &mut probs,
                    &mut want[l],
                );
            }
            let mut got = vec![[7usize; 3]; n_lanes];
            act_centralized_lanes(
                &actor,
                n_lanes,
                &mut |l, f| {
                    let o = &obs[l];
                    f(CentralizedLane {
                        state: &mut states_b[l],
                        free: &free[l],
                        running: &running[l],
                        write_joint_obs: &|out| out.copy_from_slice(o),
                        actions: &mut got[l],
                    })
                },
                &n_actions,
                eps,
                &mut rng_b,
                &mut buffers,
            );
            assert_eq!(got, want, "step {step}");
            for (a, b) in states_a.iter().zip(&states_b) {
                assert_eq!(a.h(), b.h(), "step {step}");
            }
        }
        assert_eq!(rng_a.gen::<u64>(), rng_b.gen::<u64>(), "the same draws");
    }

    #[test]
    fn the_centralized_actor_keeps_busy_agents_on_their_running_macro_actions() {
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let cfg = GruActorConfig {
            input: 5,
            mlp: [8, 8],
            hidden: 4,
            output: 12,
        };
        let actor = GruActor::new(cfg, &mut rng);
        let mut state = actor.zero_state();
        let obs = [0.1, -0.4, 0.7, 0.0, 1.0];
        let mut actions = [0, 0];
        let mut probs = Vec::new();
        let mut seen = [false; 3];
        for _ in 0..200 {
            let free = [true, false];
            act_centralized(
                &actor,
                &mut state,
                &obs,
                &free,
                &[9, 2],
                &[3, 4],
                Some(0.5),
                &mut rng,
                &mut probs,
                &mut actions,
            );
            assert_eq!(actions[1], 2, "a busy agent keeps its macro-action");
            seen[actions[0]] = true;
        }
        assert_eq!(
            seen, [true; 3],
            "the free agent samples all of its macro-actions"
        );
        let before = state.clone();
        act_centralized(
            &actor,
            &mut state,
            &obs,
            &[false, false],
            &[1, 3],
            &[3, 4],
            None,
            &mut rng,
            &mut probs,
            &mut actions,
        );
        assert_eq!(
            (actions, &state),
            ([1, 3], &before),
            "nobody free: nothing runs"
        );
    }
}
