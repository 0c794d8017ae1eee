//! The format's name, version and description file: what every reader and writer of policy
//! directories agrees on first.

/// The description file of every policy directory (a run's `policy/` and an export alike).
pub const POLICY_FILE: &str = "policy.json";
/// The `format` tag of [`POLICY_FILE`].
pub const FORMAT: &str = "macdec-policy";
/// The newest `format_version` this build reads, and the one it writes. Version 1 was two
/// formats (a run's `macdec-run-policy` and an export's `manifest.json`); both still load,
/// converted on read ([`super::legacy`]).
pub const FORMAT_VERSION: u32 = 2;
/// The description file of a version-1 export (read, never written; converted by
/// [`super::legacy`]).
pub const MANIFEST_FILE_V1: &str = "manifest.json";
