//! Q-net parameters as safetensors files with the reference's PyTorch state_dict names and shapes
//! (`fc1.weight` [M, in], ..., `lstm.weight_ih_l0` [4H, H], ...), so
//! `net.load_state_dict(safetensors.torch.load_file(path))` accepts them; and a GRU's, with a
//! bare `nn.GRU`'s names (`weight_ih_l0` [3H, in], ...), both ways
//! (`safetensors.torch.save_file(gru.state_dict(), path)` gives a file we read).

use crate::files::atomic::write_atomic;
use crate::files::bounded_read::{read_regular_file, MAX_WEIGHTS_BYTES};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

use ndarray::ArrayViewD;
use safetensors::tensor::{Dtype, SafeTensors, TensorView};

use super::gru::GRU_TENSOR_NAMES;
use super::params::{GruParams, Params};
use super::qnet::{QNet, QNetConfig, QNetParams, TENSOR_NAMES};

/// Why a weights file could not be written or read. Every message names the file, and the
/// tensor when one is at fault.
#[derive(Debug, thiserror::Error)]
pub enum WeightsError {
    /// The file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The bytes are not a safetensors file.
    #[error("{path}: not a valid safetensors file: {reason}")]
    Format {
        /// The file.
        path: PathBuf,
        /// The parser's reason.
        reason: String,
    },
    /// A tensor the net needs is absent.
    #[error("{path}: tensor `{name}` is missing (expected shape {expected:?})")]
    Missing {
        /// The file.
        path: PathBuf,
        /// The tensor's name.
        name: String,
        /// Its shape.
        expected: Vec<usize>,
    },
    /// A tensor has the wrong shape.
    #[error("{path}: tensor `{name}` has shape {found:?}, expected {expected:?}")]
    Shape {
        /// The file.
        path: PathBuf,
        /// The tensor's name.
        name: String,
        /// The shape stored.
        found: Vec<usize>,
        /// The shape the net needs.
        expected: Vec<usize>,
    },
    /// A tensor is not F32.
    #[error("{path}: tensor `{name}` has dtype {found}, expected F32")]
    Dtype {
        /// The file.
        path: PathBuf,
        /// The tensor's name.
        name: String,
        /// The dtype stored.
        found: String,
    },
    /// A tensor the net does not have.
    #[error("{path}: unexpected tensor `{name}`; a {what} has exactly {expected}")]
    Unexpected {
        /// The file.
        path: PathBuf,
        /// The tensor's name.
        name: String,
        /// What the file should hold ("Q-net", "GRU").
        what: &'static str,
        /// The tensor names the net has.
        expected: String,
    },
}

/// The file's bytes for `params` (PyTorch's `{"format": "pt"}` metadata included).
pub fn to_safetensors_bytes(params: &QNetParams) -> Vec<u8> {
    named_to_safetensors_bytes(&params.named())
}

/// Named f32 tensors as safetensors bytes, with PyTorch's `{"format": "pt"}` metadata: the one
/// writer behind every net's file.
pub fn named_to_safetensors_bytes<S: AsRef<str>>(named: &[(S, ArrayViewD<'_, f32>)]) -> Vec<u8> {
    let data: Vec<(&str, Vec<usize>, Vec<u8>)> = named
        .iter()
        .map(|(name, a)| {
            let bytes = a.iter().flat_map(|v| v.to_le_bytes()).collect();
            (name.as_ref(), a.shape().to_vec(), bytes)
        })
        .collect();
    let views = data.iter().map(|(name, shape, bytes)| {
        let view = TensorView::new(Dtype::F32, shape.clone(), bytes)
            .expect("shape and byte length agree by construction");
        (*name, view)
    });
    let meta = Some(HashMap::from([("format".to_string(), "pt".to_string())]));
    safetensors::serialize(views, &meta).expect("serializing in-memory f32 tensors cannot fail")
}

/// The shape of tensor `name` in a file's bytes (to read a net's sizes before the full check).
pub fn tensor_shape(
    bytes: &[u8],
    origin: &Path,
    name: &'static str,
) -> Result<Vec<usize>, WeightsError> {
    let st = SafeTensors::deserialize(bytes).map_err(|e| WeightsError::Format {
        path: origin.to_path_buf(),
        reason: e.to_string(),
    })?;
    let view = st.tensor(name).map_err(|_| WeightsError::Missing {
        path: origin.to_path_buf(),
        name: name.to_string(),
        expected: vec![],
    })?;
    Ok(view.shape().to_vec())
}

/// The values of exactly the tensors `expected` (name and shape, in order) from a file's bytes,
/// like PyTorch's strict `load_state_dict`: each present, F32 and of its shape, and nothing else
/// in the file. `what` names the net in errors ("GRU actor"); `origin` labels them.
pub fn read_exact(
    bytes: &[u8],
    origin: &Path,
    what: &'static str,
    expected: &[(&'static str, Vec<usize>)],
) -> Result<Vec<Vec<f32>>, WeightsError> {
    let path = origin.to_path_buf();
    let st = SafeTensors::deserialize(bytes).map_err(|e| WeightsError::Format {
        path: path.clone(),
        reason: e.to_string(),
    })?;
    let mut names: Vec<String> = st.names().into_iter().cloned().collect();
    names.sort();
    if let Some(name) = names
        .into_iter()
        .find(|n| !expected.iter().any(|(e, _)| e == n))
    {
        return Err(WeightsError::Unexpected {
            path,
            name,
            what,
            expected: expected
                .iter()
                .map(|(e, _)| *e)
                .collect::<Vec<_>>()
                .join(", "),
        });
    }
    let mut out = Vec::with_capacity(expected.len());
    for (name, shape) in expected {
        let view = st.tensor(name).map_err(|_| WeightsError::Missing {
            path: path.clone(),
            name: name.to_string(),
            expected: shape.clone(),
        })?;
        if view.dtype() != Dtype::F32 {
            return Err(WeightsError::Dtype {
                path,
                name: name.to_string(),
                found: format!("{:?}", view.dtype()),
            });
        }
        if view.shape() != shape.as_slice() {
            return Err(WeightsError::Shape {
                path,
                name: name.to_string(),
                found: view.shape().to_vec(),
                expected: shape.clone(),
            });
        }
        out.push(
            view.data()
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                .collect(),
        );
    }
    Ok(out)
}

/// Parse a file's bytes into parameters of size `cfg`. `origin` only labels errors.
/// Every expected tensor must be present, F32 and of the expected shape, and no other tensor
/// may be present (like PyTorch's strict `load_state_dict`).
pub fn from_safetensors_bytes(
    bytes: &[u8],
    cfg: QNetConfig,
    origin: &Path,
) -> Result<QNetParams, WeightsError> {
    let expected: Vec<(&'static str, Vec<usize>)> =
        TENSOR_NAMES.into_iter().zip(cfg.tensor_shapes()).collect();
    let values = read_exact(bytes, origin, "Q-net", &expected)?;
    let mut params = QNetParams::zeros(cfg);
    for (slot, v) in params.slices_mut().into_iter().zip(values) {
        slot.copy_from_slice(&v);
    }
    Ok(params)
}

/// The layer sizes a weights file describes (read from fc1, the LSTM and fc4), so a policy can
/// be loaded without knowing its sizes; the full check happens in [`from_safetensors_bytes`].
pub fn config_of_safetensors(bytes: &[u8], origin: &Path) -> Result<QNetConfig, WeightsError> {
    let path = origin.to_path_buf();
    let st = SafeTensors::deserialize(bytes).map_err(|e| WeightsError::Format {
        path: path.clone(),
        reason: e.to_string(),
    })?;
    let shape = |name: &'static str| -> Result<Vec<usize>, WeightsError> {
        let v = st.tensor(name).map_err(|_| WeightsError::Missing {
            path: path.clone(),
            name: name.to_string(),
            expected: vec![],
        })?;
        if v.shape().len() != 2 {
            return Err(WeightsError::Shape {
                path: path.clone(),
                name: name.to_string(),
                found: v.shape().to_vec(),
                expected: vec![0, 0],
            });
        }
        Ok(v.shape().to_vec())
    };
    let fc1 = shape("fc1.weight")?;
    let hh = shape("lstm.weight_hh_l0")?;
    let fc4 = shape("fc4.weight")?;
    Ok(QNetConfig {
        input: fc1[1],
        mlp: fc1[0],
        hidden: hh[1],
        output: fc4[0],
    })
}

/// The file's bytes for a GRU's parameters, under `nn.GRU`'s state_dict names
/// ([`GRU_TENSOR_NAMES`]), with PyTorch's `{"format": "pt"}` metadata.
pub fn gru_to_safetensors_bytes(params: &GruParams) -> Vec<u8> {
    named_to_safetensors_bytes(&params.named())
}

/// Parse a bare `nn.GRU` state_dict (one layer, with biases) from a file's bytes, taking the
/// sizes from `weight_ih_l0` [3H, in] and `weight_hh_l0` [3H, H]. Exactly the four tensors of
/// [`GRU_TENSOR_NAMES`] must be present, F32, of consistent shapes (an `nn.LSTM` file, with
/// 4H rows, is rejected). `origin` only labels errors.
pub fn gru_from_safetensors_bytes(bytes: &[u8], origin: &Path) -> Result<GruParams, WeightsError> {
    let path = origin.to_path_buf();
    let st = SafeTensors::deserialize(bytes).map_err(|e| WeightsError::Format {
        path: path.clone(),
        reason: e.to_string(),
    })?;
    let mut names: Vec<String> = st.names().into_iter().cloned().collect();
    names.sort();
    for name in names {
        if !GRU_TENSOR_NAMES.contains(&name.as_str()) {
            return Err(WeightsError::Unexpected {
                path,
                name,
                what: "GRU",
                expected: GRU_TENSOR_NAMES.join(", "),
            });
        }
    }
    let tensor = |name: &'static str| {
        st.tensor(name).map_err(|_| WeightsError::Missing {
            path: path.clone(),
            name: name.to_string(),
            expected: vec![],
        })
    };
    let shape_error = |name: &str, found: &[usize], expected: Vec<usize>| WeightsError::Shape {
        path: path.clone(),
        name: name.to_string(),
        found: found.to_vec(),
        expected,
    };
    let [ih, hh, _, _] = GRU_TENSOR_NAMES;
    let (w_ih, w_hh) = (tensor(ih)?, tensor(hh)?);
    let (s_ih, s_hh) = (w_ih.shape(), w_hh.shape());
    let hidden = s_hh.get(1).copied().unwrap_or(0);
    if s_hh.len() != 2 || s_hh[0] != 3 * hidden {
        return Err(shape_error(hh, s_hh, vec![3 * hidden, hidden]));
    }
    let input = s_ih.get(1).copied().unwrap_or(0);
    let mut params = GruParams::zeros(input, hidden);
    let expected: Vec<Vec<usize>> = params
        .named()
        .iter()
        .map(|(_, a)| a.shape().to_vec())
        .collect();
    let mut slots = params.slices_mut();
    for ((name, expected), slot) in GRU_TENSOR_NAMES
        .into_iter()
        .zip(expected)
        .zip(slots.iter_mut())
    {
        let view = tensor(name)?;
        if view.dtype() != Dtype::F32 {
            return Err(WeightsError::Dtype {
                path,
                name: name.to_string(),
                found: format!("{:?}", view.dtype()),
            });
        }
        if view.shape() != expected.as_slice() {
            return Err(shape_error(name, view.shape(), expected));
        }
        for (d, b) in slot.iter_mut().zip(view.data().chunks_exact(4)) {
            *d = f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
        }
    }
    drop(slots);
    Ok(params)
}

impl GruParams {
    /// Write the parameters to `path` under `nn.GRU`'s names (via a temporary file and a
    /// rename), so `gru.load_state_dict(safetensors.torch.load_file(path))` accepts them.
    pub fn save_safetensors(&self, path: &Path) -> Result<(), WeightsError> {
        let io = |source| WeightsError::Io {
            path: path.to_path_buf(),
            source,
        };
        write_atomic(path, &gru_to_safetensors_bytes(self)).map_err(io)
    }

    /// Read a GRU from a safetensors file of a bare `nn.GRU` state_dict, e.g. written by
    /// `safetensors.torch.save_file(gru.state_dict(), path)`; sizes come from the file (see
    /// [`gru_from_safetensors_bytes`] for the checks).
    pub fn load_safetensors(path: &Path) -> Result<GruParams, WeightsError> {
        let bytes =
            read_regular_file(path, MAX_WEIGHTS_BYTES).map_err(|source| WeightsError::Io {
                path: path.to_path_buf(),
                source,
            })?;
        gru_from_safetensors_bytes(&bytes, path)
    }
}

impl QNet {
    /// Write the parameters to `path` (via a temporary file and a rename, so a crash never
    /// leaves a half-written file under the final name).
    pub fn save_safetensors(&self, path: &Path) -> Result<(), WeightsError> {
        let io = |source| WeightsError::Io {
            path: path.to_path_buf(),
            source,
        };
        write_atomic(path, &to_safetensors_bytes(&self.params)).map_err(io)
    }

    /// Read a net of size `cfg` from `path` (see [`from_safetensors_bytes`] for the checks).
    pub fn load_safetensors(path: &Path, cfg: QNetConfig) -> Result<QNet, WeightsError> {
        let bytes =
            read_regular_file(path, MAX_WEIGHTS_BYTES).map_err(|source| WeightsError::Io {
                path: path.to_path_buf(),
                source,
            })?;
        Ok(QNet {
            params: from_safetensors_bytes(&bytes, cfg, path)?,
        })
    }

    /// Read a net from `path`, taking its sizes from the file.
    pub fn load_safetensors_any_size(path: &Path) -> Result<QNet, WeightsError> {
        let bytes =
            read_regular_file(path, MAX_WEIGHTS_BYTES).map_err(|source| WeightsError::Io {
                path: path.to_path_buf(),
                source,
            })?;
        let cfg = config_of_safetensors(&bytes, path)?;
        Ok(QNet {
            params: from_safetensors_bytes(&bytes, cfg, path)?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    const CFG: QNetConfig = QNetConfig {
        input: 5,
        mlp: 6,
        hidden: 4,
        output: 3,
    };

    fn net() -> QNet {
        QNet::new(CFG, &mut ChaCha8Rng::seed_from_u64(3))
    }

    /// Re-serialize `params`' tensors with one of them renamed, reshaped or dropped.
    fn tampered(edit: impl Fn(&str, Vec<usize>) -> Option<(String, Vec<usize>)>) -> Vec<u8> {
        let params = net().params;
        let data: Vec<(String, Vec<usize>, Vec<u8>)> = params
            .named()
            .into_iter()
            .filter_map(|(name, a)| {
                let (name, shape) = edit(name, a.shape().to_vec())?;
                let n: usize = shape.iter().product();
                let bytes = a
                    .iter()
                    .cycle()
                    .take(n)
                    .flat_map(|v| v.to_le_bytes())
                    .collect();
                Some((name, shape, bytes))
            })
            .collect();
        let views = data.iter().map(|(n, s, b)| {
            (
                n.clone(),
                TensorView::new(Dtype::F32, s.clone(), b).unwrap(),
            )
        });
        safetensors::serialize(views, &None).unwrap()
    }

    #[test]
    fn save_then_load_gives_identical_parameters() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("q.safetensors");
        let n = net();
        n.save_safetensors(&path).unwrap();
        let back = QNet::load_safetensors(&path, CFG).unwrap();
        assert_eq!(back, n);
        assert_eq!(QNet::load_safetensors_any_size(&path).unwrap(), n);
    }

    #[test]
    fn file_uses_pytorch_names_and_shapes() {
        let bytes = to_safetensors_bytes(&net().params);
        let st = SafeTensors::deserialize(&bytes).unwrap();
        let shape = |n: &str| st.tensor(n).unwrap().shape().to_vec();
        assert_eq!(shape("fc1.weight"), vec![6, 5]);
        assert_eq!(shape("fc2.weight"), vec![4, 6]);
        assert_eq!(shape("lstm.weight_ih_l0"), vec![16, 4]);
        assert_eq!(shape("lstm.weight_hh_l0"), vec![16, 4]);
        assert_eq!(shape("lstm.bias_ih_l0"), vec![16]);
        assert_eq!(shape("lstm.bias_hh_l0"), vec![16]);
        assert_eq!(shape("fc3.weight"), vec![6, 4]);
        assert_eq!(shape("fc4.weight"), vec![3, 6]);
        assert_eq!(shape("fc4.bias"), vec![3]);
        assert_eq!(st.names().len(), 12);
    }

    #[test]
    fn missing_tensor_is_an_error_naming_it() {
        let bytes = tampered(|n, s| (n != "lstm.bias_hh_l0").then(|| (n.to_string(), s)));
        let err = from_safetensors_bytes(&bytes, CFG, Path::new("x")).unwrap_err();
        assert!(
            matches!(
                err,
                WeightsError::Missing { ref name, .. } if name == "lstm.bias_hh_l0"
            ),
            "{err}"
        );
        assert!(err.to_string().contains("lstm.bias_hh_l0"));
    }

    #[test]
    fn misnamed_tensor_is_an_error_naming_it() {
        let bytes = tampered(|n, s| {
            Some((
                if n == "fc3.bias" {
                    "fc3.b".to_string()
                } else {
                    n.to_string()
                },
                s,
            ))
        });
        let err = from_safetensors_bytes(&bytes, CFG, Path::new("x")).unwrap_err();
        assert!(err.to_string().contains("`fc3.b`"), "{err}");
    }

    #[test]
    fn misshaped_tensor_is_an_error_naming_it_and_both_shapes() {
        let bytes = tampered(|n, s| {
            Some((
                n.to_string(),
                if n == "fc2.weight" { vec![6, 4] } else { s },
            ))
        });
        let err = from_safetensors_bytes(&bytes, CFG, Path::new("x")).unwrap_err();
        let msg = err.to_string();
        assert!(
            msg.contains("fc2.weight") && msg.contains("[6, 4]") && msg.contains("[4, 6]"),
            "{msg}"
        );
    }

    #[test]
    fn a_tensor_of_another_dtype_is_an_error_naming_it() {
        let params = net().params;
        let data: Vec<(&str, Vec<usize>, Vec<u8>, Dtype)> = params
            .named()
            .into_iter()
            .map(|(name, a)| {
                if name == "fc4.bias" {
                    let bytes = a.iter().flat_map(|v| (*v as f64).to_le_bytes()).collect();
                    (name, a.shape().to_vec(), bytes, Dtype::F64)
                } else {
                    let bytes = a.iter().flat_map(|v| v.to_le_bytes()).collect();
                    (name, a.shape().to_vec(), bytes, Dtype::F32)
                }
            })
            .collect();
        let views = data
            .iter()
            .map(|(n, s, b, d)| (*n, TensorView::new(*d, s.clone(), b).unwrap()));
        let bytes = safetensors::serialize(views, &None).unwrap();
        let err = from_safetensors_bytes(&bytes, CFG, Path::new("x")).unwrap_err();
        assert!(matches!(err, WeightsError::Dtype { .. }), "{err}");
        assert!(err.to_string().contains("fc4.bias"), "{err}");
    }

    #[test]
    fn garbage_is_a_format_error() {
        let err = from_safetensors_bytes(b"not a file", CFG, Path::new("x")).unwrap_err();
        assert!(matches!(err, WeightsError::Format { .. }));
    }
}
