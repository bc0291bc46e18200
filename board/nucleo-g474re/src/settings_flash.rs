//! The settings store on the G474's own flash: the last eight 2 KiB pages of bank 2
//! ([`sonolube::settings::G474_DUAL_BANK`]; `memory.x` keeps the image in bank 1), through
//! embassy-stm32's blocking flash driver behind embassy-embedded-hal's `BlockingAsync` adapter
//! (the store's futures complete on their first poll) and the guard of
//! [`sonolube_g474_hw::flash`]: no program or erase while TIM1's MOE is set, erases one page at
//! a time with the watchdog fed before and after each page. Also the board's side of the
//! settings ([`Persistent`] for [`BoardRig`]) and the reset cause for the boot log.
//!
//! The firmware is built `dual-bank`, the G474's factory setting (option bytes 0xFFEF_F8AA,
//! DBANK = 1): code runs from bank 1 while bank 2 is erased or programmed. When the option
//! bytes say single-bank (DBANK = 0, someone changed them) the store stays closed, `save` and
//! `load` answer `storage-failed`, and the board runs with the scene's defaults (embassy's
//! driver would panic on the mismatch).

use embassy_embedded_hal::adapter::BlockingAsync;
use embassy_stm32::Peri;
use embassy_stm32::flash::{Blocking, Flash};
use embassy_stm32::peripherals::FLASH;
use sonolube::control::Reason;
use sonolube::fx::{Q1_31, Q16_16};
use sonolube::protocol::{Command, ProtocolError, SceneName, SupervisorState};
use sonolube::sense::Calibration;
use sonolube::settings::{G474_DUAL_BANK, Record, Store};
use sonolube_app::control::ControlLoop;
use sonolube_app::persist::Persistent;
use sonolube_g474_hw::flash::{FlashGuard, GuardedFlash, dual_bank, outputs_enabled};
use sonolube_g474_hw::iwdg;

use crate::rig::BoardRig;

// embassy's page and word in dual-bank mode are the layout's (a single-bank build would see
// 4 KiB pages here).
const _: () = assert!(embassy_stm32::flash::MAX_ERASE_SIZE == G474_DUAL_BANK.page as usize);
const _: () = assert!(embassy_stm32::flash::WRITE_SIZE == G474_DUAL_BANK.word as usize);
const _: () = assert!(embassy_stm32::flash::FLASH_SIZE == G474_DUAL_BANK.size as usize);

/// The board's guard: TIM1's MOE and the IWDG.
pub struct BoardGuard;

impl FlashGuard for BoardGuard {
    fn outputs_enabled(&mut self) -> bool {
        outputs_enabled(embassy_stm32::pac::TIM1)
    }

    /// A reload (KR = 0xAAAA); harmless before the watchdog is started (the store runs at
    /// boot, before the control loop's first step starts it).
    fn feed_watchdog(&mut self) {
        iwdg::pet(embassy_stm32::pac::IWDG)
    }
}

/// The flash as the store sees it.
pub type SettingsFlash = GuardedFlash<BlockingAsync<Flash<'static, Blocking>>, BoardGuard>;

/// The store on the last pages of bank 2, or `None` (logged) when the flash is in single-bank
/// mode.
pub fn open(flash: Peri<'static, FLASH>) -> Option<Store<SettingsFlash>> {
    if !dual_bank(embassy_stm32::pac::FLASH) {
        defmt::error!(
            "settings: the flash is in single-bank mode (option bit DBANK = 0); this build expects the factory dual-bank mode (2 KiB pages, store in bank 2): no settings store"
        );
        return None;
    }
    let driver = GuardedFlash::new(BlockingAsync::new(Flash::new_blocking(flash)), BoardGuard);
    match Store::new(driver, G474_DUAL_BANK.store_offsets()) {
        Ok(store) => Some(store),
        Err(error) => {
            defmt::error!("settings: store refused its range: {}", error);
            None
        }
    }
}

/// Whether the last reset came from a watchdog (IWDG or WWDG), read from RCC_CSR; clears
/// the reset flags (RMVF) so that the next reset is told apart.
pub fn after_watchdog_reset() -> bool {
    let rcc = embassy_stm32::pac::RCC;
    let csr = rcc.csr().read();
    rcc.csr().modify(|w| w.set_rmvf(true));
    csr.iwdgrstf() || csr.wwdgrstf()
}

/// Whether this firmware has a scene of this name.
pub fn known_scene(name: &str) -> bool {
    crate::scene_start::find(name).is_some()
}

impl Persistent for BoardRig {
    fn capture(&self) -> Record {
        sonolube::settings::capture(self.station(), self.scene().name, 0)
    }

    fn commissioned(&self) -> Option<sonolube::commission::CommissionResult> {
        self.station().commissioned()
    }

    /// The record's scene (the default scene when it has none) is selected afresh, which
    /// restores the scene's own calibration, drive frequency and no target; then the record's
    /// calibrations go into the cells, its frequency to the station and TIM1, the
    /// commissioned values to the station (f0 to TIM1 first, to its cHz), its target to the
    /// controller. The record's values passed their range checks, so the last ones are
    /// not refused (a refusal is returned, with the scene already switched).
    fn apply(
        &mut self,
        record: &Record,
        commissioned: Option<&sonolube::commission::CommissionResult>,
    ) -> Result<(), ProtocolError> {
        let name = match record.scene {
            Some(name) => name,
            None => SceneName::new(crate::DEFAULT_SCENE).ok_or(ProtocolError::SettingsInvalid {
                reason: "no-default-scene",
            })?,
        };
        self.execute(&Command::Scene(name))?;
        let (normal, tangential) = self.station_mut().channels_mut();
        for (channel, cal) in [(normal, record.normal), (tangential, record.tangential)] {
            if let Some(cal) = cal {
                channel.set_calibration(Calibration::new(
                    Q1_31::from_bits(cal.offset_q31),
                    Q16_16::from_bits(cal.span_q16),
                ));
            }
        }
        if let Some(freq_chz) = record.freq_chz {
            self.execute(&Command::Freq { freq_chz })?;
        }
        if let Some(result) = commissioned {
            // f0 is in 20-60 kHz (checked when read): rounding by adding a half.
            let freq_chz = (result.resonance_hz.value * 100.0 + 0.5) as u32;
            self.execute(&Command::Freq { freq_chz })?;
            self.station_mut().apply_commissioned(result).map_err(|_| {
                ProtocolError::SettingsInvalid {
                    reason: "commissioning-refused-by-controller",
                }
            })?;
        }
        if let Some(target) = record.target {
            self.execute(&Command::Target(target))?;
        }
        Ok(())
    }

    fn state(&self) -> SupervisorState {
        self.station().state()
    }

    fn latched_fault(&self) -> Option<Reason> {
        self.station().controller().fault()
    }
}
