//! Reading a file whose size we can bound: only regular files (a FIFO would block forever and
//! `/dev/zero` would read until memory runs out), and only up to a known size, checked before
//! reading and enforced while reading (the file may grow in between).

use std::io::{self, Read};
use std::path::Path;

/// The bytes of the regular file `path`, refusing anything else and anything over `max_bytes`.
pub fn read_regular_file(path: &Path, max_bytes: u64) -> io::Result<Vec<u8>> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "not a regular file",
        ));
    }
    let too_big = |len: u64| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            format!("{len} bytes or more, at most {max_bytes} expected"),
        )
    };
    if meta.len() > max_bytes {
        return Err(too_big(meta.len()));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    std::fs::File::open(path)?
        .take(max_bytes + 1)
        .read_to_end(&mut bytes)?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_big(bytes.len() as u64));
    }
    Ok(bytes)
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
}
