//! The decentralized Q-net's architecture as an exported file describes it: the reference's
//! `DDRQN` module (spec `algorithms.md` 2), whose PyTorch `state_dict` names and shapes the
//! exported safetensors files keep, so the weights load into the reference's module unchanged.
//!
//! ```text
//! obs (input) -> fc1 -> leaky_relu(0.01) -> fc2 -> leaky_relu -> LSTM(H, H) -> fc3 -> leaky_relu
//!             -> fc4 -> Q (output)
//! ```

use safetensors::{Dtype, SafeTensors};
use serde::{Deserialize, Serialize};

/// The one architecture exported so far: the reference's `DDRQN` (fc1, fc2, one LSTM layer, fc3,
/// fc4), whose sizes are the run's `dec_mlp_layer_size` (M) and `dec_rnn_h_size` (H).
pub const DDRQN: &str = "ddrqn";

/// Negative slope of every leaky ReLU (PyTorch's `F.leaky_relu` default, used by the reference).
pub const LEAKY_RELU_SLOPE: f32 = 0.01;

/// Layer sizes of an exported net, shared by every agent of a policy (the observation and action
/// counts are per agent, in [`crate::deploy::manifest::AgentEntry`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Architecture {
    /// Which module: [`DDRQN`].
    pub kind: String,
    /// M: width of fc1 and fc3.
    pub mlp_layer_size: usize,
    /// H: width of fc2 and of the LSTM's input and hidden state.
    pub rnn_h_size: usize,
    /// Negative slope of the leaky ReLUs ([`LEAKY_RELU_SLOPE`]).
    pub leaky_relu_slope: f32,
}

impl Architecture {
    /// The reference's DDRQN with widths M and H.
    pub fn ddrqn(mlp_layer_size: usize, rnn_h_size: usize) -> Self {
        Architecture {
            kind: DDRQN.to_string(),
            mlp_layer_size,
            rnn_h_size,
            leaky_relu_slope: LEAKY_RELU_SLOPE,
        }
    }

    /// Every tensor of one agent's file, in `state_dict` order, with its PyTorch shape
    /// (`nn.Linear.weight` is `[out, in]`; the LSTM stacks its four gates i, f, g, o in `4H` rows).
    pub fn tensors(&self, obs_len: usize, n_actions: usize) -> Vec<(&'static str, Vec<usize>)> {
        let (m, h) = (self.mlp_layer_size, self.rnn_h_size);
        vec![
            ("fc1.weight", vec![m, obs_len]),
            ("fc1.bias", vec![m]),
            ("fc2.weight", vec![h, m]),
            ("fc2.bias", vec![h]),
            ("lstm.weight_ih_l0", vec![4 * h, h]),
            ("lstm.weight_hh_l0", vec![4 * h, h]),
            ("lstm.bias_ih_l0", vec![4 * h]),
            ("lstm.bias_hh_l0", vec![4 * h]),
            ("fc3.weight", vec![m, h]),
            ("fc3.bias", vec![m]),
            ("fc4.weight", vec![n_actions, m]),
            ("fc4.bias", vec![n_actions]),
        ]
    }

    /// Check a safetensors file against this architecture: exactly the expected tensor names,
    /// each f32 with the expected shape. Errors name the first offending tensor.
    pub fn check_weights(
        &self,
        bytes: &[u8],
        obs_len: usize,
        n_actions: usize,
    ) -> Result<(), WeightsError> {
        if self.kind != DDRQN {
            return Err(WeightsError::UnknownKind(self.kind.clone()));
        }
        let file =
            SafeTensors::deserialize(bytes).map_err(|e| WeightsError::Unreadable(e.to_string()))?;
        let expected = self.tensors(obs_len, n_actions);
        for (name, shape) in &expected {
            let view = file
                .tensor(name)
                .map_err(|_| WeightsError::Missing(name.to_string()))?;
            if view.dtype() != Dtype::F32 {
                return Err(WeightsError::Dtype {
                    name: name.to_string(),
                    dtype: format!("{:?}", view.dtype()),
                });
            }
            if view.shape() != shape.as_slice() {
                return Err(WeightsError::Shape {
                    name: name.to_string(),
                    expected: shape.clone(),
                    got: view.shape().to_vec(),
                });
            }
        }
        let mut names = file.names();
        names.sort();
        if let Some(extra) = names
            .into_iter()
            .find(|n| !expected.iter().any(|(e, _)| e == n))
        {
            return Err(WeightsError::Unexpected(extra.clone()));
        }
        Ok(())
    }
}

/// Why a weight file does not fit the manifest's architecture.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum WeightsError {
    #[error("unknown architecture `{0}` (this version knows `ddrqn`)")]
    UnknownKind(String),
    #[error("not a safetensors file: {0}")]
    Unreadable(String),
    #[error("tensor `{0}` is missing")]
    Missing(String),
    #[error("tensor `{0}` is not part of the architecture")]
    Unexpected(String),
    #[error("tensor `{name}` has dtype {dtype}, expected F32")]
    Dtype { name: String, dtype: String },
    #[error("tensor `{name}` has shape {got:?}, expected {expected:?}")]
    Shape {
        name: String,
        expected: Vec<usize>,
        got: Vec<usize>,
    },
}

/// A safetensors file holding every tensor of `arch` filled by `value(name, index)`: test
/// fixtures and the mock policy's placeholder weights.
pub fn synthetic_weights(
    arch: &Architecture,
    obs_len: usize,
    n_actions: usize,
    value: impl Fn(&str, usize) -> f32,
) -> Vec<u8> {
    let tensors: Vec<(String, Vec<usize>, Vec<u8>)> = arch
        .tensors(obs_len, n_actions)
        .into_iter()
        .map(|(name, shape)| {
            let n: usize = shape.iter().product();
            let bytes = (0..n)
                .flat_map(|i| value(name, i).to_le_bytes())
                .collect::<Vec<u8>>();
            (name.to_string(), shape, bytes)
        })
        .collect();
    let views = tensors.iter().map(|(name, shape, bytes)| {
        let view = safetensors::tensor::TensorView::new(Dtype::F32, shape.clone(), bytes)
            .expect("shape and byte count agree by construction");
        (name.clone(), view)
    });
    safetensors::serialize(views, &None).expect("serializing in-memory f32 tensors cannot fail")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arch() -> Architecture {
        Architecture::ddrqn(32, 16)
    }

    #[test]
    fn tensor_shapes_follow_pytorch_linear_and_lstm_layouts() {
        let t = arch().tensors(5, 8);
        assert_eq!(t.len(), 12);
        assert_eq!(t[0], ("fc1.weight", vec![32, 5]));
        assert_eq!(t[4], ("lstm.weight_ih_l0", vec![64, 16]));
        assert_eq!(t[10], ("fc4.weight", vec![8, 32]));
    }

    #[test]
    fn synthetic_weights_pass_the_check() {
        let bytes = synthetic_weights(&arch(), 5, 8, |_, i| i as f32);
        arch().check_weights(&bytes, 5, 8).unwrap();
    }

    #[test]
    fn wrong_sizes_name_the_tensor_and_both_shapes() {
        let bytes = synthetic_weights(&arch(), 5, 8, |_, _| 0.0);
        let err = arch().check_weights(&bytes, 6, 8).unwrap_err();
        assert_eq!(
            err,
            WeightsError::Shape {
                name: "fc1.weight".into(),
                expected: vec![32, 6],
                got: vec![32, 5]
            }
        );
        let err = Architecture::ddrqn(32, 8)
            .check_weights(&bytes, 5, 8)
            .unwrap_err();
        assert!(err.to_string().contains("fc2.weight"), "{err}");
    }

    #[test]
    fn garbage_bytes_and_unknown_kinds_are_refused() {
        let err = arch().check_weights(b"not tensors", 5, 8).unwrap_err();
        assert!(matches!(err, WeightsError::Unreadable(_)), "{err}");
        let mut other = arch();
        other.kind = "transformer".into();
        let bytes = synthetic_weights(&arch(), 5, 8, |_, _| 0.0);
        assert!(matches!(
            other.check_weights(&bytes, 5, 8),
            Err(WeightsError::UnknownKind(_))
        ));
    }
}
