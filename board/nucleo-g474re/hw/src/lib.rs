//! Every register the NUCLEO-G474RE firmware programs itself, as functions that take the
//! stm32-metapac peripheral handle as an argument (`pac::TIM1` in the firmware, a handle on a RAM
//! image in the tests), so the register programming runs in `cargo test` on the host.
//!
//! | module | peripherals |
//! |---|---|
//! | [`tim1`] | TIM1 (drive, dithering, dead time, break/break2, TRGO2 for ADC2, CC3 for ADC1, lock), its clock and pins |
//! | [`safe`] | the safe state (MOE cleared, PA8/PB13 driven low as GPIO) |
//! | [`protect`] | COMP1 + DAC3 (stack current), COMP3 + DAC1 (bus shunt), SYSCFG_CFGR2, DBGMCU |
//! | [`adc`] | ADC1 regular sequence, trigger, oversampling, DMA mode; DMA1/DMAMUX check |
//! | [`current`] | ADC2 (drive current) at the stepped trigger phases: CCR4 table by DMA on TIM1_UP, ADC2 ring |
//! | [`iwdg`] | the independent watchdog (50 ms on the 32 kHz LSI) |
//! | [`clock`] | HSE start with timeout, clock security, FLASH_ACR |
//! | [`flash`] | FLASH_OPTR.DBANK; the settings store's guard (no program or erase with MOE set, erase page by page feeding the watchdog) |
//!
//! Each writing function calls `hook(step)` after every register write, `step` naming the
//! register (`"TIM1_BDTR"`). The firmware passes `&mut |_| {}`, which inlines away; the tests
//! snapshot the image at every step and check the invariants that depend on the order of writes
//! (MOE never set while outputs are configured, no update event between a new ARR and its CCRs).
//! Register layouts: RM0440 rev 8 (STM32G4 reference manual).
#![cfg_attr(not(test), no_std)]

pub use stm32_metapac as pac;

pub mod adc;
pub mod clock;
pub mod current;
pub mod flash;
pub mod iwdg;
pub mod protect;
pub mod safe;
pub mod tim1;

#[cfg(test)]
mod image;

/// The register a function has just written, e.g. `"TIM1_CR1"`.
pub type Step = &'static str;
