//! `macdec render`: animate a trained run's policy as a GIF.

use crate::deploy::drive::local_eval::Choice;
use crate::experiment::run::results_tree;
use crate::policy_files::NetRole;
use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};

use super::bounds::episode_count;

#[derive(clap::Args)]
pub(super) struct RenderArgs {
    /// A run directory: <results>/<experiment>/<method>/seed-<k>.
    #[arg(long)]
    run: PathBuf,
    /// Episodes to show, one after another.
    #[arg(long, default_value_t = 1, value_parser = episode_count)]
    episodes: usize,
    /// The GIF to write.
    #[arg(long, default_value = "rollout.gif")]
    out: PathBuf,
    /// Milliseconds per primitive step.
    #[arg(long, default_value_t = 150)]
    frame_ms: u32,
    /// Which nets act: `cen` (the centralized net: Cen-DDRQN's Q-net, which Our-1, Our-1-R and
    /// Our-2 also train, or Mac-CAC's actor) or `dec` (one net per agent). Default: the nets the
    /// run's evaluations used.
    #[arg(long, value_parser = parse_net_role)]
    net: Option<NetRole>,
    /// Sample each macro-action from the actors' distributions (MacroMARL's evaluation protocol)
    /// instead of taking the most probable; actor policies only.
    #[arg(long)]
    sample: bool,
}

/// Render the run's episodes to the GIF; a policy directory given as `--run` is refused first.
pub(super) fn run(args: RenderArgs) -> Result<()> {
    let RenderArgs {
        run,
        episodes,
        out,
        frame_ms,
        net,
        sample,
    } = args;
    refuse_policy_dir_as_run(&run)?;
    let choice = if sample {
        Choice::Sampled
    } else {
        Choice::Greedy
    };
    let returns = crate::render::rollout::render_run(&run, net, choice, episodes, &out, frame_ms)
        .with_context(|| format!("rendering {}", run.display()))?;
    eprintln!(
        "wrote {} ({} episode(s), team returns {})",
        out.display(),
        returns.len(),
        summarize_returns(&returns)
    );
    Ok(())
}

/// `--net`: `cen` or `dec`, the names policy.json uses for the two kinds of net.
fn parse_net_role(text: &str) -> Result<NetRole, String> {
    match text {
        "cen" => Ok(NetRole::Cen),
        "dec" => Ok(NetRole::Dec),
        other => Err(format!("expected `cen` or `dec`, got `{other}`")),
    }
}

/// Episode returns for one line: all of them up to ten, else their mean, lowest and highest.
fn summarize_returns(returns: &[f64]) -> String {
    if returns.len() <= 10 {
        return format!("{returns:?}");
    }
    let mean = returns.iter().sum::<f64>() / returns.len() as f64;
    let (lo, hi) = returns
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &r| {
            (lo.min(r), hi.max(r))
        });
    format!("mean {mean}, lowest {lo}, highest {hi}")
}

/// `render --run` takes a run directory; an exported policy directory given instead is refused
/// with what it is (a custom domain's by name: the binary cannot simulate it).
fn refuse_policy_dir_as_run(dir: &Path) -> Result<()> {
    use crate::policy_files::{legacy::MANIFEST_FILE_V1, Manifest, POLICY_FILE};
    let run_policy = dir.join(results_tree::POLICY_DIR);
    let described = [POLICY_FILE, MANIFEST_FILE_V1].map(|f| dir.join(f).is_file());
    if !described.contains(&true) || run_policy.exists() {
        return Ok(());
    }
    let manifest = Manifest::read(dir).with_context(|| format!("reading {}", dir.display()))?;
    manifest
        .env
        .known()
        .with_context(|| format!("rendering {}", dir.display()))?;
    bail!(
        "{} is an exported policy directory, not a run directory: `macdec render --run` takes a \
         training run's directory (its policy/ files); `macdec eval --policy {}` runs this policy's \
         episodes",
        dir.display(),
        dir.display()
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::tests::{accepted, assert_refused};
    use crate::cli::Command;
    use clap::error::ErrorKind;

    fn parse(flags: &[&str]) -> RenderArgs {
        match accepted("render", flags) {
            Command::Render(args) => args,
            _ => unreachable!("`render` parses as Command::Render"),
        }
    }

    #[test]
    fn render_defaults_to_one_episode_at_150_ms_into_rollout_gif() {
        assert_refused(
            "render",
            &[],
            ErrorKind::MissingRequiredArgument,
            "--run <RUN>",
        );
        let args = parse(&["--run", "r"]);
        assert_eq!(args.run, PathBuf::from("r"));
        assert_eq!(args.episodes, 1);
        assert_eq!(args.out, PathBuf::from("rollout.gif"));
        assert_eq!(args.frame_ms, 150);
        assert_eq!(args.net, None);
        assert!(!args.sample);
        assert!(parse(&["--run", "r", "--sample"]).sample);
    }

    #[test]
    fn render_net_is_cen_or_dec_exactly() {
        assert_eq!(
            parse(&["--run", "r", "--net", "cen"]).net,
            Some(NetRole::Cen)
        );
        assert_eq!(
            parse(&["--run", "r", "--net", "dec"]).net,
            Some(NetRole::Dec)
        );
        for bad in ["CEN", "actor", ""] {
            assert_refused(
                "render",
                &["--run", "r", "--net", bad],
                ErrorKind::ValueValidation,
                &format!("expected `cen` or `dec`, got `{bad}`"),
            );
        }
    }

    #[test]
    fn render_episodes_are_bounded_like_eval_num_epi() {
        assert_eq!(
            parse(&["--run", "r", "--episodes", "100000"]).episodes,
            100_000
        );
        assert_refused(
            "render",
            &["--run", "r", "--episodes", "0"],
            ErrorKind::ValueValidation,
            "must be at least 1",
        );
        assert_refused(
            "render",
            &["--run", "r", "--episodes", "100001"],
            ErrorKind::ValueValidation,
            "must be at most 100000, got 100001",
        );
    }

    #[test]
    fn returns_are_listed_up_to_ten_then_summarized() {
        assert_eq!(summarize_returns(&[1.0, -2.5]), "[1.0, -2.5]");
        let ten = [0.5; 10];
        assert_eq!(summarize_returns(&ten), format!("{ten:?}"));
        let eleven: Vec<f64> = (0..11).map(f64::from).collect();
        assert_eq!(summarize_returns(&eleven), "mean 5, lowest 0, highest 10");
    }

    #[test]
    fn a_directory_without_policy_files_is_not_refused_as_a_policy_directory() {
        let dir = tempfile::tempdir().unwrap();
        assert!(refuse_policy_dir_as_run(dir.path()).is_ok());
        // A run directory holds policy.json in its policy/ subdirectory.
        std::fs::create_dir(dir.path().join(results_tree::POLICY_DIR)).unwrap();
        std::fs::write(dir.path().join(crate::policy_files::POLICY_FILE), "{}").unwrap();
        assert!(refuse_policy_dir_as_run(dir.path()).is_ok());
    }
}
