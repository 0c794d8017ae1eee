//! The results tree, named once: `<root>/<experiment>/<curve>/seed-<k>/` and the files of a run
//! directory. Training writes this layout, and plotting, auditing, exporting, rendering and Slurm
//! read it; each of them asks here for a path or a name instead of spelling it.

use std::path::{Path, PathBuf};

/// A run's resolved config (its identity, domain, hyperparameters and provenance).
pub const CONFIG: &str = "config.toml";
/// A run's learning curve, see [`crate::experiment::run::metrics`].
pub use crate::experiment::run::metrics::{METRICS_FILE, METRICS_FILE_GZ};
/// The whole training loop, for resuming only (never committed).
pub const CHECKPOINT: &str = "checkpoint.bin";
/// The run's nets as policy files, see [`crate::policy_files`].
pub use crate::policy_files::POLICY_DIR;
/// Written last, once a run has trained all its episodes.
pub const FINISHED: &str = "finished";
/// The file a training process holds an exclusive lock on while it trains a run.
pub const LOCK: &str = ".lock";
/// An experiment directory's record of curves that live under another experiment.
pub const SHARED_CURVES: &str = "shared_curves.toml";

/// The directory name of seed `seed`: `seed-<k>`.
pub fn seed_dir_name(seed: u64) -> String {
    format!("seed-{seed}")
}

/// The seed a directory named `seed-<k>` holds (`k` decimal digits only); `None` otherwise.
pub fn parse_seed_dir(name: &str) -> Option<u64> {
    let digits = name.strip_prefix("seed-")?;
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    digits.parse().ok()
}

/// A run's label inside its experiment, as Slurm tasks and listings name it: `<curve>/seed-<k>`.
pub fn run_label(curve: &str, seed: u64) -> String {
    format!("{curve}/{}", seed_dir_name(seed))
}

/// A run's directory below the results root: `<root>/<experiment>/<curve>/seed-<k>`.
pub fn run_dir(root: &Path, experiment: &str, curve: &str, seed: u64) -> PathBuf {
    root.join(experiment).join(run_label(curve, seed))
}

/// Whether the run in `dir` has finished training (its marker exists).
pub fn is_finished(dir: &Path) -> bool {
    // Not through a link: a planted `finished` would make an unfinished run look done.
    std::fs::symlink_metadata(dir.join(FINISHED)).is_ok_and(|m| m.is_file())
}

/// How deep below a results root a run directory may sit: `<experiment>/<curve>/seed-<k>` (3),
/// or one level deeper in a group of experiments such as `macromarl/<block>/<method>/seed-<k>`.
pub const RUN_DEPTHS: std::ops::Range<usize> = 3..5;

/// Every run directory below `root`: a real directory (links are not followed: a linked curve
/// is another experiment's run, listed where it lives) at a depth in [`RUN_DEPTHS`] for which
/// `is_run` holds; a directory that is not a run is searched further down. Sorted by path. An
/// unreadable directory is the error, with its path.
pub fn find_runs(
    root: &Path,
    is_run: &dyn Fn(&Path) -> bool,
) -> Result<Vec<PathBuf>, (PathBuf, std::io::Error)> {
    let mut runs = Vec::new();
    collect_runs(root, 1, is_run, &mut runs)?;
    runs.sort();
    Ok(runs)
}

fn collect_runs(
    dir: &Path,
    depth: usize,
    is_run: &dyn Fn(&Path) -> bool,
    runs: &mut Vec<PathBuf>,
) -> Result<(), (PathBuf, std::io::Error)> {
    if depth >= RUN_DEPTHS.end {
        return Ok(());
    }
    for sub in real_subdirs(dir).map_err(|e| (dir.to_path_buf(), e))? {
        if RUN_DEPTHS.contains(&depth) && is_run(&sub) {
            runs.push(sub);
        } else {
            collect_runs(&sub, depth + 1, is_run, runs)?;
        }
    }
    Ok(())
}

/// The subdirectories of `dir` that are directories themselves, not links to one, by name.
fn real_subdirs(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut dirs = Vec::new();
    for entry in std::fs::read_dir(dir)? {
        let entry = entry?;
        if entry.file_type()?.is_dir() {
            dirs.push(entry.path());
        }
    }
    dirs.sort();
    Ok(dirs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn run_directories_are_experiment_curve_and_seed() {
        let d = run_dir(Path::new("out"), "fig5_wtd", "our2@l_rate=0.001", 7);
        assert_eq!(d, Path::new("out/fig5_wtd/our2@l_rate=0.001/seed-7"));
        assert_eq!(run_label("our1", 12), "our1/seed-12");
    }

    #[test]
    fn only_seed_and_decimal_digits_name_a_seed_directory() {
        assert_eq!(parse_seed_dir("seed-0"), Some(0));
        assert_eq!(parse_seed_dir("seed-39"), Some(39));
        for bad in [
            "seed-", "seed-+1", "seed-1a", "seed--1", "seeds-1", "tmp", "seed-1 ",
        ] {
            assert_eq!(parse_seed_dir(bad), None, "{bad}");
        }
        // More digits than a u64 holds is not a seed either.
        assert_eq!(parse_seed_dir("seed-99999999999999999999999"), None);
    }

    #[test]
    fn a_run_is_finished_only_with_its_marker_file() {
        let t = tempfile::tempdir().unwrap();
        assert!(!is_finished(t.path()));
        std::fs::create_dir(t.path().join(FINISHED)).unwrap();
        assert!(!is_finished(t.path()), "a directory is not the marker");
        std::fs::remove_dir(t.path().join(FINISHED)).unwrap();
        std::fs::write(t.path().join(FINISHED), "").unwrap();
        assert!(is_finished(t.path()));
    }
}
