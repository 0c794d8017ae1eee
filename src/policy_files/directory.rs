//! What a policy directory may hold: before a writer replaces one, everything in it must be a
//! policy directory's own file, so `export --out notes/` never deletes someone's notes.

use super::error::PolicyError;
use super::format::{MANIFEST_FILE_V1, POLICY_FILE};
use std::path::Path;

/// Whether `name` is a file a policy directory holds (or held before format_version 2), or a
/// temp file of an interrupted write.
fn is_policy_dir_file(name: &str) -> bool {
    let name = name.strip_prefix('.').unwrap_or(name);
    let base = name.split(".tmp").next().unwrap_or(name);
    [POLICY_FILE, MANIFEST_FILE_V1]
        .iter()
        .any(|f| base == *f || base.starts_with(&format!("{f}.")))
        || base.contains(".safetensors")
}

/// Refuse to replace a directory that holds anything but a policy directory's regular files:
/// `export --out notes/` or `import --out ~` must not delete someone's files.
pub(crate) fn check_only_policy_files(dir: &Path) -> Result<(), PolicyError> {
    let entries = match std::fs::read_dir(dir) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        other => other.map_err(|e| PolicyError::io(dir, e))?,
    };
    for entry in entries {
        let entry = entry.map_err(|e| PolicyError::io(dir, e))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        let regular = entry
            .file_type()
            .map_err(|e| PolicyError::io(dir, e))?
            .is_file();
        if !regular || !is_policy_dir_file(&name) {
            return Err(PolicyError::NotAPolicyDir {
                dir: dir.to_path_buf(),
                file: name,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_new_empty_or_earlier_policy_directories_are_written_over() {
        let dir = tempfile::tempdir().unwrap();
        check_only_policy_files(&dir.path().join("new")).unwrap();
        check_only_policy_files(dir.path()).unwrap();
        for f in [
            "policy.json",
            "manifest.json",
            "agent-0.safetensors",
            "dec_agent_2.safetensors",
            "cen.safetensors",
            ".agent-1.safetensors.123-4.tmp",
        ] {
            std::fs::write(dir.path().join(f), b"x").unwrap();
        }
        check_only_policy_files(dir.path()).unwrap();
        std::fs::write(dir.path().join("notes.txt"), b"mine").unwrap();
        let err = check_only_policy_files(dir.path()).unwrap_err().to_string();
        assert!(err.contains("notes.txt"), "{err}");
        std::fs::remove_file(dir.path().join("notes.txt")).unwrap();
        std::fs::create_dir(dir.path().join("cen.safetensors.d")).unwrap();
        assert!(check_only_policy_files(dir.path()).is_err());
    }
}
