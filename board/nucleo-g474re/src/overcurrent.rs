//! Hardware overcurrent shutdown: current sense on PA1 -> COMP1 (threshold from DAC3 channel 1)
//! -> TIM1 break input -> both bridge outputs low, with no software in the path.
//!
//! COMP1's non-inverting input is PA1 (COMP1_INP, RM0440 COMP chapter); its inverting input
//! is DAC3_CH1, an internal DAC (INMSEL = 100b, embassy's `InvertingInput::Dac1` on COMP1).
//! TIM1_AF1.BKCMP1E routes the comparator output to the break input ([`crate::drive`]). The
//! comparator compares at high speed (tens of ns); the break filter adds 0.3 us.

use embassy_stm32::Peri;
use embassy_stm32::comp::{self, Comp, Hysteresis, InvertingInput};
use embassy_stm32::dac::{self, DacChannel, Value};
use embassy_stm32::mode::Blocking;
use embassy_stm32::peripherals::{COMP1, DAC3, PA1};
use sonolube::drive::OvercurrentTrip;

use crate::Irqs;

/// The armed comparator and its threshold DAC. Keep it alive: dropping it disarms the trip.
pub struct OvercurrentGuard {
    comparator: Comp<'static, COMP1>,
    threshold: DacChannel<'static, Blocking>,
}

impl OvercurrentGuard {
    /// Sets DAC3_CH1 to `trip` and enables COMP1 on PA1 against it. PA1 stays usable as the ADC
    /// input of the same signal (the comparator only borrows it to set it analog).
    pub fn arm(
        comparator: Peri<'static, COMP1>,
        sense_pin: Peri<'_, PA1>,
        dac: Peri<'static, DAC3>,
        trip: OvercurrentTrip,
    ) -> Self {
        let mut threshold = DacChannel::new_internal_blocking::<DAC3, dac::Ch1>(dac);
        threshold.set(Value::Bit12Right(trip.dac_code()));
        let config = comp::Config {
            // 20 mV against chatter at the threshold (40 mA of current at 0.5 V/A).
            hysteresis: Hysteresis::Hyst20M,
            inverting_input: InvertingInput::Dac1,
            ..comp::Config::default()
        };
        let mut comparator = Comp::new(comparator, sense_pin, Irqs, config);
        comparator.enable();
        Self {
            comparator,
            threshold,
        }
    }

    /// Moves the threshold (after the zero-current tare changed the calibration).
    pub fn set_trip(&mut self, trip: OvercurrentTrip) {
        self.threshold.set(Value::Bit12Right(trip.dac_code()));
    }

    /// The comparator output now: true while the current is above the trip level.
    pub fn over_threshold(&self) -> bool {
        self.comparator.output_level()
    }
}
