//! The fixed-point number type [`Q`]: an `i32` whose format (number of fractional bits) is part
//! of the type, its aliases, its constants and its formatting.

use core::fmt;

/// A signed 32-bit fixed-point number with `FRAC` fractional bits (`FRAC` in `0..=31`).
///
/// Format `Q(32-FRAC).FRAC`: the value is `bits * 2^-FRAC`. Range `[-2^(31-FRAC),
/// 2^(31-FRAC) - 2^-FRAC]`, resolution (one ulp) `2^-FRAC`. A `FRAC` above 31 is rejected at
/// compile time.
///
/// There are deliberately no operator impls (`+`, `*`): every operation says whether it is
/// checked (`Result`) or saturating (a [`Sat`](super::Sat) with a flag), and products and
/// quotients are rounded to nearest. Ordering and equality compare values.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[repr(transparent)]
pub struct Q<const FRAC: u32>(i32);

/// Q16.16: general values. Range [-32768, 32768), resolution 2^-16 = 1.53e-5.
pub type Q16_16 = Q<16>;
/// Q8.24: values up to 128 with 6.0e-8 resolution. Range [-128, 128).
pub type Q8_24 = Q<24>;
/// Q6.26: logarithms of wide-range quantities. Range [-32, 32), resolution 1.49e-8.
pub type Q6_26 = Q<26>;
/// Q5.27: logarithms. Range [-16, 16), resolution 7.45e-9.
pub type Q5_27 = Q<27>;
/// Q3.29: angles up to pi. Range [-4, 4), resolution 1.86e-9.
pub type Q3_29 = Q<29>;
/// Q2.30: ratios with an exact 1.0, radians up to pi/2. Range [-2, 2), resolution 9.31e-10.
pub type Q2_30 = Q<30>;
/// Q1.31: state in [-1, 1) (+1.0 is not representable). Resolution 2^-31 = 4.66e-10.
pub type Q1_31 = Q<31>;

impl<const FRAC: u32> Q<FRAC> {
    /// Evaluated by every constructor: a format with more than 31 fractional bits does not compile.
    pub(super) const FORMAT_OK: () = assert!(FRAC <= 31, "Q<FRAC> needs FRAC <= 31");

    /// Number of fractional bits.
    pub const FRAC_BITS: u32 = FRAC;
    /// Number of integer bits, sign included (`32 - FRAC`).
    pub const INT_BITS: u32 = 32 - FRAC;
    /// Zero.
    pub const ZERO: Self = Self::from_bits(0);
    /// The smallest value, `-2^(31-FRAC)`.
    pub const MIN: Self = Self::from_bits(i32::MIN);
    /// The largest value, `2^(31-FRAC) - 2^-FRAC`.
    pub const MAX: Self = Self::from_bits(i32::MAX);
    /// One unit in the last place, `2^-FRAC` (the resolution).
    pub const ULP: Self = Self::from_bits(1);
    /// Exactly 1.0. Using it with `FRAC == 31` (where 1.0 does not exist) is a compile error.
    pub const ONE: Self = Self::from_int_const(1);
    /// pi, exactly rounded (a compile error where it does not fit: `FRAC >= 30`).
    pub const PI: Self = Self::from_f64_const(core::f64::consts::PI);
    /// 2 pi, exactly rounded (compile error for `FRAC >= 29`).
    pub const TAU: Self = Self::from_f64_const(core::f64::consts::TAU);
    /// pi / 2, exactly rounded (compile error for `FRAC == 31`).
    pub const FRAC_PI_2: Self = Self::from_f64_const(core::f64::consts::FRAC_PI_2);
    /// 2 / pi (the Littmann gain, physics-notes §1), exactly rounded.
    pub const FRAC_2_PI: Self = Self::from_f64_const(core::f64::consts::FRAC_2_PI);
    /// ln 2, exactly rounded.
    pub const LN_2: Self = Self::from_f64_const(core::f64::consts::LN_2);
    /// ln 10, exactly rounded (compile error for `FRAC >= 30`).
    pub const LN_10: Self = Self::from_f64_const(core::f64::consts::LN_10);
    /// e, exactly rounded (compile error for `FRAC >= 30`).
    pub const E: Self = Self::from_f64_const(core::f64::consts::E);
    /// sqrt(2), exactly rounded (compile error for `FRAC == 31`).
    pub const SQRT_2: Self = Self::from_f64_const(core::f64::consts::SQRT_2);
    /// 1 / sqrt(2), exactly rounded.
    pub const FRAC_1_SQRT_2: Self = Self::from_f64_const(core::f64::consts::FRAC_1_SQRT_2);

    /// The number whose raw two's-complement bits are `bits` (value `bits * 2^-FRAC`).
    #[inline(always)]
    pub const fn from_bits(bits: i32) -> Self {
        let () = Self::FORMAT_OK;
        Self(bits)
    }

    /// The raw two's-complement bits (value `bits * 2^-FRAC`).
    #[inline(always)]
    pub const fn to_bits(self) -> i32 {
        self.0
    }

    /// True when the value is below zero.
    pub const fn is_negative(self) -> bool {
        self.0 < 0
    }

    /// True when the value is above zero.
    pub const fn is_positive(self) -> bool {
        self.0 > 0
    }
}

impl<const FRAC: u32> Default for Q<FRAC> {
    /// Zero.
    fn default() -> Self {
        Self::ZERO
    }
}

impl<const FRAC: u32> fmt::Debug for Q<FRAC> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "Q{}.{}({} = {:#010x})",
            32 - FRAC,
            FRAC,
            self.to_f64(),
            self.0
        )
    }
}

impl<const FRAC: u32> fmt::Display for Q<FRAC> {
    /// The exact decimal value (through f64, which holds every `Q` value exactly).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(&self.to_f64(), f)
    }
}

#[cfg(feature = "defmt")]
impl<const FRAC: u32> defmt::Format for Q<FRAC> {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(f, "Q{=u32}.{=u32}({=i32:#x})", 32 - FRAC, FRAC, self.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Exactly rounded reference for constants: `round(x * 2^frac)` from a decimal string of
    /// more than 40 significant digits, parsed by hand (independent of f64).
    fn digits_to_bits(int_part: u64, frac_digits: &str, frac: u32) -> i64 {
        // value * 2^frac = int_part * 2^frac + 0.d1d2d3... * 2^frac, evaluated with u128
        // long multiplication of the decimal fraction by 2^frac.
        let mut scaled: u128 = 0;
        let mut denom: u128 = 1;
        for c in frac_digits.chars().take(25) {
            scaled = scaled * 10 + c.to_digit(10).unwrap() as u128;
            denom *= 10;
        }
        let num = scaled << frac;
        let q = num / denom;
        let r = num % denom;
        let frac_bits = q + u128::from(2 * r >= denom);
        ((int_part as u128) << frac) as i64 + frac_bits as i64
    }

    const PI_DIGITS: &str = "141592653589793238462643383279502884";
    const LN2_DIGITS: &str = "693147180559945309417232121458176568";

    #[test]
    fn constants_are_exactly_rounded() {
        assert_eq!(
            Q16_16::PI.to_bits() as i64,
            digits_to_bits(3, PI_DIGITS, 16)
        );
        assert_eq!(Q3_29::PI.to_bits() as i64, digits_to_bits(3, PI_DIGITS, 29));
        assert_eq!(
            Q2_30::LN_2.to_bits() as i64,
            digits_to_bits(0, LN2_DIGITS, 30)
        );
        assert_eq!(
            Q1_31::LN_2.to_bits() as i64,
            digits_to_bits(0, LN2_DIGITS, 31)
        );
        // round(pi/2 * 2^30) = round(pi * 2^29)
        assert_eq!(
            Q2_30::FRAC_PI_2.to_bits() as i64,
            digits_to_bits(3, PI_DIGITS, 29)
        );
        assert_eq!(Q2_30::ONE.to_bits(), 1 << 30);
        assert_eq!(Q16_16::ONE.to_bits(), 1 << 16);
        for (c, x) in [
            (Q2_30::FRAC_2_PI, core::f64::consts::FRAC_2_PI),
            (Q2_30::SQRT_2, core::f64::consts::SQRT_2),
            (Q2_30::FRAC_1_SQRT_2, core::f64::consts::FRAC_1_SQRT_2),
        ] {
            assert!((c.to_f64() - x).abs() <= 0.5 * Q2_30::ULP.to_f64());
        }
        assert!((Q16_16::E.to_f64() - core::f64::consts::E).abs() <= 0.5 / 65536.0);
        assert!((Q16_16::TAU.to_f64() - core::f64::consts::TAU).abs() <= 0.5 / 65536.0);
        assert!((Q8_24::LN_10.to_f64() - core::f64::consts::LN_10).abs() <= 0.5 / 16777216.0);
    }

    /// The sign predicates are strict: zero is neither positive nor negative, one unit
    /// either side of it is (a `>=` or `<=` here makes zero count as a sign, so that a zero
    /// load or amplitude would pass the models' "positive" guards).
    #[test]
    fn zero_has_no_sign_and_one_unit_does() {
        assert!(!Q16_16::ZERO.is_positive());
        assert!(!Q16_16::ZERO.is_negative());
        assert!(Q16_16::from_bits(1).is_positive());
        assert!(!Q16_16::from_bits(1).is_negative());
        assert!(Q16_16::from_bits(-1).is_negative());
        assert!(!Q16_16::from_bits(-1).is_positive());
        assert!(Q2_30::MAX.is_positive() && Q2_30::MIN.is_negative());
    }

    #[test]
    fn formatting_shows_format_and_value() {
        let x = Q16_16::from_f64(-1.25).unwrap();
        assert_eq!(format!("{x}"), "-1.25");
        assert_eq!(format!("{x:?}"), "Q16.16(-1.25 = 0xfffec000)");
        assert_eq!(Q16_16::default(), Q16_16::ZERO);
    }
}
