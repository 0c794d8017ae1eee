//! The `macdec` command line: parse flags, call the library, report. The `macdec` binary is
//! [`main`]; a user's own binary gets the same command line for its own domains with
//! [`main_with`].

use crate::algos::method::Method;
use crate::bench::nets;
use crate::experiment::config::{Experiment, Overrides, DEFAULT_EXPERIMENT};
use crate::experiment::policy_files::NetRole;
use crate::experiment::results_tree;
use crate::experiment::runner::{RunStatus, RunnerOptions};
use crate::experiment::seeds::parse_seeds;
use crate::experiment::slurm::{job_script, SlurmOptions};
use crate::experiment::stop::StopSignal;
use crate::experiment::train_all::train_all;
use crate::nn::demo;
use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand, ValueEnum};
use std::io::Write;
use std::path::{Path, PathBuf};

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
    Demo {
        /// Number of Adam steps.
        #[arg(long, default_value_t = demo::DemoConfig::default().steps)]
        steps: usize,
        /// Seed of the run.
        #[arg(long, default_value_t = 0)]
        seed: u64,
    },
    /// Train methods on an experiment config, one run per (method, variant, seed), in parallel.
    Train(TrainArgs),
    /// Replay a macro-action log and print the trajectory as JSON lines.
    Replay {
        /// JSON file: {"env": "box-pushing", "grid": 10, "horizon": 100, "steps": [[a0, a1], ...]}
        #[arg(long)]
        actions: PathBuf,
        /// Also print an ASCII picture of the state after every step (to stderr).
        #[arg(long)]
        verbose: bool,
    },
    /// Every run's metrics as one long CSV (experiment, method, variant, seed, then the
    /// metrics columns), for pandas or R.
    Results {
        /// Results root: <results>/<experiment>/<curve>/seed-<k>/metrics.csv[.gz] (also one
        /// level deeper, as in reproduction/macromarl/<block>/...).
        #[arg(long, default_value = "results")]
        results: PathBuf,
        /// The CSV file to write (atomically); without it, the table goes to stdout.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Draw every experiment's learning curves (PNG + SVG) and summary tables from a results tree.
    Plot {
        /// Results root: <results>/<experiment>/<curve>/seed-<k>/metrics.csv.
        #[arg(long, default_value = "results")]
        results: PathBuf,
        /// Where the figures and <experiment>_summary.csv files go (default: the results root,
        /// as `train` does; only an explicit `--out plots` redraws the committed figures).
        #[arg(long)]
        out: Option<PathBuf>,
        /// The metrics.csv column to plot: eval_return, or any other (env_steps, updates, a
        /// method family's own such as loss or epsilon); files become <experiment>_<metric>.*.
        #[arg(long, default_value = "eval_return")]
        metric: String,
        /// Centred moving average before drawing and reading "95% of optimal first at":
        /// `auto` (half window = evaluation points / 40, at most 10: 21 points on long runs,
        /// none under 40 points), `0` (none), an odd number of evaluation points (`21`), or
        /// training episodes (`2000ep`).
        #[arg(long, default_value = "auto", value_parser = crate::curve_stats::Smoothing::parse)]
        smooth: crate::curve_stats::Smoothing,
    },
    /// Animate a trained run's greedy policy as a GIF.
    Render {
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
    },
    /// Write a Slurm job-array script (one task per run) to stdout.
    Slurm(SlurmArgs),
    /// Export a trained run's decentralized nets (Q-nets or actors) for robots: one safetensors
    /// file per agent and policy.json (domain, layout, architectures, run, SHA-256 of each file).
    Export {
        /// A run directory: <results>/<experiment>/<method>/seed-<k>.
        #[arg(long)]
        run: PathBuf,
        /// The policy directory to write.
        #[arg(long)]
        out: PathBuf,
    },
    /// Serve one agent of an exported policy to a robot: JSON lines on stdin/stdout, or over TCP
    /// with --listen (one hidden state per connection). See README "Exporting and running a policy".
    Robot(RobotArgs),
    /// Run the policy's domain here and one `macdec robot` process per agent over loopback TCP,
    /// each robot seeing only its own observations; print one JSON line per episode.
    Deploy(DeployArgs),
    /// Retrain committed runs from their recorded config and check their metrics are identical
    /// (wall-clock column aside). Exits non-zero if any differs or cannot be retrained.
    Audit(AuditArgs),
    /// Build a policy directory (as `export` writes) from PyTorch state_dicts of the reference
    /// code's DDRQN, one safetensors file per agent (scripts/torch_to_safetensors.py converts
    /// torch.save'd modules). See README "Bringing policies trained with the reference code".
    Import(ImportArgs),
    /// Greedy evaluation of a policy directory in this process (no robot processes): the same
    /// JSON line per episode as `deploy`, printed as each episode ends.
    Eval(EvalArgs),
    /// Run the policy's domain here against robots already listening elsewhere (`macdec robot
    /// --listen` on each robot, or the ROS bridge `ros/macdec_domain_node.py`); the same JSON
    /// line per episode as `deploy`. See README "Running on robots with ROS".
    Domain(DomainArgs),
    /// Measure speed.
    Bench {
        /// What to measure.
        what: BenchTarget,
        /// Timed iterations per configuration (nets).
        #[arg(long, default_value_t = 200)]
        iters: usize,
        /// Only the configuration with this name (nets: e.g. torch-wtd; train: e.g. "bp10 our1").
        #[arg(long)]
        only: Option<String>,
        /// Training episodes per run (train).
        #[arg(long, default_value_t = 200)]
        episodes: usize,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum BenchTarget {
    /// Environment primitive steps per second with random macro-actions (single thread).
    Envs,
    /// One Q-net training update (forward, backward, Adam) at the paper's shapes, 1 thread.
    Nets,
    /// Whole training (first --episodes episodes) of every method on BP 10x10 and WTD, 1 thread;
    /// then two BP Our-1 runs at once on two threads against one alone.
    Train,
    /// The recurrent layer alone: GRU beside LSTM, forward + backward over sequences at the
    /// nets' shapes, 1 thread, time per step and per flop.
    Gru,
}

#[derive(clap::Args)]
struct AuditArgs {
    /// Results root holding finished runs: <results>/<experiment>/<curve>/seed-<k>/.
    #[arg(long, default_value = "reproduction")]
    results: PathBuf,
    /// How many finished runs to retrain, chosen at random (ignored with --run).
    #[arg(long, default_value_t = 3)]
    runs: usize,
    /// Retrain exactly these run directories instead (repeatable).
    #[arg(long)]
    run: Vec<PathBuf>,
    /// Seed of the random choice (default: from the clock; printed so a choice can be repeated).
    #[arg(long)]
    seed: Option<u64>,
    /// Runs retrained in parallel (default: the number of cores).
    #[arg(long)]
    jobs: Option<usize>,
}

#[derive(clap::Args)]
struct TrainArgs {
    #[command(flatten)]
    select: Selection,
    /// Runs in parallel (default: the number of cores; never more than the runs).
    #[arg(long, value_parser = at_least_one)]
    jobs: Option<usize>,
    /// Results root: runs go to <out>/<experiment>/<method>/seed-<k>/.
    #[arg(long, default_value = "results")]
    out: PathBuf,
    /// Recompute runs that already finished (their directories are replaced).
    #[arg(long)]
    force: bool,
    /// No progress bars; one line per finished run.
    #[arg(long)]
    quiet: bool,
    /// Where the learning-curve figures go after training (default: the results root --out, as
    /// <out>/<experiment>.png, so side runs never overwrite committed figures).
    #[arg(long)]
    plots: Option<PathBuf>,
    /// Do not draw figures after training.
    #[arg(long)]
    no_plot: bool,
    /// Run only the run with this index in the experiment's run list (Slurm array tasks).
    #[arg(long)]
    run_index: Option<usize>,
}

/// Which runs of an experiment, as `train` and `slurm` both select them.
#[derive(clap::Args)]
struct Selection {
    /// Experiment TOML (see experiments/); without it, a short built-in Box Pushing 10x10 run.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Comma-separated methods: dec-hddrqn, cen-ddrqn, our1, our1-r, our2 (ICRA 2020), mac-iac,
    /// mac-cac, naive-mac-iacc, naive-mac-iasc, mac-iaicc, mac-iaisc (MacroMARL).
    #[arg(long, value_delimiter = ',')]
    methods: Option<Vec<String>>,
    /// Seeds: a range `0..40` (end exclusive) or a list `0,3,7`.
    #[arg(long)]
    seeds: Option<String>,
    /// Override a config key, e.g. total_epi=300 or dec-hddrqn.init_h=0.3 (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
}

impl Selection {
    /// The experiment with the command line's methods, seeds and `--set` applied.
    fn load(&self) -> Result<Experiment> {
        let o = overrides(
            self.methods.clone(),
            self.seeds.as_deref(),
            self.set.clone(),
        )?;
        Ok(match &self.config {
            Some(path) => {
                Experiment::load(path, &o).with_context(|| format!("loading {}", path.display()))?
            }
            None => Experiment::parse(
                DEFAULT_EXPERIMENT,
                Path::new("<built-in default>"),
                "quickstart_bp10",
                &o,
            )?,
        })
    }
}

#[derive(clap::Args)]
struct SlurmArgs {
    #[command(flatten)]
    select: Selection,
    /// Results root shared by the cluster's nodes.
    #[arg(long, default_value = "results")]
    out: PathBuf,
    /// Wall-clock limit per array task.
    #[arg(long, default_value = "12:00:00")]
    time: String,
    /// Memory per array task.
    #[arg(long, default_value = "4G")]
    mem: String,
    /// Extra #SBATCH lines, e.g. --sbatch=--partition=cpu (repeatable).
    #[arg(long = "sbatch", value_name = "LINE", allow_hyphen_values = true)]
    sbatch: Vec<String>,
}

#[derive(clap::Args)]
struct RobotArgs {
    /// Exported policy directory (policy.json and one safetensors file per agent).
    #[arg(long)]
    policy: PathBuf,
    /// Which agent this robot is (0-based).
    #[arg(long)]
    agent: usize,
    /// Serve TCP on this address (e.g. 127.0.0.1:7000; port 0 picks a free one) instead of
    /// stdin/stdout. The first stdout line is {"listening": "ADDR"}.
    #[arg(long)]
    listen: Option<std::net::SocketAddr>,
    /// With --listen: connections served at once (one more is refused with an error line).
    #[arg(long, default_value_t = 16, value_parser = |t: &str| bounded_count(t, 4096))]
    max_connections: usize,
    /// Longest request line in bytes, at most 64 MiB; a longer one gets an error reply and is
    /// discarded.
    #[arg(long, default_value_t = crate::deploy::line_reader::MAX_LINE_BYTES,
          value_parser = |t: &str| bounded_count(t, 64 << 20))]
    max_line_bytes: usize,
    /// With --listen: close a connection silent between requests for this many seconds.
    #[arg(long, default_value_t = crate::deploy::server::DEFAULT_IDLE_TIMEOUT_SECS,
          value_parser = clap::value_parser!(u64).range(1..=86_400))]
    idle_timeout_secs: u64,
    /// Run a deterministic stand-in policy instead of the weights (tests).
    #[arg(long, hide = true)]
    mock: bool,
    /// Exit when stdin closes (set by `macdec deploy`, so robots never outlive it).
    #[arg(long, hide = true)]
    exit_on_stdin_close: bool,
}

/// The flags of every command that plays a policy's greedy episodes (`deploy`, `eval`,
/// `domain`), so the three take them with one spelling, one default and one meaning.
#[derive(clap::Args)]
struct EpisodeArgs {
    /// Policy directory (from `export` or `import`).
    #[arg(long)]
    policy: PathBuf,
    /// Episodes to run.
    #[arg(long, default_value_t = 1, value_parser = episode_count)]
    episodes: usize,
    /// Seed of the environment's random stream (default: the run's seed); the stream is the
    /// evaluation env's stream of that seed.
    #[arg(long)]
    seed: Option<u64>,
    /// Include every step (executed macro-actions, reward, finished flags) in the output.
    #[arg(long)]
    trajectories: bool,
}

#[derive(clap::Args)]
struct DeployArgs {
    #[command(flatten)]
    episodes: EpisodeArgs,
    /// Seconds to wait for a robot to start, and for each reply: the whole reply must arrive
    /// within this many seconds of its request (1 to 86400).
    #[arg(long, default_value_t = 30, value_parser = parse_timeout_secs)]
    timeout_secs: u64,
    /// Robots run the deterministic stand-in policy (tests).
    #[arg(long, hide = true)]
    mock: bool,
}

/// Whose trained nets `macdec import` reads.
#[derive(Clone, Copy, ValueEnum)]
enum ImportReference {
    /// The ICRA code's DDRQN Q-nets (`--env box-pushing` or `warehouse`).
    Icra,
    /// MacroMARL's GRU actors (`--env` a gym id such as `BP-MA-v0`, `--params`).
    Macromarl,
}

#[derive(clap::Args)]
struct ImportArgs {
    /// Whose nets: the ICRA code's Q-nets or MacroMARL's actors.
    #[arg(long, value_enum, default_value = "icra")]
    reference: ImportReference,
    /// The domain the policy was trained on: `box-pushing` or `warehouse` (icra); the gym id,
    /// e.g. `BP-MA-v0`, `OSD-T-v0`, `Overcooked-MA-v1` (macromarl).
    #[arg(long)]
    env: String,
    /// MacroMARL: a JSON object of the reference's keyword arguments for `gym.make` (e.g.
    /// `{"grid_dim": [14, 14]}`); the published values where absent.
    #[arg(long)]
    params: Option<PathBuf>,
    /// ICRA Box Pushing grid size N (N x N); the paper uses 10 and 30.
    #[arg(long, value_parser = |t: &str| bounded_count(t, crate::experiment::limits::MAX_GRID_DIM))]
    grid: Option<usize>,
    /// Episode length in primitive steps (ICRA paper: Box Pushing 100 on 10x10, 200 on 30x30,
    /// Warehouse 150; required for icra). MacroMARL: the published horizon by default.
    #[arg(long, value_parser = |t: &str| bounded_count(t, crate::experiment::limits::MAX_HORIZON))]
    horizon: Option<usize>,
    /// ICRA Warehouse: std of the Turtlebots' movement noise (paper 0).
    #[arg(long, default_value_t = 0.0)]
    tb_m_noisy: f64,
    /// Comma-separated state_dict safetensors files, one per agent, in agent order.
    #[arg(long, value_delimiter = ',', required = true)]
    agents: Vec<PathBuf>,
    /// Discount per primitive step of the reported return (default: the paper's, e.g. Box
    /// Pushing 0.98, Warehouse 1.0).
    #[arg(long)]
    discount: Option<f64>,
    /// The policy directory to write.
    #[arg(long)]
    out: PathBuf,
}

#[derive(clap::Args)]
struct EvalArgs {
    #[command(flatten)]
    episodes: EpisodeArgs,
    /// Sample each macro-action from the actors' distributions (MacroMARL's evaluation protocol)
    /// instead of taking the greedy one; actor policies only.
    #[arg(long)]
    sample: bool,
}

#[derive(clap::Args)]
// The robots must serve this very policy: said where `domain --help` describes --policy.
// (`mut_arg` moves the argument to the end; moving --robots after it keeps the usage line's
// order `--policy <POLICY> --robots <ROBOTS>`.)
#[command(mut_arg("policy", |a| a.help(
    "Policy directory the robots run (their `info` must report its manifest)"
)))]
#[command(mut_arg("robots", |a| a))]
struct DomainArgs {
    #[command(flatten)]
    episodes: EpisodeArgs,
    /// Comma-separated robot addresses in agent order, e.g. 127.0.0.1:7000,127.0.0.1:7001.
    // Listed right after --policy in the help, where it was before --policy moved to EpisodeArgs.
    #[arg(long, value_delimiter = ',', required = true, display_order = 0)]
    robots: Vec<std::net::SocketAddr>,
    /// Seconds to wait for a robot to accept the connection, and for each reply: the whole
    /// reply must arrive within this many seconds of its request (1 to 86400).
    #[arg(long, default_value_t = 30, value_parser = parse_timeout_secs)]
    timeout_secs: u64,
}

/// `--timeout-secs` of `deploy` and `domain`: a deadline per robot reply, 1 s to a day. 0
/// would fail every reply at once (or, as a socket timeout, wait forever).
fn parse_timeout_secs(text: &str) -> Result<u64, String> {
    const DAY: u64 = 86_400;
    match text.trim().parse::<u64>() {
        Ok(0) => Err("a timeout of 0 s gives no robot time to answer: use 1 to 86400".into()),
        Ok(s) if s > DAY => Err(format!("at most {DAY} s (one day), got {s}")),
        Ok(s) => Ok(s),
        Err(e) => Err(format!("expected whole seconds from 1 to {DAY}: {e}")),
    }
}

/// A count flag that must be at least 1 (0 would do nothing useful, silently).
fn at_least_one(text: &str) -> Result<usize, String> {
    match text.trim().parse::<usize>() {
        Ok(0) => Err("must be at least 1".into()),
        Ok(n) => Ok(n),
        Err(e) => Err(format!("expected a positive integer: {e}")),
    }
}

/// An episode count flag: at least 1 and at most a config's `eval_num_epi` may be
/// ([`MAX_EVAL_NUM_EPI`](crate::experiment::limits::MAX_EVAL_NUM_EPI)), so a flag cannot ask
/// for more than a config could.
fn episode_count(text: &str) -> Result<usize, String> {
    bounded_count(text, crate::experiment::limits::MAX_EVAL_NUM_EPI)
}

/// A count flag in 1..=`max`: a size from a flag is bounded like one from a config.
fn bounded_count(text: &str, max: usize) -> Result<usize, String> {
    match at_least_one(text)? {
        n if n > max => Err(format!("must be at most {max}, got {n}")),
        n => Ok(n),
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

/// `--net`: `cen` or `dec`, the names policy.json uses for the two kinds of net.
fn parse_net_role(text: &str) -> Result<NetRole, String> {
    match text {
        "cen" => Ok(NetRole::Cen),
        "dec" => Ok(NetRole::Dec),
        other => Err(format!("expected `cen` or `dec`, got `{other}`")),
    }
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
        Command::Train(args) => train(args),
        Command::Replay { actions, verbose } => replay(&actions, verbose),
        Command::Export { run, out } => export(&run, &out),
        Command::Robot(args) => robot(args),
        Command::Deploy(args) => deploy(args),
        Command::Import(args) => import(args),
        Command::Eval(args) => eval(args),
        Command::Domain(args) => domain(args),
        Command::Slurm(args) => slurm(args),
        Command::Audit(args) => audit(args),
        Command::Render {
            run,
            episodes,
            out,
            frame_ms,
            net,
        } => {
            refuse_policy_dir_as_run(&run)?;
            let choice = crate::deploy::drive::local_eval::Choice::Greedy;
            let returns =
                crate::render::rollout::render_run(&run, net, choice, episodes, &out, frame_ms)
                    .with_context(|| format!("rendering {}", run.display()))?;
            eprintln!(
                "wrote {} ({} episode(s), team returns {})",
                out.display(),
                returns.len(),
                summarize_returns(&returns)
            );
            Ok(())
        }
        Command::Results { results, out } => tidy_results(&results, out.as_deref()),
        Command::Plot {
            results,
            out,
            metric,
            smooth,
        } => {
            let out = out.unwrap_or_else(|| results.clone());
            let options = crate::plot::PlotOptions {
                metric,
                smoothing: smooth,
            };
            plot(&results, &out, &options)
        }
        Command::Demo { steps, seed } => demo_run(steps, seed),
        Command::Bench {
            what,
            iters,
            only,
            episodes,
        } => match what {
            BenchTarget::Train => bench_train(only.as_deref(), episodes),
            BenchTarget::Envs => bench_envs(),
            BenchTarget::Gru => {
                print!("{}", crate::bench::gru::run(only.as_deref(), iters));
                Ok(())
            }
            BenchTarget::Nets => {
                let results: Vec<_> = nets::SHAPES
                    .iter()
                    .filter(|s| only.as_deref().is_none_or(|o| o == s.name))
                    .map(|shape| nets::bench_shape(shape, iters, iters.div_ceil(10).max(3)))
                    .collect();
                print!("{}", nets::format_table(&results));
                Ok(())
            }
        },
    }
}

fn train(args: TrainArgs) -> Result<()> {
    let experiment = args.select.load()?;
    let mut runs = experiment.runs()?;
    if let Some(i) = args.run_index {
        if i >= runs.len() {
            bail!(
                "--run-index {i}: the experiment has {} runs (0..{})",
                runs.len(),
                runs.len()
            );
        }
        runs = vec![runs.swap_remove(i)];
    }
    let jobs = crate::experiment::limits::worker_threads(
        args.jobs
            .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())),
        runs.len(),
    );
    let opts = RunnerOptions {
        out: args.out.clone(),
        jobs,
        force: args.force,
        quiet: args.quiet,
    };
    eprintln!(
        "{}: {} run(s) ({} method(s) x {} seed(s)), {} at a time, results in {}",
        experiment.name,
        runs.len(),
        experiment.methods.len(),
        experiment.seeds.len(),
        jobs,
        args.out.join(&experiment.name).display()
    );
    let selected = |curve: &String| experiment.methods.iter().any(|m| m.name() == curve);
    for (curve, home) in experiment.shared_curves.iter().filter(|(c, _)| selected(c)) {
        eprintln!(
            "  {curve}: shared with {home}, runs in {}",
            args.out.join(home).join(curve).display()
        );
    }
    experiment
        .write_shared_curves(&args.out)
        .with_context(|| format!("recording the shared curves in {}", args.out.display()))?;
    let statuses = train_all(&runs, &opts, args.force, &StopSignal::new());
    let failed = statuses
        .iter()
        .filter(|s| matches!(s, RunStatus::Failed(_)))
        .count();
    let skipped = statuses
        .iter()
        .filter(|s| matches!(s, RunStatus::Skipped))
        .count();
    if skipped > 0 {
        eprintln!("{skipped} run(s) already finished, skipped (use --force to recompute)");
    }
    let busy = statuses
        .iter()
        .filter(|s| matches!(s, RunStatus::Busy))
        .count();
    if busy > 0 {
        eprintln!("{busy} run(s) left to other processes training them");
    }
    // A refused run's directory holds another run's curve, a busy one a curve still growing:
    // show neither as this command's.
    let shown: Vec<_> = runs
        .iter()
        .zip(&statuses)
        .filter(|(_, s)| !matches!(s, RunStatus::Failed(_) | RunStatus::Busy))
        .map(|(r, _)| r.clone())
        .collect();
    crate::experiment::report::print_curves(&args.out, &shown)?;
    if !args.no_plot {
        let plots = args.plots.as_deref().unwrap_or(&args.out);
        match crate::plot::plot_results(&args.out, plots) {
            Ok(report) => {
                for p in report
                    .plots
                    .iter()
                    .filter(|p| p.experiment == experiment.name)
                {
                    eprintln!(
                        "learning curves: {} and {}",
                        p.png.display(),
                        p.svg.display()
                    );
                }
            }
            Err(e) => eprintln!("note: no figure drawn: {e}"),
        }
    }
    if failed > 0 {
        bail!("{failed} of {} run(s) failed", runs.len());
    }
    Ok(())
}

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

fn slurm(args: SlurmArgs) -> Result<()> {
    let sel = args.select;
    let mut train_args = Vec::new();
    if let Some(m) = &sel.methods {
        train_args.extend(["--methods".to_string(), m.join(",")]);
    }
    if let Some(s) = &sel.seeds {
        train_args.extend(["--seeds".to_string(), s.clone()]);
    }
    for item in &sel.set {
        train_args.extend(["--set".to_string(), item.clone()]);
    }
    let config = sel
        .config
        .as_deref()
        .context("slurm needs --config FILE (the experiment the array tasks train)")?;
    let experiment = sel.load()?;
    let labels: Vec<String> = experiment
        .runs()?
        .iter()
        .map(|r| results_tree::run_label(&r.curve_name(), r.seed))
        .collect();
    let absolute = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let config = absolute(config);
    let out = absolute(&args.out);
    let binary = std::env::current_exe().context("locating the macdec binary")?;
    let script = job_script(
        &experiment.name,
        &labels,
        &SlurmOptions {
            config: &config,
            out: &out,
            binary: &binary,
            train_args,
            time: &args.time,
            mem: &args.mem,
            extra_sbatch: args.sbatch,
        },
    )?;
    print!("{script}");
    Ok(())
}

fn audit(args: AuditArgs) -> Result<()> {
    use crate::experiment::audit::{audit_all, choose, finished_runs, AuditOutcome};
    use crate::experiment::provenance::Provenance;
    let dirs = if args.run.is_empty() {
        let all = finished_runs(&args.results)?;
        if all.is_empty() {
            bail!("{}: no finished runs to audit", args.results.display());
        }
        if args.runs == 0 {
            bail!("--runs must be at least 1");
        }
        let seed = args.seed.unwrap_or_else(|| {
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_secs())
        });
        let chosen = choose(&all, args.runs, seed);
        eprintln!(
            "auditing {} of {} finished run(s) under {} (choice seed {seed})",
            chosen.len(),
            all.len(),
            args.results.display()
        );
        chosen
    } else {
        args.run.clone()
    };
    let here = Provenance::current();
    let jobs = args
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let results = audit_all(&dirs, jobs, |r| match r {
        Ok(a) => {
            println!("{}", a.line());
            if let Some(p) = &a.provenance {
                if !crate::autograd::kernels::same_arithmetic(&p.kernel_path, &here.kernel_path) {
                    println!(
                        "  note: trained on the {} kernel path, retrained on {}: rounding may differ",
                        p.kernel_path, here.kernel_path
                    );
                }
            }
        }
        Err((dir, e)) => println!("{}: CANNOT AUDIT: {e}", dir.display()),
    });
    let differ = results
        .iter()
        .filter(|r| matches!(r, Ok(a) if !matches!(a.outcome, AuditOutcome::Identical { .. })))
        .count();
    let unaudited = results.iter().filter(|r| r.is_err()).count();
    match (differ, unaudited) {
        (0, 0) => {}
        (d, 0) => bail!("{d} of {} audited run(s) differ", results.len()),
        (0, u) => bail!("{u} of {} run(s) could not be audited", results.len()),
        (d, u) => bail!(
            "{d} of {} run(s) differ and {u} could not be audited",
            results.len()
        ),
    }
    println!("all {} audited run(s) identical", results.len());
    Ok(())
}

fn demo_run(steps: usize, seed: u64) -> Result<()> {
    let cfg = demo::DemoConfig {
        steps,
        seed,
        ..demo::DemoConfig::default()
    };
    println!(
        "delayed recall with an LSTM Q-net: {} steps, batch {}, seed {} \
         (a net without memory cannot go below {:.4})",
        cfg.steps,
        cfg.batch,
        cfg.seed,
        demo::MEMORYLESS_LOSS
    );
    let t0 = std::time::Instant::now();
    demo::run(&cfg, |step, loss| {
        println!("step {step:>6}  loss {loss:.5}")
    })?;
    println!("done in {:.1} s", t0.elapsed().as_secs_f64());
    Ok(())
}

fn bench_train(only: Option<&str>, episodes: usize) -> Result<()> {
    use crate::algos::method::Method;
    use crate::bench::train;
    let mut rows = Vec::new();
    for (env, method) in train::suite() {
        if only.is_some_and(|o| o != train::name(&env, method)) {
            continue;
        }
        let row = train::bench_train(env, method, episodes)?;
        eprintln!("{}: {:.1} s", row.name, row.seconds);
        rows.push(row);
    }
    print!("{}", train::format_table(&rows));
    if only.is_none() {
        // Two runs on two threads should take no longer than one alone (no shared state).
        let one = train::bench_train(
            crate::envs::box_pushing::paper_spec(10),
            Method::Our1,
            episodes,
        )?;
        let (a, b) = rayon::join(
            || {
                train::bench_train(
                    crate::envs::box_pushing::paper_spec(10),
                    Method::Our1,
                    episodes,
                )
            },
            || {
                train::bench_train(
                    crate::envs::box_pushing::paper_spec(10),
                    Method::Our1,
                    episodes,
                )
            },
        );
        let (a, b) = (a?, b?);
        println!(
            "\nbp10 our1 alone: {:.1} s; two at once on two threads: {:.1} s and {:.1} s (ratio {:.2})",
            one.seconds,
            a.seconds,
            b.seconds,
            a.seconds.max(b.seconds) / one.seconds
        );
    }
    Ok(())
}

fn plot(results: &Path, out: &Path, options: &crate::plot::PlotOptions) -> Result<()> {
    let report = crate::plot::plot_results_with(results, out, options)
        .with_context(|| format!("plotting {} into {}", results.display(), out.display()))?;
    for note in &report.notes {
        eprintln!("{note}");
    }
    for p in &report.plots {
        eprintln!(
            "wrote {}, {}, {}, {}",
            p.png.display(),
            p.svg.display(),
            p.summary_csv.display(),
            p.tests_csv.display()
        );
    }
    print!("{}", report.markdown());
    Ok(())
}

fn tidy_results(results: &Path, out: Option<&Path>) -> Result<()> {
    use crate::experiment::tidy_table::{write_tidy_file, write_tidy_table};
    let context = || format!("tabulating the runs of {}", results.display());
    match out {
        Some(path) => {
            let (runs, rows) = write_tidy_file(results, path).with_context(context)?;
            eprintln!("wrote {} ({runs} runs, {rows} rows)", path.display());
        }
        None => {
            let mut stdout = std::io::BufWriter::new(std::io::stdout().lock());
            match write_tidy_table(results, &mut stdout) {
                // A reader that stops early (`| head`) is not an error.
                Err(crate::experiment::tidy_table::TidyError::Write { source, .. })
                    if source.kind() == std::io::ErrorKind::BrokenPipe => {}
                other => {
                    other.with_context(context)?;
                }
            }
        }
    }
    Ok(())
}

fn replay(path: &Path, verbose: bool) -> Result<()> {
    use crate::envs::replay::{parse_replay, stream_replay};
    let text = crate::files::bounded_read::read_text_file(
        path,
        crate::files::bounded_read::MAX_ACTIONS_BYTES,
    )
    .with_context(|| format!("reading replay file {}", path.display()))?;
    let file = parse_replay(&text).with_context(|| format!("parsing {}", path.display()))?;
    drop(text);
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    let unused = stream_replay(&file, verbose, &mut |frame| {
        serde_json::to_writer(&mut out, &frame.line).map_err(std::io::Error::from)?;
        writeln!(out)?;
        if let Some(picture) = &frame.picture {
            out.flush()?;
            eprintln!("{picture}");
        }
        Ok(())
    })
    .with_context(|| format!("replaying {}", path.display()))?;
    out.flush()?;
    if unused > 0 {
        eprintln!("note: the episode ended with {unused} rows of `steps` unused");
    }
    Ok(())
}

fn bench_envs() -> Result<()> {
    const MIN_STEPS: u64 = 20_000_000;
    println!("environment primitive steps/s, random macro-actions, single thread, >= {MIN_STEPS} steps each");
    for (name, spec) in crate::envs::bench::bench_suite() {
        let r = crate::envs::bench::bench_env(name, spec, MIN_STEPS)
            .with_context(|| format!("benchmarking {name}"))?;
        println!(
            "{:<34} {:>12.0} steps/s  ({} steps, {} episodes, {:.2} s)",
            r.name, r.steps_per_second, r.steps, r.episodes, r.seconds
        );
    }
    Ok(())
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

/// Fresh policies (zero hidden state) for agent `agent`'s robot, one per connection.
fn policy_factory(
    manifest: &crate::deploy::Manifest,
    verified: &crate::deploy::VerifiedAgent,
    mock: bool,
) -> Result<crate::deploy::server::PolicyFactory> {
    use crate::deploy::{mock::MockPolicy, AgentPolicy};
    let entry = &manifest.agents[verified.index];
    if mock {
        let (obs, n, salt) = (entry.obs_size, entry.n_actions, entry.index as u64);
        return Ok(std::sync::Arc::new(move || {
            Box::new(MockPolicy::new(obs, n, salt)) as Box<dyn AgentPolicy>
        }));
    }
    let net = crate::deploy::net_policy::load_net(manifest, verified)?;
    Ok(crate::deploy::net_policy::net_factory(net))
}

fn export(run: &Path, out: &Path) -> Result<()> {
    let manifest = crate::deploy::export::export_run(run, out)
        .with_context(|| format!("exporting {} to {}", run.display(), out.display()))?;
    if !results_tree::is_finished(run) {
        eprintln!(
            "warning: {} has not finished training: exported its nets after {} episodes",
            run.display(),
            manifest.run.episodes_trained
        );
    }
    eprintln!(
        "exported {} agent(s) of {} ({} seed {}, {} episodes trained) to {}",
        manifest.agents.len(),
        manifest.env.name(),
        manifest.run.method,
        manifest.run.seed,
        manifest.run.episodes_trained,
        out.display()
    );
    Ok(())
}

fn robot(args: RobotArgs) -> Result<()> {
    use crate::deploy::{manifest::load_agent, processes, RobotSpec};
    let (manifest, verified) = load_agent(&args.policy, args.agent)
        .with_context(|| format!("loading agent {} of {}", args.agent, args.policy.display()))?;
    let spec = std::sync::Arc::new(RobotSpec::new(&manifest, args.agent)?);
    let factory = policy_factory(&manifest, &verified, args.mock)?;
    if args.exit_on_stdin_close && args.listen.is_some() {
        processes::exit_when_stdin_closes();
    }
    match args.listen {
        None => {
            crate::deploy::serve_stdio(factory(), spec, args.max_line_bytes)?;
        }
        Some(addr) => {
            let listener = std::net::TcpListener::bind(addr)
                .with_context(|| format!("listening on {addr}"))?;
            let bound = listener.local_addr()?;
            {
                let mut out = std::io::stdout().lock();
                writeln!(out, "{}", processes::announcement(bound))?;
                out.flush()?;
            }
            eprintln!(
                "robot for agent {} of {} listening on {bound}",
                args.agent,
                args.policy.display()
            );
            let limits = crate::deploy::Limits {
                max_line_bytes: args.max_line_bytes,
                max_connections: args.max_connections,
                idle_timeout: Some(std::time::Duration::from_secs(args.idle_timeout_secs)),
                ..Default::default()
            };
            crate::deploy::serve_tcp(listener, factory, spec, limits)?;
        }
    }
    Ok(())
}

/// A loaded policy directory and the evaluation stream its episodes draw from.
struct EpisodeRun {
    manifest: crate::deploy::Manifest,
    verified: Vec<crate::deploy::VerifiedAgent>,
    /// `--seed`, or the run's seed.
    seed: u64,
    rng: crate::envs::EnvRng,
}

impl EpisodeArgs {
    /// The policy (manifest and verified weights) and the evaluation env's stream of the seed.
    /// Every episode command simulates the domain, so a custom domain's policy is refused here.
    fn load(&self) -> Result<EpisodeRun> {
        use crate::experiment::seeds::{stream, Role};
        let (manifest, verified) = crate::deploy::manifest::load_all(&self.policy)
            .with_context(|| format!("loading policy {}", self.policy.display()))?;
        manifest
            .env
            .known()
            .with_context(|| format!("running episodes of {}", self.policy.display()))?;
        let seed = self.seed.unwrap_or(manifest.run.seed);
        Ok(EpisodeRun {
            manifest,
            verified,
            seed,
            rng: stream(seed, Role::EvalEnv),
        })
    }
}

/// Prints each episode's JSON line to stdout as it ends (flushed, so a long run streams) and
/// keeps the sums the summary line reports.
struct EpisodePrinter {
    trajectories: bool,
    count: usize,
    discounted: f64,
    undiscounted: f64,
}

impl EpisodePrinter {
    fn new(trajectories: bool) -> Self {
        Self {
            trajectories,
            count: 0,
            discounted: 0.0,
            undiscounted: 0.0,
        }
    }

    fn print(
        &mut self,
        trace: crate::deploy::EpisodeTrace,
    ) -> Result<(), crate::deploy::driver::DeployError> {
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
    fn summary(&self, run: &EpisodeRun, place: &str) -> String {
        format!(
            "{} episode(s) of {} {place}, seed {}: mean discounted return {:.4}",
            self.count,
            run.manifest.env.name(),
            run.seed,
            self.discounted / self.count.max(1) as f64
        )
    }

    fn mean_undiscounted(&self) -> f64 {
        self.undiscounted / self.count.max(1) as f64
    }
}

fn deploy(args: DeployArgs) -> Result<()> {
    use crate::deploy::processes::deploy_streaming;
    let mut run = args.episodes.load()?;
    let exe = std::env::current_exe().context("locating the macdec executable")?;
    let extra: Vec<String> = if args.mock {
        vec!["--mock".into()]
    } else {
        vec![]
    };
    let mut printer = EpisodePrinter::new(args.episodes.trajectories);
    deploy_streaming(
        &exe,
        &args.episodes.policy,
        &run.manifest,
        &extra,
        args.episodes.episodes,
        &mut run.rng,
        std::time::Duration::from_secs(args.timeout_secs),
        |trace| printer.print(trace),
    )
    .with_context(|| format!("deploying {}", args.episodes.policy.display()))?;
    let place = format!("with {} robot process(es)", run.manifest.agents.len());
    eprintln!("{}", printer.summary(&run, &place));
    Ok(())
}

fn import(args: ImportArgs) -> Result<()> {
    use crate::deploy::import::{import_policy, ImportRequest};
    use crate::deploy::import_actors::import_actors;
    let env = import_env(&args)?;
    let request = ImportRequest {
        discount: args
            .discount
            .or_else(|| env.paper_discount())
            .unwrap_or(1.0),
        env,
        agents: args.agents,
    };
    let manifest = match args.reference {
        ImportReference::Icra => import_policy(&request, &args.out),
        ImportReference::Macromarl => import_actors(&request, &args.out),
    }
    .with_context(|| format!("importing into {}", args.out.display()))?;
    let arch = &manifest.nets[0].architecture;
    eprintln!(
        "imported {} agent(s) of {} ({} {} / {}, discount {}) to {}",
        manifest.agents.len(),
        manifest.env.name(),
        arch.kind,
        arch.mlp_out_size
            .map_or(arch.mlp_layer_size.to_string(), |m1| format!(
                "[{}, {m1}]",
                arch.mlp_layer_size
            )),
        arch.rnn_h_size,
        manifest.discount,
        args.out.display()
    );
    Ok(())
}

/// The domain `macdec import` names: ICRA's by `--env`, `--grid`, `--horizon`, `--tb-m-noisy`;
/// MacroMARL's by its gym id, `--params` (the reference's keyword arguments) and `--horizon`.
fn import_env(args: &ImportArgs) -> Result<crate::envs::EnvSpec> {
    use crate::envs::domain::{json_to_toml, key_table, HORIZON_KEY};
    use crate::envs::EnvSpec;
    let horizon = |h: usize| (HORIZON_KEY, toml::Value::from(h as i64));
    match args.reference {
        ImportReference::Icra => {
            let Some(h) = args.horizon else {
                bail!("--reference icra needs --horizon (the episode length in primitive steps)")
            };
            if args.params.is_some() {
                bail!("--params is for --reference macromarl");
            }
            Ok(match (args.env.as_str(), args.grid) {
                ("box-pushing", Some(grid)) => EnvSpec::new(
                    "box-pushing",
                    &key_table([("grid_dim", (grid as i64).into()), horizon(h)]),
                ),
                ("box-pushing", None) => bail!("--env box-pushing needs --grid N"),
                ("warehouse", None) => EnvSpec::new(
                    "warehouse",
                    &key_table([horizon(h), ("tb_m_noisy", args.tb_m_noisy.into())]),
                ),
                ("warehouse", Some(_)) => bail!("--grid is for box-pushing; warehouse has none"),
                (other, _) => {
                    bail!("--reference icra: --env must be box-pushing or warehouse, got `{other}`")
                }
            }?)
        }
        ImportReference::Macromarl => {
            if args.grid.is_some() {
                bail!("--grid is for --reference icra; MacroMARL's grid is `grid_dim` in --params");
            }
            let mut given = toml::Table::new();
            if let Some(path) = &args.params {
                let text = crate::files::bounded_read::read_regular_file(path, 1 << 20)
                    .with_context(|| format!("reading {}", path.display()))?;
                let value: serde_json::Value = serde_json::from_slice(&text)
                    .with_context(|| format!("parsing {}", path.display()))?;
                let serde_json::Value::Object(map) = value else {
                    bail!(
                        "{}: expected a JSON object of keyword arguments",
                        path.display()
                    );
                };
                for (k, v) in map {
                    let v = json_to_toml(&v)
                        .with_context(|| format!("{}: `{k}` holds a null", path.display()))?;
                    given.insert(k, v);
                }
            }
            if let Some(h) = args.horizon {
                given.insert(HORIZON_KEY.into(), (h as i64).into());
            }
            Ok(EnvSpec::new(&args.env, &given)?)
        }
    }
}

fn eval(args: EvalArgs) -> Result<()> {
    let sample = args.sample;
    let args = args.episodes;
    let mut run = args.load()?;
    let mut printer = EpisodePrinter::new(args.trajectories);
    let choice = if sample {
        crate::deploy::local_eval::Choice::Sampled
    } else {
        crate::deploy::local_eval::Choice::Greedy
    };
    crate::deploy::local_eval::eval_policy(
        &run.manifest,
        &run.verified,
        args.episodes,
        choice,
        &mut run.rng,
        |trace| printer.print(trace),
    )
    .with_context(|| format!("evaluating {}", args.policy.display()))?;
    eprintln!(
        "{}, mean undiscounted {:.4}",
        printer.summary(&run, "in-process"),
        printer.mean_undiscounted()
    );
    Ok(())
}

fn domain(args: DomainArgs) -> Result<()> {
    let mut run = args.episodes.load()?;
    let mut printer = EpisodePrinter::new(args.episodes.trajectories);
    crate::deploy::remote::run_with_robots_at(
        &run.manifest,
        &args.robots,
        args.episodes.episodes,
        &mut run.rng,
        std::time::Duration::from_secs(args.timeout_secs),
        |trace| printer.print(trace),
    )
    .with_context(|| {
        format!(
            "running {} against its robots",
            args.episodes.policy.display()
        )
    })?;
    let place = format!("with {} remote robot(s)", run.manifest.agents.len());
    eprintln!("{}", printer.summary(&run, &place));
    Ok(())
}
