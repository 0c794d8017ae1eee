//! A net's architecture as a policy file describes it: the reference's `DDRQN` module (spec
//! `algorithms.md` 2), MacroMARL's GRU actor or ACAC's actor with its time table, whose PyTorch
//! `state_dict` names and shapes the safetensors files keep, so the weights load into the
//! reference's module unchanged. Every net entry of `policy.json` carries one
//! ([`crate::policy_files::NetEntry`]), so a net of another architecture is a new `kind` here,
//! not a new file format.
//!
//! ```text
//! obs (input) -> fc1 -> leaky_relu(0.01) -> fc2 -> leaky_relu -> LSTM(H, H) -> fc3 -> leaky_relu
//!             -> fc4 -> Q (output)
//! ```

use crate::nn::safetensors_io::{from_safetensors_bytes, WeightsError as NnWeightsError};
use crate::nn::{
    ActingNet, GruActor, GruActorConfig, QNet, QNetConfig, StateDict, TimedAcacActor,
    GRU_ACTOR_TENSOR_NAMES, TENSOR_NAMES,
};
use safetensors::Dtype;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The ICRA reference's `DDRQN` (fc1, fc2, one LSTM layer, fc3, fc4), whose sizes are the run's
/// `dec_mlp_layer_size` (M) and `dec_rnn_h_size` (H).
pub const DDRQN: &str = "ddrqn";

/// MacroMARL's actor ([`GruActor`]: fc1, fc2, one GRU layer, fc3, fc4, log_softmax), whose sizes
/// are `a_mlp_layer_size = [m0, m1]` (`mlp_layer_size`, `mlp_out_size`) and `a_rnn_layer_size`
/// (`rnn_h_size`).
pub const GRU_ACTOR: &str = "macromarl-gru-actor";

/// ACAC's actor (`AgentCentricGRUActor`: encoder fc1, fc2, GRU; fc3, LayerNorm when
/// `use_actor_ln`, fc4, log_softmax), reading the observation with its time embedding appended
/// (`time_embedding.weight`, when `time_emb_actor`): sizes `a_mlp_layer_size = [m0, m1]` and
/// `a_rnn_layer_size`, as [`GRU_ACTOR`].
pub const ACAC_ACTOR: &str = "acac-gru-actor";

/// Negative slope of every leaky ReLU (PyTorch's `F.leaky_relu` default, used by the reference).
pub const LEAKY_RELU_SLOPE: f32 = 0.01;

/// Hidden-layer sizes of one net (its input and output lengths are in its
/// [`crate::policy_files::NetEntry`], since they differ between an agent's net and the joint one).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Architecture {
    /// Which module: [`DDRQN`], [`GRU_ACTOR`] or [`ACAC_ACTOR`].
    pub kind: String,
    /// M: width of fc1 and fc3 (DDRQN); m0: width of fc1 and fc2 (GRU actor).
    pub mlp_layer_size: usize,
    /// H: width of fc2 and of the LSTM's input and hidden state (DDRQN); the GRU's hidden size
    /// (GRU actor).
    pub rnn_h_size: usize,
    /// m1: width of fc3 (the actors only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mlp_out_size: Option<usize>,
    /// Whether fc3 is followed by a LayerNorm (`use_actor_ln`; ACAC's actor only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layer_norm: Option<bool>,
    /// Rows and width of the time table the actor appends to every observation
    /// (`time_embedding.weight`; ACAC's actor with `time_emb_actor` only): a step reads row
    /// `min(step + 1, rows - 1)`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_embedding: Option<[usize; 2]>,
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
            mlp_out_size: None,
            layer_norm: None,
            time_embedding: None,
            leaky_relu_slope: LEAKY_RELU_SLOPE,
        }
    }

    /// MacroMARL's actor with `a_mlp_layer_size = [m0, m1]` and GRU hidden size H.
    pub fn gru_actor(mlp: [usize; 2], rnn_h_size: usize) -> Self {
        Architecture {
            kind: GRU_ACTOR.to_string(),
            mlp_layer_size: mlp[0],
            rnn_h_size,
            mlp_out_size: Some(mlp[1]),
            layer_norm: None,
            time_embedding: None,
            leaky_relu_slope: LEAKY_RELU_SLOPE,
        }
    }

    /// The architecture of `net`, an ACAC actor with its time table.
    pub fn acac_actor(net: &TimedAcacActor) -> Self {
        let a = &net.actor;
        Architecture {
            kind: ACAC_ACTOR.to_string(),
            mlp_layer_size: a.encoder.fc1.output(),
            rnn_h_size: a.encoder.gru.hidden(),
            mlp_out_size: Some(a.fc3.output()),
            layer_norm: Some(a.ln.is_some()),
            time_embedding: net.time.as_ref().map(|t| [t.table.nrows(), t.dim()]),
            leaky_relu_slope: LEAKY_RELU_SLOPE,
        }
    }

    /// The actor sizes of one agent's net (GRU actor).
    pub fn actor_config(&self, obs_len: usize, n_actions: usize) -> GruActorConfig {
        GruActorConfig {
            input: obs_len,
            mlp: [
                self.mlp_layer_size,
                self.mlp_out_size.unwrap_or(self.mlp_layer_size),
            ],
            hidden: self.rnn_h_size,
            output: n_actions,
        }
    }

    /// The Q-net sizes of one agent's net.
    pub fn qnet_config(&self, obs_len: usize, n_actions: usize) -> QNetConfig {
        QNetConfig {
            input: obs_len,
            mlp: self.mlp_layer_size,
            hidden: self.rnn_h_size,
            output: n_actions,
        }
    }

    /// Every tensor of one agent's file, in `state_dict` order, with its PyTorch shape
    /// (`nn.Linear.weight` is `[out, in]`; the LSTM stacks its four gates i, f, g, o in `4H` rows):
    /// nn's one table of the Q-net's tensors ([`crate::nn::TENSORS`]).
    pub fn tensors(&self, obs_len: usize, n_actions: usize) -> Vec<(&'static str, Vec<usize>)> {
        if self.kind == ACAC_ACTOR {
            let c = self.actor_config(obs_len, n_actions);
            return TimedAcacActor::tensor_shapes(
                obs_len,
                c.mlp,
                c.hidden,
                n_actions,
                self.layer_norm == Some(true),
                self.time_embedding.map(|[rows, dim]| (rows, dim)),
            );
        }
        if self.kind == GRU_ACTOR {
            return GRU_ACTOR_TENSOR_NAMES
                .into_iter()
                .zip(self.actor_config(obs_len, n_actions).tensor_shapes())
                .collect();
        }
        TENSOR_NAMES
            .into_iter()
            .zip(self.qnet_config(obs_len, n_actions).tensor_shapes())
            .collect()
    }

    /// Check a safetensors file against this architecture with nn's loader (the one that builds
    /// the net): exactly the expected tensor names, each f32 with the expected shape. Errors name
    /// the first offending tensor.
    pub fn check_weights(
        &self,
        bytes: &[u8],
        obs_len: usize,
        n_actions: usize,
    ) -> Result<(), WeightsError> {
        self.acting_net(bytes, obs_len, n_actions).map(|_| ())
    }

    /// The net a safetensors file holds, checked as [`Self::check_weights`] describes.
    pub fn acting_net(
        &self,
        bytes: &[u8],
        obs_len: usize,
        n_actions: usize,
    ) -> Result<ActingNet, WeightsError> {
        match self.kind.as_str() {
            DDRQN => self.qnet(bytes, obs_len, n_actions).map(ActingNet::Q),
            GRU_ACTOR => GruActor::from_safetensors_bytes_sized(
                bytes,
                self.actor_config(obs_len, n_actions),
                Path::new(""),
            )
            .map(ActingNet::Actor)
            .map_err(weights_error),
            ACAC_ACTOR => self.acac_actor_net(bytes, obs_len, n_actions),
            other => Err(WeightsError::UnknownKind(other.to_string())),
        }
    }

    /// The ACAC actor a safetensors file holds: ACAC's own names (nothing else), every tensor
    /// of the shape this architecture gives for `obs_len` and `n_actions`.
    fn acac_actor_net(
        &self,
        bytes: &[u8],
        obs_len: usize,
        n_actions: usize,
    ) -> Result<ActingNet, WeightsError> {
        let sd = StateDict::parse(bytes, Path::new("")).map_err(weights_error)?;
        let expected = self.tensors(obs_len, n_actions);
        for (name, shape) in &expected {
            let got = sd
                .shape(name)
                .map_err(|_| WeightsError::Missing(name.to_string()))?;
            if &got != shape {
                return Err(WeightsError::Shape {
                    name: name.to_string(),
                    expected: shape.clone(),
                    got,
                });
            }
        }
        let net = TimedAcacActor::from_state_dict(&sd).map_err(weights_error)?;
        // The shapes above cover every tensor the architecture has; a file with more (a
        // LayerNorm or a time table the description leaves out) is another actor.
        if net.time.is_some() != self.time_embedding.is_some() {
            return Err(WeightsError::Unexpected(crate::nn::TIME_TABLE.to_string()));
        }
        if net.actor.ln.is_some() != (self.layer_norm == Some(true)) {
            return Err(WeightsError::Unexpected("ln.weight".to_string()));
        }
        Ok(ActingNet::Acac(net))
    }

    /// The Q-net a safetensors file holds, checked as [`Self::check_weights`] describes.
    pub fn qnet(
        &self,
        bytes: &[u8],
        obs_len: usize,
        n_actions: usize,
    ) -> Result<QNet, WeightsError> {
        if self.kind != DDRQN {
            return Err(WeightsError::UnknownKind(self.kind.clone()));
        }
        let cfg = self.qnet_config(obs_len, n_actions);
        from_safetensors_bytes(bytes, cfg, Path::new(""))
            .map(|params| QNet { params })
            .map_err(weights_error)
    }
}

/// nn's weight-file error as the policy format reports it (the file's path is added by the
/// caller).
fn weights_error(e: NnWeightsError) -> WeightsError {
    match e {
        NnWeightsError::Io { source, .. } => WeightsError::Unreadable(source.to_string()),
        NnWeightsError::Format { reason, .. } => WeightsError::Unreadable(reason),
        NnWeightsError::Missing { name, .. } => WeightsError::Missing(name.to_string()),
        NnWeightsError::Unexpected { name, .. } => WeightsError::Unexpected(name),
        NnWeightsError::Dtype { name, found, .. } => WeightsError::Dtype { name, dtype: found },
        NnWeightsError::Shape {
            name,
            found,
            expected,
            ..
        } => WeightsError::Shape {
            name,
            expected,
            got: found,
        },
    }
}

/// Why a weight file does not fit the manifest's architecture.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum WeightsError {
    /// An architecture name this build does not know; holds it.
    #[error("unknown architecture `{0}` (this version knows `ddrqn`, `macromarl-gru-actor` and `acac-gru-actor`)")]
    UnknownKind(String),
    /// The bytes are not a safetensors file; holds the parser's reason.
    #[error("not a safetensors file: {0}")]
    Unreadable(String),
    /// A tensor the architecture needs is absent; holds its name.
    #[error("tensor `{0}` is missing")]
    Missing(String),
    /// A tensor the architecture does not have; holds its name.
    #[error("tensor `{0}` is not part of the architecture")]
    Unexpected(String),
    /// A tensor is not F32.
    #[error("tensor `{name}` has dtype {dtype}, expected F32")]
    Dtype {
        /// The tensor's name.
        name: String,
        /// The dtype stored.
        dtype: String,
    },
    /// A tensor's shape differs from the architecture's.
    #[error("tensor `{name}` has shape {got:?}, expected {expected:?}")]
    Shape {
        /// The tensor's name.
        name: String,
        /// The shape the architecture gives.
        expected: Vec<usize>,
        /// The shape stored.
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
    synthetic_weights_named(arch, obs_len, n_actions, str::to_string, value)
}

/// [`synthetic_weights`] with every tensor stored under `rename(canonical_name)` (e.g. the
/// reference's `rnn.*` scheme); `value` still sees the canonical name.
pub fn synthetic_weights_named(
    arch: &Architecture,
    obs_len: usize,
    n_actions: usize,
    rename: impl Fn(&str) -> String,
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
            (rename(name), shape, bytes)
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
    fn acac_actors_are_checked_tensor_by_tensor_time_table_and_layer_norm_included() {
        use crate::nn::{AcacActor, TimeEmbedding};
        use rand::SeedableRng;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2);
        let net = TimedAcacActor {
            actor: AcacActor::new(5 + 4, [8, 6], 5, 3, true, &mut rng),
            time: Some(TimeEmbedding::sinusoidal(20, 4).unwrap()),
        };
        let arch = Architecture::acac_actor(&net);
        assert_eq!(arch.time_embedding, Some([25, 4]));
        let bytes = synthetic_weights(&arch, 5, 3, |_, i| i as f32 * 1e-3);
        arch.check_weights(&bytes, 5, 3).unwrap();
        let real = crate::nn::safetensors_io::named_to_safetensors_bytes(&net.named());
        assert_eq!(
            arch.acting_net(&real, 5, 3).unwrap(),
            ActingNet::Acac(net.clone())
        );
        // Another observation length shows in fc1; a description without the table or the
        // LayerNorm does not fit the file.
        let err = arch.check_weights(&real, 6, 3).unwrap_err();
        assert!(err.to_string().contains("encoder.fc1.weight"), "{err}");
        let mut untimed = arch.clone();
        untimed.time_embedding = None;
        let err = untimed.check_weights(&real, 9, 3).unwrap_err();
        assert!(err.to_string().contains("time_embedding.weight"), "{err}");
        let mut no_ln = arch.clone();
        no_ln.layer_norm = Some(false);
        let err = no_ln.check_weights(&real, 5, 3).unwrap_err();
        assert!(err.to_string().contains("ln.weight"), "{err}");
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
