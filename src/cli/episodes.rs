//! What the commands that play a policy's episodes (`deploy`, `eval`, `domain`) share: their
//! flags ([`EpisodeArgs`]), the loaded policy with its evaluation stream ([`EpisodeRun`]) and the
//! JSON line per episode with the summary line after them ([`EpisodePrinter`]).

use anyhow::{Context, Result};
use std::io::Write;
use std::path::PathBuf;

use super::bounds::episode_count;

/// The flags of every command that plays a policy's greedy episodes (`deploy`, `eval`,
/// `domain`), so the three take them with one spelling, one default and one meaning.
#[derive(clap::Args)]
pub(super) struct EpisodeArgs {
    /// Policy directory (from `export` or `import`).
    #[arg(long)]
    pub(super) policy: PathBuf,
    /// Episodes to run.
    #[arg(long, default_value_t = 1, value_parser = episode_count)]
    pub(super) episodes: usize,
    /// Seed of the environment's random stream (default: the run's seed); the stream is the
    /// evaluation env's stream of that seed.
    #[arg(long)]
    pub(super) seed: Option<u64>,
    /// Include every step (executed macro-actions, reward, finished flags) in the output.
    #[arg(long)]
    pub(super) trajectories: bool,
}

/// A loaded policy directory and the evaluation stream its episodes draw from.
pub(super) struct EpisodeRun {
    pub(super) manifest: crate::policy_files::Manifest,
    /// `--seed`, or the run's seed.
    pub(super) seed: u64,
    pub(super) rng: crate::envs::EnvRng,
}

impl EpisodeArgs {
    /// The policy, every agent's net verified (robots serve them one by one: a policy that acts
    /// only centrally is refused, naming its centralized net), and the evaluation env's stream
    /// of the seed. Every episode command simulates the domain, so a custom domain's policy is
    /// refused here.
    pub(super) fn load(&self) -> Result<EpisodeRun> {
        let (manifest, _verified) = crate::policy_files::load_all(&self.policy)
            .with_context(|| format!("loading policy {}", self.policy.display()))?;
        self.episode_run(manifest)
    }

    /// The policy's evaluated nets as one [`Team`](crate::deploy::drive::team::Team) acting in
    /// this process (the agents' own nets, or the centralized net of a policy that acts only
    /// centrally), choosing by `choice`, with the evaluation env's stream of the seed.
    pub(super) fn load_team(
        &self,
        choice: crate::deploy::drive::local_eval::Choice,
    ) -> Result<(EpisodeRun, crate::deploy::drive::team::Team)> {
        let run = self.load_description()?;
        let team = crate::deploy::drive::team::Team::load(
            &run.manifest,
            &self.policy,
            run.manifest.evaluated,
            choice,
            &run.rng,
        )
        .with_context(|| format!("loading policy {}", self.policy.display()))?;
        Ok((run, team))
    }

    /// The description (checked) and the evaluation stream, no weights read yet.
    fn load_description(&self) -> Result<EpisodeRun> {
        let manifest = crate::policy_files::Manifest::read(&self.policy)
            .with_context(|| format!("loading policy {}", self.policy.display()))?;
        self.episode_run(manifest)
    }

    /// `manifest` with the evaluation stream of the seed, once its domain is known here.
    fn episode_run(&self, manifest: crate::policy_files::Manifest) -> Result<EpisodeRun> {
        use crate::experiment::definition::seeds::{stream, Role};
        manifest
            .env
            .known()
            .with_context(|| format!("running episodes of {}", self.policy.display()))?;
        let seed = self.seed.unwrap_or(manifest.run.seed);
        Ok(EpisodeRun {
            manifest,
            seed,
            rng: stream(seed, Role::EvalEnv),
        })
    }
}

/// Prints each episode's JSON line to stdout as it ends (flushed, so a long run streams) and
/// keeps the sums the summary line reports.
pub(super) struct EpisodePrinter {
    trajectories: bool,
    count: usize,
    discounted: f64,
    undiscounted: f64,
}

impl EpisodePrinter {
    pub(super) fn new(trajectories: bool) -> Self {
        Self {
            trajectories,
            count: 0,
            discounted: 0.0,
            undiscounted: 0.0,
        }
    }

    pub(super) fn print(
        &mut self,
        trace: crate::deploy::drive::driver::EpisodeTrace,
    ) -> Result<(), crate::deploy::drive::driver::DeployError> {
        let mut out = std::io::stdout().lock();
        writeln!(out, "{}", trace.json_line(self.trajectories))?;
        out.flush()?;
        self.count += 1;
        self.discounted += trace.discounted_return;
        self.undiscounted += trace.undiscounted_return;
        Ok(())
    }

    /// `N episode(s) of DOMAIN WHERE, seed S: mean discounted return M`, the line every episode
    /// command ends with (on stderr, so stdout stays JSON lines).
    pub(super) fn summary(&self, run: &EpisodeRun, place: &str) -> String {
        format!(
            "{} episode(s) of {} {place}, seed {}: mean discounted return {:.4}",
            self.count,
            run.manifest.env.name(),
            run.seed,
            self.discounted / self.count.max(1) as f64
        )
    }

    pub(super) fn mean_undiscounted(&self) -> f64 {
        self.undiscounted / self.count.max(1) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::Cli;
    use clap::CommandFactory;

    /// How `subcommand` declares `flag`: its default and help text.
    fn declared(subcommand: &str, flag: &str) -> (Vec<String>, String) {
        let cmd = Cli::command();
        let arg = cmd
            .find_subcommand(subcommand)
            .unwrap()
            .get_arguments()
            .find(|a| a.get_id() == flag)
            .unwrap_or_else(|| panic!("`{subcommand}` has no --{flag}"))
            .clone();
        let defaults = arg
            .get_default_values()
            .iter()
            .map(|v| v.to_string_lossy().into_owned());
        (defaults.collect(), arg.get_help().unwrap().to_string())
    }

    #[test]
    fn deploy_eval_and_domain_take_the_episode_flags_alike() {
        for flag in ["episodes", "seed", "trajectories"] {
            let deploy = declared("deploy", flag);
            assert_eq!(declared("eval", flag), deploy, "--{flag}");
            assert_eq!(declared("domain", flag), deploy, "--{flag}");
        }
        assert_eq!(declared("eval", "episodes").0, ["1"]);
        assert_eq!(declared("eval", "policy"), declared("deploy", "policy"));
    }

    #[test]
    fn a_missing_policy_directory_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let args = EpisodeArgs {
            policy: dir.path().join("none"),
            episodes: 1,
            seed: None,
            trajectories: false,
        };
        let e = args.load().err().expect("no policy there");
        assert_eq!(
            e.to_string(),
            format!("loading policy {}", args.policy.display())
        );
    }
}
