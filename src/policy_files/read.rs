//! The one loader of policy descriptions: reads `policy.json` of this format's version, or a
//! version-1 description (a run's `macdec-run-policy` or an export's `manifest.json`), converted
//! by [`super::legacy`].

use super::error::PolicyError;
use super::format::{FORMAT, FORMAT_VERSION, POLICY_FILE};
use super::legacy;
use super::manifest::{Manifest, MAX_DESCRIPTION_BYTES};
use crate::files::bounded_read::read_regular_file;
use std::path::Path;

impl Manifest {
    /// The one loader of descriptions: `dir/policy.json` of any version this build reads, or
    /// `dir/manifest.json` of an export from before format_version 2; older versions are
    /// converted. Validated (structure and layout; weight files are checked when read, by
    /// [`Self::read_net`]).
    pub fn read(dir: &Path) -> Result<Manifest, PolicyError> {
        let path = match [POLICY_FILE, legacy::MANIFEST_FILE_V1]
            .iter()
            .map(|f| dir.join(f))
            .find(|p| p.exists())
        {
            Some(path) => path,
            None => {
                return Err(PolicyError::Missing {
                    dir: dir.to_path_buf(),
                })
            }
        };
        let bytes = read_regular_file(&path, MAX_DESCRIPTION_BYTES)
            .map_err(|e| PolicyError::io(&path, e))?;
        let parse = |message: String| PolicyError::Parse {
            path: path.clone(),
            message,
        };
        let value: serde_json::Value =
            serde_json::from_slice(&bytes).map_err(|e| parse(e.to_string()))?;
        // Format and version first, so a future layout is named as such, not as a parse error.
        let format = value.get("format").and_then(|v| v.as_str()).unwrap_or("");
        let version = value
            .get("format_version")
            .and_then(|v| v.as_u64())
            .ok_or_else(|| parse("`format_version` is missing or not a number".into()))?;
        let manifest = match (format, version) {
            (FORMAT, v) if v == u64::from(FORMAT_VERSION) => {
                serde_json::from_value(value).map_err(|e| parse(e.to_string()))?
            }
            (FORMAT, 1) => legacy::export_v1(value, &path)?,
            (legacy::RUN_FORMAT_V1, 1) => legacy::run_v1(value, &path)?,
            (FORMAT | legacy::RUN_FORMAT_V1, found) => {
                return Err(PolicyError::Version { path, found })
            }
            (found, _) => {
                return Err(PolicyError::Format {
                    path,
                    found: found.to_string(),
                })
            }
        };
        manifest.validate(&path)?;
        Ok(manifest)
    }
}
