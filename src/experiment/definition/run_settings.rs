//! A run's domain and hyperparameters together, as its `config.toml` records them: the
//! learner's [`RunConfig`] names no domain, so the run layer keeps the domain ([`EnvSpec`])
//! beside it and writes both as one table, the domain first as the reference's four keys
//! `env_name`, `grid_dim`, `env_terminate_step` and `tb_m_noisy` ([`EnvFlags`]). Every existing
//! run directory keeps reading and writing byte for byte the same.

use crate::algos::hyper::RunConfig;
use crate::algos::method::Method;
use crate::envs::flags::{EnvFlags, EnvName};
use crate::envs::EnvSpec;
use crate::experiment::paper::paper_defaults;
use serde::{Deserialize, Serialize};

/// The domain a run trains on and its hyperparameters: `config.toml`'s `[config]` table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(from = "RunSettingsFile", into = "RunSettingsFile")]
pub struct RunSettings {
    /// The domain and its parameters, horizon included (BP 10x10: 100, 30x30: 200; WTD: 150).
    pub env: EnvSpec,
    pub config: RunConfig,
}

impl RunSettings {
    /// The paper's settings for `method` on `env` (see [`paper_defaults`]).
    pub fn paper(env: EnvSpec, method: Method) -> Self {
        RunSettings {
            env,
            config: paper_defaults(env, method),
        }
    }
}

/// `config.toml`'s `[config]` table as written since the first runs: the domain as its four
/// reference keys, then every hyperparameter, in this order. Only [`RunSettings`]'s serde goes
/// through it. Unknown keys are refused, so a typo in a hand-edited config fails instead of
/// being ignored.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct RunSettingsFile {
    env_name: EnvName,
    grid_dim: usize,
    env_terminate_step: usize,
    tb_m_noisy: f64,
    total_epi: usize,
    replay_buffer_size: usize,
    sample_epi: bool,
    dynamic_h: bool,
    init_h: f64,
    end_h: f64,
    h_stable_at: usize,
    eps_l_d: bool,
    eps_l_d_steps: usize,
    eps_end: f64,
    h_explore: bool,
    cen_explore: bool,
    l_rate: f64,
    discount: f64,
    start_train: usize,
    train_freq: usize,
    target_update_freq: usize,
    trace_len: usize,
    sub_trace_len: usize,
    batch_size: usize,
    dec_mlp_layer_size: usize,
    dec_rnn_h_size: usize,
    cen_mlp_layer_size: usize,
    cen_rnn_h_size: usize,
    eval_freq: usize,
    eval_num_epi: usize,
    checkpoint_freq: usize,
    early_return_skips_all: bool,
}

impl From<RunSettings> for RunSettingsFile {
    fn from(RunSettings { env, config: c }: RunSettings) -> Self {
        let EnvFlags {
            env_name,
            grid_dim,
            env_terminate_step,
            tb_m_noisy,
        } = EnvFlags::of(&env);
        RunSettingsFile {
            env_name,
            grid_dim,
            env_terminate_step,
            tb_m_noisy,
            total_epi: c.total_epi,
            replay_buffer_size: c.replay_buffer_size,
            sample_epi: c.sample_epi,
            dynamic_h: c.dynamic_h,
            init_h: c.init_h,
            end_h: c.end_h,
            h_stable_at: c.h_stable_at,
            eps_l_d: c.eps_l_d,
            eps_l_d_steps: c.eps_l_d_steps,
            eps_end: c.eps_end,
            h_explore: c.h_explore,
            cen_explore: c.cen_explore,
            l_rate: c.l_rate,
            discount: c.discount,
            start_train: c.start_train,
            train_freq: c.train_freq,
            target_update_freq: c.target_update_freq,
            trace_len: c.trace_len,
            sub_trace_len: c.sub_trace_len,
            batch_size: c.batch_size,
            dec_mlp_layer_size: c.dec_mlp_layer_size,
            dec_rnn_h_size: c.dec_rnn_h_size,
            cen_mlp_layer_size: c.cen_mlp_layer_size,
            cen_rnn_h_size: c.cen_rnn_h_size,
            eval_freq: c.eval_freq,
            eval_num_epi: c.eval_num_epi,
            checkpoint_freq: c.checkpoint_freq,
            early_return_skips_all: c.early_return_skips_all,
        }
    }
}

impl From<RunSettingsFile> for RunSettings {
    fn from(f: RunSettingsFile) -> Self {
        let flags = EnvFlags {
            env_name: f.env_name,
            grid_dim: f.grid_dim,
            env_terminate_step: f.env_terminate_step,
            tb_m_noisy: f.tb_m_noisy,
        };
        let config = RunConfig {
            total_epi: f.total_epi,
            replay_buffer_size: f.replay_buffer_size,
            sample_epi: f.sample_epi,
            dynamic_h: f.dynamic_h,
            init_h: f.init_h,
            end_h: f.end_h,
            h_stable_at: f.h_stable_at,
            eps_l_d: f.eps_l_d,
            eps_l_d_steps: f.eps_l_d_steps,
            eps_end: f.eps_end,
            h_explore: f.h_explore,
            cen_explore: f.cen_explore,
            l_rate: f.l_rate,
            discount: f.discount,
            start_train: f.start_train,
            train_freq: f.train_freq,
            target_update_freq: f.target_update_freq,
            trace_len: f.trace_len,
            sub_trace_len: f.sub_trace_len,
            batch_size: f.batch_size,
            dec_mlp_layer_size: f.dec_mlp_layer_size,
            dec_rnn_h_size: f.dec_rnn_h_size,
            cen_mlp_layer_size: f.cen_mlp_layer_size,
            cen_rnn_h_size: f.cen_rnn_h_size,
            eval_freq: f.eval_freq,
            eval_num_epi: f.eval_num_epi,
            checkpoint_freq: f.checkpoint_freq,
            early_return_skips_all: f.early_return_skips_all,
        };
        RunSettings {
            env: flags.spec(),
            config,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algos::method::Method;

    fn paper(env: EnvSpec, method: Method) -> RunSettings {
        RunSettings::paper(env, method)
    }

    #[test]
    fn the_domain_is_written_as_the_four_reference_keys_first() {
        let c = paper(EnvSpec::paper_warehouse(), Method::Our2);
        let text = toml::to_string(&c).unwrap();
        assert!(
            text.starts_with(
                "env_name = \"OSD_S_4\"\ngrid_dim = 10\nenv_terminate_step = 150\ntb_m_noisy = 0.0\ntotal_epi = 40000\n"
            ),
            "{text}"
        );
        let back: RunSettings = toml::from_str(&text).unwrap();
        assert_eq!(back, c);
        // The hyperparameters alone are the same keys without the domain's.
        let alone = toml::to_string(&c.config).unwrap();
        assert!(alone.starts_with("total_epi = 40000\n"), "{alone}");
        assert!(text.ends_with(&alone));
    }

    #[test]
    fn unknown_keys_are_refused_and_unused_domain_keys_are_not_read() {
        let c = paper(EnvSpec::paper_box_pushing(10), Method::Our1);
        let text = toml::to_string(&c).unwrap();
        let err = toml::from_str::<RunSettings>(&format!("{text}trace_lenn = 3\n")).unwrap_err();
        assert!(err.message().contains("trace_lenn"), "{err}");
        // A Box Pushing config's tb_m_noisy is not part of its domain.
        let noisy = text.replace("tb_m_noisy = 0.0", "tb_m_noisy = 0.3");
        assert_ne!(noisy, text);
        assert_eq!(toml::from_str::<RunSettings>(&noisy).unwrap().env, c.env);
        // A hyperparameter table refuses the domain's keys: the learner's config names none.
        let err = toml::from_str::<RunConfig>(&text).unwrap_err();
        assert!(err.message().contains("env_name"), "{err}");
    }
}
