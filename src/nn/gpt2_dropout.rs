//! Dropout masks for the GPT-2 encoder, supplied from outside the nets. ACAC never puts its
//! transformer in `eval()`, so HuggingFace's default dropout (0.1 on the embeddings, the
//! attention probabilities and both residual branches) is live whenever its critic runs
//! (its `models.py` never calls `eval()` on the critic). A mask is an array of multipliers, 0 where
//! a value is dropped and 1 / (1 - p) elsewhere (PyTorch's `nn.Dropout` in training), so a run
//! can draw its own from its seeded stream ([`Gpt2Dropout::draw`]) or replay the masks a
//! reference run drew, and the nets apply either with the same `mul`.

use ndarray::Array2;
use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// One block's masks, for B n rows of width d with n_head heads over sets of n.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockDropout {
    /// On the attention probabilities (`attn.attn_dropout`): [B n, n_head n], entry
    /// (b n + i, h n + j) for query i, key j of head h in sample b.
    pub attn: Array2<f32>,
    /// On the attention branch after `c_proj` (`attn.resid_dropout`): [B n, d].
    pub resid: Array2<f32>,
    /// On the MLP branch after its `c_proj` (`mlp.dropout`): [B n, d].
    pub mlp: Array2<f32>,
}

/// The masks of one GPT-2 forward: after the position embeddings are added (`drop`), then per
/// block.
#[derive(Debug, Clone, PartialEq)]
pub struct Gpt2Dropout {
    /// On the embeddings plus positions (`drop`): [B n, d].
    pub embd: Array2<f32>,
    /// One per block, in order.
    pub blocks: Vec<BlockDropout>,
}

/// [rows, cols] multipliers: 0 with probability p, else 1 / (1 - p). Panics unless 0 <= p < 1.
///
/// Entry by entry in row-major order, each from one `rng.gen::<f32>()` (rand's `Standard`:
/// the top 24 bits of one `next_u32`, times 2^-24). The words come from the stream in blocks
/// (`Rng::fill`, the same words in the same order as one `next_u32` each), which is several
/// times faster than a call per entry and draws the same masks.
pub fn dropout_mask(rows: usize, cols: usize, p: f32, rng: &mut ChaCha8Rng) -> Array2<f32> {
    assert!((0.0..1.0).contains(&p), "dropout rate {p} outside [0, 1)");
    let keep = 1.0 / (1.0 - p);
    let scale = 1.0 / (1u32 << 24) as f32;
    let mut out = vec![0.0f32; rows * cols];
    let mut words = [0u32; 256];
    for chunk in out.chunks_mut(words.len()) {
        let words = &mut words[..chunk.len()];
        rng.fill(words);
        for (m, &w) in chunk.iter_mut().zip(words.iter()) {
            *m = if scale * ((w >> 8) as f32) < p {
                0.0
            } else {
                keep
            };
        }
    }
    Array2::from_shape_vec((rows, cols), out).expect("rows x cols values")
}

impl Gpt2Dropout {
    /// Fresh masks with rate p for `rows` = B n rows of width `width`, sets of `set_size` rows,
    /// `n_head` heads and `n_layer` blocks, drawn in the order the forward applies them.
    pub fn draw(
        rows: usize,
        width: usize,
        set_size: usize,
        n_head: usize,
        n_layer: usize,
        p: f32,
        rng: &mut ChaCha8Rng,
    ) -> Self {
        let embd = dropout_mask(rows, width, p, rng);
        let blocks = (0..n_layer)
            .map(|_| BlockDropout {
                attn: dropout_mask(rows, n_head * set_size, p, rng),
                resid: dropout_mask(rows, width, p, rng),
                mlp: dropout_mask(rows, width, p, rng),
            })
            .collect();
        Gpt2Dropout { embd, blocks }
    }
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;

    use super::*;

    #[test]
    fn masks_drop_about_p_and_rescale_the_rest() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let m = dropout_mask(100, 100, 0.1, &mut rng);
        let dropped = m.iter().filter(|&&v| v == 0.0).count();
        assert!((900..1100).contains(&dropped), "{dropped} of 10000 dropped");
        assert!(m.iter().all(|&v| v == 0.0 || v == 1.0 / 0.9));
        // The kept values' scale keeps the mean: E[mask] = 1.
        assert!((m.mean().unwrap() - 1.0).abs() < 0.02);
    }

    #[test]
    fn kept_values_are_scaled_as_pytorchs_dropout_scales_them() {
        // The multipliers torch's nn.Dropout(0.1) applied in the fixture's recorded masks.
        let f = crate::nn::acac_fixture::Fixture::load();
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        let ours = dropout_mask(1, 50, 0.1, &mut rng);
        let keep = ours.iter().copied().fold(0.0f32, f32::max);
        for (name, m) in f.json["gpt2_dropout"]["dropout"].as_object().unwrap() {
            let (_, values) = crate::nn::acac_fixture::Fixture::tensor(m);
            assert!(values.iter().all(|&v| v == 0.0 || v == keep), "{name}");
            assert!(values.contains(&0.0) && values.contains(&keep), "{name}");
        }
    }

    #[test]
    fn masks_are_one_gen_f32_per_entry_in_row_major_order() {
        // The block draw against the definition: one `rng.gen::<f32>()` per entry, and the
        // stream left where the definition leaves it.
        let (mut a, mut b) = (ChaCha8Rng::seed_from_u64(9), ChaCha8Rng::seed_from_u64(9));
        let _ = a.gen::<u32>();
        let _ = b.gen::<u32>();
        let m = dropout_mask(37, 29, 0.1, &mut a);
        let keep = 1.0 / (1.0 - 0.1f32);
        let want =
            Array2::from_shape_simple_fn(
                (37, 29),
                || {
                    if b.gen::<f32>() < 0.1 {
                        0.0
                    } else {
                        keep
                    }
                },
            );
        assert_eq!(m, want);
        assert_eq!(a.gen::<u64>(), b.gen::<u64>());
    }

    #[test]
    fn draw_sizes_every_mask_for_its_place() {
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        let d = Gpt2Dropout::draw(12, 8, 3, 2, 2, 0.1, &mut rng);
        assert_eq!(d.embd.dim(), (12, 8));
        assert_eq!(d.blocks.len(), 2);
        assert_eq!(d.blocks[1].attn.dim(), (12, 6));
        assert_eq!(d.blocks[1].mlp.dim(), (12, 8));
    }
}
