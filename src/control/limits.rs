//! The actuator's voltage and current ratings as a ceiling on the drive amplitude.
//!
//! The piezo stack is a capacitance to the drive (physics-notes §6: C = 300 nF), so a voltage
//! amplitude `V` at the drive frequency `f` draws `I = 2 pi f C V`. The drive amplitude `a`
//! (fraction of full scale) puts `V = a V_fs` on the stack, hence
//! `a <= min(V_max / V_fs, I_max / (2 pi f C V_fs), 1)`. The friction model's amplitude is a
//! fraction of the full-scale *vibration* amplitude; the controller takes vibration amplitude
//! proportional to drive voltage (the stack's d33 response, seed 003), so the same fraction
//! caps both. Computed once, in `f64`, at configuration; the control step only compares.
//!
//! `crate::drive::DriveLimits` computes the same ceiling per frequency for the timer code;
//! this one is the controller's own copy for a fixed drive frequency, as the controller's
//! configuration is built from the scene's numbers.

use crate::fx::Q1_31;
use crate::model::actuator::ActuatorParams;

/// Electrical ratings of the actuator and its drive, SI units (configuration only).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ActuatorRatings {
    /// Largest voltage amplitude allowed on the stack, V (seed 003: 15.466 V).
    pub max_voltage_v: f64,
    /// Largest current amplitude allowed into the stack, A (seed 003: 1.75 A).
    pub max_current_a: f64,
    /// Stack capacitance, F (seed 003: 300 nF).
    pub capacitance_f: f64,
    /// Drive frequency, Hz (20-60 kHz; the reference scene uses 40 kHz).
    pub drive_frequency_hz: f64,
    /// Voltage amplitude on the stack at full-scale drive amplitude, V.
    pub full_scale_voltage_v: f64,
}

impl ActuatorRatings {
    /// The PMN-PT stack of seed 003 Table 1 at 40 kHz, with full scale at the voltage rating;
    /// the ratings come from their one definition, [`ActuatorParams::SEED_003_TABLE_1`]
    /// (V_max = 15.466 V, I_max = 1.75 A, C = 300 nF).
    pub const SEED_003_40_KHZ: Self = Self {
        max_voltage_v: ActuatorParams::SEED_003_TABLE_1.max_voltage_v,
        max_current_a: ActuatorParams::SEED_003_TABLE_1.max_current_a,
        capacitance_f: ActuatorParams::SEED_003_TABLE_1.capacitance_f,
        drive_frequency_hz: 40_000.0,
        full_scale_voltage_v: ActuatorParams::SEED_003_TABLE_1.max_voltage_v,
    };
}

/// Which rating sets the amplitude ceiling.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Binding {
    /// Neither rating binds: the ceiling is full scale.
    FullScale,
    /// The voltage rating binds.
    Voltage,
    /// The current rating (`2 pi f C V`) binds.
    Current,
}

/// The largest drive amplitude the ratings allow.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AmplitudeLimit {
    /// Largest amplitude, Q1.31 fraction of full scale in (0, 1), rounded down (a rating is
    /// never exceeded by rounding). Full scale is `Q1_31::MAX` (1 - 2^-31).
    pub max_amplitude: Q1_31,
    /// The rating that sets it.
    pub binding: Binding,
}

/// Why the ratings could not give a ceiling.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LimitsError {
    /// A rating was not a finite, strictly positive number.
    NotPositive,
    /// The ceiling is below 2^-20 of full scale: the drive could do nothing.
    NoHeadroom,
}

impl AmplitudeLimit {
    /// The ceiling for `ratings`. Configuration only (`f64`).
    pub fn new(ratings: &ActuatorRatings) -> Result<Self, LimitsError> {
        let positive = |x: f64| x.is_finite() && x > 0.0;
        if !(positive(ratings.max_voltage_v)
            && positive(ratings.max_current_a)
            && positive(ratings.capacitance_f)
            && positive(ratings.drive_frequency_hz)
            && positive(ratings.full_scale_voltage_v))
        {
            return Err(LimitsError::NotPositive);
        }
        let by_voltage = ratings.max_voltage_v / ratings.full_scale_voltage_v;
        let by_current = ratings.max_current_a
            / (core::f64::consts::TAU
                * ratings.drive_frequency_hz
                * ratings.capacitance_f
                * ratings.full_scale_voltage_v);
        let (fraction, binding) = if by_voltage >= 1.0 && by_current >= 1.0 {
            (1.0, Binding::FullScale)
        } else if by_voltage <= by_current {
            (by_voltage, Binding::Voltage)
        } else {
            (by_current, Binding::Current)
        };
        // Rounded down; `as` saturates, and 1.0 becomes MAX.
        let bits = ((fraction * 2_147_483_648.0) as i64).min(i32::MAX as i64) as i32;
        if bits < 1 << 11 {
            return Err(LimitsError::NoHeadroom);
        }
        Ok(Self {
            max_amplitude: Q1_31::from_bits(bits),
            binding,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TAU: f64 = core::f64::consts::TAU;

    fn check(r: &ActuatorRatings) -> AmplitudeLimit {
        let limit = AmplitudeLimit::new(r).unwrap();
        let a = limit.max_amplitude.to_f64();
        let volts = a * r.full_scale_voltage_v;
        let amps = TAU * r.drive_frequency_hz * r.capacitance_f * volts;
        assert!(volts <= r.max_voltage_v * (1.0 + 1e-12));
        assert!(amps <= r.max_current_a * (1.0 + 1e-12));
        // Within one Q1.31 ulp of the exact ceiling (rounded down).
        let exact = (r.max_voltage_v / r.full_scale_voltage_v)
            .min(
                r.max_current_a
                    / (TAU * r.drive_frequency_hz * r.capacitance_f * r.full_scale_voltage_v),
            )
            .min(1.0);
        assert!(exact - a <= 2.0 / 2_147_483_648.0, "{a} vs {exact}");
        limit
    }

    #[test]
    fn seed_003_stack_at_40_and_60_khz() {
        // 40 kHz: I = 2 pi 40e3 300e-9 15.466 = 1.166 A < 1.75 A: full scale allowed.
        let at_40 = check(&ActuatorRatings::SEED_003_40_KHZ);
        assert_eq!(at_40.binding, Binding::FullScale);
        assert_eq!(at_40.max_amplitude, Q1_31::MAX);
        // 65 kHz: the current rating binds at 1.75 / (2 pi 65e3 300e-9 15.466) = 0.9234.
        let at_65 = check(&ActuatorRatings {
            drive_frequency_hz: 65_000.0,
            ..ActuatorRatings::SEED_003_40_KHZ
        });
        assert_eq!(at_65.binding, Binding::Current);
        assert!((at_65.max_amplitude.to_f64() - 0.923_4).abs() < 1e-3);
        // A 24 V full scale: the voltage rating binds at 15.466 / 24.
        let at_24v = check(&ActuatorRatings {
            full_scale_voltage_v: 24.0,
            ..ActuatorRatings::SEED_003_40_KHZ
        });
        assert_eq!(at_24v.binding, Binding::Voltage);
    }

    #[test]
    fn bad_ratings_are_rejected() {
        let good = ActuatorRatings::SEED_003_40_KHZ;
        for bad in [
            ActuatorRatings {
                max_voltage_v: 0.0,
                ..good
            },
            ActuatorRatings {
                max_current_a: f64::NAN,
                ..good
            },
            ActuatorRatings {
                capacitance_f: -1.0,
                ..good
            },
            ActuatorRatings {
                drive_frequency_hz: f64::INFINITY,
                ..good
            },
            ActuatorRatings {
                full_scale_voltage_v: 0.0,
                ..good
            },
        ] {
            assert_eq!(AmplitudeLimit::new(&bad), Err(LimitsError::NotPositive));
        }
        assert_eq!(
            AmplitudeLimit::new(&ActuatorRatings {
                max_voltage_v: 1e-9,
                ..good
            }),
            Err(LimitsError::NoHeadroom)
        );
    }
}
