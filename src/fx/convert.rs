//! Conversions of [`Q`]: from and to integers, ratios, f64/f32 and other formats, and the
//! `const` constructors used for constants.
//!
//! Rounding is to nearest everywhere. From floats and ratios ties go away from zero (the
//! result is symmetric in the sign); between formats ties go toward +infinity, like the
//! products in `ops`. Float conversions are for set-up and telemetry, not for the hot path
//! (f64 is software-emulated on the Cortex-M4F).

use super::error::{FxError, Sat};
use super::q::Q;
use super::raw;

impl<const FRAC: u32> Q<FRAC> {
    /// `n` exactly, or `Overflow` when it is outside the integer range
    /// `[-2^(31-FRAC), 2^(31-FRAC))`.
    pub const fn from_int(n: i32) -> Result<Self, FxError> {
        let () = Self::FORMAT_OK;
        match raw::rescale(n as i64, -(FRAC as i32)) {
            Ok(bits) => Ok(Self::from_bits(bits)),
            Err(e) => Err(e),
        }
    }

    /// `n` clamped to the range, flagged when clamped.
    pub const fn from_int_saturating(n: i32) -> Sat<Self> {
        let () = Self::FORMAT_OK;
        let s = raw::rescale_saturating(n as i64, -(FRAC as i32));
        Sat {
            value: Self::from_bits(s.value),
            saturated: s.saturated,
        }
    }

    /// `num / den` rounded to nearest (ties away from zero). Errors: `DivisionByZero`,
    /// `Overflow`. Exact for every `i32` pair (no intermediate rounding).
    pub const fn from_ratio(num: i32, den: i32) -> Result<Self, FxError> {
        let () = Self::FORMAT_OK;
        match raw::div_round(num, den, FRAC as i32) {
            Ok(bits) => Ok(Self::from_bits(bits)),
            Err(e) => Err(e),
        }
    }

    /// Nearest value to the finite `x` (ties away from zero). Errors: `NotFinite` for NaN and
    /// infinities, `Overflow` when the rounded value is outside the range. Not for the hot path
    /// (f64 is software-emulated on Cortex-M4F).
    pub const fn from_f64(x: f64) -> Result<Self, FxError> {
        let () = Self::FORMAT_OK;
        if !x.is_finite() {
            return Err(FxError::NotFinite);
        }
        // Scaling by a power of two is exact; |scaled| < 2^32 makes `+ 0.5` exact too.
        let scaled = x * (1u64 << FRAC) as f64;
        let magnitude = scaled.abs();
        if x.is_sign_negative() {
            if magnitude >= 2147483648.5 {
                return Err(FxError::Overflow);
            }
        } else if magnitude >= 2147483647.5 {
            return Err(FxError::Overflow);
        }
        let rounded = (magnitude + 0.5) as i64; // truncation of a non-negative value = floor
        let bits = if x.is_sign_negative() {
            -rounded
        } else {
            rounded
        };
        Ok(Self::from_bits(bits as i32))
    }

    /// Like [`Self::from_f64`] but clamps out-of-range values to `MIN`/`MAX`; NaN gives zero.
    /// `saturated` is true for NaN, infinities and clamped values.
    pub const fn from_f64_saturating(x: f64) -> Sat<Self> {
        match Self::from_f64(x) {
            Ok(v) => Sat::exact(v),
            Err(_) => {
                if x.is_nan() {
                    Sat::clamped(Self::ZERO)
                } else if x < 0.0 {
                    Sat::clamped(Self::MIN)
                } else {
                    Sat::clamped(Self::MAX)
                }
            }
        }
    }

    /// Nearest value to the finite `x`; see [`Self::from_f64`] (f32 converts to f64 exactly).
    pub const fn from_f32(x: f32) -> Result<Self, FxError> {
        Self::from_f64(x as f64)
    }

    /// Like [`Self::from_f32`] but clamped and flagged; see [`Self::from_f64_saturating`].
    pub const fn from_f32_saturating(x: f32) -> Sat<Self> {
        Self::from_f64_saturating(x as f64)
    }

    /// The exact value as f64 (every `Q` value is exactly representable).
    pub const fn to_f64(self) -> f64 {
        self.to_bits() as f64 / (1u64 << FRAC) as f64
    }

    /// The value as f32, rounded once to nearest (the f64 intermediate is exact).
    pub const fn to_f32(self) -> f32 {
        self.to_f64() as f32
    }

    /// For `const` items: `x` exactly rounded. Panics when `x` does not fit, which in a `const`
    /// item is a compile error. At run time use [`Self::from_f64`].
    pub const fn from_f64_const(x: f64) -> Self {
        match Self::from_f64(x) {
            Ok(v) => v,
            Err(_) => panic!("constant does not fit the fixed-point format"),
        }
    }

    /// For `const` items: `num / den` rounded to nearest. Panics (a compile error in a `const`
    /// item) when it does not fit. At run time use [`Self::from_ratio`].
    pub const fn from_ratio_const(num: i32, den: i32) -> Self {
        Self::expect_const(Self::from_ratio(num, den))
    }

    /// For `const` items: the integer `n`. Panics (a compile error in a `const` item) when it
    /// does not fit. At run time use [`Self::from_int`].
    pub const fn from_int_const(n: i32) -> Self {
        Self::expect_const(Self::from_int(n))
    }

    /// For `const` items: unwraps a result computed at compile time, e.g.
    /// `const LN_1000: Q6_26 = Q6_26::expect_const(ln_scaled(1000, 0));`. Panics on `Err`,
    /// which in a `const` item is a compile error. Never call it at run time.
    pub const fn expect_const(result: Result<Self, FxError>) -> Self {
        match result {
            Ok(v) => v,
            Err(_) => panic!("fixed-point constant could not be computed"),
        }
    }

    /// The same value in the format `TO`, rounded to nearest (ties toward +infinity) when `TO`
    /// has fewer fractional bits; `Overflow` when it does not fit `TO`'s range.
    pub const fn convert<const TO: u32>(self) -> Result<Q<TO>, FxError> {
        match raw::rescale(self.to_bits() as i64, FRAC as i32 - TO as i32) {
            Ok(bits) => Ok(Q::<TO>::from_bits(bits)),
            Err(e) => Err(e),
        }
    }

    /// Like [`Self::convert`] but clamped to `TO`'s range and flagged.
    pub const fn convert_saturating<const TO: u32>(self) -> Sat<Q<TO>> {
        let s = raw::rescale_saturating(self.to_bits() as i64, FRAC as i32 - TO as i32);
        Sat {
            value: Q::<TO>::from_bits(s.value),
            saturated: s.saturated,
        }
    }

    /// The largest integer <= the value.
    pub const fn floor_int(self) -> i32 {
        self.to_bits() >> FRAC
    }

    /// The nearest integer (ties toward +infinity). Never overflows (the result has at most
    /// `32 - FRAC` significant bits).
    pub const fn round_int(self) -> i32 {
        if FRAC == 0 {
            self.to_bits()
        } else {
            raw::shr_round_i64(self.to_bits() as i64, FRAC) as i32
        }
    }

    /// The value times `unit`, rounded to the nearest integer (ties toward +infinity): a
    /// quantity in a finer integer unit, for example newtons to mN with `unit` 1000. Exact
    /// and never overflows (`|bits x unit| < 2^63`).
    pub const fn round_scaled(self, unit: u32) -> i64 {
        let product = self.to_bits() as i64 * unit as i64;
        if FRAC == 0 {
            product
        } else {
            raw::shr_round_i64(product, FRAC)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::q::{Q1_31, Q2_30, Q16_16};

    #[test]
    fn round_scaled_is_exact_at_the_extremes() {
        assert_eq!(Q16_16::from_bits(i32::MAX).round_scaled(1_000), 32_768_000);
        assert_eq!(Q16_16::from_bits(i32::MIN).round_scaled(1_000), -32_768_000);
        assert_eq!(
            Q1_31::from_bits(i32::MAX).round_scaled(1_000_000),
            1_000_000
        );
        assert_eq!(Q2_30::from_bits(1).round_scaled(u32::MAX), 4);
        // 0.0005 N is half a mN: ties go up; -0.0005 N goes to 0.
        let half_mn = Q16_16::from_f64(0.000_5).unwrap().to_bits();
        let exact = |bits: i32| (f64::from(bits) * 1000.0 / 65536.0 + 0.5).floor() as i64;
        for bits in [half_mn, -half_mn, 1, -1, 12_345_678, -12_345_678] {
            assert_eq!(
                Q16_16::from_bits(bits).round_scaled(1_000),
                exact(bits),
                "{bits}"
            );
        }
    }
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn f64_round_trip_and_rounding() {
        assert_eq!(Q16_16::from_f64(1.5), Ok(Q16_16::from_bits(3 << 15)));
        assert_eq!(Q16_16::from_f64(-1.5), Ok(Q16_16::from_bits(-(3 << 15))));
        // Ties go away from zero.
        assert_eq!(Q16_16::from_f64(0.5 / 65536.0), Ok(Q16_16::ULP));
        assert_eq!(Q16_16::from_f64(-0.5 / 65536.0), Ok(Q16_16::from_bits(-1)));
        assert_eq!(Q16_16::from_f64(0.49 / 65536.0), Ok(Q16_16::ZERO));
        // Extremes.
        assert_eq!(Q16_16::from_f64(-32768.0), Ok(Q16_16::MIN));
        assert_eq!(Q16_16::from_f64(-32768.0 - 0.49 / 65536.0), Ok(Q16_16::MIN));
        assert_eq!(
            Q16_16::from_f64(-32768.0 - 0.5 / 65536.0),
            Err(FxError::Overflow)
        );
        assert_eq!(Q16_16::from_f64(Q16_16::MAX.to_f64()), Ok(Q16_16::MAX));
        assert_eq!(Q16_16::from_f64(32768.0 - 0.51 / 65536.0), Ok(Q16_16::MAX));
        assert_eq!(
            Q16_16::from_f64(32768.0 - 0.5 / 65536.0),
            Err(FxError::Overflow)
        );
        assert_eq!(Q1_31::from_f64(1.0), Err(FxError::Overflow));
        assert_eq!(Q1_31::from_f64(-1.0), Ok(Q1_31::MIN));
        assert_eq!(Q16_16::from_f64(f64::NAN), Err(FxError::NotFinite));
        assert_eq!(Q16_16::from_f64(f64::INFINITY), Err(FxError::NotFinite));
        assert_eq!(Q16_16::from_f64(1e300), Err(FxError::Overflow));
        assert_eq!(Q16_16::from_f64(-0.0), Ok(Q16_16::ZERO));
        assert_eq!(Q::<0>::from_f64(2147483647.0), Ok(Q::<0>::MAX));
        let s = Q16_16::from_f64_saturating(1e9);
        assert_eq!((s.value, s.saturated), (Q16_16::MAX, true));
        let s = Q16_16::from_f64_saturating(f64::NEG_INFINITY);
        assert_eq!((s.value, s.saturated), (Q16_16::MIN, true));
        let s = Q16_16::from_f64_saturating(f64::NAN);
        assert_eq!((s.value, s.saturated), (Q16_16::ZERO, true));
        let s = Q16_16::from_f64_saturating(2.25);
        assert_eq!((s.value.to_f64(), s.saturated), (2.25, false));
        assert_eq!(Q2_30::from_f32(0.25).map(Q::to_f32), Ok(0.25));
        assert!(Q2_30::from_f32_saturating(f32::NAN).saturated);
    }

    #[test]
    fn ratios_and_integers() {
        assert_eq!(Q16_16::from_ratio(1, 3), Ok(Q16_16::from_bits(21845)));
        assert_eq!(Q16_16::from_ratio(2, 3), Ok(Q16_16::from_bits(43691)));
        assert_eq!(Q16_16::from_ratio(-2, 3), Ok(Q16_16::from_bits(-43691)));
        assert_eq!(Q16_16::from_ratio(1, 0), Err(FxError::DivisionByZero));
        assert_eq!(Q1_31::from_ratio(1, 1), Err(FxError::Overflow));
        assert_eq!(Q1_31::from_ratio(-1, 1), Ok(Q1_31::MIN));
        assert_eq!(
            Q1_31::from_ratio(i32::MIN, i32::MIN),
            Err(FxError::Overflow)
        );
        const THIRD: Q2_30 = Q2_30::from_ratio_const(1, 3);
        assert_eq!(THIRD.to_bits(), 357913941);
        assert_eq!(Q16_16::from_int(-32768), Ok(Q16_16::MIN));
        assert_eq!(Q16_16::from_int(32768), Err(FxError::Overflow));
        let s = Q16_16::from_int_saturating(40000);
        assert_eq!((s.value, s.saturated), (Q16_16::MAX, true));
        assert_eq!(Q16_16::from_int_const(7).round_int(), 7);
        assert_eq!(Q16_16::from_f64(-2.5).unwrap().round_int(), -2);
        assert_eq!(Q16_16::from_f64(-2.5).unwrap().floor_int(), -3);
        assert_eq!(Q16_16::MAX.round_int(), 32768);
        assert_eq!(Q1_31::MIN.round_int(), -1);
        assert_eq!(Q::<0>::MAX.round_int(), i32::MAX);
    }

    #[test]
    fn format_conversions_round_and_check() {
        let x = Q2_30::from_bits(0x1234_5678);
        assert_eq!(x.convert::<16>(), Ok(Q16_16::from_bits(0x48d1)));
        assert_eq!(x.convert::<31>(), Ok(Q1_31::from_bits(0x2468_acf0)));
        let big = Q2_30::from_bits(0x5234_5678);
        assert_eq!(big.convert::<31>(), Err(FxError::Overflow));
        let small = Q2_30::from_bits(-(1 << 29));
        assert_eq!(small.convert::<31>(), Ok(Q1_31::from_bits(-(1 << 30))));
        let s = big.convert_saturating::<31>();
        assert_eq!((s.value, s.saturated), (Q1_31::MAX, true));
        // Half-ulp ties go toward +infinity.
        assert_eq!(
            Q2_30::from_bits(1 << 13).convert::<16>().unwrap().to_bits(),
            1
        );
        assert_eq!(
            Q2_30::from_bits(-(1 << 13))
                .convert::<16>()
                .unwrap()
                .to_bits(),
            0
        );
        assert_eq!(Q16_16::MIN.convert::<0>().unwrap().to_bits(), -32768);
        assert_eq!(Q1_31::MAX.convert::<0>().unwrap().to_bits(), 1);
    }

    proptest! {
        #[test]
        fn to_f64_from_f64_round_trips(bits in any::<i32>()) {
            let (a, b) = (Q16_16::from_bits(bits), Q1_31::from_bits(bits));
            prop_assert_eq!(Q16_16::from_f64(a.to_f64()), Ok(a));
            prop_assert_eq!(Q1_31::from_f64(b.to_f64()), Ok(b));
        }

        #[test]
        fn from_f64_never_panics_and_is_nearest(x in any::<f64>()) {
            match Q2_30::from_f64(x) {
                Ok(q) => prop_assert!((q.to_f64() - x).abs() <= 0.5 * Q2_30::ULP.to_f64()),
                Err(_) => {
                    prop_assert!(!x.is_finite() || x.abs() >= 2.0 - 0.5 * Q2_30::ULP.to_f64())
                }
            }
            let _ = Q::<0>::from_f64_saturating(x);
            let _ = Q1_31::from_f32_saturating(x as f32);
        }

        #[test]
        fn ratio_and_convert_never_panic(a in any::<i32>(), b in any::<i32>()) {
            let _ = Q1_31::from_ratio(a, b);
            let _ = Q::<0>::from_ratio(a, b);
            let _ = Q16_16::from_int(a);
            let _ = Q16_16::from_bits(a).convert::<0>();
            let _ = Q16_16::from_bits(a).convert::<31>();
            let _ = Q::<0>::from_bits(a).convert_saturating::<31>();
            let _ = Q16_16::from_bits(a).round_int();
            if let (true, Ok(q)) = (b != 0, Q16_16::from_ratio(a, b)) {
                let exact = a as f64 / b as f64;
                let tol = 0.5 / 65536.0 + 1e-12 * exact.abs();
                prop_assert!((q.to_f64() - exact).abs() <= tol);
            }
        }
    }
}
