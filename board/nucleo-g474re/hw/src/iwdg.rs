//! The independent watchdog on the LSI (32 kHz nominal; 29.5-34 kHz over the STM32G474's
//! range, so a 50 ms setting resets after 47-54 ms).
//!
//! Start sequence (RM0440, IWDG "Window option disabled"): KR = 0xCCCC (start; the LSI turns
//! on), KR = 0x5555 (unlock PR and RLR), PR, RLR, wait until SR.PVU = SR.RVU = 0, KR = 0xAAAA
//! (reload). Once started, nothing but a reset stops it.

use crate::Step;
use crate::pac::iwdg::Iwdg;
use crate::pac::iwdg::vals::{Key, Pr};

/// Nominal LSI, Hz.
pub const LSI_HZ: u32 = 32_000;
/// Largest reload value (12 bits).
const RELOAD_MAX: u32 = 0xFFF;

/// A prescaler and reload pair.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Setting {
    /// PR code: the divider is `4 << code` (0..=6: /4 to /256).
    pub prescaler_code: u8,
    /// RLR: the counter counts down from this to 0, `reload + 1` ticks.
    pub reload: u16,
}

impl Setting {
    /// The finest setting whose timeout is `timeout_us` on the nominal LSI, rounded to the
    /// nearest tick. None if zero or beyond the longest (32.8 s at /256).
    pub const fn for_timeout_us(timeout_us: u32) -> Option<Self> {
        if timeout_us == 0 {
            return None;
        }
        let mut code = 0u8;
        while code <= 6 {
            let divider = 4u64 << code;
            // ticks = timeout * LSI / divider, rounded.
            let ticks =
                (timeout_us as u64 * LSI_HZ as u64 + divider * 500_000) / (divider * 1_000_000);
            if ticks >= 1 && ticks <= RELOAD_MAX as u64 + 1 {
                return Some(Self {
                    prescaler_code: code,
                    reload: (ticks - 1) as u16,
                });
            }
            code += 1;
        }
        None
    }

    /// The timeout this setting gives on an LSI of `lsi_hz`, us (rounded down).
    pub const fn timeout_us(self, lsi_hz: u32) -> u32 {
        let ticks = self.reload as u64 + 1;
        let divider = 4u64 << self.prescaler_code;
        (ticks * divider * 1_000_000 / lsi_hz as u64) as u32
    }
}

/// Starts the watchdog with `setting`. `max_polls` bounds the wait for the prescaler and reload
/// to reach the LSI domain (a few LSI cycles, 125 us at most); false if it did not end in time
/// (the watchdog then runs with the values being loaded, and the reload is still written).
pub fn start(iwdg: Iwdg, setting: Setting, max_polls: u32, hook: &mut impl FnMut(Step)) -> bool {
    iwdg.kr().write(|w| w.set_key(Key::START));
    hook("IWDG_KR");
    iwdg.kr().write(|w| w.set_key(Key::ENABLE));
    hook("IWDG_KR");
    iwdg.pr()
        .write(|w| w.set_pr(Pr::from_bits(setting.prescaler_code)));
    hook("IWDG_PR");
    iwdg.rlr().write(|w| w.set_rl(setting.reload));
    hook("IWDG_RLR");
    let mut polls = 0;
    let mut settled = false;
    while polls < max_polls {
        let sr = iwdg.sr().read();
        if !sr.pvu() && !sr.rvu() {
            settled = true;
            break;
        }
        polls += 1;
    }
    iwdg.kr().write(|w| w.set_key(Key::RESET));
    hook("IWDG_KR");
    settled
}

/// Reloads the counter (feeds the watchdog).
pub fn pet(iwdg: Iwdg) {
    iwdg.kr().write(|w| w.set_key(Key::RESET));
}

#[cfg(test)]
mod tests {
    use std::vec::Vec;

    use super::*;
    use crate::image::Image;

    #[test]
    fn fifty_ms_on_the_lsi() {
        let setting = Setting::for_timeout_us(50_000).unwrap();
        // /4: 8 kHz ticks, 400 ticks.
        assert_eq!(
            setting,
            Setting {
                prescaler_code: 0,
                reload: 399
            }
        );
        assert_eq!(setting.timeout_us(LSI_HZ), 50_000);
        // The LSI's spread (29.5-34 kHz): 54.2 ms and 47.1 ms.
        assert_eq!(setting.timeout_us(29_500), 54_237);
        assert_eq!(setting.timeout_us(34_000), 47_058);
        // Longer timeouts take coarser prescalers; out-of-range ones are refused.
        assert_eq!(
            Setting::for_timeout_us(1_000_000)
                .unwrap()
                .timeout_us(LSI_HZ),
            1_000_000
        );
        assert_eq!(Setting::for_timeout_us(0), None);
        assert_eq!(Setting::for_timeout_us(40_000_000), None);
    }

    #[test]
    fn the_start_sequence_in_rm0440s_order() {
        let mut image = Image::new();
        let ptr = &*image as *const Image;
        let mut keys = Vec::new();
        // SAFETY: the image outlives the handle.
        let iwdg = unsafe { Iwdg::from_ptr(image.ptr()) };
        let settled = start(
            iwdg,
            Setting::for_timeout_us(50_000).unwrap(),
            100,
            &mut |s| {
                // SAFETY: reading our image between writes. KR 0x00, PR 0x04, RLR 0x08.
                let word = unsafe {
                    (*ptr).word(match s {
                        "IWDG_KR" => 0x00,
                        "IWDG_PR" => 0x04,
                        _ => 0x08,
                    })
                };
                keys.push((s, word));
            },
        );
        assert!(settled);
        assert_eq!(
            keys,
            [
                ("IWDG_KR", 0xCCCC),
                ("IWDG_KR", 0x5555),
                ("IWDG_PR", 0),
                ("IWDG_RLR", 399),
                ("IWDG_KR", 0xAAAA)
            ]
        );
        // SR (0x0C) never clearing: bounded wait, reported.
        image.set_word(0x0C, 0b11);
        // SAFETY: as above.
        let iwdg = unsafe { Iwdg::from_ptr(image.ptr()) };
        assert!(!start(
            iwdg,
            Setting::for_timeout_us(50_000).unwrap(),
            100,
            &mut |_| {}
        ));
        assert_eq!(image.word(0x00), 0xAAAA, "reloaded anyway");
    }
}
