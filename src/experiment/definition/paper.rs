//! The paper's training settings per domain and method (spec `algorithms.md` 10): the values
//! every config key takes before the user's keys, so `env_name = "BP_MA"` alone is Figure 4a's
//! setting and `env_name = "OSD_S_4"` alone Figure 5's.
//!
//! Three layers: the ICRA paper's common settings (its Box Pushing 10 x 10 runs), the method's
//! own values (hysteresis, centralized exploration, evaluation episodes), and the keys the
//! domain's paper setting changes ([`crate::envs::Domain::paper_settings`], in the domain's
//! folder). A domain no paper trained on gets the first two.

use crate::algos::hyper::RunConfig;
use crate::algos::method::Method;
use crate::envs::EnvSpec;
use serde::Deserialize;

/// The ICRA paper's common settings for `method` (its Box Pushing 10 x 10 runs, spec 10.1).
pub fn base_settings(method: Method) -> RunConfig {
    let (init_h, end_h) = method.paper_hysteresis();
    RunConfig {
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

/// The paper's settings for `method` on `env` (spec `algorithms.md` 10), before user keys:
/// [`base_settings`] with the domain's paper keys over them.
///
/// Panics if a domain's paper settings name a key `RunConfig` does not have or give it the
/// wrong type: they are code, and every built-in domain's are checked by the tests below.
pub fn paper_defaults(env: &EnvSpec, method: Method) -> RunConfig {
    let mut table = toml::Table::try_from(base_settings(method)).expect("a table");
    for (key, value) in env.paper_settings() {
        assert!(
            table.contains_key(&key),
            "{}'s paper settings name `{key}`, which is not a hyperparameter",
            env.env_name()
        );
        table.insert(key, value);
    }
    RunConfig::deserialize(toml::Value::Table(table))
        .unwrap_or_else(|e| panic!("{}'s paper settings do not type-check: {e}", env.env_name()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_pushing_windows_follow_the_grid_and_warehouse_replays_episodes() {
        let bp10 = paper_defaults(&crate::envs::box_pushing::paper_spec(10), Method::Our1);
        assert_eq!((bp10.trace_len, bp10.train_freq), (15, 15));
        let bp30 = paper_defaults(&crate::envs::box_pushing::paper_spec(30), Method::Our1);
        assert_eq!((bp30.trace_len, bp30.train_freq), (45, 45));
        let wtd = paper_defaults(&crate::envs::warehouse::paper_spec(), Method::Our2);
        assert!(wtd.sample_epi && wtd.h_explore);
        assert_eq!(
            (wtd.discount, wtd.batch_size, wtd.total_epi),
            (1.0, 16, 40000)
        );
        assert_eq!(bp10.discount, 0.98);
    }
}
