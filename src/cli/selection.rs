//! Which runs of an experiment `train` and `slurm` select: the config file, `--methods`,
//! `--seeds` and `--set`, resolved into an [`Experiment`].

use crate::algos::families::Method;
use crate::experiment::definition::config::{quick_start, Experiment, Overrides};
use crate::experiment::definition::seeds::parse_seeds;
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};

/// Which runs of an experiment, as `train` and `slurm` both select them.
#[derive(clap::Args)]
pub(super) struct Selection {
    /// Experiment TOML (see experiments/); without it, a short built-in run of the methods'
    /// family: Box Pushing 10x10 (ICRA methods), MacroMARL's Box Pushing 6x6 (actor-critic) or
    /// 8x8 (MacroMARL value-based), ACAC's bp6 (ACAC).
    #[arg(long)]
    pub(super) config: Option<PathBuf>,
    /// Comma-separated methods: dec-hddrqn, cen-ddrqn, our1, our1-r, our2 (ICRA 2020), mac-iac,
    /// mac-cac, naive-mac-iacc, naive-mac-iasc, mac-iaicc, mac-iaisc (MacroMARL actor-critic),
    /// mac-dec-q, mac-cen-q (MacroMARL value-based), acac, acac-vanilla, acac-micro-gae (ACAC,
    /// ICML 2025).
    #[arg(long, value_delimiter = ',')]
    pub(super) methods: Option<Vec<String>>,
    /// Seeds: a range `0..40` (end exclusive) or a list `0,3,7`.
    #[arg(long)]
    pub(super) seeds: Option<String>,
    /// Override a config key, e.g. total_epi=300 or dec-hddrqn.init_h=0.3 (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub(super) set: Vec<String>,
}

impl Selection {
    /// The experiment with the command line's methods, seeds and `--set` applied.
    pub(super) fn load(&self) -> Result<Experiment> {
        let o = overrides(
            self.methods.clone(),
            self.seeds.as_deref(),
            self.set.clone(),
        )?;
        Ok(match &self.config {
            Some(path) => {
                Experiment::load(path, &o).with_context(|| format!("loading {}", path.display()))?
            }
            None => {
                let (text, name) = quick_start(o.methods.as_deref()).map_err(anyhow::Error::msg)?;
                Experiment::parse(text, Path::new("<built-in default>"), name, &o)?
            }
        })
    }
}

/// `--methods` and `--seeds` parsed (an unknown method or a bad seed list fails here); `--set`
/// items are checked when the config is resolved.
fn overrides(
    methods: Option<Vec<String>>,
    seeds: Option<&str>,
    set: Vec<String>,
) -> Result<Overrides> {
    let methods = methods
        .map(|names| {
            names
                .iter()
                .map(|n| n.parse::<Method>())
                .collect::<Result<Vec<_>, _>>()
        })
        .transpose()?;
    let seeds = seeds.map(parse_seeds).transpose()?;
    Ok(Overrides {
        methods,
        seeds,
        set,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::algos::actor_critic::method::AcMethod;

    fn selection(methods: Option<&str>, seeds: Option<&str>, set: &[&str]) -> Selection {
        Selection {
            config: None,
            methods: methods.map(|m| m.split(',').map(String::from).collect()),
            seeds: seeds.map(String::from),
            set: set.iter().map(|s| s.to_string()).collect(),
        }
    }

    #[test]
    fn no_config_selects_the_methods_family_s_quick_start() {
        let e = selection(None, None, &[]).load().unwrap();
        assert_eq!(e.name, "quickstart_bp10");
        let e = selection(Some("dec-hddrqn"), None, &[]).load().unwrap();
        assert_eq!(e.name, "quickstart_bp10");
        // An actor-critic method trains MacroMARL's Box Pushing 6x6, with its own keys.
        let e = selection(Some("mac-iac,mac-cac"), None, &[])
            .load()
            .unwrap();
        assert_eq!(e.name, "quickstart_bp6");
        assert_eq!(
            e.methods,
            [
                Method::ActorCritic(AcMethod::MacIac),
                Method::ActorCritic(AcMethod::MacCac)
            ]
        );
        let e = selection(Some("mac-iac"), None, &["n_env=4"])
            .load()
            .unwrap();
        assert_eq!(e.name, "quickstart_bp6");
        let err = format!(
            "{:#}",
            selection(Some("our1,mac-iac"), None, &[])
                .load()
                .expect_err("two families")
        );
        assert!(
            err.contains("one family's quick start") && err.contains("experiments/macromarl"),
            "{err}"
        );
    }

    #[test]
    fn methods_and_seeds_replace_the_experiment_s() {
        let e = selection(Some("our1,cen-ddrqn"), Some("3..6"), &[])
            .load()
            .unwrap();
        assert_eq!(
            e.methods.iter().map(|m| m.name()).collect::<Vec<_>>(),
            ["our1", "cen-ddrqn"]
        );
        assert_eq!(e.seeds, [3, 4, 5]);
        let e = selection(None, Some("0,3,7"), &[]).load().unwrap();
        assert_eq!(e.seeds, [0, 3, 7]);
    }

    #[test]
    fn unknown_methods_bad_seed_lists_and_unknown_keys_are_refused() {
        let err = |s: Selection| format!("{:#}", s.load().expect_err("refused"));
        assert!(err(selection(Some("our3"), None, &[])).contains("our3"));
        for seeds in ["5..2", "0,0", "x"] {
            assert!(
                err(selection(None, Some(seeds), &[])).contains(seeds),
                "{seeds}"
            );
        }
        assert!(err(selection(None, None, &["no_such_key=1"])).contains("no_such_key"));
    }
}
