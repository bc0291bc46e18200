//! Drive amplitude as a fraction of full scale, and the duty cycle that produces it.
//!
//! The half-bridge output is a rectangular wave between 0 and `V_bus` with duty `D`. Its
//! fundamental has the amplitude `(2 V_bus / pi) sin(pi D)` (Fourier series of a rectangular
//! pulse train), largest at `D = 1/2`. Driving with `D = asin(a) / pi` therefore makes the
//! fundamental `a * 2 V_bus / pi`: linear in the amplitude `a`, which keeps the plant gain the
//! controller sees constant. Only `D` in [0, 1/2] is used: the high-side pulse is the short one,
//! so the ADC can sample in the long low-side phase (see [`crate::drive::DriveTiming`]).

use super::error::DriveError;
use crate::fx::{Q1_31, Q2_30, Sat};

/// 1/pi in Q2.30, exactly rounded.
const FRAC_1_PI: Q2_30 = Q2_30::from_f64_const(core::f64::consts::FRAC_1_PI);

/// Drive amplitude: the fraction of full-scale fundamental voltage, an unsigned Q1.31
/// (`u32` bits, 2^31 = full scale) in [0, 1], full scale included.
///
/// The one encoding from the controller's output ([`crate::control::Output::amplitude`]) to
/// the drive: the controller's shaper computes in Q1.31 in [0, 1) and its command becomes an
/// amplitude exactly, every bit kept ([`Amplitude::from_command`]); full scale, which a
/// signed Q1.31 cannot hold, is `2^31` here ([`Amplitude::FULL`], the drive's limits and the
/// duty's edge). The drive's arithmetic that works in Q2.30 (the duty's arcsine, the resonance
/// loop's current thresholds) reads [`Amplitude::fraction`], the amplitude truncated to Q2.30
/// (at most 2^-31 of full scale low), the one place that rounding is made.
///
/// Full scale is the fundamental of a 50 % square wave, `2 V_bus / pi`
/// ([`crate::drive::DriveLimits`] relates it to volts on the stack).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Amplitude(u32);

/// Full scale in [`Amplitude`]'s bits.
const FULL_SCALE_BITS: u32 = 1 << 31;

impl Amplitude {
    /// No drive (duty 0: the low-side switch stays on).
    pub const ZERO: Self = Self(0);
    /// Full scale (duty 1/2).
    pub const FULL: Self = Self(FULL_SCALE_BITS);

    /// The amplitude `fraction` of full scale, exactly. Error `AmplitudeOutOfRange` outside
    /// [0, 1].
    pub const fn new(fraction: Q2_30) -> Result<Self, DriveError> {
        let bits = fraction.to_bits();
        if bits < 0 || bits > 1 << 30 {
            return Err(DriveError::AmplitudeOutOfRange);
        }
        // [0, 2^30] << 1 = [0, 2^31]: full scale at most.
        Ok(Self((bits as u32) << 1))
    }

    /// The amplitude of `bits` (unsigned Q1.31, 2^31 = full scale). Error
    /// `AmplitudeOutOfRange` above full scale (never a wrap or a silent clamp).
    pub const fn from_bits(bits: u32) -> Result<Self, DriveError> {
        if bits > FULL_SCALE_BITS {
            return Err(DriveError::AmplitudeOutOfRange);
        }
        Ok(Self(bits))
    }

    /// The amplitude `numerator / denominator` of full scale, rounded to nearest Q2.30 (the
    /// resolution the drive's timer and the search's settings use). Error
    /// `AmplitudeOutOfRange` for a zero denominator or a ratio outside [0, 1].
    pub const fn from_ratio(numerator: u32, denominator: u32) -> Result<Self, DriveError> {
        if denominator == 0 || numerator > denominator {
            return Err(DriveError::AmplitudeOutOfRange);
        }
        // numerator <= denominator < 2^32: numerator << 30 < 2^62; the quotient <= 2^30.
        let bits = (((numerator as u64) << 30) + denominator as u64 / 2) / denominator as u64;
        Ok(Self((bits as u32) << 1))
    }

    /// The amplitude truncated to a Q2.30 fraction in [0, 1] (at most 2^-31 low), for the
    /// drive's Q2.30 arithmetic.
    pub const fn fraction(self) -> Q2_30 {
        // [0, 2^31] >> 1 = [0, 2^30]: fits Q2.30.
        Q2_30::from_bits((self.0 >> 1) as i32)
    }

    /// The amplitude of a controller command (Q1.31 fraction of full scale in [-1, 1)),
    /// exactly; a negative command is no drive (the shaper never gives one). Total: every
    /// Q1.31 value maps into [0, 1 - 2^-31].
    pub const fn from_command(command: Q1_31) -> Self {
        let bits = command.to_bits();
        Self(if bits < 0 { 0 } else { bits as u32 })
    }

    /// This amplitude as a Q1.31 command, for the controller's own arithmetic: exact below
    /// full scale; full scale, which Q1.31 cannot hold, is Q1.31's largest value with
    /// `saturated` set (2^-31 low; the controller's limits keep its own commands below it).
    pub const fn command(self) -> Sat<Q1_31> {
        if self.0 >= FULL_SCALE_BITS {
            return Sat::clamped(Q1_31::MAX);
        }
        Sat::exact(Q1_31::from_bits(self.0 as i32))
    }

    /// The raw bits, unsigned Q1.31: 0 to `1 << 31`.
    pub const fn bits(self) -> u32 {
        self.0
    }

    /// The amplitude times `unit`, rounded to the nearest integer (ties up): full scale is
    /// `unit`. Exact; `bits x unit < 2^63` never overflows.
    pub const fn round_scaled(self, unit: u32) -> u64 {
        (self.0 as u64 * unit as u64 + (1 << 30)) >> 31
    }

    /// The amplitude as a fraction of full scale, exactly.
    pub const fn to_f64(self) -> f64 {
        self.0 as f64 / FULL_SCALE_BITS as f64
    }

    /// The amplitude as a fraction of full scale, rounded once to nearest `f32`.
    pub const fn to_f32(self) -> f32 {
        self.to_f64() as f32
    }

    /// The smaller of two amplitudes.
    pub const fn min(self, other: Self) -> Self {
        if self.0 <= other.0 { self } else { other }
    }

    /// The duty cycle `asin(a) / pi` (Q2.30, 0 to 1/2) whose fundamental is this amplitude.
    /// Cost: one fixed-point arcsine (25 to 60 instructions, `fx::Q2_30::asin`) and one
    /// multiplication.
    pub const fn duty(self) -> Q2_30 {
        // The amplitude is in [0, 1], the domain of asin, and asin(a)/pi <= 1/2 fits Q2.30,
        // so neither error arm can be taken; both fall back to no drive.
        match self.fraction().asin() {
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
    fn a_controller_command_becomes_an_amplitude_exactly() {
        // Zero, the smallest positive step, the largest command: every bit kept.
        assert_eq!(Amplitude::from_command(Q1_31::ZERO), Amplitude::ZERO);
        assert_eq!(Amplitude::from_command(Q1_31::from_bits(1)).bits(), 1);
        assert_eq!(
            Amplitude::from_command(Q1_31::MAX).bits(),
            FULL_SCALE_BITS - 1
        );
        // A negative command (the shaper never gives one) is no drive, never a wrap to a
        // large amplitude.
        assert_eq!(
            Amplitude::from_command(Q1_31::from_bits(-1)),
            Amplitude::ZERO
        );
        assert_eq!(Amplitude::from_command(Q1_31::MIN), Amplitude::ZERO);
        // Against the f64 value: exact, and the round trip gives the command back.
        for bits in [1, 3, 12_345, 1 << 20, (1 << 30) + 7, i32::MAX - 1, i32::MAX] {
            let command = Q1_31::from_bits(bits);
            let amplitude = Amplitude::from_command(command);
            assert_eq!(amplitude.to_f64(), command.to_f64());
            assert_eq!(amplitude.to_f32(), command.to_f32());
            assert_eq!(amplitude.command(), Sat::exact(command));
        }
    }

    #[test]
    fn the_drive_fraction_truncates_to_q2_30_and_keeps_full_scale() {
        assert_eq!(Amplitude::ZERO.fraction(), Q2_30::ZERO);
        assert_eq!(Amplitude::FULL.fraction(), Q2_30::ONE);
        // One Q1.31 lsb is below one Q2.30 lsb: dropped, never rounded up.
        assert_eq!(
            Amplitude::from_command(Q1_31::from_bits(1)).fraction(),
            Q2_30::ZERO
        );
        assert_eq!(
            Amplitude::from_command(Q1_31::MAX).fraction().to_bits(),
            (1 << 30) - 1
        );
        for bits in [1, 3, 12_345, 1 << 20, (1 << 30) + 7, i32::MAX - 1, i32::MAX] {
            let amplitude = Amplitude::from_command(Q1_31::from_bits(bits));
            let fraction = amplitude.fraction().to_f64();
            assert!(fraction <= amplitude.to_f64());
            assert!(amplitude.to_f64() - fraction < 1.0 / f64::from(1 << 30));
        }
    }

    #[test]
    fn full_scale_is_an_amplitude_and_a_flagged_command() {
        assert_eq!(Amplitude::FULL.to_f64(), 1.0);
        assert_eq!(Amplitude::FULL.command(), Sat::clamped(Q1_31::MAX));
        assert_eq!(Amplitude::ZERO.command(), Sat::exact(Q1_31::ZERO));
        let below_full = Amplitude::from_bits(FULL_SCALE_BITS - 1).unwrap();
        assert_eq!(below_full.command(), Sat::exact(Q1_31::MAX));
        for (numerator, denominator) in [(1, 1000), (1, 4), (707, 1000), (999_999, 1_000_000)] {
            let a = Amplitude::from_ratio(numerator, denominator).unwrap();
            assert_eq!(a.command().value.to_f64(), a.to_f64());
            assert_eq!(Amplitude::from_command(a.command().value), a);
        }
    }

    #[test]
    fn round_scaled_is_the_command_s_below_full_scale_and_unit_at_it() {
        assert_eq!(Amplitude::FULL.round_scaled(1_000_000), 1_000_000);
        assert_eq!(Amplitude::FULL.round_scaled(u32::MAX), u64::from(u32::MAX));
        assert_eq!(Amplitude::ZERO.round_scaled(u32::MAX), 0);
        for bits in [1, 1 << 20, (1 << 30) + 7, i32::MAX] {
            let command = Q1_31::from_bits(bits);
            assert_eq!(
                Amplitude::from_command(command).round_scaled(1_000_000),
                command.round_scaled(1_000_000) as u64
            );
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
        // Over full scale is an error, not a wrap: the largest u32 is not a small amplitude.
        assert_eq!(Amplitude::from_bits(FULL_SCALE_BITS), Ok(Amplitude::FULL));
        assert_eq!(
            Amplitude::from_bits(FULL_SCALE_BITS + 1),
            Err(DriveError::AmplitudeOutOfRange)
        );
        assert_eq!(
            Amplitude::from_bits(u32::MAX),
            Err(DriveError::AmplitudeOutOfRange)
        );
        assert_eq!(Amplitude::from_ratio(1, 4).unwrap().bits(), 1 << 29);
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
