//! The boot and fault log: boots and watchdog resets counted, and the last [`LOG_LEN`] events
//! (latched faults by their reason code, watchdog resets), oldest first.
//!
//! # Encoding, version 1 (32 bytes, little-endian)
//!
//! | bytes | field |
//! |---|---|
//! | 0..4 | magic `SLLG` |
//! | 4 | version, 1 |
//! | 5 | events held, 0..=8 |
//! | 6..8 | zero |
//! | 8..12 | boots, u32 |
//! | 12..16 | watchdog resets, u32 |
//! | 16..32 | 8 events, u16 each, oldest first, unused ones zero: `0x1000` a watchdog reset, `0x2000 + code` a fault with its [`Reason::code`] |
//!
//! then the CRC-32 of bytes 0..32 (bytes 32..36): 36 bytes in all.

use super::crc::crc32;
use super::record::{Invalid, u32_at};
use crate::control::Reason;

/// Events the log keeps.
pub const LOG_LEN: usize = 8;
/// Bytes of an encoded log.
pub const LOG_BYTES: usize = 36;
const LOG_MAGIC: [u8; 4] = *b"SLLG";
const LOG_VERSION: u8 = 1;
const WATCHDOG: u16 = 0x1000;
const FAULT: u16 = 0x2000;

/// One logged event.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Event {
    /// The previous run ended in a watchdog reset.
    WatchdogReset,
    /// A fault latched (a [`Reason`] whose [`Reason::is_fault`] holds).
    Fault(Reason),
}

impl Event {
    /// The event as one kebab-case word: `watchdog-reset` or the fault's reason name.
    pub fn name(self) -> &'static str {
        match self {
            Event::WatchdogReset => "watchdog-reset",
            Event::Fault(reason) => reason.name(),
        }
    }

    fn encode(self) -> u16 {
        match self {
            Event::WatchdogReset => WATCHDOG,
            Event::Fault(reason) => FAULT + reason.code(),
        }
    }

    fn decode(word: u16) -> Option<Self> {
        match word {
            WATCHDOG => Some(Event::WatchdogReset),
            w if w & 0xF000 == FAULT => {
                let code = w & 0x0FFF;
                Reason::all()
                    .find(|r| r.code() == code && r.is_fault())
                    .map(Event::Fault)
            }
            _ => None,
        }
    }
}

/// The log.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Log {
    /// Boots counted, saturating.
    pub boots: u32,
    /// Watchdog resets counted, saturating.
    pub watchdog_resets: u32,
    events: [Option<Event>; LOG_LEN],
}

impl Default for Log {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Log {
    /// Nothing logged.
    pub const EMPTY: Log = Log {
        boots: 0,
        watchdog_resets: 0,
        events: [None; LOG_LEN],
    };

    /// Counts a boot; `after_watchdog_reset` logs the reset that caused it.
    pub fn boot(&mut self, after_watchdog_reset: bool) {
        self.boots = self.boots.saturating_add(1);
        if after_watchdog_reset {
            self.watchdog_resets = self.watchdog_resets.saturating_add(1);
            self.push(Event::WatchdogReset);
        }
    }

    /// Logs an event, dropping the oldest when full.
    pub fn push(&mut self, event: Event) {
        if self.events.iter().all(Option::is_some) {
            self.events.rotate_left(1);
            self.events[LOG_LEN - 1] = None;
        }
        if let Some(slot) = self.events.iter_mut().find(|e| e.is_none()) {
            *slot = Some(event);
        }
    }

    /// The events, oldest first.
    pub fn events(&self) -> impl Iterator<Item = Event> + '_ {
        self.events.iter().flatten().copied()
    }

    /// The log's bytes.
    pub fn encode(&self) -> [u8; LOG_BYTES] {
        let mut out = [0u8; LOG_BYTES];
        out[0..4].copy_from_slice(&LOG_MAGIC);
        out[4] = LOG_VERSION;
        let mut held = 0u8;
        for (i, event) in self.events().enumerate() {
            out[16 + 2 * i..18 + 2 * i].copy_from_slice(&event.encode().to_le_bytes());
            held += 1;
        }
        out[5] = held;
        out[8..12].copy_from_slice(&self.boots.to_le_bytes());
        out[12..16].copy_from_slice(&self.watchdog_resets.to_le_bytes());
        let crc = crc32(&out[..32]);
        out[32..36].copy_from_slice(&crc.to_le_bytes());
        out
    }

    /// Reads a stored log: length, magic, version, CRC, then every entry. Never panics.
    pub fn decode(bytes: &[u8]) -> Result<Log, Invalid> {
        let bytes: &[u8; LOG_BYTES] = bytes.try_into().map_err(|_| Invalid::Length)?;
        if bytes[0..4] != LOG_MAGIC {
            return Err(Invalid::Magic);
        }
        if bytes[4] != LOG_VERSION {
            return Err(Invalid::Version(bytes[4]));
        }
        if crc32(&bytes[..32]) != u32_at(bytes, 32) {
            return Err(Invalid::Crc);
        }
        let held = usize::from(bytes[5]);
        if held > LOG_LEN || bytes[6] != 0 || bytes[7] != 0 {
            return Err(Invalid::LogEntry);
        }
        let mut log = Log {
            boots: u32_at(bytes, 8),
            watchdog_resets: u32_at(bytes, 12),
            events: [None; LOG_LEN],
        };
        for i in 0..LOG_LEN {
            let word = u16::from_le_bytes([bytes[16 + 2 * i], bytes[17 + 2 * i]]);
            log.events[i] = match (i < held, word) {
                (true, word) => Some(Event::decode(word).ok_or(Invalid::LogEntry)?),
                (false, 0) => None,
                (false, _) => return Err(Invalid::LogEntry),
            };
        }
        if log.watchdog_resets > log.boots {
            return Err(Invalid::LogEntry);
        }
        Ok(log)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_the_last_events_oldest_first_and_round_trips() {
        let mut log = Log::EMPTY;
        assert_eq!(Log::decode(&log.encode()), Ok(log));
        log.boot(false);
        log.boot(true);
        assert_eq!((log.boots, log.watchdog_resets), (2, 1));
        let faults: Vec<Reason> = Reason::all().filter(|r| r.is_fault()).collect();
        assert!(faults.len() > LOG_LEN);
        for &reason in &faults {
            log.push(Event::Fault(reason));
            assert_eq!(Log::decode(&log.encode()), Ok(log));
        }
        let kept: Vec<Event> = log.events().collect();
        let expected: Vec<Event> = faults[faults.len() - LOG_LEN..]
            .iter()
            .map(|&r| Event::Fault(r))
            .collect();
        assert_eq!(kept, expected);
    }

    #[test]
    fn bad_logs_are_refused() {
        let mut log = Log::EMPTY;
        log.boot(true);
        let good = log.encode();
        let recrc = |mut bytes: [u8; LOG_BYTES]| {
            let crc = crc32(&bytes[..32]);
            bytes[32..36].copy_from_slice(&crc.to_le_bytes());
            bytes
        };
        assert_eq!(Log::decode(&good[..35]), Err(Invalid::Length));
        let mut bad = good;
        bad[9] ^= 1;
        assert_eq!(Log::decode(&bad), Err(Invalid::Crc));
        // A non-fault reason code (start-command, 1) is not a fault event.
        let mut bad = good;
        bad[16..18].copy_from_slice(&(FAULT + 1).to_le_bytes());
        assert_eq!(Log::decode(&recrc(bad)), Err(Invalid::LogEntry));
        // More watchdog resets than boots.
        let mut bad = good;
        bad[8..12].fill(0);
        assert_eq!(Log::decode(&recrc(bad)), Err(Invalid::LogEntry));
        let mut bad = good;
        bad[5] = 9;
        assert_eq!(Log::decode(&recrc(bad)), Err(Invalid::LogEntry));
        assert_eq!(Log::decode(&[0xFF; LOG_BYTES]), Err(Invalid::Magic));
    }
}
