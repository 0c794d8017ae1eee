//! The on-disk format of a run's `config.toml` (issue 11): the learner's config holds the domain
//! as an `EnvSpec`, but every run directory written before (and since) reads into it and writes
//! back byte for byte, with the domain as the reference's `env_name`, `grid_dim`,
//! `env_terminate_step` and `tb_m_noisy` keys; a manifest without the newer optional
//! `[provenance]` table still loads.

use macdec::envs::EnvSpec;
use macdec::experiment::run::train_run::RunManifest;
use std::path::{Path, PathBuf};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Committed copies of two reproduction runs' `config.toml`, one per domain, as trained at
/// a4f2208 (before the config held an `EnvSpec`).
fn fixtures() -> [(PathBuf, EnvSpec); 2] {
    let dir = root().join("tests/run_config_format");
    [
        (
            dir.join("fig4a_bp10_our1_seed-0.toml"),
            macdec::envs::box_pushing::spec(10, 100),
        ),
        (
            dir.join("fig5_wtd_cen-ddrqn_seed-5.toml"),
            macdec::envs::warehouse::spec(150, 0.0),
        ),
    ]
}

fn assert_round_trips(path: &Path) -> RunManifest {
    let text = std::fs::read_to_string(path).unwrap();
    let manifest: RunManifest =
        toml::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let again = toml::to_string(&manifest).unwrap();
    assert_eq!(again, text, "{} re-serializes differently", path.display());
    manifest
}

#[test]
fn committed_run_configs_of_both_domains_re_serialize_byte_for_byte() {
    for (path, spec) in fixtures() {
        let manifest = assert_round_trips(&path);
        assert_eq!(manifest.config.env, spec, "{}", path.display());
    }
}

#[test]
fn every_config_in_the_reproduction_tree_re_serializes_byte_for_byte() {
    let mut stack = vec![root().join("reproduction")];
    let mut seen = 0;
    while let Some(dir) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for entry in entries {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.file_name().is_some_and(|n| n == "config.toml") {
                assert_round_trips(&path);
                seen += 1;
            }
        }
    }
    // The fixtures above cover both domains even in a checkout without reproduction/.
    eprintln!("{seen} reproduction config.toml files checked");
}

#[test]
fn a_manifest_without_the_newer_provenance_table_still_loads() {
    for (path, spec) in fixtures() {
        let text = std::fs::read_to_string(&path).unwrap();
        let at = text
            .find("\n[provenance]")
            .expect("the fixture records provenance");
        let older = format!("{}\n", text[..at].trim_end());
        let manifest: RunManifest = toml::from_str(&older).unwrap();
        assert_eq!(manifest.provenance, None);
        assert_eq!(manifest.config.env, spec);
        // Written back, it is the older file again (no empty table appears).
        assert_eq!(toml::to_string(&manifest).unwrap(), older);
    }
}
