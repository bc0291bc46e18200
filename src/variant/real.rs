//! Float arithmetic for the float forms of the variants: the number type ([`Real`]: `f32` or
//! `f64`) and the maths library ([`Maths`]: `micromath`'s approximations or `libm`).
//!
//! The models in [`super::float_inplane`] and [`super::float_cube`] are generic over both, so
//! one algorithm runs in every float form and the forms differ in arithmetic and library only.

use core::ops::{Add, Div, Mul, Neg, Sub};

/// A float type: `f32` or `f64`.
pub trait Real:
    Copy
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + core::fmt::Debug
{
    /// 0.
    const ZERO: Self;
    /// 1.
    const ONE: Self;
    /// pi.
    const PI: Self;
    /// 2 / pi.
    const FRAC_2_PI: Self;
    /// 1 / (2 pi).
    const FRAC_1_TAU: Self;
    /// `x` rounded to this type (scene constants and inputs).
    fn of(x: f64) -> Self;
    /// The value as `f64` (exact).
    fn to_f64(self) -> f64;
    /// Neither NaN nor infinite.
    fn is_finite(self) -> bool {
        self.to_f64().is_finite()
    }
    /// x > 0 (false for NaN).
    fn is_positive(self) -> bool {
        self > Self::ZERO
    }
    /// x >= 0 (false for NaN).
    fn is_non_negative(self) -> bool {
        self >= Self::ZERO
    }
    /// |x|.
    fn abs(self) -> Self {
        if self < Self::ZERO { -self } else { self }
    }
}

impl Real for f32 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const PI: Self = core::f32::consts::PI;
    const FRAC_2_PI: Self = core::f32::consts::FRAC_2_PI;
    const FRAC_1_TAU: Self = 1.0 / core::f32::consts::TAU;
    fn of(x: f64) -> Self {
        x as f32
    }
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
}

impl Real for f64 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    const PI: Self = core::f64::consts::PI;
    const FRAC_2_PI: Self = core::f64::consts::FRAC_2_PI;
    const FRAC_1_TAU: Self = 1.0 / core::f64::consts::TAU;
    fn of(x: f64) -> Self {
        x
    }
    fn to_f64(self) -> f64 {
        self
    }
}

/// The elementary functions a float form uses.
pub trait Maths<T: Real>: Copy + core::fmt::Debug {
    /// asin x, x in [-1, 1].
    fn asin(x: T) -> T;
    /// sqrt x, x >= 0.
    fn sqrt(x: T) -> T;
    /// e^x.
    fn exp(x: T) -> T;
    /// ln x, x > 0.
    fn ln(x: T) -> T;
    /// sin x.
    fn sin(x: T) -> T;
    /// cos x.
    fn cos(x: T) -> T;
}

/// `micromath` 2.1's approximations (`f32` only): asin through atan and a fast inverse square
/// root, exp by a 2^n split and a short series, ln by the exponent and a polynomial, sin/cos by
/// a parabola with one correction, sqrt by halving the bit pattern (up to 6 % off). Fast and
/// small, percent-level at worst (measured per model in the speed table).
#[derive(Debug, Clone, Copy)]
pub struct Micromath;

impl Maths<f32> for Micromath {
    fn asin(x: f32) -> f32 {
        micromath::F32(x).asin().0
    }
    fn sqrt(x: f32) -> f32 {
        micromath::F32(x).sqrt().0
    }
    fn exp(x: f32) -> f32 {
        micromath::F32(x).exp().0
    }
    fn ln(x: f32) -> f32 {
        micromath::F32(x).ln().0
    }
    fn sin(x: f32) -> f32 {
        micromath::F32(x).sin().0
    }
    fn cos(x: f32) -> f32 {
        micromath::F32(x).cos().0
    }
}

/// `libm` (a port of musl's maths library): accurate to about 1 ulp.
#[derive(Debug, Clone, Copy)]
pub struct Libm;

impl Maths<f32> for Libm {
    fn asin(x: f32) -> f32 {
        libm::asinf(x)
    }
    fn sqrt(x: f32) -> f32 {
        libm::sqrtf(x)
    }
    fn exp(x: f32) -> f32 {
        libm::expf(x)
    }
    fn ln(x: f32) -> f32 {
        libm::logf(x)
    }
    fn sin(x: f32) -> f32 {
        libm::sinf(x)
    }
    fn cos(x: f32) -> f32 {
        libm::cosf(x)
    }
}

impl Maths<f64> for Libm {
    fn asin(x: f64) -> f64 {
        libm::asin(x)
    }
    fn sqrt(x: f64) -> f64 {
        libm::sqrt(x)
    }
    fn exp(x: f64) -> f64 {
        libm::exp(x)
    }
    fn ln(x: f64) -> f64 {
        libm::log(x)
    }
    fn sin(x: f64) -> f64 {
        libm::sin(x)
    }
    fn cos(x: f64) -> f64 {
        libm::cos(x)
    }
}

/// phi(y) = (1 - e^-y) / y for y >= 0 (1 at y = 0), by its series below 2^-5 (where
/// 1 - e^-y cancels; 7 terms, truncation below 2e-14 relative) and directly above.
pub fn phi<T: Real, M: Maths<T>>(y: T) -> T {
    if y < T::of(0.031_25) {
        // sum over k of (-y)^k / (k + 1)!, k = 0..=6, by Horner.
        let mut sum = T::of(1.0 / 5040.0);
        for c in [1.0 / 720.0, 1.0 / 120.0, 1.0 / 24.0, 1.0 / 6.0, 0.5, 1.0] {
            sum = T::of(c) - y * sum;
        }
        sum
    } else {
        (T::ONE - M::exp(-y)) / y
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phi_matches_its_definition_on_both_sides_of_the_switch() {
        for y in [0.0, 1e-9, 1e-4, 0.01, 0.031, 0.032, 0.5, 3.0, 40.0] {
            let want = if y == 0.0 { 1.0 } else { -f64::exp_m1(-y) / y };
            let got = phi::<f64, Libm>(y);
            assert!((got - want).abs() <= 1e-14 * want, "y {y}: {got} vs {want}");
            let got32 = phi::<f32, Libm>(y as f32) as f64;
            assert!(
                (got32 - want).abs() <= 4e-7 * want,
                "y {y}: {got32} vs {want}"
            );
        }
    }

    #[test]
    fn backends_agree_with_std_to_their_accuracy() {
        for x in [-0.9f64, -0.5, 0.0, 0.3, 0.8] {
            assert!((Libm::asin(x) - x.asin()).abs() < 1e-15);
            assert!((f64::from(<Libm as Maths<f32>>::asin(x as f32)) - x.asin()).abs() < 1e-6);
            let approx = f64::from(Micromath::asin(x as f32));
            // micromath's asin (atan of x / sqrt(1 - x^2), both approximated) is off by 1.3e-2
            // at x = -0.5: wired right, and as coarse as measured in the speed table.
            assert!((approx - x.asin()).abs() < 3e-2, "asin {x}: {approx}");
        }
        for x in [-3.0f64, -0.1, 0.0, 1.0, 2.5] {
            assert!((Libm::exp(x) / x.exp() - 1.0).abs() < 1e-15);
            assert!((f64::from(Micromath::exp(x as f32)) / x.exp() - 1.0).abs() < 1e-2);
            assert!((f64::from(Micromath::cos(x as f32)) - x.cos()).abs() < 1e-2);
            assert!((f64::from(Micromath::sin(x as f32)) - x.sin()).abs() < 1e-2);
        }
        assert!((f64::from(Micromath::ln(3.0)) - 3f64.ln()).abs() < 1e-2);
        // micromath's sqrt is one integer add and shift of the bit pattern: up to 6 % off.
        let root = f64::from(Micromath::sqrt(2.0));
        assert!((root / 2f64.sqrt() - 1.0).abs() < 0.07, "{root}");
    }
}
