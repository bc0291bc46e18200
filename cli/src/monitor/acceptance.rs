//! The acceptance test of the firmware's command interface, run over a live [`Link`].
//!
//! | # | check | passes when |
//! |---|---|---|
//! | 1 | version and status | `version` and `status` are `ok` with every documented field decodable, protocol = [`PROTOCOL_VERSION`] |
//! | 2 | convergence | after `scene`, `target coef`, `telemetry`, `start` (each acknowledged with its setting): over [`observe_ms`] of firmware time, `mu` is within ±`tolerance_pct` of the target in state `running` from at most `settle_ms` after `start` on, and so are the last `last_records` records (with the target echoed) |
//! | 3 | flood | `flood_lines` seeded malformed lines get exactly as many `err` replies, in order, each with the code (and name) the host's own assembler and parser predict (oversized → `line-too-long`, non-ASCII or control → `bad-encoding`), while telemetry keeps arriving |
//! | 4 | loop unaffected | `status` after the flood: `overruns` unchanged from before it (status and telemetry), state still `running`, every telemetry record of the flood `running`, every `seq` gap matched by the increase of `lost` |
//! | 5 | stop | `stop` is `ok`; within `stop_ms` of firmware time a record shows amplitude 0 outside `running`/`ramp-up`, and `status` agrees |
//! | 6 | clean stream | every line from the firmware decoded, no reply without a command, and every `seq` gap of the whole session explained by `lost` |
//!
//! Firmware times come from telemetry `t_us`; `start` and `stop` are timed from the newest
//! record received before they were sent, which can only overstate the time they took.

use std::io::Write;

use super::checks::Run;
use super::link::Link;

/// What the acceptance test asks for, and its tolerances.
#[derive(Debug, Clone)]
pub struct AcceptanceConfig {
    /// Scene selected before `start`.
    pub scene: String,
    /// Friction coefficient target, ppm (`150_000` is `target coef 0.15`).
    pub target_coef_ppm: u32,
    /// Telemetry rate during the test, Hz.
    pub telemetry_hz: u16,
    /// Band around the target that counts as reached, percent of the target.
    pub tolerance_pct: f64,
    /// Records at the end of the observation that must all be in the band.
    pub last_records: usize,
    /// Firmware time after `start` by which `mu` must stay in the band, ms.
    pub settle_ms: u64,
    /// Firmware time after `start` that is observed, ms (at least long enough for
    /// `last_records` records after `settle_ms`, see [`observe_ms`]).
    pub observe_ms: u64,
    /// Malformed lines sent in the flood.
    pub flood_lines: usize,
    /// Seed of the flood.
    pub seed: u64,
    /// Flood lines sent ahead of their replies (at least 1).
    pub window: usize,
    /// Firmware time after `stop` by which the drive must be off, ms.
    pub stop_ms: u64,
}

impl Default for AcceptanceConfig {
    fn default() -> Self {
        AcceptanceConfig {
            scene: "reference".into(),
            target_coef_ppm: 150_000,
            telemetry_hz: 1000,
            tolerance_pct: 3.0,
            last_records: 50,
            settle_ms: 50,
            observe_ms: 150,
            flood_lines: 10_000,
            seed: 0x50a0_1be5,
            window: 4,
            stop_ms: 100,
        }
    }
}

/// Firmware time observed after `start`, ms: `observe_ms`, or longer when the telemetry rate is
/// too low to bring `last_records` records after `settle_ms`.
pub fn observe_ms(config: &AcceptanceConfig) -> u64 {
    let period_us = 1_000_000 / u64::from(config.telemetry_hz.max(1));
    let needed_ms = config.settle_ms + (config.last_records as u64 * period_us).div_ceil(1000);
    config.observe_ms.max(needed_ms)
}

/// One check's verdict and what was measured.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Check {
    /// 1 to 6, as in the module docs.
    pub number: u8,
    /// Short name.
    pub name: &'static str,
    /// The verdict.
    pub passed: bool,
    /// The measured values (and on failure, what was wrong).
    pub measured: String,
}

impl std::fmt::Display for Check {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let verdict = if self.passed { "PASS" } else { "FAIL" };
        write!(
            f,
            "{verdict} {} {}: {}",
            self.number, self.name, self.measured
        )
    }
}

/// All checks of a run.
#[derive(Debug, Clone, Default)]
pub struct AcceptanceReport {
    /// In order.
    pub checks: Vec<Check>,
}

impl AcceptanceReport {
    /// Checks passed.
    pub fn passed(&self) -> usize {
        self.checks.iter().filter(|c| c.passed).count()
    }

    /// Checks failed.
    pub fn failed(&self) -> usize {
        self.checks.len() - self.passed()
    }

    /// Whether every check passed.
    pub fn all_passed(&self) -> bool {
        self.failed() == 0 && !self.checks.is_empty()
    }

    /// The check with this number.
    pub fn check(&self, number: u8) -> Option<&Check> {
        self.checks.iter().find(|c| c.number == number)
    }

    /// `monitor acceptance: N passed, M failed`.
    pub fn summary(&self) -> String {
        format!(
            "monitor acceptance: {} passed, {} failed",
            self.passed(),
            self.failed()
        )
    }
}

/// Runs every check over `link`, writing each verdict line to `out` as it is reached.
pub fn run_acceptance(
    link: &mut Link,
    config: &AcceptanceConfig,
    out: &mut dyn Write,
) -> AcceptanceReport {
    let mut run = Run::new(link, config, out);
    let identity = run.identity();
    run.record(1, "version and status", identity);
    let converged = run.convergence();
    run.record(2, "convergence", converged);
    let (flooded, flood_window) = run.flood();
    run.record(3, "flood", flooded);
    let unaffected = run.unaffected(flood_window);
    run.record(4, "loop unaffected", unaffected);
    let stopped = run.stop();
    run.record(5, "stop", stopped);
    let clean = run.clean_stream();
    run.record(6, "clean stream", clean);
    run.report
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_observation_lasts_long_enough_for_the_judged_records() {
        let config = AcceptanceConfig::default();
        assert_eq!(observe_ms(&config), 150);
        let slow = AcceptanceConfig {
            telemetry_hz: 50,
            ..AcceptanceConfig::default()
        };
        assert_eq!(observe_ms(&slow), 50 + 50 * 20);
    }

    #[test]
    fn the_summary_counts_verdicts() {
        let check = |number, passed| Check {
            number,
            name: "x",
            passed,
            measured: "m".into(),
        };
        let report = AcceptanceReport {
            checks: vec![check(1, true), check(2, false), check(3, true)],
        };
        assert_eq!(report.summary(), "monitor acceptance: 2 passed, 1 failed");
        assert!(!report.all_passed());
        assert_eq!(report.check(2).unwrap().to_string(), "FAIL 2 x: m");
        assert!(!AcceptanceReport::default().all_passed());
    }
}
