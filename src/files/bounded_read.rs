//! Reading a file whose size we can bound: only regular files (a FIFO would block forever and
//! `/dev/zero` would read until memory runs out), and only up to a known size, checked before
//! reading and enforced while reading (the file may grow in between).

use std::io::{self, Read};
use std::path::Path;

/// Text macdec reads whole: experiment files, a run's `config.toml`, a results tree's shared-curve
/// list. The largest committed one is a few KiB.
pub const MAX_TEXT_BYTES: u64 = 1 << 20;
/// A `replay --actions` file: a long episode's actions as JSON.
pub const MAX_ACTIONS_BYTES: u64 = 64 << 20;
/// A metrics file, after decompression: at most 10^6 evaluation rows of a few hundred bytes.
pub const MAX_METRICS_BYTES: u64 = 512 << 20;
/// A safetensors file of one net read by its own reader (a policy's weight files are bounded
/// tighter, by their architecture's size).
pub const MAX_WEIGHTS_BYTES: u64 = 4 << 30;
/// A training checkpoint (nets, optimizer state and the replay buffer, bounded in turn by the
/// config's limits).
pub const MAX_CHECKPOINT_BYTES: u64 = 64 << 30;

/// Whether a read follows a link at the file's own name: a path the user typed may be a link;
/// a file inside a results tree may not ([`super::links`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Links {
    /// Follow a link to its target.
    Follow,
    /// Refuse a link by name.
    Refuse,
}

/// Open `path` for reading if it is a regular file, checked on the open handle (no race
/// between the check and the read). The open is non-blocking, so a FIFO is refused instead of
/// waiting forever for a writer.
pub fn open_regular(path: &Path, links: Links) -> io::Result<std::fs::File> {
    use std::os::unix::fs::OpenOptionsExt;
    let mut options = match links {
        Links::Follow => std::fs::OpenOptions::new(),
        Links::Refuse => super::links::open_options_no_follow(),
    };
    let flags = libc::O_NONBLOCK
        | match links {
            Links::Follow => 0,
            Links::Refuse => libc::O_NOFOLLOW,
        };
    let file = options
        .read(true)
        .custom_flags(flags)
        .open(path)
        .map_err(|e| super::links::explain_no_follow(path, e))?;
    if !file.metadata()?.is_file() {
        return Err(io::Error::new(io::ErrorKind::InvalidInput, NotRegular));
    }
    Ok(file)
}

/// The bytes of the regular file `path`, refusing anything else and anything over `max_bytes`.
pub fn read_regular_file(path: &Path, max_bytes: u64) -> io::Result<Vec<u8>> {
    read_regular(path, max_bytes, Links::Follow)
}

/// [`read_regular_file`] for a file inside a results tree: a link is refused too.
pub fn read_in_tree(path: &Path, max_bytes: u64) -> io::Result<Vec<u8>> {
    read_regular(path, max_bytes, Links::Refuse)
}

/// [`read_in_tree`] as UTF-8 text.
pub fn read_text_in_tree(path: &Path, max_bytes: u64) -> io::Result<String> {
    String::from_utf8(read_in_tree(path, max_bytes)?)
        .map_err(|_| io::Error::new(io::ErrorKind::InvalidData, "not UTF-8 text"))
}

/// [`read_regular_file`] as UTF-8 text.
pub fn read_text_file(path: &Path, max_bytes: u64) -> io::Result<String> {
    String::from_utf8(read_regular_file(path, max_bytes)?)
        .map_err(|_| io::Error::new(io::ErrorKind::InvalidData, "not UTF-8 text"))
}

/// The bytes of the regular file `path` (a link at its name followed or refused as `links`
/// says), at most `max_bytes`: checked before reading and enforced while reading (the file
/// may grow in between).
pub fn read_regular(path: &Path, max_bytes: u64, links: Links) -> io::Result<Vec<u8>> {
    let file = open_regular(path, links)?;
    let len = file.metadata()?.len();
    if len > max_bytes {
        return Err(too_big(len, max_bytes));
    }
    let mut bytes = Vec::with_capacity(len as usize);
    file.take(max_bytes + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_big(bytes.len() as u64, max_bytes));
    }
    Ok(bytes)
}

/// Decompress gzip `bytes`, refusing output over `max_bytes` (a small crafted file can expand
/// a thousandfold).
pub fn gunzip_bounded(bytes: &[u8], max_bytes: u64) -> io::Result<Vec<u8>> {
    let mut out = Vec::new();
    flate2::read::GzDecoder::new(bytes)
        .take(max_bytes + 1)
        .read_to_end(&mut out)?;
    if out.len() as u64 > max_bytes {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!("decompresses to more than {max_bytes} bytes"),
        ));
    }
    Ok(out)
}

fn too_big(len: u64, max_bytes: u64) -> io::Error {
    io::Error::new(io::ErrorKind::FileTooLarge, TooBig { len, max_bytes })
}

/// The error inside the [`io::Error`] of a read refused because the path is a directory, FIFO,
/// device or socket, for callers with their own error variant for it (`e.get_ref()`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("not a regular file")]
pub struct NotRegular;

/// The error inside the [`io::Error`] of a read refused for its size: at least `len` bytes where
/// `max_bytes` is the bound.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("{len} bytes or more, at most {max_bytes} expected")]
pub struct TooBig {
    /// Bytes found (the size, or what was read before the bound stopped it).
    pub len: u64,
    /// The bound.
    pub max_bytes: u64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_regular_files_within_the_bound_are_read() {
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("w");
        std::fs::write(&f, [7u8; 100]).unwrap();
        assert_eq!(read_regular_file(&f, 100).unwrap().len(), 100);
        assert!(read_regular_file(&f, 99).is_err());
        assert!(read_regular_file(dir.path(), 1000).is_err());
        if Path::new("/dev/zero").exists() {
            let e = read_regular_file(Path::new("/dev/zero"), 1000).unwrap_err();
            assert!(e.to_string().contains("not a regular file"), "{e}");
        }
        let fifo = dir.path().join("fifo");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|s| s.success()) {
            // Would block forever if opened.
            assert!(read_regular_file(&fifo, 1000).is_err());
        }
    }

    #[test]
    fn links_are_followed_or_refused_as_asked() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("secret");
        std::fs::write(&target, "x").unwrap();
        let link = dir.path().join("config.toml");
        std::os::unix::fs::symlink(&target, &link).unwrap();
        assert_eq!(read_regular_file(&link, 10).unwrap(), b"x");
        let e = read_in_tree(&link, 10).unwrap_err();
        assert!(e.to_string().contains("symbolic link"), "{e}");
    }

    #[test]
    fn a_gzip_bomb_stops_at_the_bound() {
        use std::io::Write;
        let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
        e.write_all(&vec![b'0'; 10_000_000]).unwrap();
        let bomb = e.finish().unwrap();
        assert!(bomb.len() < 20_000);
        let err = gunzip_bounded(&bomb, 1_000_000).unwrap_err();
        assert!(err.to_string().contains("more than 1000000 bytes"), "{err}");
        assert_eq!(gunzip_bounded(&bomb, 10_000_000).unwrap().len(), 10_000_000);
    }
}
