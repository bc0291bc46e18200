//! Where the store lives in a board's flash: the facts the G474 build relies on (and the QEMU
//! board copies, so that both run the same store configuration), checked by host tests against
//! the linker script that keeps code out of the store's pages.

use core::ops::Range;

/// A flash and the pages at its end that the settings store owns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FlashLayout {
    /// Address of the first flash byte.
    pub base: u32,
    /// Bytes of flash.
    pub size: u32,
    /// Erase page, bytes.
    pub page: u32,
    /// Programming unit, bytes.
    pub word: u32,
    /// Pages at the end of the flash given to the store.
    pub store_pages: u32,
    /// Banks the flash is split into (1, or 2 for read-while-write): in a two-bank flash the
    /// code lives in the first bank and the store in the last pages of the second, so that an
    /// erase or a program of the store never stalls instruction fetch (RM0440, 5.3.8).
    pub banks: u32,
}

/// The STM32G474RE in single-bank mode (option bit DBANK = 0): 512 KiB in 128 pages of
/// 4 KiB, programmed by 64-bit double words (RM0440, 5.3.1 and 5.3.7). The store takes the
/// last four pages, 0x0807_C000..0x0808_0000. The QEMU board's flash file has this geometry;
/// the NUCLEO-G474RE runs [`G474_DUAL_BANK`] (the factory setting).
pub const G474_SINGLE_BANK: FlashLayout = FlashLayout {
    base: 0x0800_0000,
    size: 512 * 1024,
    page: 4096,
    word: 8,
    store_pages: 4,
    banks: 1,
};

/// The STM32G474RE in dual-bank mode (option bit DBANK = 1, as it leaves the factory:
/// option bytes 0xFFEF_F8AA; the `dual-bank` feature of embassy-stm32): two banks of 256 KiB
/// in 128 pages of 2 KiB each, bank 2 at 0x0804_0000, programmed by 64-bit double words
/// (RM0440, 5.3.1). The code stays in bank 1 (`memory.x`: 256 KiB); the store takes the last
/// eight pages of bank 2, 0x0807_C000..0x0808_0000, so that code runs from bank 1 while bank 2
/// is erased or programmed (read-while-write, RM0440 5.3.8).
pub const G474_DUAL_BANK: FlashLayout = FlashLayout {
    base: 0x0800_0000,
    size: 512 * 1024,
    page: 2048,
    word: 8,
    store_pages: 8,
    banks: 2,
};

impl FlashLayout {
    /// Bytes of the store.
    pub const fn store_size(&self) -> u32 {
        self.page * self.store_pages
    }

    /// The store's range as offsets from [`FlashLayout::base`] (what flash drivers take).
    pub const fn store_offsets(&self) -> Range<u32> {
        self.size - self.store_size()..self.size
    }

    /// Bytes of one bank.
    pub const fn bank_size(&self) -> u32 {
        self.size / self.banks
    }

    /// Bytes of flash left for code and constants: the linker script's `FLASH` length. With
    /// two banks, the first bank (the store's bank is never executed from); with one, all but
    /// the store.
    pub const fn code_size(&self) -> u32 {
        if self.banks >= 2 {
            self.bank_size()
        } else {
            self.size - self.store_size()
        }
    }

    /// Start of the last bank, as an offset from [`FlashLayout::base`].
    pub const fn last_bank_offset(&self) -> u32 {
        self.size - self.bank_size()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The `LENGTH` of the `FLASH` region in a linker script, in bytes.
    fn flash_length(memory_x: &str) -> Option<u32> {
        let line = memory_x
            .lines()
            .find(|l| l.trim_start().starts_with("FLASH"))?;
        let value = line.split("LENGTH").nth(1)?.trim_start_matches([' ', '=']);
        let value = value.trim().trim_end_matches(',');
        let (digits, scale) = match value.strip_suffix('K') {
            Some(d) => (d, 1024),
            None => (value, 1),
        };
        digits.trim().parse::<u32>().ok().map(|n| n * scale)
    }

    /// The G474's linker script keeps the image in bank 1 and the store in bank 2: its
    /// `FLASH` region is bank 1 exactly (RM0440 5.3.1: bank 2 starts at 0x0804_0000 in
    /// dual-bank mode), and the store's pages lie beyond it, in bank 2.
    #[test]
    fn the_g474_linker_script_keeps_the_image_in_bank_1_and_the_store_in_bank_2() {
        let layout = G474_DUAL_BANK;
        let memory_x = include_str!("../../memory.x");
        let image_end = layout.base + flash_length(memory_x).expect("a FLASH region");
        assert!(memory_x.contains("ORIGIN = 0x08000000"));
        assert_eq!(
            image_end, 0x0804_0000,
            "the image region ends where bank 2 starts"
        );
        assert_eq!(layout.base + layout.last_bank_offset(), 0x0804_0000);
        let store = layout.store_offsets();
        assert_eq!(layout.base + store.start, 0x0807_C000);
        assert_eq!(layout.base + store.end, 0x0808_0000);
        assert!(layout.base + store.start >= image_end);
        assert!(store.start >= layout.last_bank_offset());
    }

    #[test]
    fn the_store_is_whole_pages_at_the_end_and_fits_the_library() {
        for layout in [G474_SINGLE_BANK, G474_DUAL_BANK] {
            let range = layout.store_offsets();
            assert!(range.start.is_multiple_of(layout.page));
            assert_eq!(range.end, layout.size);
            // sequential-storage needs at least two pages.
            assert!(layout.store_pages >= 2);
            // The library's largest word is 32 bytes; ours must divide the page.
            assert!(layout.word <= 32 && layout.page.is_multiple_of(layout.word));
            // 128 pages per bank: of 4 KiB in single-bank mode, of 2 KiB in each of the two
            // banks in dual-bank mode (RM0440 5.3.1).
            assert_eq!(layout.bank_size() / layout.page, 128);
        }
        // Both keep the same 16 KiB at the same addresses.
        assert_eq!(G474_SINGLE_BANK.store_offsets(), 0x7_C000..0x8_0000);
        assert_eq!(G474_DUAL_BANK.store_offsets(), 0x7_C000..0x8_0000);
        assert_eq!(G474_SINGLE_BANK.code_size(), 496 * 1024);
    }

    #[test]
    fn the_linker_length_parser_reads_the_forms_used() {
        assert_eq!(
            flash_length("  FLASH : ORIGIN = 0x08000000, LENGTH = 496K\n"),
            Some(496 * 1024)
        );
        assert_eq!(
            flash_length("FLASH : ORIGIN = 0, LENGTH = 4096"),
            Some(4096)
        );
        assert_eq!(flash_length("RAM : ORIGIN = 0, LENGTH = 4K"), None);
    }
}
