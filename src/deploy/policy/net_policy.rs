//! The real policy behind a robot: one agent's net (a recurrent Q-net or a MacroMARL actor,
//! [`ActingNet`]) and its recurrent state, stepped with the same no-tape acting forward greedy
//! evaluation uses. The scores it answers with are the net's (Q-values or log-probabilities);
//! either way the highest is the greedy macro-action.

use crate::deploy::serve::server::PolicyFactory;
use crate::deploy::AgentPolicy;
use crate::nn::{ActingNet, ActingState};
use crate::policy_files::{Manifest, PolicyError, VerifiedAgent};
use std::sync::Arc;

/// A net shared between connections, with this connection's hidden state.
pub struct NetPolicy {
    net: Arc<ActingNet>,
    state: ActingState,
    /// Where a step is computed; it becomes the state only if everything came out finite.
    candidate: ActingState,
}

impl NetPolicy {
    /// The net with a zero hidden state.
    pub fn new(net: Arc<ActingNet>) -> Self {
        let state = net.zero_state();
        let candidate = net.zero_state();
        NetPolicy {
            net,
            state,
            candidate,
        }
    }
}

impl NetPolicy {
    /// The first half of a step: the Q-values of `obs` from the current hidden state, computed
    /// into a candidate state that only [`NetPolicy::commit`] makes current. Whether the values
    /// and the candidate state came out finite. A team steps all-or-nothing with it: every
    /// agent proposes, and only if all are finite do all commit.
    pub fn propose(&mut self, obs: &[f32], step: usize, q: &mut [f32]) -> bool {
        self.candidate.copy_from(&self.state);
        q.copy_from_slice(self.net.act_step(obs, step, &mut self.candidate));
        q.iter().all(|x| x.is_finite()) && self.candidate.is_finite()
    }

    /// Makes the last [`NetPolicy::propose`]'s state the current one.
    pub fn commit(&mut self) {
        std::mem::swap(&mut self.state, &mut self.candidate);
    }
}

impl AgentPolicy for NetPolicy {
    fn obs_len(&self) -> usize {
        self.net.obs_len()
    }
    fn n_actions(&self) -> usize {
        self.net.n_actions()
    }
    fn reset(&mut self) {
        self.state.reset();
    }
    fn reads_step(&self) -> bool {
        self.net.reads_step()
    }
    fn q_values(&mut self, obs: &[f32], step: usize, q: &mut [f32]) {
        // A huge but finite observation can overflow the recurrent layer: keep the old state
        // then, so one bad message does not break the rest of the session.
        if self.propose(obs, step, q) {
            self.commit();
        }
    }
}

/// Build agent `verified.index`'s net from its verified weight bytes, sized by its net entry.
pub fn load_net(manifest: &Manifest, verified: &VerifiedAgent) -> Result<ActingNet, PolicyError> {
    manifest.agent_acting_net(verified)
}

/// A factory giving each connection the same net with a fresh zero state.
pub fn net_factory(net: ActingNet) -> PolicyFactory {
    let net = Arc::new(net);
    Arc::new(move || Box::new(NetPolicy::new(net.clone())) as Box<dyn AgentPolicy>)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nn::safetensors_io::to_safetensors_bytes;
    use crate::nn::QNet;
    use crate::nn::QNetConfig;
    use crate::policy_files::architecture::Architecture;
    use crate::policy_files::{load_agent, RunInfo};
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn an_exported_net_answers_exactly_like_the_original_across_steps_and_resets() {
        let dir = tempfile::tempdir().unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let nets: Vec<QNet> = [13, 13, 4]
            .iter()
            .zip([3, 3, 6])
            .map(|(&input, output)| {
                QNet::new(
                    QNetConfig {
                        input,
                        mlp: 8,
                        hidden: 6,
                        output,
                    },
                    &mut rng,
                )
            })
            .collect();
        let weights: Vec<Vec<u8>> = nets
            .iter()
            .map(|n| to_safetensors_bytes(&n.params))
            .collect();
        let run = RunInfo {
            experiment: "test".into(),
            method: "our1".into(),
            variant: String::new(),
            seed: 1,
            episodes_trained: 0,
            config: serde_json::Value::Null,
        };
        let env = crate::envs::warehouse::spec(150, 0.0);
        Manifest::write_policy(
            dir.path(),
            env,
            0.95,
            Architecture::ddrqn(8, 6),
            run,
            &weights,
        )
        .unwrap();
        let (manifest, verified) = load_agent(dir.path(), 2).unwrap();
        let mut policy = NetPolicy::new(Arc::new(load_net(&manifest, &verified).unwrap()));
        assert_eq!((policy.obs_len(), policy.n_actions()), (4, 6));
        let mut state = nets[2].zero_state();
        let mut q = vec![0.0; 6];
        for t in 0..5 {
            if t == 3 {
                policy.reset();
                state.reset();
            }
            let obs = [t as f32 * 0.25, 1.0, 0.0, -0.5];
            policy.q_values(&obs, t, &mut q);
            assert_eq!(q, nets[2].act_step(&obs, &mut state));
        }
    }

    #[test]
    fn an_overflowing_observation_leaves_the_hidden_state_exactly_as_it_was() {
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let cfg = QNetConfig {
            input: 5,
            mlp: 8,
            hidden: 6,
            output: 4,
        };
        let net = Arc::new(ActingNet::Q(QNet::new(cfg, &mut rng)));
        let (a, b) = ([0.5, -1.0, 0.0, 1.0, 0.25], [1.0, 0.0, 1.0, 0.0, -0.5]);
        let mut q = [0.0; 4];
        let mut reference = NetPolicy::new(net.clone());
        reference.q_values(&a, 0, &mut q);
        reference.q_values(&b, 1, &mut q);
        let expected = q;

        let mut policy = NetPolicy::new(net);
        policy.q_values(&a, 0, &mut q);
        policy.q_values(&[3.4e38; 5], 1, &mut q);
        assert!(
            q.iter().any(|v| !v.is_finite()),
            "the probe must overflow: {q:?}"
        );
        policy.q_values(&b, 1, &mut q);
        assert_eq!(q, expected);
    }
}
