//! Every shipped experiment config parses, and the paper figures carry the paper's settings.

use macdec::algos::actor_critic::method::AcMethod;
use macdec::algos::families::Method;
use macdec::algos::mac_value::method::MacValueMethod;
use macdec::algos::value::method::ValueMethod;
use macdec::experiment::definition::config::{Experiment, Overrides};
use std::path::Path;

fn load(name: &str) -> Experiment {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("experiments")
        .join(name);
    Experiment::load(&path, &Overrides::default()).unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn every_shipped_config_parses_and_resolves() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments");
    let mut n = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let e = Experiment::load(&path, &Overrides::default())
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            assert!(!e.runs().unwrap().is_empty());
            n += 1;
        }
    }
    assert!(
        n >= 7,
        "expected the four figures and three ablations, found {n}"
    );
}

#[test]
fn macromarls_blocks_have_twenty_seeds_and_the_published_methods_and_settings() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/macromarl");
    let mut names = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let e = Experiment::load(&path, &Overrides::default())
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!(e.seeds, (0..20).collect::<Vec<u64>>(), "{}", e.name);
        // Box Pushing's published Naive Mac-IACC and Mac-IAICC runs use the state critics.
        let critics = if e.name.starts_with("bp") {
            [
                Method::ActorCritic(AcMethod::NaiveMacIasc),
                Method::ActorCritic(AcMethod::MacIaisc),
            ]
        } else {
            [
                Method::ActorCritic(AcMethod::NaiveMacIacc),
                Method::ActorCritic(AcMethod::MacIaicc),
            ]
        };
        assert_eq!(
            e.methods,
            [
                Method::ActorCritic(AcMethod::MacIac),
                Method::ActorCritic(AcMethod::MacCac),
                critics[0],
                critics[1]
            ],
            "{}",
            e.name
        );
        for run in e.runs().unwrap().iter().filter(|r| r.seed == 0) {
            let c = run.config.of::<AcMethod>().expect("an actor-critic config");
            // Every published block differs from the argparse defaults in its learning rates.
            assert_ne!((c.a_lr, c.c_lr), (1e-4, 1e-3), "{} {}", e.name, run.method);
            assert!(c.train_freq >= c.n_env, "{} {}", e.name, run.method);
        }
        names.push(e.name);
    }
    names.sort();
    assert_eq!(
        names,
        [
            "bp10",
            "bp12",
            "bp14",
            "bp6",
            "bp8",
            "overcooked_a",
            "overcooked_b",
            "overcooked_c",
            "wh_a",
            "wh_ablation",
            "wh_b",
            "wh_c",
            "wh_d",
            "wh_e"
        ]
    );
    // Spot checks against `docs/MACROMARL.md` §1.4.
    let bp12 = load("macromarl/bp12.toml").runs().unwrap();
    let iac = bp12[0].config.of::<AcMethod>().unwrap();
    assert_eq!(
        (iac.n_env, iac.train_freq, iac.c_target_update_freq),
        (8, 16, 128)
    );
    let wh_b = load("macromarl/wh_b.toml").runs().unwrap();
    let cac = wh_b
        .iter()
        .find(|r| r.method == Method::ActorCritic(AcMethod::MacCac))
        .unwrap()
        .config
        .of::<AcMethod>()
        .unwrap();
    assert_eq!((cac.a_rnn_layer_size, cac.c_target_update_freq), (64, 16));
    let ablation = load("macromarl/wh_ablation.toml").runs().unwrap();
    let iac = ablation[0].config.of::<AcMethod>().unwrap();
    assert_eq!((iac.n_env, iac.c_lr), (16, 5e-4));
}

#[test]
fn paper_figures_have_forty_seeds_and_their_methods() {
    for (file, methods) in [
        (
            "fig4a_bp10.toml",
            [
                Method::Value(ValueMethod::DecHddrqn),
                Method::Value(ValueMethod::CenDdrqn),
                Method::Value(ValueMethod::Our1),
            ],
        ),
        (
            "fig4b_bp30.toml",
            [
                Method::Value(ValueMethod::DecHddrqn),
                Method::Value(ValueMethod::CenDdrqn),
                Method::Value(ValueMethod::Our1),
            ],
        ),
        (
            "fig5_wtd.toml",
            [
                Method::Value(ValueMethod::DecHddrqn),
                Method::Value(ValueMethod::CenDdrqn),
                Method::Value(ValueMethod::Our2),
            ],
        ),
        (
            "fig6_wtd_ablation.toml",
            [
                Method::Value(ValueMethod::Our1),
                Method::Value(ValueMethod::Our1R),
                Method::Value(ValueMethod::Our2),
            ],
        ),
    ] {
        let e = load(file);
        assert_eq!(e.seeds, (0..40).collect::<Vec<u64>>(), "{file}");
        assert_eq!(e.methods, methods, "{file}");
    }
}

#[test]
fn bp30_uses_longer_windows_and_horizon() {
    let runs = load("fig4b_bp30.toml").runs().unwrap();
    let c = runs[0].config.of::<ValueMethod>().expect("a value method");
    assert_eq!(runs[0].env, macdec::envs::box_pushing::spec(30, 200));
    assert_eq!((c.trace_len, c.train_freq), (45, 45));
}

#[test]
fn sweeps_expand_into_variants() {
    let e = load("ablation_bp10_lr_hidden.toml");
    let runs = e.runs().unwrap();
    assert_eq!(runs.len(), 2 * 9 * 10);
    let mut curves: Vec<String> = runs.iter().map(|r| r.curve_name()).collect();
    curves.dedup();
    assert_eq!(curves.len(), 18);
}

#[test]
fn figure_6_shares_figure_5s_our2_runs_with_identical_configs() {
    let fig5 = load("fig5_wtd.toml").runs().unwrap();
    let fig6 = load("fig6_wtd_ablation.toml").runs().unwrap();
    let our2 = |runs: &[macdec::experiment::definition::config::RunSpec]| -> Vec<_> {
        runs.iter()
            .filter(|r| r.method == Method::Value(ValueMethod::Our2))
            .cloned()
            .collect()
    };
    let (a, b) = (our2(&fig5), our2(&fig6));
    assert_eq!(a.len(), 40);
    // Same experiment name, seeds, configs and so directories: one set of runs serves both.
    assert_eq!(a, b);
    assert!(b.iter().all(|r| r.experiment == "fig5_wtd"));
    assert_eq!(
        b[3].dir(Path::new("reproduction")),
        Path::new("reproduction/fig5_wtd/our2/seed-3")
    );
    // Figure 6's own curves stay its own.
    assert!(fig6
        .iter()
        .filter(|r| r.method != Method::Value(ValueMethod::Our2))
        .all(|r| r.experiment == "fig6_wtd_ablation"));
}

#[test]
fn a_shared_curve_must_name_a_method_and_a_plain_experiment() {
    let parse =
        |text: &str| Experiment::parse(text, Path::new("t.toml"), "t", &Overrides::default());
    let err = parse("methods = [\"our1\"]\nshared_curves = { our2 = \"fig5_wtd\" }")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("shared_curves.our2") && err.contains("not one of"),
        "{err}"
    );
    let err = parse("methods = [\"our1\"]\nshared_curves = { our1 = \"../x\" }")
        .unwrap_err()
        .to_string();
    assert!(err.contains("expected an experiment name"), "{err}");
}

#[test]
fn macromarl_value_blocks_have_twenty_seeds_both_methods_and_their_scripts_rows() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments/macromarl_value");
    let mut names = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let e = Experiment::load(&path, &Overrides::default())
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!(e.seeds, (0..20).collect::<Vec<u64>>(), "{}", e.name);
        assert_eq!(
            e.methods,
            [
                Method::MacValue(MacValueMethod::MacDecQ),
                Method::MacValue(MacValueMethod::MacCenQ)
            ],
            "{}",
            e.name
        );
        for run in e.runs().unwrap().iter().filter(|r| r.seed == 0) {
            let c = run
                .config
                .of::<MacValueMethod>()
                .expect("a value-based config");
            // Every published block decays epsilon to 0.05 and moves off the argparse lr.
            assert_eq!(c.eps_end, 0.05, "{} {}", e.name, run.method);
            assert_ne!(c.l_rate, 0.0006, "{} {}", e.name, run.method);
            assert_eq!(c.h_stable_at, c.eps_l_d_steps, "{} {}", e.name, run.method);
        }
        names.push(e.name);
    }
    names.sort();
    assert_eq!(
        names,
        [
            "bp10",
            "bp12",
            "bp20",
            "bp30",
            "bp8",
            "overcooked_a",
            "overcooked_b",
            "wh_a",
            "wh_b",
            "wh_c"
        ]
    );
    // Spot checks against docs/MACROMARL.md 8.3.
    let of = |file: &str, m: MacValueMethod| {
        load(file)
            .runs()
            .unwrap()
            .into_iter()
            .find(|r| r.method == Method::MacValue(m))
            .unwrap()
            .config
            .of::<MacValueMethod>()
            .unwrap()
            .clone()
    };
    let dec = of("macromarl_value/bp30.toml", MacValueMethod::MacDecQ);
    assert_eq!((dec.l_rate, dec.trace_len, dec.batch_size), (5e-4, 45, 32));
    assert_eq!((dec.init_h, dec.end_h, dec.sample_epi), (0.2, 0.4, false));
    let cen = of("macromarl_value/bp10.toml", MacValueMethod::MacCenQ);
    assert_eq!((cen.batch_size, cen.rnn_h_size, cen.init_h), (128, 64, 1.0));
    let cen = of("macromarl_value/wh_c.toml", MacValueMethod::MacCenQ);
    assert_eq!(
        (cen.train_freq, cen.init_h, cen.total_epi),
        (64, 0.2, 80_000)
    );
    let cen = of("macromarl_value/wh_b.toml", MacValueMethod::MacCenQ);
    assert_eq!((cen.l_rate, cen.init_h), (1e-4, 1.0));
    let dec = of("macromarl_value/wh_b.toml", MacValueMethod::MacDecQ);
    assert_eq!(
        (dec.l_rate, dec.sample_epi, dec.replay_buffer_size),
        (5e-5, true, 2000)
    );
    let cen = of("macromarl_value/overcooked_b.toml", MacValueMethod::MacCenQ);
    assert_eq!(
        (cen.start_train, cen.mlp_layer_size.clone(), cen.h_explore),
        (500, vec![128, 64], true)
    );
    let dec = of("macromarl_value/overcooked_a.toml", MacValueMethod::MacDecQ);
    assert_eq!(
        (dec.l_rate, dec.init_h, dec.total_epi),
        (5e-4, 1.0, 100_000)
    );
}

/// A TOML value and a JSON value as the same number, string, boolean or list.
fn same_value(t: &toml::Value, j: &serde_json::Value) -> bool {
    match (t, j) {
        (toml::Value::Array(a), serde_json::Value::Array(b)) => {
            a.len() == b.len() && a.iter().zip(b).all(|(x, y)| same_value(x, y))
        }
        (toml::Value::String(a), serde_json::Value::String(b)) => a == b,
        (toml::Value::Boolean(a), serde_json::Value::Bool(b)) => a == b,
        (toml::Value::Integer(a), _) => j.as_f64() == Some(*a as f64),
        (toml::Value::Float(a), _) => j.as_f64() == Some(*a),
        _ => false,
    }
}

#[test]
fn acacs_fifteen_settings_resolve_to_what_its_runner_uses() {
    use macdec::algos::acac::config::{
        acac_env_name, merged_params, ENV_KEYS, ENV_NAMES, RUNNER_KEYS,
    };
    use macdec::algos::acac::method::AcacMethod;
    for name in ENV_NAMES {
        let e = load(&format!("acac/{name}.toml"));
        assert_eq!(
            e.seeds,
            (0..5).collect::<Vec<u64>>(),
            "{name}: ACAC's seeds 0-4"
        );
        let large = name.ends_with("_N6");
        assert_eq!(e.methods.len(), if large { 1 } else { 3 }, "{name}");
        for run in e.runs().unwrap().iter().filter(|r| r.seed == 0) {
            let Method::Acac(method) = run.method else {
                panic!("{name}: {} is not an ACAC method", run.method)
            };
            // The family finds ACAC's env file from the domain's keys alone.
            assert_eq!(acac_env_name(&run.env).as_deref(), Some(name));
            let ours = serde_json::to_value(run.config.of::<AcacMethod>().unwrap()).unwrap();
            let keys = run.env.keys();
            for (key, want) in merged_params(method, Some(name)) {
                let what = format!("{name} {method:?} `{key}`");
                if key == "env_id" {
                    let domain = macdec::envs::acac::domain_of(want.as_str().unwrap());
                    assert_eq!(domain, Some(run.env.env_name()), "{what}");
                } else if key == "step_penalty" && !name.starts_with("bp") {
                    let got = &keys["rewardList"]["step penalty"];
                    assert!(same_value(got, &want), "{what}: {got} vs {want}");
                } else if ENV_KEYS.contains(&key.as_str()) {
                    // Keys another domain's builder takes (map_type of Box Pushing, ...) are
                    // passed by ACAC's runner and unread by the env: only the domain's own count.
                    // ACAC's `task` 6 is the full salad, our Overcooked default.
                    if let Some(got) = keys.get(&key).filter(|_| key != "task") {
                        assert!(same_value(got, &want), "{what}: {got} vs {want}");
                    }
                } else if RUNNER_KEYS.contains(&key.as_str()) {
                    // Only ACAC's Python runner reads these (seed, device, ...).
                } else {
                    let got = ours
                        .get(&key)
                        .unwrap_or_else(|| panic!("{what}: not in ours"));
                    let equal = match (got.as_f64(), want.as_f64()) {
                        (Some(a), Some(b)) => a == b,
                        _ => *got == want,
                    };
                    assert!(equal, "{what}: ours {got}, ACAC's {want}");
                }
            }
        }
    }
}
