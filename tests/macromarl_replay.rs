//! MacroMARL's domains (issue 27) and ACAC's environment copies (issue 41 item 3) replay the
//! reference step for step.
//!
//! Each fixture in `tests/fixtures/macromarl/` is a pair written by `scripts/macromarl_traces.py`
//! from the reference code itself (`scripts/macromarl_fixtures.sh` regenerates them all), each in
//! `tests/fixtures/acac/` one written by `scripts/acac_traces.py` from ACAC's code
//! (`scripts/acac_fixtures.sh`, which also records numpy's seed and the random start): the
//! actions in the reference form of `macdec replay` (`NAME.actions.json`) and what the reference
//! printed for them (`NAME.trace.jsonl.gz`). The replay of the actions must give the same lines:
//! the same number of steps, the same executed macro-actions, `mac_done` and `done` flags, and
//! the same observations, rewards and states (to f32 precision: the reference computes in f64).

use std::io::Read;
use std::path::PathBuf;

use macdec::envs::replay::{parse_replay, run_replay};
use serde_json::Value;

/// `tests/fixtures/NAME.EXT`; `name` starts with its folder (`macromarl/`, `acac/`).
fn fixture(name: &str, ext: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(format!("{name}.{ext}"))
}

/// The reference's trace lines of fixture `name`.
fn reference_lines(name: &str) -> Vec<Value> {
    let gz = std::fs::read(fixture(name, "trace.jsonl.gz")).unwrap();
    let mut text = String::new();
    flate2::read::GzDecoder::new(&gz[..])
        .read_to_string(&mut text)
        .unwrap();
    text.lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// Whether two numbers agree to f32 precision (relative 1e-6, absolute 1e-6 near zero).
fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-6 * (1.0 + a.abs().max(b.abs()))
}

/// Compare `ours` with the reference's `theirs` field by field; `at` names the place.
fn assert_same(ours: &Value, theirs: &Value, at: &str) {
    match (ours, theirs) {
        (Value::Number(a), Value::Number(b)) => assert!(
            close(a.as_f64().unwrap(), b.as_f64().unwrap()),
            "{at}: macdec {a}, reference {b}"
        ),
        (Value::Array(a), Value::Array(b)) => {
            assert_eq!(a.len(), b.len(), "{at}: lengths differ: {ours} vs {theirs}");
            for (k, (x, y)) in a.iter().zip(b).enumerate() {
                assert_same(x, y, &format!("{at}[{k}]"));
            }
        }
        (Value::Object(a), Value::Object(b)) => {
            let mut ka: Vec<&String> = a.keys().collect();
            let mut kb: Vec<&String> = b.keys().collect();
            ka.sort();
            kb.sort();
            assert_eq!(ka, kb, "{at}: fields differ");
            for k in ka {
                assert_same(&a[k], &b[k], &format!("{at}.{k}"));
            }
        }
        _ => assert_eq!(ours, theirs, "{at}"),
    }
}

/// Replay fixture `name` and compare every line with the reference's.
fn replays_like_the_reference(name: &str) {
    let text = std::fs::read_to_string(fixture(name, "actions.json")).unwrap();
    let file = parse_replay(&text).unwrap_or_else(|e| panic!("{name}: {e}"));
    let replay = run_replay(&file, false).unwrap_or_else(|e| panic!("{name}: {e}"));
    let theirs = reference_lines(name);
    assert_eq!(
        replay.frames.len(),
        theirs.len(),
        "{name}: macdec ran {} steps, the reference {}",
        replay.frames.len() - 1,
        theirs.len() - 1
    );
    for (frame, their) in replay.frames.iter().zip(&theirs) {
        let ours = serde_json::to_value(&frame.line).unwrap();
        assert_same(&ours, their, &format!("{name} t={}", frame.line.t));
    }
}

/// Replay the fixtures `names` of MacroMARL's folder.
fn all(names: &[&str]) {
    in_folder("macromarl", names);
}

fn in_folder(folder: &str, names: &[&str]) {
    for name in names {
        replays_like_the_reference(&format!("{folder}/{name}"));
    }
}

#[test]
fn bp_ma_v0_replays_the_reference() {
    let mut names = Vec::new();
    for grid in [6, 8, 10, 12, 14] {
        names.push(format!("bp_ma_{grid}_optimum"));
        names.push(format!("bp_ma_{grid}_random0"));
        names.push(format!("bp_ma_{grid}_random1"));
    }
    // Longer episodes with penalties on 6 x 6 and 4 x 4, and a horizon cut that is no terminal.
    names.extend(
        [
            "bp_ma_6_random10",
            "bp_ma_4_random3",
            "bp_ma_10_cut25_random4",
        ]
        .map(String::from),
    );
    all(&names.iter().map(String::as_str).collect::<Vec<_>>());
    // ACAC's runner passes `terminate_step` and an integer `big_box_reward`; the env is the same.
    // ACAC's 8x8 and 10x10 settings: the big box pushed to the goal, and random episodes cut by
    // the horizon.
    in_folder(
        "acac",
        &[
            "bp6_random7",
            "bp8_big_box",
            "bp8_random7",
            "bp10_big_box",
            "bp10_random7",
        ],
    );
}

#[test]
fn osd_d_v7_replays_the_reference() {
    all(&[
        "osd_d_v7_a_random0",
        "osd_d_v7_b_random1",
        "osd_d_v7_a_scripted",
        "osd_d_v7_b_scripted",
        "osd_d_v7_costs_random2",
    ]);
}

#[test]
fn osd_t_v0_replays_the_reference() {
    // *_actors: the greedy episode of the authors' trained actors (C 801 in 99 steps).
    all(&[
        "osd_t_v0_c_random0",
        "osd_t_v0_c_scripted",
        "osd_t_v0_c_actors",
    ]);
}

#[test]
fn osd_t_v1_replays_the_reference() {
    all(&[
        "osd_t_v1_d_random0",
        "osd_t_v1_d_scripted",
        "osd_t_v1_costs_random1",
        "osd_t_v1_d_actors",
    ]);
}

#[test]
fn osd_f_v0_replays_the_reference() {
    all(&[
        "osd_f_v0_e_random0",
        "osd_f_v0_e_scripted",
        "osd_f_v0_e_actors",
    ]);
}

#[test]
fn overcooked_ma_v1_replays_the_reference() {
    all(&[
        "overcooked_a_n3_random0",
        "overcooked_b_n3_random0",
        "overcooked_c_n3_random0",
        "overcooked_a_n2_random1",
        "overcooked_a_n3_salad_plan",
        "overcooked_a_n2_tomato_plan",
        "overcooked_c9_n3_random2",
        "overcooked_b_n2_random3",
        "overcooked_a_n3_actors",
        "overcooked_b_n3_actors",
    ]);
}

#[test]
fn acac_overcooked_ma_v1_replays_acacs_code() {
    // Fixed starts: ACAC numbers agents and plates column by column. *_policy: the greedy
    // episode of our trained ovcC7 policy (seed 2), its macro-actions through ACAC's env: the
    // whole task, delivered at step 40 for 226.
    in_folder(
        "acac",
        &[
            "ovc_a7_random0",
            "ovc_b7_random1",
            "ovc_c7_random2",
            "ovc_c7_policy",
        ],
    );
}

#[test]
fn acac_random_starts_replay_numpys_draws() {
    // Each file's `start_map` is checked against the port of numpy's draws from its `np_seed`.
    in_folder(
        "acac",
        &[
            "ovc_ar7_np3_random3",
            "ovc_br7_np4_random4",
            "ovc_cr7_np5_random5",
            "ovc_br7_np123456789_random6",
        ],
    );
}

#[test]
fn acac_overcooked_ma_v0_replays_acacs_code() {
    // Overcooked-Large, fixed starts: random episodes with cycles of agents moving at once (maps
    // A and C), wrong deliveries, refreshed objects chopped; planned dishes on all three maps
    // (map A after two wrong deliveries and a chop, B and C handed over the divider).
    in_folder(
        "acac",
        &[
            "ovc_a11_random22",
            "ovc_b11_random8",
            "ovc_c11_random22",
            "ovc_a11_plan_dish",
            "ovc_b11_plan_counter",
            "ovc_c11_plan_counter",
        ],
    );
}

#[test]
fn acac_overcooked_ma_v0_random_starts_replay_numpys_draws() {
    // ovcAR11_N6 etc.: each `start_map` is checked against numpy's draws from its `np_seed`.
    in_folder(
        "acac",
        &[
            "ovc_ar11_np7_random7",
            "ovc_br11_np8_random8",
            "ovc_cr11_np9_random9",
        ],
    );
}
