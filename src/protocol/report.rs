//! The replies that carry data: `status`, `faults`, `version`, `scene list` and `help`.
//!
//! The firmware fills a report struct with integers and names and hands it to its formatter;
//! names are `&'static str` words (see [`is_word`](super::is_word)) because they come from
//! tables in the firmware, never from received text.

use heapless::string::StringView;

use super::command::KEYWORDS;
use super::reading::LoopReading;
use super::reply::{NONE, OkReply};
use super::text::FormatError;

/// The data of a `status` reply. Counters saturate at `u32::MAX` in the firmware.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct StatusReport {
    /// State, target, friction estimate and drive.
    pub reading: LoopReading,
    /// Selected scene (a word), if any.
    pub scene: Option<&'static str>,
    /// Control-loop overruns since boot.
    pub overruns: u32,
    /// Telemetry records dropped because the UART was busy, since boot.
    pub lost_telemetry: u32,
    /// The latched fault (a word), if any.
    pub latched_fault: Option<&'static str>,
    /// The resonance loop's state (a word: `pinned`, `searching`, `tracking`, `locked`,
    /// `lost`); `None` (`none`) without a loop.
    pub lock: Option<&'static str>,
    /// The motional current's phase to the voltage (the tracker's phase error), millidegrees;
    /// `None` (`undefined`) before a window with current was measured.
    pub phase_mdeg: Option<i32>,
    /// Whether the target is within reach, and the drive near the resonance.
    pub reach: super::RunReach,
    /// The loop runs on commissioned values (`values=commissioned`: a `commission`'s, or
    /// restored by `load`) instead of the scene's declared ones (`values=declared`).
    pub commissioned: bool,
}

/// The data of a `faults` reply: names (words other than `none`) of faults.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FaultReport<'a> {
    /// Faults latched until `clear`.
    pub latched: &'a [&'static str],
    /// Fault conditions present now (latched or not).
    pub active: &'a [&'static str],
}

/// The data of a `version` reply.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct VersionReport {
    /// Firmware version (a word), for example `0.1.0`.
    pub firmware: &'static str,
    /// Board name (a word), for example `nucleo-g474re`.
    pub board: &'static str,
    /// Protocol version, normally [`PROTOCOL_VERSION`](super::PROTOCOL_VERSION).
    pub protocol: u16,
}

/// Writes the `status` reply:
/// `ok state= scene= target= mu= normal_n= tangential_n= amp= freq_hz= overruns= lost= fault=
/// lock= phase_deg= reach= reachable= resonance= values=` (`phase_deg=undefined` when no phase
/// was measured; `values=commissioned|declared`, protocol 3).
pub fn format_status(report: &StatusReport, out: &mut StringView) -> Result<(), FormatError> {
    let reply = OkReply::new(out)
        .word("state", report.reading.state.name())
        .word("scene", report.scene.unwrap_or(NONE))
        .target("target", report.reading.target.as_ref())
        .fixed("mu", i64::from(report.reading.friction_coef_ppm), 6)
        .fixed("normal_n", i64::from(report.reading.normal_force_mn), 3)
        .fixed(
            "tangential_n",
            i64::from(report.reading.tangential_force_mn),
            3,
        )
        .fixed("amp", i64::from(report.reading.drive_amplitude_ppm), 6)
        .fixed("freq_hz", i64::from(report.reading.drive_freq_chz), 2)
        .uint("overruns", u64::from(report.overruns))
        .uint("lost", u64::from(report.lost_telemetry))
        .word("fault", report.latched_fault.unwrap_or(NONE))
        .word("lock", report.lock.unwrap_or(NONE));
    let reply = match report.phase_mdeg {
        Some(mdeg) => reply.fixed("phase_deg", i64::from(mdeg), 3),
        None => reply.word("phase_deg", "undefined"),
    };
    reply
        .word("reach", report.reach.state.name())
        .target("reachable", report.reach.reachable.as_ref())
        .word(
            "resonance",
            report
                .reach
                .resonance
                .map_or(super::reach::UNKNOWN_WORD, super::ResonanceDistance::name),
        )
        .word(
            "values",
            if report.commissioned {
                "commissioned"
            } else {
                "declared"
            },
        )
        .finish()
}

/// Writes the `faults` reply: `ok latched=a,b active=c` (`none` for an empty list).
pub fn format_faults(report: &FaultReport<'_>, out: &mut StringView) -> Result<(), FormatError> {
    OkReply::new(out)
        .list("latched", report.latched)
        .list("active", report.active)
        .finish()
}

/// Writes the `version` reply: `ok firmware=0.1.0 board=qemu protocol=1`.
pub fn format_version(report: &VersionReport, out: &mut StringView) -> Result<(), FormatError> {
    OkReply::new(out)
        .word("firmware", report.firmware)
        .word("board", report.board)
        .uint("protocol", u64::from(report.protocol))
        .finish()
}

/// Writes the `scene list` reply: `ok count=2 scenes=demo,ramp` (`scenes=none` when empty).
/// Fails with [`FormatError::Overflow`] when the names do not fit the buffer.
pub fn format_scene_list(names: &[&str], out: &mut StringView) -> Result<(), FormatError> {
    OkReply::new(out)
        .uint("count", names.len() as u64)
        .list("scenes", names)
        .finish()
}

/// Writes the `help` reply: `ok commands=version,status,...,help`.
pub fn format_help(out: &mut StringView) -> Result<(), FormatError> {
    OkReply::new(out).list("commands", &KEYWORDS).finish()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::protocol::decode::{Reply, parse_reply};
    use crate::protocol::reply::REPLY_CAPACITY;
    use crate::protocol::text::MAX_WORD_LEN;
    use crate::protocol::{SupervisorState, Target};
    use heapless::String;
    use std::vec::Vec;

    type Line = String<REPLY_CAPACITY>;

    /// Issue 26: `scene list` showed 16 of 22 compiled scenes with `count=16` (a board kept
    /// 16 names, and the reply held 12 full-length ones). Every compiled scene fits the reply,
    /// with the right count, whatever the names.
    #[test]
    fn the_scene_list_of_every_compiled_scene_fits_with_its_count() {
        let mut out = Line::new();
        format_scene_list(&crate::scene::SCENE_NAMES, &mut out).unwrap();
        let expected = std::format!(
            "ok count={} scenes={}\n",
            crate::scene::SCENES.len(),
            crate::scene::SCENE_NAMES.join(",")
        );
        assert_eq!(out.as_str(), expected);
        // The capacity follows the names: 22 full-length names fit a buffer sized for them.
        let name = "n".repeat(24);
        let names: Vec<&str> = (0..22).map(|_| name.as_str()).collect();
        let needed = crate::protocol::reply::scene_list_len(&names);
        let mut big: String<{ 22 * 25 + 28 }> = String::new();
        format_scene_list(&names, &mut big).unwrap();
        assert!(big.len() <= needed, "{} > {needed}", big.len());
    }

    fn status_example() -> StatusReport {
        StatusReport {
            reading: LoopReading {
                state: SupervisorState::Running,
                target: Some(Target::Force { force_mn: 12_500 }),
                friction_coef_ppm: 312_000,
                normal_force_mn: 40_000,
                tangential_force_mn: 12_480,
                drive_amplitude_ppm: 523_000,
                drive_freq_chz: 4_000_000,
            },
            scene: Some("demo"),
            overruns: 0,
            lost_telemetry: 0,
            latched_fault: None,
            lock: Some("locked"),
            phase_mdeg: Some(-1_234),
            reach: crate::protocol::RunReach::UNKNOWN,
            commissioned: false,
        }
    }

    #[test]
    fn status_reply() {
        let mut out = Line::new();
        format_status(&status_example(), &mut out).unwrap();
        assert_eq!(
            out,
            "ok state=running scene=demo target=force:12.500 mu=0.312000 normal_n=40.000 \
             tangential_n=12.480 amp=0.523000 freq_hz=40000.00 overruns=0 lost=0 fault=none \
             lock=locked phase_deg=-1.234 reach=ok reachable=none resonance=unknown \
             values=declared\n"
        );
        let Ok(Reply::Ok(payload)) = parse_reply(&out) else {
            panic!("{out}")
        };
        assert_eq!(payload.get("tangential_n"), Some("12.480"));
        assert_eq!(payload.pairs().count(), 17);
        let mut undefined = status_example();
        undefined.phase_mdeg = None;
        undefined.lock = None;
        format_status(&undefined, &mut out).unwrap();
        assert!(out.contains(" lock=none phase_deg=undefined "), "{out}");
        let mut commissioned = status_example();
        commissioned.commissioned = true;
        format_status(&commissioned, &mut out).unwrap();
        assert!(out.ends_with(" values=commissioned\n"), "{out}");
    }

    #[test]
    fn the_longest_status_fits() {
        let word = "w".repeat(MAX_WORD_LEN);
        let word: &'static str = word.leak();
        let report = StatusReport {
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
            scene: Some(word),
            overruns: u32::MAX,
            lost_telemetry: u32::MAX,
            latched_fault: Some(word),
            // The longest lock word.
            lock: Some("searching"),
            phase_mdeg: Some(i32::MIN),
            reach: crate::protocol::RunReach {
                state: crate::protocol::ReachState::TargetUnreachable,
                reachable: Some(Target::Reduction {
                    reduction_mpct: u32::MAX,
                }),
                resonance: Some(crate::protocol::ResonanceDistance::Near),
            },
            commissioned: true,
        };
        let mut out = Line::new();
        format_status(&report, &mut out).unwrap();
        assert_eq!(out.len(), 393, "{out}");
    }

    #[test]
    fn faults_version_scenes_help() {
        let mut out = Line::new();
        let report = FaultReport {
            latched: &["overcurrent"],
            active: &["overcurrent", "force-range"],
        };
        format_faults(&report, &mut out).unwrap();
        assert_eq!(
            out,
            "ok latched=overcurrent active=overcurrent,force-range\n"
        );
        format_faults(
            &FaultReport {
                latched: &[],
                active: &[],
            },
            &mut out,
        )
        .unwrap();
        assert_eq!(out, "ok latched=none active=none\n");

        let version = VersionReport {
            firmware: "0.1.0",
            board: "qemu",
            protocol: crate::protocol::PROTOCOL_VERSION,
        };
        format_version(&version, &mut out).unwrap();
        assert_eq!(out, "ok firmware=0.1.0 board=qemu protocol=3\n");

        format_scene_list(&["demo", "ramp"], &mut out).unwrap();
        assert_eq!(out, "ok count=2 scenes=demo,ramp\n");
        format_scene_list(&[], &mut out).unwrap();
        assert_eq!(out, "ok count=0 scenes=none\n");
        // A list that does not fit is refused whole, never cut.
        let name = "n".repeat(24);
        // "ok count=" N " scenes=" then 24-byte names and commas, "\n": 17 + digits + 25 n.
        let fits = (1..)
            .take_while(|&n: &usize| 17 + n.to_string().len() + 25 * n <= REPLY_CAPACITY)
            .last()
            .expect("one name fits");
        let names: Vec<&str> = (0..=fits).map(|_| name.as_str()).collect();
        format_scene_list(&names[..fits], &mut out).unwrap();
        assert_eq!(
            format_scene_list(&names, &mut out),
            Err(FormatError::Overflow)
        );
        assert!(out.is_empty());

        format_help(&mut out).unwrap();
        assert_eq!(
            out,
            "ok commands=version,status,faults,target,scene,start,stop,freq,tare,cal,clear,\
             telemetry,save,load,defaults,log,help,commission\n"
        );
    }

    #[test]
    fn names_that_would_break_the_line_are_refused() {
        let mut out = Line::new();
        for bad in ["", "two words", "a=b", "a,b", "none"] {
            let report = FaultReport {
                latched: &[bad],
                active: &[],
            };
            assert_eq!(
                format_faults(&report, &mut out),
                Err(FormatError::BadWord),
                "{bad:?}"
            );
            assert!(out.is_empty());
        }
        let mut report = status_example();
        report.scene = Some("my scene");
        assert_eq!(format_status(&report, &mut out), Err(FormatError::BadWord));
        assert_eq!(
            OkReply::new(&mut out).uint("bad key", 1).finish(),
            Err(FormatError::BadWord)
        );
    }
}
