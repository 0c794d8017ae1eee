//! `macdec domain`: the policy's domain here against robots already listening elsewhere.

use anyhow::{Context, Result};

use super::bounds::parse_timeout_secs;
use super::episodes::{EpisodeArgs, EpisodePrinter};

#[derive(clap::Args)]
// The robots must serve this very policy: said where `domain --help` describes --policy.
// (`mut_arg` moves the argument to the end; moving --robots after it keeps the usage line's
// order `--policy <POLICY> --robots <ROBOTS>`.)
#[command(mut_arg("policy", |a| a.help(
    "Policy directory the robots run (their `info` must report its manifest)"
)))]
#[command(mut_arg("robots", |a| a))]
pub(super) struct DomainArgs {
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

/// Play the episodes against robots listening at `--robots` and print each one's line.
pub(super) fn run(args: DomainArgs) -> Result<()> {
    let mut run = args.episodes.load()?;
    let mut printer = EpisodePrinter::new(args.episodes.trajectories);
    crate::deploy::drive::remote::run_with_robots_at(
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::tests::{accepted, assert_refused};
    use crate::cli::{Cli, Command};
    use clap::error::ErrorKind;
    use clap::CommandFactory;
    use std::path::PathBuf;

    fn parse(flags: &[&str]) -> DomainArgs {
        let argv = [&["--policy", "p", "--robots", "127.0.0.1:7000"], flags].concat();
        match accepted("domain", &argv) {
            Command::Domain(args) => args,
            _ => unreachable!("`domain` parses as Command::Domain"),
        }
    }

    #[test]
    fn domain_needs_a_policy_and_its_robots() {
        let missing = ErrorKind::MissingRequiredArgument;
        assert_refused("domain", &["--policy", "p"], missing, "--robots <ROBOTS>");
        assert_refused(
            "domain",
            &["--robots", "127.0.0.1:7000"],
            missing,
            "--policy <POLICY>",
        );
        let args = parse(&[]);
        assert_eq!(args.episodes.policy, PathBuf::from("p"));
        assert_eq!(args.episodes.episodes, 1);
        assert_eq!(args.episodes.seed, None);
        assert_eq!(args.timeout_secs, 30);
    }

    #[test]
    fn domain_robots_are_comma_separated_addresses_in_agent_order() {
        let argv = ["--policy", "p", "--robots", "10.0.0.2:7001,10.0.0.1:7000"];
        let Command::Domain(args) = accepted("domain", &argv) else {
            unreachable!("`domain` parses as Command::Domain")
        };
        let expected: Vec<std::net::SocketAddr> = vec![
            "10.0.0.2:7001".parse().unwrap(),
            "10.0.0.1:7000".parse().unwrap(),
        ];
        assert_eq!(args.robots, expected);
        let argv = ["--policy", "p", "--robots", "127.0.0.1:7000,robot1"];
        assert_refused("domain", &argv, ErrorKind::ValueValidation, "'robot1'");
    }

    #[test]
    fn domain_timeout_is_one_second_to_a_day() {
        assert_eq!(parse(&["--timeout-secs", "86400"]).timeout_secs, 86_400);
        let argv = [
            "--policy",
            "p",
            "--robots",
            "127.0.0.1:7000",
            "--timeout-secs",
            "0",
        ];
        let message = "a timeout of 0 s gives no robot time to answer: use 1 to 86400";
        assert_refused("domain", &argv, ErrorKind::ValueValidation, message);
    }

    #[test]
    fn domain_says_the_robots_must_serve_this_policy_and_lists_robots_after_it() {
        let cmd = Cli::command();
        let domain = cmd.find_subcommand("domain").unwrap();
        let policy = domain
            .get_arguments()
            .find(|a| a.get_id() == "policy")
            .unwrap();
        assert_eq!(
            policy.get_help().unwrap().to_string(),
            "Policy directory the robots run (their `info` must report its manifest)"
        );
        let mut domain = domain.clone();
        let usage = domain.render_usage().to_string();
        assert!(
            usage.contains("--policy <POLICY> --robots <ROBOTS>"),
            "{usage}"
        );
    }
}
