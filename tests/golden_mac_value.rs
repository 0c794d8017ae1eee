//! Differential tests of MacroMARL's value-based methods (MacDec-Q, MacCen-Q, MacDec-DDRQN,
//! Parallel-MacDec-DDRQN: its two memories, the centralized net's batch from one) against the
//! reference's own code (`docs/MACROMARL.md` §8).
//!
//! Each `tests/golden_mac_value/<case>.json` was written by
//! `scripts/mac_value_golden_from_reference.py` from the reference's objects: its runner workers
//! (`envs_runner.py: worker`, `envs_runner_cen_condi.py: worker`) replaying scripted episodes with
//! random rewards, macro-action ends and availability masks; its memory (`ReplayMemory_rand`
//! windows with FIFO eviction, or `ReplayMemory_epi`) and the indices its `sample` drew; the
//! team's `sep_joint_exps`; and its learner (`QLearn_squ`, `QLearn_squ_cen_condi_0`,
//! `QLearn_squ_dec_cen_0`: the centralized net then the agents' nets) on its
//! `DDRQN` nets and Adam, three updates with hysteresis 0.3, 0.55 and 1 and a hard target copy
//! before the third.
//!
//! Here our recorder replays the same scripted steps and must give every record (discounted
//! macro-rewards, gamma^(k-1), the joint ones, masks, flags) to 1e-6; our memory must hold as
//! many entries and the drawn entries must be the same records; and our update, from the same
//! initial weights on those entries, must give every weight after every update to 1e-5 relative
//! plus 1e-6 absolute. No torch is needed.

use std::path::Path;

use macdec::algos::mac_value::choice::Dims;
use macdec::algos::mac_value::episode::{Episode, Recorder, Step, StepParts};
use macdec::algos::mac_value::memory::Memory;
use macdec::algos::mac_value::update::{
    update_cen, update_dec, update_dec_cen, QNet, UpdateScratch,
};
use macdec::envs::StepOutcome;
use macdec::nn::{GruActor, GruActorConfig, Params};
use serde_json::Value;

const RECORD_TOL: f64 = 1e-6;
const PARAM_REL: f64 = 1e-5;
const PARAM_ABS: f64 = 1e-6;

fn load(case: &str) -> Value {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/golden_mac_value")
        .join(format!("{case}.json"));
    serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap()
}

fn floats(v: &Value) -> Vec<f32> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap() as f32)
        .collect()
}

fn counts(v: &Value) -> Vec<usize> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_u64().unwrap() as usize)
        .collect()
}

fn concat(v: &Value) -> Vec<f32> {
    v.as_array().unwrap().iter().flat_map(floats).collect()
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * a.abs().max(b.abs()).max(1.0)
}

/// Our recorder over the scripted episodes: the records the reference's runner made.
fn recorded(case: &Value) -> Vec<Episode> {
    let discount = case["discount"].as_f64().unwrap();
    let expected = case["episodes"].as_array().unwrap();
    let mut out = Vec::new();
    for (script, want) in case["scripted"].as_array().unwrap().iter().zip(expected) {
        let n_records = want.as_array().unwrap().len();
        let mut rec = Recorder::starting(concat(&script["reset_obs"]), 2, discount);
        let mut episode = None;
        for (t, s) in script["steps"].as_array().unwrap()[..n_records]
            .iter()
            .enumerate()
        {
            let executed = counts(&s["executed"]);
            let mac_done: Vec<bool> = s["mac_done"]
                .as_array()
                .unwrap()
                .iter()
                .map(|b| b.as_bool().unwrap())
                .collect();
            let reward = s["reward"].as_f64().unwrap();
            let outcome = if t + 1 == n_records {
                StepOutcome::ended(reward, s["terminal"].as_bool().unwrap())
            } else {
                StepOutcome::running(reward)
            };
            let parts = StepParts {
                next_obs: concat(&s["obs"]),
                executed: &executed,
                mac_done: &mac_done,
                next_avail: concat(&s["avail"]),
            };
            episode = rec.record_parts(parts, outcome);
        }
        let episode = episode.expect("the last step ends the episode");
        for (t, (ours, theirs)) in episode.iter().zip(want.as_array().unwrap()).enumerate() {
            check_record(ours, theirs, t);
        }
        out.push(episode);
    }
    out
}

fn check_record(ours: &Step, theirs: &Value, t: usize) {
    let same = |name: &str, a: &[f32], b: Vec<f32>| {
        assert_eq!(a.len(), b.len(), "{name} at step {t}");
        for (x, y) in a.iter().zip(&b) {
            assert!(
                close(f64::from(*x), f64::from(*y), RECORD_TOL),
                "{name} at step {t}: ours {a:?}, reference {b:?}"
            );
        }
    };
    same("obs", &ours.obs, floats(&theirs["obs"]));
    same("rewards", &ours.rewards, floats(&theirs["rewards"]));
    same("gammas", &ours.gammas, floats(&theirs["gammas"]));
    same(
        "joint_reward",
        &[ours.joint_reward],
        vec![theirs["joint_reward"].as_f64().unwrap() as f32],
    );
    same(
        "joint_gamma",
        &[ours.joint_gamma],
        vec![theirs["joint_gamma"].as_f64().unwrap() as f32],
    );
    same("next_obs", &ours.next_obs, floats(&theirs["next_obs"]));
    same(
        "next_avail",
        &ours.next_avail,
        floats(&theirs["next_avail"]),
    );
    assert_eq!(
        ours.actions,
        counts(&theirs["actions"]),
        "actions at step {t}"
    );
    assert_eq!(
        ours.terminal,
        theirs["terminal"].as_bool().unwrap(),
        "terminal at {t}"
    );
    let valid: Vec<bool> = theirs["valid"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b.as_bool().unwrap())
        .collect();
    assert_eq!(ours.valid, valid, "valid at step {t}");
}

fn net_from(cfg: GruActorConfig, tensors: &Value) -> GruActor {
    let mut net = GruActor::zeros(cfg);
    let values: Vec<Vec<f32>> = tensors.as_array().unwrap().iter().map(floats).collect();
    for (slot, v) in net.slices_mut().into_iter().zip(&values) {
        assert_eq!(slot.len(), v.len(), "tensor size");
        slot.copy_from_slice(v);
    }
    net
}

fn check_weights(net: &GruActor, want: &Value, what: &str) {
    for (k, (ours, theirs)) in net
        .slices()
        .into_iter()
        .zip(want.as_array().unwrap())
        .enumerate()
    {
        for (j, (&a, b)) in ours.iter().zip(floats(theirs)).enumerate() {
            let (a, b) = (f64::from(a), f64::from(b));
            assert!(
                (a - b).abs() <= PARAM_REL * a.abs().max(b.abs()) + PARAM_ABS,
                "{what}: tensor {k} element {j}: ours {a}, reference {b}"
            );
        }
    }
}

fn run_case(name: &str) {
    let case = load(name);
    let episodes = recorded(&case);
    let m = &case["memory"];
    let new_memory = || {
        Memory::new(
            m["sample_epi"].as_bool().unwrap(),
            m["trace_len"].as_u64().unwrap() as usize,
            m["capacity"].as_u64().unwrap() as usize,
        )
    };
    let alg = case["alg"].as_str().unwrap();
    let parallel = alg == "ParallelMacDecDDRQN";
    // Parallel-MacDec-DDRQN: the first half of the episodes came from the centralized runner.
    let (mut memory, mut cen_memory) = (new_memory(), new_memory());
    let half = episodes.len() / 2;
    for (k, e) in episodes.into_iter().enumerate() {
        if parallel && k < half {
            cen_memory.push(e);
        } else {
            memory.push(e);
        }
    }
    assert_eq!(
        memory.len() as u64,
        m["held"].as_u64().unwrap(),
        "{name}: entries held"
    );
    assert_eq!(
        cen_memory.len() as u64,
        m["cen_held"].as_u64().unwrap(),
        "{name}: centralized entries held"
    );
    let dims = Dims {
        obs_sizes: counts(&case["obs_sizes"]),
        n_actions: counts(&case["n_actions"]),
    };
    let mlp = counts(&case["mlp_layer_size"]);
    let layers = |input, output| GruActorConfig {
        input,
        mlp: [mlp[0], mlp[1]],
        hidden: case["rnn_h_size"].as_u64().unwrap() as usize,
        output,
    };
    let joint_input: usize = dims.obs_sizes.iter().sum();
    let mut shapes: Vec<GruActorConfig> = if alg == "MacCenQ" {
        vec![layers(joint_input, dims.n_joint())]
    } else {
        (0..2)
            .map(|i| layers(dims.obs_sizes[i], dims.n_actions[i]))
            .collect()
    };
    if alg.contains("DDRQN") {
        let cen_mlp = counts(&case["cen_mlp_layer_size"]);
        shapes.push(GruActorConfig {
            input: joint_input,
            mlp: [cen_mlp[0], cen_mlp[1]],
            hidden: case["cen_rnn_h_size"].as_u64().unwrap() as usize,
            output: dims.n_joint(),
        });
    }
    let lr = case["l_rate"].as_f64().unwrap();
    let mut nets: Vec<QNet> = shapes
        .iter()
        .zip(case["init_weights"].as_array().unwrap())
        .map(|(&cfg, w)| QNet::from_net(net_from(cfg, w), lr))
        .collect();
    let discount = case["discount"].as_f64().unwrap();
    // One scratch for every update, as a learner keeps it.
    let mut scratch = UpdateScratch::default();
    for (k, u) in case["updates"].as_array().unwrap().iter().enumerate() {
        if u["sync_before"].as_bool().unwrap() {
            for q in &mut nets {
                q.target.copy_values_from(&q.net);
            }
        }
        let batch: Vec<&[Step]> = counts(&u["indices"])
            .into_iter()
            .map(|i| memory.entry(i))
            .collect();
        let cen_batch: Vec<&[Step]> = counts(&u["cen_indices"])
            .into_iter()
            .map(|i| cen_memory.entry(i))
            .collect();
        let h = u["hysteresis"].as_f64().unwrap();
        let updated = match alg {
            "MacCenQ" => update_cen(
                &mut nets[0],
                &batch,
                None,
                &dims,
                h,
                discount,
                1,
                &mut scratch,
            )
            .is_some(),
            "MacDecQ" => {
                update_dec(&mut nets, &batch, None, &dims, h, discount, 1, &mut scratch).is_some()
            }
            _ => {
                let (decs, cen) = nets.split_at_mut(2);
                let cen_batch = if parallel { &cen_batch } else { &batch };
                update_dec_cen(
                    &mut cen[0],
                    decs,
                    cen_batch,
                    &batch,
                    &dims,
                    h,
                    discount,
                    1,
                    &mut scratch,
                )
                .is_some_and(|(_, decs)| decs.len() == 2)
            }
        };
        assert!(updated, "{name}: update {k} kept records");
        for (i, (q, want)) in nets
            .iter()
            .zip(u["weights_after"].as_array().unwrap())
            .enumerate()
        {
            check_weights(&q.net, want, &format!("{name}: update {k}, net {i}"));
        }
    }
}

#[test]
fn mac_dec_q_on_windows_matches_the_reference() {
    run_case("mac_dec_q_windows");
}

#[test]
fn mac_dec_q_on_whole_episodes_matches_the_reference() {
    run_case("mac_dec_q_episodes");
}

#[test]
fn mac_cen_q_on_windows_matches_the_reference() {
    run_case("mac_cen_q_windows");
}

#[test]
fn mac_cen_q_on_whole_episodes_matches_the_reference() {
    run_case("mac_cen_q_episodes");
}

#[test]
fn mac_dec_ddrqn_on_windows_matches_the_reference() {
    run_case("mac_dec_ddrqn_windows");
}

#[test]
fn mac_dec_ddrqn_on_whole_episodes_matches_the_reference() {
    run_case("mac_dec_ddrqn_episodes");
}

#[test]
fn parallel_mac_dec_ddrqn_on_windows_matches_the_reference() {
    run_case("parallel_mac_dec_ddrqn_windows");
}

#[test]
fn parallel_mac_dec_ddrqn_on_whole_episodes_matches_the_reference() {
    run_case("parallel_mac_dec_ddrqn_episodes");
}
