//! Results trees are shared: anyone who can write to one could plant a symbolic link in it. Below
//! a root macdec was given, it therefore never follows a link: directories it walks, creates or
//! empties, and files it reads, writes or locks there must be real. (The root itself may be a
//! link: the user named it.)

use std::io;
use std::path::{Component, Path, PathBuf};

/// Options that open the last component of a path without following it, when it is a link
/// (`O_NOFOLLOW`: the open fails instead).
pub fn open_options_no_follow() -> std::fs::OpenOptions {
    use std::os::unix::fs::OpenOptionsExt;
    let mut options = std::fs::OpenOptions::new();
    options.custom_flags(libc::O_NOFOLLOW);
    options
}

/// The error for a link found where macdec does not follow one.
pub fn link_refused(path: &Path) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidInput,
        format!(
            "{} is a symbolic link; macdec does not follow links inside a results tree or onto an \
             output (remove the link, or name its target)",
            path.display()
        ),
    )
}

/// An `O_NOFOLLOW` open failed with `ELOOP` when the last component is a link: say so.
pub fn explain_no_follow(path: &Path, e: io::Error) -> io::Error {
    if e.raw_os_error() == Some(libc::ELOOP) {
        link_refused(path)
    } else {
        e
    }
}

/// The paths from just below `root` down to `path` (which must lie below `root`, given the same
/// way: `root.join(relative)`); `..` below the root is refused.
fn components_below(root: &Path, path: &Path) -> io::Result<Vec<PathBuf>> {
    let relative = path.strip_prefix(root).map_err(|_| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{} is not below {}", path.display(), root.display()),
        )
    })?;
    let mut at = root.to_path_buf();
    let mut out = Vec::new();
    for c in relative.components() {
        match c {
            Component::Normal(name) => {
                at.push(name);
                out.push(at.clone());
            }
            Component::CurDir => {}
            _ => {
                return Err(io::Error::new(
                    io::ErrorKind::InvalidInput,
                    format!("{} leaves {}", path.display(), root.display()),
                ))
            }
        }
    }
    Ok(out)
}

/// Check that every existing component of `dir` below `root` is a real directory (not a link,
/// not a file); components that do not exist yet are fine.
pub fn check_real_dirs(root: &Path, dir: &Path) -> io::Result<()> {
    for at in components_below(root, dir)? {
        match std::fs::symlink_metadata(&at) {
            Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(()),
            Err(e) => return Err(e),
            Ok(m) if m.file_type().is_symlink() => return Err(link_refused(&at)),
            Ok(m) if !m.is_dir() => {
                return Err(io::Error::new(
                    io::ErrorKind::InvalidInput,
                    format!("{} is not a directory", at.display()),
                ))
            }
            Ok(_) => {}
        }
    }
    Ok(())
}

/// Create `dir` and every missing directory between `root` and it, each a real directory: an
/// existing link or file on the way is refused, and one made in between by someone else is
/// checked again after the attempt.
pub fn create_real_dirs(root: &Path, dir: &Path) -> io::Result<()> {
    if !root.as_os_str().is_empty() {
        std::fs::create_dir_all(root)?;
    }
    for at in components_below(root, dir)? {
        match std::fs::create_dir(&at) {
            Ok(()) => {}
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => {}
            Err(e) => return Err(e),
        }
        let m = std::fs::symlink_metadata(&at)?;
        if m.file_type().is_symlink() {
            return Err(link_refused(&at));
        }
        if !m.is_dir() {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("{} is not a directory", at.display()),
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::symlink;

    #[test]
    fn directories_below_the_root_must_be_real() {
        let t = tempfile::tempdir().unwrap();
        let outside = tempfile::tempdir().unwrap();
        let root = t.path().join("results");
        create_real_dirs(&root, &root.join("exp/our1/seed-0")).unwrap();
        assert!(root.join("exp/our1/seed-0").is_dir());
        check_real_dirs(&root, &root.join("exp/our1/seed-0/more")).unwrap();
        // A linked experiment directory: neither checked through nor created through.
        symlink(outside.path(), root.join("linked")).unwrap();
        let err = check_real_dirs(&root, &root.join("linked/our1/seed-0")).unwrap_err();
        assert!(err.to_string().contains("symbolic link"), "{err}");
        let err = create_real_dirs(&root, &root.join("linked/our1/seed-0")).unwrap_err();
        assert!(err.to_string().contains("symbolic link"), "{err}");
        assert_eq!(std::fs::read_dir(outside.path()).unwrap().count(), 0);
        // A file on the way, and a path that leaves the root.
        std::fs::write(root.join("file"), "").unwrap();
        assert!(create_real_dirs(&root, &root.join("file/x")).is_err());
        assert!(check_real_dirs(&root, &root.join("../elsewhere")).is_err());
        // The root itself may be a link: the user named it.
        let via_link = t.path().join("via");
        symlink(&root, &via_link).unwrap();
        create_real_dirs(&via_link, &via_link.join("exp/our1/seed-1")).unwrap();
    }

    #[test]
    fn no_follow_opens_refuse_a_link_by_name() {
        let t = tempfile::tempdir().unwrap();
        let target = t.path().join("target");
        std::fs::write(&target, "secret").unwrap();
        let link = t.path().join(".lock");
        symlink(&target, &link).unwrap();
        let e = open_options_no_follow()
            .write(true)
            .create(true)
            .truncate(false)
            .open(&link)
            .map_err(|e| explain_no_follow(&link, e))
            .unwrap_err();
        assert!(e.to_string().contains("symbolic link"), "{e}");
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "secret");
    }
}
