//! The load-cell codes on their way from the sensing task to the control loop.
//!
//! The sensing task ([`crate::sense_task`]) gets one ADC1 triplet per DMA half-buffer and
//! [`publish`]es its two load-cell codes into a short queue. The control loop drains the queue
//! at the start of every step ([`CellFeed::take`]): the newest pair is the step's sample, and
//! every pair goes into a history of the last [`HISTORY`] pairs, which `tare` and `cal`
//! average ([`CellFeed::burst`]).
//!
//! # Rates
//!
//! A triplet takes 16 (oversampling) x 3 (channels) TIM1 triggers, one per PWM period: a new
//! pair every 1.2 ms at 40 kHz (2.4 ms at 20 kHz). The control loop runs faster (10 kHz in the
//! `reference` scene), so it holds each pair for about 12 steps (24 at 20 kHz). The station's
//! stuck-reading check is widened by that factor ([`crate::rig`]), otherwise a held sample would
//! read as a stuck cell.
//!
//! The codes stay in the board's format ([`config::ADC_FORMAT`]: 16-bit oversampled ADC1 codes
//! through the INA826 front end of [`config::LOAD_CELL_INTERNAL`]): the station reads them
//! through channels of that format and that calibration ([`crate::rig`]).

use core::sync::atomic::{AtomicU32, Ordering};

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use sonolube::protocol::Axis;
use sonolube::sense::{AdcCode, AdcFormat, FaultLimits};
use sonolube::station::COMMISSIONING_SAMPLES;

use crate::config;

/// Pairs kept for `tare` and `cal`: as many as the station averages (256, 0.31 s of samples
/// at 40 kHz drive).
pub const HISTORY: usize = COMMISSIONING_SAMPLES;

/// Pairs queued between the sensing task and the control loop. The loop drains the queue every
/// step, at least 1 kHz, and pairs arrive at most at 1.25 kHz (60 kHz drive): 8 leaves room for
/// a late loop.
const QUEUE: usize = 8;

/// The two load-cell codes of one ADC1 triplet, in the internal ADC's format
/// ([`config::ADC_FORMAT`]: 0 to 65 520).
#[derive(Debug, Clone, Copy, PartialEq, Eq, defmt::Format)]
pub struct RawPair {
    /// Normal-force cell (PA0).
    pub normal: u16,
    /// Tangential-force cell (PB0).
    pub tangential: u16,
}

impl RawPair {
    const ZERO: RawPair = RawPair {
        normal: 0,
        tangential: 0,
    };

    fn code(self, axis: Axis) -> u16 {
        match axis {
            Axis::Normal => self.normal,
            Axis::Tangential => self.tangential,
        }
    }
}

static CODES: Channel<CriticalSectionRawMutex, RawPair, QUEUE> = Channel::new();

/// Pairs dropped because the queue was full (the control loop did not run), since boot.
static DROPPED: AtomicU32 = AtomicU32::new(0);

/// Offers one pair to the control loop; a full queue drops it (counted in [`dropped`]).
pub fn publish(pair: RawPair) {
    if CODES.try_send(pair).is_err() {
        DROPPED.fetch_add(1, Ordering::Relaxed);
    }
}

/// Pairs dropped since boot (wrapping).
pub fn dropped() -> u32 {
    DROPPED.load(Ordering::Relaxed)
}

/// Waits for the first pair: the control loop starts only once sensing runs (after the drive
/// is configured and the current sense tared).
pub async fn first() -> RawPair {
    CODES.receive().await
}

/// Whether `real` is at the converter's rail (within [`config::LOAD_CELL_LIMITS`]'s margin: an
/// open bridge wire or a saturated amplifier), or is a code it cannot produce.
fn at_rail(real: u16) -> bool {
    let (low_rail, high_rail) = rails(config::ADC_FORMAT, config::LOAD_CELL_LIMITS);
    real <= low_rail || real >= high_rail
}

/// The real codes at which `limits` call the reading a rail: the last code within the margin
/// at either end.
fn rails(format: AdcFormat, limits: FaultLimits) -> (u16, u16) {
    let margin = i64::from(limits.rail_margin.to_bits());
    let low = i64::from(format.min_normalized().to_bits()) + margin;
    let high = i64::from(format.max_normalized().to_bits()) - margin;
    // The code of a normalized value: divide by one code's fraction.
    let one = format
        .normalize(AdcCode::new(1))
        .map_or(1, |q| i64::from(q.to_bits()).max(1));
    let low_code = (low / one).clamp(0, i64::from(u16::MAX));
    let high_code = ((high + one - 1) / one).clamp(0, i64::from(u16::MAX));
    (
        u16::try_from(low_code).unwrap_or(0),
        u16::try_from(high_code).unwrap_or(u16::MAX),
    )
}

/// The control loop's side of the queue: the newest pair and the history.
pub struct CellFeed {
    latest: RawPair,
    history: [RawPair; HISTORY],
    /// Index of the next pair to write in `history`.
    next: usize,
    /// Pairs recorded since boot (saturating).
    recorded: u32,
    /// Pairs recorded in a row with the bridge off (saturating).
    quiet: u32,
    /// Control steps since the last new pair (saturating).
    steps_since_new: u32,
}

impl CellFeed {
    /// A feed whose first pair is `first` ([`first`]), recorded with the bridge off.
    pub fn new(first: RawPair) -> Self {
        let mut feed = Self {
            latest: first,
            history: [RawPair::ZERO; HISTORY],
            next: 0,
            recorded: 0,
            quiet: 0,
            steps_since_new: 0,
        };
        feed.record(first, false);
        feed
    }

    /// Drains the queue into the history (each pair marked with `bridge_on`, whether the bridge
    /// switched while it was taken) and returns the newest pair with the number of steps it
    /// has been held (0 when it arrived for this step).
    pub fn take(&mut self, bridge_on: bool) -> (RawPair, u32) {
        let mut arrived = false;
        while let Ok(pair) = CODES.try_receive() {
            self.record(pair, bridge_on);
            arrived = true;
        }
        if arrived {
            self.steps_since_new = 0;
        } else {
            self.steps_since_new = self.steps_since_new.saturating_add(1);
        }
        (self.latest, self.steps_since_new)
    }

    /// Whether a pair arrived within the last `stale_after_steps` steps.
    pub fn is_fresh(&self, stale_after_steps: u32) -> bool {
        self.steps_since_new <= stale_after_steps
    }

    fn record(&mut self, pair: RawPair, bridge_on: bool) {
        self.latest = pair;
        if let Some(slot) = self.history.get_mut(self.next) {
            *slot = pair;
        }
        self.next = (self.next + 1) % HISTORY;
        self.recorded = self.recorded.saturating_add(1);
        self.quiet = if bridge_on {
            0
        } else {
            self.quiet.saturating_add(1)
        };
    }

    /// Fills `codes` with the newest `codes.len()` codes of `axis`, oldest first: the samples
    /// of the moments before the command, under the load the operator put on the cell. False (nothing usable) when fewer have been recorded, when the bridge
    /// switched during any of them (a vibrating contact loads the cells), when `fresh` is false
    /// (sensing has stopped, the history is old) or when one of them is at the real
    /// converter's rail.
    pub fn burst(&self, axis: Axis, fresh: bool, codes: &mut [AdcCode]) -> bool {
        let wanted = codes.len();
        let Ok(wanted_u32) = u32::try_from(wanted) else {
            return false;
        };
        if wanted == 0 || wanted > HISTORY || !fresh {
            return false;
        }
        if self.recorded < wanted_u32 || self.quiet < wanted_u32 {
            defmt::warn!(
                "cells: {=u32} samples with the bridge off, {=u32} needed: wait and repeat",
                self.quiet.min(self.recorded),
                wanted_u32
            );
            return false;
        }
        // The newest `wanted` pairs end just before `next`.
        let start = (self.next + HISTORY - wanted) % HISTORY;
        for (k, slot) in codes.iter_mut().enumerate() {
            let pair = self
                .history
                .get((start + k) % HISTORY)
                .copied()
                .unwrap_or(RawPair::ZERO);
            let real = pair.code(axis);
            if at_rail(real) {
                defmt::warn!("cells: {} cell at its rail during the burst", axis);
                return false;
            }
            *slot = AdcCode::from_word(real);
        }
        true
    }
}
