//! `macdec import --reference acac` as a process (issue 41 item 2): ACAC's own actor
//! state_dicts, as its code builds them (the initial actors recorded by
//! `scripts/acac_golden_from_reference.py` in `tests/golden_acac/acac_bp6.safetensors`, ACAC's
//! names and its `time_embedding.weight` included), import into a policy directory that keeps
//! the time table; `eval` runs them exactly as `deploy` does on robot processes (which get each
//! observation's primitive step); bad files and ids are refused by name, writing nothing.

mod common;

use common::{run, stdout_lines};
use macdec::nn::safetensors_io::named_to_safetensors_bytes;
use macdec::nn::{ActingNet, StateDict, TimedAcacActor, TIME_TABLE};
use macdec::policy_files::architecture::ACAC_ACTOR;
use macdec::policy_files::read_nets;
use ndarray::{ArrayD, IxDyn};
use std::path::{Path, PathBuf};

const GOLDEN: &str = "tests/golden_acac/acac_bp6.safetensors";

/// Agent `agent`'s initial actor from ACAC's own code: every tensor under `init/actor<i>/`,
/// under its own name.
fn acac_actor_tensors(agent: usize) -> Vec<(String, ArrayD<f32>)> {
    let bytes = std::fs::read(GOLDEN).unwrap();
    let st = safetensors::SafeTensors::deserialize(&bytes).unwrap();
    let prefix = format!("init/actor{agent}/");
    let mut out: Vec<(String, ArrayD<f32>)> = st
        .names()
        .into_iter()
        .filter_map(|n| n.strip_prefix(&prefix).map(|s| (n.clone(), s.to_string())))
        .map(|(full, name)| {
            let t = st.tensor(&full).unwrap();
            let values: Vec<f32> = t
                .data()
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect();
            (
                name,
                ArrayD::from_shape_vec(IxDyn(t.shape()), values).unwrap(),
            )
        })
        .collect();
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

fn write(path: &Path, tensors: &[(String, ArrayD<f32>)]) -> PathBuf {
    let views: Vec<_> = tensors.iter().map(|(n, a)| (n.clone(), a.view())).collect();
    std::fs::write(path, named_to_safetensors_bytes(&views)).unwrap();
    path.to_path_buf()
}

fn import(agents: &[PathBuf], env: &str, params: &Path, out: &Path) -> std::process::Output {
    let list: Vec<String> = agents.iter().map(|p| p.display().to_string()).collect();
    run(&[
        "import",
        "--reference",
        "acac",
        "--env",
        env,
        "--params",
        params.to_str().unwrap(),
        "--horizon",
        "100",
        "--agents",
        &list.join(","),
        "--out",
        out.to_str().unwrap(),
    ])
}

#[test]
fn acacs_own_actors_import_with_their_time_tables_and_act_as_deployed() {
    let dir = tempfile::tempdir().unwrap();
    let params = dir.path().join("params.json");
    std::fs::write(&params, r#"{"grid_dim": [6, 6]}"#).unwrap();
    let tensors: Vec<_> = (0..2).map(acac_actor_tensors).collect();
    assert!(tensors[0].iter().any(|(n, _)| n == TIME_TABLE));
    let agents: Vec<PathBuf> = (0..2)
        .map(|i| write(&dir.path().join(format!("a{i}.safetensors")), &tensors[i]))
        .collect();
    let policy = dir.path().join("policy");

    // Not a gym id ACAC builds: refused by name, nothing written.
    let out = import(&agents, "OSD-T-v0", &params, &policy);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("Overcooked-MA-v1"),
        "{err}"
    );
    // Agent 1 without its time table reads too wide an input for a Box Pushing agent; without
    // its LayerNorm it is another architecture than agent 0's.
    let untimed: Vec<_> = tensors[1]
        .iter()
        .filter(|(n, _)| n != TIME_TABLE)
        .cloned()
        .collect();
    let odd = write(&dir.path().join("odd.safetensors"), &untimed);
    let out = import(&[agents[0].clone(), odd], "BP-MA-v0", &params, &policy);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success()
            && err.contains("odd.safetensors")
            && err.contains("`encoder.fc1.weight` has shape [32, 7], expected [32, 5]"),
        "{err}"
    );
    let no_ln: Vec<_> = tensors[1]
        .iter()
        .filter(|(n, _)| !n.starts_with("ln."))
        .cloned()
        .collect();
    let odd = write(&dir.path().join("odd.safetensors"), &no_ln);
    let out = import(&[agents[0].clone(), odd], "BP-MA-v0", &params, &policy);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("LayerNorm no") && err.contains("a0.safetensors"),
        "{err}"
    );
    assert!(!policy.exists(), "a refused import writes nothing");

    let out = import(&agents, "BP-MA-v0", &params, &policy);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let nets = read_nets(&policy).unwrap();
    assert!(nets
        .manifest
        .nets
        .iter()
        .all(|n| n.architecture.kind == ACAC_ACTOR
            && n.architecture.time_embedding == Some([105, 2])));
    // The nets are ACAC's, time table and all.
    for (i, net) in nets.agents.iter().enumerate() {
        let views: Vec<_> = tensors[i]
            .iter()
            .map(|(n, a)| (n.clone(), a.view()))
            .collect();
        let bytes = named_to_safetensors_bytes(&views);
        let sd = StateDict::parse(&bytes, Path::new("x")).unwrap();
        assert_eq!(
            *net,
            ActingNet::Acac(TimedAcacActor::from_state_dict(&sd).unwrap())
        );
    }

    let p = policy.to_str().unwrap();
    for flags in [&[][..], &["--sample"][..]] {
        let common = [
            &["--policy", p, "--episodes", "2", "--trajectories"][..],
            flags,
        ]
        .concat();
        let eval = stdout_lines(&run(&[&["eval"][..], &common].concat()));
        assert_eq!(eval.len(), 2);
        if flags.is_empty() {
            let deploy = stdout_lines(&run(&[&["deploy"][..], &common].concat()));
            assert_eq!(eval, deploy);
        }
    }
}
