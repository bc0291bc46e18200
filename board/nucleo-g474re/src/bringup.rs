//! Bring-up build only: hold the USER button (B1, PC13) to run the bridge at a fixed test
//! amplitude, so the outputs can be measured with a scope (board README, bring-up procedure).
//!
//! The drive soft-starts to [`config::BRINGUP_AMPLITUDE`] (capped by the stack's ratings at the
//! drive frequency) while B1 is held and ramps down when it is released. If the outputs go off
//! on their own (a break from the overcurrent comparator, or the current sense faulting), the
//! ramp stops at once and the button must be released before the drive can be re-armed.

use embassy_stm32::Peri;
use embassy_stm32::gpio::{Input, Pull};
use embassy_stm32::peripherals::PC13;
use sonolube::drive::{Amplitude, AmplitudeRamp, DriveLimits, DriveTiming};

use crate::{config, drive, safe};

/// The hold-to-run state, polled by the sensing loop every [`crate::sense_task::HOLD_POLL_TRIPLETS`]
/// ADC triplets (38 ms at 40 kHz).
pub struct HoldToRun {
    button: Input<'static>,
    timing: DriveTiming,
    ceiling: Amplitude,
    ramp: AmplitudeRamp,
    running: bool,
    locked_out: bool,
}

impl HoldToRun {
    /// B1 pulls PC13 high when pressed (NUCLEO-64 user manual); the pull-down keeps it low.
    pub fn new(button: Peri<'static, PC13>, timing: DriveTiming) -> Self {
        // One-time configuration: f64 here is fine. Invalid ratings leave a zero ceiling.
        let ceiling = DriveLimits::new(&config::STACK, config::FULL_SCALE_V)
            .map(|limits| limits.max_amplitude(timing.frequency()))
            .unwrap_or(Amplitude::ZERO);
        let ramp = AmplitudeRamp::new(config::RAMP_RISE_STEPS, config::RAMP_FALL_STEPS)
            .unwrap_or_else(|_| defmt::panic!("ramp steps are zero"));
        defmt::warn!(
            "BRING-UP BUILD: holding B1 switches the bridge at amplitude {=u32}/1024 \
             (ceiling {=u32}/1024)",
            config::BRINGUP_AMPLITUDE.bits() >> 21,
            ceiling.bits() >> 21
        );
        Self {
            button: Input::new(button, Pull::Down),
            timing,
            ceiling,
            ramp,
            running: false,
            locked_out: false,
        }
    }

    /// One step: arm, ramp, disarm according to the button and the hardware state.
    pub fn poll(&mut self) {
        let held = self.button.is_high();
        if self.running && !drive::outputs_enabled() {
            // The hardware (break) or the current-sense fault handler switched the bridge off.
            self.ramp.stop();
            self.running = false;
            self.locked_out = true;
            defmt::error!(
                "bring-up: outputs went off (break {=bool}); release B1 to re-arm",
                drive::break_tripped()
            );
        }
        if !held && self.locked_out {
            self.locked_out = false;
            drive::clear_break_flag();
        }
        if held && !self.running && !self.locked_out {
            drive::set_amplitude(&self.timing, Amplitude::ZERO);
            if drive::try_enable_outputs() {
                self.running = true;
                defmt::info!("bring-up: outputs ON");
            } else {
                self.locked_out = true;
                defmt::error!("bring-up: break input active, outputs stay off");
            }
        }
        if self.running {
            let target = if held {
                config::BRINGUP_AMPLITUDE
            } else {
                Amplitude::ZERO
            };
            let amplitude = self.ramp.step(target, self.ceiling);
            drive::set_amplitude(&self.timing, amplitude);
            if !held && amplitude == Amplitude::ZERO {
                safe::drive_safe();
                self.running = false;
                defmt::info!("bring-up: outputs OFF");
            }
        }
    }
}
