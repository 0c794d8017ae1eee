//! A set of files written as one: a policy directory's description names its weight files by
//! checksum, so a reader that saw a new `policy.json` beside old weights (a kill between two
//! file renames, or a checkpoint written while `export` reads) would find the set corrupt.
//! [`replace_dir`] writes the new set into a fresh sibling directory and swaps it in with one
//! atomic rename: at every moment the name holds the complete old set or the complete new one.

use std::ffi::CString;
use std::io;
use std::os::unix::ffi::OsStrExt;
use std::path::{Path, PathBuf};

/// Replace the directory `dir` (or create it) with one whose files `fill` writes into the empty
/// directory it is given. `dir` must not be a link, nor anything but a directory; its parent is
/// created. On any error the new directory is removed and `dir` is left as it was. Leftovers of
/// a process killed mid-way (`.<name>.<pid>-<n>.tmp` beside `dir`) are removed by the next call
/// for the same `dir` once that process is gone.
pub fn replace_dir(dir: &Path, fill: impl FnOnce(&Path) -> io::Result<()>) -> io::Result<()> {
    let name = dir.file_name().ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{} does not name a directory", dir.display()),
        )
    })?;
    let exists = match std::fs::symlink_metadata(dir) {
        Err(e) if e.kind() == io::ErrorKind::NotFound => false,
        Err(e) => return Err(e),
        Ok(m) if m.file_type().is_symlink() => return Err(super::links::link_refused(dir)),
        Ok(m) if m.is_dir() => true,
        Ok(_) => {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("{} is not a directory", dir.display()),
            ))
        }
    };
    let parent = dir
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    std::fs::create_dir_all(parent)?;
    remove_stale_generations(parent, &name.to_string_lossy())?;
    let new = create_temp_dir_beside(dir)?;
    let result = (|| {
        fill(&new)?;
        std::fs::File::open(&new)?.sync_all()?;
        if !exists {
            // Nothing to keep: a plain rename, which fails (and keeps what is there) if another
            // process created a non-empty `dir` meanwhile.
            return std::fs::rename(&new, dir);
        }
        match exchange(&new, dir) {
            Ok(()) => {}
            // A file system without an atomic exchange: move the old set aside, then the new
            // one in (for an instant the name holds nothing, never a mix).
            Err(e) if matches!(e.raw_os_error(), Some(libc::EINVAL | libc::ENOSYS)) => {
                let old = create_temp_dir_beside(dir)?;
                std::fs::remove_dir(&old)?;
                std::fs::rename(dir, &old)?;
                std::fs::rename(&new, dir)?;
                std::fs::rename(&old, &new)?;
            }
            Err(e) => return Err(e),
        }
        // `new` now holds the old set.
        std::fs::remove_dir_all(&new)
    })();
    if result.is_err() {
        let _ = std::fs::remove_dir_all(&new);
    }
    if let Ok(p) = std::fs::File::open(parent) {
        let _ = p.sync_all();
    }
    result
}

/// Swap the directories `a` and `b` in one step (Linux `renameat2` with `RENAME_EXCHANGE`).
fn exchange(a: &Path, b: &Path) -> io::Result<()> {
    let c = |p: &Path| {
        CString::new(p.as_os_str().as_bytes())
            .map_err(|_| io::Error::new(io::ErrorKind::InvalidInput, "path holds a NUL byte"))
    };
    let (a, b) = (c(a)?, c(b)?);
    // SAFETY: both paths are valid NUL-terminated strings that outlive the call.
    let rc = unsafe {
        libc::renameat2(
            libc::AT_FDCWD,
            a.as_ptr(),
            libc::AT_FDCWD,
            b.as_ptr(),
            libc::RENAME_EXCHANGE,
        )
    };
    if rc == 0 {
        Ok(())
    } else {
        Err(io::Error::last_os_error())
    }
}

/// A new empty directory beside `dir`, created exclusively (a planted name is skipped):
/// `.<name>.<pid>-<n>.tmp`, the temp-name pattern of [`super::atomic`].
fn create_temp_dir_beside(dir: &Path) -> io::Result<PathBuf> {
    super::atomic::create_beside(dir, |tmp| std::fs::create_dir(tmp)).map(|(tmp, ())| tmp)
}

/// Remove the generations of `name` in `parent` that a killed process left (directories only,
/// never through a link).
fn remove_stale_generations(parent: &Path, name: &str) -> io::Result<()> {
    for entry in std::fs::read_dir(parent)? {
        let entry = entry?;
        let file_name = entry.file_name();
        let Some(file_name) = file_name.to_str() else {
            continue;
        };
        let ours = file_name
            .strip_prefix('.')
            .and_then(|s| s.strip_prefix(name))
            .is_some_and(|s| s.starts_with('.'));
        if !ours || !entry.file_type()?.is_dir() {
            continue;
        }
        if super::atomic::temp_name_is_stale(file_name) {
            std::fs::remove_dir_all(entry.path())?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn files(dir: &Path) -> Vec<(String, String)> {
        let mut out: Vec<_> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| {
                let e = e.unwrap();
                (
                    e.file_name().to_string_lossy().into_owned(),
                    std::fs::read_to_string(e.path()).unwrap(),
                )
            })
            .collect();
        out.sort();
        out
    }

    fn write_set(dir: &Path, tag: &str, n: usize) -> io::Result<()> {
        for i in 0..n {
            std::fs::write(dir.join(format!("f{i}")), tag)?;
        }
        Ok(())
    }

    #[test]
    fn a_set_is_replaced_whole_and_nothing_is_left_beside_it() {
        let t = tempfile::tempdir().unwrap();
        let dir = t.path().join("sub/policy");
        replace_dir(&dir, |d| write_set(d, "one", 3)).unwrap();
        replace_dir(&dir, |d| write_set(d, "two", 2)).unwrap();
        assert_eq!(
            files(&dir),
            [("f0".into(), "two".into()), ("f1".into(), "two".into())]
        );
        assert_eq!(std::fs::read_dir(dir.parent().unwrap()).unwrap().count(), 1);
        // A failing writer leaves the old set and no temp directory.
        let err = replace_dir(&dir, |d| {
            write_set(d, "three", 1)?;
            Err(io::Error::other("disk full"))
        })
        .unwrap_err();
        assert!(err.to_string().contains("disk full"));
        assert_eq!(files(&dir).len(), 2);
        assert_eq!(std::fs::read_dir(dir.parent().unwrap()).unwrap().count(), 1);
    }

    #[test]
    fn links_and_files_are_refused_and_stale_generations_removed() {
        let t = tempfile::tempdir().unwrap();
        let outside = t.path().join("outside");
        std::fs::create_dir(&outside).unwrap();
        std::fs::write(outside.join("keep"), "x").unwrap();
        let link = t.path().join("policy");
        std::os::unix::fs::symlink(&outside, &link).unwrap();
        let err = replace_dir(&link, |d| write_set(d, "x", 1)).unwrap_err();
        assert!(err.to_string().contains("symbolic link"), "{err}");
        assert_eq!(files(&outside), [("keep".into(), "x".into())]);
        let file = t.path().join("file");
        std::fs::write(&file, "").unwrap();
        assert!(replace_dir(&file, |d| write_set(d, "x", 1)).is_err());
        // A dead process's generation (pid 0 is never a process that writes) goes.
        let dir = t.path().join("p");
        let stale = t.path().join(".p.4294967294-0.tmp");
        std::fs::create_dir(&stale).unwrap();
        std::fs::write(stale.join("f0"), "old").unwrap();
        replace_dir(&dir, |d| write_set(d, "new", 1)).unwrap();
        assert!(!stale.exists());
    }

    #[test]
    fn a_reader_never_sees_a_mixed_set() {
        let t = tempfile::tempdir().unwrap();
        let dir = t.path().join("policy");
        replace_dir(&dir, |d| write_set(d, "0", 4)).unwrap();
        let stop = std::sync::atomic::AtomicBool::new(false);
        std::thread::scope(|s| {
            s.spawn(|| {
                for g in 1..200 {
                    replace_dir(&dir, |d| write_set(d, &g.to_string(), 4)).unwrap();
                }
                stop.store(true, std::sync::atomic::Ordering::Relaxed);
            });
            let mut checked = 0;
            while !stop.load(std::sync::atomic::Ordering::Relaxed) {
                // Open the directory once and read the set through it, as a snapshot.
                let Ok(handle) = std::fs::File::open(&dir) else {
                    continue;
                };
                let via = PathBuf::from(format!(
                    "/proc/self/fd/{}",
                    std::os::fd::AsRawFd::as_raw_fd(&handle)
                ));
                let tags: Vec<String> = (0..4)
                    .filter_map(|i| std::fs::read_to_string(via.join(format!("f{i}"))).ok())
                    .collect();
                if tags.len() == 4 {
                    assert!(tags.iter().all(|t| *t == tags[0]), "mixed set {tags:?}");
                    checked += 1;
                }
            }
            assert!(checked > 0);
        });
    }
}
