//! The differentiable operations. Each file defines its ops' forward (as `Tape` methods) next to
//! their backward; this module only names them and dispatches the reverse pass.
//!
//! Every op is public on [`Tape`](super::Tape), with the shapes it takes in its doc comment:
//!
//! | file | ops |
//! | --- | --- |
//! | `elementwise.rs` | `add`, `sub`, `mul`, `scale`, `sigmoid`, `tanh`, `leaky_relu`, `square`, `exp`, `log` |
//! | `matmul.rs` | `matmul`, `matmul_nt`, `add_bias`, `matmul_bias`, `linear` (fused) and `linear_at` (one column per row) |
//! | `softmax.rs` | `softmax`, `log_softmax`, `logsumexp` (row-wise), `log_softmax_at` (one column per row) |
//! | `shape.rs` | `concat_rows`, `concat_cols`, `slice_cols`, `gather_cols`, `gather_rows`, `reshape` |
//! | `reduce.rs` | `sum`, `mean`, `masked_mean` |
//! | `groups.rs` | `row_group_mean`, `row_group_max` (pool each sample's n agent rows) |
//! | `layer_norm.rs` | `layer_norm` (fused, row-wise, PyTorch's `nn.LayerNorm`) |
//! | `gelu.rs` | `gelu_tanh` (fused, GPT-2's tanh approximation `gelu_new`) |
//! | `attention.rs` | `self_attention` (fused multi-head attention within sets of n rows, optional additive mask and dropout multipliers) |
//! | `lstm.rs` | `lstm`, `lstm_packed` (fused, over packed sequences) |
//! | `gru.rs` | `gru`, `gru_packed` (fused, over packed sequences) |
//!
//! Dropout is `mul` by a constant mask of 0 and 1 / (1 - p) (PyTorch's `nn.Dropout` in
//! training), so a caller can draw the mask or replay one a reference drew.

mod attention;
mod elementwise;
mod gelu;
mod groups;
mod gru;
mod layer_norm;
mod lstm;
mod matmul;
mod reduce;
mod shape;
mod softmax;

pub use attention::AttentionSpec;
pub use gru::GruVars;
pub use lstm::LstmVars;

use ndarray::Array2;

use super::kernels::dense::Activation;
use super::tape::{GradCx, Var};

/// What produced a node, with what its backward needs besides the forward values.
#[derive(Debug)]
pub(crate) enum Op {
    /// Parameter, constant, or an op's cache: nothing to propagate.
    Leaf,
    MatMul {
        a: Var,
        b: Var,
    },
    MatMulNt {
        a: Var,
        b: Var,
    },
    AddBias {
        x: Var,
        bias: Var,
    },
    MatMulBias {
        a: Var,
        b: Var,
        bias: Var,
    },
    Linear {
        x: Var,
        w: Var,
        b: Var,
        act: Activation,
    },
    LinearAt {
        x: Var,
        w: Var,
        b: Var,
        cols: Vec<usize>,
    },
    Add {
        a: Var,
        b: Var,
    },
    Sub {
        a: Var,
        b: Var,
    },
    Mul {
        a: Var,
        b: Var,
    },
    Scale {
        x: Var,
        c: f32,
    },
    Sigmoid {
        x: Var,
    },
    Tanh {
        x: Var,
    },
    LeakyRelu {
        x: Var,
        slope: f32,
    },
    Square {
        x: Var,
    },
    Exp {
        x: Var,
    },
    Log {
        x: Var,
    },
    Softmax {
        x: Var,
    },
    LogSoftmax {
        x: Var,
    },
    LogSumExp {
        x: Var,
    },
    LogSoftmaxAt {
        x: Var,
        index: Vec<usize>,
        /// Each row's shift and log-sum, as the forward computed them.
        stats: Vec<(f32, f32)>,
    },
    ConcatRows {
        parts: Vec<Var>,
    },
    ConcatCols {
        parts: Vec<Var>,
    },
    SliceCols {
        x: Var,
        start: usize,
    },
    GatherCols {
        x: Var,
        index: Vec<usize>,
    },
    GatherRows {
        x: Var,
        index: Vec<usize>,
    },
    Reshape {
        x: Var,
    },
    RowGroupMean {
        x: Var,
        n: usize,
    },
    RowGroupMax {
        x: Var,
        n: usize,
        arg: Var,
    },
    LayerNorm {
        x: Var,
        gain: Var,
        bias: Var,
        stats: Var,
    },
    GeluTanh {
        x: Var,
        t: Var,
    },
    SelfAttention(Box<attention::AttentionNode>),
    Sum {
        x: Var,
    },
    Mean {
        x: Var,
    },
    MaskedMean {
        x: Var,
        mask: Var,
    },
    Lstm(Box<lstm::LstmNode>),
    Gru(Box<gru::GruNode>),
}

impl Op {
    /// Add this node's contribution to its inputs' gradients, given the node's value `y` and
    /// the gradient `g` flowing into it.
    pub(crate) fn backward(&self, y: &Array2<f32>, g: &Array2<f32>, cx: &mut GradCx) {
        match self {
            Op::Leaf => {}
            Op::MatMul { a, b } => matmul::matmul_backward(*a, *b, g, cx),
            Op::MatMulNt { a, b } => matmul::matmul_nt_backward(*a, *b, g, cx),
            Op::AddBias { x, bias } => matmul::add_bias_backward(*x, *bias, g, cx),
            Op::MatMulBias { a, b, bias } => matmul::matmul_bias_backward(*a, *b, *bias, g, cx),
            Op::Linear { x, w, b, act } => matmul::linear_backward(*x, *w, *b, *act, y, g, cx),
            Op::LinearAt { x, w, b, cols } => matmul::linear_at_backward(*x, *w, *b, cols, g, cx),
            Op::Add { a, b } => elementwise::add_backward(*a, *b, g, cx),
            Op::Sub { a, b } => elementwise::sub_backward(*a, *b, g, cx),
            Op::Mul { a, b } => elementwise::mul_backward(*a, *b, g, cx),
            Op::Scale { x, c } => elementwise::scale_backward(*x, *c, g, cx),
            Op::Sigmoid { x } => elementwise::sigmoid_backward(*x, y, g, cx),
            Op::Tanh { x } => elementwise::tanh_backward(*x, y, g, cx),
            Op::LeakyRelu { x, slope } => elementwise::leaky_relu_backward(*x, *slope, g, cx),
            Op::Square { x } => elementwise::square_backward(*x, g, cx),
            Op::Exp { x } => elementwise::exp_backward(*x, y, g, cx),
            Op::Log { x } => elementwise::log_backward(*x, g, cx),
            Op::Softmax { x } => softmax::softmax_backward(*x, y, g, cx),
            Op::LogSoftmax { x } => softmax::log_softmax_backward(*x, y, g, cx),
            Op::LogSumExp { x } => softmax::logsumexp_backward(*x, y, g, cx),
            Op::LogSoftmaxAt { x, index, stats } => {
                softmax::log_softmax_at_backward(*x, index, stats, g, cx)
            }
            Op::ConcatRows { parts } => shape::concat_rows_backward(parts, g, cx),
            Op::ConcatCols { parts } => shape::concat_cols_backward(parts, g, cx),
            Op::SliceCols { x, start } => shape::slice_cols_backward(*x, *start, g, cx),
            Op::GatherCols { x, index } => shape::gather_cols_backward(*x, index, g, cx),
            Op::GatherRows { x, index } => shape::gather_rows_backward(*x, index, g, cx),
            Op::Reshape { x } => shape::reshape_backward(*x, g, cx),
            Op::RowGroupMean { x, n } => groups::row_group_mean_backward(*x, *n, g, cx),
            Op::RowGroupMax { x, n, arg } => groups::row_group_max_backward(*x, *n, *arg, g, cx),
            Op::LayerNorm {
                x,
                gain,
                bias,
                stats,
            } => layer_norm::layer_norm_backward(*x, *gain, *bias, *stats, g, cx),
            Op::GeluTanh { x, t } => gelu::gelu_tanh_backward(*x, *t, g, cx),
            Op::SelfAttention(node) => node.backward(g, cx),
            Op::Sum { x } => reduce::sum_backward(*x, g, cx),
            Op::Mean { x } => reduce::mean_backward(*x, g, cx),
            Op::MaskedMean { x, mask } => reduce::masked_mean_backward(*x, *mask, g, cx),
            Op::Lstm(node) => node.backward(g, cx),
            Op::Gru(node) => node.backward(g, cx),
        }
    }
}

/// `dst = expr` on the first gradient contribution, `dst += expr` afterwards, elementwise over
/// `dst` zipped with the sources.
macro_rules! put {
    ($mode:expr, $dst:expr, $($src:expr),+ ; |$($p:ident),+| $e:expr) => {{
        match $mode {
            $crate::autograd::kernels::gemm::Mode::Overwrite => ndarray::Zip::from($dst)
                $(.and($src))+
                .for_each(|d, $(&$p),+| *d = $e),
            $crate::autograd::kernels::gemm::Mode::Accumulate => ndarray::Zip::from($dst)
                $(.and($src))+
                .for_each(|d, $(&$p),+| *d += $e),
        }
    }};
}
pub(crate) use put;

#[cfg(test)]
pub(crate) mod grad_check;
