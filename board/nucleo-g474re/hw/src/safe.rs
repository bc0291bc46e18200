//! The drive's safe state, callable from anywhere (exception handlers, panic, tasks).
//!
//! Safe means both gate-driver inputs low, so both MOSFETs are off. [`drive_safe`] clears
//! TIM1's main output enable: with OSSI = 1 and OIS1 = OIS1N = 0 ([`crate::tim1::configure`])
//! both outputs go to their idle level, low, at once and in hardware. [`drive_safe_final`]
//! (HardFault, every unexpected exception, panic) then also switches PA8/PB13 from the timer to
//! plain GPIO outputs driven low, so they stay low whatever state TIM1's registers are in.
//! Writes to a peripheral whose clock is off have no effect; its pins are then still in their
//! reset state (high impedance, held low by the gate driver's pull-downs), which is safe.

use crate::Step;
use crate::pac::gpio::Gpio;
use crate::pac::gpio::vals::Moder;
use crate::pac::timer::TimAdv;
use crate::tim1::{HIGH_SIDE_PIN, LOW_SIDE_PIN};

/// Clears MOE: both outputs to their idle (low) level. Idempotent; MOE can be set again.
pub fn drive_safe(tim: TimAdv, hook: &mut impl FnMut(Step)) {
    tim.bdtr().modify(|w| w.set_moe(false));
    hook("TIM1_BDTR");
}

/// [`drive_safe`] first, then PA8 and PB13 as GPIO outputs driven low (output data low before
/// the mode switch, so they never drive high). Nothing re-arms the drive after this.
pub fn drive_safe_final(tim: TimAdv, gpioa: Gpio, gpiob: Gpio, hook: &mut impl FnMut(Step)) {
    drive_safe(tim, hook);
    gpioa.bsrr().write(|w| w.set_br(HIGH_SIDE_PIN, true));
    hook("GPIOA_BSRR");
    gpiob.bsrr().write(|w| w.set_br(LOW_SIDE_PIN, true));
    hook("GPIOB_BSRR");
    gpioa
        .moder()
        .modify(|w| w.set_moder(HIGH_SIDE_PIN, Moder::OUTPUT));
    hook("GPIOA_MODER");
    gpiob
        .moder()
        .modify(|w| w.set_moder(LOW_SIDE_PIN, Moder::OUTPUT));
    hook("GPIOB_MODER");
}

#[cfg(test)]
mod tests {
    use std::vec::Vec;

    use super::*;
    use crate::image::Image;

    #[test]
    fn the_final_safe_state_clears_moe_first_then_drives_both_pins_low_as_gpio() {
        let (mut t, mut a, mut b) = (Image::new(), Image::new(), Image::new());
        // A running drive: MOE and the lock set (BDTR 0x44), pins in AF mode.
        t.set_word(0x44, (1 << 15) | (3 << 8) | 0x22);
        a.set_word(0x00, 0b10 << 16);
        b.set_word(0x00, 0b10 << 26);
        // SAFETY: the images outlive the handles.
        let (tim, gpioa, gpiob) = unsafe {
            (
                TimAdv::from_ptr(t.ptr()),
                Gpio::from_ptr(a.ptr()),
                Gpio::from_ptr(b.ptr()),
            )
        };
        let tp = &*t as *const Image;
        let mut steps = Vec::new();
        drive_safe_final(tim, gpioa, gpiob, &mut |s| {
            // SAFETY: reading our image between writes.
            steps.push((s, unsafe { (*tp).bit(0x44, 15) }));
        });
        let names: Vec<_> = steps.iter().map(|(s, _)| *s).collect();
        assert_eq!(
            names,
            [
                "TIM1_BDTR",
                "GPIOA_BSRR",
                "GPIOB_BSRR",
                "GPIOA_MODER",
                "GPIOB_MODER"
            ]
        );
        assert!(
            steps.iter().all(|(_, moe)| !moe),
            "MOE cleared by the first write"
        );
        assert_eq!(t.word(0x44), (3 << 8) | 0x22, "only MOE changed");
        assert_eq!(a.word(0x18), 1 << (16 + 8), "PA8 reset (BR8)");
        assert_eq!(b.word(0x18), 1 << (16 + 13), "PB13 reset (BR13)");
        assert_eq!(a.bits(0x00, 16, 2), 0b01, "PA8 general-purpose output");
        assert_eq!(b.bits(0x00, 26, 2), 0b01, "PB13 general-purpose output");
    }

    #[test]
    fn drive_safe_only_clears_moe() {
        let mut t = Image::new();
        t.set_word(0x44, 0xFFFF_FFFF);
        // SAFETY: the image outlives the handle.
        drive_safe(unsafe { TimAdv::from_ptr(t.ptr()) }, &mut |_| {});
        assert_eq!(t.word(0x44), !(1 << 15));
    }
}
