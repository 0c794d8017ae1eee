//! MacroMARL's published actor-critic settings on Box Pushing (`experiments/BoxPushing/mac_*.sh`,
//! `docs/MACROMARL.md` §1.4): one row per grid and method, 40 000 episodes, gamma 0.98,
//! widths 32. The published Naive Mac-IACC and Mac-IAICC runs use the state critics
//! (`NaiveMacIASC`, `MacIAISC`); their history-critic variants take the same rows.

use super::published_row;

/// The row for `alg` on a `grid` x `grid` world (grids between the published 6..14 take the
/// next smaller published one, larger ones the 14 x 14 row); empty for an unknown `alg`.
pub fn settings(grid: usize, alg: &str) -> toml::Table {
    let g = match grid {
        ..=7 => 0,
        8..=9 => 1,
        10..=11 => 2,
        12..=13 => 3,
        _ => 4,
    };
    let eps_stable_at = [4000, 4000, 6000, 6000, 8000][g];
    let w = (32, 32, [32, 32]);
    let row = |a_lr, c_lr, n_env, tf, tgt, n| {
        published_row(
            a_lr,
            c_lr,
            n_env,
            tf,
            tgt,
            n,
            0.01,
            eps_stable_at,
            40_000,
            0.98,
            w,
        )
    };
    match alg {
        "MacIAC" => [
            row(5e-4, 3e-3, 32, 32, 32, 0),
            row(5e-4, 3e-3, 48, 48, 48, 3),
            row(1e-3, 1e-3, 16, 16, 32, 0),
            row(1e-3, 3e-3, 8, 16, 128, 3),
            row(1e-3, 1e-3, 8, 8, 32, 3),
        ][g]
            .clone(),
        "MacCAC" => [
            row(1e-3, 3e-3, 2, 2, 64, 3),
            row(3e-4, 3e-3, 32, 32, 32, 3),
            row(5e-4, 1e-3, 32, 32, 128, 3),
            row(1e-3, 3e-3, 8, 8, 128, 0),
            row(1e-3, 1e-3, 16, 16, 128, 3),
        ][g]
            .clone(),
        "NaiveMacIACC" | "NaiveMacIASC" => [
            row(3e-4, 3e-3, 32, 32, 128, 0),
            row(5e-4, 1e-3, 32, 32, 128, 0),
            row(5e-4, 1e-3, 32, 32, 128, 0),
            row(5e-4, 5e-4, 48, 48, 48, 0),
            row(5e-4, 5e-4, 32, 32, 128, 0),
        ][g]
            .clone(),
        "MacIAICC" | "MacIAISC" => [
            row(3e-4, 3e-3, 32, 32, 128, 0),
            row(3e-4, 3e-3, 32, 32, 64, 0),
            row(3e-4, 3e-3, 32, 32, 64, 0),
            row(3e-4, 3e-3, 48, 48, 144, 0),
            row(5e-4, 3e-3, 48, 48, 48, 0),
        ][g]
            .clone(),
        _ => toml::Table::new(),
    }
}
