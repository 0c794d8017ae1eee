//! Writing and reading one event file: `events.out.tfevents.<unix seconds>.<hostname>` in a
//! directory TensorBoard shows as one run. A new file is created for every writer and never
//! reopened, so a process that resumes work appends a file beside an older one instead of
//! writing into it.

use super::event::{Event, What, FILE_VERSION};
use super::record::{frame, unframe};
use crate::files::links::{explain_no_follow, open_options_no_follow};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// The prefix TensorBoard recognizes event files by (it looks for `tfevents` in the name).
pub const FILE_PREFIX: &str = "events.out.tfevents.";

/// An open event file, written through a buffer: call [`EventWriter::flush`] for a reader to
/// see what was written.
pub struct EventWriter {
    file: io::BufWriter<std::fs::File>,
    path: PathBuf,
}

impl EventWriter {
    /// Create a new event file in `dir` (which must exist) and write its first event, the
    /// [`FILE_VERSION`] at `wall_time`. The name is
    /// `events.out.tfevents.<wall_time as 10-digit seconds>.<hostname>`, with `.1`, `.2`, ...
    /// appended when a file of that second exists already (TensorBoard reads a run's files in
    /// name order, so the appended name still sorts after the earlier file). An existing file is
    /// never opened, nor a link followed.
    pub fn create(dir: &Path, wall_time: f64) -> io::Result<Self> {
        let base = format!("{FILE_PREFIX}{:010}.{}", wall_time as u64, hostname());
        let mut n = 0u32;
        let (file, path) = loop {
            let name = match n {
                0 => base.clone(),
                n => format!("{base}.{n}"),
            };
            let path = dir.join(name);
            match open_options_no_follow()
                .write(true)
                .create_new(true)
                .open(&path)
            {
                Ok(file) => break (file, path),
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists && n < 1000 => n += 1,
                Err(e) => return Err(with_path(&path, explain_no_follow(&path, e))),
            }
        };
        let mut writer = EventWriter {
            file: io::BufWriter::new(file),
            path,
        };
        writer.write(&Event {
            wall_time,
            step: 0,
            what: What::FileVersion(FILE_VERSION.to_string()),
        })?;
        Ok(writer)
    }

    /// Append one event (buffered).
    pub fn write(&mut self, event: &Event) -> io::Result<()> {
        self.file
            .write_all(&frame(&event.encode()))
            .map_err(|e| with_path(&self.path, e))
    }

    /// Hand everything written so far to the operating system, where TensorBoard reads it.
    pub fn flush(&mut self) -> io::Result<()> {
        self.file.flush().map_err(|e| with_path(&self.path, e))
    }

    /// The file being written.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

/// Every event of the file at `path`, checksums checked (for tests and checks: what
/// [`EventWriter`] wrote; TensorBoard is the reader that matters). A record cut short, a bad
/// checksum or an event of another kind is an error naming the file and the byte.
pub fn read_events(path: &Path) -> io::Result<Vec<Event>> {
    let bytes = std::fs::read(path).map_err(|e| with_path(path, e))?;
    let invalid = |what: String| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            format!("{}: {what}", path.display()),
        )
    };
    unframe(&bytes)
        .map_err(|e| invalid(e.to_string()))?
        .into_iter()
        .enumerate()
        .map(|(i, data)| Event::decode(data).map_err(|e| invalid(format!("record {i}: {e}"))))
        .collect()
}

/// The event files in `dir`, by name (the order TensorBoard reads them in).
pub fn event_files(dir: &Path) -> io::Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(|e| with_path(dir, e))? {
        let entry = entry.map_err(|e| with_path(dir, e))?;
        if entry.file_name().to_string_lossy().starts_with(FILE_PREFIX) {
            files.push(entry.path());
        }
    }
    files.sort();
    Ok(files)
}

fn with_path(path: &Path, e: io::Error) -> io::Error {
    io::Error::new(e.kind(), format!("{}: {e}", path.display()))
}

/// This machine's name as one file-name component (letters, digits, `-`, `_`, `.`; anything else
/// becomes `_`), or `localhost` when it has none: TensorBoard's writers name files by host so
/// that machines sharing a log directory never pick the same name.
pub fn hostname() -> String {
    let mut buf = [0u8; 256];
    // SAFETY: the buffer is writable for its whole length, which is passed; gethostname writes at
    // most that many bytes.
    let ok = unsafe { libc::gethostname(buf.as_mut_ptr().cast(), buf.len()) } == 0;
    let len = buf.iter().position(|&b| b == 0).unwrap_or(buf.len());
    let name: String = String::from_utf8_lossy(&buf[..if ok { len } else { 0 }])
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "-_.".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    if name.is_empty() || name.chars().all(|c| c == '.') {
        "localhost".to_string()
    } else {
        name
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::files::tensorboard::event::Scalar;

    #[test]
    fn a_written_file_reads_back_event_for_event() {
        let dir = tempfile::tempdir().unwrap();
        let mut w = EventWriter::create(dir.path(), 1_700_000_000.5).unwrap();
        let name = w.path().file_name().unwrap().to_str().unwrap().to_string();
        assert_eq!(
            name,
            format!("events.out.tfevents.1700000000.{}", hostname())
        );
        let scalars = Event {
            wall_time: 1_700_000_001.0,
            step: 5,
            what: What::Scalars(vec![Scalar {
                tag: "eval_return".into(),
                value: 2.5,
            }]),
        };
        w.write(&scalars).unwrap();
        // Nothing reaches the file before a flush.
        assert_eq!(std::fs::metadata(w.path()).unwrap().len(), 0);
        w.flush().unwrap();
        let events = read_events(w.path()).unwrap();
        assert_eq!(
            events,
            [
                Event {
                    wall_time: 1_700_000_000.5,
                    step: 0,
                    what: What::FileVersion("brain.Event:2".into()),
                },
                scalars,
            ]
        );
    }

    #[test]
    fn a_second_writer_in_the_same_second_gets_a_later_name_and_the_first_file_is_untouched() {
        let dir = tempfile::tempdir().unwrap();
        let mut first = EventWriter::create(dir.path(), 1_700_000_000.0).unwrap();
        first.flush().unwrap();
        let before = std::fs::read(first.path()).unwrap();
        let mut second = EventWriter::create(dir.path(), 1_700_000_000.9).unwrap();
        second.flush().unwrap();
        let third = EventWriter::create(dir.path(), 1_700_000_000.9).unwrap();
        assert_eq!(
            event_files(dir.path()).unwrap(),
            [
                first.path().to_path_buf(),
                second.path().to_path_buf(),
                third.path().to_path_buf()
            ]
        );
        assert!(second.path().to_str().unwrap().ends_with(".1"));
        assert_eq!(std::fs::read(first.path()).unwrap(), before);
    }

    #[test]
    fn a_cut_file_is_an_error_naming_it() {
        let dir = tempfile::tempdir().unwrap();
        let mut w = EventWriter::create(dir.path(), 1.0).unwrap();
        w.flush().unwrap();
        let bytes = std::fs::read(w.path()).unwrap();
        std::fs::write(w.path(), &bytes[..bytes.len() - 2]).unwrap();
        let e = read_events(w.path()).unwrap_err().to_string();
        assert!(
            e.contains(&w.path().display().to_string()) && e.contains("ends inside a record"),
            "{e}"
        );
    }

    #[test]
    fn the_hostname_is_one_plain_path_component() {
        let h = hostname();
        assert!(
            !h.is_empty() && !h.contains('/') && h != "." && h != "..",
            "{h}"
        );
    }
}
