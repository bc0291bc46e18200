//! The settings store: a [`sequential_storage`] map over any `NorFlash` (async), holding the
//! settings [`Record`] under key 1, the boot and fault [`Log`] under key 2 and the
//! commissioned values (`super::commissioned`) under key 3.
//!
//! The map appends each new version of an item after the previous ones and only erases a page
//! after the newest items have been copied out of it, so the writes are spread over all the
//! pages (wear levelling) and a power cut in the middle of a write leaves the previous version
//! readable: the half-written item fails the map's own checks and the record's CRC, and the
//! newest complete one is found. Boards run the blocking flash drivers under it (the futures
//! complete on their first poll).

use core::ops::Range;

use embedded_storage_async::nor_flash::NorFlash;
use sequential_storage::cache::{Cache, Uncached};
use sequential_storage::map::{MapConfig, MapStorage};

use super::commissioned::{
    COMMISSIONED_LEN, CommissionedInvalid, decode_commissioned, encode_commissioned,
};
use super::log::{LOG_BYTES, Log};
use super::record::{Invalid, RECORD_LEN, Record};
use crate::commission::CommissionResult;

const KEY_RECORD: u8 = 1;
const KEY_LOG: u8 = 2;
const KEY_COMMISSIONED: u8 = 3;

/// Buffer for one item (key and value), rounded up to the largest flash word (32 bytes) and
/// aligned for drivers that need it.
#[repr(C, align(8))]
struct Buffer([u8; 128]);

/// Why a store operation failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum StoreError {
    /// The flash range is not whole pages, or fewer than two.
    Config,
    /// The flash driver reported an error (or power was cut).
    Flash,
    /// No room even after reclaiming pages.
    Full,
    /// The map's structure is damaged beyond its own repair.
    Corrupted,
    /// Any other failure the library reports (buffer, serialization, internal).
    Other,
}

impl StoreError {
    /// The error as one kebab-case word.
    pub const fn name(self) -> &'static str {
        match self {
            StoreError::Config => "bad-flash-range",
            StoreError::Flash => "flash-error",
            StoreError::Full => "flash-full",
            StoreError::Corrupted => "flash-corrupted",
            StoreError::Other => "store-error",
        }
    }
}

impl<E> From<sequential_storage::Error<E>> for StoreError {
    fn from(error: sequential_storage::Error<E>) -> Self {
        match error {
            sequential_storage::Error::Storage { .. } => StoreError::Flash,
            sequential_storage::Error::FullStorage => StoreError::Full,
            sequential_storage::Error::Corrupted { .. } => StoreError::Corrupted,
            _ => StoreError::Other,
        }
    }
}

/// The store on `flash`, in `range` (whole erase pages, at least two).
pub struct Store<F: NorFlash> {
    map: MapStorage<u8, F, Cache<Uncached, Uncached, Uncached, u8>>,
    buffer: Buffer,
}

impl<F: NorFlash> Store<F> {
    /// The store in `range` of `flash`. Error `Config` when the range is not whole pages or
    /// fewer than two.
    pub fn new(flash: F, range: Range<u32>) -> Result<Self, StoreError> {
        let config = MapConfig::try_new(range).map_err(|_| StoreError::Config)?;
        Ok(Self {
            map: MapStorage::new(flash, config, Cache::new_uncached()),
            buffer: Buffer([0; 128]),
        })
    }

    /// Gives the flash back.
    pub fn into_flash(self) -> F {
        self.map.destroy().0
    }

    async fn fetch(&mut self, key: u8, out: &mut [u8]) -> Result<usize, Invalid> {
        match self.map.fetch_item::<&[u8]>(&mut self.buffer.0, &key).await {
            Ok(Some(bytes)) => {
                let len = bytes.len();
                let Some(slot) = out.get_mut(..len) else {
                    return Err(Invalid::Length);
                };
                slot.copy_from_slice(bytes);
                Ok(len)
            }
            Ok(None) => Err(Invalid::Empty),
            Err(_) => Err(Invalid::Storage),
        }
    }

    /// The stored settings, checked ([`Record::decode`]).
    pub async fn load(&mut self, known_scene: impl Fn(&str) -> bool) -> Result<Record, Invalid> {
        let mut bytes = [0u8; RECORD_LEN + 1];
        let len = self.fetch(KEY_RECORD, &mut bytes).await?;
        Record::decode(&bytes[..len], known_scene)
    }

    /// The stored log, checked ([`Log::decode`]).
    pub async fn load_log(&mut self) -> Result<Log, Invalid> {
        let mut bytes = [0u8; LOG_BYTES + 1];
        let len = self.fetch(KEY_LOG, &mut bytes).await?;
        Log::decode(&bytes[..len])
    }

    pub(super) async fn store(&mut self, key: u8, bytes: &[u8]) -> Result<(), StoreError> {
        match self.map.store_item(&mut self.buffer.0, &key, &bytes).await {
            Err(sequential_storage::Error::Corrupted { .. }) => {
                // Damaged beyond the library's repair (not a power cut, which it repairs):
                // start the range afresh rather than refuse every save from now on.
                self.map.erase_all().await?;
                Ok(self
                    .map
                    .store_item(&mut self.buffer.0, &key, &bytes)
                    .await?)
            }
            other => Ok(other?),
        }
    }

    /// Stores `record` as the newest settings.
    pub async fn save(&mut self, record: &Record) -> Result<(), StoreError> {
        self.store(KEY_RECORD, &record.encode()).await
    }

    /// Stores `result` as the commissioning saved with `record` (call after saving `record`:
    /// a power cut between the two leaves a commissioning linked to other settings, which is
    /// not used).
    pub async fn save_commissioned(
        &mut self,
        result: &CommissionResult,
        record: &Record,
    ) -> Result<(), StoreError> {
        self.store(KEY_COMMISSIONED, &encode_commissioned(result, record))
            .await
    }

    /// The stored commissioning for the settings `record` ([`decode_commissioned`]): `None`
    /// when there is none or it was saved with other settings.
    pub async fn load_commissioned(
        &mut self,
        record: &Record,
    ) -> Result<Option<CommissionResult>, CommissionedInvalid> {
        let mut bytes = [0u8; COMMISSIONED_LEN + 1];
        match self.fetch(KEY_COMMISSIONED, &mut bytes).await {
            Ok(len) => decode_commissioned(&bytes[..len], record),
            Err(Invalid::Empty) => Ok(None),
            Err(Invalid::Length) => Err(CommissionedInvalid::Length),
            Err(_) => Err(CommissionedInvalid::Storage),
        }
    }

    /// Stores `log` as the newest log.
    pub async fn save_log(&mut self, log: &Log) -> Result<(), StoreError> {
        self.store(KEY_LOG, &log.encode()).await
    }
}

/// Where the settings a boot uses came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Source {
    /// The stored record passed every check.
    Stored,
    /// The defaults, because of this.
    Defaults(Invalid),
}

impl Source {
    /// `stored`, or `defaults`.
    pub const fn name(self) -> &'static str {
        match self {
            Source::Stored => "stored",
            Source::Defaults(_) => "defaults",
        }
    }
}

/// What a boot found and did.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Boot {
    /// The settings to run with.
    pub record: Record,
    /// Where they came from.
    pub source: Source,
    /// The commissioned values saved with the stored settings (`Ok(None)`: none, or the
    /// settings are the defaults), or why they are not used (the loop then runs on the
    /// declared values).
    pub commissioned: Result<Option<CommissionResult>, CommissionedInvalid>,
    /// The log, with this boot counted.
    pub log: Log,
    /// Why the stored log was not used (a fresh one was started), if it was not.
    pub log_invalid: Option<Invalid>,
    /// Why this boot could not be written to the log, if it could not.
    pub log_write: Option<StoreError>,
}

/// The boot sequence: loads and checks the settings (the defaults, with the reason, when they
/// are missing or invalid) and the commissioning saved with them, loads the log, counts this boot (and the watchdog reset that caused
/// it) and writes the log back.
pub async fn boot<F: NorFlash>(
    store: &mut Store<F>,
    after_watchdog_reset: bool,
    known_scene: impl Fn(&str) -> bool,
) -> Boot {
    let (record, source) = match store.load(known_scene).await {
        Ok(record) => (record, Source::Stored),
        Err(why) => (Record::DEFAULTS, Source::Defaults(why)),
    };
    let commissioned = match source {
        Source::Stored => store.load_commissioned(&record).await,
        Source::Defaults(_) => Ok(None),
    };
    let (mut log, log_invalid) = match store.load_log().await {
        Ok(log) => (log, None),
        Err(Invalid::Empty) => (Log::EMPTY, None),
        Err(why) => (Log::EMPTY, Some(why)),
    };
    log.boot(after_watchdog_reset);
    let log_write = store.save_log(&log).await.err();
    Boot {
        record,
        source,
        commissioned,
        log,
        log_invalid,
        log_write,
    }
}
