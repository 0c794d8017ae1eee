//! A safetensors file read as a PyTorch `state_dict`: tensors looked up by dotted name, each
//! checked for dtype and shape. For nets that are one module inside a larger state_dict (ACAC's
//! critic holds its agents' encoders, a GPT-2 encoder and a value head, each under its own
//! prefix), where [`read_exact`](super::safetensors_io::read_exact)'s "exactly these tensors"
//! would be the wrong check; [`StateDict::check_names_under`] gives the same strictness
//! within one prefix.

use std::path::{Path, PathBuf};

use ndarray::{Array1, Array2};
use safetensors::tensor::{Dtype, SafeTensors};

use super::gru::GRU_TENSOR_NAMES;
use super::params::{GruParams, LinearParams};
use super::safetensors_io::WeightsError;

/// The tensors of one safetensors file (borrowing its bytes).
pub struct StateDict<'a> {
    st: SafeTensors<'a>,
    path: PathBuf,
}

impl std::fmt::Debug for StateDict<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StateDict")
            .field("path", &self.path)
            .field("tensors", &self.st.len())
            .finish()
    }
}

impl<'a> StateDict<'a> {
    /// Parse a file's bytes; `origin` labels errors.
    pub fn parse(bytes: &'a [u8], origin: &Path) -> Result<Self, WeightsError> {
        let st = SafeTensors::deserialize(bytes).map_err(|e| WeightsError::Format {
            path: origin.to_path_buf(),
            reason: e.to_string(),
        })?;
        Ok(StateDict {
            st,
            path: origin.to_path_buf(),
        })
    }

    /// The file (as given to [`StateDict::parse`]).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Whether the file holds a tensor `name`.
    pub fn has(&self, name: &str) -> bool {
        self.st.tensor(name).is_ok()
    }

    /// The shape of tensor `name` (to read a net's sizes before loading it).
    pub fn shape(&self, name: &str) -> Result<Vec<usize>, WeightsError> {
        self.st
            .tensor(name)
            .map(|v| v.shape().to_vec())
            .map_err(|_| self.missing(name, vec![]))
    }

    /// The [rows, cols] shape of tensor `name`, which must be 2-D.
    pub fn shape2(&self, name: &str) -> Result<(usize, usize), WeightsError> {
        match self.shape(name)?[..] {
            [r, c] => Ok((r, c)),
            ref found => Err(WeightsError::Shape {
                path: self.path.clone(),
                name: name.to_string(),
                found: found.to_vec(),
                expected: vec![0, 0],
            }),
        }
    }

    /// The values of tensor `name`, which must be F32 of shape `shape`.
    pub fn values(&self, name: &str, shape: &[usize]) -> Result<Vec<f32>, WeightsError> {
        let view = self
            .st
            .tensor(name)
            .map_err(|_| self.missing(name, shape.to_vec()))?;
        if view.dtype() != Dtype::F32 {
            return Err(WeightsError::Dtype {
                path: self.path.clone(),
                name: name.to_string(),
                found: format!("{:?}", view.dtype()),
            });
        }
        if view.shape() != shape {
            return Err(WeightsError::Shape {
                path: self.path.clone(),
                name: name.to_string(),
                found: view.shape().to_vec(),
                expected: shape.to_vec(),
            });
        }
        Ok(view
            .data()
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect())
    }

    /// Tensor `name` as a vector of `len` values (shape \[len\]).
    pub fn array1(&self, name: &str, len: usize) -> Result<Array1<f32>, WeightsError> {
        Ok(Array1::from_vec(self.values(name, &[len])?))
    }

    /// Tensor `name` as a [rows, cols] matrix.
    pub fn array2(
        &self,
        name: &str,
        rows: usize,
        cols: usize,
    ) -> Result<Array2<f32>, WeightsError> {
        let v = self.values(name, &[rows, cols])?;
        Ok(Array2::from_shape_vec((rows, cols), v).expect("values() checked the shape"))
    }

    /// `nn.Linear` under `prefix` (`weight` `[out, in]`, `bias` `[out]`), its sizes read from the
    /// file.
    pub fn linear(&self, prefix: &str) -> Result<LinearParams, WeightsError> {
        let name = format!("{prefix}weight");
        let (out, input) = self.shape2(&name)?;
        Ok(LinearParams {
            weight: self.array2(&name, out, input)?,
            bias: self.array1(&format!("{prefix}bias"), out)?,
        })
    }

    /// A one-layer `nn.GRU` under `prefix` (e.g. `encoder.gru.`), its sizes read from
    /// `weight_ih_l0` [3H, in].
    pub fn gru(&self, prefix: &str) -> Result<GruParams, WeightsError> {
        let n = GRU_TENSOR_NAMES.map(|t| format!("{prefix}{t}"));
        let (gates, input) = self.shape2(&n[0])?;
        let hidden = gates / 3;
        Ok(GruParams {
            weight_ih: self.array2(&n[0], 3 * hidden, input)?,
            weight_hh: self.array2(&n[1], 3 * hidden, hidden)?,
            bias_ih: self.array1(&n[2], 3 * hidden)?,
            bias_hh: self.array1(&n[3], 3 * hidden)?,
        })
    }

    /// Tensor `name` as a scalar (shape [], e.g. PopArt's `debiasing_term`).
    pub fn scalar(&self, name: &str) -> Result<f32, WeightsError> {
        Ok(self.values(name, &[])?[0])
    }

    /// Fail on a tensor under `prefix` that is neither in `known` nor ends with one of the
    /// dotted suffixes `ignored` (whole segments: `attn.bias` ignores `h.0.attn.bias`, not
    /// `h.0.attn.c_attn.bias`; buffers that are not weights, such as GPT-2's causal-mask `attn.bias`): PyTorch's
    /// strict `load_state_dict`, within one module. `what` names the module in the error.
    pub fn check_names_under(
        &self,
        prefix: &str,
        known: &[String],
        ignored: &[&str],
        what: &'static str,
    ) -> Result<(), WeightsError> {
        let mut names: Vec<&String> = self
            .st
            .names()
            .into_iter()
            .filter(|n| n.starts_with(prefix))
            .collect();
        names.sort();
        for name in names {
            let is_known = known.iter().any(|k| k == name);
            // Segments count from the prefix: `time_embedding.weight` under `init/actor0/`.
            let within = &name[prefix.len()..];
            if !is_known && !ignored.iter().any(|s| ends_with_segments(within, s)) {
                let mut expected: Vec<&str> = known
                    .iter()
                    .filter_map(|k| k.strip_prefix(prefix))
                    .collect();
                expected.sort();
                return Err(WeightsError::Unexpected {
                    path: self.path.clone(),
                    name: name.clone(),
                    what,
                    expected: format!("{} under `{prefix}`", expected.join(", ")),
                });
            }
        }
        Ok(())
    }

    fn missing(&self, name: &str, expected: Vec<usize>) -> WeightsError {
        WeightsError::Missing {
            path: self.path.clone(),
            name: name.to_string(),
            expected,
        }
    }
}

/// Whether `name` ends with the whole dotted segments `suffix`.
fn ends_with_segments(name: &str, suffix: &str) -> bool {
    name.strip_suffix(suffix)
        .is_some_and(|head| head.is_empty() || head.ends_with('.'))
}

#[cfg(test)]
mod tests {
    use ndarray::{arr1, ArrayD};

    use super::*;
    use crate::nn::safetensors_io::named_to_safetensors_bytes;

    fn file() -> Vec<u8> {
        let a = ArrayD::from_shape_vec(vec![2, 3], (0..6).map(|i| i as f32).collect()).unwrap();
        let b = arr1(&[1.5f32]).into_dyn();
        let s = ArrayD::from_elem(vec![], 7.0f32);
        named_to_safetensors_bytes(&[
            ("net.a", a.view()),
            ("net.b", b.view()),
            ("net.attn.bias", s.view()),
            ("other.c", s.view()),
        ])
    }

    #[test]
    fn values_come_back_by_name_with_their_shapes() {
        let bytes = file();
        let sd = StateDict::parse(&bytes, Path::new("f")).unwrap();
        assert_eq!(sd.array2("net.a", 2, 3).unwrap()[[1, 2]], 5.0);
        assert_eq!(sd.array1("net.b", 1).unwrap()[0], 1.5);
        assert_eq!(sd.scalar("other.c").unwrap(), 7.0);
        assert_eq!(sd.shape("net.a").unwrap(), vec![2, 3]);
        assert!(sd.has("net.b") && !sd.has("net.z"));
    }

    #[test]
    fn wrong_shapes_and_missing_names_are_errors_naming_the_tensor() {
        let bytes = file();
        let sd = StateDict::parse(&bytes, Path::new("f")).unwrap();
        let err = sd.array2("net.a", 3, 2).unwrap_err().to_string();
        assert!(err.contains("net.a") && err.contains("[2, 3]") && err.contains("[3, 2]"));
        let err = sd.array1("net.z", 4).unwrap_err().to_string();
        assert!(err.contains("net.z") && err.contains("missing"), "{err}");
    }

    #[test]
    fn only_names_under_the_prefix_are_checked_and_buffers_may_be_ignored() {
        let bytes = file();
        let sd = StateDict::parse(&bytes, Path::new("f")).unwrap();
        let known = vec!["net.a".to_string(), "net.b".to_string()];
        sd.check_names_under("net.", &known, &["attn.bias"], "net")
            .unwrap();
        let err = sd
            .check_names_under("net.", &known, &[], "net")
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("net.attn.bias") && err.contains("a, b"),
            "{err}"
        );
    }
}
