//! What MacroMARL's domains share (GitHub `yuchen-x/MacroMARL`): the keyword arguments its
//! training script hands to every Box Pushing and Warehouse environment, whichever one it builds.
//!
//! `scripts/pg_based_main.py` builds one dictionary of keyword arguments for every `BP-*` and
//! `OSD-*` gym id and passes all of it to `gym.make`; each environment reads the ones it needs and
//! swallows the rest in `**kwargs`. A config written for the reference therefore names keys its
//! domain ignores. macdec accepts exactly those silently (and drops them from the recorded
//! config); any other key a domain does not know is an error naming it.

/// The keyword arguments `pg_based_main.py` passes to every `BP-*` and `OSD-*` environment.
pub const SHARED_KWARGS: [&str; 15] = [
    "grid_dim",
    "big_box_reward",
    "small_box_reward",
    "penalty",
    "n_agent",
    "terminate_step",
    "TB_move_speed",
    "TB_move_noisy",
    "TB_move_cost",
    "fetch_pass_obj_tc",
    "fetch_look_for_obj_tc",
    "fetch_manip_noisy",
    "delay_delivery_penalty",
    "obs_human_wait",
    "human_speed_per_step",
];

/// `given` without the shared keyword arguments a domain ignores: those in [`SHARED_KWARGS`]
/// that are not among the domain's own keys `used`. Other keys stay, so the domain's
/// [`super::domain::fill_keys`] refuses the unknown ones by name.
pub fn without_ignored_kwargs(given: &toml::Table, used: &[&str]) -> toml::Table {
    given
        .iter()
        .filter(|(k, _)| !SHARED_KWARGS.contains(&k.as_str()) || used.contains(&k.as_str()))
        .map(|(k, v)| (k.clone(), v.clone()))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_shared_kwargs_the_domain_ignores_are_dropped() {
        let given = toml::toml! {
            grid_dim = [6, 6]
            TB_move_speed = 0.6
            penalty = -10
            colour = "red"
        };
        let kept = without_ignored_kwargs(&given, &["grid_dim", "penalty"]);
        let keys: Vec<&str> = kept.keys().map(String::as_str).collect();
        assert_eq!(keys, ["grid_dim", "penalty", "colour"]);
    }
}
