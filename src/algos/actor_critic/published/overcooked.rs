//! MacroMARL's published actor-critic settings on Overcooked maps A-C
//! (`experiments/Overcooked/mac_*.sh`, `docs/MACROMARL.md` §1.4): gamma 0.99, eps to 0.05
//! over 20 000 episodes, 100 000 episodes (120 000 on map B). The critics of Mac-CAC, Naive
//! Mac-IACC and Mac-IAICC are wider (MLP [128, 64], GRU 64).

use super::published_row;

/// The row for `alg` on map `map` ('A', 'B' or 'C'); empty for an unknown `alg`.
pub fn settings(map: char, alg: &str) -> toml::Table {
    let m = match map {
        'A' => 0,
        'B' => 1,
        _ => 2,
    };
    let total = [100_000, 120_000, 100_000][m];
    let small = (32, 32, [32, 32]);
    let wide = (32, 64, [128, 64]);
    let row = |a_lr, n_env: [i64; 3], tgt: [i64; 3], n: [i64; 3], widths| {
        published_row(
            a_lr, 3e-3, n_env[m], n_env[m], tgt[m], n[m], 0.05, 20_000, total, 0.99, widths,
        )
    };
    match alg {
        "MacIAC" => row(3e-4, [4, 4, 8], [8, 8, 32], [5, 5, 5], small),
        "MacCAC" => row(1e-4, [8, 4, 8], [32, 16, 32], [5, 3, 3], wide),
        "NaiveMacIACC" | "NaiveMacIASC" => row(3e-4, [4, 8, 8], [16, 16, 16], [5, 5, 5], wide),
        "MacIAICC" | "MacIAISC" => row(3e-4, [8, 4, 8], [32, 32, 32], [5, 5, 5], wide),
        _ => toml::Table::new(),
    }
}
