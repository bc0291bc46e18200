//! Sensor fault detection on the raw reading: disconnected, stuck, implausible jump.
//!
//! The checks run on the reading as a fraction of full scale, before calibration, so they do
//! not depend on the tare or gain and work the same on every converter:
//! - *rail*: an open bridge wire or unplugged cell drives the amplifier to a supply rail (the
//!   inputs float off), so the converter reads its lowest or highest code. The front ends put
//!   zero load at mid-scale (instrumentation amplifier reference at mid-supply, bipolar
//!   external ADC), so a healthy cell never sits at a rail.
//! - *stuck*: a live strain bridge always shows some noise; a reading that stays within the
//!   noise band for many samples means a dead converter, a frozen DMA buffer or a held value.
//! - *jump*: the load cell signal is low-passed (seed 003 measured it through an 80 Hz span,
//!   physics-notes §6), so a change larger than its physical slew between two samples is a
//!   glitch, a loose connector or an overload, not a force.

use super::format::AdcFormat;
use crate::fx::Q1_31;

/// Thresholds of the fault checks, as fractions of full scale (Q1.31).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FaultLimits {
    /// A reading within this distance of either end of the converter's range is at the rail.
    pub rail_margin: Q1_31,
    /// Changes up to this size (from the first sample of a still run) are noise.
    pub noise_band: Q1_31,
    /// This many consecutive samples inside the noise band mean the reading is stuck; 0
    /// disables the check.
    pub stuck_samples: u32,
    /// A change between two consecutive samples larger than this is implausible.
    pub max_step: Q1_31,
}

/// What is wrong with a sensor reading.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SensorFault {
    /// The reading is at the converter's lowest code: the sensor is disconnected or the
    /// amplifier saturated low.
    LowRail {
        /// The reading, fraction of full scale.
        reading: Q1_31,
    },
    /// The reading is at the converter's highest code: disconnected or saturated high.
    HighRail {
        /// The reading, fraction of full scale.
        reading: Q1_31,
    },
    /// The reading has not moved beyond the noise band for this many samples.
    Stuck {
        /// Consecutive samples inside the noise band.
        samples: u32,
    },
    /// The reading changed by more than the plausible step between two samples.
    Jump {
        /// The previous reading.
        from: Q1_31,
        /// This reading.
        to: Q1_31,
    },
}

/// Fault checks for one channel: thresholds and the little history they need.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FaultMonitor {
    limits: FaultLimits,
    low_rail: Q1_31,
    high_rail: Q1_31,
    previous: Option<Q1_31>,
    anchor: Q1_31,
    still: u32,
}

impl FaultMonitor {
    /// A monitor for a channel of `format` with `limits`.
    pub const fn new(format: AdcFormat, limits: FaultLimits) -> Self {
        let low_rail = format
            .min_normalized()
            .to_bits()
            .saturating_add(limits.rail_margin.to_bits());
        let high_rail = format
            .max_normalized()
            .to_bits()
            .saturating_sub(limits.rail_margin.to_bits());
        Self {
            limits,
            low_rail: Q1_31::from_bits(low_rail),
            high_rail: Q1_31::from_bits(high_rail),
            previous: None,
            anchor: Q1_31::ZERO,
            still: 0,
        }
    }

    /// Checks one reading (fraction of full scale) and updates the history. Rail faults take
    /// precedence over jumps, jumps over stuck readings. No latching: the caller decides what
    /// a fault means (the supervisor stops the drive).
    pub fn check(&mut self, reading: Q1_31) -> Result<(), SensorFault> {
        let previous = self.previous.replace(reading);
        let moved = reading.to_bits().abs_diff(self.anchor.to_bits());
        if self.still == 0 || moved > self.limits.noise_band.to_bits().unsigned_abs() {
            self.anchor = reading;
            self.still = 1;
        } else {
            self.still = self.still.saturating_add(1);
        }
        if reading <= self.low_rail {
            return Err(SensorFault::LowRail { reading });
        }
        if reading >= self.high_rail {
            return Err(SensorFault::HighRail { reading });
        }
        if let Some(from) = previous
            && reading.to_bits().abs_diff(from.to_bits())
                > self.limits.max_step.to_bits().unsigned_abs()
        {
            return Err(SensorFault::Jump { from, to: reading });
        }
        if self.limits.stuck_samples != 0 && self.still >= self.limits.stuck_samples {
            return Err(SensorFault::Stuck {
                samples: self.still,
            });
        }
        Ok(())
    }

    /// Forgets the history (after a reconfiguration or a deliberate gap in the samples).
    pub fn reset(&mut self) {
        self.previous = None;
        self.still = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sense::format::{AdcCode, Oversampling};

    /// The board's internal ADC channels: 12 bits, 16x oversampled, 16-bit result.
    fn adc16() -> AdcFormat {
        AdcFormat::oversampled(12, Oversampling::new(4, 0).unwrap()).unwrap()
    }

    fn limits() -> FaultLimits {
        FaultLimits {
            rail_margin: Q1_31::from_bits(1 << 22), // 0.2 % FS
            noise_band: Q1_31::from_bits(2 << 15),  // 2 LSB of the 16-bit result
            stuck_samples: 50,
            max_step: Q1_31::from_bits(1 << 27), // 1/16 FS per sample
        }
    }

    /// A healthy reading near mid-scale with a few LSB of deterministic noise.
    fn healthy(i: u32) -> i32 {
        32_000 + [0, 3, -2, 5, -4, 1, -6, 2][(i % 8) as usize]
    }

    #[test]
    fn a_healthy_noisy_signal_raises_nothing() {
        let format = adc16();
        let mut monitor = FaultMonitor::new(format, limits());
        for i in 0..10_000 {
            assert_eq!(
                monitor.check(format.normalize(AdcCode::new(healthy(i))).unwrap()),
                Ok(())
            );
        }
    }

    #[test]
    fn a_disconnected_cell_reads_at_a_rail() {
        let format = adc16();
        let mut monitor = FaultMonitor::new(format, limits());
        let top = format.normalize(AdcCode::new(65_520)).unwrap();
        assert_eq!(
            monitor.check(top),
            Err(SensorFault::HighRail { reading: top })
        );
        let mut monitor = FaultMonitor::new(format, limits());
        let near_zero = format.normalize(AdcCode::new(100)).unwrap(); // 0.15 % FS, inside the margin
        assert_eq!(
            monitor.check(near_zero),
            Err(SensorFault::LowRail { reading: near_zero })
        );
        let just_off = format.normalize(AdcCode::new(140)).unwrap(); // 0.21 % FS
        assert_eq!(monitor.check(just_off), Ok(()));
    }

    #[test]
    fn a_frozen_value_is_stuck_after_the_set_number_of_samples() {
        let format = adc16();
        let mut monitor = FaultMonitor::new(format, limits());
        for i in 0..100 {
            monitor
                .check(format.normalize(AdcCode::new(healthy(i))).unwrap())
                .unwrap();
        }
        let frozen = format.normalize(AdcCode::new(31_000)).unwrap();
        for _ in 0..49 {
            assert_eq!(monitor.check(frozen), Ok(()));
        }
        assert_eq!(
            monitor.check(frozen),
            Err(SensorFault::Stuck { samples: 50 })
        );
        // Still within the band (2 LSB) keeps it stuck; movement clears it.
        let wobble = format.normalize(AdcCode::new(31_002)).unwrap();
        assert_eq!(
            monitor.check(wobble),
            Err(SensorFault::Stuck { samples: 51 })
        );
        assert_eq!(
            monitor.check(format.normalize(AdcCode::new(31_010)).unwrap()),
            Ok(())
        );
    }

    #[test]
    fn an_implausible_jump_is_reported_once() {
        let format = adc16();
        let mut monitor = FaultMonitor::new(format, limits());
        let before = format.normalize(AdcCode::new(30_000)).unwrap();
        let after = format.normalize(AdcCode::new(30_000 + 4097)).unwrap(); // just over 1/16 FS
        monitor.check(before).unwrap();
        assert_eq!(
            monitor.check(after),
            Err(SensorFault::Jump {
                from: before,
                to: after
            })
        );
        // The next sample continues from the new level.
        assert_eq!(
            monitor.check(format.normalize(AdcCode::new(30_000 + 4100)).unwrap()),
            Ok(())
        );
        // A step of exactly the limit is plausible.
        let mut monitor = FaultMonitor::new(format, limits());
        monitor.check(before).unwrap();
        assert_eq!(
            monitor.check(format.normalize(AdcCode::new(30_000 + 4096)).unwrap()),
            Ok(())
        );
    }

    #[test]
    fn rails_win_over_jumps_and_reset_forgets_history() {
        let format = adc16();
        let mut monitor = FaultMonitor::new(format, limits());
        monitor
            .check(format.normalize(AdcCode::new(32_000)).unwrap())
            .unwrap();
        let zero = format.normalize(AdcCode::new(0)).unwrap();
        assert_eq!(
            monitor.check(zero),
            Err(SensorFault::LowRail { reading: zero })
        );
        monitor.reset();
        // Without history a far-away reading is not a jump.
        assert_eq!(
            monitor.check(format.normalize(AdcCode::new(10_000)).unwrap()),
            Ok(())
        );
    }

    #[test]
    fn the_stuck_check_can_be_disabled_and_works_on_a_bipolar_converter() {
        let format = AdcFormat::bipolar(24).unwrap();
        let mut monitor = FaultMonitor::new(
            format,
            FaultLimits {
                stuck_samples: 0,
                ..limits()
            },
        );
        let constant = format.normalize(AdcCode::new(-1_000_000)).unwrap();
        for _ in 0..1000 {
            assert_eq!(monitor.check(constant), Ok(()));
        }
        let bottom = format.normalize(AdcCode::new(-0x80_0000)).unwrap();
        assert_eq!(
            monitor.check(bottom),
            Err(SensorFault::LowRail { reading: bottom })
        );
    }
}
