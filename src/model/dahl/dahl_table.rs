//! The Dahl steady state at loop speed: a table of F_avg / (mu W) over its dimensionless
//! groups, interpolated bicubically, and its inverse by Newton steps on the same interpolant
//! (issues 13 and 24; physics-notes §2).
//!
//! For alpha = 1 the periodic steady-state ratio R = F_avg / (mu W) depends only on
//! zeta = v / v_a and kappa x_a = k_t x_a / (mu W). The table is over
//! - `w = sqrt(1 - zeta)` in [0, 1], `S` nodes at w = i / (S - 1). R has a square-root
//!   singularity in zeta at zeta = 1 (the Coulomb limit: 1 - R ~ (4/pi) sqrt((1 - zeta)/2));
//!   in w it is smooth, and w costs one division and one square root (no asin);
//! - `y = log2(kappa x_a)` over [[`LOG2_KXA_MIN`], [`LOG2_KXA_MAX`]] = [-20, 12], `S` nodes:
//!   at a fixed kappa x_a, R is smooth in zeta down to 0, where at a fixed tau = zeta kappa x_a
//!   it is not (the soft-to-stiff transition sits at zeta ~ tau). The logarithm is a table
//!   lookup (`LOG2_MANTISSA`, 257 entries) and one linear interpolation: 2.8e-6 of a binary
//!   order at most, below 1e-6 of the ratio.
//!
//! with one ghost node on every side (linear extrapolation of the edge nodes), so that a
//! Catmull-Rom cubic in each direction needs no branch at the edges. The nodes are Q2.30 values
//! of the **independent f64 reference** (`host-tests/src/reference/dahl.rs`: closed-form fixed
//! point, converged adaptive quadrature), written by the host tool into
//! [`super::dahl_table_nodes`] and compiled into flash: nothing at scene start, alpha = 1 only
//! (a scene with another alpha cannot build a table variant, [`DahlTable::new`]).
//!
//! Beyond the table: below y = -20 (kappa x_a < 1e-6) R is the soft limit
//! (D_f - D_b) / (D_f + D_b) to within O(kappa x_a): the table's bottom row is used. Above
//! y = 12 (kappa x_a > 4096) R is extrapolated towards the Coulomb limit x = mu_i(zeta): the
//! correction R - x decays as c(w) / (kappa x_a) (the reference: (R - x) kappa x_a changes by
//! less than 1 % from kappa x_a = 2^12 to 2^20 for w >= 0.35), except in a boundary layer
//! near the onset (zeta -> 1) of width w ~ (kappa x_a)^(-1/3), where R - x = w G(kappa x_a w^3)
//! and the extrapolation goes by that similarity ([`DahlTable::stiff`]). Only there is asin
//! evaluated.
//!
//! The inverse (the amplitude for a target ratio): at a fixed operating point
//! tau = zeta kappa x_a = kappa |v| / omega does not depend on the amplitude, so the amplitudes
//! trace the curve y = log2 tau - log2(1 - w^2) through the table. A start w0 is read
//! (bilinearly) from `GUESS`, a table of the curve's inverse over the target and log2 tau,
//! then Newton steps on the forward interpolant along the curve (its gradient comes with the
//! bicubic's weights) land on the table's own value, so `ratio(invert(r)) = r` to the Newton
//! residual; the amplitude is a_min / (1 - w^2), a_min = |v| / (omega x_a,max).
//!
//! Accuracy and cost are measured, not assumed: `cli/tests/dahl_table.rs` (against the
//! reference over the table and at its extremes, and the round trip) and `docs/speed.md`.

use crate::fx::{Q1_31, Q2_30, Q8_24, sqrt_q32_approx};

use super::dahl::DahlParams;
use super::dahl_table_nodes::{GUESS, LOG2_MANTISSA, NODES};
use super::littmann::mu_i;
use super::{FrictionModel, Inversion, ModelError, OperatingPoint, Reach};

/// Lower end of the table's log2(kappa x_a) axis.
pub const LOG2_KXA_MIN: i32 = -16;
/// Upper end of the table's log2(kappa x_a) axis.
pub const LOG2_KXA_MAX: i32 = 8;
/// Nodes per binary order of kappa x_a on the y axis.
pub const NODES_PER_OCTAVE: usize = 3;
/// Nodes of the table along w (48 cells over [0, 1]).
pub const SIDE_W: usize = 49;
/// Nodes of the table along y ([`NODES_PER_OCTAVE`] per binary order over
/// [[`LOG2_KXA_MIN`], [`LOG2_KXA_MAX`]]: 72 cells).
pub const SIDE_Y: usize = (LOG2_KXA_MAX - LOG2_KXA_MIN) as usize * NODES_PER_OCTAVE + 1;
/// Stride of the padded node array (a ghost node on each side of every y row).
const STRIDE: usize = SIDE_Y + 2;
/// Nodes of the inverse's start table along u = sqrt(1 - r) (32 cells over [0, 1]).
pub const GUESS_U: usize = 33;
/// Nodes of the inverse's start table along log2 tau (one per binary order over the table's
/// y range).
pub const GUESS_TAU: usize = (LOG2_KXA_MAX - LOG2_KXA_MIN) as usize + 1;
/// Newton steps of the inverse after the start table, at most: it stops after a step below
/// [`CONVERGED_STEP`].
const NEWTON_STEPS: u32 = 4;
/// A Newton step in w (Q0.32) below 2^-16: the next would move R by about
/// R_ww / 2 * 2^-32 (< 1e-9), so the step's linear prediction is the interpolant's value.
const CONVERGED_STEP: i64 = 1 << 16;
/// Newton steps of the inverse where the curve leaves the table's stiff end.
const STIFF_STEPS: u32 = 8;
/// The table's y span in Q8.24 (24 binary orders).
const TOP: i32 = (LOG2_KXA_MAX - LOG2_KXA_MIN) << 24;
/// round(2^30 ln 2).
const LN2_Q30: i64 = 744_261_118;
/// round(2^30 * 2 / ln 2): dy/dw = 2 w / (zeta ln 2) in binary orders per unit of w.
const TWO_OVER_LN2_Q30: i64 = 3_098_164_010;
/// round(2^30 * 4 / pi): the Coulomb limit's slope in w is -(4/pi) / sqrt(1 + zeta).
const FOUR_OVER_PI_Q30: i64 = 1_367_130_551;
/// The nodes' offset: a node n (`i16`) stands for R = n / 2^15 + 1/2 (Q1.15 of R - 1/2: R in
/// [-0.5, 1.5) at a resolution of 3.1e-5, rounded to 1.5e-5). 1/2 in Q2.30.
const NODE_OFFSET_Q30: i64 = 1 << 29;

/// The Dahl table: `SIDE_W` x `SIDE_Y` nodes and their ghosts.
#[derive(Debug, PartialEq, Eq)]
pub struct DahlGrid {
    /// Nodes along w (the variant's table side, `T=49x73`).
    pub side: usize,
    /// (SIDE_W + 2)(SIDE_Y + 2) nodes, Q1.15 of R - 1/2 ([`NODE_OFFSET_Q30`]), w-major: node
    /// (i, j) (i in -1..=SIDE_W, j in -1..=SIDE_Y) at (i + 1) [`STRIDE`] + j + 1. Values in
    /// [0, 1] on the grid; the ghosts are the reference's own values one step beyond the edge
    /// (y both ends; w = 1 by the ratio's odd symmetry in zeta), except at w = 0 (linear
    /// extrapolation: R has no continuation in w below the onset).
    nodes: &'static [i16],
}

/// The 49 x 73 table (7.6 KB of nodes with ghosts).
pub static GRID: DahlGrid = DahlGrid {
    side: SIDE_W,
    nodes: &NODES,
};

/// log2(x) of an integer x > 0, Q8.24 (0 for x = 0, which no caller passes): the binary order
/// from a count of leading zeros, the mantissa's from `LOG2_MANTISSA` (256 intervals, linear
/// interpolation: error <= 2.8e-6). About 15 instructions.
#[inline]
fn log2_q24(x: u32) -> i32 {
    if x == 0 {
        return 0;
    }
    let lz = x.leading_zeros();
    let fraction = (x << lz) << 1; // mantissa - 1, Q0.32
    let k = (fraction >> 24) as usize; // 0..=255
    let t = ((fraction >> 8) & 0xFFFF) as i64; // Q.16 within the interval
    let (a, b) = (LOG2_MANTISSA[k] as i64, LOG2_MANTISSA[k + 1] as i64);
    let mantissa_q28 = a + (((b - a) * t) >> 16);
    ((31 - lz as i32) << 24) + ((mantissa_q28 + 8) >> 4) as i32
}

/// num 2^32 / den for 0 <= num < den: Q0.32 quotient within 8 units (2e-9), by a 32-bit
/// `UDIV` seed (16 bits) and one Newton step on the reciprocal. About 20 instructions.
#[inline]
fn div_frac(num: u32, den: u32) -> u32 {
    if den == 0 || num >= den {
        return u32::MAX;
    }
    let s = den.leading_zeros();
    let (d, n) = (den << s, num << s); // d in [2^31, 2^32), n < d
    // r ~ 2^63 / d in (2^31, 2^32]: seed from the top 16 bits, then r += r (2^63 - d r) / 2^63.
    let seed = ((u32::MAX / (d >> 16)) as u64) << 15;
    let error = ((1u64 << 63) as i64).wrapping_sub((d as u64 * seed) as i64); // |.| < 2^49
    let r = (seed as i64 + ((seed as i64 * (error >> 31)) >> 32)).clamp(0, u32::MAX as i64);
    let q = (n as u64 * r as u64) >> 31;
    q.min(u32::MAX as u64) as u32
}

/// num / den in Q.32 for den > 0 and |num| <= 2 den (clamped otherwise), to 2^-15 of the
/// quotient: one 32-bit `UDIV` for a 16-bit reciprocal of the normalised divisor (each Newton
/// step then leaves 2^-15 of its own size, far below the error it removes).
fn quotient_q32(num: i64, den: i64) -> i64 {
    if den <= 0 {
        return 0;
    }
    let num = num.clamp(-2 * den, 2 * den);
    let shift = den.leading_zeros() as i32 - 32; // den << shift in [2^31, 2^32)
    let d = if shift >= 0 {
        den << shift
    } else {
        den >> -shift
    } as u32;
    let r = (u32::MAX / (d >> 16)) as i64; // ~ 2^48 / d, 2^16 < r < 2^17
    // num / den 2^32 = num 2^shift r 2^(32 - 48); |num r| < 2^(35 + 17).
    let e = shift - 16;
    if e >= 0 {
        (num * r) << e
    } else {
        (num * r) >> -e
    }
}

/// The four Catmull-Rom weights at fraction `t` (Q.30, [0, 1]), in Q.30 (each within
/// [-0.15, 1], summing to 1 within 4 units): 32-bit arithmetic around two `SMULL`s. The
/// intermediate sums may leave the `i32` range, the weights do not: wrapping sums are exact.
#[inline]
fn weights(t: i32) -> [i32; 4] {
    let t2 = ((t as i64 * t as i64) >> 30) as i32;
    let t3 = ((t2 as i64 * t as i64) >> 30) as i32;
    let (h, h2, h3) = (t >> 1, t2 >> 1, t3 >> 1);
    [
        t2 - h3 - h,
        (1i32 << 30)
            .wrapping_add(h3.wrapping_mul(3))
            .wrapping_sub(h2.wrapping_mul(5)),
        h.wrapping_add(t2.wrapping_mul(2))
            .wrapping_sub(h3.wrapping_mul(3)),
        h3 - h2,
    ]
}

/// The derivatives of [`weights`] in t, Q.30 (each within [-1.5, 1.5]; wrapping sums as
/// there).
#[inline]
fn weight_slopes(t: i32) -> [i32; 4] {
    let t2 = ((t as i64 * t as i64) >> 30) as i32;
    let (h, h2) = (t >> 1, t2 >> 1);
    [
        t.wrapping_mul(2)
            .wrapping_sub(h2.wrapping_mul(3))
            .wrapping_sub(1 << 29),
        h2.wrapping_mul(9).wrapping_sub(h.wrapping_mul(10)),
        h.wrapping_mul(8)
            .wrapping_sub(h2.wrapping_mul(9))
            .wrapping_add(1 << 29),
        h2.wrapping_mul(3).wrapping_sub(t),
    ]
}

/// sum w_k n_k, Q.30 weights on Q2.30 values, rounded to Q2.30 (|sum| < 2^62 for values below
/// 2 in magnitude and weights below 1.5).
#[inline]
fn dot(w: &[i32; 4], n: &[i32; 4]) -> i32 {
    let acc = w[0] as i64 * n[0] as i64
        + w[1] as i64 * n[1] as i64
        + w[2] as i64 * n[2] as i64
        + w[3] as i64 * n[3] as i64;
    ((acc + (1 << 29)) >> 30) as i32
}

/// sum w_k n_k, Q.30 weights on Q1.15 nodes, rounded to Q2.30 (|sum| < 2^47).
#[inline]
fn dot_nodes(w: &[i32; 4], n: &[i16; 4]) -> i32 {
    let acc = w[0] as i64 * n[0] as i64
        + w[1] as i64 * n[1] as i64
        + w[2] as i64 * n[2] as i64
        + w[3] as i64 * n[3] as i64;
    ((acc + (1 << 14)) >> 15) as i32
}

/// R and its slopes at a point of the table: `value` Q2.30; `per_w`, `per_y`: dR/dw per unit
/// of w and dR/dy per binary order of kappa x_a, Q.30.
#[derive(Debug, Clone, Copy)]
struct Slope {
    value: i64,
    per_w: i64,
    per_y: i64,
}

impl DahlGrid {
    /// The grid with `side` nodes along w (49: the only table).
    pub fn of_side(side: usize) -> Option<&'static DahlGrid> {
        (side == SIDE_W).then_some(&GRID)
    }

    /// Cells and fractions (Q.30) of w (Q0.32) and of the y offset `d` (Q8.24 in [0, 24]).
    /// 48 cells in w and 3 per binary order in y: one multiplication each, no division.
    #[inline]
    fn split(w: u32, d: i32) -> (usize, i32, usize, i32) {
        let pw = w as u64 * (SIDE_W as u64 - 1); // Q.32 position in nodes
        let (i, tx) = ((pw >> 32) as usize, ((pw as u32) >> 2) as i32);
        let p = d as i64 * NODES_PER_OCTAVE as i64; // Q.24 position in nodes
        let j = (p >> 24) as usize;
        if j >= SIDE_Y - 1 {
            return (i, tx, SIDE_Y - 2, 1 << 30);
        }
        (i, tx, j, ((p & ((1 << 24) - 1)) << 6) as i32)
    }

    /// The 4 x 4 nodes around cell (i, j), one bounds check (a failed lookup, which the split
    /// rules out, reads as zeros rather than panicking).
    #[inline]
    fn block(&self, i: usize, j: usize) -> [[i16; 4]; 4] {
        // Node (i - 1, j - 1) sits at padded (i, j).
        let base = i * STRIDE + j;
        let Some(b) = self.nodes.get(base..base + 3 * STRIDE + 4) else {
            return [[0; 4]; 4];
        };
        let row = |r: usize| {
            [
                b[r * STRIDE],
                b[r * STRIDE + 1],
                b[r * STRIDE + 2],
                b[r * STRIDE + 3],
            ]
        };
        [row(0), row(1), row(2), row(3)]
    }

    /// The four rows (in w) of a block, interpolated in y with `wy` (Q2.30, without the
    /// nodes' offset).
    #[inline]
    fn rows(block: &[[i16; 4]; 4], wy: &[i32; 4]) -> [i32; 4] {
        [
            dot_nodes(wy, &block[0]),
            dot_nodes(wy, &block[1]),
            dot_nodes(wy, &block[2]),
            dot_nodes(wy, &block[3]),
        ]
    }

    /// R at w (Q0.32 in [0, 1)) and y offset `d` (Q8.24 in [0, 24]): the bicubic Catmull-Rom
    /// interpolant, Q2.30 (the weights sum to 1 within 4 units, so the offset is added once).
    fn bicubic(&self, w: u32, d: i32) -> i64 {
        let (i, tx, j, ty) = Self::split(w, d);
        let rows = Self::rows(&self.block(i, j), &weights(ty));
        dot(&weights(tx), &rows) as i64 + NODE_OFFSET_Q30
    }

    /// [`Self::bicubic`] with its slopes in w and y (the weights' slopes sum to 0: the offset
    /// drops out of them).
    fn slope(&self, w: u32, d: i32) -> Slope {
        let (i, tx, j, ty) = Self::split(w, d);
        let block = self.block(i, j);
        let rows = Self::rows(&block, &weights(ty));
        let row_slopes = Self::rows(&block, &weight_slopes(ty));
        let wx = weights(tx);
        Slope {
            value: dot(&wx, &rows) as i64 + NODE_OFFSET_Q30,
            per_w: dot(&weight_slopes(tx), &rows) as i64 * (SIDE_W as i64 - 1),
            per_y: dot(&wx, &row_slopes) as i64 * NODES_PER_OCTAVE as i64,
        }
    }
}

/// The Dahl steady state of a scene (alpha = 1) evaluated from a [`DahlGrid`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DahlTable {
    grid: &'static DahlGrid,
    /// a_min = |v| / (omega x_a,max) as a Q1.31 amplitude is (|v| bits (Q8.24) *
    /// `onset_mantissa`) >> `onset_shift`: the amplitude at which the velocity starts to
    /// reverse (zeta = 1).
    onset_mantissa: u32,
    onset_shift: u32,
    /// log2(k_t x_a,max / mu) - 15, Q8.24: y = log2(a bits) - log2(W bits) + this.
    kxa_offset: i32,
    /// log2(k_t / (mu omega)) - 8, Q8.24: log2 tau = log2(|v| bits) - log2(W bits) + this.
    tau_offset: i32,
}

fn domain(input: &'static str, reason: &'static str) -> ModelError {
    ModelError::OutOfDomain { input, reason }
}

/// The binary exponent e of a positive normal f64 (x in [2^e, 2^(e + 1))) and its mantissa's
/// top 32 bits (1.f in Q1.31), or `None` for zero, negative, subnormal, infinite or NaN x.
fn exponent_mantissa(x: f64) -> Option<(i32, u32)> {
    if !(x.is_finite() && x >= f64::MIN_POSITIVE) {
        return None;
    }
    let bits = x.to_bits();
    let exponent = ((bits >> 52) & 0x7FF) as i32 - 1023;
    Some((exponent, (1 << 31) | ((bits >> 21) as u32 & 0x7FFF_FFFF)))
}

/// log2 of a positive f64 (scene load), Q8.24, or `OutOfDomain` beyond +-127: the exponent's
/// bits and [`log2_q24`] of the mantissa's top 32 bits (within 3e-6 of a binary order; the
/// same integer arithmetic on the host and the board, and no `libm` logarithm, whose tables
/// would cost the G474 4 KB of flash).
fn log2_q24_f64(x: f64, input: &'static str) -> Result<i32, ModelError> {
    let beyond = || domain(input, "kappa x_a or tau beyond 2^+-127");
    let (exponent, mantissa) = exponent_mantissa(x).ok_or_else(beyond)?;
    if exponent.abs() >= 127 {
        return Err(beyond());
    }
    Ok((exponent << 24) + log2_q24(mantissa) - (31 << 24))
}

impl DahlTable {
    /// The table model of a scene's Dahl parameters (f64, scene load) on `grid`. Errors as
    /// [`super::dahl::DahlConstants::new`] for mu, k_t, f and x_a,max; `OutOfDomain` for
    /// alpha != 1 (the committed tables are for alpha = 1; the quadrature points are unused)
    /// and for scale factors beyond the formats (|log2| >= 127, or omega x_a,max outside
    /// 2^-32 to 2^7 m/s).
    pub fn new(params: &DahlParams, grid: &'static DahlGrid) -> Result<Self, ModelError> {
        // Same validation as the exact model (mu, k_t, f, x_a, alpha), one source of truth.
        super::dahl::DahlConstants::new(&DahlParams {
            quadrature_points: 64,
            ..*params
        })?;
        if params.shape_exponent != 1.0 {
            return Err(domain("alpha", "the Dahl tables are built for alpha = 1"));
        }
        let mu = params.friction_coefficient;
        let k_t = params.tangential_stiffness;
        let omega = core::f64::consts::TAU * params.frequency_hz;
        let x_a = params.full_scale_amplitude_m;
        // a_min bits = |v| bits 2^7 / (omega x_a): 2^7 / (omega x_a) = m 2^-shift, m in [2^31, 2^32).
        let onset = 128.0 / (omega * x_a);
        let beyond = || domain("x_a", "omega x_a,max beyond 2^-32 to 2^7 m/s");
        let (order, _) = exponent_mantissa(onset).ok_or_else(beyond)?;
        let shift = 31 - order;
        if !(1..=62).contains(&shift) {
            return Err(beyond());
        }
        // onset 2^shift, exactly (a power of two), rounded to an integer.
        let scale = f64::from_bits(((1023 + shift) as u64) << 52);
        let mantissa = libm::round(onset * scale).min(u32::MAX as f64);
        Ok(Self {
            grid,
            onset_mantissa: mantissa as u32,
            onset_shift: shift as u32,
            kxa_offset: log2_q24_f64(k_t * x_a / mu, "k_t")? - (15 << 24),
            tau_offset: log2_q24_f64(k_t / (mu * omega), "k_t")? - (8 << 24),
        })
    }

    /// The grid (table size).
    pub fn grid(&self) -> &'static DahlGrid {
        self.grid
    }

    /// R at w (Q0.32) and y = log2(kappa x_a) (Q8.24), with `zeta` = 1 - w^2 (Q0.32) for the
    /// stiff extrapolation: Q2.30 in [0, 1].
    fn value(&self, w: u32, y: i32, zeta: u32) -> i64 {
        let d = y as i64 - ((LOG2_KXA_MIN as i64) << 24);
        let top = TOP as i64;
        if d > top {
            return self.stiff(w, zeta, d - top).value;
        }
        self.grid.bicubic(w, d.max(0) as i32)
    }

    /// R and its slopes at w (Q0.32) and y (Q8.24), `zeta` = 1 - w^2 (Q0.32); below the table
    /// the slope in y is 0 (the bottom row is used), above it the extrapolation's.
    fn slope(&self, w: u32, y: i32, zeta: u32) -> Slope {
        let d = y as i64 - ((LOG2_KXA_MIN as i64) << 24);
        let top = TOP as i64;
        if d > top {
            return self.stiff(w, zeta, d - top);
        }
        let mut s = self.grid.slope(w, d.max(0) as i32);
        if d < 0 {
            s.per_y = 0;
        }
        s
    }

    /// Beyond the stiff end, `beyond` (Q8.24 binary orders) above it, towards the Coulomb
    /// limit x = mu_i(zeta) (the decay laws below were measured with the f64 reference:
    /// `docs/dahl.md`). R - x = w G(kappa x_a w^3) near zeta = 1 (the backward stretch's
    /// travel, kappa x_a w^3, sets the boundary layer) and R - x ~ c(w) / (kappa x_a) once
    /// kappa x_a w^3 is large, so:
    /// - for w < 1/4, by similarity from the top row at w' = w 2^(beyond / 3) (the same
    ///   kappa x_a w^3): R = x + (R(w', top) - x(w')) w / w';
    /// - otherwise (or where w' >= 1: R - x < 3e-5 w there), R = x + (R(w, top) - x) 2^-beyond.
    ///
    /// Slopes: the Coulomb limit's, -(4/pi) / sqrt(1 + zeta) (1 / sqrt(1 + zeta) to 2 % by a
    /// line), and the excess's; they serve the inverse's Newton steps only.
    fn stiff(&self, w: u32, zeta: u32, beyond: i64) -> Slope {
        let coulomb_slope = |z: u32| {
            let inv_root = (1i64 << 30) - ((314_491_699i64 * z as i64) >> 32);
            -((FOUR_OVER_PI_Q30 * inv_root) >> 30)
        };
        let coulomb =
            |z: u32| mu_i(Q2_30::from_bits((z >> 2) as i32)).map_or(0, |x| x.to_bits() as i64);
        // e^-nepers, Q.30, for nepers in Q8.24 >= 0.
        let decay = |nepers: i64| {
            if nepers >= 127 << 24 {
                0
            } else {
                Q8_24::from_bits(nepers as i32)
                    .exp_neg()
                    .map_or(0, |q| q.to_bits() as i64)
            }
        };
        let x = coulomb(zeta);
        let x_w = coulomb_slope(zeta);
        if w < 1 << 30 {
            let scale = decay(((beyond * LN2_Q30) >> 30) / 3); // w / w' = 2^(-beyond / 3), Q.30
            let scale32 = (scale << 2).min(u32::MAX as i64) as u32;
            if w < scale32 {
                let w1 = div_frac(w, scale32);
                let z1 = u32::MAX - ((w1 as u64 * w1 as u64) >> 32) as u32;
                let edge = self.grid.slope(w1, TOP);
                let excess = edge.value - coulomb(z1);
                let excess_w = edge.per_w - coulomb_slope(z1);
                // d/dy of excess(w') w / w' at fixed w: (excess_w w' - excess) (w / w') ln2 / 3.
                let per_y = ((((excess_w * (w1 >> 2) as i64) >> 30) - excess) * scale) >> 30;
                return Slope {
                    value: (x + ((excess * scale) >> 30)).clamp(0, 1 << 30),
                    per_w: x_w + excess_w,
                    per_y: ((per_y * LN2_Q30) >> 30) / 3,
                };
            }
        }
        let edge = self.grid.slope(w, TOP);
        let q = decay((beyond * LN2_Q30) >> 30);
        let excess = edge.value - x;
        Slope {
            value: (x + ((excess * q) >> 30)).clamp(0, 1 << 30),
            per_w: ((x_w * ((1 << 30) - q)) >> 30) + ((edge.per_w * q) >> 30),
            per_y: -((((excess * q) >> 30) * LN2_Q30) >> 30),
        }
    }

    /// a_min (Q1.31 bits, saturated at 2^31) for a speed in Q8.24 bits.
    #[inline]
    fn onset(&self, speed: u32) -> u64 {
        ((speed as u64 * self.onset_mantissa as u64) >> self.onset_shift).min(1 << 31)
    }

    /// R at w (Q0.32 in [0, 1)) and y = log2(kappa x_a) (Q8.24): the table's own function of
    /// its coordinates, Q2.30 in [0, 1].
    pub fn ratio_at(&self, w: u32, log2_kxa: Q8_24) -> Q2_30 {
        let w2 = ((w as u64 * w as u64) >> 32) as u32;
        let r = self.value(w, log2_kxa.to_bits(), u32::MAX - w2);
        Q2_30::from_bits(r.clamp(0, 1 << 30) as i32)
    }

    /// The start of the inverse: w (Q0.32) from `GUESS`, bilinear in u = sqrt(1 - target)
    /// (target Q2.30 in [0, 1)) and log2 tau (Q8.24, clamped to the table's range). In u the
    /// start is smooth at both ends: near r = 1, w ~ (1 - r)^(1/3) (a soft contact) to
    /// (1 - r) (a stiff one), which a uniform r axis would interpolate badly.
    fn guess(target: i64, log2_tau: i32) -> u32 {
        let u = sqrt_q32_approx(
            (((1i64 << 30) - target.clamp(0, 1 << 30)) << 2).min(u32::MAX as i64) as u32,
        );
        let pu = u as u64 * (GUESS_U as u64 - 1); // Q.32 nodes
        let (k, tk) = if (pu >> 32) as usize >= GUESS_U - 1 {
            (GUESS_U - 2, 1i64 << 32)
        } else {
            ((pu >> 32) as usize, (pu as u32) as i64)
        };
        // One node per binary order: the offset's integer part is the column.
        let d = (log2_tau as i64 - ((LOG2_KXA_MIN as i64) << 24)).clamp(0, TOP as i64);
        let (l, tl) = if (d >> 24) as usize >= GUESS_TAU - 1 {
            (GUESS_TAU - 2, 1i64 << 24)
        } else {
            ((d >> 24) as usize, d & ((1 << 24) - 1))
        };
        let at = |k: usize, l: usize| GUESS.get(k * GUESS_TAU + l).map_or(0, |&g| g as i64);
        let lerp = |a: i64, b: i64, t: i64, bits: u32| a + (((b - a) * t) >> bits);
        let lower = lerp(at(k, l), at(k, l + 1), tl, 24);
        let upper = lerp(at(k + 1, l), at(k + 1, l + 1), tl, 24);
        // Q0.16 to Q0.32.
        (lerp(lower, upper, tk, 32) << 16).clamp(0, u32::MAX as i64) as u32
    }
}

impl FrictionModel for DahlTable {
    /// `kappa x_a = k_t x_a / (mu W)`: the load enters only through `mu W`.
    fn load_enters_as_coulomb_force(&self) -> bool {
        true
    }

    /// F'/F at the operating point (W Q16.16 > 0, v Q8.24) and `amplitude` (Q1.31 in [0, 1)):
    /// w = sqrt((a - a_min) / a) (one quotient, one square root), y = log2(a) - log2(W) + a
    /// scene constant (two table logarithms), then the bicubic table. Exactly 1 without
    /// reversal (a <= a_min, or no vibration), 0 at v = 0.
    /// Errors: W <= 0, amplitude < 0, v = 0 without vibration.
    fn ratio(&self, point: &OperatingPoint, amplitude: Q1_31) -> Result<Q2_30, ModelError> {
        let a = amplitude.to_bits();
        if a < 0 {
            return Err(domain("amplitude", "must be >= 0"));
        }
        let load = point.normal_force.to_bits();
        if load <= 0 {
            return Err(domain("W", "must be > 0 (F_c = mu W)"));
        }
        let speed = point.sliding_velocity.saturating_abs().value.to_bits() as u32;
        if speed == 0 {
            return if a == 0 {
                Err(domain(
                    "v",
                    "no sliding: the friction ratio is undefined without vibration",
                ))
            } else {
                Ok(Q2_30::ZERO)
            };
        }
        let a = a as u32;
        let onset = self.onset(speed);
        if a as u64 <= onset {
            return Ok(Q2_30::ONE); // no reversal: zeta >= 1
        }
        let w2 = div_frac(a - onset as u32, a); // 1 - zeta, Q0.32
        let w = sqrt_q32_approx(w2);
        let y = log2_q24(a) - log2_q24(load as u32) + self.kxa_offset;
        let r = self.value(w, y, u32::MAX - w2);
        Ok(Q2_30::from_bits(r.clamp(0, 1 << 30) as i32))
    }

    /// The amplitude for `target` (Q2.30) at the operating point: the start from `GUESS`, then
    /// [`NEWTON_STEPS`] Newton steps in w along the curve y = log2 tau - log2(1 - w^2) on the
    /// forward interpolant (its slope dR/dw + dR/dy dy/dw, dy/dw = 2 w / ((1 - w^2) ln 2)),
    /// and a = a_min / (1 - w^2). The returned ratio is the last step's linear prediction
    /// (the target; the interpolant's value at the step's start if the step was clamped). `BelowMinimum` (full amplitude) when the
    /// target needs a >= 1; `AboveNatural` for a target >= 1.
    /// Errors: W <= 0, v = 0 (the ratio is 0 at every amplitude: undefined).
    fn invert(&self, point: &OperatingPoint, target: Q2_30) -> Result<Inversion, ModelError> {
        self.invert_in(point, target, NEWTON_STEPS)
    }
}

impl DahlTable {
    /// [`FrictionModel::invert`] with `steps` Newton steps.
    fn invert_in(
        &self,
        point: &OperatingPoint,
        target: Q2_30,
        steps: u32,
    ) -> Result<Inversion, ModelError> {
        let speed = point.sliding_velocity.saturating_abs().value.to_bits() as u32;
        if speed == 0 {
            return Err(domain(
                "v",
                "no sliding: the friction ratio is undefined without vibration",
            ));
        }
        if target >= Q2_30::ONE {
            return Ok(Inversion {
                amplitude: Q1_31::ZERO,
                ratio: Q2_30::ONE,
                reach: Reach::AboveNatural,
            });
        }
        let load = point.normal_force.to_bits();
        if load <= 0 {
            return Err(domain("W", "must be > 0 (F_c = mu W)"));
        }
        let full = || {
            Ok(Inversion {
                amplitude: Q1_31::MAX,
                ratio: self.ratio(point, Q1_31::MAX)?,
                reach: Reach::BelowMinimum,
            })
        };
        let onset = self.onset(speed);
        if onset >= 1 << 31 {
            return full(); // no reversal at any amplitude: R = 1
        }
        let t = target.to_bits().max(0) as i64;
        let log2_tau = log2_q24(speed) - log2_q24(load as u32) + self.tau_offset;
        let mut w = Self::guess(t, log2_tau) as i64;
        let mut ratio = t;
        // Beyond the stiff end the slopes are approximate (`stiff`): Newton converges
        // linearly there, and takes up to STIFF_STEPS steps.
        let top = LOG2_KXA_MAX << 24;
        for step in 0..steps.max(STIFF_STEPS) {
            let w32 = w.clamp(0, u32::MAX as i64) as u32;
            let zeta = u32::MAX - ((w32 as u64 * w32 as u64) >> 32) as u32;
            if zeta == 0 {
                break;
            }
            let y = log2_tau - (log2_q24(zeta) - (32 << 24));
            if step >= steps && y <= top {
                break;
            }
            let s = self.slope(w32, y, zeta);
            // The interpolant's slopes are below 4 in magnitude; clamped so that no input
            // can make the products below overflow.
            let (per_w, per_y) = (
                s.per_w.clamp(-8 << 30, 8 << 30),
                s.per_y.clamp(-8 << 30, 8 << 30),
            );
            // Multiplied through by zeta: (R - t) zeta / (R_w zeta + R_y 2 w / ln 2).
            // Q.30 throughout (|R_w|, |R_y| <= 8, 2 w / ln 2 < 2.9: every product < 2^63).
            let zeta30 = (zeta >> 2) as i64;
            let num = ((s.value - t) * zeta30) >> 30;
            let dy_dw = ((w32 as u64 * TWO_OVER_LN2_Q30 as u64) >> 32) as i64; // 2 w / ln 2
            let den = ((per_w * zeta30) >> 30) + ((per_y * dy_dw) >> 30);
            if den >= 0 {
                ratio = s.value;
                break; // not falling: stay (cannot happen on the table's monotone curve)
            }
            let step = quotient_q32(num, -den); // Q0.32 of w, dR < 0
            let next = w + step;
            w = next.clamp(0, u32::MAX as i64);
            // The step's linear prediction is the target itself, unless it was clamped.
            ratio = if w == next { t } else { s.value };
            if step.abs() < CONVERGED_STEP && y <= top {
                break;
            }
        }
        let w32 = w as u32;
        let zeta = u32::MAX - ((w32 as u64 * w32 as u64) >> 32) as u32;
        // a = a_min / zeta, Q1.31: a_min (Q1.31) < zeta (Q0.32) / 2 for a < 1.
        if zeta == 0 || (onset << 1) >= zeta as u64 {
            return full();
        }
        let amplitude = div_frac((onset << 1) as u32, zeta) >> 1;
        Ok(Inversion {
            amplitude: Q1_31::from_bits(amplitude as i32),
            ratio: Q2_30::from_bits(ratio.clamp(0, 1 << 30) as i32),
            reach: Reach::Reached,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fx::Q16_16;

    fn seed_003(k_t: f64, grid: &'static DahlGrid) -> DahlTable {
        DahlTable::new(
            &DahlParams {
                friction_coefficient: 0.2,
                tangential_stiffness: k_t,
                frequency_hz: 40e3,
                full_scale_amplitude_m: 2.0 * 0.0683 / (core::f64::consts::TAU * 40e3),
                shape_exponent: 1.0,
                quadrature_points: 64,
            },
            grid,
        )
        .unwrap()
    }

    fn point(w: f64, v: f64) -> OperatingPoint {
        OperatingPoint {
            normal_force: Q16_16::from_f64(w).unwrap(),
            sliding_velocity: Q8_24::from_f64(v).unwrap(),
        }
    }

    /// The table logarithm against libm over every binary order and dense mantissas: within
    /// 3e-6 (the linear interpolation's 2.8e-6 plus the Q.24 rounding).
    #[test]
    fn log2_is_within_its_bound() {
        for e in 0..32u32 {
            for k in 0..2000u64 {
                let x = ((1u64 << e) + (k * (1u64 << e)) / 2000).min(u32::MAX as u64) as u32;
                let got = f64::from(log2_q24(x)) / 16_777_216.0;
                let want = libm::log2(f64::from(x));
                assert!((got - want).abs() < 3e-6, "log2({x}) = {got} vs {want}");
            }
        }
        assert_eq!(log2_q24(1), 0);
        assert_eq!(log2_q24(1 << 20), 20 << 24);
    }

    /// The quotient against u64 division: within 8 units of Q0.32, at extremes and between.
    #[test]
    fn div_frac_is_within_eight_units() {
        let cases = [
            (0u32, 1u32),
            (1, 2),
            (u32::MAX - 1, u32::MAX),
            (1, u32::MAX),
            (0x7FFF_FFFF, 0x8000_0000),
            (12345, 67890),
            (3, 0x8000),
        ];
        let mut state = 0x1234_5678_9abc_def0u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let random = (0..20_000).map(|_| {
            let den = (next() as u32).max(1) >> (next() % 32);
            let den = den.max(1);
            ((next() as u32) % den, den)
        });
        for (num, den) in cases.into_iter().chain(random) {
            let want = ((num as u64) << 32) / den as u64;
            let got = div_frac(num, den) as u64;
            assert!(got.abs_diff(want) <= 8, "{num} / {den}: {got} vs {want}");
        }
        assert_eq!(div_frac(5, 5), u32::MAX);
        assert_eq!(div_frac(1, 0), u32::MAX);
    }

    #[test]
    fn interpolation_reproduces_the_nodes() {
        let grid = &GRID;
        for i in 0..SIDE_W - 1 {
            for j in 0..SIDE_Y {
                let w = ((i as u64) << 32).div_ceil(SIDE_W as u64 - 1) as u32;
                let d = (((j as i64) << 24) + NODES_PER_OCTAVE as i64 - 1) as i32
                    / NODES_PER_OCTAVE as i32;
                let node =
                    grid.nodes[(i + 1) * STRIDE + j + 1] as i64 * (1 << 15) + NODE_OFFSET_Q30;
                // w and d round up onto the node, at most 1.2e-7 of a cell beyond it: within
                // 2^10 units (1e-6) of Q2.30 for slopes below 8 per cell.
                assert!((grid.bicubic(w, d) - node).abs() <= 1 << 10, "({i}, {j})");
                assert!(
                    (grid.slope(w, d).value - node).abs() <= 1 << 10,
                    "({i}, {j})"
                );
            }
        }
    }

    /// The slopes the inverse uses are those of the interpolant: against central differences.
    #[test]
    fn slopes_are_the_interpolants() {
        let grid = &GRID;
        for &(w, d) in &[
            (0.3, 10.3),
            (0.05, 20.7),
            (0.93, 3.1),
            (0.51, 16.0),
            (0.002, 23.5),
        ] {
            let wq = (w * 4294967296.0) as u32;
            let dq = (d * 16777216.0) as i32;
            let s = grid.slope(wq, dq);
            let (hw, hd) = (1u32 << 16, 1i32 << 10);
            let dw = (grid.bicubic(wq + hw, dq) - grid.bicubic(wq - hw, dq)) as f64
                / (2.0 * hw as f64 / 4294967296.0);
            let dd = (grid.bicubic(wq, dq + hd) - grid.bicubic(wq, dq - hd)) as f64
                / (2.0 * hd as f64 / 16777216.0);
            assert!(
                (s.per_w as f64 - dw).abs() <= 2e-3 * (1 << 30) as f64,
                "w {w} d {d}"
            );
            assert!(
                (s.per_y as f64 - dd).abs() <= 2e-3 * (1 << 30) as f64,
                "w {w} d {d}"
            );
        }
    }

    #[test]
    fn ratio_is_monotone_in_amplitude_and_the_inverse_returns_to_it() {
        for (k_t, grid) in [(5.6e4, &GRID), (2.5e7, &GRID), (1e10, &GRID)] {
            let m = seed_003(k_t, grid);
            for (w, v) in [(0.54, 0.038), (4.155, 0.038), (7.905, 0.01), (2.0, -0.03)] {
                let p = point(w, v);
                let mut last = Q2_30::ONE;
                for k in 0..=200 {
                    let a = Q1_31::from_bits((k as i64 * i32::MAX as i64 / 200) as i32);
                    let r = m.ratio(&p, a).unwrap();
                    assert!(r <= last, "k_t {k_t} W {w}: step {k}: {r:?} after {last:?}");
                    last = r;
                }
                let lowest = m.ratio(&p, Q1_31::MAX).unwrap().to_f64();
                for target in [0.3, 0.5, 0.8, 0.95, 0.999] {
                    let inv = m.invert(&p, Q2_30::from_f64(target).unwrap()).unwrap();
                    if target <= lowest {
                        assert_eq!(inv.reach, Reach::BelowMinimum, "k_t {k_t} W {w} {target}");
                        continue;
                    }
                    assert_eq!(inv.reach, Reach::Reached, "k_t {k_t} W {w} {target}");
                    let back = m.ratio(&p, inv.amplitude).unwrap().to_f64();
                    assert!(
                        (back - target).abs() < 2e-5 && (inv.ratio.to_f64() - target).abs() < 2e-5,
                        "k_t {k_t} W {w}: target {target}, ratio at the inverse {back}, reported {}",
                        inv.ratio.to_f64()
                    );
                }
            }
        }
    }

    #[test]
    fn special_inputs_are_reported_not_wrapped() {
        let m = seed_003(5.6e4, &GRID);
        let p = point(1.0, 0.038);
        assert_eq!(m.ratio(&p, Q1_31::ZERO), Ok(Q2_30::ONE));
        assert!(m.ratio(&p, Q1_31::from_bits(-5)).is_err());
        assert_eq!(m.ratio(&point(1.0, 0.0), Q1_31::MAX), Ok(Q2_30::ZERO));
        assert!(m.ratio(&point(1.0, 0.0), Q1_31::ZERO).is_err());
        assert!(m.ratio(&point(0.0, 0.038), Q1_31::MAX).is_err());
        assert!(
            m.invert(&point(1.0, 0.0), Q2_30::from_f64(0.5).unwrap())
                .is_err()
        );
        let above = m.invert(&p, Q2_30::ONE).unwrap();
        assert_eq!(
            (above.reach, above.amplitude),
            (Reach::AboveNatural, Q1_31::ZERO)
        );
        // Sliding faster than the full-scale vibration: no reversal, R = 1 at every amplitude.
        let fast = m
            .invert(&point(1.0, 0.5), Q2_30::from_f64(0.5).unwrap())
            .unwrap();
        assert_eq!((fast.reach, fast.ratio), (Reach::BelowMinimum, Q2_30::ONE));
        let other = DahlParams {
            friction_coefficient: 0.2,
            tangential_stiffness: 5.6e4,
            frequency_hz: 40e3,
            full_scale_amplitude_m: 1e-6,
            shape_exponent: 2.0,
            quadrature_points: 64,
        };
        assert!(DahlTable::new(&other, &GRID).is_err());
        assert!(DahlGrid::of_side(33).is_none());
    }
}
