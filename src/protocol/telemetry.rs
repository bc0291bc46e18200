//! Telemetry records: one line per control-loop sample sent, tagged `tel`.
//!
//! The format (every field, its unit and range) is documented in the
//! [module documentation](super#telemetry); the field order is fixed and the decoder insists on
//! it, so a record that parses is a record the firmware of this protocol version wrote.

use heapless::string::StringView;

use super::decode::{DecodeError, check_pairs, strip_terminator, words};
use super::lock::Lock;
use super::number::{NumberError, decode_i32, decode_u32, decode_u64};
use super::reach::{ReachState, ResonanceDistance, RunReach, UNKNOWN_WORD};
use super::reading::LoopReading;
use super::state::SupervisorState;
use super::target::{decode_target, write_target};
use super::text::{FormatError, put, put_fixed, put_uint, write_line};

/// First word of every telemetry line; replies start with `ok` or `err`.
pub const TELEMETRY_TAG: &str = "tel";

/// Buffer size (bytes) that holds every telemetry line; the longest possible line is 337 bytes
/// (265 before the reach fields of protocol 2).
pub const TELEMETRY_CAPACITY: usize = 352;

/// One telemetry sample. All fields take their full integer range on the wire.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TelemetryRecord {
    /// Time of the sample in µs since boot.
    pub time_us: u64,
    /// Record number, +1 per record produced (sent or lost), wrapping.
    pub seq: u32,
    /// State, target, friction estimate and drive.
    pub reading: LoopReading,
    /// Control-loop overruns since boot.
    pub overruns: u32,
    /// Records dropped since boot because the UART was still busy.
    pub lost_records: u32,
    /// The resonance loop's state; `None` (`none`) without a loop.
    pub lock: Option<Lock>,
    /// The motional current's phase to the drive voltage, mdeg; `None` (`undefined`) before
    /// anything was measured.
    pub phase_mdeg: Option<i32>,
    /// Whether the target is within reach, and the drive near the resonance.
    pub reach: RunReach,
}

// Keys in line order; the decoder names them in its errors.
const KEY_TIME: &str = "t_us";
const KEY_SEQ: &str = "seq";
const KEY_STATE: &str = "state";
const KEY_TARGET: &str = "target";
const KEY_MU: &str = "mu";
const KEY_NORMAL: &str = "normal_n";
const KEY_TANGENTIAL: &str = "tangential_n";
const KEY_AMP: &str = "amp";
const KEY_FREQ: &str = "freq_hz";
const KEY_OVERRUNS: &str = "overruns";
const KEY_LOST: &str = "lost";
const KEY_LOCK: &str = "lock";
const KEY_PHASE: &str = "phase_deg";
const KEY_REACH: &str = "reach";
const KEY_REACHABLE: &str = "reachable";
const KEY_RESONANCE: &str = "resonance";
/// The word of an undefined phase.
const UNDEFINED: &str = "undefined";

/// Fraction digits of the scaled fields: ppm and mN and cHz.
const PPM_DECIMALS: u8 = 6;
const MN_DECIMALS: u8 = 3;
const CHZ_DECIMALS: u8 = 2;

/// Writes `record` as one `tel ...\n` line, replacing the buffer's contents. Cannot fail with a
/// buffer of [`TELEMETRY_CAPACITY`] bytes.
pub fn format_telemetry(record: &TelemetryRecord, out: &mut StringView) -> Result<(), FormatError> {
    write_line(out, |out| {
        put(out, TELEMETRY_TAG)?;
        key(out, KEY_TIME)?;
        put_uint(out, record.time_us)?;
        key(out, KEY_SEQ)?;
        put_uint(out, u64::from(record.seq))?;
        key(out, KEY_STATE)?;
        put(out, record.reading.state.name())?;
        key(out, KEY_TARGET)?;
        write_target(out, record.reading.target.as_ref())?;
        key(out, KEY_MU)?;
        put_fixed(
            out,
            i64::from(record.reading.friction_coef_ppm),
            PPM_DECIMALS,
        )?;
        key(out, KEY_NORMAL)?;
        put_fixed(out, i64::from(record.reading.normal_force_mn), MN_DECIMALS)?;
        key(out, KEY_TANGENTIAL)?;
        put_fixed(
            out,
            i64::from(record.reading.tangential_force_mn),
            MN_DECIMALS,
        )?;
        key(out, KEY_AMP)?;
        put_fixed(
            out,
            i64::from(record.reading.drive_amplitude_ppm),
            PPM_DECIMALS,
        )?;
        key(out, KEY_FREQ)?;
        put_fixed(out, i64::from(record.reading.drive_freq_chz), CHZ_DECIMALS)?;
        key(out, KEY_OVERRUNS)?;
        put_uint(out, u64::from(record.overruns))?;
        key(out, KEY_LOST)?;
        put_uint(out, u64::from(record.lost_records))?;
        key(out, KEY_LOCK)?;
        put(out, record.lock.map_or(super::NONE, Lock::name))?;
        key(out, KEY_PHASE)?;
        match record.phase_mdeg {
            Some(mdeg) => put_fixed(out, i64::from(mdeg), MN_DECIMALS)?,
            None => put(out, UNDEFINED)?,
        }
        key(out, KEY_REACH)?;
        put(out, record.reach.state.name())?;
        key(out, KEY_REACHABLE)?;
        write_target(out, record.reach.reachable.as_ref())?;
        key(out, KEY_RESONANCE)?;
        put(
            out,
            record
                .reach
                .resonance
                .map_or(UNKNOWN_WORD, ResonanceDistance::name),
        )?;
        put(out, "\n")
    })
}

/// Appends ` key=`.
fn key(out: &mut StringView, key: &str) -> Result<(), FormatError> {
    put(out, " ")?;
    put(out, key)?;
    put(out, "=")
}

/// The fields of a record line, read in their fixed order.
struct Fields<'a, I: Iterator<Item = &'a str>> {
    words: I,
}

impl<'a, I: Iterator<Item = &'a str>> Fields<'a, I> {
    /// The value of the next field, which must have key `key`.
    fn next(&mut self, key: &'static str) -> Result<&'a str, DecodeError> {
        let word = self.words.next().ok_or(DecodeError::MissingField { key })?;
        match word.split_once('=') {
            Some((found, value)) if found == key => Ok(value),
            _ => Err(DecodeError::UnexpectedField { key }),
        }
    }

    /// The next field read as a number with `decode`.
    fn number<T>(
        &mut self,
        key: &'static str,
        decimals: u8,
        decode: fn(&str, u8) -> Result<T, NumberError>,
    ) -> Result<T, DecodeError> {
        let value = self.next(key)?;
        decode(value, decimals).map_err(|error| DecodeError::BadNumber { key, error })
    }
}

/// Decodes a telemetry line (with or without its terminator).
///
/// Fields must appear once each in the documented order; numbers may have fewer decimals than
/// printed (`mu=0.35` is read as 350000 ppm) but never a non-zero digit finer than their unit.
pub fn parse_telemetry(line: &str) -> Result<TelemetryRecord, DecodeError> {
    let line = strip_terminator(line);
    let mut all = words(line);
    match all.next() {
        Some(TELEMETRY_TAG) => {}
        Some(_) => return Err(DecodeError::UnknownTag),
        None => return Err(DecodeError::Empty),
    }
    let body = line
        .trim_start_matches([' ', '\t'])
        .get(TELEMETRY_TAG.len()..)
        .unwrap_or("");
    check_pairs(body)?;
    let mut fields = Fields { words: all };
    let record = TelemetryRecord {
        time_us: fields.number(KEY_TIME, 0, decode_u64)?,
        seq: fields.number(KEY_SEQ, 0, decode_u32)?,
        reading: LoopReading {
            state: SupervisorState::from_name(fields.next(KEY_STATE)?)
                .ok_or(DecodeError::BadState)?,
            target: decode_target(fields.next(KEY_TARGET)?).map_err(DecodeError::BadTarget)?,
            friction_coef_ppm: fields.number(KEY_MU, PPM_DECIMALS, decode_u32)?,
            normal_force_mn: fields.number(KEY_NORMAL, MN_DECIMALS, decode_i32)?,
            tangential_force_mn: fields.number(KEY_TANGENTIAL, MN_DECIMALS, decode_i32)?,
            drive_amplitude_ppm: fields.number(KEY_AMP, PPM_DECIMALS, decode_u32)?,
            drive_freq_chz: fields.number(KEY_FREQ, CHZ_DECIMALS, decode_u32)?,
        },
        overruns: fields.number(KEY_OVERRUNS, 0, decode_u32)?,
        lost_records: fields.number(KEY_LOST, 0, decode_u32)?,
        lock: match fields.next(KEY_LOCK)? {
            word if word == super::NONE => None,
            // An unknown lock word is a bad state word, like `state=`'s.
            word => Some(Lock::from_name(word).ok_or(DecodeError::BadState)?),
        },
        phase_mdeg: match fields.next(KEY_PHASE)? {
            UNDEFINED => None,
            value => {
                Some(
                    decode_i32(value, MN_DECIMALS).map_err(|error| DecodeError::BadNumber {
                        key: KEY_PHASE,
                        error,
                    })?,
                )
            }
        },
        reach: RunReach {
            state: ReachState::from_name(fields.next(KEY_REACH)?).ok_or(DecodeError::BadState)?,
            reachable: decode_target(fields.next(KEY_REACHABLE)?)
                .map_err(DecodeError::BadTarget)?,
            resonance: match fields.next(KEY_RESONANCE)? {
                UNKNOWN_WORD => None,
                word => Some(ResonanceDistance::from_name(word).ok_or(DecodeError::BadState)?),
            },
        },
    };
    match fields.words.next() {
        Some(_) => Err(DecodeError::ExtraField),
        None => Ok(record),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::Target;
    use crate::protocol::decode::{Incoming, parse_incoming};
    use heapless::String;
    use proptest::prelude::*;

    type Line = String<TELEMETRY_CAPACITY>;

    const EXAMPLE: &str = "tel t_us=1250000 seq=12500 state=running target=force:12.500 \
        mu=0.312000 normal_n=40.000 tangential_n=-12.480 amp=0.523000 freq_hz=40000.00 \
        overruns=0 lost=3 lock=locked phase_deg=-0.250 reach=target-unreachable \
        reachable=force:14.000 resonance=near\n";

    fn example() -> TelemetryRecord {
        TelemetryRecord {
            time_us: 1_250_000,
            seq: 12_500,
            reading: LoopReading {
                state: SupervisorState::Running,
                target: Some(Target::Force { force_mn: 12_500 }),
                friction_coef_ppm: 312_000,
                normal_force_mn: 40_000,
                tangential_force_mn: -12_480,
                drive_amplitude_ppm: 523_000,
                drive_freq_chz: 4_000_000,
            },
            overruns: 0,
            lost_records: 3,
            lock: Some(Lock::Locked),
            phase_mdeg: Some(-250),
            reach: RunReach {
                state: ReachState::TargetUnreachable,
                reachable: Some(Target::Force { force_mn: 14_000 }),
                resonance: Some(ResonanceDistance::Near),
            },
        }
    }

    fn line(record: &TelemetryRecord) -> Line {
        let mut out = Line::new();
        format_telemetry(record, &mut out).unwrap();
        out
    }

    #[test]
    fn documented_example() {
        assert_eq!(line(&example()), EXAMPLE);
        assert_eq!(parse_telemetry(EXAMPLE), Ok(example()));
        assert_eq!(parse_incoming(EXAMPLE), Ok(Incoming::Telemetry(example())));
    }

    #[test]
    fn the_longest_record_fits() {
        let record = TelemetryRecord {
            time_us: u64::MAX,
            seq: u32::MAX,
            reading: LoopReading {
                state: SupervisorState::Calibrating,
                target: Some(Target::Reduction {
                    reduction_mpct: u32::MAX,
                }),
                friction_coef_ppm: u32::MAX,
                normal_force_mn: i32::MIN,
                tangential_force_mn: i32::MIN,
                drive_amplitude_ppm: u32::MAX,
                drive_freq_chz: u32::MAX,
            },
            overruns: u32::MAX,
            lost_records: u32::MAX,
            lock: Some(Lock::Searching),
            phase_mdeg: Some(i32::MIN),
            reach: RunReach {
                state: ReachState::TargetUnreachable,
                reachable: Some(Target::Reduction {
                    reduction_mpct: u32::MAX,
                }),
                resonance: Some(ResonanceDistance::Near),
            },
        };
        let text = line(&record);
        assert_eq!(text.len(), 337, "{text}");
        assert_eq!(parse_telemetry(&text), Ok(record));
    }

    #[test]
    fn decoder_errors() {
        let replace = |from: &str, to: &str| EXAMPLE.replacen(from, to, 1);
        assert_eq!(parse_telemetry(""), Err(DecodeError::Empty));
        assert_eq!(parse_telemetry("ok a=1"), Err(DecodeError::UnknownTag));
        assert_eq!(
            parse_telemetry(&replace("seq=12500 ", "")),
            Err(DecodeError::UnexpectedField { key: "seq" })
        );
        assert_eq!(
            parse_telemetry(&replace(" resonance=near", "")),
            Err(DecodeError::MissingField { key: "resonance" })
        );
        assert_eq!(
            parse_telemetry(&replace("resonance=near", "resonance=near extra=1")),
            Err(DecodeError::ExtraField)
        );
        assert_eq!(
            parse_telemetry(&replace("resonance=near", "resonance=near extra")),
            Err(DecodeError::BadPair { index: 16 })
        );
        assert_eq!(
            parse_telemetry(&replace("lock=locked", "lock=wobbly")),
            Err(DecodeError::BadState)
        );
        assert_eq!(
            parse_telemetry(&replace("reach=target-unreachable", "reach=maybe")),
            Err(DecodeError::BadState)
        );
        assert_eq!(
            parse_telemetry(&replace("resonance=near", "resonance=unknown")),
            Ok(TelemetryRecord {
                reach: RunReach {
                    resonance: None,
                    ..example().reach
                },
                ..example()
            })
        );
        assert_eq!(
            parse_telemetry(&replace("phase_deg=-0.250", "phase_deg=undefined")),
            Ok(TelemetryRecord {
                phase_mdeg: None,
                ..example()
            })
        );
        assert!(matches!(
            parse_telemetry(&replace("phase_deg=-0.250", "phase_deg=-0.2501")),
            Err(DecodeError::BadNumber {
                key: "phase_deg",
                ..
            })
        ));
        assert_eq!(
            parse_telemetry(&replace("state=running", "state=dancing")),
            Err(DecodeError::BadState)
        );
        assert!(matches!(
            parse_telemetry(&replace("force:", "speed:")),
            Err(DecodeError::BadTarget(_))
        ));
        assert_eq!(
            parse_telemetry(&replace("mu=0.312000", "mu=0.3120001")),
            Err(DecodeError::BadNumber {
                key: "mu",
                error: NumberError::TooManyDecimals
            })
        );
        assert_eq!(
            parse_telemetry(&replace("normal_n=40.000", "normal_n=3000000")),
            Err(DecodeError::BadNumber {
                key: "normal_n",
                error: NumberError::OutOfRange
            })
        );
        // Shorter numbers and extra spacing are read; the record is the same.
        let loose = replace("mu=0.312000", "mu=0.312").replace(' ', "  \t");
        assert_eq!(parse_telemetry(&loose), Ok(example()));
    }

    fn any_target() -> impl Strategy<Value = Option<Target>> {
        prop_oneof![
            Just(None),
            any::<u32>().prop_map(|force_mn| Some(Target::Force { force_mn })),
            any::<u32>().prop_map(|coef_ppm| Some(Target::Coef { coef_ppm })),
            any::<u32>().prop_map(|reduction_mpct| Some(Target::Reduction { reduction_mpct })),
        ]
    }

    fn any_record() -> impl Strategy<Value = TelemetryRecord> {
        (
            (
                any::<u64>(),
                any::<u32>(),
                proptest::sample::select(&SupervisorState::ALL[..]),
            ),
            any_target(),
            (any::<u32>(), any::<i32>(), any::<i32>()),
            (any::<u32>(), any::<u32>(), any::<u32>(), any::<u32>()),
            (
                proptest::option::of(proptest::sample::select(&Lock::ALL[..])),
                proptest::option::of(any::<i32>()),
                proptest::sample::select(&ReachState::ALL[..]),
                any_target(),
                proptest::option::of(proptest::sample::select(&ResonanceDistance::ALL[..])),
            ),
        )
            .prop_map(
                |(
                    (time_us, seq, state),
                    target,
                    (mu, normal, tangential),
                    (amp, freq, overruns, lost),
                    (lock, phase_mdeg, reach, reachable, resonance),
                )| {
                    TelemetryRecord {
                        time_us,
                        seq,
                        reading: LoopReading {
                            state,
                            target,
                            friction_coef_ppm: mu,
                            normal_force_mn: normal,
                            tangential_force_mn: tangential,
                            drive_amplitude_ppm: amp,
                            drive_freq_chz: freq,
                        },
                        overruns,
                        lost_records: lost,
                        lock,
                        phase_mdeg,
                        reach: RunReach {
                            state: reach,
                            reachable,
                            resonance,
                        },
                    }
                },
            )
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2_000))]

        /// Property (c): any record formats into the buffer and parses back to itself.
        #[test]
        fn records_round_trip(record in any_record()) {
            let text = line(&record);
            prop_assert!(text.ends_with('\n') && text.starts_with("tel "));
            prop_assert_eq!(parse_telemetry(&text), Ok(record));
        }
    }
}
