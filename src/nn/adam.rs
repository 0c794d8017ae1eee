//! Adam with PyTorch's semantics (`torch.optim.Adam`, single-tensor path): betas (0.9, 0.999),
//! eps 1e-8, bias correction, no weight decay, no AMSGrad, no gradient clipping (`docs/ALGORITHMS.md` §2.4).

use serde::{Deserialize, Serialize};

use super::params::Params;
use crate::autograd::kernels::activations::simd_dispatch;

/// Adam's hyperparameters. Scalars are f64 as PyTorch's are Python floats; they are rounded to
/// f32 where they meet the tensors, as in PyTorch.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AdamConfig {
    /// Learning rate.
    pub lr: f64,
    /// Decay of the first moment (PyTorch's default 0.9).
    pub beta1: f64,
    /// Decay of the second moment (PyTorch's default 0.999).
    pub beta2: f64,
    /// Added to the root of the second moment (PyTorch's default 1e-8).
    pub eps: f64,
}

impl AdamConfig {
    /// PyTorch's defaults with learning rate `lr`.
    pub fn with_lr(lr: f64) -> Self {
        AdamConfig {
            lr,
            beta1: 0.9,
            beta2: 0.999,
            eps: 1e-8,
        }
    }
}

/// Adam's state: the step count and the first and second moments of every tensor (serializable
/// for training checkpoints).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Adam {
    /// The hyperparameters.
    pub config: AdamConfig,
    step: u64,
    m: Vec<Vec<f32>>,
    v: Vec<Vec<f32>>,
}

impl Adam {
    /// Zero moments shaped like `params`.
    pub fn new<P: Params>(config: AdamConfig, params: &P) -> Self {
        let sizes: Vec<usize> = params.slices().iter().map(|s| s.len()).collect();
        Adam {
            config,
            step: 0,
            m: sizes.iter().map(|&n| vec![0.0; n]).collect(),
            v: sizes.iter().map(|&n| vec![0.0; n]).collect(),
        }
    }

    /// Number of steps taken.
    pub fn steps_taken(&self) -> u64 {
        self.step
    }

    /// One update of `params` from `grads` (the same parameter type, so tensors line up):
    /// ```text
    /// m = m + (1 - b1) (g - m)          (PyTorch's lerp)
    /// v = b2 v + (1 - b2) g^2
    /// p = p - lr / (1 - b1^t) * m / (sqrt(v) / sqrt(1 - b2^t) + eps)
    /// ```
    /// Panics if the tensor sizes differ from those Adam was created for.
    pub fn step<P: Params>(&mut self, params: &mut P, grads: &P) {
        self.step += 1;
        let c = self.config;
        let t = self.step as i32;
        let bias_correction1 = 1.0 - c.beta1.powi(t);
        let bias_correction2 = 1.0 - c.beta2.powi(t);
        let step_size = (c.lr / bias_correction1) as f32;
        let bc2_sqrt = bias_correction2.sqrt() as f32;
        let (w1, b2, w2, eps) = (
            (1.0 - c.beta1) as f32,
            c.beta2 as f32,
            (1.0 - c.beta2) as f32,
            c.eps as f32,
        );
        let ps = params.slices_mut();
        let gs = grads.slices();
        assert_eq!(ps.len(), self.m.len(), "adam: different number of tensors");
        assert_eq!(
            gs.len(),
            self.m.len(),
            "adam: different number of gradient tensors"
        );
        for (((p, g), m), v) in ps.into_iter().zip(gs).zip(&mut self.m).zip(&mut self.v) {
            assert_eq!(p.len(), m.len(), "adam: tensor size changed");
            assert_eq!(
                g.len(),
                m.len(),
                "adam: gradient size differs from the parameter's"
            );
            adam_update(p, g, m, v, [w1, b2, w2, bc2_sqrt, eps, step_size]);
        }
    }
}

simd_dispatch! {
    /// The elementwise update of one tensor; c = [1 - b1, b2, 1 - b2, sqrt(1 - b2^t), eps,
    /// lr / (1 - b1^t)]. Vectorized, identical bits on every instruction set.
    pub fn adam_update(p: &mut [f32], g: &[f32], m: &mut [f32], v: &mut [f32], c: [f32; 6]) {
        let [w1, b2, w2, bc2_sqrt, eps, step_size] = c;
        let n = p.len();
        let (g, m, v) = (&g[..n], &mut m[..n], &mut v[..n]);
        for i in 0..n {
            let gi = g[i];
            let mi = m[i] + w1 * (gi - m[i]);
            let vi = b2 * v[i] + w2 * gi * gi;
            let denom = vi.sqrt() / bc2_sqrt + eps;
            p[i] -= step_size * (mi / denom);
            m[i] = mi;
            v[i] = vi;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct One(Vec<f32>);
    impl Params for One {
        fn slices(&self) -> Vec<&[f32]> {
            vec![&self.0]
        }
        fn slices_mut(&mut self) -> Vec<&mut [f32]> {
            vec![&mut self.0]
        }
    }

    #[test]
    fn first_step_moves_each_parameter_by_about_lr_against_the_gradient_sign() {
        // t = 1: m = 0.1 g, v = 0.001 g^2, m / (1 - 0.9) = g, sqrt(v / (1 - 0.999)) = |g|,
        // so the step is lr * g / (|g| + eps) = lr * sign(g).
        let mut p = One(vec![1.0, 1.0, 1.0]);
        let g = One(vec![0.5, -2.0, 0.0]);
        let mut adam = Adam::new(AdamConfig::with_lr(0.01), &p);
        adam.step(&mut p, &g);
        assert!((p.0[0] - 0.99).abs() < 1e-6);
        assert!((p.0[1] - 1.01).abs() < 1e-6);
        assert_eq!(p.0[2], 1.0);
    }

    #[test]
    fn matches_a_hand_computed_second_step() {
        let mut p = One(vec![0.0]);
        let mut adam = Adam::new(AdamConfig::with_lr(0.1), &p);
        adam.step(&mut p, &One(vec![1.0]));
        adam.step(&mut p, &One(vec![3.0]));
        // m2 = 0.9 * 0.1 + 0.1 * 3 = 0.39; v2 = 0.999 * 0.001 + 0.001 * 9 = 0.009999
        // p2 = -0.1 - 0.1 / (1 - 0.81) * 0.39 / (sqrt(0.009999 / (1 - 0.998001)) + 1e-8)
        let p2 = -0.1 - 0.1 / 0.19 * 0.39 / ((0.009999f64 / 0.001999).sqrt() + 1e-8);
        assert!((p.0[0] as f64 - p2).abs() < 1e-6, "{} vs {p2}", p.0[0]);
        assert_eq!(adam.steps_taken(), 2);
    }
}
