//! Welch's unequal-variance t-test, one-sided, for comparing two methods' final returns over
//! seeds: "is A's mean above B's?". The Student-t tail comes from the regularized incomplete beta
//! function (continued fraction, modified Lentz), so no statistics crate is needed.

/// The result of testing H1: mean(A) > mean(B).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WelchTest {
    /// Welch's t statistic.
    pub t: f64,
    /// Welch-Satterthwaite degrees of freedom.
    pub df: f64,
    /// One-sided p-value of H1: mean(A) > mean(B).
    pub p_greater: f64,
}

/// Welch's test of mean(a) > mean(b). `None` when a side has fewer than two values, or when
/// both sides have no spread and equal means (nothing to test).
pub fn welch_greater(a: &[f64], b: &[f64]) -> Option<WelchTest> {
    if a.len() < 2 || b.len() < 2 || a.iter().chain(b).any(|v| !v.is_finite()) {
        return None;
    }
    let (ma, va) = mean_var(a);
    let (mb, vb) = mean_var(b);
    let (sa, sb) = (va / a.len() as f64, vb / b.len() as f64);
    let s = sa + sb;
    if s == 0.0 {
        return (ma != mb).then_some(WelchTest {
            t: if ma > mb {
                f64::INFINITY
            } else {
                f64::NEG_INFINITY
            },
            df: f64::INFINITY,
            p_greater: if ma > mb { 0.0 } else { 1.0 },
        });
    }
    let t = (ma - mb) / s.sqrt();
    let df = s * s / (sa * sa / (a.len() - 1) as f64 + sb * sb / (b.len() - 1) as f64);
    Some(WelchTest {
        t,
        df,
        p_greater: student_t_sf(t, df),
    })
}

/// Mean and sample variance (ddof 1).
fn mean_var(xs: &[f64]) -> (f64, f64) {
    let n = xs.len() as f64;
    let mean = xs.iter().sum::<f64>() / n;
    let ss: f64 = xs.iter().map(|x| (x - mean) * (x - mean)).sum();
    (mean, ss / (n - 1.0))
}

/// P(T > t) for Student's t with `df` degrees of freedom.
pub fn student_t_sf(t: f64, df: f64) -> f64 {
    if t.is_infinite() {
        return if t > 0.0 { 0.0 } else { 1.0 };
    }
    // P(|T| > |t|) = I_{df / (df + t^2)}(df / 2, 1 / 2).
    let two_sided = regularized_beta(df / (df + t * t), df / 2.0, 0.5);
    if t >= 0.0 {
        two_sided / 2.0
    } else {
        1.0 - two_sided / 2.0
    }
}

/// I_x(a, b), the regularized incomplete beta function, for a, b > 0 and 0 <= x <= 1.
pub fn regularized_beta(x: f64, a: f64, b: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let ln_front = a * x.ln() + b * (1.0 - x).ln() - ln_beta(a, b);
    // The continued fraction converges fast below the mean of the Beta(a, b) distribution;
    // above it, use the symmetry I_x(a, b) = 1 - I_{1-x}(b, a).
    if x < (a + 1.0) / (a + b + 2.0) {
        ln_front.exp() * beta_continued_fraction(x, a, b) / a
    } else {
        1.0 - ln_front.exp() * beta_continued_fraction(1.0 - x, b, a) / b
    }
}

fn ln_beta(a: f64, b: f64) -> f64 {
    ln_gamma(a) + ln_gamma(b) - ln_gamma(a + b)
}

/// The continued fraction of I_x(a, b) (without its prefactor), by the modified Lentz method.
fn beta_continued_fraction(x: f64, a: f64, b: f64) -> f64 {
    const TINY: f64 = 1e-300;
    const EPS: f64 = 1e-15;
    let guard = |v: f64| if v.abs() < TINY { TINY } else { v };
    let mut c = 1.0;
    let mut d = 1.0 / guard(1.0 - (a + b) * x / (a + 1.0));
    let mut h = d;
    for m in 1..=500 {
        let m = m as f64;
        // Even step: d_{2m} = m (b - m) x / ((a + 2m - 1)(a + 2m)).
        let even = m * (b - m) * x / ((a + 2.0 * m - 1.0) * (a + 2.0 * m));
        d = 1.0 / guard(1.0 + even * d);
        c = guard(1.0 + even / c);
        h *= d * c;
        // Odd step: d_{2m+1} = -(a + m)(a + b + m) x / ((a + 2m)(a + 2m + 1)).
        let odd = -(a + m) * (a + b + m) * x / ((a + 2.0 * m) * (a + 2.0 * m + 1.0));
        d = 1.0 / guard(1.0 + odd * d);
        c = guard(1.0 + odd / c);
        let step = d * c;
        h *= step;
        if (step - 1.0).abs() < EPS {
            break;
        }
    }
    h
}

/// ln Γ(x) for x > 0 (Lanczos, g = 7, nine terms; about 15 significant digits).
fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const COEF: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection: Γ(x) Γ(1 - x) = π / sin(π x).
        return (std::f64::consts::PI / (std::f64::consts::PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut sum = COEF[0];
    for (i, c) in COEF.iter().enumerate().skip(1) {
        sum += c / (x + i as f64);
    }
    let t = x + G + 0.5;
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + sum.ln()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    #[test]
    fn ln_gamma_matches_factorials_and_half_integers() {
        // Γ(n) = (n-1)!, Γ(1/2) = sqrt(π).
        assert!(close(ln_gamma(1.0), 0.0, 1e-13));
        assert!(close(ln_gamma(5.0), 24f64.ln(), 1e-13));
        assert!(close(
            ln_gamma(20.0),
            121_645_100_408_832_000f64.ln(),
            1e-11
        ));
        assert!(close(
            ln_gamma(0.5),
            std::f64::consts::PI.sqrt().ln(),
            1e-13
        ));
    }

    #[test]
    fn student_t_tails_match_closed_forms() {
        // df 1 is the Cauchy distribution: P(T > t) = 1/2 - atan(t)/π.
        for t in [-3.0, -0.5, 0.0, 1.0, 4.0] {
            let want = 0.5 - f64::atan(t) / std::f64::consts::PI;
            assert!(close(student_t_sf(t, 1.0), want, 1e-12), "t {t}");
        }
        // df 2: P(T > t) = 1/2 - t / (2 sqrt(t^2 + 2)).
        for t in [-2.0f64, 0.3, 1.0, 7.0] {
            let want = 0.5 - t / (2.0 * (t * t + 2.0).sqrt());
            assert!(close(student_t_sf(t, 2.0), want, 1e-12), "t {t}");
        }
        // Tabulated: t = 2.228 is the 97.5% point for df 10; a huge df is the normal.
        assert!(close(student_t_sf(2.228, 10.0), 0.025, 1e-4));
        assert!(close(student_t_sf(1.959_964, 1e7), 0.025, 1e-6));
    }

    #[test]
    fn welch_uses_satterthwaite_df_and_its_two_sides_sum_to_one() {
        // a: mean 2, var 1; b: mean 6, var 4; n = 3 each.
        // s = 1/3 + 4/3 = 5/3; t = -4 / sqrt(5/3); df = (5/3)^2 / ((1/3)^2/2 + (4/3)^2/2) = 50/17.
        let a = [1.0, 2.0, 3.0];
        let b = [4.0, 6.0, 8.0];
        let ab = welch_greater(&a, &b).unwrap();
        assert!(close(ab.t, -4.0 / (5.0f64 / 3.0).sqrt(), 1e-12));
        assert!(close(ab.df, 50.0 / 17.0, 1e-12));
        let ba = welch_greater(&b, &a).unwrap();
        assert!(close(ab.p_greater + ba.p_greater, 1.0, 1e-12));
        assert!(ba.p_greater < 0.05 && ab.p_greater > 0.95);
    }

    #[test]
    fn degenerate_samples_are_handled() {
        assert_eq!(welch_greater(&[1.0], &[2.0, 3.0]), None);
        assert_eq!(welch_greater(&[5.0, 5.0], &[5.0, 5.0]), None);
        assert_eq!(
            welch_greater(&[5.0, 5.0], &[4.0, 4.0]).unwrap().p_greater,
            0.0
        );
        assert_eq!(welch_greater(&[f64::NAN, 1.0], &[4.0, 4.0]), None);
    }
}
