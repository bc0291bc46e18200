//! Settings that survive a reset: the load-cell calibrations (offset and span per axis, with a
//! calibration counter), the selected scene, the last target and the drive frequency, plus a
//! boot and fault log, kept in flash by a wear-levelled, power-cut-safe store.
//!
//! - [`Record`]: the settings, their 64-byte encoding (magic, version, CRC-32) and their range
//!   checks; [`Record::DEFAULTS`] are the scene's own values.
//! - the commissioned values ([`encode_commissioned`]): what a `commission` measured, under a
//!   key of its own, linked to the settings record saved with it ([`CommissionedInvalid`]);
//! - [`Log`]: boots and watchdog resets counted, the last [`LOG_LEN`] latched faults (reason
//!   codes) and watchdog resets.
//! - [`Store`]: a `sequential-storage` map over any async `NorFlash` (the G474's flash pages,
//!   QEMU's semihosted file, the library's mock flash in the tests); [`boot`] loads, checks,
//!   falls back to the defaults with the reason ([`Invalid`]), and counts the boot in the log.
//! - [`capture`] and [`apply`]: between a running [`crate::station::Station`] and a record
//!   (with its commissioned values).
//! - [`format_settings`], [`format_log`]: the replies of `save`, `load`, `defaults` and `log`.
//!
//! Pure logic: no board, no simulation; host tests run it on the library's mock flash,
//! including a power cut at every byte of a save (`tests.rs`).

mod apply;
mod commissioned;
mod crc;
mod layout;
mod log;
mod record;
mod report;
mod store;

#[cfg(test)]
mod tests;

pub use apply::{apply, capture};
pub use commissioned::{
    COMMISSIONED_LEN, COMMISSIONED_VERSION, CommissionedInvalid, decode_commissioned,
    encode_commissioned, link,
};
pub use crc::crc32;
pub use layout::{FlashLayout, G474_DUAL_BANK, G474_SINGLE_BANK};
pub use log::{Event, LOG_BYTES, LOG_LEN, Log};
pub use record::{AxisCal, FREQ_RANGE_CHZ, Invalid, RECORD_LEN, RECORD_VERSION, Record};
pub use report::{format_log, format_settings};
pub use store::{Boot, Source, Store, StoreError, boot};
