//! Division of [`Q`] values, rounded to nearest from the exact quotient.
//!
//! Division is not a hot-path operation on the Cortex-M4: the 64-bit quotient goes through the
//! runtime library (`__aeabi_uldivmod`, about 200 instructions with call overhead, measured under
//! QEMU). In the 10 kHz loop, multiply by a reciprocal computed when the parameter changes.

use super::error::FxError;
use super::q::Q;
use super::raw;

impl<const FRAC: u32> Q<FRAC> {
    /// `self / rhs` in the same format, rounded to nearest (ties away from zero, error <= 0.5
    /// ulp). Errors: `DivisionByZero`, `Overflow`. Cost: a 64-bit library division (about
    /// 200 instructions on Cortex-M4); multiply by a precomputed reciprocal in the inner loop.
    pub const fn checked_div(self, rhs: Self) -> Result<Self, FxError> {
        self.checked_div_to::<FRAC, FRAC>(rhs)
    }

    /// `self / rhs` with the result in the caller's format `OUT`, rounded to nearest from the
    /// exact quotient (error <= 0.5 ulp of `OUT`). Errors: `DivisionByZero`, `Overflow`.
    /// Example: `v_sliding.checked_div_to::<30, _>(v_amplitude)` gives the velocity ratio
    /// zeta in Q2.30 from two Q16.16 speeds.
    pub const fn checked_div_to<const OUT: u32, const R: u32>(
        self,
        rhs: Q<R>,
    ) -> Result<Q<OUT>, FxError> {
        wrap_div(raw::div_round(
            self.to_bits(),
            rhs.to_bits(),
            OUT as i32 - FRAC as i32 + R as i32,
        ))
    }

    /// `self / n` for an integer `n`, rounded to nearest (ties away from zero). Errors:
    /// `DivisionByZero`, `Overflow` (only `MIN / -1`). Uses `SDIV`-class library code.
    pub const fn checked_div_int(self, n: i32) -> Result<Self, FxError> {
        wrap_div(raw::div_round(self.to_bits(), n, 0))
    }
}

/// Wraps raw bits from the division kernel into a `Q` (const-compatible `map`).
const fn wrap_div<const F: u32>(r: Result<i32, FxError>) -> Result<Q<F>, FxError> {
    match r {
        Ok(bits) => Ok(Q::<F>::from_bits(bits)),
        Err(e) => Err(e),
    }
}

#[cfg(test)]
mod tests {
    use super::super::q::{Q1_31, Q2_30, Q16_16};
    use super::*;
    use proptest::prelude::*;

    fn q16(x: f64) -> Q16_16 {
        Q16_16::from_f64(x).unwrap()
    }

    #[test]
    fn division_rounds_and_reports() {
        assert_eq!(q16(1.0).checked_div(q16(3.0)), Ok(Q16_16::from_bits(21845)));
        assert_eq!(
            q16(-2.0).checked_div(q16(3.0)),
            Ok(Q16_16::from_bits(-43691))
        );
        assert_eq!(
            q16(1.0).checked_div(Q16_16::ZERO),
            Err(FxError::DivisionByZero)
        );
        assert_eq!(q16(30000.0).checked_div(q16(0.5)), Err(FxError::Overflow));
        let zeta: Q2_30 = q16(0.038).checked_div_to(q16(0.0683)).unwrap();
        assert!(
            (zeta.to_f64() - q16(0.038).to_f64() / q16(0.0683).to_f64()).abs()
                <= 0.5 / (1u64 << 30) as f64
        );
        assert_eq!(q16(1.0).checked_div_to::<30, 16>(q16(1.0)), Ok(Q2_30::ONE));
        assert_eq!(
            q16(2.0).checked_div_to::<30, 16>(q16(1.0)),
            Err(FxError::Overflow)
        );
        assert_eq!(q16(-2.0).checked_div_to::<30, 16>(q16(1.0)), Ok(Q2_30::MIN));
        assert_eq!(q16(7.0).checked_div_int(2), Ok(q16(3.5)));
        assert_eq!(
            Q16_16::from_bits(-3).checked_div_int(2),
            Ok(Q16_16::from_bits(-2))
        );
        assert_eq!(Q16_16::MIN.checked_div_int(-1), Err(FxError::Overflow));
    }

    proptest! {
        #[test]
        fn division_never_panics_and_is_nearest(a in any::<i32>(), b in any::<i32>()) {
            let (x, y) = (Q16_16::from_bits(a), Q16_16::from_bits(b));
            match x.checked_div(y) {
                Ok(q) => {
                    let exact = x.to_f64() / y.to_f64();
                    prop_assert!((q.to_f64() - exact).abs() <= 0.5 / 65536.0 * (1.0 + 1e-9));
                }
                Err(e) => prop_assert!(b == 0 || e == FxError::Overflow),
            }
            let _ = Q1_31::from_bits(a).checked_div_to::<31, 0>(Q::<0>::from_bits(b));
            let _ = Q::<0>::from_bits(a).checked_div_to::<31, 31>(Q1_31::from_bits(b));
            let _ = Q::<0>::from_bits(a).checked_div_to::<0, 31>(Q1_31::from_bits(b));
            let _ = Q1_31::from_bits(a).checked_div_to::<0, 0>(Q::<0>::from_bits(b));
            let _ = x.checked_div_int(b);
        }

        #[test]
        fn general_division_matches_f64(a in any::<i32>(), b in any::<i32>()) {
            prop_assume!(b != 0);
            let x = Q::<0>::from_bits(a);
            let y = Q1_31::from_bits(b);
            // Q32.0 / Q1.31 -> Q16.16 uses the two-step long division (shift 47).
            let exact = x.to_f64() / y.to_f64();
            match x.checked_div_to::<16, 31>(y) {
                Ok(q) => prop_assert!((q.to_f64() - exact).abs() <= (0.5 + 1e-6) / 65536.0),
                Err(e) => {
                    prop_assert_eq!(e, FxError::Overflow);
                    prop_assert!(exact.abs() >= 32767.99)
                }
            }
        }
    }
}
