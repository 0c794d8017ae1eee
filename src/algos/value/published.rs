//! The value family's published settings per domain, as config keys applied over the ICRA
//! paper's common settings before the user's keys (`docs/ALGORITHMS.md` §10): Figure 4's windows
//! on Box Pushing (10 x 10: 15, 30 x 30: 45, also the training period), Figure 5's Warehouse
//! block, MacroMARL's `mac_dec_q.sh` windows on its Box Pushing (10, 14, 20, 35 or 45 steps for
//! grids 6 to 14), and on every domain a paper trained on, the discount its returns are reported
//! under ([`crate::envs::Domain::paper_discount`]). The family names the domains here (it sits
//! above them); the domains know nothing of it.

use crate::envs::domain::{key_table, key_usize};
use crate::envs::EnvSpec;

/// The keys the papers set for the value methods on `env`'s setting.
pub fn settings(env: &EnvSpec) -> toml::Table {
    let keys = env.keys();
    let window = |trace_len: i64| {
        key_table([
            ("trace_len", trace_len.into()),
            ("train_freq", trace_len.into()),
        ])
    };
    let mut table = match env.env_name() {
        "BP_MA" => {
            let grid =
                key_usize(keys, "grid_dim").unwrap_or(crate::envs::box_pushing::DEFAULT_GRID_DIM);
            window(if grid >= 30 { 45 } else { 15 })
        }
        "OSD_S_4" => key_table([
            ("total_epi", 40000.into()),
            ("replay_buffer_size", 1000.into()),
            ("sample_epi", true.into()),
            ("h_explore", true.into()),
            ("l_rate", 0.0006.into()),
            ("train_freq", 30.into()),
            ("trace_len", 10.into()),
            ("batch_size", 16.into()),
            ("dec_rnn_h_size", 64.into()),
        ]),
        "BP-MA-v0" => window(match crate::envs::bp_ma_v0::grid_of(keys) {
            ..=6 => 10,
            7..=8 => 14,
            9..=10 => 20,
            11..=12 => 35,
            _ => 45,
        }),
        _ => toml::Table::new(),
    };
    if let Some(discount) = env.paper_discount() {
        table.insert("discount".into(), discount.into());
    }
    table
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_follow_the_grid_and_every_paper_domain_has_its_discount() {
        let icra = |grid| settings(&crate::envs::box_pushing::paper_spec(grid));
        assert_eq!(icra(10)["trace_len"].as_integer(), Some(15));
        assert_eq!(icra(30)["train_freq"].as_integer(), Some(45));
        assert_eq!(icra(30)["discount"].as_float(), Some(0.98));
        let wtd = settings(&crate::envs::warehouse::paper_spec());
        assert_eq!(wtd["discount"].as_float(), Some(1.0));
        assert_eq!(wtd["batch_size"].as_integer(), Some(16));
        let bp = |grid| settings(&crate::envs::bp_ma_v0::spec(grid, 100));
        assert_eq!(bp(6)["trace_len"].as_integer(), Some(10));
        assert_eq!(bp(12)["trace_len"].as_integer(), Some(35));
        assert_eq!(bp(20)["trace_len"].as_integer(), Some(45));
        let overcooked = EnvSpec::new("Overcooked-MA-v1", &toml::Table::new()).unwrap();
        assert_eq!(
            settings(&overcooked),
            key_table([("discount", 0.99.into())])
        );
    }
}
