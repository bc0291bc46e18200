//! Safe state of the drive output, callable from anywhere (exception handlers, panic, tasks):
//! the host-tested `sonolube_g474_hw::safe` functions on the real TIM1 and GPIO ports.
//!
//! - on reset, PA8 and PB13 are analog inputs (high impedance); the 10 kOhm pull-downs on the
//!   gate-driver inputs (board README) hold them low until the firmware takes over;
//! - once [`crate::drive`] has configured TIM1, clearing the main output enable (BDTR.MOE)
//!   forces both outputs to their idle level, low (CR2.OIS1 = OIS1N = 0 with BDTR.OSSI = 1),
//!   at once and in hardware; the break inputs (comparators, core lockup) clear MOE the same
//!   way without software;
//! - after a panic, a HardFault or any unexpected exception, the pins are additionally switched
//!   from the timer to plain GPIO outputs driven low ([`drive_safe_final`]).

use embassy_stm32::pac;
use sonolube_g474_hw::safe;

/// Forces the drive outputs to their idle (off) level by clearing TIM1's main output enable.
/// Idempotent; the drive can be re-armed afterwards by setting MOE again.
pub fn drive_safe() {
    safe::drive_safe(pac::TIM1, &mut |_| {});
}

/// The fault path: [`drive_safe`], then both gate-driver pins as GPIO outputs driven low.
/// Final: nothing re-arms the drive after this.
pub fn drive_safe_final() {
    safe::drive_safe_final(pac::TIM1, pac::GPIOA, pac::GPIOB, &mut |_| {});
}
