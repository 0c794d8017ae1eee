//! The four Warehouse environments as configs, runs and replay files know them: `env_name` is
//! the gym id (`OSD-D-v7`, `OSD-T-v0`, `OSD-T-v1`, `OSD-F-v0`), the keys are the reference's
//! keyword arguments by name, and their defaults are the published experiments' values
//! (`experiments/Warehouse/*.sh`: Warehouse A, C, D, E; `tb_m_speed=0.8`, `d_pen=-20`).
//!
//! The training script passes every BP/OSD kwarg to every env ([`SHARED_KWARGS`]); the ones
//! these envs ignore (`grid_dim`, the box rewards, `n_agent`, which the classes hard-code, spec
//! 5.2 item 3, and `terminate_step` except in OSD-F-v0) are accepted and dropped.
//!
//! [`SHARED_KWARGS`]: crate::envs::macromarl::SHARED_KWARGS

use super::layout::{LAYOUTS, N_WORK_STEPS};
use super::{Osd, OsdParams, D7, F0, T0, T1};
use crate::envs::domain::{fill_keys, key_f64, key_usize, Domain, KeyError, HORIZON_KEY};
use crate::envs::macromarl::refuse_ignored_kwargs;
use crate::envs::EnvError;

/// The domain of [`LAYOUTS`]`[V]`.
#[derive(Debug, Clone, Copy, Default)]
pub struct OsdDomain<const V: usize>;

/// Warehouse A and B.
pub const OSD_D_V7: OsdDomain<D7> = OsdDomain;
/// Warehouse C.
pub const OSD_T_V0: OsdDomain<T0> = OsdDomain;
/// Warehouse D.
pub const OSD_T_V1: OsdDomain<T1> = OsdDomain;
/// Warehouse E.
pub const OSD_F_V0: OsdDomain<F0> = OsdDomain;

const TERMINATE_STEP: &str = "terminate_step";
const HUMAN_SPEEDS: &str = "human_speed_per_step";

impl<const V: usize> OsdDomain<V> {
    /// Whether the env reads `terminate_step` (OSD-F-v0 only).
    fn reads_terminate_step() -> bool {
        LAYOUTS[V].terminal_at_terminate_step
    }

    /// Every key with its published default, in recording order.
    fn defaults() -> toml::Table {
        let layout = &LAYOUTS[V];
        let p = OsdParams::published(layout);
        let speeds: Vec<toml::Value> = layout
            .default_human_speeds
            .iter()
            .map(|s| toml::Value::Array(s.iter().map(|&v| v.into()).collect()))
            .collect();
        let mut t = toml::Table::new();
        t.insert(HORIZON_KEY.into(), (p.horizon as i64).into());
        if Self::reads_terminate_step() {
            t.insert(TERMINATE_STEP.into(), (p.terminate_step as i64).into());
        }
        t.insert(HUMAN_SPEEDS.into(), toml::Value::Array(speeds));
        t.insert("TB_move_speed".into(), p.tb_move_speed.into());
        t.insert("TB_move_noisy".into(), p.tb_move_noisy.into());
        t.insert("TB_move_cost".into(), p.tb_move_cost.into());
        t.insert(
            "fetch_pass_obj_tc".into(),
            (p.fetch_pass_obj_tc as i64).into(),
        );
        t.insert(
            "fetch_look_for_obj_tc".into(),
            (p.fetch_look_for_obj_tc as i64).into(),
        );
        t.insert("fetch_manip_noisy".into(), p.fetch_manip_noisy.into());
        t.insert(
            "fetch_drop_obj_penalty".into(),
            p.fetch_drop_obj_penalty.into(),
        );
        t.insert(
            "delay_delivery_penalty".into(),
            p.delay_delivery_penalty.into(),
        );
        t.insert("obs_human_wait".into(), p.obs_human_wait.into());
        t
    }
}

/// `human_speed_per_step`: a list of per-human lists of step times.
fn human_speeds(keys: &toml::Table) -> Result<Vec<[f64; N_WORK_STEPS]>, KeyError> {
    let bad = |why: String| KeyError::new(HUMAN_SPEEDS, why);
    let Some(toml::Value::Array(humans)) = keys.get(HUMAN_SPEEDS) else {
        return Err(bad("expected a list of lists of step times".into()));
    };
    humans
        .iter()
        .map(|h| {
            let toml::Value::Array(steps) = h else {
                return Err(bad(format!(
                    "expected a list of {N_WORK_STEPS} step times, got {h}"
                )));
            };
            if steps.len() != N_WORK_STEPS {
                return Err(bad(format!(
                    "each human has {N_WORK_STEPS} work steps, got {} times in {h}",
                    steps.len()
                )));
            }
            let mut out = [0.0; N_WORK_STEPS];
            for (o, v) in out.iter_mut().zip(steps) {
                *o = match v {
                    toml::Value::Integer(i) => *i as f64,
                    toml::Value::Float(f) => *f,
                    other => return Err(bad(format!("step times are numbers, got {other}"))),
                };
            }
            Ok(out)
        })
        .collect()
}

fn key_bool(keys: &toml::Table, key: &str) -> Result<bool, KeyError> {
    match keys.get(key) {
        Some(toml::Value::Boolean(b)) => Ok(*b),
        Some(v) => Err(KeyError::new(key, format!("expected a boolean, got {v}"))),
        None => Err(KeyError::new(key, "missing")),
    }
}

/// The parameters the keys describe (not yet validated).
fn params(keys: &toml::Table) -> Result<OsdParams, KeyError> {
    let horizon = key_usize(keys, HORIZON_KEY)?;
    Ok(OsdParams {
        horizon,
        terminate_step: match keys.get(TERMINATE_STEP) {
            Some(_) => key_usize(keys, TERMINATE_STEP)?,
            None => horizon,
        },
        human_speeds: human_speeds(keys)?,
        tb_move_speed: key_f64(keys, "TB_move_speed")?,
        tb_move_noisy: key_f64(keys, "TB_move_noisy")?,
        tb_move_cost: key_f64(keys, "TB_move_cost")?,
        fetch_pass_obj_tc: key_usize(keys, "fetch_pass_obj_tc")?,
        fetch_look_for_obj_tc: key_usize(keys, "fetch_look_for_obj_tc")?,
        fetch_manip_noisy: key_f64(keys, "fetch_manip_noisy")?,
        fetch_drop_obj_penalty: key_f64(keys, "fetch_drop_obj_penalty")?,
        delay_delivery_penalty: key_f64(keys, "delay_delivery_penalty")?,
        obs_human_wait: key_bool(keys, "obs_human_wait")?,
    })
}

/// A refused parameter as a key error (the parameters are named by their keys).
fn key_of(e: EnvError) -> KeyError {
    match e {
        EnvError::InvalidParameter { name, reason } => KeyError::new(name, reason),
        other => KeyError::new("env_name", other.to_string()),
    }
}

impl<const V: usize> Domain for OsdDomain<V> {
    type Env = Osd<V>;

    fn name(&self) -> &'static str {
        LAYOUTS[V].gym_id
    }

    /// The reference's kwargs (see the module doc); OSD-F-v0's `terminate_step` defaults to
    /// `env_terminate_step`, as the training script passes the same value to both.
    fn keys(&self, given: &toml::Table) -> Result<toml::Table, KeyError> {
        let defaults = Self::defaults();
        let used: Vec<&str> = defaults.keys().map(String::as_str).collect();
        refuse_ignored_kwargs(given, &used)?;
        let mut keys = fill_keys(given, defaults)?;
        if Self::reads_terminate_step() && !given.contains_key(TERMINATE_STEP) {
            let horizon = keys[HORIZON_KEY].clone();
            keys.insert(TERMINATE_STEP.into(), horizon);
        }
        params(&keys)?.validate(&LAYOUTS[V]).map_err(key_of)?;
        Ok(keys)
    }

    fn build(&self, keys: &toml::Table) -> Result<Osd<V>, KeyError> {
        Osd::new(params(keys)?).map_err(key_of)
    }

    /// MacroMARL's Warehouse runs are undiscounted (`gamma` 1.0 in every published block, for
    /// the actor-critic and the value-based methods alike); its returns are reported so.
    fn paper_discount(&self, _keys: &toml::Table) -> Option<f64> {
        Some(1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::domain::key_table;
    use crate::envs::MacroEnv;

    #[test]
    fn defaults_are_the_published_settings() {
        let keys = Domain::keys(&OSD_D_V7, &toml::Table::new()).unwrap();
        let env = OSD_D_V7.build(&keys).unwrap();
        let p = env.params();
        assert_eq!(p.horizon, 200);
        assert_eq!(p.human_speeds, [[27.0, 20.0, 20.0, 20.0]; 2]);
        assert_eq!((p.tb_move_speed, p.delay_delivery_penalty), (0.8, -20.0));
        assert_eq!((p.fetch_pass_obj_tc, p.fetch_look_for_obj_tc), (4, 6));
        assert_eq!(
            (p.tb_move_noisy, p.fetch_manip_noisy, p.tb_move_cost),
            (0.0, 0.0, 0.0)
        );
        assert_eq!((p.fetch_drop_obj_penalty, p.obs_human_wait), (-10.0, false));
        let horizons: Vec<usize> = [
            Domain::keys(&OSD_T_V0, &toml::Table::new()),
            Domain::keys(&OSD_T_V1, &toml::Table::new()),
            Domain::keys(&OSD_F_V0, &toml::Table::new()),
        ]
        .into_iter()
        .map(|k| key_usize(&k.unwrap(), HORIZON_KEY).unwrap())
        .collect();
        assert_eq!(horizons, [250, 250, 300]);
        let t1 = OSD_T_V1
            .build(&Domain::keys(&OSD_T_V1, &toml::Table::new()).unwrap())
            .unwrap();
        assert_eq!(t1.params().human_speeds[2], [27.0; 4]);
        assert_eq!(t1.n_agents(), 4);
        let f0 = Domain::keys(&OSD_F_V0, &key_table([(HORIZON_KEY, 250.into())])).unwrap();
        assert_eq!(
            key_usize(&f0, TERMINATE_STEP).unwrap(),
            250,
            "follows the horizon"
        );
        assert_eq!(OSD_D_V7.name(), "OSD-D-v7");
        assert_eq!(OSD_D_V7.tag(), "OSD-D-v7");
    }

    #[test]
    fn shared_kwargs_the_env_ignores_and_unknown_keys_are_refused() {
        let given = toml::toml! { TB_move_speed = 0.6  fetch_pass_obj_tc = 5 };
        let keys = Domain::keys(&OSD_D_V7, &given).unwrap();
        assert_eq!(key_f64(&keys, "TB_move_speed").unwrap(), 0.6);
        // MacroMARL's script passes these to every Warehouse env, which ignores them.
        for ignored in [
            toml::toml! { grid_dim = [6, 6] },
            toml::toml! { big_box_reward = 300 },
            toml::toml! { n_agent = 3 },
            toml::toml! { terminate_step = 200 },
        ] {
            let err = Domain::keys(&OSD_D_V7, &ignored).unwrap_err();
            let key = ignored.keys().next().unwrap();
            assert_eq!(&err.key, key, "{err:?}");
            assert!(err.message.contains("leave it out"), "{err:?}");
        }
        let err = Domain::keys(&OSD_D_V7, &toml::toml! { n_objs = 3 }).unwrap_err();
        assert_eq!(err.key, "n_objs");
        // OSD-F-v0 reads terminate_step.
        let keys = Domain::keys(&OSD_F_V0, &toml::toml! { terminate_step = 120 }).unwrap();
        assert_eq!(key_usize(&keys, TERMINATE_STEP).unwrap(), 120);
    }

    #[test]
    fn bad_values_are_refused_naming_the_key() {
        let cases = [
            (
                toml::toml! { human_speed_per_step = [[27, 20, 20, 20]] },
                HUMAN_SPEEDS,
            ),
            (
                toml::toml! { human_speed_per_step = [[27, 20, 20], [1, 1, 1]] },
                HUMAN_SPEEDS,
            ),
            (
                toml::toml! { human_speed_per_step = [[27, 0, 20, 20], [27, 20, 20, 20]] },
                HUMAN_SPEEDS,
            ),
            (
                toml::toml! { human_speed_per_step = [[27, 1.5, 20, 20], [27, 20, 20, 20]] },
                HUMAN_SPEEDS,
            ),
            (
                toml::toml! { human_speed_per_step = [["a", 1, 20, 20], [27, 20, 20, 20]] },
                HUMAN_SPEEDS,
            ),
            (toml::toml! { human_speed_per_step = 3 }, HUMAN_SPEEDS),
            (toml::toml! { TB_move_speed = 0 }, "TB_move_speed"),
            (toml::toml! { TB_move_noisy = -0.1 }, "TB_move_noisy"),
            (toml::toml! { fetch_pass_obj_tc = 0 }, "fetch_pass_obj_tc"),
            (
                toml::toml! { fetch_look_for_obj_tc = 2.5 },
                "fetch_look_for_obj_tc",
            ),
            (toml::toml! { obs_human_wait = 1 }, "obs_human_wait"),
            (toml::toml! { env_terminate_step = 0 }, HORIZON_KEY),
            (toml::toml! { env_terminate_step = 100000000 }, HORIZON_KEY),
        ];
        for (given, key) in cases {
            let err = Domain::keys(&OSD_D_V7, &given).unwrap_err();
            assert_eq!(err.key, key, "{given}: {err}");
        }
        let err = Domain::keys(&OSD_F_V0, &toml::toml! { terminate_step = 0 }).unwrap_err();
        assert_eq!(err.key, TERMINATE_STEP);
    }
}
