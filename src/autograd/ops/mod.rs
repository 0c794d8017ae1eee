//! The differentiable operations. Each file defines its ops' forward (as `Tape` methods) next to
//! their backward; this module only names them and dispatches the reverse pass.

mod elementwise;
mod lstm;
mod matmul;
mod reduce;
mod shape;

pub use lstm::LstmVars;

use ndarray::Array2;

use super::kernels::dense::Activation;
use super::tape::{GradCx, Var};

/// What produced a node, with what its backward needs besides the forward values.
#[derive(Debug)]
pub(crate) enum Op {
    /// Parameter, constant, or an op's cache: nothing to propagate.
    Leaf,
    #[cfg(test)]
    MatMulNt {
        a: Var,
        b: Var,
    },
    #[cfg(test)]
    AddBias {
        x: Var,
        bias: Var,
    },
    Linear {
        x: Var,
        w: Var,
        b: Var,
        act: Activation,
    },
    #[cfg(test)]
    Add {
        a: Var,
        b: Var,
    },
    Sub {
        a: Var,
        b: Var,
    },
    #[cfg(test)]
    Mul {
        a: Var,
        b: Var,
    },
    #[cfg(test)]
    Sigmoid {
        x: Var,
    },
    #[cfg(test)]
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
    #[cfg(test)]
    ConcatRows {
        parts: Vec<Var>,
    },
    #[cfg(test)]
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
    Mean {
        x: Var,
    },
    Lstm(Box<lstm::LstmNode>),
}

impl Op {
    /// Add this node's contribution to its inputs' gradients, given the node's value `y` and
    /// the gradient `g` flowing into it.
    pub(crate) fn backward(&self, y: &Array2<f32>, g: &Array2<f32>, cx: &mut GradCx) {
        match self {
            Op::Leaf => {}
            #[cfg(test)]
            Op::MatMulNt { a, b } => matmul::matmul_nt_backward(*a, *b, g, cx),
            #[cfg(test)]
            Op::AddBias { x, bias } => matmul::add_bias_backward(*x, *bias, g, cx),
            Op::Linear { x, w, b, act } => matmul::linear_backward(*x, *w, *b, *act, y, g, cx),
            #[cfg(test)]
            Op::Add { a, b } => elementwise::add_backward(*a, *b, g, cx),
            Op::Sub { a, b } => elementwise::sub_backward(*a, *b, g, cx),
            #[cfg(test)]
            Op::Mul { a, b } => elementwise::mul_backward(*a, *b, g, cx),
            #[cfg(test)]
            Op::Sigmoid { x } => elementwise::sigmoid_backward(*x, y, g, cx),
            #[cfg(test)]
            Op::Tanh { x } => elementwise::tanh_backward(*x, y, g, cx),
            Op::LeakyRelu { x, slope } => elementwise::leaky_relu_backward(*x, *slope, g, cx),
            Op::Square { x } => elementwise::square_backward(*x, g, cx),
            #[cfg(test)]
            Op::ConcatRows { parts } => shape::concat_rows_backward(parts, g, cx),
            #[cfg(test)]
            Op::SliceCols { x, start } => shape::slice_cols_backward(*x, *start, g, cx),
            Op::GatherCols { x, index } => shape::gather_cols_backward(*x, index, g, cx),
            Op::GatherRows { x, index } => shape::gather_rows_backward(*x, index, g, cx),
            Op::Mean { x } => reduce::mean_backward(*x, g, cx),
            Op::Lstm(node) => node.backward(g, cx),
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
