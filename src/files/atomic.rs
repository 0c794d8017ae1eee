//! Crash-safe file writes: a finished result is never half-written or lost.

use std::fs;
use std::io::{self, Write};
use std::path::Path;

/// Write `bytes` to `path` by writing a sibling temp file, syncing it, and renaming it over
/// `path`, so readers see either the old file or the new one, never a torn one.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_atomic_with(path, |f| f.write_all(bytes))
}

/// [`write_atomic`] for output too large to hold at once: `write` streams it into the (buffered)
/// temp file, which replaces `path` only if `write` succeeds.
pub fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> io::Result<()> {
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty());
    if let Some(dir) = dir {
        fs::create_dir_all(dir)?;
    }
    let name = path
        .file_name()
        .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "path has no file name"))?;
    let tmp = path.with_file_name(format!(
        ".{}.{}.tmp",
        name.to_string_lossy(),
        std::process::id()
    ));
    let written = (|| {
        let mut f = io::BufWriter::new(fs::File::create(&tmp)?);
        write(&mut f)?;
        let f = f.into_inner().map_err(io::IntoInnerError::into_error)?;
        f.sync_all()?;
        fs::rename(&tmp, path)
    })();
    // A failed write (disk full, say) must not leave its temp file behind.
    written.inspect_err(|_| {
        let _ = fs::remove_file(&tmp);
    })
}

/// The pid in a temp file name written by [`write_atomic`] (`.<name>.<pid>.tmp`), if it is one.
fn temp_file_pid(file_name: &str) -> Option<u32> {
    let stem = file_name.strip_prefix('.')?.strip_suffix(".tmp")?;
    let (_, pid) = stem.rsplit_once('.')?;
    pid.parse().ok()
}

/// Whether process `pid` may still be running (and writing). Without `/proc`, every other
/// process is assumed alive, so nothing of a live writer is ever removed.
fn may_be_alive(pid: u32) -> bool {
    let proc = Path::new("/proc");
    !proc.is_dir() || proc.join(pid.to_string()).exists()
}

/// Remove the temp files in `dir` left by [`write_atomic`] calls of processes that died mid-write
/// (killed, or out of disk). Returns how many were removed.
pub fn remove_stale_temp_files(dir: &Path) -> io::Result<usize> {
    let me = std::process::id();
    let mut removed = 0;
    for entry in fs::read_dir(dir)? {
        let entry = entry?;
        let name = entry.file_name();
        let Some(pid) = name.to_str().and_then(temp_file_pid) else {
            continue;
        };
        if (pid == me || !may_be_alive(pid)) && entry.file_type()?.is_file() {
            fs::remove_file(entry.path())?;
            removed += 1;
        }
    }
    Ok(removed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replaces_content_and_leaves_no_temp_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("sub/out.txt");
        write_atomic(&p, b"one").unwrap();
        write_atomic(&p, b"two").unwrap();
        assert_eq!(fs::read(&p).unwrap(), b"two");
        let names: Vec<_> = fs::read_dir(p.parent().unwrap()).unwrap().collect();
        assert_eq!(names.len(), 1);
    }

    #[test]
    fn temp_files_of_dead_writers_are_removed_and_others_kept() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        // A pid that cannot be running (beyond the kernel's pid_max).
        let dead = d.join(".checkpoint.bin.4294967.tmp");
        let mine = d.join(format!(".metrics.csv.{}.tmp", std::process::id()));
        let parent = d.join(format!(".checkpoint.bin.{}.tmp", 1));
        let other = d.join("checkpoint.bin");
        for p in [&dead, &mine, &parent, &other] {
            fs::write(p, b"x").unwrap();
        }
        assert_eq!(remove_stale_temp_files(d).unwrap(), 2);
        assert!(!dead.exists() && !mine.exists());
        assert!(parent.exists(), "pid 1 is alive: its temp file stays");
        assert!(other.exists());
        assert_eq!(temp_file_pid(".checkpoint.bin.123.tmp"), Some(123));
        assert_eq!(temp_file_pid("checkpoint.bin"), None);
    }

    #[test]
    fn a_failed_write_leaves_no_temp_file() {
        let dir = tempfile::tempdir().unwrap();
        // Renaming onto a non-empty directory fails after the temp file was written.
        let target = dir.path().join("taken");
        fs::create_dir(&target).unwrap();
        fs::write(target.join("inside"), b"x").unwrap();
        assert!(write_atomic(&target, b"data").is_err());
        let names: Vec<_> = fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 1);
    }
}
