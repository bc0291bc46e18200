//! A RAM register image for the tests: the metapac accessors are pointed at it, and the tests
//! read raw words at RM0440's offsets (independently of the metapac's field names).

use std::vec::Vec;

/// 1 KiB of registers, word-aligned (every peripheral block used here fits).
#[repr(C, align(4))]
pub struct Image(pub [u32; 256]);

impl Image {
    pub fn new() -> Box<Self> {
        Box::new(Self([0; 256]))
    }

    pub fn ptr(&mut self) -> *mut () {
        self.0.as_mut_ptr() as *mut ()
    }

    /// The word at byte `offset`.
    pub fn word(&self, offset: usize) -> u32 {
        // SAFETY: volatile read of our own buffer (the accessors wrote it through a raw pointer).
        unsafe { core::ptr::read_volatile(self.0.as_ptr().add(offset / 4)) }
    }

    pub fn set_word(&mut self, offset: usize, value: u32) {
        // SAFETY: as above.
        unsafe { core::ptr::write_volatile(self.0.as_mut_ptr().add(offset / 4), value) }
    }

    /// `width` bits at `lsb` of the word at byte `offset`.
    pub fn bits(&self, offset: usize, lsb: u32, width: u32) -> u32 {
        (self.word(offset) >> lsb) & ((1u64 << width) - 1) as u32
    }

    pub fn bit(&self, offset: usize, bit: u32) -> bool {
        self.bits(offset, bit, 1) == 1
    }

    pub fn snapshot(&self) -> Vec<u32> {
        (0..256).map(|i| self.word(i * 4)).collect()
    }
}
