//! A run's policy files, under the path the tests name: `<run>/policy/` is a policy directory of
//! the one format in [`crate::policy_files`].

pub use crate::policy_files::{
    dec_file_name, read_policy_files, write_actor_policy_files, write_policy_files, NetRole,
    PolicyError, PolicyNets, CEN_FILE, POLICY_DIR, POLICY_FILE,
};
