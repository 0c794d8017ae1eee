//! A domain as the reference's command line names it: `--env_name`, `--grid_dim`,
//! `--env_terminate_step` and `--tb_m_noisy`.
//!
//! These four keys are how experiment files choose a domain and how every run's `config.toml`
//! records it. [`EnvFlags`] converts them to and from an [`EnvSpec`], so the learner, the config
//! layer and the plots hold the spec and never ask which key belongs to which domain.

use serde::{Deserialize, Serialize};

use super::{EnvError, EnvSpec};

/// The reference's `--grid_dim` default. Warehouse has no grid; its runs record this value
/// (`grid_dim = 10`), as they always have.
pub const DEFAULT_GRID_DIM: usize = 10;

/// Which domain, by the reference's `--env_name`.
///
/// The variant order is part of `checkpoint.bin`'s format (bincode writes the variant index).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum EnvName {
    /// Box Pushing (`box_pushing.md`).
    #[serde(rename = "BP_MA", alias = "box-pushing")]
    BoxPushing,
    /// Warehouse Tool Delivery (`warehouse.md`).
    #[serde(rename = "OSD_S_4", alias = "warehouse")]
    Warehouse,
}

impl EnvName {
    /// The paper's setting of this domain with grid side `grid_dim`, which only Box Pushing uses
    /// ([`EnvSpec::paper_box_pushing`], [`EnvSpec::paper_warehouse`]).
    pub fn paper_spec(self, grid_dim: usize) -> EnvSpec {
        match self {
            EnvName::BoxPushing => EnvSpec::paper_box_pushing(grid_dim),
            EnvName::Warehouse => EnvSpec::paper_warehouse(),
        }
    }
}

/// The four domain keys of a config, in the order `config.toml` writes them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EnvFlags {
    pub env_name: EnvName,
    /// Box Pushing's grid side; [`DEFAULT_GRID_DIM`] for Warehouse.
    pub grid_dim: usize,
    /// The horizon in primitive steps.
    pub env_terminate_step: usize,
    /// Warehouse's Turtlebot movement noise std; 0 for Box Pushing.
    pub tb_m_noisy: f64,
}

impl EnvFlags {
    /// The domain these keys describe. A key the domain does not use is not read (`grid_dim`
    /// of a Warehouse run, `tb_m_noisy` of a Box Pushing run).
    pub fn spec(&self) -> EnvSpec {
        match self.env_name {
            EnvName::BoxPushing => EnvSpec::BoxPushing {
                grid: self.grid_dim,
                horizon: self.env_terminate_step,
            },
            EnvName::Warehouse => EnvSpec::Warehouse {
                horizon: self.env_terminate_step,
                tb_m_noisy: self.tb_m_noisy,
            },
        }
    }

    /// The keys recording `spec`; the ones its domain does not use hold the reference's defaults.
    pub fn of(spec: &EnvSpec) -> Self {
        match *spec {
            EnvSpec::BoxPushing { grid, horizon } => EnvFlags {
                env_name: EnvName::BoxPushing,
                grid_dim: grid,
                env_terminate_step: horizon,
                tb_m_noisy: 0.0,
            },
            EnvSpec::Warehouse {
                horizon,
                tb_m_noisy,
            } => EnvFlags {
                env_name: EnvName::Warehouse,
                grid_dim: DEFAULT_GRID_DIM,
                env_terminate_step: horizon,
                tb_m_noisy,
            },
        }
    }
}

/// Check `spec` ([`EnvSpec::validate`]) and name the bad parameter by the config key that sets
/// it (`grid_dim`, `env_terminate_step`, `tb_m_noisy`), so a config error points at what the
/// user wrote.
pub fn check_spec(spec: &EnvSpec) -> Result<(), (&'static str, String)> {
    spec.validate().map_err(|e| match e {
        EnvError::InvalidParameter { name, reason } => (
            flag_of_parameter(name),
            format!("{reason} ({} parameter `{name}`)", spec.name()),
        ),
        other => ("env_name", other.to_string()),
    })
}

/// The config key setting a domain parameter named in [`EnvError::InvalidParameter`]. Parameters
/// no key sets (Warehouse's fixed layout) are reported against `env_name`.
fn flag_of_parameter(name: &str) -> &'static str {
    match name {
        "grid" => "grid_dim",
        "horizon" | "terminate_step" => "env_terminate_step",
        "tb_move_noisy" => "tb_m_noisy",
        _ => "env_name",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flags_round_trip_through_the_spec() {
        for spec in [
            EnvSpec::paper_box_pushing(10),
            EnvSpec::paper_box_pushing(30),
            EnvSpec::paper_warehouse(),
            EnvSpec::Warehouse {
                horizon: 90,
                tb_m_noisy: 0.25,
            },
        ] {
            assert_eq!(EnvFlags::of(&spec).spec(), spec);
        }
        let wtd = EnvFlags::of(&EnvSpec::paper_warehouse());
        assert_eq!((wtd.grid_dim, wtd.env_terminate_step), (10, 150));
    }

    #[test]
    fn paper_specs_have_the_papers_horizons() {
        let h = |name: EnvName, grid| name.paper_spec(grid).horizon();
        assert_eq!(h(EnvName::BoxPushing, 10), 100);
        assert_eq!(h(EnvName::BoxPushing, 30), 200);
        assert_eq!(h(EnvName::Warehouse, 30), 150);
    }

    #[test]
    fn each_bad_parameter_is_named_by_its_config_key() {
        let bp = |grid, horizon| EnvSpec::BoxPushing { grid, horizon };
        let wtd = |horizon, tb_m_noisy| EnvSpec::Warehouse {
            horizon,
            tb_m_noisy,
        };
        let cases = [
            (bp(6, 100), "grid_dim"),
            (bp(11, 100), "grid_dim"),
            (bp(10, 0), "env_terminate_step"),
            (wtd(0, 0.0), "env_terminate_step"),
            (wtd(150, -1.0), "tb_m_noisy"),
            (wtd(150, f64::NAN), "tb_m_noisy"),
        ];
        for (spec, key) in cases {
            assert_eq!(check_spec(&spec).unwrap_err().0, key, "{spec:?}");
        }
        check_spec(&bp(10, 100)).unwrap();
        check_spec(&wtd(150, 0.3)).unwrap();
    }
}
