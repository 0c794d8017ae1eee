//! MacroMARL's published value-based settings (`experiments/{BoxPushing,Warehouse,Overcooked}/
//! mac_{dec,cen}_q.sh`, `docs/MACROMARL.md` §8.3) as config keys over the argparse defaults. Every
//! published block passes `--dynamic_h --eps_l_d` with `eps_end` 0.05 and the epsilon decay and
//! hysteresis spans equal (`--h_stable_at` = `--eps_l_d_steps`). Where a script sets
//! `--init_h=1.0 --end_h=1.0` the hysteresis is off; where it omits them the argparse 0.2 -> 0.4
//! applies (Warehouse C's MacCen-Q included, `docs/MACROMARL.md` §8.4 bug 6).
//! No value-based script exists for BP 6 or 14, Warehouse D or E, or Overcooked C: those
//! settings keep the defaults.

use crate::algos::actor_critic::published::osd::{double_room_block, Block, HUMAN_SPEEDS};
use crate::envs::EnvSpec;

/// The published row for `alg` (`MacDecQ`, `MacCenQ`) on `env`; empty where none was published.
pub fn settings(env: &EnvSpec, alg: &str) -> toml::Table {
    let keys = env.keys();
    match env.env_name() {
        "BP-MA-v0" => box_pushing(crate::envs::bp_ma_v0::grid_of(keys), alg),
        "OSD-D-v7" => warehouse(double_room_block(keys.get(HUMAN_SPEEDS)), alg),
        "OSD-T-v0" => warehouse(Block::C, alg),
        "Overcooked-MA-v1" => overcooked(crate::envs::overcooked::map_letter(keys), alg),
        _ => toml::Table::new(),
    }
}

/// The keys every published block sets the same way, and the row's own.
struct Row {
    l_rate: f64,
    batch_size: i64,
    train_freq: i64,
    trace_len: Option<i64>,
    replay_buffer_size: i64,
    decay_episodes: i64,
    start_train: i64,
    total_epi: i64,
    discount: f64,
    hysteretic: bool,
    mlp: Option<[i64; 2]>,
    rnn_h_size: i64,
    sample_epi: bool,
    h_explore: bool,
}

impl Row {
    fn table(&self) -> toml::Table {
        let mut t = toml::Table::new();
        let mut put = |k: &str, v: toml::Value| {
            t.insert(k.to_string(), v);
        };
        put("l_rate", self.l_rate.into());
        put("batch_size", self.batch_size.into());
        put("train_freq", self.train_freq.into());
        if let Some(len) = self.trace_len {
            put("trace_len", len.into());
        }
        put("replay_buffer_size", self.replay_buffer_size.into());
        put("h_stable_at", self.decay_episodes.into());
        put("eps_l_d_steps", self.decay_episodes.into());
        put("eps_end", 0.05.into());
        put("start_train", self.start_train.into());
        put("total_epi", self.total_epi.into());
        put("discount", self.discount.into());
        put("target_update_freq", 5000.into());
        if !self.hysteretic {
            put("init_h", 1.0.into());
            put("end_h", 1.0.into());
        }
        if let Some(m) = self.mlp {
            put(
                "mlp_layer_size",
                toml::Value::Array(m.iter().map(|&w| w.into()).collect()),
            );
        }
        put("rnn_h_size", self.rnn_h_size.into());
        put("sample_epi", self.sample_epi.into());
        put("h_explore", self.h_explore.into());
        t
    }
}

/// `experiments/BoxPushing/mac_{dec,cen}_q.sh` (grids 8, 10, 12, 20, 30): windows of
/// `trace_len` = `train_freq`, 100 000 of them, 500 episodes before training, discount 0.98.
fn box_pushing(grid: usize, alg: &str) -> toml::Table {
    let g = match grid {
        8 => 0,
        10 => 1,
        12 => 2,
        20 => 3,
        30 => 4,
        _ => return toml::Table::new(),
    };
    let train_freq = [10, 14, 20, 35, 45][g];
    let decay = [4000, 6000, 6000, 8000, 8000][g];
    let (l_rate, batch, hysteretic, rnn) = match alg {
        "MacDecQ" => (
            [1e-3, 1e-3, 1e-3, 1e-3, 5e-4][g],
            [64, 32, 32, 32, 32][g],
            true,
            32,
        ),
        "MacCenQ" => (1e-3, [64, 128, 128, 64, 32][g], false, 64),
        _ => return toml::Table::new(),
    };
    Row {
        l_rate,
        batch_size: batch,
        train_freq,
        trace_len: Some(train_freq),
        replay_buffer_size: 100_000,
        decay_episodes: decay,
        start_train: 500,
        total_epi: 40_000,
        discount: 0.98,
        hysteretic,
        mlp: None,
        rnn_h_size: rnn,
        sample_epi: false,
        h_explore: false,
    }
    .table()
}

/// `experiments/Warehouse/mac_{dec,cen}_q.sh` (A, B: `OSD-D-v7`; C: `OSD-T-v0`): whole
/// episodes, 2000 of them, 2000 episodes before training, discount 1, decays over 10 000.
fn warehouse(block: Block, alg: &str) -> toml::Table {
    let total = match block {
        Block::A | Block::B => 40_000,
        Block::C => 80_000,
        _ => return toml::Table::new(),
    };
    let row = |l_rate, train_freq, hysteretic, rnn_h_size| Row {
        l_rate,
        batch_size: 64,
        train_freq,
        trace_len: None,
        replay_buffer_size: 2000,
        decay_episodes: 10_000,
        start_train: 2000,
        total_epi: total,
        discount: 1.0,
        hysteretic,
        mlp: None,
        rnn_h_size,
        sample_epi: true,
        h_explore: false,
    };
    match (alg, block) {
        ("MacDecQ", Block::A) => row(1e-4, 128, true, 32),
        ("MacDecQ", _) => row(5e-5, 128, true, 32),
        ("MacCenQ", Block::C) => row(5e-5, 64, true, 64),
        ("MacCenQ", _) => row(1e-4, 128, false, 64),
        _ => return toml::Table::new(),
    }
    .table()
}

/// `experiments/Overcooked/mac_{dec,cen}_q.sh` (maps A and B): whole episodes, `--h_explore`,
/// hysteresis off, discount 0.99, epsilon over 20 000 of 100 000 episodes.
fn overcooked(map: char, alg: &str) -> toml::Table {
    let row = |l_rate, batch_size, buffer: i64, mlp, rnn_h_size| Row {
        l_rate,
        batch_size,
        train_freq: 64,
        trace_len: None,
        replay_buffer_size: buffer,
        decay_episodes: 20_000,
        start_train: buffer,
        total_epi: 100_000,
        discount: 0.99,
        hysteretic: false,
        mlp,
        rnn_h_size,
        sample_epi: true,
        h_explore: true,
    };
    match (alg, map) {
        ("MacDecQ", 'A') => row(5e-4, 64, 1000, None, 32),
        ("MacDecQ", 'B') => row(5e-4, 32, 3000, None, 32),
        ("MacCenQ", 'A') => row(3e-5, 64, 1000, Some([128, 64]), 64),
        ("MacCenQ", 'B') => row(1e-4, 64, 500, Some([128, 64]), 64),
        _ => return toml::Table::new(),
    }
    .table()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn given(id: &str, extra: toml::Table) -> EnvSpec {
        EnvSpec::new(id, &extra).unwrap()
    }

    #[test]
    fn published_rows_match_the_scripts() {
        let bp30 = settings(&crate::envs::bp_ma_v0::spec(30, 200), "MacDecQ");
        assert_eq!(bp30["l_rate"].as_float(), Some(5e-4));
        assert_eq!(bp30["trace_len"].as_integer(), Some(45));
        assert!(!bp30.contains_key("init_h"));
        let bp10 = settings(&crate::envs::bp_ma_v0::spec(10, 100), "MacCenQ");
        assert_eq!(bp10["batch_size"].as_integer(), Some(128));
        assert_eq!(bp10["end_h"].as_float(), Some(1.0));
        let wh_c = settings(&given("OSD-T-v0", toml::Table::new()), "MacCenQ");
        assert_eq!(wh_c["train_freq"].as_integer(), Some(64));
        assert!(!wh_c.contains_key("init_h"), "WH-C MacCen-Q is hysteretic");
        let wh_a = settings(&given("OSD-D-v7", toml::Table::new()), "MacCenQ");
        assert_eq!(wh_a["init_h"].as_float(), Some(1.0));
        let map_b = toml::toml! { map_type = "B" };
        let oc_b = settings(&given("Overcooked-MA-v1", map_b), "MacCenQ");
        assert_eq!(oc_b["start_train"].as_integer(), Some(500));
        assert_eq!(oc_b["h_explore"].as_bool(), Some(true));
        assert!(settings(&crate::envs::bp_ma_v0::spec(6, 100), "MacDecQ").is_empty());
        assert!(settings(&given("OSD-F-v0", toml::Table::new()), "MacDecQ").is_empty());
    }
}
