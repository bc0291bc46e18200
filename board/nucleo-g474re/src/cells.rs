//! The load-cell codes on their way from the sensing task to the control loop, and their
//! conversion to the scene cell's converter format.
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
//! # Format conversion (an assumption, see [`CodeMap`])
//!
//! The station reads codes in the format of the *scene's* cells (`sonolube::sim::cell_format`:
//! unipolar, `adc_bits` bits, zero force at mid-scale, `full_scale_n` at either end). The board
//! has other cells: 16-bit oversampled ADC1 codes through the INA826 front end of
//! [`config::LOAD_CELL_INTERNAL`] (222 N cells, about 488 N per converter span). [`CodeMap`]
//! converts a real code to newtons with the board's datasheet calibration and expresses that
//! force as the scene cell's code, so the station's own calibration (its nominal one, then
//! `tare` and `cal`) applies unchanged.

use core::sync::atomic::{AtomicU32, Ordering};

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use sonolube::protocol::Axis;
use sonolube::scene::LoadCell;
use sonolube::sense::{AdcFormat, Calibration, FaultLimits};
use sonolube::sim::COMMISSIONING_SAMPLES;

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

/// A real ADC1 code of one cell to the code the scene's cell would give for the same force.
///
/// Assumptions, all of them the board's documented front end (board README, "Power stage and
/// front ends"): the cell and amplifier follow their datasheet calibration
/// ([`config::LOAD_CELL_INTERNAL`]: zero force at mid-scale, the rated load at 1.5 V from
/// it); the offset and gain errors of the real cell stay in the codes, where the station's
/// `tare` and `cal` remove them as they would on the scene's cell. The conversion is linear and
/// exact up to rounding to the scene's converter step; it cannot add resolution: with the
/// board's 222 N cells one real step is 7.45 mN, 7.6 steps of the `reference` scene's 2 N
/// tangential cell.
///
/// Forces beyond the scene cell's full scale give its end codes, which the station reads as a
/// rail (a `disconnected` sensor fault, drive safe): the scene's cell would saturate the same
/// way. A real code at the real converter's rail (within [`config::LOAD_CELL_LIMITS`]'s
/// margin: an open bridge wire or a saturated amplifier) gives the scene cell's rail code
/// whatever the scales, so a broken real cell always reads as one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, defmt::Format)]
pub struct CodeMap {
    /// Scene codes per real code, Q32.32.
    gain_q32: i64,
    /// Scene code of real code 0, Q32.32.
    offset_q32: i64,
    /// The scene cell's largest code.
    max_code: u16,
    /// Real codes at or below this are the low rail.
    low_rail: u16,
    /// Real codes at or above this are the high rail.
    high_rail: u16,
}

impl CodeMap {
    /// The map from the board's cell with calibration `real` (newtons per converter span, zero
    /// reading) to the scene's `cell`. Configuration, `f64`, once per scene.
    pub fn new(cell: &LoadCell, real: &Calibration) -> Self {
        let format = config::ADC_FORMAT;
        // One real code as a fraction of the converter span (2^-16).
        let per_code = format.normalize(1).map_or(0.0, |q| q.to_f64());
        let zero_reading = real.offset().to_f64();
        let newtons_per_span = real.span().to_f64();
        let zero_code = f64::from(cell.zero_code());
        let codes_per_newton = zero_code / cell.full_scale_n;
        // scene = zero_code + (real * per_code - zero_reading) * span * codes_per_newton
        let gain = per_code * newtons_per_span * codes_per_newton;
        let offset = zero_code - zero_reading * newtons_per_span * codes_per_newton;
        let (low_rail, high_rail) = rails(format, config::LOAD_CELL_LIMITS);
        Self {
            gain_q32: to_q32(gain),
            offset_q32: to_q32(offset),
            max_code: cell.max_code(),
            low_rail,
            high_rail,
        }
    }

    /// Whether `real` is at the real converter's rail (or is a code it cannot produce).
    pub fn at_rail(&self, real: u16) -> bool {
        real <= self.low_rail || real >= self.high_rail
    }

    /// The scene cell's code for the real code `real`. Integer: one 64-bit product.
    pub fn convert(&self, real: u16) -> u16 {
        if real <= self.low_rail {
            return 0;
        }
        if real >= self.high_rail {
            return self.max_code;
        }
        let scaled = self
            .gain_q32
            .saturating_mul(i64::from(real))
            .saturating_add(self.offset_q32)
            .saturating_add(1 << 31)
            >> 32;
        u16::try_from(scaled.clamp(0, i64::from(self.max_code))).unwrap_or(self.max_code)
    }
}

/// `value` in Q32.32, saturated to +-2^30 (a scene cell millions of times finer than the board's
/// converter: meaningless, but not a panic).
fn to_q32(value: f64) -> i64 {
    const LIMIT: f64 = (1u64 << 30) as f64;
    let clamped = if value.is_nan() {
        0.0
    } else {
        value.clamp(-LIMIT, LIMIT)
    };
    // |clamped| * 2^32 <= 2^62: within i64; `as` rounds toward zero, enough here.
    (clamped * 4_294_967_296.0) as i64
}

/// The real codes at which `limits` call the reading a rail: the last code within the margin
/// at either end.
fn rails(format: AdcFormat, limits: FaultLimits) -> (u16, u16) {
    let margin = i64::from(limits.rail_margin.to_bits());
    let low = i64::from(format.min_normalized().to_bits()) + margin;
    let high = i64::from(format.max_normalized().to_bits()) - margin;
    // The code of a normalized value: divide by one code's fraction.
    let one = format
        .normalize(1)
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

    /// Fills `codes` with the newest `codes.len()` codes of `axis`, oldest first, converted
    /// with `map`: the samples of the moments before the command, under the load the operator
    /// put on the cell. False (nothing usable) when fewer have been recorded, when the bridge
    /// switched during any of them (a vibrating contact loads the cells), when `fresh` is false
    /// (sensing has stopped, the history is old) or when one of them is at the real
    /// converter's rail.
    pub fn burst(&self, axis: Axis, map: &CodeMap, fresh: bool, codes: &mut [i32]) -> bool {
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
            if map.at_rail(real) {
                defmt::warn!("cells: {} cell at its rail during the burst", axis);
                return false;
            }
            *slot = i32::from(map.convert(real));
        }
        true
    }
}
