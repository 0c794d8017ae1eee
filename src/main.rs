//! The `macdec` command line: parse, call the library, report. No logic lives here.

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand, ValueEnum};
use macdec::algos::method::Method;
use macdec::experiment::config::{Experiment, Overrides, DEFAULT_EXPERIMENT};
use macdec::experiment::runner::{run_all, RunStatus, RunnerOptions};
use macdec::experiment::seeds::parse_seeds;
//TMP use macdec::experiment::train_run::train_run;
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
    /// Serve one agent of an exported policy to a robot: JSON lines on stdin/stdout, or over TCP
    /// with --listen (one hidden state per connection). See README "Exporting and running a policy".
    Robot(RobotArgs),
    /// Run the policy's domain here and one `macdec robot` process per agent over loopback TCP,
    /// each robot seeing only its own observations; print one JSON line per episode.
    Deploy(DeployArgs),
    /// Measure speed.
    Bench {
        /// What to measure.
        what: BenchTarget,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum BenchTarget {
    /// Environment primitive steps per second with random macro-actions (single thread).
    Envs,
}

#[derive(clap::Args)]
struct TrainArgs {
    /// Experiment TOML (see experiments/); without it, a short built-in Box Pushing 10x10 run.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Comma-separated methods: dec-hddrqn, cen-ddrqn, our1, our1-r, our2.
    #[arg(long, value_delimiter = ',')]
    methods: Option<Vec<String>>,
    /// Seeds: a range `0..40` (end exclusive) or a list `0,3,7`.
    #[arg(long)]
    seeds: Option<String>,
    /// Runs in parallel (default: the number of cores).
    #[arg(long)]
    jobs: Option<usize>,
    /// Results root: runs go to <out>/<experiment>/<method>/seed-<k>/.
    #[arg(long, default_value = "results")]
    out: PathBuf,
    /// Override a config key, e.g. total_epi=300 or dec-hddrqn.init_h=0.3 (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
    /// Recompute runs that already finished (their directories are replaced).
    #[arg(long)]
    force: bool,
    /// No progress bars; one line per finished run.
    #[arg(long)]
    quiet: bool,
}

#[derive(clap::Args)]
struct RobotArgs {
    /// Exported policy directory (manifest.json and one safetensors file per agent).
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
    #[arg(long, default_value_t = 16)]
    max_connections: usize,
    /// Longest request line in bytes; a longer one gets an error reply and is discarded.
    #[arg(long, default_value_t = macdec::deploy::line_reader::MAX_LINE_BYTES)]
    max_line_bytes: usize,
    /// With --listen: close a connection idle for this many seconds (default: never).
    #[arg(long)]
    idle_timeout_secs: Option<u64>,
    /// Run a deterministic stand-in policy instead of the weights (tests).
    #[arg(long, hide = true)]
    mock: bool,
    /// Exit when stdin closes (set by `macdec deploy`, so robots never outlive it).
    #[arg(long, hide = true)]
    exit_on_stdin_close: bool,
}

#[derive(clap::Args)]
struct DeployArgs {
    /// Exported policy directory.
    #[arg(long)]
    policy: PathBuf,
    /// Episodes to run.
    #[arg(long, default_value_t = 1)]
    episodes: usize,
    /// Seed of the environment's random stream (default: the run's seed); the stream is the
    /// evaluation env's stream of that seed.
    #[arg(long)]
    seed: Option<u64>,
    /// Include every step (executed macro-actions, reward, finished flags) in the output.
    #[arg(long)]
    trajectories: bool,
    /// Seconds to wait for a robot to start or to answer one message.
    #[arg(long, default_value_t = 30)]
    timeout_secs: u64,
    /// Robots run the deterministic stand-in policy (tests).
    #[arg(long, hide = true)]
    mock: bool,
}

fn main() -> Result<()> {
    match Cli::parse().command {
        Command::Train(args) => train(args),
        Command::Replay { actions, verbose } => replay(&actions, verbose),
        Command::Robot(args) => robot(args),
        Command::Deploy(args) => deploy(args),
        Command::Bench { what } => match what {
            BenchTarget::Envs => bench_envs(),
        },
    }
}

fn train(args: TrainArgs) -> Result<()> {
    let methods = args
        .methods
        .map(|names| {
            names
                .iter()
                .map(|n| n.parse::<Method>())
                .collect::<Result<Vec<_>, _>>()
        })
        .transpose()?;
    let seeds = args.seeds.as_deref().map(parse_seeds).transpose()?;
    let overrides = Overrides {
        methods,
        seeds,
        set: args.set,
    };
    let experiment = match &args.config {
        Some(path) => Experiment::load(path, &overrides)
            .with_context(|| format!("loading {}", path.display()))?,
        None => Experiment::parse(
            DEFAULT_EXPERIMENT,
            Path::new("<built-in default>"),
            "quickstart_bp10",
            &overrides,
        )?,
    };
    let runs = experiment.runs()?;
    let jobs = args
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
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
    let force = args.force;
    let statuses = run_all(&runs, &opts, |spec, dir, progress| {
        let _ = (spec, dir, progress, force);
        Err("trainer not merged yet".to_string())
    });
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
    macdec::experiment::report::print_curves(&args.out, &runs)?;
    if failed > 0 {
        bail!("{failed} of {} run(s) failed", runs.len());
    }
    Ok(())
}

fn replay(path: &Path, verbose: bool) -> Result<()> {
    use macdec::envs::replay::{parse_replay, run_replay};
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("reading replay file {}", path.display()))?;
    let file = parse_replay(&text).with_context(|| format!("parsing {}", path.display()))?;
    let replay =
        run_replay(&file, verbose).with_context(|| format!("replaying {}", path.display()))?;
    let mut out = std::io::stdout().lock();
    for frame in &replay.frames {
        serde_json::to_writer(&mut out, &frame.line)?;
        writeln!(out)?;
        if let Some(picture) = &frame.picture {
            out.flush()?;
            eprintln!("{picture}");
        }
    }
    if replay.unused_steps > 0 {
        eprintln!(
            "note: the episode ended with {} rows of `steps` unused",
            replay.unused_steps
        );
    }
    Ok(())
}

fn bench_envs() -> Result<()> {
    const MIN_STEPS: u64 = 20_000_000;
    println!("environment primitive steps/s, random macro-actions, single thread, >= {MIN_STEPS} steps each");
    for (name, spec) in macdec::envs::bench::bench_suite() {
        let r = macdec::envs::bench::bench_env(name, spec, MIN_STEPS)
            .with_context(|| format!("benchmarking {name}"))?;
        println!(
            "{:<34} {:>12.0} steps/s  ({} steps, {} episodes, {:.2} s)",
            r.name, r.steps_per_second, r.steps, r.episodes, r.seconds
        );
    }
    Ok(())
}

/// Fresh policies (zero hidden state) for agent `agent`'s robot, one per connection.
fn policy_factory(
    manifest: &macdec::deploy::Manifest,
    verified: &macdec::deploy::VerifiedAgent,
    mock: bool,
) -> Result<macdec::deploy::server::PolicyFactory> {
    use macdec::deploy::{mock::MockPolicy, AgentPolicy};
    let entry = &manifest.agents[verified.index];
    if mock {
        let (obs, n, salt) = (entry.obs_size, entry.n_actions, entry.index as u64);
        return Ok(std::sync::Arc::new(move || {
            Box::new(MockPolicy::new(obs, n, salt)) as Box<dyn AgentPolicy>
        }));
    }
    // LEAD: build the QNet from `verified.weights` (safetensors bytes, checked against the
    // manifest's architecture) and return a factory cloning it with a zero LSTM state.
    bail!("running exported Q-nets is not wired in yet (the nets land with issue 3); use the test-only --mock")
}

fn robot(args: RobotArgs) -> Result<()> {
    use macdec::deploy::{manifest::load_agent, processes, RobotSpec};
    let (manifest, verified) = load_agent(&args.policy, args.agent)
        .with_context(|| format!("loading agent {} of {}", args.agent, args.policy.display()))?;
    let spec = std::sync::Arc::new(RobotSpec::new(&manifest, args.agent)?);
    let factory = policy_factory(&manifest, &verified, args.mock)?;
    if args.exit_on_stdin_close && args.listen.is_some() {
        processes::exit_when_stdin_closes();
    }
    match args.listen {
        None => {
            macdec::deploy::serve_stdio(factory(), spec, args.max_line_bytes)?;
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
            let limits = macdec::deploy::Limits {
                max_line_bytes: args.max_line_bytes,
                max_connections: args.max_connections,
                idle_timeout: args.idle_timeout_secs.map(std::time::Duration::from_secs),
                ..Default::default()
            };
            macdec::deploy::serve_tcp(listener, factory, spec, limits)?;
        }
    }
    Ok(())
}

fn deploy(args: DeployArgs) -> Result<()> {
    use macdec::deploy::{manifest::load_all, processes::deploy_with_processes};
    use macdec::experiment::seeds::{stream, Role};
    let (manifest, _) = load_all(&args.policy)
        .with_context(|| format!("loading policy {}", args.policy.display()))?;
    let seed = args.seed.unwrap_or(manifest.run.seed);
    let mut rng = stream(seed, Role::EvalEnv);
    let exe = std::env::current_exe().context("locating the macdec executable")?;
    let extra: Vec<String> = if args.mock {
        vec!["--mock".into()]
    } else {
        vec![]
    };
    let traces = deploy_with_processes(
        &exe,
        &args.policy,
        &manifest,
        &extra,
        args.episodes,
        &mut rng,
        std::time::Duration::from_secs(args.timeout_secs),
    )
    .with_context(|| format!("deploying {}", args.policy.display()))?;
    let mut out = std::io::stdout().lock();
    for mut trace in traces.iter().cloned() {
        if !args.trajectories {
            trace.trajectory.clear();
        }
        serde_json::to_writer(&mut out, &trace)?;
        writeln!(out)?;
    }
    let mean = traces.iter().map(|t| t.discounted_return).sum::<f64>() / traces.len().max(1) as f64;
    eprintln!(
        "{} episode(s) of {} with {} robot process(es), seed {seed}: mean discounted return {mean:.4}",
        traces.len(),
        manifest.env.name(),
        manifest.agents.len()
    );
    Ok(())
}
