//! `macdec import` (issue 12): a policy directory from state_dicts of the reference's PyTorch
//! `DDRQN` modules, one safetensors file per agent (see `scripts/torch_to_safetensors.py` for
//! `torch.save`d modules). Each file is checked against the domain and the architecture (M and H
//! read from its shapes), its tensors are renamed to the canonical `lstm.*` scheme, and the
//! directory is written by [`Manifest::write_policy`], exactly as `macdec export` writes one.
//!
//! The reference names the LSTM `lstm` in `MA_dec_cen_hddrqn` (MacDec-MADDRQN, Our-1/Our-2) and
//! `rnn` in `MA_hddrqn` (Dec-HDDRQN); both are accepted.

use crate::envs::{AnyEnv, EnvSpec, MacroEnv};
use crate::files::bounded_read::{read_regular_file, NotRegular, TooBig};
use crate::nn::safetensors_io::{from_safetensors_bytes, to_safetensors_bytes};
use crate::nn::QNetConfig;
use crate::policy_files::architecture::Architecture;
use crate::policy_files::{sha256_hex, Manifest, PolicyError, RunInfo};
use safetensors::tensor::Dtype;
use safetensors::SafeTensors;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Largest state_dict file read. The paper's nets are about 0.1 MB (Warehouse, H = 64); even
/// M = H = 1024 stays under 40 MB, so anything larger is not a DDRQN and is refused unread.
pub const MAX_STATE_DICT_BYTES: u64 = 64 << 20;

/// `run.experiment` and `run.method` of an imported policy.
pub const IMPORTED: &str = "imported";

/// Prefix of the LSTM's tensors in the reference's `MA_hddrqn` (Dec-HDDRQN) module.
const RNN_PREFIX: &str = "rnn.";
/// Prefix of the LSTM's tensors in `MA_dec_cen_hddrqn` and in macdec's files.
const LSTM_PREFIX: &str = "lstm.";

/// Why a state_dict could not be imported. Messages name the file, and the tensor when one is
/// at fault.
#[derive(Debug, thiserror::Error)]
pub enum ImportError {
    /// A file could not be read.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error, as text.
        message: String,
    },
    /// The path is a directory, FIFO or device, refused before reading.
    #[error("{path}: not a regular file")]
    NotAFile {
        /// The path given.
        path: PathBuf,
    },
    /// The file exceeds [`MAX_STATE_DICT_BYTES`], refused unread.
    #[error("{path}: {size} bytes, more than any DDRQN state_dict ({MAX_STATE_DICT_BYTES} bytes at most); not read")]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// Its size in bytes.
        size: u64,
    },
    /// The bytes are not a safetensors file.
    #[error("{path}: not a safetensors file ({reason}); convert a torch.save'd module with scripts/torch_to_safetensors.py")]
    Unreadable {
        /// The file.
        path: PathBuf,
        /// The safetensors parser's reason.
        reason: String,
    },
    /// Both the `lstm.*` and the `rnn.*` naming appear in one file.
    #[error(
        "{path}: holds both `lstm.*` and `rnn.*` tensors (`{lstm}`, `{rnn}`); a DDRQN has one LSTM"
    )]
    MixedNaming {
        /// The file.
        path: PathBuf,
        /// One `lstm.*` tensor found.
        lstm: String,
        /// One `rnn.*` tensor found.
        rnn: String,
    },
    /// A tensor the architecture needs is absent.
    #[error("{path}: tensor `{name}` is missing (expected shape {expected})")]
    Missing {
        /// The file.
        path: PathBuf,
        /// Canonical tensor name, e.g. `fc1.weight`.
        name: String,
        /// The shape, e.g. `[32, 5]`, or `[M, 5]` while M is not known yet.
        expected: String,
    },
    /// A tensor that is not part of a DDRQN.
    #[error("{path}: unexpected tensor `{name}`; a DDRQN state_dict has exactly {expected}")]
    Unexpected {
        /// The file.
        path: PathBuf,
        /// The tensor's name as stored.
        name: String,
        /// The tensor names a DDRQN state_dict holds.
        expected: String,
    },
    /// A tensor is not F32.
    #[error("{path}: tensor `{name}` has dtype {found}, expected F32")]
    Dtype {
        /// The file.
        path: PathBuf,
        /// Canonical tensor name.
        name: String,
        /// The dtype stored.
        found: String,
    },
    /// A tensor's shape does not fit the domain or the architecture.
    #[error("{path}: tensor `{name}` has shape {found:?}, expected {expected}{hint}")]
    Shape {
        /// The file.
        path: PathBuf,
        /// Canonical tensor name.
        name: String,
        /// The shape stored.
        found: Vec<usize>,
        /// As in [`ImportError::Missing`].
        expected: String,
        /// Extra advice appended to the message (may be empty).
        hint: String,
    },
    /// A weight is NaN or infinite.
    #[error("{path}: tensor `{name}` holds {value} at element {index}; weights must be finite")]
    NonFinite {
        /// The file.
        path: PathBuf,
        /// Canonical tensor name.
        name: String,
        /// Flat (row-major) element index.
        index: usize,
        /// The value found.
        value: f32,
    },
    /// Two agents' Q-nets have different M or H.
    #[error("{path}: M = {m}, H = {h}, but {first} has M = {first_m}, H = {first_h}; all agents of a policy share one architecture")]
    ArchitectureMismatch {
        /// The file that disagrees.
        path: PathBuf,
        /// Its M (fc1 and fc3 width).
        m: usize,
        /// Its H (fc2 and LSTM width).
        h: usize,
        /// The first agent's file, whose widths the others must match.
        first: PathBuf,
        /// M of the first file.
        first_m: usize,
        /// H of the first file.
        first_h: usize,
    },
    /// Two agents' actors have different widths.
    #[error("{path}: widths {mlp:?} and hidden size {hidden}, but {first} has {first_mlp:?} and {first_hidden}; all agents of a policy share one architecture")]
    ActorMismatch {
        /// The file that disagrees.
        path: PathBuf,
        /// Its two MLP widths.
        mlp: [usize; 2],
        /// Its recurrent hidden size.
        hidden: usize,
        /// The first agent's file, whose widths the others must match.
        first: PathBuf,
        /// MLP widths of the first file.
        first_mlp: [usize; 2],
        /// Hidden size of the first file.
        first_hidden: usize,
    },
    /// Two agents' ACAC actors differ in architecture.
    #[error("{path}: {arch}, but {first} has {first_arch}; all agents of a policy share one architecture")]
    AcacActorMismatch {
        /// The file that disagrees.
        path: PathBuf,
        /// Its architecture, in words.
        arch: String,
        /// The first agent's file.
        first: PathBuf,
        /// The first file's architecture, in words.
        first_arch: String,
    },
    /// The number of files is not the domain's number of agents.
    #[error("the {env} domain has {expected} agents, {got} state_dict files were given (one per agent, in agent order)")]
    AgentCount {
        /// The domain's name.
        env: &'static str,
        /// Agents the domain has.
        expected: usize,
        /// Files given.
        got: usize,
    },
    /// The domain could not be built from its config (the message says why).
    #[error("environment: {0}")]
    Env(String),
    /// Writing or checking the policy directory failed.
    #[error(transparent)]
    Policy(#[from] PolicyError),
}

/// Which name the file gave the LSTM.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Naming {
    /// `lstm.*` (`MA_dec_cen_hddrqn`, macdec).
    #[serde(rename = "lstm.*")]
    Lstm,
    /// `rnn.*` (`MA_hddrqn`).
    #[serde(rename = "rnn.*")]
    Rnn,
}

/// One agent's state_dict, checked: its widths, how it named the LSTM, and the canonical
/// safetensors bytes (what `macdec export` writes for the same parameters).
#[derive(Debug, Clone, PartialEq)]
pub struct CheckedStateDict {
    /// M: width of fc1 and fc3 (rows of `fc1.weight`).
    pub mlp: usize,
    /// H: width of fc2 and the LSTM (rows of `fc2.weight`).
    pub hidden: usize,
    /// Which LSTM naming the file used (reported; the written file is always `lstm.*`).
    pub naming: Naming,
    /// The safetensors bytes under canonical names, as `macdec export` writes them.
    pub canonical: Vec<u8>,
}

/// What to import: the domain, the discount of the reported return, and one file per agent.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportRequest {
    /// The domain the policy acts in (its name and config).
    pub env: EnvSpec,
    /// Discount per primitive step of the evaluation return written into the manifest
    /// (the paper's is [`EnvSpec::paper_discount`]).
    pub discount: f64,
    /// Agent i's state_dict file is `agents[i]`.
    pub agents: Vec<PathBuf>,
}

/// Read `path` whole, refusing anything but a regular file of at most `max_bytes` before
/// reading it (a FIFO or device would block or never end): [`read_regular_file`] with this
/// command's errors.
pub fn read_bounded(path: &Path, max_bytes: u64) -> Result<Vec<u8>, ImportError> {
    read_regular_file(path, max_bytes).map_err(|e| {
        let inner = e.get_ref();
        if let Some(big) = inner.and_then(|i| i.downcast_ref::<TooBig>()) {
            ImportError::TooLarge {
                path: path.to_path_buf(),
                size: big.len,
            }
        } else if inner.is_some_and(|i| i.is::<NotRegular>()) {
            ImportError::NotAFile {
                path: path.to_path_buf(),
            }
        } else {
            ImportError::Io {
                path: path.to_path_buf(),
                message: e.to_string(),
            }
        }
    })
}

/// The canonical name of a tensor (`rnn.X` -> `lstm.X`).
fn canonical_name(name: &str) -> String {
    match name.strip_prefix(RNN_PREFIX) {
        Some(rest) => format!("{LSTM_PREFIX}{rest}"),
        None => name.to_string(),
    }
}

/// Check one agent's state_dict `bytes` (from `path`, which labels errors) against a domain
/// agent with `obs_len` observation values and `n_actions` macro-actions: exactly the DDRQN's
/// twelve tensors (LSTM as `lstm.*` or `rnn.*`), each F32, finite and of the shape that M and H,
/// read from `fc1.weight` and `fc2.weight`, imply.
pub fn check_state_dict(
    bytes: &[u8],
    path: &Path,
    obs_len: usize,
    n_actions: usize,
) -> Result<CheckedStateDict, ImportError> {
    let p = || path.to_path_buf();
    let file = SafeTensors::deserialize(bytes).map_err(|e| ImportError::Unreadable {
        path: p(),
        reason: e.to_string(),
    })?;
    let mut names: Vec<&String> = file.names();
    names.sort();
    let lstm = names.iter().find(|n| n.starts_with(LSTM_PREFIX));
    let rnn = names.iter().find(|n| n.starts_with(RNN_PREFIX));
    let naming = match (lstm, rnn) {
        (Some(l), Some(r)) => {
            return Err(ImportError::MixedNaming {
                path: p(),
                lstm: l.to_string(),
                rnn: r.to_string(),
            })
        }
        (None, Some(_)) => Naming::Rnn,
        _ => Naming::Lstm,
    };
    let file_name = |canonical: &str| match naming {
        Naming::Rnn => canonical.replacen(LSTM_PREFIX, RNN_PREFIX, 1),
        Naming::Lstm => canonical.to_string(),
    };
    // M and H from the first two layers; their full shapes are checked with the rest below.
    let width = |name: &str, expected: String| -> Result<usize, ImportError> {
        let view = file.tensor(name).map_err(|_| ImportError::Missing {
            path: p(),
            name: name.to_string(),
            expected: expected.clone(),
        })?;
        match view.shape() {
            [rows, _] if *rows > 0 => Ok(*rows),
            got => Err(ImportError::Shape {
                path: p(),
                name: name.to_string(),
                found: got.to_vec(),
                expected,
                hint: " (M and H are read from the rows of fc1.weight and fc2.weight)".into(),
            }),
        }
    };
    let m = width("fc1.weight", format!("[M, {obs_len}]"))?;
    let h = width("fc2.weight", format!("[H, {m}]"))?;
    let arch = Architecture::ddrqn(m, h);
    let expected = arch.tensors(obs_len, n_actions);
    if let Some(extra) = names
        .iter()
        .find(|n| !expected.iter().any(|(e, _)| *e == canonical_name(n)))
    {
        let listed: Vec<String> = expected.iter().map(|(e, _)| file_name(e)).collect();
        return Err(ImportError::Unexpected {
            path: p(),
            name: extra.to_string(),
            expected: listed.join(", "),
        });
    }
    let mut renamed = Vec::with_capacity(expected.len());
    for (canonical, shape) in &expected {
        let name = file_name(canonical);
        let view = file.tensor(&name).map_err(|_| ImportError::Missing {
            path: p(),
            name: name.clone(),
            expected: format!("{shape:?}"),
        })?;
        if view.dtype() != Dtype::F32 {
            return Err(ImportError::Dtype {
                path: p(),
                name,
                found: format!("{:?}", view.dtype()),
            });
        }
        if view.shape() != shape.as_slice() {
            let gru =
                canonical.starts_with("lstm.weight") && view.shape().first() == Some(&(3 * h));
            return Err(ImportError::Shape {
                path: p(),
                hint: if gru {
                    " (3H rows: a GRU; only the LSTM DDRQN is supported)".into()
                } else {
                    format!(" (M = {m}, H = {h}, {obs_len} observation values, {n_actions} macro-actions)")
                },
                name,
                found: view.shape().to_vec(),
                expected: format!("{shape:?}"),
            });
        }
        let bad = view
            .data()
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .enumerate()
            .find(|(_, v)| !v.is_finite());
        if let Some((index, value)) = bad {
            return Err(ImportError::NonFinite {
                path: p(),
                name,
                index,
                value,
            });
        }
        renamed.push((canonical.to_string(), view));
    }
    let renamed_bytes = safetensors::serialize(renamed.iter().map(|(n, v)| (n.as_str(), v)), &None)
        .map_err(|e| ImportError::Unreadable {
            path: p(),
            reason: e.to_string(),
        })?;
    let cfg = QNetConfig {
        input: obs_len,
        mlp: m,
        hidden: h,
        output: n_actions,
    };
    let params =
        from_safetensors_bytes(&renamed_bytes, cfg, path).map_err(|e| ImportError::Unreadable {
            path: p(),
            reason: e.to_string(),
        })?;
    Ok(CheckedStateDict {
        mlp: m,
        hidden: h,
        naming,
        canonical: to_safetensors_bytes(&params),
    })
}

/// One imported file as the manifest's `run.config` records it (every importer's).
#[derive(Debug, Serialize)]
pub struct ImportedFile {
    /// The agent it is the net of.
    pub agent: usize,
    /// The path as given on the command line.
    pub file: String,
    /// SHA-256 of the file as read (before any renaming).
    pub sha256: String,
    /// The ICRA Q-nets' LSTM naming, `lstm.*` or `rnn.*`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tensor_names: Option<Naming>,
}

impl ImportedFile {
    /// Agent `agent`'s file `path`, whose bytes as read are `bytes`.
    pub fn new(agent: usize, path: &Path, bytes: &[u8]) -> Self {
        ImportedFile {
            agent,
            file: path.display().to_string(),
            sha256: sha256_hex(bytes),
            tensor_names: None,
        }
    }
}

/// Every weight of `named` (a net's tensors by name, as read from `path`) is finite, else
/// [`ImportError::NonFinite`] naming the first tensor and element that is not.
pub fn check_finite<S: AsRef<str>>(
    path: &Path,
    named: &[(S, ndarray::ArrayViewD<'_, f32>)],
) -> Result<(), ImportError> {
    for (name, tensor) in named {
        if let Some((index, &value)) = tensor.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(ImportError::NonFinite {
                path: path.to_path_buf(),
                name: name.as_ref().to_string(),
                index,
                value,
            });
        }
    }
    Ok(())
}

/// The request's domain, built, with one file per agent (else [`ImportError::AgentCount`]).
pub fn request_domain(request: &ImportRequest) -> Result<AnyEnv, ImportError> {
    let env = request
        .env
        .build()
        .map_err(|e| ImportError::Env(e.to_string()))?;
    if request.agents.len() != env.n_agents() {
        return Err(ImportError::AgentCount {
            env: request.env.name(),
            expected: env.n_agents(),
            got: request.agents.len(),
        });
    }
    Ok(env)
}

/// The run section of an imported policy: `imported`, with `config` saying where from.
pub fn imported_run(config: serde_json::Value) -> RunInfo {
    RunInfo {
        experiment: IMPORTED.to_string(),
        method: IMPORTED.to_string(),
        variant: String::new(),
        seed: 0,
        episodes_trained: 0,
        config,
    }
}

/// Import one state_dict per agent into the policy directory `out` (see the module doc). The
/// manifest's run section says `imported` and lists each source file with its SHA-256.
pub fn import_policy(request: &ImportRequest, out: &Path) -> Result<Manifest, ImportError> {
    let env = request_domain(request)?;
    let mut checked: Vec<CheckedStateDict> = Vec::with_capacity(request.agents.len());
    let mut sources = Vec::with_capacity(request.agents.len());
    for (agent, path) in request.agents.iter().enumerate() {
        let bytes = read_bounded(path, MAX_STATE_DICT_BYTES)?;
        let one = check_state_dict(&bytes, path, env.obs_sizes()[agent], env.n_actions()[agent])?;
        if let Some(first) = checked.first() {
            if (first.mlp, first.hidden) != (one.mlp, one.hidden) {
                return Err(ImportError::ArchitectureMismatch {
                    path: path.clone(),
                    m: one.mlp,
                    h: one.hidden,
                    first: request.agents[0].clone(),
                    first_m: first.mlp,
                    first_h: first.hidden,
                });
            }
        }
        sources.push(ImportedFile {
            tensor_names: Some(one.naming),
            ..ImportedFile::new(agent, path, &bytes)
        });
        checked.push(one);
    }
    let (m, h) = (checked[0].mlp, checked[0].hidden);
    let run = imported_run(serde_json::json!({
        "imported_from": "PyTorch DDRQN state_dicts (reference code)",
        "files": sources,
    }));
    let weights: Vec<Vec<u8>> = checked.into_iter().map(|c| c.canonical).collect();
    Ok(Manifest::write_policy(
        out,
        request.env.clone(),
        request.discount,
        Architecture::ddrqn(m, h),
        run,
        &weights,
    )?)
}

/// A state_dict file as the reference's `DDRQN.state_dict()` names it, filled by
/// `value(canonical_name, index)`: test fixtures for both naming schemes.
pub fn reference_state_dict(
    arch: &Architecture,
    obs_len: usize,
    n_actions: usize,
    naming: Naming,
    value: impl Fn(&str, usize) -> f32,
) -> Vec<u8> {
    let rename = |name: &str| match naming {
        Naming::Rnn => name.replacen(LSTM_PREFIX, RNN_PREFIX, 1),
        Naming::Lstm => name.to_string(),
    };
    crate::policy_files::architecture::synthetic_weights_named(
        arch, obs_len, n_actions, rename, value,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::policy_files::architecture::synthetic_weights;
    use crate::policy_files::load_all;
    use safetensors::tensor::TensorView;

    fn bp10() -> EnvSpec {
        crate::envs::box_pushing::spec(10, 100)
    }

    fn value(name: &str, i: usize) -> f32 {
        ((i * 7 + name.len() * 13) % 17) as f32 * 0.1 - 0.8
    }

    fn write(dir: &Path, file: &str, bytes: &[u8]) -> PathBuf {
        let path = dir.join(file);
        std::fs::write(&path, bytes).unwrap();
        path
    }

    /// A state_dict with one tensor replaced (or removed when `replacement` is `None`).
    fn edited(
        naming: Naming,
        target: &str,
        replacement: Option<(&str, Dtype, Vec<usize>)>,
    ) -> Vec<u8> {
        let original = reference_state_dict(&Architecture::ddrqn(8, 4), 5, 8, naming, value);
        let file = SafeTensors::deserialize(&original).unwrap();
        let mut tensors: Vec<(String, Dtype, Vec<usize>, Vec<u8>)> = file
            .tensors()
            .into_iter()
            .filter(|(n, _)| n != target)
            .map(|(n, v)| (n, v.dtype(), v.shape().to_vec(), v.data().to_vec()))
            .collect();
        if let Some((name, dtype, shape)) = replacement {
            let n: usize = shape.iter().product::<usize>() * dtype.size();
            tensors.push((name.to_string(), dtype, shape, vec![0u8; n]));
        }
        let views = tensors
            .iter()
            .map(|(n, d, s, b)| (n.clone(), TensorView::new(*d, s.clone(), b).unwrap()));
        safetensors::serialize(views, &None).unwrap()
    }

    fn check(bytes: &[u8]) -> Result<CheckedStateDict, ImportError> {
        check_state_dict(bytes, Path::new("a1.safetensors"), 5, 8)
    }

    #[test]
    fn both_naming_schemes_give_the_bytes_export_writes() {
        let arch = Architecture::ddrqn(8, 4);
        let exported = from_safetensors_bytes(
            &synthetic_weights(&arch, 5, 8, value),
            QNetConfig {
                input: 5,
                mlp: 8,
                hidden: 4,
                output: 8,
            },
            Path::new("x"),
        )
        .unwrap();
        let canonical = to_safetensors_bytes(&exported);
        for naming in [Naming::Lstm, Naming::Rnn] {
            let bytes = reference_state_dict(&arch, 5, 8, naming, value);
            let got = check(&bytes).unwrap();
            assert_eq!((got.mlp, got.hidden, got.naming), (8, 4, naming));
            assert_eq!(got.canonical, canonical);
        }
        // The rnn.* fixture really uses rnn.* names.
        let rnn = reference_state_dict(&arch, 5, 8, Naming::Rnn, value);
        let names = SafeTensors::deserialize(&rnn).unwrap();
        assert!(names.tensor("rnn.weight_hh_l0").is_ok());
        assert!(names.tensor("lstm.weight_hh_l0").is_err());
    }

    #[test]
    fn wrong_names_shapes_and_dtypes_are_refused_naming_file_and_tensor() {
        type Case<'a> = (
            Naming,
            &'a str,
            Option<(&'a str, Dtype, Vec<usize>)>,
            &'a str,
        );
        let cases: Vec<Case> = vec![
            (
                Naming::Rnn,
                "fc4.bias",
                None,
                "tensor `fc4.bias` is missing (expected shape [8])",
            ),
            (
                Naming::Lstm,
                "fc1.weight",
                None,
                "tensor `fc1.weight` is missing (expected shape [M, 5])",
            ),
            (
                Naming::Lstm,
                "fc2.weight",
                Some(("fc2.weight", Dtype::F32, vec![32])),
                "`fc2.weight` has shape [32], expected [H, 8] (M and H are read",
            ),
            (
                Naming::Rnn,
                "rnn.bias_hh_l0",
                None,
                "tensor `rnn.bias_hh_l0` is missing",
            ),
            (
                Naming::Lstm,
                "fc3.bias",
                Some(("fc5.bias", Dtype::F32, vec![8])),
                "unexpected tensor `fc5.bias`",
            ),
            (
                Naming::Rnn,
                "rnn.weight_ih_l0",
                Some(("rnn.weight_ih_l0", Dtype::F32, vec![12, 4])),
                "`rnn.weight_ih_l0` has shape [12, 4], expected [16, 4] (3H rows: a GRU",
            ),
            (
                Naming::Lstm,
                "fc4.weight",
                Some(("fc4.weight", Dtype::F32, vec![7, 8])),
                "`fc4.weight` has shape [7, 8], expected [8, 8] (M = 8, H = 4",
            ),
            (
                Naming::Lstm,
                "fc1.weight",
                Some(("fc1.weight", Dtype::F32, vec![8, 6])),
                "`fc1.weight` has shape [8, 6], expected [8, 5]",
            ),
            (
                Naming::Lstm,
                "fc2.bias",
                Some(("fc2.bias", Dtype::F64, vec![4])),
                "`fc2.bias` has dtype F64, expected F32",
            ),
            (
                Naming::Lstm,
                "fc3.weight",
                Some(("rnn.weight_ih_l0", Dtype::F32, vec![16, 4])),
                "both `lstm.*` and `rnn.*`",
            ),
            (
                Naming::Rnn,
                "rnn.weight_hh_l0",
                Some(("rnn.weight_hh_l1", Dtype::F32, vec![16, 4])),
                "unexpected tensor `rnn.weight_hh_l1`",
            ),
        ];
        for (naming, target, replacement, needle) in cases {
            let err = check(&edited(naming, target, replacement))
                .unwrap_err()
                .to_string();
            assert!(
                err.starts_with("a1.safetensors: ") && err.contains(needle),
                "expected `{needle}` in: {err}"
            );
        }
        let err = check(b"\x80\x02}q\x00.").unwrap_err().to_string();
        assert!(err.contains("torch_to_safetensors.py"), "{err}");
    }

    #[test]
    fn non_finite_weights_are_refused_with_the_element() {
        let arch = Architecture::ddrqn(8, 4);
        let bytes = reference_state_dict(&arch, 5, 8, Naming::Lstm, |name, i| {
            if name == "fc3.weight" && i == 9 {
                f32::NAN
            } else {
                0.5
            }
        });
        let err = check(&bytes).unwrap_err().to_string();
        assert!(err.contains("`fc3.weight` holds NaN at element 9"), "{err}");
    }

    #[test]
    fn non_regular_and_oversized_files_are_refused_before_reading() {
        let dir = tempfile::tempdir().unwrap();
        let err = read_bounded(dir.path(), MAX_STATE_DICT_BYTES).unwrap_err();
        assert!(matches!(err, ImportError::NotAFile { .. }), "{err}");
        #[cfg(unix)]
        {
            let err = read_bounded(Path::new("/dev/zero"), MAX_STATE_DICT_BYTES).unwrap_err();
            assert!(matches!(err, ImportError::NotAFile { .. }), "{err}");
        }
        let big = dir.path().join("big.safetensors");
        let f = std::fs::File::create(&big).unwrap();
        f.set_len(MAX_STATE_DICT_BYTES + 1).unwrap(); // sparse: nothing is written
        let err = read_bounded(&big, MAX_STATE_DICT_BYTES)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("big.safetensors") && err.contains("not read"),
            "{err}"
        );
        let small = write(dir.path(), "small", b"12345");
        assert_eq!(read_bounded(&small, 5).unwrap(), b"12345");
        assert!(matches!(
            read_bounded(&small, 4),
            Err(ImportError::TooLarge { size: 5, .. })
        ));
        let err = read_bounded(&dir.path().join("absent"), 5).unwrap_err();
        assert!(err.to_string().contains("absent"), "{err}");
    }

    #[test]
    fn import_writes_a_verifiable_policy_recording_its_sources() {
        let dir = tempfile::tempdir().unwrap();
        let arch = Architecture::ddrqn(8, 4);
        let a0 = write(
            dir.path(),
            "a0.safetensors",
            &reference_state_dict(&arch, 5, 8, Naming::Lstm, value),
        );
        let a1_bytes = reference_state_dict(&arch, 5, 8, Naming::Rnn, |n, i| value(n, i + 1));
        let a1 = write(dir.path(), "a1.safetensors", &a1_bytes);
        let out = dir.path().join("policy");
        let request = ImportRequest {
            env: bp10(),
            discount: 0.98,
            agents: vec![a0.clone(), a1.clone()],
        };
        let written = import_policy(&request, &out).unwrap();
        let (manifest, verified) = load_all(&out).unwrap();
        assert_eq!(manifest, written);
        assert_eq!(manifest.discount, 0.98);
        assert!(manifest.nets.iter().all(|n| n.architecture == arch));
        assert_eq!(manifest.run.method, "imported");
        let files = &manifest.run.config["files"];
        assert_eq!(files[1]["file"], a1.display().to_string());
        assert_eq!(files[1]["sha256"], sha256_hex(&a1_bytes));
        assert_eq!(files[1]["tensor_names"], "rnn.*");
        assert_eq!(files[0]["tensor_names"], "lstm.*");
        let expected = check(&a1_bytes).unwrap().canonical;
        assert_eq!(verified[1].weights, expected);

        // Wrong agent count, and agents of different widths.
        let one = ImportRequest {
            agents: vec![a0.clone()],
            ..request.clone()
        };
        let err = import_policy(&one, &out).unwrap_err().to_string();
        assert!(err.contains("2 agents, 1 state_dict"), "{err}");
        let wide = write(
            dir.path(),
            "wide.safetensors",
            &reference_state_dict(&Architecture::ddrqn(8, 6), 5, 8, Naming::Lstm, value),
        );
        let mixed = ImportRequest {
            agents: vec![a0, wide],
            ..request
        };
        let err = import_policy(&mixed, &dir.path().join("p2"))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("wide.safetensors: M = 8, H = 6") && err.contains("M = 8, H = 4"),
            "{err}"
        );
        assert!(!dir.path().join("p2").exists());
    }

    #[test]
    fn warehouse_agents_get_their_own_sizes_and_the_paper_discount() {
        let spec = crate::envs::warehouse::spec(150, 0.0);
        assert_eq!(spec.paper_discount(), Some(1.0));
        let env = spec.build().unwrap();
        let dir = tempfile::tempdir().unwrap();
        let arch = Architecture::ddrqn(32, 64);
        let agents: Vec<PathBuf> = (0..3)
            .map(|i| {
                let bytes = reference_state_dict(
                    &arch,
                    env.obs_sizes()[i],
                    env.n_actions()[i],
                    Naming::Rnn,
                    value,
                );
                write(dir.path(), &format!("a{i}"), &bytes)
            })
            .collect();
        let mut request = ImportRequest {
            env: spec,
            discount: 1.0,
            agents,
        };
        let m = import_policy(&request, &dir.path().join("p")).unwrap();
        assert_eq!(
            (
                m.nets[2].architecture.mlp_layer_size,
                m.nets[2].architecture.rnn_h_size
            ),
            (32, 64)
        );
        // Agent files in the wrong order do not fit the agents' layouts (the Fetch robot differs).
        request.agents.swap(0, 2);
        let err = import_policy(&request, &dir.path().join("q"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("a2: tensor `fc1.weight`"), "{err}");
    }
}
