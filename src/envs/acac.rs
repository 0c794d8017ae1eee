//! What ACAC's environment copies share (GitHub `LGAI-Research/acac`): its gym ids, which name
//! macdec domains other than MacroMARL's of the same id, and the fields of its replay form
//! (`{"source": "acac", "env": ID, "params": {...}, "np_seed": S, "start_map": [[...]], "steps":
//! [...]}`, see [`super::replay`]; `docs/ACAC.md`).

/// ACAC's gym ids and the macdec domains that are exactly ACAC's code. `BP-MA-v0` is
/// MacroMARL's (ACAC's files are byte-identical); `Overcooked-MA-v1` is ACAC's own copy;
/// `Overcooked-MA-v0` (Overcooked-Large) is ACAC's alone.
pub const GYM_IDS: [(&str, &str); 3] = [
    ("BP-MA-v0", "BP-MA-v0"),
    ("Overcooked-MA-v1", "ACAC-Overcooked-MA-v1"),
    ("Overcooked-MA-v0", "ACAC-Overcooked-MA-v0"),
];

/// The macdec domain of ACAC's gym id `id`, or `None` for an id ACAC's runner does not build.
pub fn domain_of(id: &str) -> Option<&'static str> {
    GYM_IDS.iter().find(|(g, _)| *g == id).map(|(_, d)| *d)
}
