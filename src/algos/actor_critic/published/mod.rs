//! MacroMARL's published actor-critic settings per domain and method (`experiments/*/mac_*.sh`,
//! `docs/MACROMARL.md` §1.4), as config keys applied over the reference's argparse defaults
//! before the user's keys: one file per domain the paper trained on. The family names the
//! domains here (it sits above them); the domains know nothing of it.

pub mod bp_ma_v0;
pub mod osd;
pub mod overcooked;

use crate::envs::EnvSpec;

/// The published row for the reference's `--alg` (`MacIAC`, `MacCAC`, `NaiveMacIACC`,
/// `NaiveMacIASC`, `MacIAICC`, `MacIAISC`) on `env`'s setting; empty for a domain or method
/// MacroMARL did not publish.
pub fn settings(env: &EnvSpec, alg: &str) -> toml::Table {
    let keys = env.keys();
    match env.env_name() {
        "BP-MA-v0" => bp_ma_v0::settings(crate::envs::bp_ma_v0::grid_of(keys), alg),
        "OSD-D-v7" => osd::settings(osd::double_room_block(keys.get(osd::HUMAN_SPEEDS)), alg),
        "OSD-T-v0" => osd::settings(osd::Block::C, alg),
        "OSD-T-v1" => osd::settings(osd::Block::D, alg),
        "OSD-F-v0" => osd::settings(osd::Block::E, alg),
        "Overcooked-MA-v1" => overcooked::settings(crate::envs::overcooked::map_letter(keys), alg),
        _ => toml::Table::new(),
    }
}

/// One published experiment block's settings (a row of `docs/MACROMARL.md` §1.4), as
/// config keys. Widths are (a_rnn, c_rnn, c_mlp).
#[allow(clippy::too_many_arguments)]
pub fn published_row(
    a_lr: f64,
    c_lr: f64,
    n_env: i64,
    train_freq: i64,
    c_target_update_freq: i64,
    n_step_td: i64,
    eps_end: f64,
    eps_stable_at: i64,
    total_epi: i64,
    gamma: f64,
    widths: (i64, i64, [i64; 2]),
) -> toml::Table {
    let (a_rnn, c_rnn, c_mlp) = widths;
    let mut t = toml::Table::new();
    let mut put = |k: &str, v: toml::Value| {
        t.insert(k.to_string(), v);
    };
    put("a_lr", a_lr.into());
    put("c_lr", c_lr.into());
    put("n_env", n_env.into());
    put("train_freq", train_freq.into());
    put("c_target_update_freq", c_target_update_freq.into());
    put("n_step_TD", n_step_td.into());
    put("eps_end", eps_end.into());
    put("eps_stable_at", eps_stable_at.into());
    put("total_epi", total_epi.into());
    put("gamma", gamma.into());
    put("a_rnn_layer_size", a_rnn.into());
    put("c_rnn_layer_size", c_rnn.into());
    put(
        "c_mlp_layer_size",
        toml::Value::Array(c_mlp.iter().map(|&w| w.into()).collect()),
    );
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_published_domain_finds_its_rows_and_others_have_none() {
        let bp6 = settings(&crate::envs::bp_ma_v0::spec(6, 100), "MacCAC");
        assert_eq!(bp6["n_env"].as_integer(), Some(2));
        let bp14 = settings(&crate::envs::bp_ma_v0::spec(14, 100), "MacCAC");
        assert_eq!(bp14["n_env"].as_integer(), Some(16));
        let given = |id: &str, extra: toml::Table| EnvSpec::new(id, &extra).unwrap();
        let wh_b = toml::toml! { human_speed_per_step = [[18, 15, 15, 15], [48, 18, 15, 15]] };
        let b = settings(&given("OSD-D-v7", wh_b), "MacIAC");
        assert_eq!(b["a_lr"].as_float(), Some(5e-4));
        let a = settings(&given("OSD-D-v7", toml::Table::new()), "MacIAC");
        assert_eq!(a["a_lr"].as_float(), Some(3e-4));
        let e = settings(&given("OSD-F-v0", toml::Table::new()), "MacIAC");
        assert_eq!(e["total_epi"].as_integer(), Some(100_000));
        let map_b = toml::toml! { map_type = "B" };
        let oc_b = settings(&given("Overcooked-MA-v1", map_b), "MacIAC");
        assert_eq!(oc_b["total_epi"].as_integer(), Some(120_000));
        assert!(settings(&crate::envs::box_pushing::spec(10, 100), "MacIAC").is_empty());
        assert!(settings(&crate::envs::bp_ma_v0::spec(6, 100), "DecHDDRQN").is_empty());
    }
}
