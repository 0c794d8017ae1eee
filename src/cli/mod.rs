//! The `macdec` command line: parse flags, call the library, report. The `macdec` binary is
//! [`main`]; a user's own binary gets the same command line for its own domains with
//! [`main_with`].
//!
//! One file per subcommand holds its flags (a clap `Args` struct), their value parsers and its
//! handler; what several subcommands share sits in a module named for it: `bounds` (bounded
//! numeric flags), `selection` (which runs `train` and `slurm` select) and `episodes` (what the
//! commands that play a policy's episodes share).

mod audit;
mod bench;
mod bounds;
mod demo;
mod deploy;
mod domain;
mod episodes;
mod eval;
mod export;
mod import;
mod plot;
mod render;
mod replay;
mod report;
mod results;
mod robot;
mod selection;
mod slurm;
mod train;

use anyhow::Result;
use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "macdec",
    version,
    about = "Macro-action multi-agent deep RL (MacDec-MADDRQN, ICRA 2020)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// The learning engine on a toy memory task: an LSTM Q-net learns delayed recall.
    Demo(demo::DemoArgs),
    /// Train methods on an experiment config, one run per (method, variant, seed), in parallel.
    Train(train::TrainArgs),
    /// Replay a macro-action log and print the trajectory as JSON lines.
    Replay(replay::ReplayArgs),
    /// Every run's metrics as one long CSV (experiment, method, variant, seed, then the
    /// metrics columns), for pandas or R.
    Results(results::ResultsArgs),
    /// Draw every experiment's learning curves (PNG + SVG) and summary tables from a results tree.
    Plot(plot::PlotArgs),
    /// Aggregate statistics per block and method (IQM, mean, median, optimality gap with 95%
    /// bootstrap intervals, probability of improvement), performance profiles,
    /// sample-efficiency curves, and the runs as marl-eval's JSON.
    Report(report::ReportArgs),
    /// Animate a trained run's greedy policy as a GIF.
    Render(render::RenderArgs),
    /// Write a Slurm job-array script (one task per run) to stdout.
    Slurm(slurm::SlurmArgs),
    /// Export a trained run's decentralized nets (Q-nets or actors) for robots: one safetensors
    /// file per agent and policy.json (domain, layout, architectures, run, SHA-256 of each file).
    Export(export::ExportArgs),
    /// Serve one agent of an exported policy to a robot: JSON lines on stdin/stdout, or over TCP
    /// with --listen (one hidden state per connection). See README "Exporting and running a policy".
    Robot(robot::RobotArgs),
    /// Run the policy's domain here and one `macdec robot` process per agent over loopback TCP,
    /// each robot seeing only its own observations; print one JSON line per episode.
    Deploy(deploy::DeployArgs),
    /// Retrain committed runs from their recorded config and check their metrics are identical
    /// (wall-clock column aside). Exits non-zero if any differs or cannot be retrained.
    Audit(audit::AuditArgs),
    /// Build a policy directory (as `export` writes) from PyTorch state_dicts of the reference
    /// code's DDRQN, one safetensors file per agent (scripts/torch_to_safetensors.py converts
    /// torch.save'd modules). See README "Bringing policies trained with the reference code".
    Import(import::ImportArgs),
    /// Greedy evaluation of a policy directory in this process (no robot processes): the same
    /// JSON line per episode as `deploy`, printed as each episode ends.
    Eval(eval::EvalArgs),
    /// Run the policy's domain here against robots already listening elsewhere (`macdec robot
    /// --listen` on each robot, or the ROS bridge `ros/macdec_domain_node.py`); the same JSON
    /// line per episode as `deploy`. See README "Running on robots with ROS".
    Domain(domain::DomainArgs),
    /// Measure speed.
    Bench(bench::BenchArgs),
}

/// The whole `macdec` command line over the built-in domains and `domains`, a program's own
/// ([`crate::envs::Domain`]): configs select them by `env_name`, and `train` (with `--jobs`,
/// resume and `finished` markers), `plot` (with the domain's optimum), `export`, `eval`,
/// `deploy`, `robot`, `domain`, `audit`, `slurm` and `render` (if the domain draws) work on them
/// as on the built-in ones.
///
/// ```no_run
/// # use macdec::envs::domain::KeyError;
/// # struct MyDomain;
/// # impl macdec::envs::Domain for MyDomain {
/// #     type Env = macdec::envs::box_pushing::BoxPushing;
/// #     fn name(&self) -> &'static str { "mine" }
/// #     fn keys(&self, _: &toml::Table) -> Result<toml::Table, KeyError> { todo!() }
/// #     fn build(&self, _: &toml::Table) -> Result<Self::Env, KeyError> { todo!() }
/// # }
/// fn main() -> std::process::ExitCode {
///     macdec::cli::main_with(&[&MyDomain])
/// }
/// ```
pub fn main_with(
    domains: &[&'static dyn crate::envs::registry::DomainEntry],
) -> std::process::ExitCode {
    for domain in domains {
        if let Err(e) = crate::envs::registry::register(*domain) {
            eprintln!("Error: registering domain `{}`: {e}", domain.name());
            return std::process::ExitCode::FAILURE;
        }
    }
    main()
}

/// The `macdec` command line over the built-in domains: parse `std::env::args`, run the
/// subcommand, print any error with its causes, and return the exit code.
pub fn main() -> std::process::ExitCode {
    match run() {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{}", error_report(&e));
            std::process::ExitCode::FAILURE
        }
    }
}

/// The error and its causes, one per line, leaving out a cause whose text the line above already
/// includes (library errors print their source inline, so anyhow's chain would repeat it).
fn error_report(e: &anyhow::Error) -> String {
    let mut lines = vec![format!("Error: {e}")];
    let mut shown = e.to_string();
    for cause in e.chain().skip(1) {
        let text = cause.to_string();
        if !shown.contains(&text) {
            lines.push(format!("  caused by: {text}"));
            shown.push('\n');
            shown.push_str(&text);
        }
    }
    lines.join("\n")
}

fn run() -> Result<()> {
    match Cli::parse().command {
        Command::Train(args) => train::run(args),
        Command::Replay(args) => replay::run(args),
        Command::Export(args) => export::run(args),
        Command::Robot(args) => robot::run(args),
        Command::Deploy(args) => deploy::run(args),
        Command::Import(args) => import::run(args),
        Command::Eval(args) => eval::run(args),
        Command::Domain(args) => domain::run(args),
        Command::Slurm(args) => slurm::run(args),
        Command::Audit(args) => audit::run(args),
        Command::Render(args) => render::run(args),
        Command::Results(args) => results::run(args),
        Command::Plot(args) => plot::run(args),
        Command::Report(args) => report::run(args),
        Command::Demo(args) => demo::run(args),
        Command::Bench(args) => bench::run(args),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::error::ErrorKind;
    use clap::CommandFactory;

    /// `macdec <subcommand> <flags>` parsed as the binary parses it.
    pub(super) fn parse(subcommand: &str, flags: &[&str]) -> Result<Command, clap::Error> {
        let argv = ["macdec", subcommand]
            .into_iter()
            .chain(flags.iter().copied());
        Cli::try_parse_from(argv).map(|cli| cli.command)
    }

    /// The parsed subcommand. Panics with clap's message if the command line is refused.
    pub(super) fn accepted(subcommand: &str, flags: &[&str]) -> Command {
        parse(subcommand, flags).unwrap_or_else(|e| {
            panic!("`macdec {subcommand} {}` was refused: {e}", flags.join(" "))
        })
    }

    /// Asserts that the command line is refused with an error of `kind` whose message contains
    /// `message`. Panics if it is accepted.
    pub(super) fn assert_refused(subcommand: &str, flags: &[&str], kind: ErrorKind, message: &str) {
        let shown = format!("`macdec {subcommand} {}`", flags.join(" "));
        let e = match parse(subcommand, flags) {
            Ok(_) => panic!("{shown} was accepted"),
            Err(e) => e,
        };
        let text = e.to_string();
        assert_eq!(e.kind(), kind, "{shown}: {text}");
        assert!(
            text.contains(message),
            "{shown}: `{message}` is not in: {text}"
        );
    }

    /// The message of a handler's error, with its causes as `main` prints them.
    pub(super) fn error_text(result: Result<()>) -> String {
        error_report(&result.expect_err("the handler should have failed"))
    }

    #[test]
    fn the_command_line_passes_clap_s_own_checks() {
        // Duplicate flags, a `mut_arg` naming no argument, a default its parser refuses, ...
        Cli::command().debug_assert();
    }

    #[test]
    fn the_subcommands_keep_their_names_and_help_order() {
        let names: Vec<String> = Cli::command()
            .get_subcommands()
            .map(|c| c.get_name().to_string())
            .collect();
        assert_eq!(
            names,
            [
                "demo", "train", "replay", "results", "plot", "report", "render", "slurm",
                "export", "robot", "deploy", "audit", "import", "eval", "domain", "bench"
            ]
        );
    }

    #[test]
    fn a_subcommand_is_required_and_an_unknown_one_refused() {
        let none = Cli::try_parse_from(["macdec"]).map(|_| ()).unwrap_err();
        assert_eq!(
            none.kind(),
            ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
        );
        assert_refused("nosuch", &[], ErrorKind::InvalidSubcommand, "'nosuch'");
    }

    #[test]
    fn error_report_shows_a_cause_once() {
        let inner = anyhow::anyhow!("disk full");
        assert_eq!(
            error_report(&inner.context("writing results/x")),
            "Error: writing results/x\n  caused by: disk full"
        );
        // A library error that prints its source inline: the cause adds nothing.
        let inline = anyhow::anyhow!("disk full").context("writing results/x: disk full");
        assert_eq!(error_report(&inline), "Error: writing results/x: disk full");
    }
}
