//! The hardware overcurrent threshold: a drive current to the DAC code a comparator uses.
//!
//! The current-sense amplifier output goes to an ADC input and to the non-inverting input of
//! COMP1; the inverting input is DAC3 channel 1 (RM0440, COMP chapter: COMP1 INMSEL = 100b,
//! DAC3_CH1). The comparator output drives TIM1's break input, which forces the bridge off
//! within the break filter delay, without software. The DAC and the ADC share VREF+, so the
//! comparator threshold is the same fraction of full scale as the ADC reading of the trip
//! current: the current channel's [`Calibration`], inverted, gives it. DAC output =
//! VREF+ * code / 4096 (RM0440, DAC chapter, "DAC output voltage").

use super::error::DriveError;
use crate::fx::{Q1_31, Q16_16};
use crate::sense::Calibration;

/// Largest 12-bit DAC code.
const DAC_MAX_CODE: u32 = 4095;

/// An overcurrent trip level as the 12-bit, right-aligned DAC code (DAC3_DHR12R1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct OvercurrentTrip {
    dac_code: u16,
}

impl OvercurrentTrip {
    /// The threshold for `trip_current` (Q16.16 amperes) on the current channel calibrated by
    /// `current_sense`, rounded *down* to a DAC step so the hardware never trips later than
    /// asked. One-time configuration.
    ///
    /// Error `TripOutOfSensorRange` unless the trip current is positive and its reading lies
    /// above the zero-current reading and below the top of the ADC range (a threshold outside
    /// the range could never trip).
    pub fn new(trip_current: Q16_16, current_sense: &Calibration) -> Result<Self, DriveError> {
        if !trip_current.is_positive() {
            return Err(DriveError::TripOutOfSensorRange);
        }
        let reading = current_sense
            .reading_for(trip_current)
            .map_err(|_| DriveError::TripOutOfSensorRange)?;
        let zero = current_sense.offset();
        if reading <= zero || reading.is_negative() {
            return Err(DriveError::TripOutOfSensorRange);
        }
        // Q1.31 fraction to 12 bits: keep the top 12 fraction bits (rounds down).
        let code = (reading.to_bits() as u32) >> 19;
        if code > DAC_MAX_CODE || code <= (zero.to_bits().max(0) as u32) >> 19 {
            return Err(DriveError::TripOutOfSensorRange);
        }
        Ok(Self {
            dac_code: code as u16,
        })
    }

    /// The code for DAC3_DHR12R1, 1 to 4095.
    pub const fn dac_code(self) -> u16 {
        self.dac_code
    }

    /// The current at which the comparator actually trips (after the DAC's quantization), as
    /// the current channel reads it; saturated at the Q16.16 range.
    pub const fn trip_current(self, current_sense: &Calibration) -> Q16_16 {
        let reading = Q1_31::from_bits((self.dac_code as i32) << 19);
        current_sense.apply(reading).value
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 0.5 V/A around 1.65 V on a 3.3 V ADC: 6.6 A per full scale, zero at 1/2.
    fn board_current_sense() -> Calibration {
        Calibration::new(
            Q1_31::from_bits(1 << 30),
            Q16_16::from_ratio(66, 10).unwrap(),
        )
    }

    #[test]
    fn two_and_a_half_amperes_on_the_board_shunt() {
        let sense = board_current_sense();
        let trip = OvercurrentTrip::new(Q16_16::from_ratio(5, 2).unwrap(), &sense).unwrap();
        // (1.65 V + 1.25 V) / 3.3 V * 4096 = 3599.5: rounded down.
        assert_eq!(trip.dac_code(), 3599);
        let actual = trip.trip_current(&sense).to_f64();
        assert!(actual <= 2.5 && actual > 2.5 - 6.6 / 4096.0, "{actual}");
    }

    #[test]
    fn every_trip_level_in_range_is_at_most_one_dac_step_early() {
        let sense = board_current_sense();
        // 10 mA steps from 0.01 A to 3.29 A (the top of the 3.3 V range is 3.3 A).
        for centiamps in 1..=329 {
            let wanted = Q16_16::from_ratio(centiamps, 100).unwrap();
            let trip = OvercurrentTrip::new(wanted, &sense).unwrap();
            let actual = trip.trip_current(&sense).to_f64();
            let wanted = wanted.to_f64();
            assert!(actual <= wanted + 1e-4, "{wanted} A trips at {actual} A");
            assert!(
                actual > wanted - 6.6 / 4096.0 - 1e-4,
                "{wanted} A trips at {actual} A"
            );
        }
    }

    #[test]
    fn levels_that_could_never_trip_are_refused() {
        let sense = board_current_sense();
        for amps in [0.0, -1.0, 3.31, 100.0] {
            assert_eq!(
                OvercurrentTrip::new(Q16_16::from_f64(amps).unwrap(), &sense),
                Err(DriveError::TripOutOfSensorRange),
                "{amps} A"
            );
        }
        // A trip level that rounds down onto the zero-current code is refused too.
        let tiny = Q16_16::from_f64(0.001).unwrap();
        assert_eq!(
            OvercurrentTrip::new(tiny, &sense),
            Err(DriveError::TripOutOfSensorRange)
        );
        // A sensor with a negative span reads positive currents below its zero.
        let reversed = Calibration::new(sense.offset(), Q16_16::from_ratio(-66, 10).unwrap());
        assert_eq!(
            OvercurrentTrip::new(Q16_16::ONE, &reversed),
            Err(DriveError::TripOutOfSensorRange)
        );
    }
}
