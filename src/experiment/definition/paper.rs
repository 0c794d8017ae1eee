//! The papers' training settings per domain and method: the values every config key takes
//! before the user's keys, so `env_name = "BP_MA"` alone is Figure 4a's setting, `env_name =
//! "OSD_S_4"` alone Figure 5's, and `env_name = "BP-MA-v0"` with `mac-iac` MacroMARL's published
//! Box Pushing block.
//!
//! Value methods (`docs/ALGORITHMS.md` §10), three layers: the ICRA paper's common settings (its
//! Box Pushing 10 x 10 runs), the method's own values (hysteresis, centralized exploration,
//! evaluation episodes), and the keys the papers set on the domain
//! ([`crate::algos::value::published`]). A domain no paper trained on gets the first two.
//!
//! Actor-critic methods (`docs/MACROMARL.md` §1.4): the reference's argparse defaults, then the
//! domain's published row for the method ([`crate::algos::actor_critic::published`]). A
//! domain MacroMARL did not publish on keeps the defaults, with the discount of its paper
//! setting when it has one.

use crate::algos::hyper::{AcConfig, RunConfig, ValueConfig};
use crate::algos::method::{Family, Method};
use crate::envs::EnvSpec;
use serde::Deserialize;

/// The ICRA paper's common settings for `method` (its Box Pushing 10 x 10 runs, `docs/ALGORITHMS.md` §10.1).
pub fn base_settings(method: Method) -> ValueConfig {
    let (init_h, end_h) = method.paper_hysteresis();
    ValueConfig {
        total_epi: 15000,
        replay_buffer_size: 80000,
        sample_epi: false,
        dynamic_h: true,
        init_h,
        end_h,
        h_stable_at: 6000,
        eps_l_d: true,
        eps_l_d_steps: 6000,
        eps_end: 0.1,
        h_explore: false,
        cen_explore: method.paper_cen_explore(),
        l_rate: 0.001,
        discount: 0.98,
        start_train: 2,
        train_freq: 15,
        target_update_freq: 5000,
        trace_len: 15,
        sub_trace_len: 1,
        batch_size: 128,
        dec_mlp_layer_size: 32,
        dec_rnn_h_size: 32,
        cen_mlp_layer_size: 32,
        cen_rnn_h_size: 64,
        eval_freq: 10,
        eval_num_epi: method.paper_eval_num_epi(),
        checkpoint_freq: 500,
        early_return_skips_all: true,
    }
}

/// The papers' settings for `method` on `env`, before user keys, of the method's family.
///
/// Panics if a domain's settings name a key the family does not have or give it the wrong
/// type: they are code, and every built-in domain's are checked by the tests.
pub fn paper_defaults(env: &EnvSpec, method: Method) -> RunConfig {
    match method.family() {
        Family::Value => value_paper_defaults(env, method).into(),
        Family::ActorCritic => actor_critic_defaults(env, method).into(),
    }
}

/// MacroMARL's published settings for actor-critic `method` on `env` (see the module doc).
pub fn actor_critic_defaults(env: &EnvSpec, method: Method) -> AcConfig {
    let alg = method
        .actor_critic()
        .map_or("", |design| design.reference_alg);
    let mut table = toml::Table::try_from(AcConfig::reference_defaults()).expect("a table");
    let published = crate::algos::actor_critic::published::settings(env, alg);
    if published.is_empty() {
        if let Some(d) = env.paper_discount() {
            table.insert("gamma".into(), d.into());
        }
    }
    for (key, value) in published {
        assert!(
            table.contains_key(&key),
            "{}'s actor-critic settings name `{key}`, which is not a hyperparameter",
            env.env_name()
        );
        table.insert(key, value);
    }
    AcConfig::deserialize(toml::Value::Table(table)).unwrap_or_else(|e| {
        panic!(
            "{}'s actor-critic settings do not type-check: {e}",
            env.env_name()
        )
    })
}

/// The ICRA paper's settings for value `method` on `env` (`docs/ALGORITHMS.md` §10), before user
/// keys: [`base_settings`] with the domain's paper keys over them.
pub fn value_paper_defaults(env: &EnvSpec, method: Method) -> ValueConfig {
    let mut table = toml::Table::try_from(base_settings(method)).expect("a table");
    for (key, value) in crate::algos::value::published::settings(env) {
        assert!(
            table.contains_key(&key),
            "{}'s paper settings name `{key}`, which is not a hyperparameter",
            env.env_name()
        );
        table.insert(key, value);
    }
    ValueConfig::deserialize(toml::Value::Table(table))
        .unwrap_or_else(|e| panic!("{}'s paper settings do not type-check: {e}", env.env_name()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_pushing_windows_follow_the_grid_and_warehouse_replays_episodes() {
        let bp10 = value_paper_defaults(&crate::envs::box_pushing::paper_spec(10), Method::Our1);
        assert_eq!((bp10.trace_len, bp10.train_freq), (15, 15));
        let bp30 = value_paper_defaults(&crate::envs::box_pushing::paper_spec(30), Method::Our1);
        assert_eq!((bp30.trace_len, bp30.train_freq), (45, 45));
        let wtd = value_paper_defaults(&crate::envs::warehouse::paper_spec(), Method::Our2);
        assert!(wtd.sample_epi && wtd.h_explore);
        assert_eq!(
            (wtd.discount, wtd.batch_size, wtd.total_epi),
            (1.0, 16, 40000)
        );
        assert_eq!(bp10.discount, 0.98);
    }

    #[test]
    fn every_actor_critic_method_has_published_settings_on_macromarls_domains() {
        let ac = Method::ALL
            .into_iter()
            .filter(|m| m.family() == Family::ActorCritic);
        for method in ac {
            for grid in [6, 8, 10, 12, 14] {
                let c = actor_critic_defaults(&crate::envs::bp_ma_v0::spec(grid, 100), method);
                assert_eq!((c.gamma, c.total_epi), (0.98, 40_000), "{method} bp{grid}");
            }
            let bp6 = actor_critic_defaults(&crate::envs::bp_ma_v0::spec(6, 100), method);
            // Published rows differ from the argparse defaults (a_lr 1e-4) everywhere.
            assert_ne!(bp6.a_lr, 1e-4, "{method}");
            for id in [
                "OSD-D-v7",
                "OSD-T-v0",
                "OSD-T-v1",
                "OSD-F-v0",
                "Overcooked-MA-v1",
            ] {
                let spec = EnvSpec::new(id, &toml::Table::new()).unwrap();
                let c = actor_critic_defaults(&spec, method);
                assert!(c.gamma == 1.0 || c.gamma == 0.99, "{method} {id}");
                assert_eq!(c.n_env, c.train_freq, "{method} {id}");
            }
        }
        // BP 12x12 Mac-IAC: 8 environments, 16 episodes per update.
        let c = actor_critic_defaults(&crate::envs::bp_ma_v0::spec(12, 100), Method::MacIac);
        assert_eq!((c.n_env, c.train_freq, c.n_step_td), (8, 16, 3));
        // An ICRA domain keeps the defaults with its discount.
        let c = actor_critic_defaults(&crate::envs::box_pushing::paper_spec(10), Method::MacIac);
        assert_eq!((c.gamma, c.a_lr), (0.98, 1e-4));
    }
}
