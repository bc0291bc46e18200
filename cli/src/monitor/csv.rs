//! The telemetry of a session as CSV: a header row, then one row per record received, one
//! column per telemetry field, named and written as on the wire (protocol docs, "Telemetry").
//!
//! | column | unit |
//! |---|---|
//! | `t_us` | µs since the firmware booted |
//! | `seq` | record number |
//! | `state` | supervisor state name |
//! | `target` | `kind:value` or `none` |
//! | `mu` | friction coefficient estimate, 6 decimals |
//! | `normal_n`, `tangential_n` | N, 3 decimals |
//! | `amp` | drive amplitude, fraction of full scale, 6 decimals |
//! | `freq_hz` | Hz, 2 decimals |
//! | `overruns` | control-loop overruns since boot |
//! | `lost` | telemetry records lost since boot |
//! | `lock`, `phase_deg` | resonance loop state, motional phase (degrees) |
//! | `reach`, `reachable`, `resonance` | `ok` or `target-unreachable`, the value the full drive reaches (or `none`), `near`/`far`/`unknown` |

use std::fmt::Write as _;

use sonolube::protocol::TelemetryRecord;

use super::reports::{fixed, target_text};

/// The header row (without its newline).
pub const CSV_HEADER: &str = "t_us,seq,state,target,mu,normal_n,tangential_n,amp,freq_hz,overruns,lost,lock,phase_deg,\
     reach,reachable,resonance";

/// The CSV text of `records`.
pub fn telemetry_csv(records: &[TelemetryRecord]) -> String {
    let mut text = String::with_capacity(96 * (records.len() + 1));
    text.push_str(CSV_HEADER);
    text.push('\n');
    for r in records {
        let _ = writeln!(
            text,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            r.time_us,
            r.seq,
            r.reading.state.name(),
            target_text(r.reading.target.as_ref()),
            fixed(i64::from(r.reading.friction_coef_ppm), 6),
            fixed(i64::from(r.reading.normal_force_mn), 3),
            fixed(i64::from(r.reading.tangential_force_mn), 3),
            fixed(i64::from(r.reading.drive_amplitude_ppm), 6),
            fixed(i64::from(r.reading.drive_freq_chz), 2),
            r.overruns,
            r.lost_records,
            r.lock.map_or("none", |lock| lock.name()),
            r.phase_mdeg
                .map_or_else(|| "undefined".to_string(), |m| fixed(i64::from(m), 3)),
            r.reach.state.name(),
            target_text(r.reach.reachable.as_ref()),
            r.reach.resonance.map_or("unknown", |d| d.name()),
        );
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;
    use sonolube::protocol::LoopReading;
    use sonolube::protocol::{SupervisorState, Target, format_telemetry};

    #[test]
    fn one_row_per_record_with_the_wire_values() {
        let record = TelemetryRecord {
            time_us: 1_250_000,
            seq: 12_500,
            reading: LoopReading {
                state: SupervisorState::Running,
                target: Some(Target::Coef { coef_ppm: 150_000 }),
                friction_coef_ppm: 151_000,
                normal_force_mn: 40_000,
                tangential_force_mn: -6_040,
                drive_amplitude_ppm: 523_000,
                drive_freq_chz: 4_000_000,
            },
            overruns: 0,
            lost_records: 3,
            lock: None,
            phase_mdeg: None,
            reach: sonolube::protocol::RunReach::UNKNOWN,
        };
        let text = telemetry_csv(&[record, record]);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 3);
        assert_eq!(lines[0], CSV_HEADER);
        // Same values, same text as the telemetry line itself.
        let mut wire = heapless::String::<{ sonolube::protocol::TELEMETRY_CAPACITY }>::new();
        format_telemetry(&record, &mut wire).unwrap();
        let values: Vec<&str> = wire
            .trim_end()
            .split(' ')
            .skip(1)
            .map(|pair| pair.split_once('=').unwrap().1)
            .collect();
        assert_eq!(lines[1], values.join(","));
        assert_eq!(lines[0].split(',').count(), values.len());
    }
}
