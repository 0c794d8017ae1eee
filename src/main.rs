//! The `macdec` command line: parse, call the library, report. No logic lives here.

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use std::path::PathBuf;

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
    /// Draw every experiment's learning curves (PNG + SVG) and summary tables from a results tree.
    Plot {
        /// Results root: <results>/<experiment>/<curve>/seed-<k>/metrics.csv.
        #[arg(long, default_value = "results")]
        results: PathBuf,
        /// Where the figures and <experiment>_summary.csv files go.
        #[arg(long, default_value = "plots")]
        out: PathBuf,
    },
}

fn main() -> Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Command::Plot { results, out } => plot(&results, &out),
    }
}

fn plot(results: &std::path::Path, out: &std::path::Path) -> Result<()> {
    let report = macdec::plot::plot_results(results, out)
        .with_context(|| format!("plotting {} into {}", results.display(), out.display()))?;
    for note in &report.notes {
        eprintln!("{note}");
    }
    for p in &report.plots {
        eprintln!(
            "wrote {}, {}, {}",
            p.png.display(),
            p.svg.display(),
            p.summary_csv.display()
        );
    }
    print!("{}", report.markdown());
    Ok(())
}
