//! MacroMARL's published actor-critic settings on Warehouse A-E
//! (`experiments/Warehouse/mac_*.sh`, `docs/MACROMARL.md` §1.4): gamma 1, 40 000 episodes
//! on A and B, 80 000 on C and D, 100 000 on E. Warehouse A, B and the ablation are all
//! `OSD-D-v7` and differ in the humans' speeds: B's ([18, 15, 15, 15] and [48, 18, 15, 15]) and
//! the ablation's ([18, 18, 18, 18] for both humans) select their rows, any other A's.
//! Where the reference's scripts disagree with each other (`docs/MACROMARL.md` §5.2: Warehouse C's Naive
//! Mac-IACC and Mac-IAICC ran on `OSD-T-v1`, Naive Mac-IACC's "Warehouse B" used A's speeds), the
//! rows are each script's own: a config that wants the other reading sets its keys.

use super::published_row;

/// Which published block a Warehouse setting is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Block {
    /// Warehouse A (`OSD-D-v7`, any speeds but B's and the ablation's; `docs/MACROMARL.md` §3.2).
    A,
    /// Warehouse B (`OSD-D-v7` with B's human speeds).
    B,
    /// `experiments/Warehouse/*.sh`'s "Ablation" block: A's layout, both humans at 18.
    Ablation,
    /// Warehouse C (`OSD-T-v0`; Naive Mac-IACC and Mac-IAICC ran `OSD-T-v1`, `docs/MACROMARL.md`
    /// §5.2).
    C,
    /// Warehouse D (`OSD-T-v1`).
    D,
    /// Warehouse E (`OSD-F-v0`).
    E,
}

/// The key of the humans' speeds, which tells Warehouse A, B and the ablation apart.
pub const HUMAN_SPEEDS: &str = "human_speed_per_step";

/// Warehouse B's human speeds (`--h0_speed_ps`, `--h1_speed_ps`).
const B_SPEEDS: [[i64; 4]; 2] = [[18, 15, 15, 15], [48, 18, 15, 15]];

/// The ablation block's human speeds.
const ABLATION_SPEEDS: [[i64; 4]; 2] = [[18, 18, 18, 18], [18, 18, 18, 18]];

/// The block of an `OSD-D-v7` setting with these human speeds: B or the ablation for theirs, A
/// otherwise.
pub fn double_room_block(speeds: Option<&toml::Value>) -> Block {
    let value = |humans: &[[i64; 4]; 2]| {
        toml::Value::Array(
            humans
                .iter()
                .map(|h| toml::Value::Array(h.iter().map(|&s| s.into()).collect()))
                .collect(),
        )
    };
    if speeds == Some(&value(&B_SPEEDS)) {
        Block::B
    } else if speeds == Some(&value(&ABLATION_SPEEDS)) {
        Block::Ablation
    } else {
        Block::A
    }
}

/// The row for `alg` on `block`; empty for an unknown `alg`.
pub fn settings(block: Block, alg: &str) -> toml::Table {
    let (total, eps_end) = match block {
        Block::A | Block::B | Block::Ablation => (40_000, 0.05),
        Block::C | Block::D => (80_000, 0.01),
        Block::E => (100_000, 0.01),
    };
    let row = |a_lr, c_lr, n_env, tgt, n, widths, eps_end: f64| {
        published_row(
            a_lr, c_lr, n_env, n_env, tgt, n, eps_end, 10_000, total, 1.0, widths,
        )
    };
    let iac = (32, 32, [32, 32]);
    let cac = (64, 64, [32, 32]);
    let cc = (32, 64, [32, 32]);
    use Block::*;
    match (alg, block) {
        ("MacIAC", A) => row(3e-4, 3e-3, 4, 32, 5, iac, eps_end),
        ("MacIAC", B) => row(5e-4, 1e-3, 4, 32, 5, iac, eps_end),
        ("MacIAC", C) => row(5e-4, 5e-4, 8, 64, 5, iac, eps_end),
        ("MacIAC", D) => row(5e-4, 1e-3, 8, 64, 5, iac, eps_end),
        ("MacIAC", E) => row(3e-4, 3e-3, 4, 16, 5, iac, eps_end),
        ("MacIAC", Ablation) => row(5e-4, 5e-4, 16, 16, 5, iac, eps_end),
        ("MacCAC", A) => row(3e-4, 3e-3, 4, 32, 5, cac, eps_end),
        ("MacCAC", B) => row(3e-4, 3e-3, 4, 16, 5, cac, eps_end),
        ("MacCAC", C) => row(5e-4, 1e-3, 8, 64, 5, cac, eps_end),
        ("MacCAC", D) => row(3e-4, 3e-3, 8, 64, 3, cac, eps_end),
        ("MacCAC", E) => row(3e-4, 3e-3, 8, 64, 3, cac, eps_end),
        ("MacCAC", Ablation) => row(5e-4, 1e-3, 8, 64, 5, cac, eps_end),
        ("NaiveMacIACC" | "NaiveMacIASC", A | B) => row(3e-4, 3e-3, 4, 32, 3, cc, 0.01),
        ("NaiveMacIACC" | "NaiveMacIASC", C) => row(3e-4, 3e-3, 16, 64, 5, cc, eps_end),
        ("NaiveMacIACC" | "NaiveMacIASC", D) => row(3e-4, 3e-3, 8, 64, 5, cc, eps_end),
        ("NaiveMacIACC" | "NaiveMacIASC", E) => row(5e-4, 5e-4, 4, 32, 5, cc, eps_end),
        ("NaiveMacIACC" | "NaiveMacIASC", Ablation) => row(3e-4, 3e-3, 8, 64, 5, cc, eps_end),
        ("MacIAICC" | "MacIAISC", A | B) => row(5e-4, 5e-4, 4, 32, 5, cc, eps_end),
        ("MacIAICC" | "MacIAISC", C) => row(3e-4, 3e-3, 4, 64, 5, cc, eps_end),
        ("MacIAICC" | "MacIAISC", D | E) => row(3e-4, 3e-3, 8, 64, 5, cc, eps_end),
        ("MacIAICC" | "MacIAISC", Ablation) => row(5e-4, 5e-4, 4, 64, 5, cc, eps_end),
        _ => toml::Table::new(),
    }
}
