//! The clock source: the NUCLEO-G474RE's 24 MHz HSE crystal (X3; ST fits 24 MHz crystals on the
//! G431RB/G474RE/G491RE Nucleo-64 boards, MB1367) through the PLL to 170 MHz, with HSI16 as the
//! fallback when the crystal does not start. With HSE, a 40 kHz drive is as accurate as the
//! crystal (tens of ppm: about 1 Hz) instead of HSI16's +-1 % (+-400 Hz).
//!
//! [`start_hse`] runs before embassy's clock setup, which waits for HSERDY without a timeout:
//! only a crystal that is already running is handed to it.

use crate::Step;
use crate::pac::flash::Flash;
use crate::pac::flash::vals::Latency;
use crate::pac::rcc::Rcc;

/// The crystal, Hz.
pub const HSE_HZ: u32 = 24_000_000;
/// HSI16, Hz.
pub const HSI_HZ: u32 = 16_000_000;
/// PLL from HSE: /6 (4 MHz into the VCO), x85 (340 MHz VCO), R /2.
pub const HSE_PLL: Pll = Pll {
    prediv: 6,
    mul: 85,
    divr: 2,
};
/// PLL from HSI16: /4, x85, R /2.
pub const HSI_PLL: Pll = Pll {
    prediv: 4,
    mul: 85,
    divr: 2,
};
/// SYSCLK, Hz.
pub const SYSCLK_HZ: u32 = 170_000_000;
/// Flash wait states at 170 MHz in range 1 boost mode (RM0440, "Number of wait states
/// according to CPU clock frequency": 4 WS for 136-170 MHz).
pub const FLASH_LATENCY: Latency = Latency::WS4;

/// PLL dividers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Pll {
    /// PLLM.
    pub prediv: u32,
    /// PLLN.
    pub mul: u32,
    /// PLLR.
    pub divr: u32,
}

impl Pll {
    /// The PLL's input (VCO input), VCO and R output for `source_hz`, Hz.
    pub const fn frequencies(self, source_hz: u32) -> (u32, u32, u32) {
        let input = source_hz / self.prediv;
        let vco = input * self.mul;
        (input, vco, vco / self.divr)
    }
}

/// The outcome of [`start_hse`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum HseStart {
    /// HSERDY rose after this many polls.
    Ready { polls: u32 },
    /// HSERDY did not rise within the polls: HSE switched off again, use HSI16.
    TimedOut,
}

/// Switches the crystal oscillator on (HSEBYP = 0) and waits up to `max_polls` polls of HSERDY,
/// calling `wait` between polls (the firmware busy-waits 1 us there). On timeout HSEON is
/// cleared again.
pub fn start_hse(
    rcc: Rcc,
    max_polls: u32,
    mut wait: impl FnMut(),
    hook: &mut impl FnMut(Step),
) -> HseStart {
    rcc.cr().modify(|w| {
        w.set_hsebyp(false);
        w.set_hseon(true);
    });
    hook("RCC_CR");
    let mut polls = 0;
    while polls < max_polls {
        if rcc.cr().read().hserdy() {
            return HseStart::Ready { polls };
        }
        wait();
        polls += 1;
    }
    if rcc.cr().read().hserdy() {
        return HseStart::Ready { polls };
    }
    rcc.cr().modify(|w| w.set_hseon(false));
    hook("RCC_CR");
    HseStart::TimedOut
}

/// Clock security system: a crystal failure switches SYSCLK to HSI16, raises an NMI and breaks
/// TIM1 (RM0440, "Clock security system"). Call once the system runs on HSE.
pub fn enable_css(rcc: Rcc, hook: &mut impl FnMut(Step)) {
    rcc.cr().modify(|w| w.set_csson(true));
    hook("RCC_CR");
}

/// FLASH_ACR for 170 MHz: 4 wait states, prefetch, instruction and data caches on.
pub fn configure_flash(flash: Flash, hook: &mut impl FnMut(Step)) {
    flash.acr().modify(|w| {
        w.set_latency(FLASH_LATENCY);
        w.set_prften(true);
        w.set_icen(true);
        w.set_dcen(true);
    });
    hook("FLASH_ACR");
}

#[cfg(test)]
mod tests {
    use std::cell::Cell;

    use super::*;
    use crate::image::Image;

    #[test]
    fn both_plls_give_170_mhz_within_the_pll_limits() {
        for (pll, source) in [(HSE_PLL, HSE_HZ), (HSI_PLL, HSI_HZ)] {
            let (input, vco, out) = pll.frequencies(source);
            assert_eq!(input, 4_000_000);
            // RM0440: VCO input 2.66-8 MHz, VCO 96-344 MHz.
            assert!((2_660_000..=8_000_000).contains(&input));
            assert!((96_000_000..=344_000_000).contains(&vco));
            assert_eq!(out, SYSCLK_HZ);
        }
    }

    fn rcc(image: &mut Image) -> Rcc {
        // SAFETY: the image outlives the handle.
        unsafe { Rcc::from_ptr(image.ptr()) }
    }

    #[test]
    fn a_crystal_that_starts_is_used() {
        // RM0440 RCC_CR at 0x00: HSEON 16, HSERDY 17, HSEBYP 18, CSSON 19.
        let mut image = Image::new();
        image.set_word(0x00, 1 << 18); // a stale HSEBYP
        let ptr = &mut *image as *mut Image;
        let polls = Cell::new(0);
        let outcome = start_hse(
            rcc(&mut image),
            2000,
            || {
                // The oscillator stabilises after 300 polls.
                polls.set(polls.get() + 1);
                if polls.get() == 300 {
                    // SAFETY: our image, between the accessor's reads.
                    unsafe { (*ptr).set_word(0x00, (*ptr).word(0x00) | (1 << 17)) };
                }
            },
            &mut |_| {},
        );
        assert_eq!(outcome, HseStart::Ready { polls: 300 });
        assert!(image.bit(0x00, 16), "HSEON");
        assert!(
            !image.bit(0x00, 18),
            "HSEBYP cleared: a crystal, not an external clock"
        );
        enable_css(rcc(&mut image), &mut |_| {});
        assert!(image.bit(0x00, 19), "CSSON");
    }

    #[test]
    fn a_crystal_that_does_not_start_times_out_and_is_switched_off() {
        let mut image = Image::new();
        let waits = Cell::new(0u32);
        let mut steps = std::vec::Vec::new();
        let outcome = start_hse(
            rcc(&mut image),
            2000,
            || waits.set(waits.get() + 1),
            &mut |s| steps.push(s),
        );
        assert_eq!(outcome, HseStart::TimedOut);
        assert_eq!(waits.get(), 2000, "waited the whole timeout");
        assert!(!image.bit(0x00, 16), "HSEON cleared again");
        assert_eq!(steps, ["RCC_CR", "RCC_CR"]);
    }

    #[test]
    fn flash_wait_states_and_accelerators() {
        let mut image = Image::new();
        // SAFETY: the image outlives the handle.
        configure_flash(unsafe { Flash::from_ptr(image.ptr()) }, &mut |_| {});
        // RM0440 FLASH_ACR at 0x00: LATENCY 0-3, PRFTEN 8, ICEN 9, DCEN 10.
        assert_eq!(image.bits(0x00, 0, 4), 4);
        assert!(image.bit(0x00, 8) && image.bit(0x00, 9) && image.bit(0x00, 10));
    }
}
