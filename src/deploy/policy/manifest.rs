//! The exported policy directory's description, under the path the tests and earlier releases
//! name: since format_version 2 it is the one policy-file format of [`crate::policy_files`]
//! (`policy.json`), shared with a run's `policy/` directory.

pub use crate::policy_files::{
    load_agent, load_all, sha256_hex, weights_file_name, AgentLayout, Manifest, PolicyError,
    RunInfo, VerifiedAgent, FORMAT, FORMAT_VERSION, POLICY_FILE as MANIFEST_FILE,
};
