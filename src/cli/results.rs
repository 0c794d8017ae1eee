//! `macdec results`: every run's metrics of a results tree as one long CSV.

use anyhow::{Context, Result};
use std::path::PathBuf;

#[derive(clap::Args)]
pub(super) struct ResultsArgs {
    /// Results root: <results>/<experiment>/<curve>/seed-<k>/metrics.csv[.gz] (also one
    /// level deeper, as in reproduction/macromarl/<block>/...).
    #[arg(long, default_value = "results")]
    results: PathBuf,
    /// The CSV file to write (atomically); without it, the table goes to stdout.
    #[arg(long)]
    out: Option<PathBuf>,
}

/// Write the tidy table to `--out`, or to stdout (a reader closing early is no error).
pub(super) fn run(args: ResultsArgs) -> Result<()> {
    let ResultsArgs { results, out } = args;
    let (results, out) = (results.as_path(), out.as_deref());
    use crate::experiment::run::tidy_table::{write_tidy_file, write_tidy_table};
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
                Err(crate::experiment::run::tidy_table::TidyError::Write { source, .. })
                    if source.kind() == std::io::ErrorKind::BrokenPipe => {}
                other => {
                    other.with_context(context)?;
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::tests::accepted;
    use crate::cli::Command;

    fn parse(flags: &[&str]) -> ResultsArgs {
        match accepted("results", flags) {
            Command::Results(args) => args,
            _ => unreachable!("`results` parses as Command::Results"),
        }
    }

    #[test]
    fn results_reads_results_and_writes_to_stdout_by_default() {
        let args = parse(&[]);
        assert_eq!(args.results, PathBuf::from("results"));
        assert_eq!(args.out, None);
        let args = parse(&["--results", "reproduction", "--out", "all.csv"]);
        assert_eq!(args.results, PathBuf::from("reproduction"));
        assert_eq!(args.out, Some(PathBuf::from("all.csv")));
    }
}
