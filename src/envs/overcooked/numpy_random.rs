//! numpy's legacy global random stream, as far as ACAC's random starts use it: `np.random.seed(s)`
//! then `np.random.randint(low, high[, size])` (`docs/ACAC.md`; `../shared/spec/acac_envs.md`
//! §Overcooked-MA-v1 item 2).
//!
//! The legacy `RandomState` is MT19937 seeded by `init_genrand` (`mt19937_seed`), and its
//! `randint` on the default `int64` dtype draws by masked rejection on 32-bit outputs when the
//! range fits in 32 bits (`random_bounded_uint64_fill` with `use_masked`): `v = next_u32() & mask`
//! until `v <= high - 1 - low`, where `mask` is the range with every lower bit set. A `size`
//! argument draws its values one after the other in the same way. Checked against numpy 2.4 in
//! the tests below (the values were printed by numpy itself).

use serde::{Deserialize, Serialize};

/// Words of MT19937's state.
const N: usize = 624;
/// MT19937's middle word offset.
const M: usize = 397;

/// numpy's legacy `RandomState` stream (MT19937).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct NumpyRandom {
    /// The 624 state words (a `Vec` because serde has no impl for arrays this long).
    key: Vec<u32>,
    /// The next word to temper; `N` means the state must be regenerated first.
    pos: usize,
}

/// Where a random start's integers come from: numpy's stream (replaying ACAC) or the run's own.
pub trait DrawInt {
    /// An integer uniform in `low..high` (`high > low`), as `np.random.randint(low, high)`.
    fn draw(&mut self, low: i64, high: i64) -> i64;
}

impl NumpyRandom {
    /// The stream after `np.random.seed(seed)` (`mt19937_seed`).
    pub fn seed(seed: u32) -> Self {
        let mut key = vec![0u32; N];
        let mut s = seed;
        for (pos, k) in key.iter_mut().enumerate() {
            *k = s;
            s = 1_812_433_253u32
                .wrapping_mul(s ^ (s >> 30))
                .wrapping_add(pos as u32 + 1);
        }
        NumpyRandom { key, pos: N }
    }

    /// Regenerate the state words (`mt19937_gen`).
    fn generate(&mut self) {
        const UPPER: u32 = 0x8000_0000;
        const LOWER: u32 = 0x7fff_ffff;
        const MATRIX_A: u32 = 0x9908_b0df;
        let twist = |hi: u32, lo: u32, far: u32| {
            let y = (hi & UPPER) | (lo & LOWER);
            far ^ (y >> 1) ^ if y & 1 == 1 { MATRIX_A } else { 0 }
        };
        for i in 0..N {
            let far = self.key[(i + M) % N];
            self.key[i] = twist(self.key[i], self.key[(i + 1) % N], far);
        }
        self.pos = 0;
    }

    /// The next 32-bit output (`mt19937_next32`, with MT19937's tempering).
    pub fn next_u32(&mut self) -> u32 {
        if self.pos == N {
            self.generate();
        }
        let mut y = self.key[self.pos];
        self.pos += 1;
        y ^= y >> 11;
        y ^= (y << 7) & 0x9d2c_5680;
        y ^= (y << 15) & 0xefc6_0000;
        y ^ (y >> 18)
    }
}

impl DrawInt for NumpyRandom {
    /// `np.random.randint(low, high)` for a range below 2^32 (all ACAC draws are).
    ///
    /// Panics if `high <= low` or the range reaches 2^32 (numpy raises or takes another path).
    fn draw(&mut self, low: i64, high: i64) -> i64 {
        assert!(high > low, "randint needs high > low, got {low}..{high}");
        let range = u64::try_from(high - 1 - low).expect("high > low");
        assert!(
            range < 0xffff_ffff,
            "range {range} is beyond the masked 32-bit path"
        );
        if range == 0 {
            return low;
        }
        let range = range as u32;
        let mask = u32::MAX >> range.leading_zeros();
        loop {
            let v = self.next_u32() & mask;
            if v <= range {
                return low + i64::from(v);
            }
        }
    }
}

impl DrawInt for super::super::EnvRng {
    /// Uniform in `low..high` from the run's own stream (training with random starts).
    fn draw(&mut self, low: i64, high: i64) -> i64 {
        rand::Rng::gen_range(self, low..high)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values numpy 2.4 printed for the same calls:
    /// `np.random.seed(0); np.random.randint(1, 6, 2), randint(0, 20), randint(0, 33)`.
    #[test]
    fn draws_are_numpys_legacy_randint() {
        let mut r = NumpyRandom::seed(0);
        let got: Vec<i64> = [(1, 6), (1, 6), (0, 20), (0, 33)]
            .iter()
            .map(|&(lo, hi)| r.draw(lo, hi))
            .collect();
        assert_eq!(got, [5, 1, 3, 3]);
        let mut r = NumpyRandom::seed(12345);
        let got: Vec<i64> = [(0, 1000), (0, 1000), (0, 1000), (1, 10), (1, 10)]
            .iter()
            .map(|&(lo, hi)| r.draw(lo, hi))
            .collect();
        assert_eq!(got, [482, 485, 285, 2, 5]);
        assert_eq!(NumpyRandom::seed(u32::MAX).draw(0, 1 << 31), 419_326_371);
    }

    #[test]
    fn a_single_value_range_draws_nothing() {
        let mut r = NumpyRandom::seed(7);
        let before = r.clone();
        assert_eq!(r.draw(4, 5), 4);
        assert_eq!(r, before);
    }
}
