//! Policy files: a directory of nets (one safetensors file each) and `policy.json` describing
//! them, the one format of a training run's `policy/` directory (written with every checkpoint)
//! and of an exported or imported policy that robots serve. One writer ([`Manifest::write_new`]),
//! one loader ([`Manifest::read`], [`Manifest::read_net`]) and one error ([`PolicyError`]) serve
//! `train`, `export`, `import`, `eval`, `robot`, `deploy`, `render` and the library.
//!
//! It sits beside [`crate::files`] on the ground floor: it knows domains ([`crate::envs`]) and
//! nets ([`crate::nn`]), never a learner, a run or a robot, so every layer may read and write it.
//!
//! Nets are described by kind (`q` or `actor`; a critic would be another), role (`dec` with an
//! agent, or `cen`), their input and output lengths and their architecture, so every family's
//! policy is written and loaded the same way: a training run's learner hands over one list of
//! nets, each saying its kind, role and agent and whether the evaluated policy acts with it
//! ([`SavedNet`]), and [`write_policy_files`] writes that list without asking which family
//! trained it. An
//! export is a policy directory holding fewer nets: each agent's decentralized net (`evaluated`
//! `dec`) beside the per-agent layout robots need.
//!
//! ```json
//! {"format": "macdec-policy", "format_version": 2,
//!  "env": {"env": "box-pushing", "grid": 10, "horizon": 100}, "discount": 0.98,
//!  "evaluated": "dec",
//!  "agents": [{"index": 0, "obs_size": 5, "obs_names": [...], "n_actions": 8,
//!              "action_names": [...]}, ...],
//!  "nets": [{"kind": "q", "role": "dec", "agent": 0, "file": "dec_agent_0.safetensors",
//!            "sha256": "9f86...", "input": 5, "output": 8,
//!            "architecture": {"kind": "ddrqn", "mlp_layer_size": 32, "rnn_h_size": 32,
//!                             "leaky_relu_slope": 0.01}},
//!           {"kind": "q", "role": "cen", "file": "cen.safetensors", ...}],
//!  "experiment": "fig4a", "method": "our1", "variant": "", "seed": 3,
//!  "episodes_trained": 15000, "config": {...}}
//! ```
//!
//! A domain defined outside this binary is named `{"env": "custom", "name": ..., "horizon": ...}`
//! ([`PolicyEnv`]); its layout is then checked only for consistency.
//!
//! Loading checks everything against the domain and the files, so nothing runs weights that are
//! corrupt, truncated, swapped between agents or written for another domain: the SHA-256 of every
//! weight file, bounded reads of regular files only, each file's tensors against its entry, the
//! layout against a built-in domain. A write replaces the whole directory in one atomic step
//! (a new generation swapped in), so a kill or a concurrent reader never meets a mixed set.
//!
//! Compatibility: `agents` entries and architectures refuse unknown keys (a typo is an error,
//! as export manifests always did); the top level and net entries ignore keys they do not know
//! (as a run's policy.json always did), so a newer build may add optional keys without a new
//! version. `format_version` is bumped for any change an older reader would misread, and a
//! reader refuses versions newer than it knows. Version 1's two formats, a run's
//! `"macdec-run-policy"` policy.json and an export's `manifest.json`, still load ([`legacy`]).

pub mod architecture;
mod directory;
pub mod error;
pub mod format;
pub mod legacy;
pub mod manifest;
pub mod policy_env;
mod read;
pub mod run_nets;

pub use architecture::{Architecture, WeightsError};
pub use error::PolicyError;
pub use manifest::{
    load_agent, load_all, sha256_hex, weights_file_name, AgentLayout, Manifest, NetEntry, NetFile,
    NetKind, NetRole, RunInfo, VerifiedAgent, FORMAT, FORMAT_VERSION, POLICY_FILE,
};
pub use policy_env::{CustomEnv, NotInBinary, PolicyEnv};
pub use run_nets::{
    dec_file_name, read_nets, read_policy_files, write_policy_files, PolicyNets, SavedNet,
    CEN_FILE, POLICY_DIR,
};
