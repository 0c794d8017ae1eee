//! `macdec replay`: replay a macro-action log and print the trajectory as JSON lines.

use anyhow::{Context, Result};
use std::io::Write;
use std::path::PathBuf;

#[derive(clap::Args)]
pub(super) struct ReplayArgs {
    /// JSON file: {"env": "box-pushing", "grid": 10, "horizon": 100, "steps": [[a0, a1], ...]}
    #[arg(long)]
    actions: PathBuf,
    /// Also print an ASCII picture of the state after every step (to stderr).
    #[arg(long)]
    verbose: bool,
}

/// Print one JSON line per step of the log (and a picture per step with `--verbose`).
pub(super) fn run(args: ReplayArgs) -> Result<()> {
    let ReplayArgs { actions, verbose } = args;
    let path = actions.as_path();
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::tests::{accepted, assert_refused, error_text};
    use crate::cli::Command;
    use clap::error::ErrorKind;

    fn parse(flags: &[&str]) -> ReplayArgs {
        match accepted("replay", flags) {
            Command::Replay(args) => args,
            _ => unreachable!("`replay` parses as Command::Replay"),
        }
    }

    #[test]
    fn replay_needs_the_actions_file_and_is_quiet_by_default() {
        assert_refused(
            "replay",
            &[],
            ErrorKind::MissingRequiredArgument,
            "--actions <ACTIONS>",
        );
        let args = parse(&["--actions", "log.json"]);
        assert_eq!(args.actions, PathBuf::from("log.json"));
        assert!(!args.verbose);
        assert!(parse(&["--actions", "log.json", "--verbose"]).verbose);
    }

    #[test]
    fn replay_of_a_missing_file_names_it() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("none.json");
        let text = error_text(run(parse(&["--actions", path.to_str().unwrap()])));
        assert!(
            text.starts_with(&format!("Error: reading replay file {}", path.display())),
            "{text}"
        );
    }
}
