//! Voltage and current limits of the stack as a ceiling on the drive amplitude.
//!
//! The stack is a capacitor to the drive (seed 003 Table 1: C = 300 nF, Z = 1 / (C omega)), so
//! a voltage amplitude `V` at frequency `f` draws `I = 2 pi f C V`. With the amplitude `a`
//! giving `V = a V_fs` on the stack, the two ratings cap `a` at
//! `min(V_max / V_fs, I_max / (2 pi f C V_fs))`: a constant, and a ceiling falling as `1/f`
//! above the *current corner* `f_c = I_max / (2 pi C V_fs)`. The corner is computed once, in
//! `f64`, when the limits are built; the per-step ceiling is one integer division.
//!
//! The model ignores the stack's motional branch (at resonance it draws more current than the
//! capacitance alone); the hardware overcurrent trip ([`crate::drive::OvercurrentTrip`]) and
//! the measured current cover that.

use super::amplitude::Amplitude;
use super::error::DriveError;
use super::frequency::Frequency;
use crate::fx::Q2_30;
use crate::model::actuator::ActuatorParams;

/// Electrical ratings of the piezo stack.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StackRatings {
    /// Largest voltage amplitude on the stack, in volts.
    pub max_voltage_v: f64,
    /// Largest current amplitude into the stack, in amperes.
    pub max_current_a: f64,
    /// Capacitance of the stack, in farads.
    pub capacitance_f: f64,
}

impl StackRatings {
    /// The ratings of the PMN-PT stack of seed 003 Table 1, taken from its one definition,
    /// [`ActuatorParams::SEED_003_TABLE_1`] (V_max = 15.466 V, I_max = 1.75 A, C = 300 nF).
    pub const SEED_003: Self = Self {
        max_voltage_v: ActuatorParams::SEED_003_TABLE_1.max_voltage_v,
        max_current_a: ActuatorParams::SEED_003_TABLE_1.max_current_a,
        capacitance_f: ActuatorParams::SEED_003_TABLE_1.capacitance_f,
    };
}

/// The amplitude ceiling of one stack on one power stage.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DriveLimits {
    voltage_ceiling: Amplitude,
    current_corner: Frequency,
}

impl DriveLimits {
    /// Limits for `stack` driven by a power stage that puts `full_scale_voltage_v` volts
    /// (amplitude of the fundamental) on it at [`Amplitude::FULL`]. For the half-bridge that is
    /// `2 V_bus / pi` times the gain of whatever sits between bridge and stack (1 for a direct
    /// connection; measured at bring-up, board README).
    ///
    /// One-time configuration (`f64`). Error `InvalidRating` unless every number is finite and
    /// strictly positive.
    pub fn new(stack: &StackRatings, full_scale_voltage_v: f64) -> Result<Self, DriveError> {
        let positive = |x: f64| x.is_finite() && x > 0.0;
        if !(positive(stack.max_voltage_v)
            && positive(stack.max_current_a)
            && positive(stack.capacitance_f)
            && positive(full_scale_voltage_v))
        {
            return Err(DriveError::InvalidRating);
        }
        let voltage_ratio = stack.max_voltage_v / full_scale_voltage_v;
        let voltage_ceiling = if voltage_ratio >= 1.0 {
            Amplitude::FULL
        } else {
            // Rounded down: the ceiling never exceeds the rating. `as` saturates, and the ratio
            // is in (0, 1), so the bits are in [0, 2^30).
            Amplitude::new(Q2_30::from_bits((voltage_ratio * 1_073_741_824.0) as i32))?
        };
        let corner_hz = stack.max_current_a
            / (core::f64::consts::TAU * stack.capacitance_f * full_scale_voltage_v);
        // Rounded down to the millihertz, saturating at 4.29 MHz (no current limit in band).
        let current_corner = Frequency::from_millihertz((corner_hz * 1000.0) as u32);
        Ok(Self {
            voltage_ceiling,
            current_corner,
        })
    }

    /// The largest amplitude at `frequency` that keeps both the voltage and the current within
    /// the ratings (rounded down). Integer only: one `u64` division.
    pub const fn max_amplitude(&self, frequency: Frequency) -> Amplitude {
        let f = frequency.millihertz() as u64;
        let corner = self.current_corner.millihertz() as u64;
        let current_ceiling = if corner >= f {
            Amplitude::FULL
        } else {
            // corner < f <= u32::MAX: (corner << 30) / f < 2^30 and fits u64.
            match Amplitude::new(Q2_30::from_bits(((corner << 30) / f) as i32)) {
                Ok(ceiling) => ceiling,
                Err(_) => Amplitude::ZERO,
            }
        };
        current_ceiling.min(self.voltage_ceiling)
    }

    /// The amplitude ceiling set by the voltage rating alone.
    pub const fn voltage_ceiling(&self) -> Amplitude {
        self.voltage_ceiling
    }

    /// The frequency above which the current rating, not the voltage rating, caps a
    /// full-scale drive: `I_max / (2 pi C V_fs)`.
    pub const fn current_corner(&self) -> Frequency {
        self.current_corner
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TAU: f64 = core::f64::consts::TAU;

    /// Checks every 10 Hz of the band against the f64 ratings: never above either rating, and
    /// within 1e-7 of the exact ceiling (the corner is kept to the millihertz, 6e-8 relative).
    fn check_band(stack: &StackRatings, full_scale_v: f64) {
        let limits = DriveLimits::new(stack, full_scale_v).unwrap();
        for hz in (20_000..=60_000).step_by(10) {
            let amplitude = limits
                .max_amplitude(Frequency::from_hz(hz))
                .fraction()
                .to_f64();
            let volts = amplitude * full_scale_v;
            let amps = TAU * f64::from(hz) * stack.capacitance_f * volts;
            assert!(volts <= stack.max_voltage_v, "{hz} Hz: {volts} V");
            assert!(amps <= stack.max_current_a, "{hz} Hz: {amps} A");
            let exact = (stack.max_voltage_v / full_scale_v)
                .min(
                    stack.max_current_a
                        / (TAU * f64::from(hz) * stack.capacitance_f * full_scale_v),
                )
                .min(1.0);
            assert!(exact - amplitude < 1e-7, "{hz} Hz: {amplitude} vs {exact}");
        }
    }

    #[test]
    fn seed_ratings_are_the_table_values() {
        let stack = StackRatings::SEED_003;
        assert!((stack.max_voltage_v - 15.466).abs() < 1e-3);
        // Table 1 derives I_max from V_max at 60 kHz: 2 pi 60 kHz 300 nF 15.466 V = 1.749 A.
        let i_at_60k = TAU * 60e3 * stack.capacitance_f * stack.max_voltage_v;
        assert!((i_at_60k - stack.max_current_a).abs() < 0.01);
    }

    #[test]
    fn a_24_v_half_bridge_may_use_full_scale_over_the_whole_band() {
        // Fundamental of a 24 V square wave: 2 * 24 / pi = 15.28 V < 15.466 V, and the current
        // corner 1.75 A / (2 pi 300 nF 15.28 V) = 60.76 kHz lies above the band.
        let full_scale = 2.0 * 24.0 / core::f64::consts::PI;
        let limits = DriveLimits::new(&StackRatings::SEED_003, full_scale).unwrap();
        assert_eq!(limits.voltage_ceiling(), Amplitude::FULL);
        assert_eq!(limits.current_corner().hz_rounded(), 60_764);
        assert_eq!(limits.max_amplitude(Frequency::BAND_MAX), Amplitude::FULL);
        check_band(&StackRatings::SEED_003, full_scale);
    }

    #[test]
    fn with_headroom_the_voltage_rating_binds_and_the_current_rating_agrees_at_60_khz() {
        let limits = DriveLimits::new(&StackRatings::SEED_003, 30.0).unwrap();
        let at_40k = limits.max_amplitude(Frequency::from_hz(40_000));
        let at_60k = limits.max_amplitude(Frequency::BAND_MAX);
        assert_eq!(at_40k, limits.voltage_ceiling());
        assert!((at_40k.fraction().to_f64() - 15.466 / 30.0).abs() < 1e-4);
        // The corner sits at 30.9 kHz but only 51.6 % amplitude is allowed anyway: at 60 kHz
        // the current limit (0.51578) and the voltage limit (0.51553) nearly coincide.
        assert_eq!(at_60k, limits.voltage_ceiling());
        check_band(&StackRatings::SEED_003, 30.0);
    }

    #[test]
    fn a_lower_current_rating_takes_over_above_the_corner() {
        let stack = StackRatings {
            max_current_a: 1.0,
            ..StackRatings::SEED_003
        };
        let limits = DriveLimits::new(&stack, 30.0).unwrap();
        // Corner 1 A / (2 pi 300 nF 30 V) = 17.68 kHz; at 60 kHz the ceiling is 0.2947.
        assert_eq!(limits.current_corner().hz_rounded(), 17_684);
        let at_60k = limits
            .max_amplitude(Frequency::BAND_MAX)
            .fraction()
            .to_f64();
        assert!((at_60k - 0.294_731).abs() < 1e-5, "{at_60k}");
        let at_45k = limits
            .max_amplitude(Frequency::from_hz(45_000))
            .fraction()
            .to_f64();
        assert!((at_45k - 0.294_731 * 60.0 / 45.0).abs() < 1e-5, "{at_45k}");
        // Below 34.3 kHz the voltage rating binds again.
        let at_30k = limits.max_amplitude(Frequency::from_hz(30_000));
        assert_eq!(at_30k, limits.voltage_ceiling());
        check_band(&stack, 30.0);
    }

    #[test]
    fn invalid_ratings_are_refused() {
        let seed = StackRatings::SEED_003;
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert_eq!(DriveLimits::new(&seed, bad), Err(DriveError::InvalidRating));
            let stacks = [
                StackRatings {
                    max_voltage_v: bad,
                    ..seed
                },
                StackRatings {
                    max_current_a: bad,
                    ..seed
                },
                StackRatings {
                    capacitance_f: bad,
                    ..seed
                },
            ];
            for stack in stacks {
                assert_eq!(
                    DriveLimits::new(&stack, 15.0),
                    Err(DriveError::InvalidRating)
                );
            }
        }
    }

    #[test]
    fn a_tiny_stack_has_no_current_limit_in_band() {
        let stack = StackRatings {
            capacitance_f: 1e-15,
            ..StackRatings::SEED_003
        };
        let limits = DriveLimits::new(&stack, 15.0).unwrap();
        assert_eq!(limits.current_corner().millihertz(), u32::MAX);
        assert_eq!(limits.max_amplitude(Frequency::BAND_MAX), Amplitude::FULL);
    }
}
