//! The domains built into macdec: **the one list** a new built-in domain joins (the macro
//! `built_in_domains`). Each line names the domain's [`AnyEnv`] variant, its environment type
//! and its [`super::domain::Domain`]; the list becomes [`AnyEnv`] (one variant per domain, plus
//! [`AnyEnv::Custom`] for a user's own) and its [`MacroEnv`] forwarding here, and the registry's
//! built-in entries in [`super::registry`].
//!
//! Everything else about a domain lives in its folder (`src/envs/<domain>/`): its dynamics, its
//! config keys and their defaults, its paper settings, its optimum, its limits and its drawing.

use std::any::Any;

use super::custom_env::{CustomEnv, ErasedEnv};
use super::{EnvError, EnvRng, FirstRecordObs, MacroEnv, StepOutcome};

/// The list of built-in domains, handed to the macro `$then` (which generates what the list
/// decides). Domains that share an environment type share its variant: `Variant(Env) = Domain;
/// OtherDomain,`.
macro_rules! built_in_domains {
    ($then:ident) => {
        $then! {
            BoxPushing(crate::envs::box_pushing::BoxPushing) = crate::envs::box_pushing::BoxPushingDomain; crate::envs::bp_ma_v0::BpMaV0Domain,
            Warehouse(crate::envs::warehouse::Warehouse) = crate::envs::warehouse::WarehouseDomain,
            OsdD7(crate::envs::osd::OsdD7) = crate::envs::osd::OSD_D_V7,
            OsdT0(crate::envs::osd::OsdT0) = crate::envs::osd::OSD_T_V0,
            OsdT1(crate::envs::osd::OsdT1) = crate::envs::osd::OSD_T_V1,
            OsdF0(crate::envs::osd::OsdF0) = crate::envs::osd::OSD_F_V0,
            Overcooked(crate::envs::overcooked::Overcooked) = crate::envs::overcooked::OvercookedDomain; crate::envs::overcooked_acac::OvercookedAcacDomain; crate::envs::overcooked_large::OvercookedLargeDomain,
        }
    };
}
pub(crate) use built_in_domains;

/// Generate [`AnyEnv`], [`AnyEnv::hold`] and the forwarding macro from the list.
macro_rules! any_env {
    ($($variant:ident($env:ty) = $domain:expr $(; $more:expr)*,)+) => {
        /// Any built environment: a built-in domain's, by `match` (no dynamic dispatch on the hot
        /// path, `Clone`, and a checkpoint's bincode names the variant), or a user's own behind
        /// [`AnyEnv::Custom`].
        ///
        /// The variants differ in size (Warehouse is larger); a run holds one `AnyEnv`, so
        /// boxing would only add a pointer chase to every step of the hot loop.
        #[allow(clippy::large_enum_variant)]
        #[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
        pub enum AnyEnv {
            $(
                #[doc = concat!("A built-in domain's environment (`", stringify!($variant), "`).")]
                $variant($env),
            )+
            /// A domain not built in (the variant comes last, so the built-in variants keep
            /// their bincode indices).
            Custom(CustomEnv),
        }

        impl AnyEnv {
            /// `env` of the domain named `domain` as the pipeline holds it: a built-in
            /// environment type in its own variant, any other behind [`AnyEnv::Custom`].
            pub fn hold<E: ErasedEnv + 'static>(domain: &'static str, env: E) -> AnyEnv {
                let mut slot = Some(env);
                let any: &mut dyn Any = &mut slot;
                $(
                    if let Some(built_in) = any.downcast_mut::<Option<$env>>() {
                        return AnyEnv::$variant(built_in.take().expect("just filled"));
                    }
                )+
                AnyEnv::Custom(CustomEnv::new(domain, slot.take().expect("just filled")))
            }
        }

        /// Forward a method call to the variant's environment.
        macro_rules! dispatch {
            ($self:expr, $e:ident => $call:expr) => {
                match $self {
                    $(AnyEnv::$variant($e) => $call,)+
                    AnyEnv::Custom($e) => $call,
                }
            };
        }
    };
}
built_in_domains!(any_env);

impl MacroEnv for AnyEnv {
    fn n_agents(&self) -> usize {
        dispatch!(self, e => e.n_agents())
    }
    fn obs_sizes(&self) -> &[usize] {
        dispatch!(self, e => e.obs_sizes())
    }
    fn n_actions(&self) -> &[usize] {
        dispatch!(self, e => e.n_actions())
    }
    fn action_names(&self, agent: usize) -> &'static [&'static str] {
        dispatch!(self, e => e.action_names(agent))
    }
    fn obs_names(&self, agent: usize) -> Vec<String> {
        dispatch!(self, e => e.obs_names(agent))
    }
    fn horizon(&self) -> usize {
        dispatch!(self, e => e.horizon())
    }
    fn reset(&mut self, rng: &mut EnvRng) {
        dispatch!(self, e => e.reset(rng))
    }
    #[inline]
    fn step(&mut self, actions: &[usize], rng: &mut EnvRng) -> Result<StepOutcome, EnvError> {
        dispatch!(self, e => e.step(actions, rng))
    }
    #[inline]
    fn obs(&self, agent: usize) -> &[f32] {
        dispatch!(self, e => e.obs(agent))
    }
    fn executed(&self) -> &[usize] {
        dispatch!(self, e => e.executed())
    }
    #[inline]
    fn mac_done(&self) -> &[bool] {
        dispatch!(self, e => e.mac_done())
    }
    #[inline]
    fn is_free(&self, agent: usize) -> bool {
        dispatch!(self, e => e.is_free(agent))
    }
    fn t(&self) -> usize {
        dispatch!(self, e => e.t())
    }
    fn render_ascii(&self) -> String {
        dispatch!(self, e => e.render_ascii())
    }
    fn first_record_obs(&self) -> FirstRecordObs {
        dispatch!(self, e => e.first_record_obs())
    }
    fn deterministic(&self) -> bool {
        dispatch!(self, e => e.deterministic())
    }
    fn optimal_return(&self, discount: f64) -> Option<f64> {
        dispatch!(self, e => e.optimal_return(discount))
    }
    fn describe(&self) -> String {
        dispatch!(self, e => e.describe())
    }
    fn draw(&self) -> Option<crate::draw::Picture> {
        dispatch!(self, e => e.draw())
    }
    fn state_size(&self) -> usize {
        dispatch!(self, e => e.state_size())
    }
    fn write_state(&self, out: &mut [f32]) {
        dispatch!(self, e => e.write_state(out))
    }
}
