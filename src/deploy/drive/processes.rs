//! Robot processes for `macdec deploy`: start one `macdec robot ... --listen 127.0.0.1:0` per
//! agent, learn each one's port from the first line it prints, connect, and stop them when done.
//!
//! The contract with the robot: in `--listen` mode its first stdout line is
//! `{"listening": "127.0.0.1:PORT"}` (see [`announcement`]), printed once the socket is bound.
//! Started with `--exit-on-stdin-close`, it exits when its stdin closes, so robots never outlive
//! a deployment that was killed.

use crate::deploy::drive::driver::{run_episode, DeployError, EpisodeTrace};
use crate::deploy::drive::link::JsonLink;
use crate::envs::EnvRng;
use crate::policy_files::Manifest;
use serde::{Deserialize, Serialize};
use std::io::{BufRead, BufReader, Read};
use std::net::SocketAddr;
use std::path::Path;
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

/// The robot's first stdout line in `--listen` mode.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Announcement {
    listening: SocketAddr,
}

/// `{"listening":"ADDR"}`: what a listening robot prints first.
pub fn announcement(addr: SocketAddr) -> String {
    serde_json::to_string(&Announcement { listening: addr }).expect("an address serializes")
}

/// The address in an announcement line, if it is one.
pub fn parse_announcement(line: &str) -> Option<SocketAddr> {
    serde_json::from_str::<Announcement>(line.trim())
        .ok()
        .map(|a| a.listening)
}

/// Exit this process when stdin reaches end of input (the parent deployment is gone). Spawns a
/// watcher thread; returns at once.
pub fn exit_when_stdin_closes() {
    std::thread::spawn(|| {
        let mut sink = [0u8; 256];
        let mut stdin = std::io::stdin();
        loop {
            match stdin.read(&mut sink) {
                Ok(0) | Err(_) => std::process::exit(0),
                Ok(_) => {}
            }
        }
    });
}

/// The command line of agent `agent`'s robot: `EXE robot --policy DIR --agent I --listen
/// 127.0.0.1:0 --exit-on-stdin-close`, plus `extra_args` (e.g. the hidden `--mock`).
pub fn robot_command(
    exe: &Path,
    policy_dir: &Path,
    agent: usize,
    extra_args: &[String],
) -> Command {
    let mut cmd = Command::new(exe);
    cmd.arg("robot")
        .arg("--policy")
        .arg(policy_dir)
        .arg("--agent")
        .arg(agent.to_string())
        .arg("--listen")
        .arg("127.0.0.1:0")
        .arg("--exit-on-stdin-close")
        .args(extra_args);
    cmd
}

/// A started robot process. Dropping it closes its stdin, then kills it if it has not exited.
pub struct RobotProcess {
    child: Child,
    stdin: Option<ChildStdin>,
    addr: SocketAddr,
}

impl RobotProcess {
    /// Start `command` (see [`robot_command`]) and wait up to `timeout` for its announcement.
    pub fn spawn(
        mut command: Command,
        agent: usize,
        timeout: Duration,
    ) -> Result<RobotProcess, DeployError> {
        let fail = |reason: String| DeployError::Spawn { agent, reason };
        let mut child = command
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .map_err(|e| fail(format!("cannot start {:?}: {e}", command.get_program())))?;
        let stdin = child.stdin.take();
        let stdout = child.stdout.take().expect("stdout was piped");
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            let mut first = String::new();
            let mut reader = BufReader::new(stdout);
            let read = reader.read_line(&mut first).map(|_| first);
            let _ = tx.send(read);
            // Keep draining so the robot never blocks on a full pipe.
            let _ = std::io::copy(&mut reader, &mut std::io::sink());
        });
        let mut process = RobotProcess {
            child,
            stdin,
            addr: SocketAddr::from(([127, 0, 0, 1], 0)),
        };
        let line = match rx.recv_timeout(timeout) {
            Ok(Ok(line)) => line,
            Ok(Err(e)) => return Err(fail(format!("reading its stdout: {e}"))),
            Err(_) => return Err(fail(format!("no announcement within {timeout:?}"))),
        };
        match parse_announcement(&line) {
            Some(addr) => {
                process.addr = addr;
                Ok(process)
            }
            None if line.is_empty() => {
                let status = process
                    .child
                    .wait()
                    .map_or_else(|e| e.to_string(), |s| s.to_string());
                Err(fail(format!("it exited before listening ({status})")))
            }
            None => Err(fail(format!(
                "expected {{\"listening\": \"ADDR\"}} as its first line, got {:?}",
                line.trim_end()
            ))),
        }
    }

    /// Where the robot listens.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }
}

impl Drop for RobotProcess {
    fn drop(&mut self) {
        drop(self.stdin.take());
        for _ in 0..50 {
            if let Ok(Some(_)) = self.child.try_wait() {
                return;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// `macdec deploy`: start one robot process per agent of the policy in `policy_dir` (whose
/// manifest the caller loaded and verified), connect to each over loopback TCP, run `episodes`
/// greedy episodes of the manifest's domain, and stop the robots. `timeout` bounds every start
/// and every reply.
pub fn deploy_with_processes(
    exe: &Path,
    policy_dir: &Path,
    manifest: &Manifest,
    extra_args: &[String],
    episodes: usize,
    rng: &mut EnvRng,
    timeout: Duration,
) -> Result<Vec<EpisodeTrace>, DeployError> {
    let mut traces = Vec::with_capacity(episodes.min(4096));
    deploy_streaming(
        exe,
        policy_dir,
        manifest,
        extra_args,
        episodes,
        rng,
        timeout,
        |trace| {
            traces.push(trace);
            Ok(())
        },
    )?;
    Ok(traces)
}

/// [`deploy_with_processes`], handing each episode to `on_episode` as soon as it ends instead of
/// keeping them all: memory stays one episode's worth, and a killed deployment has already
/// reported every finished episode.
#[allow(clippy::too_many_arguments)]
pub fn deploy_streaming<F>(
    exe: &Path,
    policy_dir: &Path,
    manifest: &Manifest,
    extra_args: &[String],
    episodes: usize,
    rng: &mut EnvRng,
    timeout: Duration,
    mut on_episode: F,
) -> Result<(), DeployError>
where
    F: FnMut(EpisodeTrace) -> Result<(), DeployError>,
{
    let mut env = manifest
        .env
        .build()
        .map_err(|e| DeployError::Policy(e.to_string()))?;
    let processes = (0..manifest.agents.len())
        .map(|agent| {
            RobotProcess::spawn(
                robot_command(exe, policy_dir, agent, extra_args),
                agent,
                timeout,
            )
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mut links = processes
        .iter()
        .enumerate()
        .map(|(agent, p)| {
            JsonLink::connect(p.addr(), agent, manifest, timeout)
                .map_err(|source| DeployError::Link { agent, source })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let result = (0..episodes).try_for_each(|k| {
        on_episode(run_episode(
            &mut env,
            &mut links,
            manifest.discount,
            rng,
            k,
        )?)
    });
    drop(links);
    drop(processes);
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn announcement_round_trips_and_other_lines_are_not_one() {
        let addr: SocketAddr = "127.0.0.1:40123".parse().unwrap();
        assert_eq!(announcement(addr), r#"{"listening":"127.0.0.1:40123"}"#);
        assert_eq!(parse_announcement(&(announcement(addr) + "\n")), Some(addr));
        assert_eq!(parse_announcement("listening on 127.0.0.1:4"), None);
        assert_eq!(parse_announcement(r#"{"listening":"nowhere"}"#), None);
    }

    #[test]
    fn a_command_that_never_announces_is_a_named_spawn_error() {
        let mut cmd = Command::new("sh");
        cmd.arg("-c").arg("echo hello");
        let err = RobotProcess::spawn(cmd, 1, Duration::from_secs(10))
            .err()
            .unwrap()
            .to_string();
        assert!(err.contains("agent 1") && err.contains("hello"), "{err}");
        let mut cmd = Command::new("sh");
        cmd.arg("-c").arg("exit 3");
        let err = RobotProcess::spawn(cmd, 0, Duration::from_secs(10))
            .err()
            .unwrap()
            .to_string();
        assert!(err.contains("exited before listening"), "{err}");
    }
}
