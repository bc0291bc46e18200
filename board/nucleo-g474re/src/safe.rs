//! Safe state of the drive output, callable from anywhere (panic, fault, task).
//!
//! The power stage is driven by TIM1's complementary outputs. Clearing the main output enable
//! (BDTR.MOE) forces every TIM1 output to its idle level at once, without software in the loop
//! afterwards; the break input does the same in hardware on overcurrent. Writing the register
//! needs no driver object, so the panic handler can do it before anything else.

use embassy_stm32::pac;

/// Forces the drive outputs to their idle (off) level. Idempotent; safe to call before the
/// timer is set up (a write to a timer whose clock is off has no effect, and its outputs are
/// then still in their reset state, which is off).
pub fn drive_safe() {
    pac::TIM1.bdtr().modify(|w| w.set_moe(false));
}
