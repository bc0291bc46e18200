//! The settings record: what survives a reset, its encoding (magic, version, CRC-32) and the
//! range checks that decide whether a stored record may be used.
//!
//! A field that is `None` means "the scene's own": the scene's datasheet calibration, its drive
//! frequency, no target, the board's default scene. [`Record::DEFAULTS`] is all `None`.
//!
//! # Encoding, versions 1 and 2 (64 bytes, little-endian)
//!
//! Version 2 adds the signed net-force target (issue 27): target kind 4, its value an `i32`
//! in mN. A record is written with the lowest version that carries it (1 unless its target is
//! a net force), so a firmware that knows only version 1 still reads every record it could
//! have written, and refuses a net-force record as `other-version` instead of misreading it.
//! Both versions are read; kind 4 in a version-1 record is `Invalid::Target`.
//!
//! | bytes | field |
//! |---|---|
//! | 0..4 | magic `SLST` |
//! | 4 | version, 1 or 2 |
//! | 5 | presence flags: bit 0 scene, 1 normal calibration, 2 tangential calibration, 3 target, 4 drive frequency; bits 5-7 zero |
//! | 6 | scene name length, 0 when absent, else 1..=24 |
//! | 7 | target kind: 0 none, 1 force, 2 coef, 3 reduction, 4 net force (version 2) |
//! | 8..32 | scene name, zero padded |
//! | 32..40 | normal cell: offset (Q1.31 fraction of full scale, i32), span (Q16.16 N per full scale, i32) |
//! | 40..48 | tangential cell: offset, span |
//! | 48..52 | calibration counter, u32 |
//! | 52..56 | target value, u32 scaled (mN, ppm, milli-percent); i32 mN for the net force |
//! | 56..60 | drive frequency, u32 cHz |
//! | 60..64 | CRC-32 of bytes 0..60 |
//!
//! Absent fields are zero. Decoding checks, in order: length, magic, version, CRC, flags,
//! then every range, and names the first failure ([`Invalid`]).

use super::crc::crc32;
use crate::protocol::{MAX_SCENE_NAME_LEN, SceneName, Target, TargetRange};

/// Bytes of an encoded record.
pub const RECORD_LEN: usize = 64;
/// The record format's newest version (written for a net-force target; others are written as
/// version 1, [`RECORD_VERSION_UNSIGNED`]).
pub const RECORD_VERSION: u8 = 2;
/// The first version: the three unsigned target kinds only.
pub const RECORD_VERSION_UNSIGNED: u8 = 1;
const RECORD_MAGIC: [u8; 4] = *b"SLST";

/// Lowest and highest drive frequency that may be stored, cHz (the `freq` command's range).
pub const FREQ_RANGE_CHZ: core::ops::RangeInclusive<u32> = 2_000_000..=6_000_000;

/// One load cell's calibration, as [`crate::sense::Calibration`] holds it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AxisCal {
    /// The reading that means zero: Q1.31 fraction of the converter's full scale (bits), any
    /// value in `[-1, 1)`.
    pub offset_q31: i32,
    /// Newtons of one full scale: Q16.16 (bits), non-zero (negative for a cell mounted the
    /// other way round).
    pub span_q16: i32,
}

/// What is kept across resets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Record {
    /// The selected scene; `None`: the board's default scene.
    pub scene: Option<SceneName>,
    /// The normal cell's calibration; `None`: the scene's datasheet calibration.
    pub normal: Option<AxisCal>,
    /// The tangential cell's calibration; `None`: the scene's datasheet calibration.
    pub tangential: Option<AxisCal>,
    /// Successful `tare` and `cal` commands since the defaults, saturating.
    pub cal_count: u32,
    /// The last friction target; `None`: no target.
    pub target: Option<Target>,
    /// The drive frequency (set by `freq` or found by the resonance search), cHz in
    /// [`FREQ_RANGE_CHZ`]; `None`: the scene's.
    pub freq_chz: Option<u32>,
}

/// Why a stored record (or log) is not used. Each has a kebab-case [`Invalid::reason`] word for
/// the boot log and the `log` reply.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Invalid {
    /// Nothing is stored (a new or erased flash).
    Empty,
    /// The store could not be read (see [`super::StoreError`]).
    Storage,
    /// The item has the wrong length.
    Length,
    /// The first four bytes are not the magic.
    Magic,
    /// Written by another format version.
    Version(u8),
    /// The check value does not match the contents.
    Crc,
    /// Unknown flag bits, or a field's flag and contents disagree.
    Flags,
    /// The scene name is not a valid name.
    SceneName,
    /// No scene of this firmware has the stored name.
    UnknownScene,
    /// A stored calibration span of zero (every force would read zero).
    ZeroSpan,
    /// An unknown target kind or a value outside the `target` command's range.
    Target,
    /// A drive frequency outside 20-60 kHz.
    Freq,
    /// A log entry that is not a known event or fault code, or counts that disagree.
    LogEntry,
    /// The record passed its checks but the board could not apply it (its scene or
    /// calibration could not be built).
    Refused,
}

impl Invalid {
    /// The reason as one kebab-case word.
    pub const fn reason(self) -> &'static str {
        match self {
            Invalid::Empty => "nothing-stored",
            Invalid::Storage => "storage-unreadable",
            Invalid::Length => "bad-length",
            Invalid::Magic => "bad-magic",
            Invalid::Version(_) => "other-version",
            Invalid::Crc => "crc-mismatch",
            Invalid::Flags => "bad-flags",
            Invalid::SceneName => "bad-scene-name",
            Invalid::UnknownScene => "unknown-scene",
            Invalid::ZeroSpan => "zero-span",
            Invalid::Target => "target-out-of-range",
            Invalid::Freq => "freq-out-of-range",
            Invalid::LogEntry => "bad-log-entry",
            Invalid::Refused => "refused-by-board",
        }
    }
}

const FLAG_SCENE: u8 = 1 << 0;
const FLAG_NORMAL: u8 = 1 << 1;
const FLAG_TANGENTIAL: u8 = 1 << 2;
const FLAG_TARGET: u8 = 1 << 3;
const FLAG_FREQ: u8 = 1 << 4;
const FLAGS_KNOWN: u8 = FLAG_SCENE | FLAG_NORMAL | FLAG_TANGENTIAL | FLAG_TARGET | FLAG_FREQ;

impl Record {
    /// Everything the scene's own, no target, no calibration counted.
    pub const DEFAULTS: Record = Record {
        scene: None,
        normal: None,
        tangential: None,
        cal_count: 0,
        target: None,
        freq_chz: None,
    };

    /// The range checks (also applied by [`Record::decode`]); `known_scene` tells whether the
    /// firmware has a scene of that name.
    pub fn validate(&self, known_scene: impl Fn(&str) -> bool) -> Result<(), Invalid> {
        if let Some(scene) = &self.scene
            && !known_scene(scene.as_str())
        {
            return Err(Invalid::UnknownScene);
        }
        for cal in [self.normal, self.tangential].into_iter().flatten() {
            if cal.span_q16 == 0 {
                return Err(Invalid::ZeroSpan);
            }
        }
        if let Some(target) = &self.target
            && !target.is_valid()
        {
            return Err(Invalid::Target);
        }
        if let Some(freq) = self.freq_chz
            && !FREQ_RANGE_CHZ.contains(&freq)
        {
            return Err(Invalid::Freq);
        }
        Ok(())
    }

    /// The record's 64 bytes.
    pub fn encode(&self) -> [u8; RECORD_LEN] {
        let mut out = [0u8; RECORD_LEN];
        out[0..4].copy_from_slice(&RECORD_MAGIC);
        out[4] = if self.target.is_some_and(|target| target.is_signed()) {
            RECORD_VERSION
        } else {
            RECORD_VERSION_UNSIGNED
        };
        let mut flags = 0;
        if let Some(scene) = &self.scene {
            flags |= FLAG_SCENE;
            let name = scene.as_str().as_bytes();
            // A SceneName is 1..=24 bytes.
            out[6] = name.len() as u8;
            out[8..8 + name.len()].copy_from_slice(name);
        }
        for (flag, cal, at) in [
            (FLAG_NORMAL, self.normal, 32),
            (FLAG_TANGENTIAL, self.tangential, 40),
        ] {
            if let Some(cal) = cal {
                flags |= flag;
                out[at..at + 4].copy_from_slice(&cal.offset_q31.to_le_bytes());
                out[at + 4..at + 8].copy_from_slice(&cal.span_q16.to_le_bytes());
            }
        }
        out[48..52].copy_from_slice(&self.cal_count.to_le_bytes());
        if let Some(target) = &self.target {
            flags |= FLAG_TARGET;
            out[7] = match target {
                Target::Force { .. } => 1,
                Target::Coef { .. } => 2,
                Target::Reduction { .. } => 3,
                Target::NetForce { .. } => 4,
            };
            // Valid values fit the field (u32, or i32 for the net force, two's complement);
            // an invalid one is refused by `decode` either way.
            let value = target.scaled_value() as u32;
            out[52..56].copy_from_slice(&value.to_le_bytes());
        }
        if let Some(freq) = self.freq_chz {
            flags |= FLAG_FREQ;
            out[56..60].copy_from_slice(&freq.to_le_bytes());
        }
        out[5] = flags;
        let crc = crc32(&out[..60]);
        out[60..64].copy_from_slice(&crc.to_le_bytes());
        out
    }

    /// Reads a stored record: length, magic, version, CRC, flags, then the ranges of
    /// [`Record::validate`]. Never panics, whatever the bytes.
    pub fn decode(bytes: &[u8], known_scene: impl Fn(&str) -> bool) -> Result<Record, Invalid> {
        let bytes: &[u8; RECORD_LEN] = bytes.try_into().map_err(|_| Invalid::Length)?;
        if bytes[0..4] != RECORD_MAGIC {
            return Err(Invalid::Magic);
        }
        let version = bytes[4];
        if version != RECORD_VERSION && version != RECORD_VERSION_UNSIGNED {
            return Err(Invalid::Version(version));
        }
        if crc32(&bytes[..60]) != u32_at(bytes, 60) {
            return Err(Invalid::Crc);
        }
        let flags = bytes[5];
        if flags & !FLAGS_KNOWN != 0 {
            return Err(Invalid::Flags);
        }
        let has = |flag: u8| flags & flag != 0;
        let name_len = usize::from(bytes[6]);
        let scene = if has(FLAG_SCENE) {
            if name_len == 0 || name_len > MAX_SCENE_NAME_LEN {
                return Err(Invalid::SceneName);
            }
            if bytes[8 + name_len..32].iter().any(|&b| b != 0) {
                return Err(Invalid::Flags);
            }
            let name =
                core::str::from_utf8(&bytes[8..8 + name_len]).map_err(|_| Invalid::SceneName)?;
            Some(SceneName::new(name).ok_or(Invalid::SceneName)?)
        } else {
            if name_len != 0 || bytes[8..32].iter().any(|&b| b != 0) {
                return Err(Invalid::Flags);
            }
            None
        };
        let cal = |flag: u8, at: usize| -> Result<Option<AxisCal>, Invalid> {
            let cal = AxisCal {
                offset_q31: u32_at(bytes, at) as i32,
                span_q16: u32_at(bytes, at + 4) as i32,
            };
            match (has(flag), cal) {
                (true, cal) => Ok(Some(cal)),
                (
                    false,
                    AxisCal {
                        offset_q31: 0,
                        span_q16: 0,
                    },
                ) => Ok(None),
                (false, _) => Err(Invalid::Flags),
            }
        };
        let normal = cal(FLAG_NORMAL, 32)?;
        let tangential = cal(FLAG_TANGENTIAL, 40)?;
        let value = u32_at(bytes, 52);
        let target = match (has(FLAG_TARGET), bytes[7]) {
            (false, 0) if value == 0 => None,
            (false, _) => return Err(Invalid::Flags),
            (true, 1) => Some(Target::Force { force_mn: value }),
            (true, 2) => Some(Target::Coef { coef_ppm: value }),
            (true, 3) => Some(Target::Reduction {
                reduction_mpct: value,
            }),
            (true, 4) if version >= RECORD_VERSION => Some(Target::NetForce {
                force_mn: value as i32,
            }),
            (true, _) => return Err(Invalid::Target),
        };
        let freq = u32_at(bytes, 56);
        let freq_chz = match (has(FLAG_FREQ), freq) {
            (true, freq) => Some(freq),
            (false, 0) => None,
            (false, _) => return Err(Invalid::Flags),
        };
        let record = Record {
            scene,
            normal,
            tangential,
            cal_count: u32_at(bytes, 48),
            target,
            freq_chz,
        };
        record.validate(known_scene)?;
        Ok(record)
    }
}

/// The little-endian u32 at `at` (callers index inside the fixed-size array).
pub(super) fn u32_at<const N: usize>(bytes: &[u8; N], at: usize) -> u32 {
    let mut word = [0u8; 4];
    if let Some(src) = bytes.get(at..at + 4) {
        word.copy_from_slice(src);
    }
    u32::from_le_bytes(word)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use proptest::prelude::*;

    pub(crate) fn known(name: &str) -> bool {
        // The longest name is the protocol's limit, 24 bytes (a 25-byte name is no SceneName).
        ["reference", "demo", "a-scene-name-of-24-bytes"].contains(&name)
    }

    pub(crate) fn sample(n: u32) -> Record {
        Record {
            scene: SceneName::new("reference"),
            normal: Some(AxisCal {
                offset_q31: -123_456_789,
                span_q16: 100 << 16,
            }),
            tangential: Some(AxisCal {
                offset_q31: i32::MIN,
                span_q16: -(50 << 16) - 7,
            }),
            cal_count: n,
            target: Some(Target::Coef {
                coef_ppm: 150_000 + n,
            }),
            freq_chz: Some(3_950_050),
        }
    }

    fn any_record() -> impl Strategy<Value = Record> {
        let cal = prop_oneof![
            Just(None),
            (any::<i32>(), any::<i32>().prop_filter("zero", |s| *s != 0)).prop_map(
                |(offset_q31, span_q16)| Some(AxisCal {
                    offset_q31,
                    span_q16
                })
            )
        ];
        let target = prop_oneof![
            Just(None),
            (1u32..=50_000_000).prop_map(|force_mn| Some(Target::Force { force_mn })),
            (1u32..=2_000_000).prop_map(|coef_ppm| Some(Target::Coef { coef_ppm })),
            (0u32..=99_999).prop_map(|reduction_mpct| Some(Target::Reduction { reduction_mpct })),
            (-50_000_000i32..=50_000_000).prop_map(|force_mn| Some(Target::NetForce { force_mn })),
        ];
        let scene = prop_oneof![
            Just(None),
            Just(SceneName::new("demo")),
            Just(SceneName::new("a-scene-name-of-24-bytes"))
        ];
        let freq = prop_oneof![Just(None), (2_000_000u32..=6_000_000).prop_map(Some)];
        (scene, cal.clone(), cal, any::<u32>(), target, freq).prop_map(
            |(scene, normal, tangential, cal_count, target, freq_chz)| Record {
                scene,
                normal,
                tangential,
                cal_count,
                target,
                freq_chz,
            },
        )
    }

    /// A version-1 record as the firmware before the net-force target wrote it (bytes laid
    /// out by hand from the version-1 table): still read, and written back identically.
    #[test]
    fn version_one_records_stay_loadable() {
        let mut old = [0u8; RECORD_LEN];
        old[0..4].copy_from_slice(b"SLST");
        old[4] = 1;
        old[5] = FLAG_SCENE | FLAG_TARGET;
        old[6] = 9;
        old[7] = 3; // reduction
        old[8..17].copy_from_slice(b"reference");
        old[52..56].copy_from_slice(&35_000u32.to_le_bytes());
        let crc = crc32(&old[..60]);
        old[60..64].copy_from_slice(&crc.to_le_bytes());
        let record = Record::decode(&old, known).unwrap();
        assert_eq!(
            record.target,
            Some(Target::Reduction {
                reduction_mpct: 35_000
            })
        );
        assert_eq!(record.scene, SceneName::new("reference"));
        assert_eq!(record.encode(), old);
        // The net force is written as version 2, with its sign; kind 4 under version 1 is
        // a target the old format cannot hold.
        let mut signed = record;
        signed.target = Some(Target::NetForce { force_mn: -5_000 });
        let bytes = signed.encode();
        assert_eq!(bytes[4], RECORD_VERSION);
        assert_eq!(bytes[7], 4);
        assert_eq!(Record::decode(&bytes, known), Ok(signed));
        let mut as_v1 = bytes;
        as_v1[4] = RECORD_VERSION_UNSIGNED;
        let crc = crc32(&as_v1[..60]);
        as_v1[60..64].copy_from_slice(&crc.to_le_bytes());
        assert_eq!(Record::decode(&as_v1, known), Err(Invalid::Target));
    }

    #[test]
    fn defaults_and_a_full_record_round_trip() {
        for record in [Record::DEFAULTS, sample(7)] {
            assert_eq!(Record::decode(&record.encode(), known), Ok(record));
        }
    }

    #[test]
    fn each_check_names_its_failure() {
        let good = sample(3).encode();
        let recrc = |mut bytes: [u8; RECORD_LEN]| {
            let crc = crc32(&bytes[..60]);
            bytes[60..64].copy_from_slice(&crc.to_le_bytes());
            bytes
        };
        assert_eq!(Record::decode(&good[..63], known), Err(Invalid::Length));
        assert_eq!(Record::decode(&[], known), Err(Invalid::Length));
        let mut bad = good;
        bad[0] = b'X';
        assert_eq!(Record::decode(&bad, known), Err(Invalid::Magic));
        let mut bad = good;
        bad[4] = 3;
        assert_eq!(Record::decode(&bad, known), Err(Invalid::Version(3)));
        let mut bad = good;
        bad[50] ^= 0x10;
        assert_eq!(Record::decode(&bad, known), Err(Invalid::Crc));
        let mut bad = good;
        bad[5] |= 0x80;
        assert_eq!(Record::decode(&recrc(bad), known), Err(Invalid::Flags));
        let mut bad = good;
        bad[8] = b'R';
        assert_eq!(Record::decode(&recrc(bad), known), Err(Invalid::SceneName));
        let mut bad = good;
        bad[8] = b'x';
        assert_eq!(
            Record::decode(&recrc(bad), known),
            Err(Invalid::UnknownScene)
        );
        let mut bad = good;
        bad[36..40].fill(0);
        assert_eq!(Record::decode(&recrc(bad), known), Err(Invalid::ZeroSpan));
        let mut bad = good;
        bad[7] = 4;
        assert_eq!(Record::decode(&recrc(bad), known), Err(Invalid::Target));
        let mut bad = good;
        bad[52..56].copy_from_slice(&2_000_001u32.to_le_bytes());
        assert_eq!(Record::decode(&recrc(bad), known), Err(Invalid::Target));
        let mut bad = good;
        bad[56..60].copy_from_slice(&6_000_001u32.to_le_bytes());
        assert_eq!(Record::decode(&recrc(bad), known), Err(Invalid::Freq));
        let mut bad = good;
        bad[56..60].copy_from_slice(&1_999_999u32.to_le_bytes());
        assert_eq!(Record::decode(&recrc(bad), known), Err(Invalid::Freq));
        // A present value behind a cleared flag.
        let mut bad = good;
        bad[5] &= !FLAG_FREQ;
        assert_eq!(Record::decode(&recrc(bad), known), Err(Invalid::Flags));
        // Erased flash reads 0xFF.
        assert_eq!(
            Record::decode(&[0xFF; RECORD_LEN], known),
            Err(Invalid::Magic)
        );
    }

    #[test]
    fn range_extremes() {
        let mut record = sample(7);
        record.cal_count = u32::MAX;
        for freq in [2_000_000, 6_000_000] {
            record.freq_chz = Some(freq);
            assert_eq!(Record::decode(&record.encode(), known), Ok(record));
        }
        for target in [
            Target::Force { force_mn: 1 },
            Target::Force {
                force_mn: 50_000_000,
            },
            Target::Coef {
                coef_ppm: 2_000_000,
            },
            Target::Reduction { reduction_mpct: 0 },
            Target::Reduction {
                reduction_mpct: 99_999,
            },
            Target::NetForce {
                force_mn: -50_000_000,
            },
            Target::NetForce {
                force_mn: 50_000_000,
            },
            Target::NetForce { force_mn: 0 },
        ] {
            record.target = Some(target);
            assert_eq!(Record::decode(&record.encode(), known), Ok(record));
        }
        for target in [
            Target::Force { force_mn: 0 },
            Target::Coef { coef_ppm: 0 },
            Target::Reduction {
                reduction_mpct: 100_000,
            },
            Target::NetForce {
                force_mn: -50_000_001,
            },
            Target::NetForce { force_mn: i32::MIN },
        ] {
            record.target = Some(target);
            assert_eq!(
                Record::decode(&record.encode(), known),
                Err(Invalid::Target)
            );
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2_000))]

        #[test]
        fn every_valid_record_round_trips(record in any_record()) {
            prop_assert_eq!(Record::decode(&record.encode(), known), Ok(record));
        }

        /// Garbage never panics and is never taken for a record unless it carries the magic,
        /// version and a matching CRC.
        #[test]
        fn garbage_is_refused(bytes in proptest::collection::vec(any::<u8>(), 0..80)) {
            if let Ok(record) = Record::decode(&bytes, known) {
                let encoded = record.encode();
                prop_assert_eq!(encoded.as_slice(), bytes.as_slice());
            }
        }

        /// Any one corrupted byte of a valid record is found.
        #[test]
        fn one_corrupted_byte_is_found(record in any_record(), at in 0usize..RECORD_LEN, x in 1u8..=255) {
            let mut bytes = record.encode();
            bytes[at] ^= x;
            prop_assert!(Record::decode(&bytes, known).is_err());
        }
    }
}
