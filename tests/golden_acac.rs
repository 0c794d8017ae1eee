//! ACAC's three learners (`acac`, `acac-micro-gae`, `acac-vanilla`) against one `train` call
//! each, recorded from ACAC's own code (`tests/golden_acac/README.md`, written by `scripts/acac_golden_from_reference.py`).
//!
//! From each case's batch (the runner's padded episodes) we build our recorded episodes and
//! squeeze them; from its `init` weights (ACAC's `state_dict` names) our nets; with its dropout
//! masks replayed, our update must give the squeezed batch exactly, the returns (GAE with
//! PopArt, or acac-vanilla's n-step returns) and advantages, the actors' log pi_old (PPO) or
//! entropies (vanilla), each epoch's critic and actor losses, and every weight after the last
//! epoch, to the tolerances below. No torch.

use std::path::{Path, PathBuf};

use macdec::algos::acac::batch::{AcacBatch, SqueezedEpisode};
use macdec::algos::acac::nets::AcacCritic;
use macdec::algos::acac::train_step::update;
use macdec::algos::acac::update::{
    AcacNets, DropoutSource, GaeLambda, Objective, UpdateParams, UpdateTrace,
};
use macdec::algos::actor_critic::episode::{Episode, EpisodeRecorder};
use macdec::autograd::Tape;
use macdec::envs::{EnvRng, EnvSpec, MacroEnv};
use macdec::experiment::definition::config::{Experiment, Overrides};
use macdec::nn::{AcacActor, TIME_TABLE};
use macdec::nn::{BlockDropout, Gpt2Dropout, StateDict, TimeEmbedding, ValueHead};
use ndarray::{Array2, ArrayViewD};
use rand::SeedableRng;
use serde_json::Value;

/// Advantages, returns, log-probabilities and losses, relative to max(|x|, 1). Measured on the
/// four cases (2026-12-05, `GOLDEN_ACAC_VERBOSE=1` prints each quantity's worst): at most
/// 1.1e-6, float rounding between our kernels and torch's.
const VALUE_TOL: f64 = 1e-5;
/// Every weight after the last epoch (2 to 5 Adam steps), likewise: at most 1.2e-6 measured.
const WEIGHT_TOL: f64 = 1e-5;

struct Case {
    json: Value,
    weights: Vec<u8>,
    path: PathBuf,
}

fn load(case: &str) -> Case {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden_acac");
    let json: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join(format!("{case}.json"))).unwrap())
            .unwrap();
    assert_eq!(json["format"], "acac-golden-1", "{case}: format");
    let path = dir.join(json["weights_file"].as_str().unwrap());
    let weights = std::fs::read(&path).unwrap();
    Case {
        json,
        weights,
        path,
    }
}

/// Every number of a nested list, row-major.
fn flat(v: &Value) -> Vec<f64> {
    match v {
        Value::Array(items) => items.iter().flat_map(flat).collect(),
        Value::Number(n) => vec![n.as_f64().unwrap()],
        Value::Bool(b) => vec![f64::from(u8::from(*b))],
        other => panic!("not a number: {other}"),
    }
}

fn usize_of(v: &Value) -> usize {
    v.as_u64().unwrap() as usize
}

fn list(v: &Value) -> &Vec<Value> {
    v.as_array().unwrap()
}

/// Fails naming the entry furthest from ACAC's (relative to max(|x|, 1)) if it exceeds `tol`.
fn assert_all_close(what: &str, ours: &[f64], theirs: &[f64], tol: f64) {
    assert_eq!(ours.len(), theirs.len(), "{what}: lengths");
    let err = |a: f64, b: f64| (a - b).abs() / a.abs().max(b.abs()).max(1.0);
    let worst = ours
        .iter()
        .zip(theirs)
        .enumerate()
        .max_by(|x, y| err(*x.1 .0, *x.1 .1).total_cmp(&err(*y.1 .0, *y.1 .1)));
    if let Some((k, (a, b))) = worst {
        if std::env::var_os("GOLDEN_ACAC_VERBOSE").is_some() {
            eprintln!("{what}: worst [{k}] relative error {:.2e}", err(*a, *b));
        }
        assert!(
            err(*a, *b) <= tol,
            "{what}[{k}]: ours {a}, ACAC's {b} (relative error {:.2e} > {tol:.0e})",
            err(*a, *b)
        );
    }
}

fn f64s(v: &[f32]) -> Vec<f64> {
    v.iter().map(|&x| f64::from(x)).collect()
}

/// Our recorded episodes from the batch ACAC's memory returned (`batch` in the README).
fn episodes(case: &Value) -> Vec<Episode> {
    let b = &case["batch"];
    let obs_sizes: Vec<usize> = list(&case["obs_size"]).iter().map(usize_of).collect();
    let n = obs_sizes.len();
    let lens: Vec<usize> = list(&b["epi_len"]).iter().map(usize_of).collect();
    lens.iter()
        .enumerate()
        .map(|(e, &steps)| {
            let mut obs = Vec::new();
            for t in 0..=steps {
                for i in 0..n {
                    let row = if t < steps {
                        &b["obs"][i][e][t]
                    } else {
                        &b["final_next_obs"][i][e]
                    };
                    obs.extend(flat(row).iter().map(|&x| x as f32));
                }
            }
            let per_agent = |field: &str| -> Vec<f64> {
                (0..steps).flat_map(|t| flat(&b[field][e][t])).collect()
            };
            let per_step = |field: &str| -> Vec<f64> {
                (0..steps)
                    .map(|t| b[field][e][t].as_f64().unwrap())
                    .collect()
            };
            Episode {
                n_agents: n,
                joint_obs_size: obs_sizes.iter().sum(),
                state_size: 0,
                steps,
                obs,
                state: Vec::new(),
                mac_start: per_agent("mac_start").iter().map(|&x| x != 0.0).collect(),
                action: per_agent("action").iter().map(|&x| x as u32).collect(),
                reward: per_agent("reward").iter().map(|&x| x as f32).collect(),
                joint_reward: per_step("joint_reward").iter().map(|&x| x as f32).collect(),
                terminate: per_step("terminate").iter().map(|&x| x != 0.0).collect(),
                valid: per_agent("mac_valid").iter().map(|&x| x != 0.0).collect(),
            }
        })
        .collect()
}

/// The nets as ACAC built them (`init/<net>/<state_dict name>`), with the case's optimizers.
fn nets(case: &Case) -> AcacNets {
    let sd = StateDict::parse(&case.weights, &case.path).unwrap();
    let s = &case.json["settings"];
    let n = list(&case.json["obs_size"]).len();
    let actors: Vec<AcacActor> = (0..n)
        .map(|i| AcacActor::from_state_dict(&sd, &format!("init/actor{i}/")).unwrap())
        .collect();
    let head = ValueHead::from_reference_name(s["value_head"].as_str().unwrap()).unwrap();
    let critic =
        AcacCritic::from_state_dict(&sd, "init/critic/", head, usize_of(&s["cc_n_head"])).unwrap();
    assert_eq!(critic.encoders.len(), n, "the critic's encoders");
    let time = s["time_emb"].as_bool().unwrap().then(|| {
        let table = TimeEmbedding::from_state_dict(&sd, "init/critic/time_embedding.").unwrap();
        // ACAC's table is the fixed sinusoid of env_terminate_step + 5 rows: ours must equal it.
        let ours = TimeEmbedding::sinusoidal(
            usize_of(&s["env_terminate_step"]),
            usize_of(&s["time_emb_dim"]),
        )
        .unwrap();
        let (a, b) = (&ours.named("")[0].1, &table.named("")[0].1);
        assert_eq!(a.shape(), b.shape(), "time table shape");
        for (x, y) in a.iter().zip(b.iter()) {
            assert!((x - y).abs() <= 1e-6, "time table: ours {x}, ACAC's {y}");
        }
        table
    });
    assert!(sd.has(&format!("init/actor0/{TIME_TABLE}")) == time.is_some());
    AcacNets::new(
        actors,
        critic,
        time,
        s["a_lr"].as_f64().unwrap(),
        s["c_lr"].as_f64().unwrap(),
    )
}

/// One recorded dropout mask: `bits` (1 = kept, 4 per hex digit, most significant first) as
/// multipliers 1 / (1 - p) or 0, [rows, cols].
fn mask(m: &Value, rows: usize, cols: usize) -> Array2<f32> {
    let p = m["p"].as_f64().unwrap() as f32;
    let keep = 1.0 / (1.0 - p);
    let hex = m["bits"].as_str().unwrap().as_bytes();
    let total: usize = list(&m["shape"]).iter().map(usize_of).product();
    assert_eq!(total, rows * cols, "mask {} size", m["module"]);
    let bit = |k: usize| {
        let d = (hex[k / 4] as char).to_digit(16).unwrap();
        (d >> (3 - k % 4)) & 1 == 1
    };
    Array2::from_shape_fn(
        (rows, cols),
        |(r, c)| {
            if bit(r * cols + c) {
                keep
            } else {
                0.0
            }
        },
    )
}

/// Every critic forward's masks in ACAC's order, in our layout: rows b n + i; the attention's
/// [N, n_head, n, n] as (b n + i, h n + j).
fn dropout(case: &Value) -> Vec<Gpt2Dropout> {
    list(&case["dropout"])
        .iter()
        .map(|call| {
            let masks = list(&call["masks"]);
            let module = |suffix: &str| -> &Value {
                masks
                    .iter()
                    .find(|m| m["module"].as_str().unwrap().ends_with(suffix))
                    .unwrap_or_else(|| panic!("{}: no {suffix} mask", call["call"]))
            };
            let drop = module("transformer.drop");
            let shape: Vec<usize> = list(&drop["shape"]).iter().map(usize_of).collect();
            let [rows, n, d] = shape[..] else {
                panic!("drop mask shape {shape:?}")
            };
            let attn = module("attn.attn_dropout");
            let n_head = usize_of(&attn["shape"][1]);
            let raw = mask(attn, rows * n_head * n, n);
            // (b, h, i, j) -> (b n + i, h n + j)
            let attn = Array2::from_shape_fn((rows * n, n_head * n), |(r, c)| {
                let (b, i, h, j) = (r / n, r % n, c / n, c % n);
                raw[[(b * n_head + h) * n + i, j]]
            });
            Gpt2Dropout {
                embd: mask(drop, rows * n, d),
                blocks: vec![BlockDropout {
                    attn,
                    resid: mask(module("attn.resid_dropout"), rows * n, d),
                    mlp: mask(module("mlp.dropout"), rows * n, d),
                }],
            }
        })
        .collect()
}

/// The case's settings; `vanilla` takes acac-vanilla's objective from them, else PPO with
/// `gae_lambda`.
fn params(case: &Value, vanilla: bool, gae_lambda: GaeLambda) -> UpdateParams {
    let s = &case["settings"];
    let f = |k: &str| s[k].as_f64().unwrap();
    let objective = if vanilla {
        Objective::Vanilla {
            n_step: usize_of(&s["n_step_TD"]),
            critic_iterations: usize_of(&s["c_train_iteration"]),
            entropy_weight: case["etrpy_w"].as_f64().unwrap(),
        }
    } else {
        Objective::Ppo(gae_lambda)
    };
    UpdateParams {
        gamma: f("gamma"),
        lambda: f("GAE_lambda"),
        objective,
        clip_ratio: f("clip_ratio"),
        n_train_repeat: usize_of(&s["n_train_repeat"]),
        eps: case["eps"].as_f64().unwrap(),
        grad_clip_value: f("grad_clip_value"),
        grad_clip_norm: f("grad_clip_norm"),
        duplicate: s["duplicate"].as_bool().unwrap(),
    }
}

/// The first `lens[e]` entries of each episode's rows of a [e][K][1] (or [e][J][1]) tensor.
fn valid_rows(v: &Value, lens: &[usize]) -> Vec<f64> {
    lens.iter()
        .enumerate()
        .flat_map(|(e, &l)| (0..l).flat_map(move |k| flat(&v[e][k])))
        .collect()
}

fn compare_weights(what: &str, ours: Vec<(String, ArrayViewD<'_, f32>)>, sd: &StateDict) {
    for (name, ours) in ours {
        let shape = sd.shape(&name).unwrap_or_else(|e| panic!("{what}: {e}"));
        let theirs = sd.values(&name, &shape).unwrap();
        // `wpe.weight` after an epoch holds only the agents' rows (the rest never change).
        let ours: Vec<f32> = ours.iter().copied().take(theirs.len()).collect();
        assert_all_close(&name, &f64s(&ours), &f64s(&theirs), WEIGHT_TOL);
    }
}

fn replay(case_name: &str, gae_lambda: GaeLambda) {
    let case = load(case_name);
    let j = &case.json;
    let vanilla = j["alg"] == "acac_vanilla";
    let (reward_key, terminal_key) = if vanilla {
        ("reward", "terminate")
    } else {
        ("jr", "j_terminate")
    };
    let obs_sizes: Vec<usize> = list(&j["obs_size"]).iter().map(usize_of).collect();
    let n = obs_sizes.len();

    // The squeeze.
    let eps = episodes(j);
    let batch = AcacBatch {
        episodes: eps
            .iter()
            .enumerate()
            .map(|(k, e)| SqueezedEpisode::from_episode(e, k, &obs_sizes).unwrap())
            .collect(),
    };
    let sq = &j["squeezed"];
    let joint: Vec<usize> = list(&sq["cen_epi_len"]).iter().map(usize_of).collect();
    assert_eq!(
        batch
            .episodes
            .iter()
            .map(|e| e.joint_steps)
            .collect::<Vec<_>>(),
        joint,
        "joint macro-steps per episode"
    );
    let rewards: Vec<f64> = batch
        .episodes
        .iter()
        .flat_map(|e| f64s(&e.rewards))
        .collect();
    assert_all_close(
        reward_key,
        &rewards,
        &valid_rows(&sq[reward_key], &joint),
        1e-6,
    );
    for (e, ep) in batch.episodes.iter().enumerate() {
        let last = joint[e] - 1;
        let terminal = sq[terminal_key][e][last][0].as_f64().unwrap() != 0.0;
        assert_eq!(ep.terminated, terminal, "episode {e}: terminal");
    }
    for i in 0..n {
        let a = &sq["agents"][i];
        let lens: Vec<usize> = list(&a["epi_len"]).iter().map(usize_of).collect();
        let ours: Vec<usize> = batch
            .episodes
            .iter()
            .map(|e| e.agents[i].actions.len())
            .collect();
        assert_eq!(ours, lens, "agent {i}: macro-actions per episode");
        let actions: Vec<f64> = batch
            .episodes
            .iter()
            .flat_map(|e| e.agents[i].actions.iter().map(|&x| x as f64))
            .collect();
        assert_eq!(
            actions,
            valid_rows(&a["action"], &lens),
            "agent {i}: actions"
        );
    }

    // The update.
    let mut nets = nets(&case);
    let masks = dropout(j);
    let p = params(j, vanilla, gae_lambda);
    let trace = update(
        &mut nets,
        &batch,
        &p,
        DropoutSource::Replay(masks.iter()),
        &mut Tape::new(),
    )
    .unwrap();
    if vanilla {
        check_vanilla(j, &trace, &joint);
    } else {
        check_ppo(j, &trace, &joint);
    }
    let epochs = list(&j["epochs"]);
    assert_eq!(trace.critic_losses.len(), epochs.len(), "epochs");
    for (k, epoch) in epochs.iter().enumerate() {
        let mb = &epoch["minibatches"][0];
        assert_all_close(
            &format!("epoch {k}: critic loss"),
            &[f64::from(trace.critic_losses[k])],
            &[mb["critic"]["loss"].as_f64().unwrap()],
            VALUE_TOL,
        );
        let ours: Vec<f64> = trace.actors[k].iter().map(|a| f64::from(a.loss)).collect();
        let theirs: Vec<f64> = list(&mb["actors"])
            .iter()
            .map(|a| a["loss"].as_f64().unwrap())
            .collect();
        assert_all_close(
            &format!("epoch {k}: actor losses"),
            &ours,
            &theirs,
            VALUE_TOL,
        );
    }

    // Every weight after the last epoch (PopArt's statistics included).
    let sd = StateDict::parse(&case.weights, &case.path).unwrap();
    let last = format!(
        "{}/",
        epochs.last().unwrap()["minibatches"][0]["weights_after"]
            .as_str()
            .unwrap()
    );
    for (i, actor) in nets.actors.iter().enumerate() {
        compare_weights(
            &format!("actor {i}"),
            actor.named(&format!("{last}actor{i}/")),
            &sd,
        );
    }
    compare_weights("critic", nets.critic.named(&format!("{last}critic/")), &sd);
}

/// Each agent's macro-actions per episode.
fn agent_lens(j: &Value, i: usize) -> Vec<usize> {
    list(&j["squeezed"]["agents"][i]["epi_len"])
        .iter()
        .map(usize_of)
        .collect()
}

/// acac and acac-micro-gae: GAE, PopArt's targets, log pi_old.
fn check_ppo(j: &Value, trace: &UpdateTrace, joint: &[usize]) {
    let gae = &j["gae"];
    assert_all_close(
        "advantage",
        &f64s(&trace.advantages),
        &valid_rows(&gae["advantage"], joint),
        VALUE_TOL,
    );
    assert_all_close(
        "returns_raw",
        &f64s(&trace.returns),
        &valid_rows(&gae["returns_raw"], joint),
        VALUE_TOL,
    );
    assert_all_close(
        "returns (PopArt-normalized)",
        &f64s(&trace.targets),
        &valid_rows(&gae["returns"], joint),
        VALUE_TOL,
    );
    for i in 0..trace.old_log_pi.len() {
        let lens = agent_lens(j, i);
        assert_all_close(
            &format!("old_log_pi[{i}]"),
            &f64s(&trace.old_log_pi[i]),
            &valid_rows(&j["old_log_pi"][i], &lens),
            VALUE_TOL,
        );
    }
}

/// acac-vanilla: n-step returns, advantages from the updated critic, the actors' entropies.
fn check_vanilla(j: &Value, trace: &UpdateTrace, joint: &[usize]) {
    let mb = &j["epochs"][0]["minibatches"][0];
    let returns = valid_rows(&j["returns"]["returns"], joint);
    assert_all_close("n-step returns", &f64s(&trace.returns), &returns, VALUE_TOL);
    let after = valid_rows(&mb["values_for_advantage"], joint);
    let adv: Vec<f64> = returns.iter().zip(&after).map(|(g, v)| g - v).collect();
    assert_all_close(
        "advantages G - V",
        &f64s(&trace.advantages),
        &adv,
        VALUE_TOL,
    );
    for a in &trace.actors[0] {
        let lens = agent_lens(j, a.agent);
        assert_all_close(
            &format!("agent {}: entropies", a.agent),
            &f64s(&a.entropies),
            &valid_rows(&mb["actors"][a.agent]["pi_entropy"], &lens),
            VALUE_TOL,
        );
    }
    assert!(trace.old_log_pi.iter().all(Vec::is_empty));
}

#[test]
fn acac_on_box_pushing_6x6_matches_acacs_learner() {
    replay("acac_bp6", GaeLambda::PerMacroStep);
}

#[test]
fn acac_on_overcooked_a_matches_acacs_learner() {
    replay("acac_ovcA7", GaeLambda::PerMacroStep);
}

#[test]
fn acac_micro_gae_on_box_pushing_6x6_matches_acacs_learner() {
    replay("acac_micro_gae_bp6", GaeLambda::PerPrimitiveStep);
}

#[test]
fn acac_micro_gae_on_overcooked_a_matches_acacs_learner() {
    replay("acac_micro_gae_ovcA7", GaeLambda::PerPrimitiveStep);
}

#[test]
#[should_panic(expected = "advantage")]
fn the_goldens_tell_macro_step_lambda_from_lambda_per_primitive_step() {
    // acac's case replayed with acac-micro-gae's lambda^duration: the advantages must differ
    // (guards against goldens too loose or too uniform to separate the two methods).
    replay("acac_bp6", GaeLambda::PerPrimitiveStep);
}

#[test]
fn acac_vanilla_on_box_pushing_6x6_matches_acacs_learner() {
    // The GAE variant is not read: acac-vanilla takes n-step returns.
    replay("acac_vanilla_bp6", GaeLambda::PerMacroStep);
}

#[test]
fn acac_vanilla_on_overcooked_a_matches_acacs_learner() {
    replay("acac_vanilla_ovcA7", GaeLambda::PerMacroStep);
}

/// Our copy of the case's environment, as `experiments/acac/<env>.toml` sets it up.
fn env_spec(case: &Value) -> EnvSpec {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("experiments/acac")
        .join(format!("{}.toml", case["env"].as_str().unwrap()));
    let experiment = Experiment::load(&path, &Overrides::default()).unwrap();
    experiment.runs().unwrap()[0].env.clone()
}

/// Floats of a record to f32 precision (ACAC's runner makes float32 tensors of float64 sums).
fn assert_floats(what: &str, ours: &[f32], theirs: &[f32]) {
    assert_eq!(ours.len(), theirs.len(), "{what}: lengths");
    for (k, (a, b)) in ours.iter().zip(theirs).enumerate() {
        let tol = 1e-6 * a.abs().max(b.abs()).max(1.0);
        assert!((a - b).abs() <= tol, "{what}[{k}]: ours {a}, ACAC's {b}");
    }
}

/// The batch ACAC's runner recorded (its workers' accumulators, `envs_runner.py`): our
/// environment stepped with the same macro-actions and our lanes' [`EpisodeRecorder`] must
/// record the same episodes, record for record: observations (the first record's included),
/// macro-action starts, executed macro-actions, macro-rewards discounted inside the
/// macro-action, joint rewards, terminal flags (bp6's episodes end at a goal, ovcA7's at the
/// horizon, not terminal) and the agents' macro-action ends. The learner goldens above start
/// from ACAC's records; this closes the gap between the environment and them.
fn recorder_records_the_batch(case_name: &str) {
    let case = load(case_name);
    let j = &case.json;
    let spec = env_spec(j);
    let gamma = j["settings"]["gamma"].as_f64().unwrap();
    for (e, want) in episodes(j).iter().enumerate() {
        let n = want.n_agents;
        let mut rng = EnvRng::seed_from_u64(0);
        let mut env = spec.build().unwrap();
        env.reset(&mut rng);
        let mut rec = EpisodeRecorder::new(&env, gamma, false);
        for t in 0..want.steps {
            let actions: Vec<usize> = (0..n).map(|i| want.action(t, i)).collect();
            let outcome = env.step(&actions, &mut rng).unwrap();
            rec.record(&env, outcome);
            assert_eq!(
                outcome.done,
                t + 1 == want.steps,
                "{case_name} episode {e}: our episode ended at step {t}, ACAC's after {}",
                want.steps
            );
        }
        let ours = rec.episode();
        let at = |what: &str| format!("{case_name} episode {e}: {what}");
        assert_eq!(ours.steps, want.steps, "{}", at("steps"));
        assert_eq!(ours.action, want.action, "{}", at("executed macro-actions"));
        assert_eq!(
            ours.mac_start,
            want.mac_start,
            "{}",
            at("macro-action starts")
        );
        assert_eq!(ours.valid, want.valid, "{}", at("macro-action ends"));
        assert_eq!(ours.terminate, want.terminate, "{}", at("terminal flags"));
        assert_floats(&at("observations"), &ours.obs, &want.obs);
        assert_floats(&at("macro-rewards"), &ours.reward, &want.reward);
        assert_floats(&at("joint rewards"), &ours.joint_reward, &want.joint_reward);
    }
}

#[test]
fn our_recorder_records_acacs_box_pushing_batch() {
    recorder_records_the_batch("acac_bp6");
}

#[test]
fn our_recorder_records_acacs_overcooked_batch() {
    recorder_records_the_batch("acac_ovcA7");
}
