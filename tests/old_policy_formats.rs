//! Policy directories written before the one policy-file format (format_version 1) still load,
//! converted on read: a run's `policy/` (`"macdec-run-policy"` policy.json) and exports
//! (`manifest.json`, built-in and custom domain). The fixtures in
//! `tests/fixtures/old_policy_formats/` were written by the code of that format (Box Pushing 8x8,
//! Q-nets with M = H = 2); `expected_q.json` holds each net's Q-values for three fixed
//! observations from a zero state, computed by that build.

use macdec::deploy::policy::export::export_run;
use macdec::deploy::policy::net_policy::load_net;
use macdec::nn::{ActingNet, QNet};
use macdec::policy_files::{
    load_all, read_nets, read_policy_files, Manifest, NetKind, NetRole, PolicyEnv, FORMAT_VERSION,
    POLICY_FILE,
};
use std::path::{Path, PathBuf};

mod common;

use common::{ok, run};

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/old_policy_formats")
}

/// Q-values after each observation t: `trace[t][action]`.
type Trace = Vec<Vec<f32>>;

/// expected_q.json: each agent's net's trace and the centralized net's.
#[derive(serde::Deserialize)]
struct Expected {
    dec: Vec<Trace>,
    cen: Trace,
}

fn expected() -> Expected {
    let text = std::fs::read_to_string(fixtures().join("expected_q.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// The net's Q-values for observations `obs_t[i] = ((i + 2 t) % 3) * 0.5`, t = 0, 1, 2, from a
/// zero state (the observations the fixtures' Q-values were computed for).
fn q_trace(net: &QNet) -> Trace {
    let n_in = net.config().input;
    let mut state = net.zero_state();
    (0..3)
        .map(|t| {
            let obs: Vec<f32> = (0..n_in).map(|i| ((i + 2 * t) % 3) as f32 * 0.5).collect();
            net.act_step(&obs, &mut state).to_vec()
        })
        .collect()
}

/// The Q-nets of a version-1 policy (every net of that version is one).
fn q_nets(nets: &[ActingNet]) -> Vec<QNet> {
    nets.iter().map(|n| n.as_q().unwrap().clone()).collect()
}

#[test]
fn a_version_1_run_policy_dir_loads_with_its_nets_and_layout() {
    let policy = read_policy_files(&fixtures().join("run")).unwrap();
    let m = &policy.manifest;
    assert_eq!(m.format_version, FORMAT_VERSION);
    assert_eq!(
        (m.run.method.as_str(), m.run.seed, m.run.episodes_trained),
        ("our1", 11, 40)
    );
    assert_eq!(m.evaluated, NetRole::Dec);
    assert_eq!(m.discount, 0.98);
    assert_eq!(m.agents.len(), 2);
    assert_eq!((m.agents[1].obs_size, m.agents[1].n_actions), (5, 8));
    assert_eq!(m.agents[0].action_names.len(), 8);
    assert!(m.nets.iter().all(|n| n.kind == NetKind::Q));
    assert_eq!(m.nets[2].file, "cen.safetensors");
    assert_eq!((m.nets[2].input, m.nets[2].output), (10, 64));

    let want = expected();
    let dec = q_nets(&policy.agents);
    assert_eq!(dec.len(), 2);
    for (agent, net) in dec.iter().enumerate() {
        assert_eq!(q_trace(net), want.dec[agent], "agent {agent}");
    }
    let cen = policy.team.as_ref().and_then(|n| n.as_q()).unwrap();
    assert_eq!(q_trace(cen), want.cen);
}

#[test]
fn version_1_exports_load_for_robots_with_the_same_nets() {
    let run_nets = q_nets(&read_policy_files(&fixtures().join("run")).unwrap().agents);
    let want = expected();
    for (dir, env_name, discount) in [
        ("export", "box-pushing", 0.98),
        ("export-custom", "corridor", 0.95),
    ] {
        let dir = fixtures().join(dir);
        let (manifest, verified) = load_all(&dir).unwrap();
        assert_eq!(manifest.format_version, FORMAT_VERSION);
        assert_eq!(
            (manifest.env.name(), manifest.discount),
            (env_name, discount)
        );
        assert_eq!(manifest.env.horizon(), 20);
        assert_eq!(manifest.evaluated, NetRole::Dec);
        assert_eq!(manifest.nets[1].file, "agent-1.safetensors");
        assert_eq!(manifest.agents[0].obs_names.len(), 5);
        for v in &verified {
            let net = load_net(&manifest, v).unwrap().as_q().unwrap().clone();
            assert_eq!(
                net,
                run_nets[v.index],
                "{}: agent {}",
                dir.display(),
                v.index
            );
            assert_eq!(q_trace(&net), want.dec[v.index]);
        }
        assert_eq!(q_nets(&read_nets(&dir).unwrap().agents), run_nets);
    }
    let custom = Manifest::read(&fixtures().join("export-custom")).unwrap();
    assert!(matches!(custom.env, PolicyEnv::Custom(_)));

    // A run's policy/ is a policy directory of the same format: robots can load it directly.
    let run_policy = fixtures().join("run/policy");
    let (manifest, verified) = load_all(&run_policy).unwrap();
    for v in &verified {
        assert_eq!(
            load_net(&manifest, v).unwrap().as_q(),
            Some(&run_nets[v.index])
        );
    }
}

#[test]
fn a_version_1_run_exports_to_the_current_format_and_evaluates() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("export");
    let written = export_run(&fixtures().join("run"), &out).unwrap();
    let text = std::fs::read_to_string(out.join(POLICY_FILE)).unwrap();
    assert!(text.contains("\"format_version\": 2"), "{text}");
    assert_eq!(Manifest::read(&out).unwrap(), written);
    assert_eq!(written.nets.len(), 2, "only the decentralized nets");
    let run_nets = q_nets(&read_policy_files(&fixtures().join("run")).unwrap().agents);
    assert_eq!(q_nets(&read_nets(&out).unwrap().agents), run_nets);

    // The commands read old exports as they read new ones, and give the same episodes.
    let episodes = |policy: &Path| {
        let p = policy.to_str().unwrap();
        ok(&run(&[
            "eval",
            "--policy",
            p,
            "--episodes",
            "2",
            "--seed",
            "3",
        ]))
    };
    assert_eq!(episodes(&fixtures().join("export")), episodes(&out));
}
