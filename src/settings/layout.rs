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
}

/// The STM32G474RE in single-bank mode (option bit DBANK = 0, the `single-bank` feature of
/// embassy-stm32): 512 KiB in 128 pages of 4 KiB, programmed by 64-bit double words (RM0440,
/// 5.3.1 and 5.3.7). The store takes the last four pages, 0x0807_C000..0x0808_0000. In
/// dual-bank mode the pages are 2 KiB: the firmware then leaves the store closed.
pub const G474_SINGLE_BANK: FlashLayout = FlashLayout {
    base: 0x0800_0000,
    size: 512 * 1024,
    page: 4096,
    word: 8,
    store_pages: 4,
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

    /// Bytes of flash left for code and constants: the linker script's `FLASH` length.
    pub const fn code_size(&self) -> u32 {
        self.size - self.store_size()
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

    #[test]
    fn the_g474_linker_script_keeps_code_out_of_the_store() {
        let layout = G474_SINGLE_BANK;
        let memory_x = include_str!("../../memory.x");
        assert_eq!(flash_length(memory_x), Some(layout.code_size()));
        assert!(memory_x.contains("ORIGIN = 0x08000000"));
        assert_eq!(layout.store_offsets(), 0x7_C000..0x8_0000);
        assert_eq!(layout.base + layout.store_offsets().start, 0x0807_C000);
    }

    #[test]
    fn the_store_is_whole_pages_at_the_end_and_fits_the_library() {
        let layout = G474_SINGLE_BANK;
        let range = layout.store_offsets();
        assert!(range.start.is_multiple_of(layout.page));
        assert_eq!(range.end, layout.size);
        // sequential-storage needs at least two pages.
        assert!(layout.store_pages >= 2);
        // The library's largest word is 32 bytes; ours must divide the page.
        assert!(layout.word <= 32 && layout.page.is_multiple_of(layout.word));
        // 128 pages of 4 KiB in single-bank mode.
        assert_eq!(layout.size / layout.page, 128);
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
