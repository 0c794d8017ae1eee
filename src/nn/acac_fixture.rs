//! Test-only access to `tests/fixtures/acac_nets_torch.{json,safetensors}`, written by
//! `scripts/acac_nets_fixture_from_torch.py` from ACAC's own PyTorch modules: the values the
//! ACAC nets' parity tests compare with.

use ndarray::{Array2, ArrayView, Dimension};
use serde_json::Value;

/// The fixture: its JSON (inputs, outputs, gradients) and its safetensors bytes (the modules'
/// state_dicts under prefixes `critic.`, `actor.`, `concat.`, `max_linear.`,
/// `gpt2_two_layers.`).
pub(crate) struct Fixture {
    pub json: Value,
    pub bytes: &'static [u8],
}

impl Fixture {
    pub fn load() -> Self {
        Fixture {
            json: serde_json::from_str(include_str!("../../tests/fixtures/acac_nets_torch.json"))
                .expect("the fixture is JSON"),
            bytes: include_bytes!("../../tests/fixtures/acac_nets_torch.safetensors"),
        }
    }

    /// A `{"shape": [...], "data": [...]}` tensor's shape and values.
    pub fn tensor(v: &Value) -> (Vec<usize>, Vec<f32>) {
        let shape = v["shape"]
            .as_array()
            .unwrap_or_else(|| panic!("not a tensor: {v}"))
            .iter()
            .map(|d| d.as_u64().unwrap() as usize)
            .collect();
        let data = v["data"]
            .as_array()
            .unwrap()
            .iter()
            .map(|d| d.as_f64().unwrap() as f32)
            .collect();
        (shape, data)
    }

    /// A tensor of two dimensions as an array; one dimension becomes one row.
    pub fn array2(v: &Value) -> Array2<f32> {
        let (shape, data) = Self::tensor(v);
        let (r, c) = match shape[..] {
            [r, c] => (r, c),
            [c] => (1, c),
            _ => panic!("array2 of shape {shape:?}"),
        };
        Array2::from_shape_vec((r, c), data).unwrap()
    }
}

/// Panics unless `ours` has `want`'s element count and every element is within
/// tol * (1 + |want|) of it.
pub(crate) fn assert_close<D: Dimension>(
    what: &str,
    ours: ArrayView<f32, D>,
    want: &Value,
    tol: f32,
) {
    let (_, want) = Fixture::tensor(want);
    assert_eq!(ours.len(), want.len(), "{what}: element count");
    for (i, (a, b)) in ours.iter().zip(&want).enumerate() {
        assert!(
            (a - b).abs() <= tol * (1.0 + b.abs()),
            "{what}[{i}]: ours {a}, torch {b}"
        );
    }
}
