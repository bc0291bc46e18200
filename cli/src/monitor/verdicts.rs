//! The measurements behind the acceptance checks, computed from received records and replies
//! alone (no I/O), so each can be tested on made-up data.

use std::collections::BTreeMap;

use sonolube::protocol::{ErrorCode, Reply, SupervisorState, Target, TelemetryRecord};

use super::flood::{FloodKind, FloodLine};
use super::inbox::ReplyLine;

/// How the friction estimate approached a coefficient target after `start`.
#[derive(Debug, Clone, PartialEq)]
pub struct Convergence {
    /// Records after `start` up to the end of the observation.
    pub records: usize,
    /// Firmware time from `start` to the first record from which every record is `running`
    /// within the band (`None`: the last record is outside it).
    pub settled_after_us: Option<u64>,
    /// Records judged at the end of the window (the last `last` ones, fewer if fewer came).
    pub judged: usize,
    /// Largest `|mu - target| / target` of the judged records, percent.
    pub max_error_pct: f64,
    /// Smallest and largest `mu` of the judged records, ppm.
    pub mu_range_ppm: (u32, u32),
    /// Judged records in a state other than `running`.
    pub not_running: usize,
    /// Judged records whose `target` is not the one set.
    pub wrong_target: usize,
}

impl Convergence {
    /// Whether it settled within `limit_us` and the last `last` records all hold the target
    /// within the band.
    pub fn passed(&self, last: usize, tolerance_pct: f64, limit_us: u64) -> bool {
        self.judged >= last
            && self.settled_after_us.is_some_and(|t| t <= limit_us)
            && self.max_error_pct <= tolerance_pct
            && self.not_running == 0
            && self.wrong_target == 0
    }
}

fn error_pct(record: &TelemetryRecord, target_ppm: u32) -> f64 {
    let target = f64::from(target_ppm.max(1));
    100.0 * (f64::from(record.reading.friction_coef_ppm) - target).abs() / target
}

/// Judges `records` (those after `start`, sent at firmware time `start_us`) against a
/// coefficient target of `target_ppm` within `tolerance_pct` percent, over the last `last`.
pub fn convergence(
    records: &[TelemetryRecord],
    start_us: u64,
    target_ppm: u32,
    tolerance_pct: f64,
    last: usize,
) -> Convergence {
    let in_band = |r: &TelemetryRecord| {
        r.reading.state == SupervisorState::Running && error_pct(r, target_ppm) <= tolerance_pct
    };
    let settled_from = records
        .iter()
        .rposition(|r| !in_band(r))
        .map_or(0, |i| i + 1);
    let settled_after_us = records
        .get(settled_from)
        .map(|r| r.time_us.saturating_sub(start_us));
    let judged = &records[records.len().saturating_sub(last)..];
    let wanted = Some(Target::Coef {
        coef_ppm: target_ppm,
    });
    Convergence {
        records: records.len(),
        settled_after_us,
        judged: judged.len(),
        max_error_pct: judged
            .iter()
            .map(|r| error_pct(r, target_ppm))
            .fold(0.0, f64::max),
        mu_range_ppm: (
            judged
                .iter()
                .map(|r| r.reading.friction_coef_ppm)
                .min()
                .unwrap_or(0),
            judged
                .iter()
                .map(|r| r.reading.friction_coef_ppm)
                .max()
                .unwrap_or(0),
        ),
        not_running: judged
            .iter()
            .filter(|r| r.reading.state != SupervisorState::Running)
            .count(),
        wrong_target: judged.iter().filter(|r| r.reading.target != wanted).count(),
    }
}

/// Whether a record shows the drive off after `stop`: amplitude 0 and the loop no longer
/// running or ramping up.
pub fn drive_is_off(record: &TelemetryRecord) -> bool {
    record.reading.drive_amplitude_ppm == 0
        && !matches!(
            record.reading.state,
            SupervisorState::Running | SupervisorState::RampUp
        )
}

/// The replies to the flood, matched line by line against the expected errors.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct FloodTally {
    /// Replies received.
    pub replies: usize,
    /// `err` replies.
    pub errors: usize,
    /// `ok` replies (a malformed line was accepted as a command).
    pub oks: usize,
    /// Replies that did not decode.
    pub malformed: usize,
    /// Replies other than `err` with the expected code and its name.
    pub mismatches: usize,
    /// The first mismatch, described.
    pub first_mismatch: Option<String>,
    /// Per kind: (lines answered, lines answered with the expected code).
    pub by_kind: BTreeMap<FloodKind, (usize, usize)>,
}

impl FloodTally {
    /// Files the reply to flood line `index`.
    pub fn add(&mut self, index: usize, line: &FloodLine, reply: &ReplyLine) {
        self.replies += 1;
        let expected = line.expected.code();
        let slot = self.by_kind.entry(line.kind).or_insert((0, 0));
        slot.0 += 1;
        let matched = match reply.decode() {
            Ok(Reply::Err(error)) => {
                self.errors += 1;
                error.code == expected.code() && error.name == expected.name()
            }
            Ok(Reply::Ok(_)) => {
                self.oks += 1;
                false
            }
            Err(_) => {
                self.malformed += 1;
                false
            }
        };
        if matched {
            slot.1 += 1;
        } else {
            self.mismatches += 1;
            if self.first_mismatch.is_none() {
                self.first_mismatch = Some(format!(
                    "line {} ({}, {:?}): expected err {} {}, got {:?}",
                    index + 1,
                    line.kind.name(),
                    String::from_utf8_lossy(&line.bytes),
                    expected.code(),
                    expected.name(),
                    reply.text
                ));
            }
        }
    }

    /// Whether all `count` lines got the expected `err`, in order.
    pub fn passed(&self, count: usize) -> bool {
        self.replies == count && self.errors == count && self.mismatches == 0
    }

    /// `garbage 2031/2031, ..., oversized 1012/1012 line-too-long, ...`.
    pub fn by_kind_text(&self) -> String {
        FloodKind::ALL
            .iter()
            .filter_map(|kind| {
                let (answered, matched) = self.by_kind.get(kind)?;
                let code = kind
                    .required_code()
                    .map_or(String::new(), |c: ErrorCode| format!(" {}", c.name()));
                Some(format!("{} {matched}/{answered}{code}", kind.name()))
            })
            .collect::<Vec<_>>()
            .join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sonolube::protocol::LoopReading;
    use sonolube::protocol::ProtocolError;

    fn record(time_ms: u64, mu_ppm: u32, state: SupervisorState) -> TelemetryRecord {
        TelemetryRecord {
            time_us: time_ms * 1000,
            seq: time_ms as u32,
            reading: LoopReading {
                state,
                target: Some(Target::Coef { coef_ppm: 150_000 }),
                friction_coef_ppm: mu_ppm,
                normal_force_mn: 40_000,
                tangential_force_mn: 6_000,
                drive_amplitude_ppm: 500_000,
                drive_freq_chz: 4_000_000,
            },
            overruns: 0,
            lost_records: 0,
            lock: None,
            phase_mdeg: None,
            reach: sonolube::protocol::RunReach::UNKNOWN,
        }
    }

    fn approach(n: u64, tau_ms: f64) -> Vec<TelemetryRecord> {
        (1..=n)
            .map(|ms| {
                let mu = 0.15 + 0.09 * (-(ms as f64) / tau_ms).exp();
                record(1000 + ms, (mu * 1e6) as u32, SupervisorState::Running)
            })
            .collect()
    }

    #[test]
    fn a_first_order_approach_settles() {
        let records = approach(200, 3.0);
        let c = convergence(&records, 1_000_000, 150_000, 3.0, 50);
        // 0.09 e^(-t/3) <= 0.0045 from t = 3 ln 20 = 9.0 ms on.
        assert_eq!(c.settled_after_us, Some(9_000));
        assert_eq!((c.records, c.judged), (200, 50));
        assert!(c.max_error_pct < 0.01, "{c:?}");
        assert!(c.passed(50, 3.0, 50_000));
        assert!(!c.passed(50, 3.0, 8_000));
        assert!(!c.passed(201, 3.0, 50_000));
    }

    #[test]
    fn a_late_excursion_or_wrong_state_fails() {
        let mut records = approach(200, 3.0);
        records[190].reading.friction_coef_ppm = 160_000;
        let c = convergence(&records, 1_000_000, 150_000, 3.0, 50);
        assert_eq!(c.settled_after_us, Some(192_000));
        assert!(c.max_error_pct > 6.0);
        assert!(!c.passed(50, 3.0, 50_000));
        let mut records = approach(200, 3.0);
        records[199].reading.state = SupervisorState::Fault;
        let c = convergence(&records, 1_000_000, 150_000, 3.0, 50);
        assert_eq!((c.settled_after_us, c.not_running), (None, 1));
        let c = convergence(&[], 0, 150_000, 3.0, 50);
        assert_eq!((c.judged, c.settled_after_us), (0, None));
        assert!(!c.passed(50, 3.0, 50_000));
    }

    #[test]
    fn the_drive_is_off_only_at_zero_amplitude_out_of_the_loop() {
        let mut r = record(1, 150_000, SupervisorState::Idle);
        assert!(!drive_is_off(&r));
        r.reading.drive_amplitude_ppm = 0;
        assert!(drive_is_off(&r));
        r.reading.state = SupervisorState::Running;
        assert!(!drive_is_off(&r));
    }

    #[test]
    fn flood_replies_are_matched_in_order() {
        let line = |bytes: &[u8], kind| FloodLine {
            bytes: bytes.to_vec(),
            kind,
            expected: super::super::flood::expected_error(bytes).unwrap(),
        };
        let lines = [
            line(b"jump", FloodKind::UnknownKeyword),
            line(&[b'x'; 100], FloodKind::Oversized),
        ];
        assert!(matches!(
            lines[1].expected,
            ProtocolError::LineTooLong { .. }
        ));
        let reply = |text: &str| ReplyLine { text: text.into() };
        let mut good = FloodTally::default();
        good.add(
            0,
            &lines[0],
            &reply("err 1 unknown-command \"jump\" is not a command"),
        );
        good.add(
            1,
            &lines[1],
            &reply("err 11 line-too-long line of 100 bytes"),
        );
        assert!(good.passed(2));
        assert_eq!(
            good.by_kind_text(),
            "unknown keyword 1/1, oversized 1/1 line-too-long"
        );
        let mut bad = FloodTally::default();
        bad.add(
            0,
            &lines[0],
            &reply("err 11 line-too-long line of 100 bytes"),
        );
        bad.add(1, &lines[1], &reply("ok"));
        assert!(!bad.passed(2));
        assert_eq!((bad.errors, bad.oks, bad.mismatches), (1, 1, 2));
        assert!(
            bad.first_mismatch
                .unwrap()
                .starts_with("line 1 (unknown keyword")
        );
        let mut short = FloodTally::default();
        short.add(0, &lines[0], &reply("err 1 unknown-command x"));
        assert!(!short.passed(2));
    }
}
