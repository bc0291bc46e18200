//! The Dahl steady state at loop speed: a table of F_avg / (mu W) over its dimensionless
//! groups, interpolated bicubically, and its inverse (issue 13; physics-notes §2).
//!
//! For alpha = 1 the periodic steady-state ratio R = F_avg / (mu W) depends only on
//! zeta = v / v_a and kappa x_a = k_t x_a / (mu W). The table is over
//! - `x = mu_i(zeta) = (2/pi) asin(zeta)` in [0, 1] (the Coulomb ratio: the stiff limit of R
//!   is exactly x, and the soft limit (D_f - D_b) / (D_f + D_b) is smooth in it), `S` nodes
//!   at x = i / (S - 1), and
//! - `y = ln(kappa x_a)` over [[`LN_KXA_MIN`], [`LN_KXA_MAX`]] = [-8, 8], `S` nodes,
//!
//! with one ghost node on every side (linear extrapolation of the edge nodes), so that a
//! Catmull-Rom cubic in each direction needs no branch at the edges. The nodes are Q2.30 values
//! of the **independent f64 reference** (`host-tests/src/reference/dahl.rs`: closed-form fixed
//! point, converged adaptive quadrature), written by the host tool into
//! [`super::dahl_table_nodes`] and compiled into flash: built once, nothing at scene start,
//! for alpha = 1 only (a scene with another alpha cannot build a table variant and keeps the
//! exact steady state, [`DahlTable::new`]).
//!
//! Beyond the table: for y > 8 (kappa x_a > 2981) R is extrapolated towards the Coulomb limit
//! as x + (R(x, 8) - x) e^-(y - 8) (the correction decays as 1 / (kappa x_a), measured by the
//! reference to 1 % between y = 8 and 14); below y = -8 (kappa x_a < 3.4e-4) the table
//! refuses (`OutOfDomain`): such a contact never reverses its force, and no scene's operating
//! range reaches there (kappa x_a >= kappa |v| / omega whenever the velocity reverses).
//!
//! Accuracy and cost are measured, not assumed: `host-tests/tests/dahl_table.rs` (against
//! the reference at the corners and over the scenes' grids) and `docs/speed.md`.

use crate::fx::{Q1_31, Q2_30, Q8_24, sin};

use super::dahl::DahlParams;
use super::dahl_table_nodes::{LN_SIN_33, LN_SIN_65, NODES_33, NODES_65};
use super::littmann::{VelocityRatio, velocity_ratio};
use super::{FrictionModel, Inversion, ModelError, OperatingPoint, Reach};
use crate::fx::scaled::Scaled;
use crate::fx::wide;

/// Lower end of the table's ln(kappa x_a) axis.
pub const LN_KXA_MIN: i32 = -8;
/// Upper end of the table's ln(kappa x_a) axis.
pub const LN_KXA_MAX: i32 = 8;
/// log2 of the span (16) of the ln(kappa x_a) axis.
const SPAN_LOG2: u32 = 4;

/// One table size: `side` x `side` nodes, their ghosts, and the curve constants of the inverse.
#[derive(Debug, PartialEq, Eq)]
pub struct DahlGrid {
    /// Nodes per axis S (33 or 65: S - 1 a power of two).
    pub side: usize,
    /// log2(S - 1).
    steps_log2: u32,
    /// (S + 2)^2 nodes, Q2.30, x-major: node (i, j) (i, j in -1..=S) at (i + 1)(S + 2) + j + 1.
    /// Values in [0, 1] on the grid, ghosts within [-1, 2).
    nodes: &'static [i32],
    /// ln sin(pi x_i / 2) at the x nodes, Q8.24 (i = 0: `i32::MIN`, unused).
    ln_sin: &'static [i32],
}

/// The 33 x 33 table (4.6 KB of nodes with ghosts).
pub static GRID_33: DahlGrid = DahlGrid {
    side: 33,
    steps_log2: 5,
    nodes: &NODES_33,
    ln_sin: &LN_SIN_33,
};

/// The 65 x 65 table (18 KB of nodes with ghosts).
pub static GRID_65: DahlGrid = DahlGrid {
    side: 65,
    steps_log2: 6,
    nodes: &NODES_65,
    ln_sin: &LN_SIN_65,
};

impl DahlGrid {
    /// The grid with `side` nodes per axis (33 or 65; 65 only in a build with the cargo
    /// feature `dahl-fine-table`, which the built-in scenes never select).
    pub fn of_side(side: usize) -> Option<&'static DahlGrid> {
        match side {
            33 => Some(&GRID_33),
            65 if cfg!(feature = "dahl-fine-table") => Some(&GRID_65),
            _ => None,
        }
    }

    #[cfg(test)]
    fn stride(&self) -> usize {
        self.side + 2
    }

    /// Cell and fraction (Q.30) of an x in Q2.30, 0 <= x < 1, on a grid of 2^K + 1 nodes.
    #[inline]
    fn split_x<const K: u32>(x: i32) -> (usize, i64) {
        let cell = (x >> (30 - K)) as usize;
        let t = ((x as i64) << K) & ((1 << 30) - 1);
        (cell, t)
    }

    /// Cell and fraction (Q.30) of an offset `d` = y - [`LN_KXA_MIN`] in Q8.24, 0 <= d <= 16,
    /// on a grid of 2^K + 1 nodes. The top edge (d = 16) is the last cell at t = 1.
    #[inline]
    fn split_y<const K: u32>(d: i32) -> (usize, i64) {
        let p = (d as i64) << K >> SPAN_LOG2; // Q.24 position in nodes
        let cell = (p >> 24) as usize;
        if cell >= 1 << K {
            return ((1 << K) - 1, 1 << 30);
        }
        (cell, (p & ((1 << 24) - 1)) << 6)
    }

    /// The four Catmull-Rom weights at fraction `t` (Q.30, [0, 1]), in Q.30 (they sum to
    /// 2^30 up to the rounding of the halving; each within [-0.15, 1]: `i32`, so that the
    /// products below are single `SMULL`/`SMLAL`s).
    #[inline]
    fn weights(t: i64) -> [i32; 4] {
        let t2 = (t * t) >> 30;
        let t3 = (t2 * t) >> 30;
        [
            ((-t3 + 2 * t2 - t) >> 1) as i32,
            ((3 * t3 - 5 * t2 + (2 << 30)) >> 1) as i32,
            ((-3 * t3 + 4 * t2 + t) >> 1) as i32,
            ((t3 - t2) >> 1) as i32,
        ]
    }

    /// sum w_k n_k, Q.30 weights on Q2.30 nodes, rounded to Q2.30 (|sum| < 1.4 * 2^60: no
    /// overflow for nodes below 1.1 in magnitude and Catmull-Rom weights).
    #[inline]
    fn dot(w: &[i32; 4], n: &[i32; 4]) -> i32 {
        let acc = w[0] as i64 * n[0] as i64
            + w[1] as i64 * n[1] as i64
            + w[2] as i64 * n[2] as i64
            + w[3] as i64 * n[3] as i64;
        ((acc + (1 << 29)) >> 30) as i32
    }

    /// Four nodes from `at` (an index the splits keep inside the padded table: a failed
    /// lookup, which cannot happen, reads as zeros rather than panicking).
    #[inline]
    fn four(&self, at: usize) -> [i32; 4] {
        match self.nodes.get(at..at + 4) {
            Some(&[a, b, c, d]) => [a, b, c, d],
            _ => [0; 4],
        }
    }

    /// R at x (Q2.30 in [0, 1)) and y offset `d` (Q8.24 in [0, 16]): the bicubic Catmull-Rom
    /// interpolant, Q2.30. (Dispatched on the size so that every shift and stride is a
    /// constant.)
    fn bicubic(&self, x: i32, d: i32) -> i64 {
        if self.steps_log2 == 5 {
            self.bicubic_k::<5>(x, d)
        } else {
            self.bicubic_k::<6>(x, d)
        }
    }

    fn bicubic_k<const K: u32>(&self, x: i32, d: i32) -> i64 {
        let (i, tx) = Self::split_x::<K>(x);
        let (j, ty) = Self::split_y::<K>(d);
        let (wx, wy) = (Self::weights(tx), Self::weights(ty));
        let stride = (1 << K) + 3;
        // Node (i - 1, j - 1) sits at padded (i, j).
        let base = i * stride + j;
        let rows = [
            Self::dot(&wy, &self.four(base)),
            Self::dot(&wy, &self.four(base + stride)),
            Self::dot(&wy, &self.four(base + 2 * stride)),
            Self::dot(&wy, &self.four(base + 3 * stride)),
        ];
        Self::dot(&wx, &rows) as i64
    }

    /// R along the x node `i` (0..S) at y offset `d` (Q8.24 >= 0): the cubic in y, or beyond
    /// the top edge the extrapolation towards x_i. Q2.30.
    fn column(&self, i: usize, d: i32) -> i64 {
        if self.steps_log2 == 5 {
            self.column_k::<5>(i, d)
        } else {
            self.column_k::<6>(i, d)
        }
    }

    fn column_k<const K: u32>(&self, i: usize, d: i32) -> i64 {
        let top: i32 = 16 << 24;
        let at = (i + 1) * ((1 << K) + 3);
        if d > top {
            let x = (i as i64) << (30 - K);
            let edge = self.nodes.get(at + (1 << K) + 1).map_or(0, |&n| n as i64);
            return x + stiff_decay(edge - x, d - top);
        }
        let (j, ty) = Self::split_y::<K>(d);
        Self::dot(&Self::weights(ty), &self.four(at + j)) as i64
    }
}

/// `excess * e^-(beyond)` for `beyond` >= 0 in Q8.24 (the stiff-side extrapolation).
fn stiff_decay(excess: i64, beyond: i32) -> i64 {
    let decay = Q8_24::from_bits(beyond)
        .exp_neg()
        .map_or(0, |q| q.to_bits() as i64);
    (excess * decay + (1 << 29)) >> 30
}

/// The Dahl steady state of a scene (alpha = 1) evaluated from a [`DahlGrid`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DahlTable {
    grid: &'static DahlGrid,
    /// omega x_a,max in m/s.
    full_scale_velocity: Scaled,
    /// 1 / (omega x_a,max) in s/m.
    inv_full_scale_velocity: Scaled,
    /// k_t x_a,max / mu in N: kappa x_a = this * amplitude / W.
    kxa_per_load: Scaled,
    /// k_t / (mu omega) in N s/m: tau = kappa |v| / omega = this * |v| / W.
    tau_per_load: Scaled,
}

fn domain(input: &'static str, reason: &'static str) -> ModelError {
    ModelError::OutOfDomain { input, reason }
}

impl DahlTable {
    /// The table model of a scene's Dahl parameters (f64, scene load) on `grid`. Errors as
    /// [`super::dahl::DahlConstants::new`] for mu, k_t, f and x_a,max; `OutOfDomain` for
    /// alpha != 1 (the committed tables are for alpha = 1; the quadrature points are unused).
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
        let full_scale_velocity = crate::model::scaled_from_f64(omega * x_a, "x_a")?;
        Ok(Self {
            grid,
            full_scale_velocity,
            inv_full_scale_velocity: wide::recip(full_scale_velocity),
            kxa_per_load: crate::model::scaled_from_f64(k_t * x_a / mu, "k_t")?,
            tau_per_load: crate::model::scaled_from_f64(k_t / (mu * omega), "k_t")?,
        })
    }

    /// The grid (table size).
    pub fn grid(&self) -> &'static DahlGrid {
        self.grid
    }

    fn inv_load(point: &OperatingPoint) -> Result<Scaled, ModelError> {
        wide::from_q(point.normal_force)
            .map(wide::recip)
            .ok_or(domain("W", "must be > 0 (F_c = mu W)"))
    }

    /// R at x = mu_i(zeta) (Q2.30 in [0, 1)) and y = ln(kappa x_a) (Q8.24), Q2.30 in [0, 1].
    /// Error `OutOfDomain` for y below the table.
    pub fn ratio_at(&self, x: Q2_30, ln_kxa: Q8_24) -> Result<Q2_30, ModelError> {
        let x = x.to_bits();
        if x >= 1 << 30 {
            return Ok(Q2_30::ONE);
        }
        let d = ln_kxa.to_bits() as i64 - ((LN_KXA_MIN as i64) << 24);
        if d < 0 {
            return Err(domain("kappa x_a", "below the Dahl table (e^-8)"));
        }
        let top = 16i64 << 24;
        let r = if d > top {
            let edge = self.grid.bicubic(x, top as i32);
            x as i64 + stiff_decay(edge - x as i64, (d - top) as i32)
        } else {
            self.grid.bicubic(x, d as i32)
        };
        Ok(Q2_30::from_bits(r.clamp(0, 1 << 30) as i32))
    }
}

/// ln of a positive `Scaled` in Q8.24; `None` when |ln| >= 128 (kappa x_a or tau beyond
/// e^+-128), with the sign of the logarithm.
fn ln_q24(a: Scaled) -> Result<Q8_24, bool> {
    wide::ln::<24>(a).map_err(|_| a.exp2 > 0)
}

impl FrictionModel for DahlTable {
    /// `kappa x_a = k_t x_a / (mu W)`: the load enters only through `mu W`.
    fn load_enters_as_coulomb_force(&self) -> bool {
        true
    }

    /// F'/F at the operating point (W Q16.16 > 0, v Q8.24) and `amplitude` (Q1.31 in [0, 1)):
    /// zeta and kappa x_a as the exact model forms them, x = mu_i(zeta), y = ln(kappa x_a), then
    /// the bicubic table. Exactly 1 without reversal (|zeta| >= 1 or no vibration), 0 at v = 0.
    /// Errors: W <= 0, amplitude < 0, v = 0 without vibration, kappa x_a below e^-8.
    fn ratio(&self, point: &OperatingPoint, amplitude: Q1_31) -> Result<Q2_30, ModelError> {
        if amplitude.is_negative() {
            return Err(domain("amplitude", "must be >= 0"));
        }
        let inv_load = Self::inv_load(point)?;
        let scale = wide::from_q(amplitude);
        let v_a = scale.map(|a| wide::mul(a, self.full_scale_velocity));
        let zeta = velocity_ratio(point.sliding_velocity, v_a)?;
        let (VelocityRatio::Finite { .. }, Some(a)) = (zeta, scale) else {
            return Ok(if zeta == VelocityRatio::Zero {
                Q2_30::ZERO
            } else {
                Q2_30::ONE
            });
        };
        let x = zeta.mu_i()?;
        let x = Q2_30::from_bits(x.to_bits().abs());
        if x >= Q2_30::ONE {
            return Ok(Q2_30::ONE);
        }
        let kxa = wide::mul(a, wide::mul(self.kxa_per_load, inv_load));
        match ln_q24(kxa) {
            Ok(y) => self.ratio_at(x, y),
            Err(true) => Ok(x), // kappa x_a > e^128: the Coulomb limit, exactly in Q2.30
            Err(false) => Err(domain("kappa x_a", "below the Dahl table (e^-8)")),
        }
    }

    /// The amplitude for `target` (Q2.30) at the operating point. At a fixed operating point
    /// tau = zeta kappa x_a = kappa |v| / omega does not depend on the amplitude, so the
    /// amplitudes trace the curve y = ln tau - ln sin(pi x / 2) through the table; R rises
    /// along it with x. The inverse evaluates the curve at the x nodes (a cubic in y per node),
    /// bisects the nodes for the target's cell, solves the Catmull-Rom cubic through four curve
    /// values there (a secant start and two Newton steps, 32-bit divisions), and turns x into
    /// the amplitude zeta_fs / sin(pi x / 2). The returned ratio is the curve's value at the
    /// solution (it differs from [`Self::ratio`] there by the interpolation error only).
    /// Errors: W <= 0, v = 0 (the ratio is 0 at every amplitude: undefined), tau below the
    /// table.
    fn invert(&self, point: &OperatingPoint, target: Q2_30) -> Result<Inversion, ModelError> {
        let Some(speed) = wide::from_q(point.sliding_velocity.saturating_abs().value) else {
            return Err(domain(
                "v",
                "no sliding: the friction ratio is undefined without vibration",
            ));
        };
        if target >= Q2_30::ONE {
            return Ok(Inversion {
                amplitude: Q1_31::ZERO,
                ratio: Q2_30::ONE,
                reach: Reach::AboveNatural,
            });
        }
        let inv_load = Self::inv_load(point)?;
        let full = || {
            Ok(Inversion {
                amplitude: Q1_31::MAX,
                ratio: self.ratio(point, Q1_31::MAX)?,
                reach: Reach::BelowMinimum,
            })
        };
        let zeta_fs = wide::mul(speed, self.inv_full_scale_velocity);
        if wide::at_least_one(zeta_fs) {
            return full(); // no reversal at any amplitude: R = 1
        }
        let x_fs = VelocityRatio::Finite {
            negative: false,
            magnitude: zeta_fs,
        }
        .mu_i()?
        .to_bits();
        let tau = wide::mul(speed, wide::mul(self.tau_per_load, inv_load));
        let ln_tau = match ln_q24(tau) {
            Ok(y) => y.to_bits() as i64,
            Err(true) => i64::MAX / 4, // beyond e^128: every node on the stiff side
            Err(false) => return Err(domain("kappa |v| / omega", "below the Dahl table (e^-8)")),
        };
        let grid = self.grid;
        let last = grid.side - 1;
        let min_d = (LN_KXA_MIN as i64) << 24;
        // R along the curve at x node i (0 < i < S - 1; 0 at x = 0, 1 at x = 1), or `BELOW`
        // where the curve leaves the table's soft end.
        const BELOW: i64 = i64::MIN;
        let curve = |i: usize| -> i64 {
            if i == 0 {
                return 0;
            }
            if i >= last {
                return 1 << 30;
            }
            let g = grid.ln_sin.get(i).map_or(0, |&g| g as i64);
            let d = ln_tau - g - min_d;
            if d < 0 {
                return BELOW;
            }
            grid.column(i, d.min(i32::MAX as i64) as i32)
        };
        let below = || domain("kappa x_a", "below the Dahl table (e^-8)");
        let t = target.to_bits() as i64;
        // Cell of x_fs, then bisection for the last node at or below the target (the curve
        // rises with x; a node past the soft end has every later node past it too).
        let mut lo = (x_fs >> (30 - grid.steps_log2)) as usize;
        let start = curve(lo);
        if start == BELOW {
            return Err(below());
        }
        if start > t {
            return full();
        }
        let mut hi = last; // curve(last) = 1 > target
        let (mut c1, mut c2) = (start, 1 << 30);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            let c = curve(mid);
            if c == BELOW {
                return Err(below());
            }
            if c <= t {
                (lo, c1) = (mid, c);
            } else {
                (hi, c2) = (mid, c);
            }
        }
        let c0 = if lo == 0 { 2 * c1 - c2 } else { curve(lo - 1) };
        let c3 = if hi == last {
            2 * c2 - c1
        } else {
            curve(hi + 1)
        };
        if c0 == BELOW || c3 == BELOW {
            return Err(below());
        }
        // Catmull-Rom through c0..c3 on [c1, c2]: p(s) = a0 + a1 s + a2 s^2 + a3 s^3 (Q.30).
        let a1 = (c2 - c0) / 2;
        let a2 = (2 * c0 - 5 * c1 + 4 * c2 - c3) / 2;
        let a3 = (-c0 + 3 * c1 - 3 * c2 + c3) / 2;
        let mut s = quotient_q16(t - c1, c2 - c1); // secant start, Q.16 in [0, 1]
        for _ in 0..NEWTON_STEPS {
            let s30 = (s as i64) << 14;
            let s2 = (s30 * s30) >> 30;
            let p = c1 + ((a1 * s30) >> 30) + ((a2 * s2) >> 30) + ((((a3 * s2) >> 30) * s30) >> 30);
            let dp = a1 + ((2 * a2 * s30) >> 30) + ((3 * a3 * s2) >> 30);
            if dp <= 0 {
                break;
            }
            s = (s - quotient_q16(p - t, dp)).clamp(0, 1 << 16);
        }
        let x = (((lo as i64) << 16) + s as i64) << (14 - grid.steps_log2);
        if x < x_fs as i64 {
            return full();
        }
        let ratio = {
            let s30 = (s as i64) << 14;
            let s2 = (s30 * s30) >> 30;
            c1 + ((a1 * s30) >> 30) + ((a2 * s2) >> 30) + ((((a3 * s2) >> 30) * s30) >> 30)
        };
        // zeta = sin(pi x / 2): a phase of x / 4 of a turn, x in Q.30 = x * 2^30 of 2^32.
        let zeta = sin(x.min((1 << 30) - 1) as u32);
        let amplitude = match wide::from_q(zeta) {
            Some(z) => wide::to_q::<31>(wide::mul(zeta_fs, wide::recip(z))),
            None => return full(),
        };
        if amplitude.saturated {
            return full();
        }
        Ok(Inversion {
            amplitude: amplitude.value,
            ratio: Q2_30::from_bits(ratio.clamp(0, 1 << 30) as i32),
            reach: Reach::Reached,
        })
    }
}

/// Newton steps on the curve's cubic after the secant start (the second matters only in the
/// steep last cells of a stiff contact, where the first leaves up to 4e-5 of the ratio).
const NEWTON_STEPS: u32 = 2;

/// num / den in Q.16 for 0 < den < 2^31 and |num| <= 2 den (clamped to [-2, 2] otherwise),
/// with one 32-bit division (13 significant bits of the divisor: the Newton step that follows
/// squares the error).
fn quotient_q16(num: i64, den: i64) -> i32 {
    if den <= 0 {
        return 0;
    }
    let num = num.clamp(-2 * den, 2 * den);
    let shift = den.leading_zeros() as i64 - 33; // den << shift in [2^30, 2^31)
    let (n, d) = if shift >= 0 {
        (num << shift, den << shift)
    } else {
        (num >> -shift, den >> -shift)
    };
    ((n >> 2) as i32) / ((d >> 18) as i32)
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

    /// The generated ln sin(pi x_i / 2) column holds, at every x node x_i = i / (S - 1) but
    /// the unused first, the correctly rounded Q8.24 value (within half an ulp of libm's f64;
    /// values from ln sin(pi / 128) = -3.7 at the 65-node grid's first node up to 0 at x = 1).
    #[test]
    fn ln_sin_columns_are_their_formula_rounded() {
        for grid in [&GRID_33, &GRID_65] {
            let s = grid.side;
            assert_eq!(grid.ln_sin.len(), s);
            assert_eq!(grid.ln_sin[0], i32::MIN);
            for (i, &bits) in grid.ln_sin.iter().enumerate().skip(1) {
                let x = i as f64 / (s - 1) as f64;
                let want = libm::log(libm::sin(core::f64::consts::FRAC_PI_2 * x)) * 16_777_216.0;
                assert!(
                    (f64::from(bits) - want).abs() <= 0.5 + 1e-6,
                    "{s} nodes, x_{i}: {bits} vs {want}"
                );
            }
        }
    }

    #[test]
    fn interpolation_reproduces_the_nodes_and_the_limits() {
        for grid in [&GRID_33, &GRID_65] {
            let s = grid.side;
            for i in 0..s - 1 {
                for j in 0..s {
                    let x = ((i as i64) << (30 - grid.steps_log2)) as i32;
                    let d = ((j as i64) << (24 + SPAN_LOG2 - grid.steps_log2)) as i32;
                    let node = grid.nodes[(i + 1) * grid.stride() + j + 1] as i64;
                    assert!((grid.bicubic(x, d) - node).abs() <= 1, "{s}: ({i}, {j})");
                    assert!(
                        (grid.column(i, d) - node).abs() <= 1,
                        "{s}: column ({i}, {j})"
                    );
                }
            }
            // x = 0 gives 0 at every kappa x_a; x = 1 gives 1.
            let t = DahlTable::new(
                &DahlParams {
                    friction_coefficient: 1.0,
                    tangential_stiffness: 1.0,
                    frequency_hz: 1.0,
                    full_scale_amplitude_m: 1.0,
                    shape_exponent: 1.0,
                    quadrature_points: 4,
                },
                grid,
            )
            .unwrap();
            for y in [-8.0, -3.3, 0.0, 7.9, 8.0, 12.0, 100.0] {
                let y = Q8_24::from_f64(y).unwrap();
                assert!(t.ratio_at(Q2_30::ZERO, y).unwrap().to_bits().abs() <= 2);
                assert_eq!(t.ratio_at(Q2_30::ONE, y), Ok(Q2_30::ONE));
            }
            let below = Q8_24::from_f64(-8.01).unwrap();
            assert!(t.ratio_at(Q2_30::from_f64(0.5).unwrap(), below).is_err());
        }
    }

    #[test]
    fn ratio_is_monotone_in_amplitude_and_the_inverse_returns_to_it() {
        for (k_t, grid) in [
            (5.6e4, &GRID_33),
            (5.6e4, &GRID_65),
            (2.5e7, &GRID_65),
            (1e10, &GRID_65),
        ] {
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
        let m = seed_003(5.6e4, &GRID_65);
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
        assert!(DahlTable::new(&other, &GRID_33).is_err());
        assert!(DahlGrid::of_side(17).is_none());
    }
}
