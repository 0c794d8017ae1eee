//! `macdec robot`: serve one agent of an exported policy over stdin/stdout or TCP.

use anyhow::{Context, Result};
use std::io::Write;
use std::path::PathBuf;

use super::bounds::bounded_count;

#[derive(clap::Args)]
pub(super) struct RobotArgs {
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
    #[arg(long, default_value_t = crate::deploy::serve::line_reader::MAX_LINE_BYTES,
          value_parser = |t: &str| bounded_count(t, 64 << 20))]
    max_line_bytes: usize,
    /// With --listen: close a connection silent between requests for this many seconds.
    #[arg(long, default_value_t = crate::deploy::serve::server::DEFAULT_IDLE_TIMEOUT_SECS,
          value_parser = clap::value_parser!(u64).range(1..=86_400))]
    idle_timeout_secs: u64,
    /// Run a deterministic stand-in policy instead of the weights (tests).
    #[arg(long, hide = true)]
    mock: bool,
    /// Exit when stdin closes (set by `macdec deploy`, so robots never outlive it).
    #[arg(long, hide = true)]
    exit_on_stdin_close: bool,
}

/// Fresh policies (zero hidden state) for agent `agent`'s robot, one per connection.
fn policy_factory(
    manifest: &crate::policy_files::Manifest,
    verified: &crate::policy_files::VerifiedAgent,
    mock: bool,
) -> Result<crate::deploy::serve::server::PolicyFactory> {
    use crate::deploy::{policy::mock::MockPolicy, AgentPolicy};
    let entry = &manifest.agents[verified.index];
    if mock {
        let (obs, n, salt) = (entry.obs_size, entry.n_actions, entry.index as u64);
        return Ok(std::sync::Arc::new(move || {
            Box::new(MockPolicy::new(obs, n, salt)) as Box<dyn AgentPolicy>
        }));
    }
    let net = crate::deploy::policy::net_policy::load_net(manifest, verified)?;
    Ok(crate::deploy::policy::net_policy::net_factory(net))
}

/// Serve the agent's policy on stdin/stdout, or on TCP with `--listen`.
pub(super) fn run(args: RobotArgs) -> Result<()> {
    use crate::deploy::drive::processes;
    use crate::deploy::serve::robot::RobotSpec;
    use crate::policy_files::load_agent;
    let (manifest, verified) = load_agent(&args.policy, args.agent)
        .with_context(|| format!("loading agent {} of {}", args.agent, args.policy.display()))?;
    let spec = std::sync::Arc::new(RobotSpec::new(&manifest, args.agent)?);
    let factory = policy_factory(&manifest, &verified, args.mock)?;
    if args.exit_on_stdin_close && args.listen.is_some() {
        processes::exit_when_stdin_closes();
    }
    match args.listen {
        None => {
            crate::deploy::serve::robot::serve_stdio(factory(), spec, args.max_line_bytes)?;
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
            let limits = crate::deploy::serve::server::Limits {
                max_line_bytes: args.max_line_bytes,
                max_connections: args.max_connections,
                idle_timeout: Some(std::time::Duration::from_secs(args.idle_timeout_secs)),
                ..Default::default()
            };
            crate::deploy::serve::server::serve_tcp(listener, factory, spec, limits)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::tests::{accepted, assert_refused};
    use crate::cli::Command;
    use clap::error::ErrorKind;

    fn parse(flags: &[&str]) -> RobotArgs {
        let argv = [&["--policy", "p", "--agent", "1"], flags].concat();
        match accepted("robot", &argv) {
            Command::Robot(args) => args,
            _ => unreachable!("`robot` parses as Command::Robot"),
        }
    }

    fn refused(flags: &[&str], message: &str) {
        let argv = [&["--policy", "p", "--agent", "0"], flags].concat();
        assert_refused("robot", &argv, ErrorKind::ValueValidation, message);
    }

    #[test]
    fn robot_needs_a_policy_and_an_agent() {
        let missing = ErrorKind::MissingRequiredArgument;
        assert_refused("robot", &["--agent", "0"], missing, "--policy <POLICY>");
        assert_refused("robot", &["--policy", "p"], missing, "--agent <AGENT>");
        assert_refused(
            "robot",
            &["--policy", "p", "--agent", "x"],
            ErrorKind::ValueValidation,
            "'x'",
        );
    }

    #[test]
    fn robot_serves_stdio_with_the_server_s_default_limits() {
        let args = parse(&[]);
        assert_eq!(args.policy, PathBuf::from("p"));
        assert_eq!(args.agent, 1);
        assert_eq!(args.listen, None);
        assert_eq!(args.max_connections, 16);
        assert_eq!(
            args.max_line_bytes,
            crate::deploy::serve::line_reader::MAX_LINE_BYTES
        );
        assert_eq!(args.max_line_bytes, 64 * 1024);
        assert_eq!(
            args.idle_timeout_secs,
            crate::deploy::serve::server::DEFAULT_IDLE_TIMEOUT_SECS
        );
        assert_eq!(args.idle_timeout_secs, 300);
        assert!(!args.mock && !args.exit_on_stdin_close);
        let args = parse(&["--mock", "--exit-on-stdin-close"]);
        assert!(args.mock && args.exit_on_stdin_close);
    }

    #[test]
    fn robot_listen_takes_a_socket_address() {
        let args = parse(&["--listen", "127.0.0.1:0"]);
        assert_eq!(args.listen, Some("127.0.0.1:0".parse().unwrap()));
        refused(&["--listen", "localhost"], "'localhost'");
    }

    #[test]
    fn robot_limits_are_bounded() {
        assert_eq!(parse(&["--max-connections", "4096"]).max_connections, 4096);
        refused(&["--max-connections", "0"], "must be at least 1");
        refused(
            &["--max-connections", "4097"],
            "must be at most 4096, got 4097",
        );
        let most = (64 << 20).to_string();
        assert_eq!(parse(&["--max-line-bytes", &most]).max_line_bytes, 64 << 20);
        refused(&["--max-line-bytes", "0"], "must be at least 1");
        refused(
            &["--max-line-bytes", "67108865"],
            "must be at most 67108864, got 67108865",
        );
        assert_eq!(parse(&["--idle-timeout-secs", "1"]).idle_timeout_secs, 1);
        assert_eq!(
            parse(&["--idle-timeout-secs", "86400"]).idle_timeout_secs,
            86_400
        );
        refused(&["--idle-timeout-secs", "0"], "0 is not in 1..=86400");
        refused(
            &["--idle-timeout-secs", "86401"],
            "86401 is not in 1..=86400",
        );
    }
}
