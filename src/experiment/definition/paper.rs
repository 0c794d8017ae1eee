//! The paper's training settings per domain and method (spec `algorithms.md` 10): the values
//! every config key takes before the user's keys, so `env_name = "BP_MA"` alone is Figure 4a's
//! setting and `env_name = "OSD_S_4"` alone Figure 5's.
//!
//! These are facts about the paper's experiments, not about the domains, so they live here and
//! not in `envs`; this is the one place that picks hyperparameters by domain.

use crate::algos::hyper::RunConfig;
use crate::algos::method::Method;
use crate::envs::EnvSpec;

/// The paper's settings for `method` on `env` (spec `algorithms.md` 10), before user keys.
///
/// `env` is used as given, horizon included ([`EnvSpec::paper_box_pushing`] and
/// [`EnvSpec::paper_warehouse`] give the paper's); Box Pushing's windows follow its grid.
pub fn paper_defaults(env: EnvSpec, method: Method) -> RunConfig {
    let (init_h, end_h) = method.paper_hysteresis();
    let box_pushing = |grid: usize| {
        // 10x10: windows of 15; 30x30: windows of 45 (spec 10.1, 10.2).
        let trace_len = if grid >= 30 { 45 } else { 15 };
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
            discount: env.paper_discount(),
            start_train: 2,
            train_freq: trace_len,
            target_update_freq: 5000,
            trace_len,
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
    };
    match env {
        EnvSpec::BoxPushing { grid, .. } => box_pushing(grid),
        // Figure 5's commands differ from Box Pushing's only in these keys (spec 10.3).
        EnvSpec::Warehouse { .. } => RunConfig {
            total_epi: 40000,
            replay_buffer_size: 1000,
            sample_epi: true,
            h_explore: true,
            l_rate: 0.0006,
            train_freq: 30,
            trace_len: 10,
            batch_size: 16,
            dec_rnn_h_size: 64,
            ..box_pushing(10)
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_pushing_windows_follow_the_grid_and_warehouse_replays_episodes() {
        let bp10 = paper_defaults(EnvSpec::paper_box_pushing(10), Method::Our1);
        assert_eq!((bp10.trace_len, bp10.train_freq), (15, 15));
        let bp30 = paper_defaults(EnvSpec::paper_box_pushing(30), Method::Our1);
        assert_eq!((bp30.trace_len, bp30.train_freq), (45, 45));
        let wtd = paper_defaults(EnvSpec::paper_warehouse(), Method::Our2);
        assert!(wtd.sample_epi && wtd.h_explore);
        assert_eq!(
            (wtd.discount, wtd.batch_size, wtd.total_epi),
            (1.0, 16, 40000)
        );
        assert_eq!(bp10.discount, 0.98);
    }
}
