//! Drive amplitude as a fraction of full scale, and the duty cycle that produces it.
//!
//! The half-bridge output is a rectangular wave between 0 and `V_bus` with duty `D`. Its
//! fundamental has the amplitude `(2 V_bus / pi) sin(pi D)` (Fourier series of a rectangular
//! pulse train), largest at `D = 1/2`. Driving with `D = asin(a) / pi` therefore makes the
//! fundamental `a * 2 V_bus / pi`: linear in the amplitude `a`, which keeps the plant gain the
//! controller sees constant. Only `D` in [0, 1/2] is used: the high-side pulse is the short one,
//! so the ADC can sample in the long low-side phase (see [`crate::drive::DriveTiming`]).

use super::error::DriveError;
use crate::fx::{Q1_31, Q2_30};

/// 1/pi in Q2.30, exactly rounded.
const FRAC_1_PI: Q2_30 = Q2_30::from_f64_const(core::f64::consts::FRAC_1_PI);

/// Drive amplitude: the fraction of full-scale fundamental voltage, Q2.30 in [0, 1].
///
/// This is the drive's encoding. The controller computes its command in Q1.31 in [0, 1)
/// (`crate::control::Output::amplitude`: one more bit of resolution, and 1 itself is not
/// needed, the limits keep the command below full scale); [`Amplitude::from_command`] and
/// [`Amplitude::command`] are the only conversions between the two, so the rounding and the
/// edges are stated once: Q1.31 to Q2.30 drops the last bit (truncation, at most 2^-31 of full
/// scale low), Q2.30 to Q1.31 is exact below 1, and 1 becomes the largest Q1.31.
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

    /// The drive amplitude of a controller command (Q1.31 fraction of full scale in [-1, 1)):
    /// the command with its last bit dropped; a negative command is no drive. Total: every
    /// Q1.31 value maps into [0, 1 - 2^-30].
    pub const fn from_command(command: Q1_31) -> Self {
        let bits = command.to_bits();
        // [0, 2^31 - 1] >> 1 = [0, 2^30 - 1]: inside [0, 1].
        Self(Q2_30::from_bits(if bits < 0 { 0 } else { bits >> 1 }))
    }

    /// This amplitude as a controller command, Q1.31 in [0, 1): exact below full scale; full
    /// scale (1, which Q1.31 cannot hold) is its largest value, 1 - 2^-31.
    pub const fn command(self) -> Q1_31 {
        // bits in [0, 2^30]: << 1 is at most 2^31, one past i32::MAX at full scale only.
        let doubled = (self.0.to_bits() as i64) << 1;
        Q1_31::from_bits(if doubled > i32::MAX as i64 {
            i32::MAX
        } else {
            doubled as i32
        })
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
    fn a_controller_command_converts_at_its_extremes() {
        // Zero, the smallest positive step, the largest command, and every negative one.
        assert_eq!(Amplitude::from_command(Q1_31::ZERO), Amplitude::ZERO);
        assert_eq!(Amplitude::from_command(Q1_31::from_bits(1)).bits(), 0); // below one Q2.30 lsb
        assert_eq!(Amplitude::from_command(Q1_31::from_bits(2)).bits(), 1);
        assert_eq!(Amplitude::from_command(Q1_31::MAX).bits(), (1 << 30) - 1);
        assert_eq!(
            Amplitude::from_command(Q1_31::from_bits(-1)),
            Amplitude::ZERO
        );
        assert_eq!(Amplitude::from_command(Q1_31::MIN), Amplitude::ZERO);
        // Against the f64 value: truncation, never more than one Q2.30 lsb low, never high.
        for bits in [1, 3, 12_345, 1 << 20, (1 << 30) + 7, i32::MAX - 1, i32::MAX] {
            let command = Q1_31::from_bits(bits).to_f64();
            let amplitude = Amplitude::from_command(Q1_31::from_bits(bits))
                .fraction()
                .to_f64();
            assert!(amplitude <= command && command - amplitude < 1.0 / f64::from(1 << 30));
        }
    }

    #[test]
    fn an_amplitude_converts_to_a_command_exactly_below_full_scale() {
        assert_eq!(Amplitude::ZERO.command(), Q1_31::ZERO);
        assert_eq!(Amplitude::FULL.command(), Q1_31::MAX);
        let below_full = Amplitude::new(Q2_30::from_bits((1 << 30) - 1)).unwrap();
        assert_eq!(below_full.command().to_bits(), i32::MAX - 1);
        for (numerator, denominator) in [(1, 1000), (1, 4), (707, 1000), (999_999, 1_000_000)] {
            let a = Amplitude::from_ratio(numerator, denominator).unwrap();
            assert_eq!(a.command().to_f64(), a.fraction().to_f64());
            // The round trip returns the amplitude: no bit is lost below full scale.
            assert_eq!(Amplitude::from_command(a.command()), a);
        }
    }

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
