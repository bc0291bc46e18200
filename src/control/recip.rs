//! Reciprocal of a positive fixed-point value by Newton-Raphson, without a division.
//!
//! The friction coefficient `F_t / F_n` and the force-target ratio need a division by the
//! normal force, which changes every step, and by the natural friction coefficient. A 64-bit
//! division goes through the runtime library on the Cortex-M4 (about 200 instructions,
//! `fx::div`); this reciprocal takes three multiply steps per iteration and no branch: about
//! 30 instructions.
//!
//! Method: normalise `x = m 2^-e` with `m / 2^32` in [1/2, 1), seed `y0 = 48/17 - 32/17 m`
//! (the minimax line, relative error <= 1/17), then three Newton steps
//! `y <- y (2 - m y)`, each squaring the relative error: (1/17)^8 = 1.4e-10, below the
//! Q2.30 rounding of the mantissa. Measured error: <= 3 ulp of the Q2.30 mantissa (2.8e-9
//! relative), see the tests.

use crate::fx::{Q, Sat};

/// `48/17` in Q2.30 (as `u64`), the seed line's intercept.
const SEED_INTERCEPT: u64 = 3_031_741_621;
/// `32/17` in Q2.30, the seed line's slope.
const SEED_SLOPE: u64 = 2_021_161_080;
/// 2.0 in Q2.30.
const TWO_Q30: u64 = 2 << 30;

/// `1 / x` for a positive fixed-point `x`, kept as a mantissa and a binary exponent so that
/// no precision is lost whatever the size of `x`: `1 / x = mantissa * 2^(exponent - 62)`,
/// with `mantissa` in (2^30, 2^31] (a Q2.30 value in (1, 2]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Reciprocal {
    mantissa: u32,
    exponent: u32,
}

impl Reciprocal {
    /// The reciprocal of 1.0.
    pub const ONE: Self = Self {
        mantissa: 1 << 31,
        exponent: 31,
    };

    /// The reciprocal of `x`, or `None` unless `x > 0`. Relative error <= 3e-9.
    pub const fn of<const F: u32>(x: Q<F>) -> Option<Self> {
        let bits = x.to_bits();
        if bits <= 0 {
            return None;
        }
        let shift = (bits as u32).leading_zeros();
        let m = ((bits as u32) << shift) as u64; // [2^31, 2^32): x = m 2^-(F + shift)
        // m < 2^32 and y < 2^31 keep every product below 2^63.
        let mut y = SEED_INTERCEPT - ((SEED_SLOPE * m + (1 << 31)) >> 32);
        y = newton_step(y, m);
        y = newton_step(y, m);
        y = newton_step(y, m);
        // Newton approaches 1/m from below; rounding can add an ulp at m = 2^31 (y = 2).
        if y > 1 << 31 {
            y = 1 << 31;
        }
        Some(Self {
            mantissa: y as u32,
            exponent: F + shift,
        })
    }

    /// `value / x` in the format `OUT`, rounded to nearest, clamped to `OUT`'s range and
    /// flagged when clamped. One 32x32 multiply and a shift.
    pub const fn times<const A: u32, const OUT: u32>(self, value: Q<A>) -> Sat<Q<OUT>> {
        // value / x = v_bits 2^-A * mantissa 2^(exponent - 62); in OUT units shift right by s.
        let product = value.to_bits() as i64 * self.mantissa as i64; // |.| <= 2^62
        let s = 62 + A as i32 - OUT as i32 - self.exponent as i32;
        let bits = if s >= 63 {
            0 // |product| 2^-63 <= 1/2 rounds to 0 (ties toward +inf: -1/2 -> 0)
        } else if s > 0 {
            (product + (1 << (s - 1))) >> s
        } else {
            let left = (-s) as u32;
            if product == 0 {
                0
            } else if left >= 32 || product.unsigned_abs() > (i32::MAX as u64) >> left {
                if product < 0 { i64::MIN } else { i64::MAX }
            } else {
                product << left
            }
        };
        if bits > i32::MAX as i64 {
            Sat::clamped(Q::<OUT>::MAX)
        } else if bits < i32::MIN as i64 {
            Sat::clamped(Q::<OUT>::MIN)
        } else {
            Sat::exact(Q::<OUT>::from_bits(bits as i32))
        }
    }
}

/// One Newton step `y (2 - m y)` for `1 / (m 2^-32)`, `y` in Q2.30, rounded.
#[inline(always)]
const fn newton_step(y: u64, m: u64) -> u64 {
    let my = (m * y + (1 << 31)) >> 32; // m y in Q2.30, within 1/17 of 1.0 after the seed
    (y * (TWO_Q30 - my) + (1 << 29)) >> 30
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fx::{Q1_31, Q2_30, Q8_24, Q16_16};
    use proptest::prelude::*;

    /// A quotient that lands on the largest value of its format is in range, not clamped:
    /// 1 / (1 + 2^-30) into Q1.31 (from an integer 1: the product of the value and the
    /// mantissa, 2^31 - 1, is used unshifted) is 1 - 2^-31 = `Q1_31::MAX`, exact, and -1 over
    /// it is -(1 - 2^-31), exact; 2 / (1 + 2^-30) does not fit Q1.31 and is flagged.
    #[test]
    fn a_quotient_at_the_top_of_its_format_is_exact() {
        let x = Q2_30::from_bits((1 << 30) + 1);
        let r = Reciprocal::of(x).unwrap();
        let one = Q::<0>::from_bits(1);
        assert_eq!(r.times::<0, 31>(one), Sat::exact(Q1_31::MAX));
        assert_eq!(
            r.times::<0, 31>(Q::<0>::from_bits(-1)),
            Sat::exact(Q1_31::from_bits(-i32::MAX))
        );
        assert_eq!(
            r.times::<0, 31>(Q::<0>::from_bits(2)),
            Sat::clamped(Q1_31::MAX)
        );
        // The true quotient is 1 - 2^-30 + 2^-60: the result is within 1 ulp of Q1.31.
        let q = r.times::<0, 31>(one).value.to_f64();
        assert!((q - 1.0 / x.to_f64()).abs() <= 2f64.powi(-31));
    }

    fn relative_error<const F: u32>(x: Q<F>) -> f64 {
        let r = Reciprocal::of(x).unwrap();
        let approx = r.mantissa as f64 * 2f64.powi(r.exponent as i32 - 62);
        (approx * x.to_f64() - 1.0).abs()
    }

    #[test]
    fn mantissa_is_accurate_over_every_octave_position() {
        let mut worst: f64 = 0.0;
        for i in 0..200_000u32 {
            // Walk the normalised mantissa range [2^31, 2^32) and a few exponents.
            let m = (1u32 << 31) + i.wrapping_mul(10_737);
            for shift in [1u32, 7, 19, 30] {
                let bits = (m >> shift) as i32;
                if bits > 0 {
                    worst = worst.max(relative_error(Q16_16::from_bits(bits)));
                }
            }
        }
        assert!(worst < 3e-9, "reciprocal relative error {worst:e}");
        assert_eq!(Reciprocal::of(Q16_16::ZERO), None);
        assert_eq!(Reciprocal::of(Q2_30::ONE), Some(Reciprocal::ONE));
        assert_eq!(Reciprocal::of(Q16_16::ONE), Some(Reciprocal::ONE));
        assert_eq!(Reciprocal::of(Q16_16::from_bits(-5)), None);
    }

    #[test]
    fn quotients_round_and_saturate() {
        let four = Reciprocal::of(Q16_16::from_int(4).unwrap()).unwrap();
        let q: Sat<Q2_30> = four.times(Q16_16::from_int(3).unwrap());
        assert_eq!(q, Sat::exact(Q2_30::from_f64(0.75).unwrap()));
        // 12 N / 40 N = 0.3 in Q2.30, within an ulp.
        let forty = Reciprocal::of(Q16_16::from_int(40).unwrap()).unwrap();
        let mu: Sat<Q2_30> = forty.times(Q16_16::from_int(12).unwrap());
        assert!((mu.value.to_f64() - 0.3).abs() <= 2.0 * Q2_30::ULP.to_f64());
        // 1000 N / 1 ulp N does not fit Q2.30: clamped, either sign.
        let tiny = Reciprocal::of(Q16_16::ULP).unwrap();
        let big: Sat<Q2_30> = tiny.times(Q16_16::from_int(1000).unwrap());
        assert_eq!(big, Sat::clamped(Q2_30::MAX));
        let neg: Sat<Q2_30> = tiny.times(Q16_16::from_int(-1000).unwrap());
        assert_eq!(neg, Sat::clamped(Q2_30::MIN));
        // A huge divisor sends a Q1.31 value to zero without overflow.
        let huge = Reciprocal::of(Q16_16::MAX).unwrap();
        let zero: Sat<Q1_31> = huge.times(Q1_31::from_bits(1));
        assert_eq!(zero, Sat::exact(Q1_31::ZERO));
        let r: Sat<Q8_24> = Reciprocal::of(Q2_30::ONE).unwrap().times(Q8_24::MIN);
        assert_eq!(r, Sat::exact(Q8_24::MIN));
    }

    proptest! {
        #[test]
        fn quotient_matches_f64(num in any::<i32>(), den in 1..=i32::MAX) {
            let r = Reciprocal::of(Q16_16::from_bits(den)).unwrap();
            let got: Sat<Q2_30> = r.times(Q16_16::from_bits(num));
            let exact = num as f64 / den as f64;
            if exact.abs() < 1.9 {
                prop_assert!(!got.saturated);
                // 3e-9 relative on the mantissa plus half an ulp of rounding.
                let tol = exact.abs() * 3e-9 + 0.5 * Q2_30::ULP.to_f64() + 1e-12;
                prop_assert!((got.value.to_f64() - exact).abs() <= tol + Q2_30::ULP.to_f64());
            } else if exact.abs() > 2.1 {
                prop_assert!(got.saturated);
            }
        }
    }
}
