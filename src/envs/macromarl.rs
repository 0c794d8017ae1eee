//! What MacroMARL's domains share (GitHub `yuchen-x/MacroMARL`): the keyword arguments its
//! training script hands to every Box Pushing and Warehouse environment, whichever one it builds.
//!
//! `scripts/pg_based_main.py` builds one dictionary of keyword arguments for every `BP-*` and
//! `OSD-*` gym id and passes all of it to `gym.make`; each environment reads the ones it needs and
//! swallows the rest in `**kwargs`. macdec refuses a key its domain would ignore, naming it
//! ([`refuse_ignored_kwargs`]): a value given and never read would be a silently dropped setting.

use super::domain::KeyError;

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

/// Refuses the shared keyword arguments in `given` that the domain ignores (those in
/// [`SHARED_KWARGS`] that are not among its own keys `used`), naming the key and why it is not
/// simply dropped: a value given and never read is a setting the user believes in and the run
/// does not have. Other unknown keys are left to the domain's [`super::domain::fill_keys`].
pub fn refuse_ignored_kwargs(given: &toml::Table, used: &[&str]) -> Result<(), KeyError> {
    match given
        .keys()
        .find(|k| SHARED_KWARGS.contains(&k.as_str()) && !used.contains(&k.as_str()))
    {
        Some(key) => Err(KeyError::new(
            key,
            "this domain does not read it (MacroMARL's script passes it to every Box Pushing and \
             Warehouse environment, which ignores it there); leave it out",
        )),
        None => Ok(()),
    }
}

/// The keyword arguments of a reference's `gym.make` call (a replay file's `params`, which
/// records every kwarg MacroMARL's or ACAC's runner passed) that the domain reads: the
/// [`SHARED_KWARGS`] its environment swallowed in `**kwargs` without reading are left out, as the
/// reference left them unread; `own` is the domain's key table. Configs, Python and `import`
/// refuse such keys instead ([`refuse_ignored_kwargs`]): there a value given is a setting asked
/// for, here it is a record of the reference's call.
pub fn kwargs_read(given: &toml::Table, own: &toml::Table) -> toml::Table {
    given
        .iter()
        .filter(|(k, _)| !SHARED_KWARGS.contains(&k.as_str()) || own.contains_key(*k))
        .map(|(k, v)| (k.clone(), v.clone()))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reference_calls_unread_shared_kwargs_are_left_out_others_kept() {
        let own = toml::toml! { grid_dim = [10, 10]  penalty = -10 };
        let given = toml::toml! {
            grid_dim = [6, 6]
            TB_move_speed = 0.6
            penalty = -10
            colour = "red"
        };
        let kept = kwargs_read(&given, &own);
        let keys: Vec<&str> = kept.keys().map(String::as_str).collect();
        assert_eq!(keys, ["grid_dim", "penalty", "colour"]);
    }

    #[test]
    fn shared_kwargs_the_domain_ignores_are_refused_by_name() {
        let used = ["grid_dim", "penalty"];
        let own = toml::toml! { grid_dim = [6, 6]  penalty = -10  colour = "red" };
        refuse_ignored_kwargs(&own, &used).unwrap();
        let given = toml::toml! { grid_dim = [6, 6]  TB_move_speed = 0.6 };
        let err = refuse_ignored_kwargs(&given, &used).unwrap_err();
        assert_eq!(err.key, "TB_move_speed");
        assert!(err.message.contains("does not read it"), "{}", err.message);
    }
}
