//! Crash-safe file writes: a finished result is never half-written or lost.

use std::fs;
use std::io::{self, Write};
use std::path::Path;

/// Write `bytes` to `path` by writing a sibling temp file, syncing it, and renaming it over
/// `path`, so readers see either the old file or the new one, never a torn one. `path` must be a
/// regular file or not exist ([`check_output_file`]).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_atomic_with(path, |f| f.write_all(bytes))
}

/// [`write_atomic`] for output too large to hold at once: `write` streams it into the (buffered)
/// temp file, which replaces `path` only if `write` succeeds.
pub fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> io::Result<()> {
    write_atomic_try(path, write, |e| e)
}

/// [`write_atomic_with`] for a writer with its own error type `E` (an encoder's, a table's), which
/// file errors are turned into by `io_error`: `path` is replaced only if `write` returns `Ok`,
/// whose value is returned.
pub fn write_atomic_try<T, E>(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> Result<T, E>,
    io_error: impl Fn(io::Error) -> E,
) -> Result<T, E> {
    check_output_file(path).map_err(&io_error)?;
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty());
    if let Some(dir) = dir {
        fs::create_dir_all(dir).map_err(&io_error)?;
    }
    let (tmp, file) = create_temp_beside(path).map_err(&io_error)?;
    let written = (|| {
        let mut f = io::BufWriter::new(file);
        let value = write(&mut f)?;
        let finish = || -> io::Result<()> {
            let f = f.into_inner().map_err(io::IntoInnerError::into_error)?;
            f.sync_all()?;
            fs::rename(&tmp, path)
        };
        finish().map_err(&io_error)?;
        Ok(value)
    })();
    // A failed write (disk full, say) must not leave its temp file behind.
    written.inspect_err(|_| {
        let _ = fs::remove_file(&tmp);
    })
}

/// Refuse to write onto anything but a regular file: a device (as root, renaming a GIF over
/// `/dev/null` would replace it), a FIFO, a socket, a directory, or a link (which a shared tree
/// could plant). A path that does not exist yet is fine.
pub fn check_output_file(path: &Path) -> io::Result<()> {
    match fs::symlink_metadata(path) {
        Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(e),
        Ok(m) if m.file_type().is_symlink() => Err(super::links::link_refused(path)),
        Ok(m) if m.is_file() => Ok(()),
        Ok(m) => Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "{} is {}, not a regular file; macdec writes only regular files",
                path.display(),
                if m.is_dir() {
                    "a directory"
                } else {
                    "a device, FIFO or socket"
                }
            ),
        )),
    }
}

/// The `<n>` of the next temp file name this process tries.
static TEMP_COUNTER: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// A new temp file beside `path`, created exclusively and without following a link (a name
/// someone planted is skipped, never written through): `.<name>.<pid>-<n>.tmp`.
pub fn create_temp_beside(path: &Path) -> io::Result<(std::path::PathBuf, fs::File)> {
    create_beside(path, |tmp| {
        super::links::open_options_no_follow()
            .write(true)
            .create_new(true)
            .open(tmp)
    })
}

/// Make something new at the next free temp name beside `path` ([`temp_name_beside`]) with
/// `create`, which must fail with `AlreadyExists` where the name is taken (a file opened
/// `create_new`, a directory): taken names, perhaps planted, are skipped.
pub fn create_beside<T>(
    path: &Path,
    mut create: impl FnMut(&Path) -> io::Result<T>,
) -> io::Result<(std::path::PathBuf, T)> {
    for _ in 0..64 {
        let tmp = temp_name_beside(path)?;
        match create(&tmp) {
            Ok(made) => return Ok((tmp, made)),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        }
    }
    Err(io::Error::new(
        io::ErrorKind::AlreadyExists,
        format!("no free temp name beside {}", path.display()),
    ))
}

/// The next temp name beside `path` for this process: `.<name>.<pid>-<n>.tmp`, `n` counting up.
pub fn temp_name_beside(path: &Path) -> io::Result<std::path::PathBuf> {
    let name = path
        .file_name()
        .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "path has no file name"))?;
    let n = TEMP_COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    Ok(path.with_file_name(format!(
        ".{}.{}-{n}.tmp",
        name.to_string_lossy(),
        std::process::id()
    )))
}

/// Whether `file_name` is a temp name of [`temp_name_beside`] whose process is this one or gone
/// (so nothing is writing it any more).
pub fn temp_name_is_stale(file_name: &str) -> bool {
    temp_file_pid(file_name).is_some_and(|pid| pid == std::process::id() || !may_be_alive(pid))
}

/// The pid in a temp file name written by [`write_atomic`] (`.<name>.<pid>.tmp`), if it is one.
fn temp_file_pid(file_name: &str) -> Option<u32> {
    let stem = file_name.strip_prefix('.')?.strip_suffix(".tmp")?;
    let (_, pid) = stem.rsplit_once('.')?;
    // `<pid>-<n>`, or `<pid>` as earlier versions named them.
    pid.split('-').next()?.parse().ok()
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
    let mut removed = 0;
    for entry in fs::read_dir(dir)? {
        let entry = entry?;
        let name = entry.file_name();
        if name.to_str().is_some_and(temp_name_is_stale) && entry.file_type()?.is_file() {
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
        assert_eq!(temp_file_pid(".checkpoint.bin.123-7.tmp"), Some(123));
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

    #[test]
    fn outputs_onto_devices_directories_and_links_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let outside = dir.path().join("outside");
        fs::write(&outside, b"keep").unwrap();
        let link = dir.path().join("out.gif");
        std::os::unix::fs::symlink(&outside, &link).unwrap();
        let e = write_atomic(&link, b"x").unwrap_err();
        assert!(e.to_string().contains("symbolic link"), "{e}");
        assert_eq!(fs::read(&outside).unwrap(), b"keep");
        let e = write_atomic(dir.path(), b"x").unwrap_err();
        assert!(e.to_string().contains("a directory"), "{e}");
        if Path::new("/dev/null").exists() {
            let e = check_output_file(Path::new("/dev/null")).unwrap_err();
            assert!(e.to_string().contains("not a regular file"), "{e}");
        }
    }

    #[test]
    fn a_planted_temp_file_link_is_never_written_through() {
        let dir = tempfile::tempdir().unwrap();
        let outside = dir.path().join("outside");
        fs::write(&outside, b"keep").unwrap();
        let p = dir.path().join("config.toml");
        // Plant links at the next temp names this process would try.
        let next = TEMP_COUNTER.load(std::sync::atomic::Ordering::Relaxed);
        for n in next..next + 10 {
            let name = format!(".config.toml.{}-{n}.tmp", std::process::id());
            let _ = std::os::unix::fs::symlink(&outside, dir.path().join(name));
        }
        write_atomic(&p, b"new").unwrap();
        assert_eq!(fs::read(&p).unwrap(), b"new");
        assert_eq!(fs::read(&outside).unwrap(), b"keep");
    }
}
