//! `macdec render`: animate a trained run's policy as a GIF.

use crate::experiment::policy_files::NetRole;
use crate::experiment::results_tree;
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
    /// Which nets act: `cen` (the centralized Q-net, which Our-1, Our-1-R and Our-2 also
    /// train) or `dec` (one Q-net per agent). Default: the nets the run's evaluations used.
    #[arg(long, value_parser = parse_net_role)]
    net: Option<NetRole>,
}

/// Render the run's episodes to the GIF; a policy directory given as `--run` is refused first.
pub(super) fn run(args: RenderArgs) -> Result<()> {
    let RenderArgs {
        run,
        episodes,
        out,
        frame_ms,
        net,
    } = args;
    refuse_policy_dir_as_run(&run)?;
    let returns = crate::render::rollout::render_run(&run, net, episodes, &out, frame_ms)
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
