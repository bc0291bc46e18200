//! The commissioning record: the values a `commission` measured ([`CommissionResult`]: f0,
//! tau, Q, mu0, each with its standard error, the ring-down's point count, each cell's zero and
//! noise), kept under a key of its own beside the settings [`Record`] so that the record's
//! format is unchanged.
//!
//! A commissioning belongs to the settings it was saved with: the record carries the CRC-32
//! of the settings record's encoding at that `save` ([`link`]). `save` writes the settings
//! record first, then the commissioning (only when the loop runs on commissioned values), so
//! that a power cut between the two, or a later `save` of declared values, leaves a
//! commissioning whose link is not the stored record's: it is not used (the loop runs on the
//! declared values), never mixed with other settings. A commissioning that is damaged or out
//! of its physical ranges is refused with the reason ([`CommissionedInvalid`]).
//!
//! # Encoding, version 1 (116 bytes, little-endian)
//!
//! | bytes | field |
//! |---|---|
//! | 0..4 | magic `SLCM` |
//! | 4 | version, 1 |
//! | 5 | flags: bit 0 normal noise measured, bit 1 tangential noise measured; bits 2-7 zero |
//! | 6..8 | zero |
//! | 8..12 | link: CRC-32 of the settings record saved with it, its check value left out ([`link`]) |
//! | 12..16 | ring-down points, u32 |
//! | 16..112 | twelve `f64` (IEEE 754 bits): f0 Hz and its standard error, tau s and its, Q and its, mu0 and its, normal zero N, normal noise N RMS, tangential zero, tangential noise (a noise whose flag is clear is zero) |
//! | 112..116 | CRC-32 of bytes 0..112 |
//!
//! The `f64` are stored bit for bit: the loop restored from them runs on exactly the values
//! the `commission` measured. Decoding checks, in order: length, magic, version, CRC, flags,
//! link, then every range ([`crate::commission::check`]).

use super::crc::crc32;
use super::record::{RECORD_LEN, Record, u32_at};
use crate::commission::{CellZero, CommissionResult, Measured, Step, check};

/// Bytes of an encoded commissioning record.
pub const COMMISSIONED_LEN: usize = 116;
/// The commissioning record format's version.
pub const COMMISSIONED_VERSION: u8 = 1;
const MAGIC: [u8; 4] = *b"SLCM";
const FLAG_NORMAL_NOISE: u8 = 1 << 0;
const FLAG_TANGENTIAL_NOISE: u8 = 1 << 1;
const FLAGS_KNOWN: u8 = FLAG_NORMAL_NOISE | FLAG_TANGENTIAL_NOISE;
const VALUES_AT: usize = 16;
const CRC_AT: usize = 112;

/// Why a stored commissioning is not used. Each has a kebab-case [`Self::reason`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum CommissionedInvalid {
    /// The store could not be read.
    Storage,
    /// The item has the wrong length.
    Length,
    /// The first four bytes are not the magic.
    Magic,
    /// Written by another format version.
    Version(u8),
    /// The check value does not match the contents.
    Crc,
    /// Unknown flag bits, non-zero reserved bytes, or a noise present behind a cleared flag.
    Flags,
    /// A value outside its physical range: the step and reason of
    /// [`crate::commission::check`].
    Range {
        /// The step the value belongs to.
        step: Step,
        /// Why, in words.
        reason: &'static str,
    },
}

impl CommissionedInvalid {
    /// The reason as one kebab-case word.
    pub const fn reason(self) -> &'static str {
        match self {
            CommissionedInvalid::Storage => "commissioning-unreadable",
            CommissionedInvalid::Length => "commissioning-bad-length",
            CommissionedInvalid::Magic => "commissioning-bad-magic",
            CommissionedInvalid::Version(_) => "commissioning-other-version",
            CommissionedInvalid::Crc => "commissioning-crc-mismatch",
            CommissionedInvalid::Flags => "commissioning-bad-flags",
            CommissionedInvalid::Range { .. } => "commissioning-out-of-range",
        }
    }
}

/// The link of a commissioning to `record`: the CRC-32 of the record's encoding without its
/// own check value (its last four bytes). (Over the whole encoding, the check value included,
/// a CRC is the same constant for every record: its residue.)
pub fn link(record: &Record) -> u32 {
    let bytes: [u8; RECORD_LEN] = record.encode();
    crc32(bytes.get(..RECORD_LEN - 4).unwrap_or(&bytes))
}

/// The 116 bytes of `result`, saved with `record`.
pub fn encode_commissioned(result: &CommissionResult, record: &Record) -> [u8; COMMISSIONED_LEN] {
    let mut out = [0u8; COMMISSIONED_LEN];
    out[0..4].copy_from_slice(&MAGIC);
    out[4] = COMMISSIONED_VERSION;
    let mut flags = 0;
    if result.normal.noise_rms_n.is_some() {
        flags |= FLAG_NORMAL_NOISE;
    }
    if result.tangential.noise_rms_n.is_some() {
        flags |= FLAG_TANGENTIAL_NOISE;
    }
    out[5] = flags;
    out[8..12].copy_from_slice(&link(record).to_le_bytes());
    out[12..16].copy_from_slice(&result.ring_down_points.to_le_bytes());
    for (i, value) in values(result).into_iter().enumerate() {
        let at = VALUES_AT + 8 * i;
        out[at..at + 8].copy_from_slice(&value.to_le_bytes());
    }
    let crc = crc32(&out[..CRC_AT]);
    out[CRC_AT..].copy_from_slice(&crc.to_le_bytes());
    out
}

/// The twelve stored values, in the encoding's order.
fn values(r: &CommissionResult) -> [f64; 12] {
    [
        r.resonance_hz.value,
        r.resonance_hz.standard_error,
        r.time_constant_s.value,
        r.time_constant_s.standard_error,
        r.quality_factor.value,
        r.quality_factor.standard_error,
        r.natural_coefficient.value,
        r.natural_coefficient.standard_error,
        r.normal.zero_n,
        r.normal.noise_rms_n.unwrap_or(0.0),
        r.tangential.zero_n,
        r.tangential.noise_rms_n.unwrap_or(0.0),
    ]
}

/// Reads a stored commissioning for the settings `record` loaded with it: `Ok(None)` when it
/// was saved with other settings (its link is not `record`'s: the loop runs on the declared
/// values), the result when it passes every check, else the first failure. Never panics,
/// whatever the bytes.
pub fn decode_commissioned(
    bytes: &[u8],
    record: &Record,
) -> Result<Option<CommissionResult>, CommissionedInvalid> {
    let bytes: &[u8; COMMISSIONED_LEN] =
        bytes.try_into().map_err(|_| CommissionedInvalid::Length)?;
    if bytes[0..4] != MAGIC {
        return Err(CommissionedInvalid::Magic);
    }
    if bytes[4] != COMMISSIONED_VERSION {
        return Err(CommissionedInvalid::Version(bytes[4]));
    }
    if crc32(&bytes[..CRC_AT]) != u32_at(bytes, CRC_AT) {
        return Err(CommissionedInvalid::Crc);
    }
    let flags = bytes[5];
    if flags & !FLAGS_KNOWN != 0 || bytes[6] != 0 || bytes[7] != 0 {
        return Err(CommissionedInvalid::Flags);
    }
    if u32_at(bytes, 8) != link(record) {
        return Ok(None);
    }
    let value = |i: usize| {
        let at = VALUES_AT + 8 * i;
        let mut word = [0u8; 8];
        if let Some(src) = bytes.get(at..at + 8) {
            word.copy_from_slice(src);
        }
        f64::from_le_bytes(word)
    };
    let noise = |flag: u8, i: usize| match (flags & flag != 0, value(i)) {
        (true, noise) => Ok(Some(noise)),
        (false, noise) if noise.to_bits() == 0 => Ok(None),
        (false, _) => Err(CommissionedInvalid::Flags),
    };
    let measured = |i: usize| Measured {
        value: value(i),
        standard_error: value(i + 1),
    };
    let result = CommissionResult {
        resonance_hz: measured(0),
        time_constant_s: measured(2),
        quality_factor: measured(4),
        natural_coefficient: measured(6),
        ring_down_points: u32_at(bytes, 12),
        normal: CellZero {
            zero_n: value(8),
            noise_rms_n: noise(FLAG_NORMAL_NOISE, 9)?,
        },
        tangential: CellZero {
            zero_n: value(10),
            noise_rms_n: noise(FLAG_TANGENTIAL_NOISE, 11)?,
        },
    };
    check(&result).map_err(|refusal| CommissionedInvalid::Range {
        step: refusal.step,
        reason: refusal.reason,
    })?;
    Ok(Some(result))
}
