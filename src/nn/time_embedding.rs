//! ACAC's sinusoidal time embedding (`models.py: positionalencoding1d`, `time_emb_alg` "sinu"):
//! a constant table whose row t is appended to the inputs of a macro-observation made at
//! primitive step t (actor: `time_emb_actor`, critic: `time_emb`). The reference wraps it in a
//! frozen `nn.Embedding.from_pretrained` of max_timestep + 5 rows, so its state_dicts hold the
//! table as `time_embedding.weight` [max_timestep + 5, dim].
//!
//! ```text
//! w_i = exp(2i * -(ln 10000 / dim)),  pe[t, 2i] = sin(t w_i),  pe[t, 2i + 1] = cos(t w_i)
//! ```
//!
//! computed in f32 in the reference's order. The learned variant ("learn") is a trainable table
//! of the same shape: put it on a tape with `param` and pick rows with `gather_rows`.

use ndarray::{Array2, ArrayViewD};

use super::state_dict::StateDict;
use super::WeightsError;

/// Why a table cannot be built.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TimeEmbeddingError {
    /// sin and cos come in pairs (the reference raises the same ValueError).
    #[error("cannot use sin/cos positional encoding with odd dim (got dim={0})")]
    OddDim(usize),
}

/// ACAC's `positionalencoding1d(length, dim)`: [length, dim], sin in even columns, cos in odd.
pub fn sinusoidal_table(length: usize, dim: usize) -> Result<Array2<f32>, TimeEmbeddingError> {
    if !dim.is_multiple_of(2) {
        return Err(TimeEmbeddingError::OddDim(dim));
    }
    // -(math.log(10000.0) / d_model) in f64, then used as an f32 scalar, as torch does.
    let rate = (-(10000f64.ln() / dim as f64)) as f32;
    let freq: Vec<f32> = (0..dim / 2)
        .map(|i| ((2 * i) as f32 * rate).exp())
        .collect();
    Ok(Array2::from_shape_fn((length, dim), |(t, c)| {
        let angle = t as f32 * freq[c / 2];
        if c % 2 == 0 {
            angle.sin()
        } else {
            angle.cos()
        }
    }))
}

/// A time-embedding table, [rows, dim].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TimeEmbedding {
    /// Row t embeds primitive step t.
    pub table: Array2<f32>,
}

impl TimeEmbedding {
    /// The table ACAC builds for episodes of up to `max_timestep` steps: max_timestep + 5
    /// rows (`models.py`).
    pub fn sinusoidal(max_timestep: usize, dim: usize) -> Result<Self, TimeEmbeddingError> {
        Ok(TimeEmbedding {
            table: sinusoidal_table(max_timestep + 5, dim)?,
        })
    }

    /// The table under `prefix` (e.g. `time_embedding.`) in a state_dict: `weight`, any size.
    pub fn from_state_dict(sd: &StateDict, prefix: &str) -> Result<Self, WeightsError> {
        let name = format!("{prefix}weight");
        let (rows, dim) = sd.shape2(&name)?;
        Ok(TimeEmbedding {
            table: sd.array2(&name, rows, dim)?,
        })
    }

    /// The tensor under `prefix`: `weight`.
    pub fn named(&self, prefix: &str) -> Vec<(String, ArrayViewD<'_, f32>)> {
        vec![(format!("{prefix}weight"), self.table.view().into_dyn())]
    }

    /// Embedding width.
    pub fn dim(&self) -> usize {
        self.table.ncols()
    }

    /// The rows for steps `steps`: [steps.len(), dim]. Panics on a step past the table (the
    /// reference's `nn.Embedding` raises an IndexError there).
    pub fn lookup(&self, steps: &[usize]) -> Array2<f32> {
        let mut out = Array2::zeros((steps.len(), self.dim()));
        for (mut row, &t) in out.rows_mut().into_iter().zip(steps) {
            assert!(
                t < self.table.nrows(),
                "time embedding: step {t} past the table's {} rows",
                self.table.nrows()
            );
            row.assign(&self.table.row(t));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::nn::acac_fixture::{assert_close, Fixture};

    #[test]
    fn matches_acacs_positionalencoding1d() {
        let f = Fixture::load();
        // positionalencoding1d(205, 6): max_timestep 200, a width that is not a power of two.
        let want = &f.json["time_embedding"]["table"];
        let ours = TimeEmbedding::sinusoidal(200, 6).unwrap();
        assert_eq!(ours.table.dim(), (205, 6));
        assert_close("pe(205, 6)", ours.table.view(), want, 2e-6);
        // The actor's frozen table in its state_dict (max_timestep 20, dim 4).
        let sd = StateDict::parse(f.bytes, Path::new("fixture")).unwrap();
        let file = TimeEmbedding::from_state_dict(&sd, "actor.time_embedding.").unwrap();
        assert_eq!(file.table.dim(), (25, 4));
        let ours = TimeEmbedding::sinusoidal(20, 4).unwrap();
        for (a, b) in ours.table.iter().zip(file.table.iter()) {
            assert!((a - b).abs() <= 2e-6, "{a} vs {b}");
        }
    }

    #[test]
    fn even_columns_are_sines_and_odd_ones_cosines_of_the_same_angle() {
        let pe = sinusoidal_table(50, 8).unwrap();
        assert_eq!(
            pe.row(0).to_vec(),
            vec![0.0, 1.0, 0.0, 1.0, 0.0, 1.0, 0.0, 1.0]
        );
        for t in 0..50 {
            for i in 0..4 {
                let (s, c) = (pe[[t, 2 * i]], pe[[t, 2 * i + 1]]);
                assert!((s * s + c * c - 1.0).abs() < 1e-5);
            }
        }
        // Column pair 0 has frequency 1: sin(t).
        assert!((pe[[3, 0]] - 3.0f32.sin()).abs() < 1e-6);
    }

    #[test]
    fn an_odd_width_is_an_error_and_lookup_picks_rows() {
        assert_eq!(
            sinusoidal_table(10, 3).unwrap_err().to_string(),
            "cannot use sin/cos positional encoding with odd dim (got dim=3)"
        );
        let e = TimeEmbedding::sinusoidal(10, 4).unwrap();
        let rows = e.lookup(&[3, 0, 3]);
        assert_eq!(rows.row(0), e.table.row(3));
        assert_eq!(rows.row(1), e.table.row(0));
        assert_eq!(rows.row(2), rows.row(0));
    }
}
