//! The telemetry records received in a session, and the accounting of `seq` gaps against the
//! firmware's `lost` counter (protocol docs, "Telemetry": a gap in `seq` with a matching increase
//! of `lost` means records were dropped by the firmware, not corrupted on the way).

use sonolube::protocol::TelemetryRecord;

/// Records kept in memory by default: about 56 MB. Later records are still counted and checked
/// for gaps, but not kept for the CSV and the plot.
pub const DEFAULT_RECORD_CAPACITY: usize = 1_000_000;

/// What the `seq` numbers of consecutive received records say.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SeqGaps {
    /// Pairs of consecutive records whose `seq` jumps by more than one.
    pub gaps: u64,
    /// Records missing in those jumps.
    pub missing: u64,
    /// Missing records that the increase of `lost` between the two records accounts for.
    pub explained: u64,
    /// Missing records that `lost` does not account for: lost or corrupted on the way.
    pub unexplained: u64,
    /// Pairs whose `seq` repeats or goes backwards (a reboot, or a duplicated record).
    pub restarts: u64,
}

impl SeqGaps {
    /// Accounts for the step from `previous` to `next`.
    pub fn add(&mut self, previous: &TelemetryRecord, next: &TelemetryRecord) {
        let step = next.seq.wrapping_sub(previous.seq);
        if step == 1 {
            return;
        }
        if step == 0 || step > u32::MAX / 2 {
            self.restarts += 1;
            return;
        }
        let missing = u64::from(step - 1);
        let lost = u64::from(next.lost_records.wrapping_sub(previous.lost_records));
        let explained = missing.min(lost);
        self.gaps += 1;
        self.missing += missing;
        self.explained += explained;
        self.unexplained += missing - explained;
    }

    /// The accounting over consecutive records of `records`.
    pub fn of(records: &[TelemetryRecord]) -> SeqGaps {
        let mut gaps = SeqGaps::default();
        for pair in records.windows(2) {
            gaps.add(&pair[0], &pair[1]);
        }
        gaps
    }

    /// Whether every gap is accounted for by `lost` and `seq` never went backwards.
    pub fn all_explained(&self) -> bool {
        self.unexplained == 0 && self.restarts == 0
    }
}

/// The records of a session in arrival order, with running counts over all of them.
#[derive(Debug, Clone)]
pub struct TelemetryLog {
    records: Vec<TelemetryRecord>,
    capacity: usize,
    received: u64,
    gaps: SeqGaps,
    last: Option<TelemetryRecord>,
}

impl TelemetryLog {
    /// An empty log that keeps at most `capacity` records.
    pub fn new(capacity: usize) -> Self {
        TelemetryLog {
            records: Vec::new(),
            capacity,
            received: 0,
            gaps: SeqGaps::default(),
            last: None,
        }
    }

    /// Adds a received record.
    pub fn push(&mut self, record: TelemetryRecord) {
        if let Some(last) = &self.last {
            self.gaps.add(last, &record);
        }
        self.last = Some(record);
        self.received += 1;
        if self.records.len() < self.capacity {
            self.records.push(record);
        }
    }

    /// The kept records, oldest first (the first [`capacity`](Self::new) received).
    pub fn records(&self) -> &[TelemetryRecord] {
        &self.records
    }

    /// Records received, kept or not.
    pub fn received(&self) -> u64 {
        self.received
    }

    /// Records received but not kept because the log was full.
    pub fn not_kept(&self) -> u64 {
        self.received - self.records.len() as u64
    }

    /// The `seq` accounting over every record received.
    pub fn gaps(&self) -> SeqGaps {
        self.gaps
    }

    /// The newest record received.
    pub fn last(&self) -> Option<&TelemetryRecord> {
        self.last.as_ref()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sonolube::protocol::LoopReading;
    use sonolube::protocol::SupervisorState;

    fn record(seq: u32, lost: u32) -> TelemetryRecord {
        TelemetryRecord {
            time_us: u64::from(seq) * 1000,
            seq,
            reading: LoopReading {
                state: SupervisorState::Running,
                target: None,
                friction_coef_ppm: 0,
                normal_force_mn: 0,
                tangential_force_mn: 0,
                drive_amplitude_ppm: 0,
                drive_freq_chz: 0,
            },
            overruns: 0,
            lost_records: lost,
            lock: None,
            phase_mdeg: None,
            reach: sonolube::protocol::RunReach::UNKNOWN,
        }
    }

    #[test]
    fn consecutive_records_have_no_gap() {
        let gaps = SeqGaps::of(&[record(7, 0), record(8, 0), record(9, 0)]);
        assert_eq!(gaps, SeqGaps::default());
        assert!(gaps.all_explained());
    }

    #[test]
    fn a_gap_matched_by_lost_is_explained() {
        let gaps = SeqGaps::of(&[record(1, 2), record(5, 5), record(6, 5)]);
        assert_eq!(
            gaps,
            SeqGaps {
                gaps: 1,
                missing: 3,
                explained: 3,
                unexplained: 0,
                restarts: 0
            }
        );
        assert!(gaps.all_explained());
    }

    #[test]
    fn a_gap_without_lost_is_not() {
        let gaps = SeqGaps::of(&[record(1, 0), record(3, 0), record(10, 4)]);
        assert_eq!((gaps.gaps, gaps.missing), (2, 7));
        assert_eq!((gaps.explained, gaps.unexplained), (4, 3));
        assert!(!gaps.all_explained());
    }

    #[test]
    fn wrapping_seq_is_a_step_and_going_back_is_a_restart() {
        let wrap = SeqGaps::of(&[record(u32::MAX, 0), record(0, 0)]);
        assert_eq!(wrap, SeqGaps::default());
        let back = SeqGaps::of(&[record(10, 0), record(3, 0), record(3, 0)]);
        assert_eq!(back.restarts, 2);
        assert!(!back.all_explained());
    }

    #[test]
    fn the_log_counts_past_its_capacity() {
        let mut log = TelemetryLog::new(2);
        for seq in [1, 2, 4, 5] {
            log.push(record(seq, 0));
        }
        assert_eq!(log.records().len(), 2);
        assert_eq!((log.received(), log.not_kept()), (4, 2));
        assert_eq!(log.gaps().unexplained, 1);
        assert_eq!(log.last().map(|r| r.seq), Some(5));
    }
}
