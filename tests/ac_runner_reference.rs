//! The actor-critic training loop against MacroMARL's own runner (issue 42, item 6).
//!
//! The goldens (`tests/golden_ac.rs`) prove one learner update on a given batch. Here the batch
//! itself is at stake: each fixture in `tests/fixtures/ac_runner/` was written by
//! `scripts/ac_runner_trace_from_reference.py` from a few updates of the reference's own
//! `learn()` (its runner, controller, memory and schedule, unchanged): every macro-action its
//! controller sampled on every environment at every lockstep step, the exploration weight of
//! each batch, the batch its memory handed the learner, when it copied the target critics, and
//! its evaluation returns.
//!
//! Those macro-actions drive our [`TrainingLoop`] (the code path `macdec train` runs) through
//! [`ActionScript`], the only seam: the script answers where the actors would have sampled, and
//! checks on the way that the loop asks for the same environment, step and exploration weight,
//! with the same agents free. After each update the test checks that the batch our lanes
//! collected is the reference's record for record (observations, states, start flags, executed
//! macro-actions, discounted macro-rewards, terminal and end flags, to f32 precision; lengths
//! exactly), that the exploration weight is the reference's, that the targets were copied after
//! exactly the same updates, and that each evaluation came at the same episode count with the
//! reference's mean return (and, with gamma 1, the same undiscounted one). No torch is needed.

use std::collections::VecDeque;
use std::io::Read;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use macdec::algos::actor_critic::config::AcConfig;
use macdec::algos::actor_critic::episode::Episode;
use macdec::algos::actor_critic::learner::AcLearner;
use macdec::algos::actor_critic::method::{AcActor, AcMethod};
use macdec::algos::actor_critic::scripted::{ActingCall, ActionScript};
use macdec::algos::family::FamilyMethod;
use macdec::algos::learner::MethodName;
use macdec::algos::training_loop::{Advance, TrainingLoop};
use macdec::envs::{AnyEnv, EnvShape, EnvSpec};
use macdec::experiment::run::train_run::run_rngs;
use serde_json::Value;

/// The reference's float32 tensors against our f32 records: relative 1e-6 (absolute near zero).
fn close32(ours: f64, theirs: f64) -> bool {
    (ours - theirs).abs() <= 1e-6 * (1.0 + theirs.abs())
}

/// Python floats against our f64 arithmetic: the same operations up to summation order
/// (numpy's pairwise mean), so relative 1e-12.
fn close64(ours: f64, theirs: f64) -> bool {
    (ours - theirs).abs() <= 1e-12 * (1.0 + theirs.abs())
}

fn f(v: &Value) -> f64 {
    v.as_f64().expect("a number")
}

fn u(v: &Value) -> usize {
    v.as_u64().expect("a count") as usize
}

fn list(v: &Value) -> &Vec<Value> {
    v.as_array().expect("a list")
}

fn fixture(case: &str) -> Value {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/ac_runner")
        .join(format!("{case}.json.gz"));
    let gz = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut text = String::new();
    flate2::read::GzDecoder::new(&gz[..])
        .read_to_string(&mut text)
        .unwrap();
    serde_json::from_str(&text).unwrap()
}

/// Our environment from the fixture's macdec keys (as `experiments/macromarl/*.toml` name them).
fn spec_of(doc: &Value) -> EnvSpec {
    let mut keys = doc["env"]["macdec"].as_object().unwrap().clone();
    let name = keys.remove("env_name").unwrap();
    let table = toml::Table::try_from(Value::Object(keys)).unwrap();
    EnvSpec::new(name.as_str().unwrap(), &table).unwrap()
}

/// Two config values equal, an integer standing for the same float (JSON writes 1.0 as 1.0, a
/// Python int as 1).
fn same(a: &toml::Value, b: &toml::Value) -> bool {
    match (a, b) {
        (toml::Value::Float(x), toml::Value::Integer(y))
        | (toml::Value::Integer(y), toml::Value::Float(x)) => *x == *y as f64,
        _ => a == b,
    }
}

/// Our published config for the case's method and domain, with the case's overrides. Every
/// key the fixture records must be our published value, or an override whose published value
/// is ours (the published row is the reference's command).
fn config_of(doc: &Value, method: AcMethod, spec: &EnvSpec) -> AcConfig {
    let shape = EnvShape::of(spec).unwrap();
    let mut table = toml::Table::try_from(method.defaults(spec)).unwrap();
    let overrides = doc["overrides"].as_object().unwrap();
    for (key, value) in doc["config"].as_object().unwrap() {
        if key == "env_terminate_step" {
            assert_eq!(u(value), shape.horizon, "the horizon is the domain's");
            continue;
        }
        let ours = table
            .get(key.as_str())
            .unwrap_or_else(|| panic!("no key {key}"));
        let value = toml::Value::try_from(value).unwrap();
        let published = match overrides.get(key) {
            Some(o) => toml::Value::try_from(&o["published"]).unwrap(),
            None => value.clone(),
        };
        assert!(
            same(ours, &published),
            "{key}: our published value {ours}, the reference's command {published}"
        );
        let value = match (ours, value) {
            (toml::Value::Float(_), toml::Value::Integer(v)) => toml::Value::Float(v as f64),
            (_, v) => v,
        };
        table.insert(key.clone(), value);
    }
    let c: AcConfig = toml::Value::Table(table).try_into().unwrap();
    method
        .check(&c, &shape)
        .unwrap_or_else(|(k, why)| panic!("{k}: {why}"));
    c
}

/// One acting call the reference made: where, with which weight, and its controller's actions.
#[derive(Debug, Clone)]
struct Call {
    phase: usize,
    step: usize,
    env: usize,
    eps: Option<f64>,
    actions: Vec<i64>,
}

/// The reference's acting calls in order, and how far our loop has consumed them.
#[derive(Debug, Default)]
struct Script {
    calls: VecDeque<Call>,
    consumed: usize,
    /// Whether Mac-CAC's joint actions are checked on busy agents' running macro-actions.
    centralized: bool,
}

impl Script {
    fn answer(&mut self, call: ActingCall<'_>, actions: &mut [usize]) {
        let c = self
            .calls
            .pop_front()
            .expect("our loop stepped an environment the reference did not");
        self.consumed += 1;
        let at = format!("phase {} step {} env {}", c.phase, c.step, c.env);
        assert_eq!(
            call.eps.is_some(),
            c.eps.is_some(),
            "{at}: training vs evaluation"
        );
        if let (Some(ours), Some(theirs)) = (call.eps, c.eps) {
            assert!(close64(ours, theirs), "{at}: eps {ours} vs {theirs}");
        }
        let some_free = call.free.iter().any(|&x| x);
        for (i, &a) in c.actions.iter().enumerate() {
            if self.centralized {
                // MacCAC's controller returns a full joint action: a busy agent's component is
                // its running macro-action when some agent chooses (P4's conditioning).
                if some_free && !call.free[i] {
                    assert_eq!(
                        a, call.running[i] as i64,
                        "{at}: agent {i}'s running action"
                    );
                }
            } else {
                // Decentralized controllers give -1 for a busy agent.
                assert_eq!(
                    call.free[i],
                    a >= 0,
                    "{at}: agent {i} free? ({:?})",
                    c.actions
                );
            }
            if call.free[i] {
                actions[i] = usize::try_from(a).expect("a free agent's action");
            }
        }
    }
}

/// The fixture's episode as rows, against ours.
fn compare_episode(ours: &Episode, theirs: &Value, at: &str) {
    let steps = list(&theirs["action"]).len();
    assert_eq!(ours.steps, steps, "{at}: episode length");
    let n = ours.n_agents;
    let rows = |key: &str| -> Vec<f64> {
        list(&theirs[key])
            .iter()
            .flat_map(|r| list(r).iter().map(f))
            .collect()
    };
    let floats = |what: &str, a: &[f32], b: &[f64]| {
        assert_eq!(a.len(), b.len(), "{at}: {what} length");
        for (k, (&x, &y)) in a.iter().zip(b).enumerate() {
            assert!(
                close32(f64::from(x), y),
                "{at}: {what}[{k}] ours {x} vs {y}"
            );
        }
    };
    floats("obs", &ours.obs, &rows("obs"));
    if theirs.get("state").is_some() {
        floats("state", &ours.state, &rows("state"));
    } else {
        assert!(
            ours.state.is_empty(),
            "{at}: a state the reference did not record"
        );
    }
    floats("reward", &ours.reward, &rows("reward"));
    if let Some(j) = theirs.get("joint_reward") {
        let j: Vec<f64> = list(j).iter().map(f).collect();
        floats("joint_reward", &ours.joint_reward, &j);
    }
    let flags = |v: &[bool]| v.iter().map(|&b| usize::from(b) as f64).collect::<Vec<_>>();
    assert_eq!(flags(&ours.valid), rows("valid"), "{at}: valid");
    let terminate: Vec<f64> = list(&theirs["terminate"]).iter().map(f).collect();
    assert_eq!(flags(&ours.terminate), terminate, "{at}: terminate");
    let action: Vec<u32> = rows("action").iter().map(|&a| a as u32).collect();
    assert_eq!(ours.action, action, "{at}: executed macro-actions");
    // Families without `mac_start` imply it: a macro-action starts after one ended.
    let starts = if theirs.get("mac_start").is_some() {
        rows("mac_start")
    } else {
        let mut s = vec![1.0; n];
        let valid = rows("valid");
        s.extend_from_slice(&valid[..valid.len() - n]);
        s
    };
    assert_eq!(flags(&ours.mac_start), starts, "{at}: macro-action starts");
}

/// Replay fixture `case` through our loop and check it step by step; returns what it showed.
fn replays_like_the_reference(case: &str) -> Vec<String> {
    let doc = fixture(case);
    let method = *AcMethod::ALL
        .iter()
        .find(|m| m.name() == doc["method"].as_str().unwrap())
        .unwrap();
    assert_eq!(method.design().reference_alg, doc["alg"].as_str().unwrap());
    let spec = spec_of(&doc);
    let config = config_of(&doc, method, &spec);
    let phases = list(&doc["phases"]);
    let script = Arc::new(Mutex::new(Script {
        centralized: method.design().actor == AcActor::Centralized,
        ..Default::default()
    }));
    for (p, ph) in phases.iter().enumerate() {
        let eps = (ph["kind"] == "train").then(|| f(&ph["eps"]));
        for (s, step) in list(&ph["steps"]).iter().enumerate() {
            for (e, a) in list(step).iter().enumerate() {
                let actions = list(a).iter().map(|x| x.as_i64().unwrap()).collect();
                script.lock().unwrap().calls.push_back(Call {
                    phase: p,
                    step: s,
                    env: e,
                    eps,
                    actions,
                });
            }
        }
    }
    let mut l: TrainingLoop<AcLearner, AnyEnv> =
        TrainingLoop::new(&config, method, 0, run_rngs(0), || spec.build()).unwrap();
    let shared = Arc::clone(&script);
    l.learner_mut()
        .set_action_script(Some(ActionScript::new(move |call, actions| {
            shared.lock().unwrap().answer(call, actions)
        })));

    let n_env = config.n_env;
    let mut shown = Vec::new();
    let mut expected_consumed = 0;
    let mut train_steps = 0;
    let mut updates = 0;
    let mut last_eps = config.eps_start;
    let mut returns_since_eval: Vec<f64> = Vec::new();
    // Steps of the reference's completed training episodes: known exactly while every batch
    // kept all its completed episodes (the ones a batch completes beyond `train_freq` are not
    // in the recording), a lower bound after.
    let (mut completed_steps, mut completed_exact) = (0u64, true);
    let mut evals = 0;
    let mut p = 0;
    while p < phases.len() {
        // One advance: the evaluation before the batch when one is due, then the batch.
        let eval = (phases[p]["kind"] == "eval").then(|| &phases[p]);
        if eval.is_some() {
            p += 1;
        }
        let train = &phases[p];
        assert_eq!(train["kind"], "train", "phase {p}: a batch follows");
        for ph in eval.into_iter().chain([train]) {
            expected_consumed += list(&ph["steps"]).len() * n_env;
        }
        let before = l.episodes();
        assert_eq!(before, u(&train["epi_count"]) as u64, "phase {p}: episodes");
        assert!(matches!(l.advance().unwrap(), Advance::Episode { .. }));
        assert_eq!(
            script.lock().unwrap().consumed,
            expected_consumed,
            "phase {p}: our loop stepped the environments a different number of times"
        );
        if let Some(ev) = eval {
            let point = &l.evals()[evals];
            evals += 1;
            let at = format!("evaluation at episode {}", point.episode);
            assert_eq!(point.episode, u(&ev["epi_count"]) as u64, "{at}");
            assert_eq!(point.updates, updates, "{at}: updates");
            assert_eq!(
                point.env_steps,
                (train_steps * n_env) as u64,
                "{at}: env steps"
            );
            let mean = f(&ev["mean"]);
            assert!(
                close64(point.eval_return, mean),
                "{at}: ours {} vs the reference's {mean}",
                point.eval_return
            );
            let returns: Vec<f64> = list(&ev["returns"]).iter().map(f).collect();
            let last = &returns[returns.len() - config.eval_num_epi..];
            if config.gamma == 1.0 {
                // Undiscounted is ours only; with gamma 1 it is the reference's return.
                let plain = point.eval_return_undiscounted.unwrap();
                assert!(close64(plain, mean), "{at}: undiscounted {plain} vs {mean}");
            }
            // Our columns: the previous batch's eps; the mean return of the training episodes
            // completed since the previous row (in the reference's train_returns).
            let eps = point.family[0].unwrap();
            assert!(
                close64(eps, last_eps),
                "{at}: eps column {eps} vs {last_eps}"
            );
            let train_return = point.family[3];
            if returns_since_eval.is_empty() {
                assert_eq!(train_return, None, "{at}: train_return");
            } else {
                let m = returns_since_eval.iter().sum::<f64>() / returns_since_eval.len() as f64;
                let ours = train_return.expect("a train_return");
                assert!(close64(ours, m), "{at}: train_return {ours} vs {m}");
            }
            returns_since_eval.clear();
            let ours = point.family[4].unwrap() as u64;
            if completed_exact {
                assert_eq!(ours, completed_steps, "{at}: steps of completed episodes");
            } else {
                assert!(ours > completed_steps, "{at}: steps of completed episodes");
            }
            if returns.len() > config.eval_num_epi {
                shown.push(format!(
                    "{at}: {} episodes completed, the mean of the last {} ({last:?})",
                    returns.len(),
                    config.eval_num_epi
                ));
            }
        }
        // The batch.
        let at = format!("update at episode {before}");
        let eps = f(&train["eps"]);
        let ours_eps = l.learner().eps();
        assert!(close64(ours_eps, eps), "{at}: eps {ours_eps} vs {eps}");
        if ours_eps != eps {
            shown.push(format!(
                "{at}: eps {ours_eps:?} vs the reference's {eps:?} (rounding of the same line)"
            ));
        }
        last_eps = ours_eps;
        let batch = list(&train["batch"]);
        let ours = l.learner().batch();
        assert_eq!(ours.len(), batch.len(), "{at}: batch size");
        for (k, (o, t)) in ours.iter().zip(batch).enumerate() {
            compare_episode(o, t, &format!("{at}, episode {k}"));
        }
        let completed = list(&train["train_returns"]).len();
        if completed > config.train_freq {
            shown.push(format!(
                "{at}: {completed} episodes completed for {}, the last kept",
                config.train_freq
            ));
        }
        returns_since_eval.extend(list(&train["train_returns"]).iter().map(f));
        completed_exact &= completed == config.train_freq;
        completed_steps += batch
            .iter()
            .map(|e| list(&e["action"]).len() as u64)
            .sum::<u64>();
        train_steps += list(&train["steps"]).len();
        updates += 1;
        assert_eq!(l.updates(), updates, "{at}");
        assert_eq!(
            l.episodes(),
            before + config.train_freq as u64,
            "{at}: counted"
        );
        // The targets are the online critics right after a copy, and differ after an update
        // without one (every update steps every critic).
        let synced = train["target_sync_after"].as_bool().unwrap();
        for (c, critic) in l.learner().nets().critics.iter().enumerate() {
            assert_eq!(
                critic.target == critic.net,
                synced,
                "{at}: critic {c}'s target copied?"
            );
        }
        p += 1;
    }
    assert_eq!(l.advance().unwrap(), Advance::Finished, "the run ends");
    assert_eq!(
        l.evals().len(),
        evals,
        "no evaluation after the last update"
    );
    assert!(script.lock().unwrap().calls.is_empty(), "calls left over");
    shown.extend(
        list(&doc["exercised"])
            .iter()
            .map(|e| e.as_str().unwrap().to_string()),
    );
    shown
}

#[test]
fn box_pushing_mac_iaisc_collects_syncs_and_evaluates_as_the_reference() {
    let shown = replays_like_the_reference("bp6_mac_iaisc");
    eprintln!("{}", shown.join("\n"));
}

#[test]
fn warehouse_a_mac_cac_collects_syncs_and_evaluates_as_the_reference() {
    let shown = replays_like_the_reference("wh_a_mac_cac");
    eprintln!("{}", shown.join("\n"));
}
