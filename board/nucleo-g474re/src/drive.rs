//! TIM1 as the half-bridge drive: the pure timing of `sonolube::drive` written to registers.
//!
//! embassy-stm32's `ComplementaryPwm` claims TIM1 and the two pins (clock, reset, alternate
//! functions); everything it has no API for goes through the PAC: dithering (CR1.DITHEN), the
//! 20-bit dithered ARR and CCR values, the DTG byte, idle levels, the COMP1 break source and
//! TRGO2 from OC4REF for the ADC. Register layout and sequences: RM0440, advanced-control
//! timers (TIM1/TIM8/TIM20).
//!
//! Outputs stay off (BDTR.MOE = 0) after [`Drive::new`]; only [`try_enable_outputs`] sets MOE:
//! the control loop's [`crate::bridge`] in the normal build, the hold-to-run button in the
//! bring-up build.

use core::sync::atomic::{AtomicBool, Ordering};

use embassy_stm32::Peri;
use embassy_stm32::gpio::OutputType;
use embassy_stm32::pac;
use embassy_stm32::pac::timer::regs::{ArrDitherCore, Ccr1ch, CcrDither1ch};
use embassy_stm32::pac::timer::vals::{Bkinp, Bkp, FilterValue, Mms2, Ocm, Ossi, Ossr};
use embassy_stm32::peripherals::{PA8, PB13, TIM1};
use embassy_stm32::time::Hertz;
use embassy_stm32::timer::complementary_pwm::{ComplementaryPwm, ComplementaryPwmPin};
use embassy_stm32::timer::low_level::CountingMode;
use embassy_stm32::timer::simple_pwm::PwmPin;
use sonolube::drive::{Amplitude, DriveTiming};

/// CH1 is channel index 0; the ADC trigger uses CH4, index 3.
const CH1: usize = 0;
const CH4: usize = 3;
/// COMP1 is break source index 0 in TIM1_AF1.BKCMPxE.
const COMP1: usize = 0;
/// BRK (not BRK2) is index 0 in the BDTR break fields.
const BRK: usize = 0;
/// TIM1_SR flags, all rc_w0 (a 1 leaves a flag alone, a 0 clears it), except BIF (bit 7):
/// UIF..TIF (bits 0-6), B2IF..SBIF (8-13), CC5IF, CC6IF (16-17), IDXF..TERRF (20-23). Writing
/// this clears the break flag only; reserved bits stay 0.
const SR_ALL_BUT_BIF: u32 = 0x00F3_3F7F;

/// Break filter: 6 samples at f_DTS / 8 (282 ns at 170 MHz). Rejects the comparator's response
/// to switching spikes; an overcurrent still stops the bridge within 0.3 us, far less than the
/// 16.7 us period at 60 kHz.
const BREAK_FILTER: FilterValue = FilterValue::FDTS_DIV8_N6;

/// TIM1 owned and configured as the drive. Keep it alive: dropping it would release TIM1.
pub struct Drive {
    _pwm: ComplementaryPwm<'static, TIM1>,
}

impl Drive {
    /// Claims TIM1 with CH1 on PA8 and CH1N on PB13, and configures it for `timing` with the
    /// outputs off, the break input fed by COMP1 and TRGO2 triggering the ADC at 3/4 period.
    /// The counter runs afterwards (the ADC needs its triggers), the outputs do not.
    pub fn new(
        tim: Peri<'static, TIM1>,
        high_side: Peri<'static, PA8>,
        low_side: Peri<'static, PB13>,
        timing: &DriveTiming,
    ) -> Self {
        let pwm = ComplementaryPwm::new(
            tim,
            Some(PwmPin::new(high_side, OutputType::PushPull)),
            Some(ComplementaryPwmPin::new(low_side, OutputType::PushPull)),
            None,
            None,
            None,
            None,
            None,
            None,
            Hertz(timing.frequency().hz_rounded()),
            CountingMode::EdgeAlignedUp,
        );
        let tim1 = pac::TIM1;
        // The HAL set MOE; the channel outputs are still disabled (CC1E = CC1NE = 0), so
        // nothing has been driven. Clear MOE before enabling anything.
        tim1.bdtr().modify(|w| w.set_moe(false));
        // DITHEN may only change while the counter is stopped (RM0440, "Dithering mode").
        tim1.cr1().modify(|w| w.set_cen(false));
        tim1.cr2().modify(|w| {
            w.set_ois(CH1, false);
            w.set_oisn(CH1, false);
            w.set_mms2(Mms2::COMPARE_OC4);
        });
        tim1.bdtr().modify(|w| {
            w.set_ossi(Ossi::IDLE_LEVEL);
            w.set_ossr(Ossr::IDLE_LEVEL);
            w.set_aoe(false);
            w.set_bkp(BRK, Bkp::ACTIVE_HIGH);
            w.set_bkf(BRK, BREAK_FILTER);
        });
        tim1.af1().modify(|w| {
            w.set_bkine(false);
            w.set_bkcmpe(COMP1, true);
            w.set_bkcmpp(COMP1, Bkinp::NOT_INVERTED);
        });
        tim1.bdtr().modify(|w| w.set_bke(BRK, true));
        // CH4: PWM mode 2, so OC4REF rises at CCR4 (3/4 period) and TRGO2 starts the ADC there.
        tim1.ccmr_output(1).modify(|w| {
            w.set_ocm(1, Ocm::PWM_MODE2);
            w.set_ocpe(1, true);
        });
        tim1.cr1().modify(|w| {
            w.set_dithen(true);
            w.set_arpe(true);
        });
        write_timing(timing, Amplitude::ZERO);
        // Load the preloaded ARR and CCRs now, then enable the channel outputs: with MOE = 0
        // and OSSI = 1 they are driven to the idle level, low.
        tim1.egr().write(|w| w.set_ug(true));
        tim1.ccer().modify(|w| {
            w.set_cce(CH1, true);
            w.set_ccne(CH1, true);
        });
        clear_break_flag();
        tim1.cr1().modify(|w| w.set_cen(true));
        Self { _pwm: pwm }
    }
}

/// Writes period, dead time, duty for `amplitude` and the ADC trigger. ARR and CCRs are
/// preloaded, so a running timer switches at the next period boundary without a glitch; the
/// dead time applies at once (change it only with the outputs off).
pub fn write_timing(timing: &DriveTiming, amplitude: Amplitude) {
    let tim1 = pac::TIM1;
    tim1.bdtr().modify(|w| w.set_dtg(timing.dead_time().dtg()));
    tim1.arr_dither()
        .write_value(ArrDitherCore(timing.period().arr_register()));
    // stm32-metapac models dither-mode CCRs for CH1-2 only (`ccr_dither(n)` asserts n < 2 and
    // panics at run time for CH4). CCR4 is the same 32-bit register at TIM1 + 0x40 whatever the
    // mode; in dither mode it holds the 20-bit value (16.4) written here raw through `ccr(3)`.
    tim1.ccr(CH4)
        .write_value(Ccr1ch(timing.adc_trigger_compare()));
    set_amplitude(timing, amplitude);
}

/// Sets the duty for `amplitude` (CCR1, dithered), effective at the next period.
pub fn set_amplitude(timing: &DriveTiming, amplitude: Amplitude) {
    pac::TIM1
        .ccr_dither(CH1)
        .write_value(CcrDither1ch(timing.duty_compare(amplitude)));
}

/// Sets MOE: the bridge switches. Refused (returns false) while the break input is active or a
/// break has not been acknowledged with [`clear_break_flag`].
pub fn try_enable_outputs() -> bool {
    if break_tripped() {
        return false;
    }
    pac::TIM1.bdtr().modify(|w| w.set_moe(true));
    pac::TIM1.bdtr().read().moe()
}

/// Whether a break (overcurrent) has occurred since the flag was last cleared.
pub fn break_tripped() -> bool {
    pac::TIM1.sr().read().bif(BRK)
}

/// Acknowledges a break.
pub fn clear_break_flag() {
    pac::TIM1
        .sr()
        .write_value(pac::timer::regs::SrAdv(SR_ALL_BUT_BIF));
}

/// Whether the outputs are enabled (MOE).
pub fn outputs_enabled() -> bool {
    pac::TIM1.bdtr().read().moe()
}

/// Whether the latest current-sense sample was healthy (no rail, a valid code). False until
/// sensing runs. The control loop switches the bridge on only while it is true: the current
/// sense is the safety channel, and its faulty samples make the sensing task clear MOE.
static CURRENT_SENSE_HEALTHY: AtomicBool = AtomicBool::new(false);

/// Records the health of the latest current-sense sample (sensing task).
pub fn set_current_sense_healthy(healthy: bool) {
    CURRENT_SENSE_HEALTHY.store(healthy, Ordering::Relaxed);
}

/// Whether the latest current-sense sample was healthy.
pub fn current_sense_healthy() -> bool {
    CURRENT_SENSE_HEALTHY.load(Ordering::Relaxed)
}
