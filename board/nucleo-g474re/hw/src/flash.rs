//! The settings store's flash: dual-bank mode, and a guard between the store and the flash
//! driver that refuses to program or erase while the bridge's outputs are enabled and erases
//! page by page, feeding the watchdog between pages.
//!
//! Why (RM0440 5.3.8, DS12288): in dual-bank mode (FLASH_OPTR.DBANK = 1, the factory
//! setting) code runs from bank 1 while bank 2 is programmed or erased, but the firmware's
//! store runs inside the control task with a blocking driver, so a page erase (about 22 ms)
//! holds the control loop, and with it the watchdog keeper (fed only while the loop steps),
//! for its whole duration. The store's repair erases every one of its pages in one call
//! (eight pages: some 180 ms against the 47-54 ms watchdog); a fault-log write may erase a
//! page while the bring-up build's button drives the bridge. Hence: no program or erase while
//! TIM1's main output is enabled (BDTR.MOE), and one page per erase call with the watchdog fed
//! before and after each page.

use embedded_storage_async::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};

use crate::pac::flash::Flash;

/// Whether the flash runs in dual-bank mode: FLASH_OPTR.DBANK (bit 22, RM0440 5.7.20), loaded
/// from the option bytes at reset.
pub fn dual_bank(flash: Flash) -> bool {
    flash.optr().read().dbank()
}

/// Whether TIM1's outputs are enabled (BDTR.MOE, bit 15): while it is set the bridge may
/// switch, so the store must not stall the control loop.
pub use crate::tim1::outputs_enabled;

/// What the guarded flash asks of the board.
pub trait FlashGuard {
    /// Whether the bridge's outputs are enabled now (a program or an erase is then refused).
    fn outputs_enabled(&mut self) -> bool;
    /// Feeds the watchdog: called before and after each page erase.
    fn feed_watchdog(&mut self);
}

/// A flash error, or a program or erase refused because the outputs were enabled.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum GuardedError<E> {
    /// Refused: the bridge's outputs were enabled.
    OutputsEnabled,
    /// The flash driver's error.
    Flash(E),
}

impl<E: NorFlashError> NorFlashError for GuardedError<E> {
    fn kind(&self) -> NorFlashErrorKind {
        match self {
            GuardedError::OutputsEnabled => NorFlashErrorKind::Other,
            GuardedError::Flash(e) => e.kind(),
        }
    }
}

/// `flash` behind `guard`: reads pass through; writes are refused while the outputs are
/// enabled; erases are refused likewise (checked before each page) and split into single
/// pages with the watchdog fed before and after each one.
pub struct GuardedFlash<F, G> {
    flash: F,
    guard: G,
}

impl<F, G> GuardedFlash<F, G> {
    /// `flash` behind `guard`.
    pub fn new(flash: F, guard: G) -> Self {
        Self { flash, guard }
    }

    /// The flash and the guard back.
    pub fn release(self) -> (F, G) {
        (self.flash, self.guard)
    }
}

impl<F: ErrorType, G> ErrorType for GuardedFlash<F, G> {
    type Error = GuardedError<F::Error>;
}

impl<F: ReadNorFlash, G> ReadNorFlash for GuardedFlash<F, G> {
    const READ_SIZE: usize = F::READ_SIZE;

    async fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        self.flash
            .read(offset, bytes)
            .await
            .map_err(GuardedError::Flash)
    }

    fn capacity(&self) -> usize {
        self.flash.capacity()
    }
}

impl<F: NorFlash, G: FlashGuard> NorFlash for GuardedFlash<F, G> {
    const WRITE_SIZE: usize = F::WRITE_SIZE;
    const ERASE_SIZE: usize = F::ERASE_SIZE;

    async fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        // ERASE_SIZE is a page: 2 KiB on the G474 in dual-bank mode.
        let page = F::ERASE_SIZE as u32;
        let mut at = from;
        while at < to {
            if self.guard.outputs_enabled() {
                return Err(GuardedError::OutputsEnabled);
            }
            let end = at.saturating_add(page).min(to);
            self.guard.feed_watchdog();
            let erased = self.flash.erase(at, end).await;
            self.guard.feed_watchdog();
            erased.map_err(GuardedError::Flash)?;
            at = end;
        }
        Ok(())
    }

    async fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        if self.guard.outputs_enabled() {
            return Err(GuardedError::OutputsEnabled);
        }
        self.flash
            .write(offset, bytes)
            .await
            .map_err(GuardedError::Flash)
    }
}

#[cfg(test)]
mod tests {
    use std::cell::RefCell;
    use std::rc::Rc;
    use std::vec::Vec;

    use sequential_storage::mock_flash::{MockFlashBase, WriteCountCheck};
    use sonolube::settings::{G474_DUAL_BANK, Record, Store, StoreError};

    use super::*;
    use crate::image::Image;
    use crate::pac::timer::TimAdv;

    /// The store's eight 2 KiB pages of 8-byte words (G474_DUAL_BANK, checked below).
    type Mock = MockFlashBase<8, 8, 256>;

    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    enum Event {
        Feed,
        /// An erase call on the flash, as page indices `first..end`.
        Erase(u32, u32),
        Write,
    }

    type Events = Rc<RefCell<Vec<Event>>>;

    /// The mock flash, recording each erase and write it is asked for.
    struct Recorded {
        flash: Mock,
        events: Events,
    }

    impl ErrorType for Recorded {
        type Error = <Mock as ErrorType>::Error;
    }

    impl ReadNorFlash for Recorded {
        const READ_SIZE: usize = Mock::READ_SIZE;
        async fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
            self.flash.read(offset, bytes).await
        }
        fn capacity(&self) -> usize {
            self.flash.capacity()
        }
    }

    impl NorFlash for Recorded {
        const WRITE_SIZE: usize = Mock::WRITE_SIZE;
        const ERASE_SIZE: usize = Mock::ERASE_SIZE;
        async fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
            let page = Self::ERASE_SIZE as u32;
            self.events
                .borrow_mut()
                .push(Event::Erase(from / page, to.div_ceil(page)));
            self.flash.erase(from, to).await
        }
        async fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
            self.events.borrow_mut().push(Event::Write);
            self.flash.write(offset, bytes).await
        }
    }

    struct Board {
        outputs: Rc<RefCell<bool>>,
        events: Events,
    }

    impl FlashGuard for Board {
        fn outputs_enabled(&mut self) -> bool {
            *self.outputs.borrow()
        }
        fn feed_watchdog(&mut self) {
            self.events.borrow_mut().push(Event::Feed);
        }
    }

    type Guarded = GuardedFlash<Recorded, Board>;

    struct Rig {
        store: Store<Guarded>,
        outputs: Rc<RefCell<bool>>,
        events: Events,
    }

    fn range() -> core::ops::Range<u32> {
        0..G474_DUAL_BANK.store_size()
    }

    fn rig(flash: Mock) -> Rig {
        let outputs = Rc::new(RefCell::new(false));
        let events = Events::default();
        let recorded = Recorded {
            flash,
            events: events.clone(),
        };
        let board = Board {
            outputs: outputs.clone(),
            events: events.clone(),
        };
        let store = Store::new(GuardedFlash::new(recorded, board), range()).expect("whole pages");
        Rig {
            store,
            outputs,
            events,
        }
    }

    fn run<T>(future: impl core::future::Future<Output = T>) -> T {
        embassy_futures::block_on(future)
    }

    fn record(n: u32) -> Record {
        Record {
            cal_count: n,
            ..Record::DEFAULTS
        }
    }

    #[test]
    fn the_mock_has_the_stores_geometry() {
        assert_eq!(Mock::ERASE_SIZE as u32, G474_DUAL_BANK.page);
        assert_eq!(Mock::WRITE_SIZE as u32, G474_DUAL_BANK.word);
        assert_eq!(
            Mock::new(WriteCountCheck::OnceOnly, None, true).capacity() as u32,
            G474_DUAL_BANK.store_size()
        );
    }

    #[test]
    fn a_save_is_refused_while_the_outputs_are_enabled() {
        let mut rig = rig(Mock::new(WriteCountCheck::OnceOnly, None, true));
        run(rig.store.save(&record(1))).unwrap();
        *rig.outputs.borrow_mut() = true;
        rig.events.borrow_mut().clear();
        assert_eq!(run(rig.store.save(&record(2))), Err(StoreError::Flash));
        assert!(
            !rig.events
                .borrow()
                .iter()
                .any(|e| matches!(e, Event::Write | Event::Erase(..))),
            "nothing reached the flash: {:?}",
            rig.events.borrow()
        );
        // The old record is still there, and the store works once the outputs are off.
        *rig.outputs.borrow_mut() = false;
        assert_eq!(run(rig.store.load(|_| true)), Ok(record(1)));
        run(rig.store.save(&record(3))).unwrap();
        assert_eq!(run(rig.store.load(|_| true)), Ok(record(3)));
    }

    /// The store's repair (a map damaged beyond the library's own repair: every page marked
    /// closed) erases all eight pages: one page per erase call, the watchdog fed before and
    /// after each, so it is never left unfed for longer than one page erase.
    #[test]
    fn the_repair_erases_page_by_page_feeding_the_watchdog_between_pages() {
        let mut flash = Mock::new(WriteCountCheck::OnceOnly, None, true);
        let page = G474_DUAL_BANK.page as usize;
        for p in flash.as_bytes_mut().chunks_mut(page) {
            p[..8].fill(0);
            p[page - 8..].fill(0);
        }
        let mut rig = rig(flash);
        run(rig.store.save(&record(4))).expect("repaired");
        assert_eq!(run(rig.store.load(|_| true)), Ok(record(4)));
        let events = rig.events.borrow().clone();
        let erases: Vec<(usize, Event)> = events
            .iter()
            .copied()
            .enumerate()
            .filter(|(_, e)| matches!(e, Event::Erase(..)))
            .collect();
        let pages = G474_DUAL_BANK.store_pages;
        let erased: Vec<u32> = erases
            .iter()
            .map(|&(_, e)| match e {
                Event::Erase(first, end) => {
                    assert_eq!(end, first + 1, "one page per erase call");
                    first
                }
                _ => unreachable!(),
            })
            .collect();
        assert!(
            (0..pages).all(|p| erased.contains(&p)),
            "every page erased: {erased:?}"
        );
        for &(at, _) in &erases {
            assert_eq!(events[at - 1], Event::Feed, "fed before: {events:?}");
            assert_eq!(events[at + 1], Event::Feed, "fed after: {events:?}");
        }
    }

    #[test]
    fn an_erase_stops_at_the_page_where_the_outputs_come_on() {
        let events = Events::default();
        let recorded = Recorded {
            flash: Mock::new(WriteCountCheck::OnceOnly, None, true),
            events: events.clone(),
        };
        /// Outputs come on after `pages` page erases.
        struct OnAfter {
            pages: u32,
            events: Events,
        }
        impl FlashGuard for OnAfter {
            fn outputs_enabled(&mut self) -> bool {
                let erased = self
                    .events
                    .borrow()
                    .iter()
                    .filter(|e| matches!(e, Event::Erase(..)))
                    .count();
                erased as u32 >= self.pages
            }
            fn feed_watchdog(&mut self) {
                self.events.borrow_mut().push(Event::Feed);
            }
        }
        let mut flash = GuardedFlash::new(
            recorded,
            OnAfter {
                pages: 3,
                events: events.clone(),
            },
        );
        let all = G474_DUAL_BANK.store_size();
        assert_eq!(run(flash.erase(0, all)), Err(GuardedError::OutputsEnabled));
        let erased: Vec<Event> = events
            .borrow()
            .iter()
            .copied()
            .filter(|e| matches!(e, Event::Erase(..)))
            .collect();
        assert_eq!(
            erased,
            [Event::Erase(0, 1), Event::Erase(1, 2), Event::Erase(2, 3)]
        );
    }

    /// FLASH_OPTR.DBANK is bit 22 at offset 0x20 (RM0440 5.7.20); the factory option bytes
    /// 0xFFEF_F8AA have it set. TIM1_BDTR.MOE is bit 15 at offset 0x44 (RM0440 28.6.20).
    #[test]
    fn dbank_and_moe_are_read_at_their_rm0440_places() {
        let mut image = Image::new();
        let flash = unsafe { Flash::from_ptr(image.ptr()) };
        image.set_word(0x20, 0xFFEF_F8AA);
        assert!(dual_bank(flash));
        image.set_word(0x20, 0xFFEF_F8AA & !(1 << 22));
        assert!(!dual_bank(flash));
        let mut image = Image::new();
        let tim1 = unsafe { TimAdv::from_ptr(image.ptr()) };
        assert!(!outputs_enabled(tim1));
        image.set_word(0x44, 1 << 15);
        assert!(outputs_enabled(tim1));
        image.set_word(0x44, !(1 << 15));
        assert!(!outputs_enabled(tim1));
    }
}
