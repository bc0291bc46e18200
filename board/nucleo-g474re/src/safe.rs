//! Safe state of the drive output, callable from anywhere (panic, fault, task).
//!
//! The half-bridge is driven by TIM1 CH1 (PA8, high side) and CH1N (PB13, low side). Safe
//! means both gate-driver inputs low, so both MOSFETs are off:
//! - on reset, PA8 and PB13 are analog inputs (high impedance); the 10 kOhm pull-downs on the
//!   gate-driver inputs (board README) hold them low until the firmware takes over;
//! - once [`crate::drive`] has configured TIM1, clearing the main output enable (BDTR.MOE)
//!   forces both outputs to their idle level, low (CR2.OIS1 = OIS1N = 0 with BDTR.OSSI = 1),
//!   at once and in hardware; the break input (COMP1 on overcurrent) clears MOE the same way
//!   without software (RM0440, advanced-control timers, "Using the break function");
//! - after a panic, the pins are additionally switched from the timer to plain GPIO outputs
//!   driven low, so they stay low even if TIM1's registers are in an unexpected state.
//!
//! Writing registers needs no driver object, so the panic handler can do it before anything
//! else. A write to a peripheral whose clock is off has no effect; its pins are then still in
//! their reset state, which is safe.

use embassy_stm32::pac;
use embassy_stm32::pac::gpio::vals::Moder;

/// PA8: TIM1_CH1, high-side gate-driver input.
const HIGH_SIDE_PIN: usize = 8;
/// PB13: TIM1_CH1N, low-side gate-driver input.
const LOW_SIDE_PIN: usize = 13;

/// Forces the drive outputs to their idle (off) level by clearing TIM1's main output enable.
/// Idempotent; the drive can be re-armed afterwards (bring-up build) by setting MOE again.
pub fn drive_safe() {
    pac::TIM1.bdtr().modify(|w| w.set_moe(false));
}

/// The panic path: [`drive_safe`], then both gate-driver pins as GPIO outputs driven low.
/// Final: nothing re-arms the drive after this.
pub fn drive_safe_final() {
    drive_safe();
    // Output data low first, then the mode switch, so the pins never drive high.
    pac::GPIOA.bsrr().write(|w| w.set_br(HIGH_SIDE_PIN, true));
    pac::GPIOB.bsrr().write(|w| w.set_br(LOW_SIDE_PIN, true));
    pac::GPIOA
        .moder()
        .modify(|w| w.set_moder(HIGH_SIDE_PIN, Moder::OUTPUT));
    pac::GPIOB
        .moder()
        .modify(|w| w.set_moder(LOW_SIDE_PIN, Moder::OUTPUT));
}
