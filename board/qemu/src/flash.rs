//! The settings flash of the QEMU board: a host file through ARM semihosting (SYS_OPEN,
//! SYS_SEEK, SYS_READ, SYS_WRITE), with the G474's single-bank geometry (4 KiB pages,
//! 8-byte double-word programming), so that the same store runs on it and its contents
//! survive a QEMU restart.
//!
//! It behaves as NOR flash: an erased byte reads 0xFF, a page erase sets a whole page to 0xFF,
//! and a double word can be programmed only while erased (the G474's rule; programming it
//! again is an error). Programming goes word by word and erasing page by page, each one a
//! separate write to the file, so that a power cut ([`POWER_CUT`]) falls between two of them.
//!
//! `cut=N` (see `args.rs`) cuts the power just before the N+1-th word program or page erase
//! since boot: QEMU exits at once with [`exit::POWER_CUT`], nothing flushed or closed, and
//! the file holds exactly the words and pages done before the cut.

use core::ffi::CStr;
use core::sync::atomic::{AtomicU32, Ordering};

use embedded_storage_async::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};
use semihosting::fd::{AsFd, OwnedFd};
use semihosting::sys::arm_compat::{
    OpenMode, sys_flen, sys_open, sys_read_orig, sys_seek, sys_write_orig,
};

use crate::exit;

use sonolube::settings::G474_SINGLE_BANK as G474;

/// Erase page, bytes (the G474's in single-bank mode).
pub const PAGE: usize = G474.page as usize;
/// Programming unit, bytes (a G474 double word).
pub const WORD: usize = G474.word as usize;
/// Pages of the emulated flash (as many as the G474 gives its store).
pub const PAGES: usize = G474.store_pages as usize;
/// Bytes of the emulated flash.
pub const SIZE: usize = PAGE * PAGES;
/// Longest path of the flash file, bytes.
pub const MAX_PATH: usize = 200;

/// Opens the flash file at `path` (at most [`MAX_PATH`] bytes) and the settings store on it.
pub fn open_store(path: &str) -> Result<sonolube::settings::Store<FileFlash>, FlashError> {
    let mut name = [0u8; MAX_PATH + 1];
    let bytes = path.as_bytes();
    name.get_mut(..bytes.len())
        .ok_or(FlashError::OutOfBounds)?
        .copy_from_slice(bytes);
    let path = CStr::from_bytes_until_nul(&name).map_err(|_| FlashError::Host)?;
    let flash = FileFlash::open(path)?;
    sonolube::settings::Store::new(flash, 0..SIZE as u32).map_err(|_| FlashError::NotAligned)
}

/// Word programs and page erases left before the power is cut; `u32::MAX`: never.
static POWER_CUT: AtomicU32 = AtomicU32::new(u32::MAX);
/// Word programs and page erases since boot.
static OPERATIONS: AtomicU32 = AtomicU32::new(0);

/// Cuts the power after `operations` more word programs or page erases.
pub fn cut_power_after(operations: u32) {
    POWER_CUT.store(operations, Ordering::Relaxed);
}

/// Word programs and page erases since boot.
pub fn operations() -> u32 {
    OPERATIONS.load(Ordering::Relaxed)
}

/// A flash operation, for the power-cut log.
#[derive(Debug, Clone, Copy, PartialEq, Eq, defmt::Format)]
enum Operation {
    /// Programming one double word.
    Program,
    /// Erasing one page.
    Erase,
}

/// Counts one operation; cuts the power first when the budget is spent.
fn operation(kind: Operation, address: usize) {
    if POWER_CUT.load(Ordering::Relaxed) == 0 {
        defmt::warn!(
            "power cut before flash operation {=u32}: {} at {=usize:#06x}",
            operations() + 1,
            kind,
            address
        );
        exit::exit(exit::POWER_CUT);
    }
    if kind == Operation::Erase {
        defmt::info!(
            "flash operation {=u32}: page erase at {=usize:#06x}",
            operations() + 1,
            address
        );
    }
    let _ = POWER_CUT.fetch_update(Ordering::Relaxed, Ordering::Relaxed, |left| {
        if left == u32::MAX {
            None
        } else {
            Some(left - 1)
        }
    });
    OPERATIONS.fetch_add(1, Ordering::Relaxed);
}

/// A failed flash operation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, defmt::Format)]
pub enum FlashError {
    /// Outside the flash.
    OutOfBounds,
    /// Not aligned to the word or page.
    NotAligned,
    /// Programming a double word that is not erased.
    NotErased,
    /// The host file could not be read or written.
    Host,
}

impl NorFlashError for FlashError {
    fn kind(&self) -> NorFlashErrorKind {
        match self {
            FlashError::OutOfBounds => NorFlashErrorKind::OutOfBounds,
            FlashError::NotAligned => NorFlashErrorKind::NotAligned,
            FlashError::NotErased | FlashError::Host => NorFlashErrorKind::Other,
        }
    }
}

/// The flash file.
pub struct FileFlash {
    fd: OwnedFd,
}

impl FileFlash {
    /// Opens `path` (creating it erased, or growing it with erased bytes, to [`SIZE`]).
    pub fn open(path: &CStr) -> Result<Self, FlashError> {
        let fd = match sys_open(path, OpenMode::RDWR_BINARY) {
            Ok(fd) => fd,
            Err(_) => sys_open(path, OpenMode::RDWR_TRUNC_BINARY).map_err(|_| FlashError::Host)?,
        };
        let flash = Self { fd };
        let len = sys_flen(flash.fd.as_fd()).map_err(|_| FlashError::Host)?;
        if len < SIZE {
            let erased = [0xFFu8; 256];
            let mut at = len;
            while at < SIZE {
                let n = (SIZE - at).min(erased.len());
                flash.put(at, &erased[..n])?;
                at += n;
            }
        }
        Ok(flash)
    }

    fn seek(&self, at: usize) -> Result<(), FlashError> {
        // SAFETY: `at` is inside the file, which is SIZE bytes long (or being grown to it
        // from its end).
        unsafe { sys_seek(self.fd.as_fd(), at) }.map_err(|_| FlashError::Host)
    }

    fn put(&self, at: usize, bytes: &[u8]) -> Result<(), FlashError> {
        self.seek(at)?;
        match sys_write_orig(self.fd.as_fd(), bytes) {
            Ok(0) => Ok(()),
            _ => Err(FlashError::Host),
        }
    }

    fn get(&self, at: usize, bytes: &mut [u8]) -> Result<(), FlashError> {
        self.seek(at)?;
        match sys_read_orig(self.fd.as_fd(), bytes) {
            Ok(0) => Ok(()),
            _ => Err(FlashError::Host),
        }
    }
}

fn span(offset: u32, len: usize) -> Result<usize, FlashError> {
    let at = offset as usize;
    match at.checked_add(len) {
        Some(end) if end <= SIZE => Ok(at),
        _ => Err(FlashError::OutOfBounds),
    }
}

impl ErrorType for FileFlash {
    type Error = FlashError;
}

impl ReadNorFlash for FileFlash {
    const READ_SIZE: usize = 1;

    async fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), FlashError> {
        let at = span(offset, bytes.len())?;
        if bytes.is_empty() {
            return Ok(());
        }
        self.get(at, bytes)
    }

    fn capacity(&self) -> usize {
        SIZE
    }
}

impl NorFlash for FileFlash {
    const WRITE_SIZE: usize = WORD;
    const ERASE_SIZE: usize = PAGE;

    async fn erase(&mut self, from: u32, to: u32) -> Result<(), FlashError> {
        let (from, to) = (from as usize, to as usize);
        if from > to || to > SIZE {
            return Err(FlashError::OutOfBounds);
        }
        if !from.is_multiple_of(PAGE) || !to.is_multiple_of(PAGE) {
            return Err(FlashError::NotAligned);
        }
        let erased = [0xFFu8; PAGE];
        for page in (from..to).step_by(PAGE) {
            operation(Operation::Erase, page);
            self.put(page, &erased)?;
        }
        Ok(())
    }

    async fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), FlashError> {
        let at = span(offset, bytes.len())?;
        if !at.is_multiple_of(WORD) || !bytes.len().is_multiple_of(WORD) {
            return Err(FlashError::NotAligned);
        }
        for (i, word) in bytes.chunks_exact(WORD).enumerate() {
            let address = at + i * WORD;
            let mut old = [0u8; WORD];
            self.get(address, &mut old)?;
            if old != [0xFF; WORD] {
                return Err(FlashError::NotErased);
            }
            operation(Operation::Program, address);
            self.put(address, word)?;
        }
        Ok(())
    }
}
