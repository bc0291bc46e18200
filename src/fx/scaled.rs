//! Wide-range positive values: `mantissa * 2^exp2` with a Q2.30 mantissa in [1, 2).
//!
//! Loads (1 mN to 50 kN), real contact areas (1e-8 to 1 of A_n), the elastic shares of seed 000
//! eqs 4 and 7 (about 1e-8) and u / delta (up to about 1e11) span more decades than any 32-bit
//! fixed format holds at 1e-4 relative precision (physics-notes §5). The model carries them as
//! natural logarithms in Q6.26 or Q8.24 (absolute error ~1e-8, hence ~1e-8 relative), and
//! [`Scaled::from_ln`] turns such a logarithm back into a value with 30 significant bits without
//! any float: one exact range reduction by ln 2 and one `exp`.

use super::{Q, Q1_31, Q2_30};

/// round(ln 2 * 2^40) (ln 2 * 2^40 = 762123384786.43).
const LN2_Q40: i64 = 762_123_384_786;
/// round(2^30 / ln 2), for the estimate of the binary exponent only.
const LOG2E_Q30: i64 = 1_549_082_005;

/// A positive value `mantissa * 2^exp2`: `mantissa` Q2.30 in [1, 2), `exp2` any `i32`.
///
/// Relative resolution 9.3e-10. Built from a logarithm by [`Scaled::from_ln`]; turned into a
/// float only at the tool level ([`Scaled::to_f64`], exact) or into a wide fixed value by
/// [`Scaled::to_q30_wide`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Scaled {
    /// Significand, Q2.30 in [1, 2).
    pub mantissa: Q2_30,
    /// Binary exponent.
    pub exp2: i32,
}

impl Scaled {
    /// `e^ln` for a logarithm `ln` in a format with 24 to 31 fractional bits (Q8.24 and Q6.26
    /// in this crate; |ln| < 128). Never fails.
    ///
    /// Error: 1.5e-9 relative (the `exp` of the fractional part) plus the logarithm's own error.
    /// Cost: about 70 instructions (one `exp`, no division).
    pub fn from_ln<const F: u32>(ln: Q<F>) -> Self {
        const {
            assert!(
                F >= 24 && F <= 31,
                "from_ln takes Q8.24 to Q1.31 logarithms"
            )
        };
        let bits = ln.to_bits() as i64;
        let x40 = bits << (40 - F); // |x40| < 2^47
        // k = floor(ln / ln 2), estimated from a Q.24 copy (|x24 * LOG2E_Q30| < 2^62) and then
        // corrected so that the remainder lies in [0, ln 2).
        let x24 = bits >> (F - 24);
        let mut k = (x24 * LOG2E_Q30) >> 54;
        let mut rest = x40 - k * LN2_Q40;
        while rest < 0 {
            k -= 1;
            rest += LN2_Q40;
        }
        while rest >= LN2_Q40 {
            k += 1;
            rest -= LN2_Q40;
        }
        // rest < ln2 2^40, so the Q.31 copy is below 1.49e9 < 2^31.
        let rest_q31 = Q1_31::from_bits(((rest + 256) >> 9) as i32);
        match rest_q31.exp::<30>() {
            Ok(mantissa) => Self {
                mantissa,
                exp2: k as i32,
            },
            // e^rest rounded up to 2.0: renormalise.
            Err(_) => Self {
                mantissa: Q2_30::ONE,
                exp2: k as i32 + 1,
            },
        }
    }

    /// The value in Q.30 held in an `i64` (range up to 2^33), rounded to nearest; `None` when
    /// `exp2 > 31` (value >= 2^32). Cost: a few instructions.
    pub fn to_q30_wide(self) -> Option<i64> {
        let bits = self.mantissa.to_bits() as i64;
        if self.exp2 > 31 {
            None
        } else if self.exp2 >= 0 {
            Some(bits << self.exp2)
        } else if self.exp2 <= -33 {
            Some(0) // below half an ulp of Q.30
        } else {
            let shift = self.exp2.unsigned_abs();
            Some((bits + (1 << (shift - 1))) >> shift)
        }
    }

    /// The value as f64, exactly (tool level and telemetry only, never in the control step).
    pub fn to_f64(self) -> f64 {
        libm::scalbn(self.mantissa.to_f64(), self.exp2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fx::{Q6_26, Q8_24};

    #[test]
    fn from_ln_matches_exp_over_the_range() {
        let mut worst: f64 = 0.0;
        for i in 0..=200_000i64 {
            let ln = -120.0 + 240.0 * i as f64 / 200_000.0;
            let q = Q8_24::from_f64(ln).unwrap();
            let s = Scaled::from_ln(q);
            assert!(s.mantissa >= Q2_30::ONE && s.mantissa.to_bits() >= 1 << 30);
            let exact = q.to_f64().exp();
            worst = worst.max((s.to_f64() / exact - 1.0).abs());
        }
        assert!(worst < 2e-9, "relative error {worst:e}");
        let one = Scaled::from_ln(Q6_26::ZERO);
        assert_eq!((one.mantissa, one.exp2), (Q2_30::ONE, 0));
        let two = Scaled::from_ln(Q6_26::LN_2);
        assert!((two.to_f64() - 2.0).abs() < 4e-9);
        assert!(Scaled::from_ln(Q6_26::MIN).to_f64() > 0.0);
        assert!(Scaled::from_ln(Q6_26::MAX).to_f64().is_finite());
    }

    #[test]
    fn wide_q30_rounds_and_refuses_large_values() {
        let s = Scaled {
            mantissa: Q2_30::from_f64(1.5).unwrap(),
            exp2: 3,
        };
        assert_eq!(s.to_q30_wide(), Some(12 << 30));
        let small = Scaled { exp2: -40, ..s };
        assert_eq!(small.to_q30_wide(), Some(0));
        let half = Scaled { exp2: -2, ..s };
        assert_eq!(half.to_q30_wide(), Some(3 << 27));
        assert_eq!(Scaled { exp2: 32, ..s }.to_q30_wide(), None);
        assert_eq!(Scaled { exp2: 31, ..s }.to_q30_wide(), Some(3i64 << 60));
    }
}
