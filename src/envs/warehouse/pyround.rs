//! Python's `round(x, 2)` for f64, bit for bit (`docs/WAREHOUSE.md` §5 step 1, quirk Q3).
//!
//! CPython rounds the *exact* binary value of `x` to the nearest multiple of 0.01 (ties to even,
//! which only happens when `x` is exactly `k/100 + 1/200`, e.g. 0.125) and returns the f64 nearest
//! to that decimal. Computing `(x * 100.0).round() / 100.0` differs when the product `x * 100` rounds
//! across a half-way point, and uses ties-away. Here the product is split error-free into
//! `p + e` (Dekker's two-product; 100 needs no split), the half-way comparison is done on the
//! exact value, and the final `n / 100.0` is one correctly rounded division, which is the nearest
//! f64 to the decimal `n/100` — exactly what CPython's string round-trip produces.

/// `round(x, 2)` as CPython computes it, for finite `0 <= x < 2^40` (distances here are < 10);
/// NaN, negative or huge inputs give unspecified (non-panicking) results.
pub fn round2(x: f64) -> f64 {
    let p = x * 100.0;
    let e = product_error(x, p);
    // floor of the exact value p + e (p may have rounded up onto an integer). Truncation is the
    // floor for p >= 0 and avoids a libm call.
    let mut lo = p as u64;
    if lo as f64 == p && e < 0.0 && lo > 0 {
        lo -= 1;
    }
    let lo_f = lo as f64;
    // Sign of (p + e) - (lo + 0.5): `p - lo - 0.5` is exact (or far from zero), `e` exact, and a
    // rounded sum keeps the sign of the exact sum.
    let above_half = (p - lo_f - 0.5) + e;
    let n = if above_half > 0.0 || (above_half == 0.0 && lo % 2 == 1) {
        lo + 1
    } else {
        lo
    };
    n as f64 / 100.0
}

/// The exact rounding error of `p = x * 100.0`, so that `x * 100 = p + e` exactly (Dekker).
fn product_error(x: f64, p: f64) -> f64 {
    // Veltkamp split of x into 26-bit halves; 100 has 7 significant bits, so x_hi * 100 is exact.
    const SPLIT: f64 = 134_217_729.0; // 2^27 + 1
    let c = SPLIT * x;
    let x_hi = c - (c - x);
    let x_lo = x - x_hi;
    (x_hi * 100.0 - p) + x_lo * 100.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Oracle: exact decimal expansion of x (every f64 has one), rounded half-even at 2 places,
    /// then parsed back (Rust's parse is correctly rounded).
    fn oracle(x: f64) -> f64 {
        // Exact: x in [0, 10) has at most 62 fractional binary digits, hence as many decimal ones,
        // and Rust prints the exact expansion when enough digits are asked for.
        let s = format!("{x:.80}");
        let (int, frac) = s.split_once('.').unwrap();
        let kept = &frac[..2];
        let rest = &frac[2..];
        let mut n: u64 = format!("{int}{kept}").parse().unwrap();
        let half = rest.as_bytes()[0] > b'5'
            || (rest.as_bytes()[0] == b'5' && rest[1..].bytes().any(|b| b != b'0'));
        let tie = rest.as_bytes()[0] == b'5' && rest[1..].bytes().all(|b| b == b'0');
        if half || (tie && n % 2 == 1) {
            n += 1;
        }
        format!("{}.{:02}", n / 100, n % 100).parse().unwrap()
    }

    #[test]
    fn known_python_values() {
        // Values from CPython: round(2.675, 2) == 2.67 (binary value below the half),
        // round(0.125, 2) == 0.12 and round(0.375, 2) == 0.38 (exact ties, to even).
        assert_eq!(round2(2.675), 2.67);
        assert_eq!(round2(0.125), 0.12);
        assert_eq!(round2(0.375), 0.38);
        assert_eq!(round2(0.6000000000000005), 0.6);
        assert_eq!(round2(4.8), 4.8);
        assert_eq!(round2(0.0), 0.0);
        assert_eq!(round2(1.005), 1.0); // 1.005 is 1.00499999999999989...
    }

    #[test]
    fn matches_exact_decimal_rounding_on_random_values() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for _ in 0..20_000 {
            let x: f64 = rng.gen_range(0.0..10.0);
            assert_eq!(round2(x).to_bits(), oracle(x).to_bits(), "x = {x:e}");
            // Values right at the half-way points, where naive rounding goes wrong.
            let k: u32 = rng.gen_range(0..1000);
            let h = (f64::from(k) + 0.5) / 100.0;
            // And right at multiples of 0.01, where x * 100 may round onto an integer.
            let m = f64::from(k + 1) / 100.0;
            let near = [h, m].map(|v| {
                [
                    v,
                    f64::from_bits(v.to_bits() + 1),
                    f64::from_bits(v.to_bits() - 1),
                ]
            });
            for y in near.into_iter().flatten() {
                assert_eq!(round2(y).to_bits(), oracle(y).to_bits(), "y = {y:e}");
            }
        }
    }
}
