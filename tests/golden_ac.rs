//! Differential tests of the actor-critic methods against the authors' reference implementation
//! (MacroMARL, `docs/MACROMARL.md` §2).
//!
//! Each directory `tests/golden_ac/<case>/` was written by `scripts/ac_golden_from_reference.py`
//! from the reference's own objects (its runner, `Memory_epi`, controller, nets, Adam and
//! learner): the initial actor, critic and target-critic weights, then two updates, each with the
//! batch of episodes exactly as the reference's memory held it, what its learner computed
//! (squeezed lengths, bootstraps, returns G, values, losses, advantages, the actors'
//! log-probabilities and policy-gradient weights), every net's gradient at its optimizer step
//! and every weight after the update.
//!
//! Here the same weights and batches go through our [`update`], update after update with our
//! own Adam state, and every number is compared: returns, values, advantages, log-probabilities
//! and losses to 1e-5 relative (relative to max(|x|, 1)), actions and lengths exactly,
//! gradients to 1e-4 relative plus 1e-6 of the tensor's scale, weights to 1e-5 relative plus
//! 1e-7 absolute (an element whose gradient is zero up to rounding moves by at most 2 lr; see
//! `tests/golden.rs`). No torch is needed.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use macdec::algos::actor_critic::config::AcConfig;
use macdec::algos::actor_critic::episode::Episode;
use macdec::algos::actor_critic::method::{AcActor, AcCritic, AcDesign, AcMethod};
use macdec::algos::actor_critic::nets::{AcNets, CriticNet, NetSizes};
use macdec::algos::actor_critic::update::{update, UpdateParams, UpdateTrace};
use macdec::algos::family::FamilyMethod;
use macdec::autograd::Tape;
use macdec::nn::{Params, GRU_ACTOR_TENSOR_NAMES, STATE_CRITIC_TENSOR_NAMES};
use rand::SeedableRng;
use safetensors::tensor::Dtype;
use safetensors::SafeTensors;
use serde_json::Value;

const VALUE_REL: f64 = 1e-5;
const GRAD_REL: f64 = 1e-4;
const GRAD_OF_SCALE: f64 = 1e-6;
const PARAM_REL: f64 = 1e-5;
const PARAM_ABS: f64 = 1e-7;
/// Below this gradient magnitude Adam's first steps are ill-conditioned (see `tests/golden.rs`).
const GRAD_FLOOR: f64 = 1e-6;

fn case_dir(case: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/golden_ac")
        .join(case)
}

fn f(v: &Value) -> f64 {
    v.as_f64().expect("a number")
}

fn usize_of(v: &Value) -> usize {
    v.as_u64().expect("a count") as usize
}

fn list(v: &Value) -> &Vec<Value> {
    v.as_array().expect("a list")
}

/// The tensors of a safetensors file, by name.
fn tensor(st: &SafeTensors<'_>, name: &str) -> Vec<f32> {
    let t = st
        .tensor(name)
        .unwrap_or_else(|_| panic!("tensor `{name}` missing"));
    assert_eq!(t.dtype(), Dtype::F32, "{name}");
    t.data()
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

/// A net's tensor names in its `Params::slices` order.
fn names_of(net: &CriticNet) -> &'static [&'static str] {
    match net {
        CriticNet::History(_) => &GRU_ACTOR_TENSOR_NAMES,
        CriticNet::State(_) => &STATE_CRITIC_TENSOR_NAMES,
    }
}

fn load_into(slots: Vec<&mut [f32]>, names: &[&str], st: &SafeTensors<'_>, prefix: &str) {
    for (slot, name) in slots.into_iter().zip(names) {
        let v = tensor(st, &format!("{prefix}.{name}"));
        assert_eq!(slot.len(), v.len(), "{prefix}.{name}: size");
        slot.copy_from_slice(&v);
    }
}

fn critic_slices_mut(net: &mut CriticNet) -> Vec<&mut [f32]> {
    match net {
        CriticNet::History(n) => n.slices_mut(),
        CriticNet::State(n) => n.slices_mut(),
    }
}

fn critic_slices(net: &CriticNet) -> Vec<&[f32]> {
    match net {
        CriticNet::History(n) => n.slices(),
        CriticNet::State(n) => n.slices(),
    }
}

/// The golden names of our nets: actors and critics, per agent or shared.
fn actor_name(design: AcDesign, a: usize) -> String {
    match design.actor {
        AcActor::Centralized => "actor".into(),
        AcActor::Decentralized => format!("actor{a}"),
    }
}

fn critic_name(design: AcDesign, c: usize) -> String {
    match design.critic {
        AcCritic::JointHistory | AcCritic::JointState => "critic".into(),
        _ => format!("critic{c}"),
    }
}

/// Load every net (online and target critics) from `st`.
fn load_nets(nets: &mut AcNets, design: AcDesign, st: &SafeTensors<'_>, with_targets: bool) {
    for (a, actor) in nets.actors.iter_mut().enumerate() {
        load_into(
            actor.net.slices_mut(),
            &GRU_ACTOR_TENSOR_NAMES,
            st,
            &actor_name(design, a),
        );
    }
    for (c, critic) in nets.critics.iter_mut().enumerate() {
        let names = names_of(&critic.net);
        let name = critic_name(design, c);
        load_into(critic_slices_mut(&mut critic.net), names, st, &name);
        if with_targets {
            load_into(
                critic_slices_mut(&mut critic.target),
                names,
                st,
                &format!("{name}_tgt"),
            );
        }
    }
}

/// One batch of the reference's memory as our episodes.
fn episodes(u: &Value, n: usize, obs_sizes: &[usize], state_size: usize) -> Vec<Episode> {
    let joint: usize = obs_sizes.iter().sum();
    list(&u["episodes"])
        .iter()
        .map(|records| {
            let records = list(records);
            let mut e = Episode {
                n_agents: n,
                joint_obs_size: joint,
                state_size,
                steps: records.len(),
                ..Default::default()
            };
            let mut last_valid = vec![true; n];
            for (t, r) in records.iter().enumerate() {
                let obs: Vec<f32> = list(&r["obs"])
                    .iter()
                    .flat_map(|o| list(o).iter().map(|v| f(v) as f32))
                    .collect();
                if t > 0 {
                    // Our rows share next_obs with the following record's obs: check they agree.
                    let prev = &e.obs[e.obs.len() - joint..];
                    assert_eq!(
                        prev,
                        &obs[..],
                        "record {t}: obs is not the previous next_obs"
                    );
                } else {
                    e.obs.extend(&obs);
                }
                let next: Vec<f32> = list(&r["next_obs"])
                    .iter()
                    .flat_map(|o| list(o).iter().map(|v| f(v) as f32))
                    .collect();
                e.obs.extend(&next);
                if state_size > 0 {
                    if t == 0 {
                        e.state
                            .extend(list(&r["state"]).iter().map(|v| f(v) as f32));
                    }
                    e.state
                        .extend(list(&r["next_state"]).iter().map(|v| f(v) as f32));
                }
                for i in 0..n {
                    // Families without `mac_start` record it implicitly: a start follows an end.
                    let start = r
                        .get("mac_start")
                        .map_or(last_valid[i], |s| usize_of(&s[i]) == 1);
                    e.mac_start.push(start);
                    e.action.push(usize_of(&r["action"][i]) as u32);
                    e.reward.push(f(&r["reward"][i]) as f32);
                    e.valid.push(usize_of(&r["valid"][i]) == 1);
                }
                e.joint_reward
                    .push(r.get("joint_reward").map_or(0.0, |v| f(v) as f32));
                e.terminate.push(f(&r["terminate"]) != 0.0);
                for (i, lv) in last_valid.iter_mut().enumerate() {
                    *lv = usize_of(&r["valid"][i]) == 1;
                }
            }
            e
        })
        .collect()
}

/// The reference's padded [B][K] array flattened over each row's first `lengths[b]` entries.
fn unpad(v: &Value, lengths: &[usize]) -> Vec<f64> {
    list(v)
        .iter()
        .zip(lengths)
        .flat_map(|(row, &l)| list(row)[..l].iter().map(f).collect::<Vec<_>>())
        .collect()
}

fn close(ours: f64, reference: f64, rel: f64) -> bool {
    (ours - reference).abs() <= rel * reference.abs().max(1.0)
}

fn compare_values(what: &str, ours: &[f32], reference: &[f64], report: &mut String) {
    if ours.len() != reference.len() {
        let _ = writeln!(
            report,
            "{what}: {} values vs the reference's {}",
            ours.len(),
            reference.len()
        );
        return;
    }
    let bad: Vec<(usize, f32, f64)> = ours
        .iter()
        .zip(reference)
        .enumerate()
        .filter(|(_, (&o, &r))| !close(f64::from(o), r, VALUE_REL))
        .map(|(k, (&o, &r))| (k, o, r))
        .collect();
    if let Some((k, o, r)) = bad.first() {
        let _ = writeln!(
            report,
            "{what}: {} of {} differ, first at {k}: ours {o} vs {r}",
            bad.len(),
            ours.len()
        );
    }
}

/// Elements whose Adam step was ill-conditioned at some update so far (the reference's gradient
/// below [`GRAD_FLOOR`]), per tensor, with how many such steps each took: each may have moved
/// the weight by up to 2 lr differently, and the difference stays in the weight.
type IllConditioned = std::collections::HashMap<String, Vec<u32>>;

/// Record the elements of `prefix`'s tensors whose reference gradient in `grads` is below the
/// floor.
fn note_ill_conditioned(
    ill: &mut IllConditioned,
    grads: &SafeTensors<'_>,
    prefix: &str,
    names: &[&str],
) {
    for name in names {
        let key = format!("{prefix}.{name}");
        let g = tensor(grads, &key);
        let counts = ill.entry(key).or_insert_with(|| vec![0; g.len()]);
        for (c, v) in counts.iter_mut().zip(&g) {
            *c += u32::from(f64::from(*v).abs() < GRAD_FLOOR);
        }
    }
}

/// Every tensor against the reference's: |d| <= rel |ref| + abs + of_scale max|ref|; an element
/// with ill-conditioned steps (`ill`, with the net's learning rate) may differ by 2 lr per such
/// step.
#[allow(clippy::too_many_arguments)]
fn compare_tensors(
    what: &str,
    ours: Vec<&[f32]>,
    names: &[&str],
    st: &SafeTensors<'_>,
    prefix: &str,
    (rel, abs, of_scale): (f64, f64, f64),
    ill: Option<(&IllConditioned, f64)>,
    report: &mut String,
) {
    for (a, name) in ours.into_iter().zip(names) {
        let key = format!("{prefix}.{name}");
        let b = tensor(st, &key);
        let steps = ill.and_then(|(m, lr)| m.get(&key).map(|c| (c, lr)));
        let scale = b.iter().fold(0.0f64, |m, &v| m.max(f64::from(v).abs()));
        let mut bad = 0;
        let mut worst = None;
        for (k, (&x, &y)) in a.iter().zip(&b).enumerate() {
            let (x, y) = (f64::from(x), f64::from(y));
            let mut bound = rel * y.abs() + abs + of_scale * scale;
            if let Some((counts, lr)) = steps {
                bound = bound.max(2.0 * lr * f64::from(counts[k]));
            }
            if (x - y).abs() > bound {
                bad += 1;
                worst.get_or_insert((x, y, k));
            }
        }
        if let Some((x, y, k)) = worst {
            let _ = writeln!(
                report,
                "{what} {prefix}.{name}: {bad} of {} differ, e.g. [{k}] ours {x:e} vs {y:e}",
                a.len()
            );
        }
    }
}

fn compare_update(
    design: AcDesign,
    trace: &UpdateTrace,
    learner: &Value,
    report: &mut String,
    exercised: &mut Vec<String>,
) {
    for (c, critic) in trace.critics.iter().enumerate() {
        let name = critic_name(design, c);
        let g = &learner["critics"][&name];
        let stepped = g["stepped"].as_bool().unwrap_or(true);
        let Some(critic) = critic else {
            if stepped {
                let _ = writeln!(report, "{name}: skipped here, stepped by the reference");
            }
            continue;
        };
        if !stepped {
            let _ = writeln!(report, "{name}: stepped here, skipped by the reference");
            continue;
        }
        let lengths: Vec<usize> = list(&g["epi_len"]).iter().map(usize_of).collect();
        if lengths != critic.lengths {
            let _ = writeln!(
                report,
                "{name}: squeezed lengths {:?} vs {lengths:?}",
                critic.lengths
            );
            continue;
        }
        compare_values(
            &format!("{name} bootstrap"),
            &critic.bootstraps,
            &unpad(&g["bootstrap"], &lengths),
            report,
        );
        compare_values(
            &format!("{name} G"),
            &critic.returns,
            &unpad(&g["G"], &lengths),
            report,
        );
        compare_values(
            &format!("{name} V"),
            &critic.values,
            &unpad(&g["V"], &lengths),
            report,
        );
        compare_values(
            &format!("{name} advantage"),
            &critic.advantages,
            &unpad(&g["adv"], &lengths),
            report,
        );
        compare_values(
            &format!("{name} loss"),
            &[critic.loss],
            &[f(&g["loss"])],
            report,
        );
        exercised.push(format!("{name}: {} macro-actions", critic.returns.len()));
    }
    for (a, actor) in trace.actors.iter().enumerate() {
        let name = actor_name(design, a);
        let g = &learner["actors"][&name];
        let stepped = g["stepped"].as_bool().unwrap_or(true);
        let Some(actor) = actor else {
            if stepped {
                let _ = writeln!(report, "{name}: skipped here, stepped by the reference");
            }
            continue;
        };
        let lengths: Vec<usize> = list(&g["epi_len"]).iter().map(usize_of).collect();
        if lengths != actor.lengths {
            let _ = writeln!(
                report,
                "{name}: squeezed lengths {:?} vs {lengths:?}",
                actor.lengths
            );
            continue;
        }
        let actions: Vec<usize> = unpad(&g["action"], &lengths)
            .into_iter()
            .map(|a| a as usize)
            .collect();
        if actions != actor.actions {
            let _ = writeln!(report, "{name}: actions differ");
        }
        compare_values(
            &format!("{name} advantage"),
            &actor.advantages,
            &unpad(&g["adv"], &lengths),
            report,
        );
        compare_values(
            &format!("{name} discount"),
            &actor.discounts,
            &unpad(&g["discount"], &lengths),
            report,
        );
        compare_values(
            &format!("{name} log_pi"),
            &actor.log_probs,
            &unpad(&g["log_pi_a"], &lengths),
            report,
        );
        compare_values(
            &format!("{name} loss"),
            &[actor.loss],
            &[f(&g["loss"])],
            report,
        );
    }
}

fn run_case(case: &str) -> String {
    let dir = case_dir(case);
    let golden: Value =
        serde_json::from_slice(&std::fs::read(dir.join("golden.json")).unwrap()).unwrap();
    let alg = golden["alg"].as_str().unwrap();
    let method = *AcMethod::ALL
        .iter()
        .find(|m| m.design().reference_alg == alg)
        .unwrap_or_else(|| panic!("no method is the reference's {alg}"));
    let design = method.design();
    let h = &golden["hyper"];
    let sizes = NetSizes {
        obs_sizes: list(&h["obs_sizes"]).iter().map(usize_of).collect(),
        n_actions: list(&h["n_actions"]).iter().map(usize_of).collect(),
        state_size: h["state_size"].as_u64().unwrap_or(0) as usize,
    };
    let mut c = AcConfig::reference_defaults();
    c.a_lr = f(&h["a_lr"]);
    c.c_lr = f(&h["c_lr"]);
    c.gamma = f(&h["gamma"]);
    c.n_step_td = usize_of(&h["n_step_TD"]);
    c.a_mlp_layer_size = list(&h["a_mlp_layer_size"]).iter().map(usize_of).collect();
    c.c_mlp_layer_size = list(&h["c_mlp_layer_size"]).iter().map(usize_of).collect();
    c.a_rnn_layer_size = usize_of(&h["a_rnn_layer_size"]);
    c.c_rnn_layer_size = usize_of(&h["c_rnn_layer_size"]);
    c.c_mid_layer_size = usize_of(&h["c_mid_layer_size"]);
    let state_size = if matches!(design.critic, AcCritic::JointState | AcCritic::AgentState) {
        sizes.state_size
    } else {
        0
    };
    let mut nets = AcNets::new(
        design,
        &c,
        &NetSizes {
            state_size,
            ..sizes.clone()
        },
        &mut rand_chacha::ChaCha8Rng::seed_from_u64(0),
    )
    .unwrap();
    let init = std::fs::read(dir.join("init.safetensors")).unwrap();
    load_nets(
        &mut nets,
        design,
        &SafeTensors::deserialize(&init).unwrap(),
        true,
    );
    let mut report = String::new();
    let mut exercised = Vec::new();
    let mut tape = Tape::new();
    let mut ill = IllConditioned::new();
    for (k, u) in list(&golden["updates"]).iter().enumerate() {
        let batch = episodes(u, sizes.obs_sizes.len(), &sizes.obs_sizes, state_size);
        let p = UpdateParams {
            design,
            gamma: c.gamma,
            n_step: c.n_step_td,
            eps: f(&u["eps"]),
            pg_discount_at_start: false,
            pg_plain_log_prob: false,
            obs_sizes: sizes.obs_sizes.clone(),
            n_actions: sizes.n_actions.clone(),
        };
        let trace = update(&mut nets, &p, &batch, &mut tape);
        let what = format!("update {}", k + 1);
        let mut r = String::new();
        compare_update(design, &trace, &u["learner"], &mut r, &mut exercised);
        let grads_bytes =
            std::fs::read(dir.join(format!("update{}_grads.safetensors", k + 1))).unwrap();
        let grads = SafeTensors::deserialize(&grads_bytes).unwrap();
        let weights_bytes =
            std::fs::read(dir.join(format!("update{}_weights.safetensors", k + 1))).unwrap();
        let weights = SafeTensors::deserialize(&weights_bytes).unwrap();
        let grad_tol = (GRAD_REL, 0.0, GRAD_OF_SCALE);
        let param_tol = (PARAM_REL, PARAM_ABS, 0.0);
        for (c_idx, critic) in trace.critics.iter().enumerate() {
            let name = critic_name(design, c_idx);
            let net = &nets.critics[c_idx];
            if let Some(t) = critic {
                compare_tensors(
                    &format!("{what} grad"),
                    critic_slices(&t.grads),
                    names_of(&t.grads),
                    &grads,
                    &name,
                    grad_tol,
                    None,
                    &mut r,
                );
                note_ill_conditioned(&mut ill, &grads, &name, names_of(&net.net));
            }
            compare_tensors(
                &format!("{what} weight"),
                critic_slices(&net.net),
                names_of(&net.net),
                &weights,
                &name,
                param_tol,
                Some((&ill, c.c_lr)),
                &mut r,
            );
        }
        for (a_idx, actor) in trace.actors.iter().enumerate() {
            let name = actor_name(design, a_idx);
            if let Some(t) = actor {
                compare_tensors(
                    &format!("{what} grad"),
                    t.grads.slices(),
                    &GRU_ACTOR_TENSOR_NAMES,
                    &grads,
                    &name,
                    grad_tol,
                    None,
                    &mut r,
                );
                note_ill_conditioned(&mut ill, &grads, &name, &GRU_ACTOR_TENSOR_NAMES);
            }
            compare_tensors(
                &format!("{what} weight"),
                nets.actors[a_idx].net.slices(),
                &GRU_ACTOR_TENSOR_NAMES,
                &weights,
                &name,
                param_tol,
                Some((&ill, c.a_lr)),
                &mut r,
            );
        }
        if !r.is_empty() {
            let _ = write!(report, "{what}:\n{r}");
        }
        if u["target_sync_after"].as_bool().unwrap_or(false) {
            nets.sync_targets();
        }
    }
    let said: Vec<String> = list(&golden["exercised"])
        .iter()
        .map(|v| v.as_str().unwrap_or("").to_string())
        .collect();
    eprintln!("{case}: {alg}, exercised: {}", said.join("; "));
    report
}

fn assert_case(case: &str) {
    let report = run_case(case);
    assert!(
        report.is_empty(),
        "{case} differs from the reference:\n{report}"
    );
}

#[test]
fn mac_iac_box_pushing_matches_the_reference() {
    assert_case("mac_iac_bp4_g098_n0");
}

#[test]
fn mac_iac_warehouse_e_five_step_with_a_target_sync_matches_the_reference() {
    assert_case("mac_iac_osdf_g1_n5_sync");
}

#[test]
fn mac_cac_warehouse_a_matches_the_reference() {
    assert_case("mac_cac_osdd_g1_n0");
}

#[test]
fn mac_cac_box_pushing_three_step_matches_the_reference() {
    assert_case("mac_cac_bp4_g098_n3");
}

#[test]
fn naive_mac_iacc_warehouse_e_matches_the_reference() {
    assert_case("naive_mac_iacc_osdf_g1_n3");
}

#[test]
fn naive_mac_iasc_box_pushing_matches_the_reference() {
    assert_case("naive_mac_iasc_bp4_g098_n1");
}

#[test]
fn mac_iaicc_warehouse_a_four_step_matches_the_reference() {
    assert_case("mac_iaicc_osdd_g098_n4");
}

#[test]
fn mac_iaicc_box_pushing_matches_the_reference() {
    assert_case("mac_iaicc_bp4_g1_n0");
}

#[test]
fn mac_iaisc_box_pushing_three_step_matches_the_reference() {
    assert_case("mac_iaisc_bp6_g098_n3");
}
