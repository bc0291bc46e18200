//! Drive amplitude as a fraction of full scale, and the duty cycle that produces it.
//!
//! The half-bridge output is a rectangular wave between 0 and `V_bus` with duty `D`. Its
//! fundamental has the amplitude `(2 V_bus / pi) sin(pi D)` (Fourier series of a rectangular
//! pulse train), largest at `D = 1/2`. Driving with `D = asin(a) / pi` therefore makes the
//! fundamental `a * 2 V_bus / pi`: linear in the amplitude `a`, which keeps the plant gain the
//! controller sees constant. Only `D` in [0, 1/2] is used: the high-side pulse is the short one,
//! so the ADC can sample in the long low-side phase (see [`crate::drive::DriveTiming`]).

use super::error::DriveError;
use crate::fx::Q2_30;

/// 1/pi in Q2.30, exactly rounded.
const FRAC_1_PI: Q2_30 = Q2_30::from_f64_const(core::f64::consts::FRAC_1_PI);

/// Drive amplitude: the fraction of full-scale fundamental voltage, Q2.30 in [0, 1].
///
/// Full scale is the fundamental of a 50 % square wave, `2 V_bus / pi`
/// ([`crate::drive::DriveLimits`] relates it to volts on the stack).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Amplitude(Q2_30);

impl Amplitude {
    /// No drive (duty 0: the low-side switch stays on).
    pub const ZERO: Self = Self(Q2_30::ZERO);
    /// Full scale (duty 1/2).
    pub const FULL: Self = Self(Q2_30::ONE);

    /// The amplitude `fraction` of full scale. Error `AmplitudeOutOfRange` outside [0, 1].
    pub const fn new(fraction: Q2_30) -> Result<Self, DriveError> {
        let bits = fraction.to_bits();
        if bits < 0 || bits > 1 << 30 {
            return Err(DriveError::AmplitudeOutOfRange);
        }
        Ok(Self(fraction))
    }

    /// The amplitude `numerator / denominator` of full scale, rounded to nearest. Error
    /// `AmplitudeOutOfRange` for a zero denominator or a ratio outside [0, 1].
    pub const fn from_ratio(numerator: u32, denominator: u32) -> Result<Self, DriveError> {
        if denominator == 0 || numerator > denominator {
            return Err(DriveError::AmplitudeOutOfRange);
        }
        // numerator <= denominator < 2^32: numerator << 30 < 2^62.
        let bits = (((numerator as u64) << 30) + denominator as u64 / 2) / denominator as u64;
        Ok(Self(Q2_30::from_bits(bits as i32)))
    }

    /// The amplitude as a Q2.30 fraction in [0, 1].
    pub const fn fraction(self) -> Q2_30 {
        self.0
    }

    /// The raw Q2.30 bits, 0 to `1 << 30`.
    pub const fn bits(self) -> u32 {
        self.0.to_bits() as u32
    }

    /// The smaller of two amplitudes.
    pub const fn min(self, other: Self) -> Self {
        if self.0.to_bits() <= other.0.to_bits() {
            self
        } else {
            other
        }
    }

    /// The duty cycle `asin(a) / pi` (Q2.30, 0 to 1/2) whose fundamental is this amplitude.
    /// Cost: one fixed-point arcsine (25 to 60 instructions, `fx::Q2_30::asin`) and one
    /// multiplication.
    pub const fn duty(self) -> Q2_30 {
        // The amplitude is in [0, 1], the domain of asin, and asin(a)/pi <= 1/2 fits Q2.30,
        // so neither error arm can be taken; both fall back to no drive.
        match self.0.asin() {
            Ok(angle) => match angle.checked_mul(FRAC_1_PI) {
                Ok(duty) => duty,
                Err(_) => Q2_30::ZERO,
            },
            Err(_) => Q2_30::ZERO,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn range_is_enforced() {
        assert_eq!(Amplitude::new(Q2_30::ONE), Ok(Amplitude::FULL));
        assert_eq!(Amplitude::new(Q2_30::ZERO), Ok(Amplitude::ZERO));
        assert_eq!(
            Amplitude::new(Q2_30::from_bits((1 << 30) + 1)),
            Err(DriveError::AmplitudeOutOfRange)
        );
        assert_eq!(
            Amplitude::new(Q2_30::from_bits(-1)),
            Err(DriveError::AmplitudeOutOfRange)
        );
        assert_eq!(Amplitude::from_ratio(1, 4).unwrap().bits(), 1 << 28);
        assert_eq!(
            Amplitude::from_ratio(u32::MAX, u32::MAX),
            Ok(Amplitude::FULL)
        );
        assert_eq!(
            Amplitude::from_ratio(2, 1),
            Err(DriveError::AmplitudeOutOfRange)
        );
        assert_eq!(
            Amplitude::from_ratio(0, 0),
            Err(DriveError::AmplitudeOutOfRange)
        );
    }

    #[test]
    fn the_fundamental_of_the_duty_is_linear_in_the_amplitude() {
        // sin(pi D) must give back a: the fundamental is a * 2 V_bus / pi.
        for step in 0..=4096u32 {
            let amplitude = Amplitude::from_ratio(step, 4096).unwrap();
            let duty = amplitude.duty().to_f64();
            assert!((0.0..=0.5).contains(&duty), "duty {duty}");
            let fundamental = (core::f64::consts::PI * duty).sin();
            let wanted = f64::from(step) / 4096.0;
            assert!(
                (fundamental - wanted).abs() < 1e-8,
                "a = {wanted}: sin(pi D) = {fundamental}"
            );
        }
        assert_eq!(Amplitude::ZERO.duty(), Q2_30::ZERO);
        assert_eq!(Amplitude::FULL.duty().to_bits(), 1 << 29);
    }

    #[test]
    fn min_picks_the_smaller() {
        let half = Amplitude::from_ratio(1, 2).unwrap();
        assert_eq!(half.min(Amplitude::FULL), half);
        assert_eq!(Amplitude::FULL.min(half), half);
    }
}
