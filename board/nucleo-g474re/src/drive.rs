//! TIM1 as the half-bridge drive: the pure timing of `sonolube::drive` written to registers by
//! the host-tested functions of `sonolube-g474-hw` (`hw::tim1`), pointed at the real TIM1.
//!
//! The firmware owns TIM1 without an embassy driver: `ComplementaryPwm` writes BDTR in its
//! constructor, which freezes BDTR's LOCK field at 0 (RM0440: LOCK is written once after
//! reset), so the lock, the dead time and the break setup could never be locked afterwards.
//! [`Drive::new`] resets TIM1, configures it (BDTR once, locked, MOE = 0), then connects
//! PA8/PB13 (AF6), routes the system break sources to TIM1 (SYSCFG_CFGR2) and freezes TIM1 on a
//! debug halt (DBGMCU).
//!
//! Outputs stay off (BDTR.MOE = 0) after [`Drive::new`]; only [`try_enable_outputs`] sets MOE:
//! the control loop's [`crate::bridge`] in the normal build, the hold-to-run button in the
//! bring-up build.

use core::sync::atomic::{AtomicBool, Ordering};

use embassy_stm32::Peri;
use embassy_stm32::pac;
use embassy_stm32::peripherals::{PA8, PB13, TIM1};
use sonolube::drive::{Amplitude, DriveTiming};
use sonolube_g474_hw::{protect, tim1};

use crate::{current, safe};

/// TIM1 and its two pins, owned and configured as the drive. Keep it alive.
pub struct Drive {
    _tim: Peri<'static, TIM1>,
    _high_side: Peri<'static, PA8>,
    _low_side: Peri<'static, PB13>,
}

impl Drive {
    /// Claims TIM1 with CH1 on PA8 and CH1N on PB13, and configures it for `timing` with the
    /// outputs off, BRK fed by COMP1, BRK2 by COMP3 and COMP6, CC3 triggering ADC1 at 3/4 of the
    /// period and TRGO2 (CCR4) ADC2, and BDTR locked. The counter runs afterwards (the ADC needs its triggers), the
    /// outputs do not. Err when TIM1 refused the configuration (it then stays off).
    pub fn new(
        tim: Peri<'static, TIM1>,
        high_side: Peri<'static, PA8>,
        low_side: Peri<'static, PB13>,
        timing: &DriveTiming,
    ) -> Result<Self, tim1::Refused> {
        tim1::enable_clock(pac::RCC, &mut |_| {});
        tim1::configure(pac::TIM1, timing, &mut |_| {})?;
        tim1::connect_pins(pac::GPIOA, pac::GPIOB, &mut |_| {});
        protect::lock_system_breaks(pac::SYSCFG, &mut |_| {});
        protect::freeze_tim1_on_halt(pac::DBGMCU, &mut |_| {});
        // Bring-up: a debugger may halt the core without a watchdog reset (the bridge then
        // resumes at its old duty when the core resumes: README, step 5). Field builds keep
        // the watchdog running, so a long halt ends in a reset with the drive safe.
        #[cfg(feature = "bringup")]
        protect::freeze_watchdog_on_halt(pac::DBGMCU, &mut |_| {});
        Ok(Self {
            _tim: tim,
            _high_side: high_side,
            _low_side: low_side,
        })
    }
}

/// Writes period and duty for `amplitude` together (update events held off during the write),
/// and the ADC trigger: CCR4 itself until the stepped current sampling runs, afterwards
/// [`current::change_timing`] (the table and CCR4 kept below the smaller ARR across the change,
/// so no conversion is lost; an update event suppressed by the write is counted there). A
/// timing whose dead time differs from the locked one is refused: logged, and the drive made
/// safe.
pub fn write_timing(timing: &DriveTiming, amplitude: Amplitude) {
    if current::running() {
        if let Err(refused) = current::change_timing(timing, amplitude) {
            safe::drive_safe();
            defmt::error!("TIM1 timing refused: {}", refused);
        }
    } else if let Err(refused) = cortex_m::interrupt::free(|_| {
        // The UDIS window must not be stretched past a period by an interrupt.
        tim1::write_timing(pac::TIM1, timing, amplitude, &mut |_| {})
    }) {
        safe::drive_safe();
        defmt::error!("TIM1 timing refused: {}", refused);
    }
}

/// Sets the duty for `amplitude` (CCR1, dithered), effective at the next period, and moves the
/// stepped ADC trigger's table with the fundamental's maximum (CCR1/2).
pub fn set_amplitude(timing: &DriveTiming, amplitude: Amplitude) {
    tim1::set_amplitude(pac::TIM1, timing, amplitude, &mut |_| {});
    current::follow_drive(timing, amplitude);
}

/// Sets MOE: the bridge switches. Refused (returns false) while a break flag is set; false too
/// when the break input went active as MOE was set.
pub fn try_enable_outputs() -> bool {
    tim1::try_enable_outputs(pac::TIM1, &mut |_| {})
}

/// Whether a break (stack or DC-link overcurrent, or a system break) has occurred since the
/// flags were last cleared.
pub fn break_tripped() -> bool {
    tim1::break_tripped(pac::TIM1)
}

/// Acknowledges the breaks.
pub fn clear_break_flag() {
    tim1::clear_break_flags(pac::TIM1, &mut |_| {});
}

/// Whether the outputs are enabled (MOE).
pub fn outputs_enabled() -> bool {
    tim1::outputs_enabled(pac::TIM1)
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
