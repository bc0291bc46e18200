//! The checks of the acceptance test (listed in [`acceptance`](super::acceptance)), each
//! talking to the firmware over the link and returning its verdict with what it measured.

use std::io::Write;
use std::time::Instant;

use sonolube::protocol::{
    Command, PROTOCOL_VERSION, SceneName, SupervisorState, Target, TelemetryRecord,
};

use super::acceptance::{AcceptanceConfig, AcceptanceReport, Check, observe_ms};
use super::flood::flood;
use super::link::Link;
use super::reports::{Status, decode_status, decode_version, fixed, ok_payload, target_text};
use super::telemetry_log::SeqGaps;
use super::verdicts::{FloodTally, convergence, drive_is_off};

/// `Ok(measured)` for a pass, `Err(measured and what was wrong)` for a failure.
pub(crate) type Verdict = Result<String, String>;

/// What check 4 needs from check 3.
pub(crate) struct FloodWindow {
    before: Result<Status, String>,
    first_record: usize,
}

/// A run of the checks, collecting their verdicts.
pub(crate) struct Run<'a> {
    link: &'a mut Link,
    config: &'a AcceptanceConfig,
    out: &'a mut dyn Write,
    pub(crate) report: AcceptanceReport,
}

impl<'a> Run<'a> {
    pub(crate) fn new(
        link: &'a mut Link,
        config: &'a AcceptanceConfig,
        out: &'a mut dyn Write,
    ) -> Self {
        Run {
            link,
            config,
            out,
            report: AcceptanceReport::default(),
        }
    }

    /// Prints and keeps a verdict.
    pub(crate) fn record(&mut self, number: u8, name: &'static str, verdict: Verdict) {
        let (passed, measured) = match verdict {
            Ok(measured) => (true, measured),
            Err(measured) => (false, measured),
        };
        let check = Check {
            number,
            name,
            passed,
            measured,
        };
        let _ = writeln!(self.out, "{check}");
        let _ = self.out.flush();
        self.report.checks.push(check);
    }

    /// Sends `command`; its reply must be `ok`, with `key=value` when given.
    fn acknowledged(&mut self, command: &Command, expect: Option<(&str, &str)>) -> Verdict {
        let reply = self
            .link
            .send_command(command)
            .map_err(|e| format!("{}: {e}", command.keyword()))?;
        let payload = ok_payload(&reply).map_err(|e| format!("{}: {e}", command.keyword()))?;
        if let Some((key, value)) = expect
            && payload.get(key) != Some(value)
        {
            return Err(format!(
                "{}: expected {key}={value} in {:?}",
                command.keyword(),
                reply.text
            ));
        }
        Ok(reply.text)
    }

    fn status(&mut self) -> Result<Status, String> {
        let reply = self
            .link
            .send_command(&Command::Status)
            .map_err(|e| format!("status: {e}"))?;
        decode_status(&reply).map_err(|e| format!("status: {e}"))
    }

    /// (records kept, `t_us` of the newest).
    fn telemetry_mark(&self) -> (usize, Option<u64>) {
        self.link
            .with_telemetry(|log| (log.records().len(), log.last().map(|r| r.time_us)))
    }

    fn records(&self, from: usize, to: usize) -> Vec<TelemetryRecord> {
        self.link.with_telemetry(|log| {
            let records = log.records();
            records[from.min(records.len())..to.min(records.len())].to_vec()
        })
    }

    pub(crate) fn identity(&mut self) -> Verdict {
        let reply = self
            .link
            .send_command(&Command::Version)
            .map_err(|e| format!("version: {e}"))?;
        let version = decode_version(&reply).map_err(|e| format!("version: {e}"))?;
        if version.protocol != PROTOCOL_VERSION {
            return Err(format!(
                "version: protocol={} but this host speaks protocol {PROTOCOL_VERSION}",
                version.protocol
            ));
        }
        let status = self.status()?;
        let extra = if status.extra_keys.is_empty() {
            String::new()
        } else {
            format!(" (undocumented keys: {})", status.extra_keys.join(","))
        };
        Ok(format!(
            "firmware={} board={} protocol={}; status has all {} fields: state={} scene={} \
             target={} mu={} amp={} overruns={} fault={} reach={} resonance={}{extra}",
            version.firmware,
            version.board,
            version.protocol,
            super::STATUS_KEYS.len(),
            status.state.name(),
            status.scene.as_deref().unwrap_or("none"),
            target_text(status.target.as_ref()),
            fixed(i64::from(status.friction_coef_ppm), 6),
            fixed(i64::from(status.drive_amplitude_ppm), 6),
            status.overruns,
            status.fault.as_deref().unwrap_or("none"),
            status.reach,
            status.resonance,
        ))
    }

    pub(crate) fn convergence(&mut self) -> Verdict {
        let config = self.config;
        let scene = SceneName::new(&config.scene)
            .ok_or_else(|| format!("{:?} is not a scene name", config.scene))?;
        let target = Target::Coef {
            coef_ppm: config.target_coef_ppm,
        };
        let rate = config.telemetry_hz.to_string();
        self.acknowledged(&Command::Scene(scene), Some(("scene", &config.scene)))?;
        self.acknowledged(
            &Command::Target(target),
            Some(("target", &target_text(Some(&target)))),
        )?;
        self.acknowledged(
            &Command::Telemetry {
                rate_hz: config.telemetry_hz,
            },
            Some(("telemetry_hz", &rate)),
        )?;
        let (first, _) = self.telemetry_mark();
        self.link
            .wait_for_record(first, |_| true)
            .map_err(|e| format!("after telemetry {rate}: {e}"))?;
        let (from, start_us) = self.telemetry_mark();
        let start_us = start_us.unwrap_or(0);
        self.acknowledged(&Command::Start, None)?;
        let end_us = start_us + observe_ms(config) * 1000;
        let (last, _) = self
            .link
            .wait_for_record(from, |r| r.time_us >= end_us)
            .map_err(|e| format!("after start: {e}"))?;
        let records = self.records(from, last + 1);
        let c = convergence(
            &records,
            start_us,
            config.target_coef_ppm,
            config.tolerance_pct,
            config.last_records,
        );
        let settled = match c.settled_after_us {
            Some(us) => format!("{} ms", fixed(i64::try_from(us).unwrap_or(i64::MAX), 3)),
            None => "never".into(),
        };
        let measured = format!(
            "target coef {}: in ±{} % and running from {settled} after start (limit {} ms); \
             last {} of {} records: mu {}..{}, max error {:.3} % (tolerance {} %), {} not \
             running, {} with another target",
            fixed(i64::from(config.target_coef_ppm), 6),
            config.tolerance_pct,
            config.settle_ms,
            c.judged,
            c.records,
            fixed(i64::from(c.mu_range_ppm.0), 6),
            fixed(i64::from(c.mu_range_ppm.1), 6),
            c.max_error_pct,
            config.tolerance_pct,
            c.not_running,
            c.wrong_target,
        );
        if c.passed(
            config.last_records,
            config.tolerance_pct,
            config.settle_ms * 1000,
        ) {
            Ok(measured)
        } else {
            Err(measured)
        }
    }

    pub(crate) fn flood(&mut self) -> (Verdict, FloodWindow) {
        let config = self.config;
        let before = self.status();
        let (first_record, _) = self.telemetry_mark();
        let window = FloodWindow {
            before,
            first_record: first_record.saturating_sub(1),
        };
        let lines = match flood(config.seed, config.flood_lines) {
            Ok(lines) => lines,
            Err(why) => return (Err(format!("cannot make the flood: {why}")), window),
        };
        let bytes: Vec<Vec<u8>> = lines.iter().map(|l| l.bytes.clone()).collect();
        let mut tally = FloodTally::default();
        let started = Instant::now();
        let sent = self.link.pipeline(&bytes, config.window, |index, reply| {
            tally.add(index, &lines[index], &reply)
        });
        let wall_s = started.elapsed().as_secs_f64();
        let (last_record, _) = self.telemetry_mark();
        let during = self.records(first_record, last_record);
        let span = match (during.first(), during.last()) {
            (Some(a), Some(b)) => format!(
                ", t_us {}..{} ({} ms of firmware time)",
                a.time_us,
                b.time_us,
                fixed(
                    i64::try_from(b.time_us - a.time_us.min(b.time_us)).unwrap_or(0),
                    3
                )
            ),
            _ => String::new(),
        };
        let mut problems = Vec::new();
        if let Err(e) = &sent {
            problems.push(e.to_string());
        }
        if tally.oks > 0 {
            problems.push(format!("{} ok replies", tally.oks));
        }
        if tally.malformed > 0 {
            problems.push(format!("{} malformed replies", tally.malformed));
        }
        if let Some(first) = &tally.first_mismatch {
            problems.push(format!("{} mismatches, first {first}", tally.mismatches));
        }
        if during.is_empty() {
            problems.push("no telemetry during the flood".into());
        }
        let measured = format!(
            "{} lines (seed {:#x}), {} replies, {} err with the predicted code in order: {}; \
             {} telemetry records meanwhile{span}; {wall_s:.1} s wall",
            config.flood_lines,
            config.seed,
            tally.replies,
            tally
                .by_kind
                .values()
                .map(|(_, matched)| matched)
                .sum::<usize>(),
            tally.by_kind_text(),
            during.len(),
        );
        let verdict = if problems.is_empty() && tally.passed(config.flood_lines) {
            Ok(measured)
        } else {
            Err(format!("{}; {measured}", problems.join("; ")))
        };
        (verdict, window)
    }

    pub(crate) fn unaffected(&mut self, window: FloodWindow) -> Verdict {
        let after = self.status();
        let (to, _) = self.telemetry_mark();
        let records = self.records(window.first_record, to);
        let gaps = SeqGaps::of(&records);
        let not_running = records
            .iter()
            .filter(|r| r.reading.state != SupervisorState::Running)
            .count();
        let tel_overruns = match (records.first(), records.last()) {
            (Some(a), Some(b)) => Some((a.overruns, b.overruns)),
            _ => None,
        };
        let lost = |s: &Status| s.lost;
        let mut problems = Vec::new();
        let status_text = match (&window.before, &after) {
            (Ok(before), Ok(after)) => {
                if before.overruns != after.overruns {
                    problems.push(format!(
                        "overruns rose by {}",
                        after.overruns.wrapping_sub(before.overruns)
                    ));
                }
                if after.state != SupervisorState::Running {
                    problems.push(format!("state {} after the flood", after.state.name()));
                }
                format!(
                    "status overruns {} -> {}, state {} -> {}, lost {} -> {}",
                    before.overruns,
                    after.overruns,
                    before.state.name(),
                    after.state.name(),
                    lost(before),
                    lost(after)
                )
            }
            (Err(e), _) | (_, Err(e)) => {
                problems.push(e.clone());
                "status unreadable".into()
            }
        };
        let tel_text = match tel_overruns {
            Some((a, b)) => {
                if a != b {
                    problems.push(format!("telemetry overruns {a} -> {b}"));
                }
                format!("telemetry overruns {a} -> {b}")
            }
            None => {
                problems.push("no telemetry records".into());
                "no telemetry".into()
            }
        };
        if not_running > 0 {
            problems.push(format!("{not_running} records not running"));
        }
        if !gaps.all_explained() {
            problems.push(format!(
                "{} records missing without lost, {} seq restarts",
                gaps.unexplained, gaps.restarts
            ));
        }
        let measured = format!(
            "{status_text}; {tel_text}; {} records: {} seq gaps, {} missing, {} accounted by \
             lost, {} unexplained",
            records.len(),
            gaps.gaps,
            gaps.missing,
            gaps.explained,
            gaps.unexplained
        );
        if problems.is_empty() {
            Ok(measured)
        } else {
            Err(format!("{}; {measured}", problems.join("; ")))
        }
    }

    pub(crate) fn stop(&mut self) -> Verdict {
        let (from, stop_us) = self.telemetry_mark();
        let stop_us = stop_us.unwrap_or(0);
        self.acknowledged(&Command::Stop, None)?;
        let limit_us = stop_us + self.config.stop_ms * 1000;
        let (_, record) = self
            .link
            .wait_for_record(from, |r| drive_is_off(r) || r.time_us >= limit_us)
            .map_err(|e| format!("after stop: {e}"))?;
        let status = self.status()?;
        let status_text = format!(
            "status state={} amp={}",
            status.state.name(),
            fixed(i64::from(status.drive_amplitude_ppm), 6)
        );
        let status_off = status.drive_amplitude_ppm == 0
            && !matches!(
                status.state,
                SupervisorState::Running | SupervisorState::RampUp
            );
        if !drive_is_off(&record) {
            return Err(format!(
                "still amp={} state={} {} ms after stop (limit {} ms); {status_text}",
                fixed(i64::from(record.reading.drive_amplitude_ppm), 6),
                record.reading.state.name(),
                fixed(
                    i64::try_from(record.time_us.saturating_sub(stop_us)).unwrap_or(0),
                    3
                ),
                self.config.stop_ms
            ));
        }
        let measured = format!(
            "amp 0 and state {} {} ms after stop (limit {} ms); {status_text}",
            record.reading.state.name(),
            fixed(
                i64::try_from(record.time_us.saturating_sub(stop_us)).unwrap_or(0),
                3
            ),
            self.config.stop_ms
        );
        if status_off {
            Ok(measured)
        } else {
            Err(format!("status does not show the drive off; {measured}"))
        }
    }

    pub(crate) fn clean_stream(&mut self) -> Verdict {
        // Leave the firmware quiet; a refusal is reported with the stream's state.
        let quiet = self.acknowledged(&Command::TelemetryOff, Some(("telemetry_hz", "off")));
        let anomalies = self.link.anomalies();
        let (gaps, received) = self.link.with_telemetry(|log| (log.gaps(), log.received()));
        let mut measured = format!(
            "{} lines received ({received} telemetry records), {} malformed, {} replies \
             without a command; session seq gaps {} ({} missing, {} unexplained, {} restarts)",
            self.link.lines_received(),
            anomalies.malformed,
            anomalies.unsolicited,
            gaps.gaps,
            gaps.missing,
            gaps.unexplained,
            gaps.restarts,
        );
        if let Some(partial) = &anomalies.partial_first_line {
            measured.push_str(&format!("; first line discarded as partial: {partial:?}"));
        }
        if let Some(example) = anomalies.examples.first() {
            measured.push_str(&format!("; first problem: {example}"));
        }
        if let Err(e) = quiet {
            return Err(format!("telemetry off refused: {e}; {measured}"));
        }
        if anomalies.is_clean() && gaps.all_explained() {
            Ok(measured)
        } else {
            Err(measured)
        }
    }
}
