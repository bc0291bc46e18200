//! The cube model tabulated once per scene and interpolated per step: the classic DSP trade of
//! a precomputed table for the exact evaluation (issue 7, the table-size knob).
//!
//! **What is tabulated.** F'/F of the exact fixed-point [`CubeModel`] (the scene's own
//! quadrature, elastic or elastic-plastic contact) on a `side` x `side` grid of nodes:
//! - rows: ln(F_n / 1 N) (Q6.26), evenly spaced over the scene's `contents.load_range_n`
//!   widened by [`LN_LOAD_MARGIN`] (1/8 in ln F_n, a factor e^(1/8) = 1.133) on each side, so
//!   that sensor noise and calibration error around the stated range stay in the table. The
//!   cube ratio depends on the load through d = (R_q / lambda) ln(K_F / F_n) only
//!   (physics-notes §3-4), a smooth function of ln F_n: this axis keeps the interpolation error
//!   even over the range. The cube ratio does not depend on the sliding velocity
//!   ([`super::cube_model`] docs): no velocity axis.
//! - columns: the amplitude fraction a = k / (side - 1), k = 0..side-1, over [0, 1] (Q2.30,
//!   the exact model's own amplitude format; a = 1 is `Q1_31::MAX` rounded to Q2.30).
//!
//! Node values are Q2.30 `i32` (F'/F in (0, 1] at the node, the only configuration tabulated:
//! see below), row-major, in a fixed-capacity array of [`MAX_NODES`] (17 x 17, 1,156 bytes)
//! whatever the knob: `crate::model::AnyModel` holds one model by value (no heap), so its size
//! is that of its largest variant anyway. 33 x 33 (4,356 bytes) was tried and dropped: it made
//! every `AnyModel` (the plant's and the controller's) 5.4 KB and a `sonolube_sim::ClosedLoop` 18 KB,
//! and the QEMU benchmark build, which builds closed loops on its stack, ended in a watchdog
//! reset; its error (1.1e-4 against the exact model on 40-240 N) is not needed by any scene's
//! budget, and 17 x 17 already gives 4.2e-4.
//!
//! **Built from the exact fixed-point model**, not from `f64`: it is what the firmware can
//! build at scene start (no software `f64` quadrature on the Cortex-M4), and host and firmware
//! build bit-identical tables. Cost: side rows x (one `prepare` + side evaluations), about
//! side^2 x 1,230 Cortex-M4 instructions at N = 16 (measured per table size by the QEMU
//! benchmark build, `docs/speed.md`, "Table builds").
//!
//! **Evaluation** ([`FrictionModel::ratio`]): ln F_n (the exact model's own first step), the
//! load cell and fraction (one integer division by the row step, a multiply by its
//! reciprocal), the amplitude cell and fraction (shifts: side - 1 is a power of two), then
//! bilinear interpolation in `i64`: along the load for the two bracketing columns, then along
//! the amplitude. At a node the result is the node exactly. At fixed load it is piecewise
//! linear and non-increasing in the amplitude (rows are checked non-increasing at build).
//!
//! **Inversion** ([`FrictionModel::invert`]): the same load interpolation on every column gives
//! the row at this load; a binary search over the (non-increasing) row finds the segment, and
//! the linear segment is solved exactly (one 64-bit division). The amplitude is within 2^-30 of
//! the inverse of the interpolant, and the returned ratio is [`FrictionModel::ratio`] at the
//! returned amplitude, within 2^-24 of the target when reached.
//!
//! **Outside the tabulated load range** (below lo e^-1/8 or above hi e^1/8) the table is not
//! used: ratio and invert fall back to the exact model it was built from, which the table keeps
//! ([`CubeTable::exact`]). The result is then exact but costs an exact evaluation; nothing is
//! clamped. [`CubeTable::covers`] tells which path a load takes.
//!
//! **From flash alone** ([`CubeTable::from_flash`]): a compiled scene's nodes and its contact
//! kind, without the exact model. A firmware whose every cube scene is compiled in needs no
//! more (the cargo feature `cube-exact` off on a bare-metal target: no `f64` contact setup at
//! scene start, no exact evaluation in flash); a load outside the tabulated range is then an
//! error (`OutOfDomain` on "normal force"), never a clamp. On a host (tools, tests, the build
//! script that computes the nodes) the exact model is always compiled.
//!
//! Scenes whose u-term can act (off the node with an in-phase u, or the literal window) are
//! refused at build: F'/F is not monotone in the amplitude there, and the inversion needs it.

use crate::fx::{Q1_31, Q2_30, Q6_26, Q16_16};

use super::contact::{ContactKind, ln_load, ln_load_from_si};
#[cfg(any(feature = "cube-exact", not(target_os = "none")))]
use super::cube_model::CubeModel;
use super::fx_error;
use super::{FrictionModel, Inversion, ModelError, OperatingPoint, Reach};

/// Largest side of a table: 17 nodes per axis (see the module docs for 33).
pub const MAX_SIDE: usize = 17;
/// Node capacity of every table, [`MAX_SIDE`]^2.
pub const MAX_NODES: usize = MAX_SIDE * MAX_SIDE;
/// Widening of the load axis beyond the scene's load range on each side, in ln(F_n / 1 N),
/// Q6.26 bits: 1/8 (a factor e^(1/8) = 1.133 on the load).
pub const LN_LOAD_MARGIN: i32 = 1 << 23;

/// A load outside the range of a table that has no exact model to fall back to.
const OUTSIDE_FLASH_TABLE: ModelError = ModelError::OutOfDomain {
    input: "normal force",
    reason: "outside the cube table's load range, and this table has no exact model (a table from flash; cargo feature `cube-exact`)",
};

const ONE_Q30: i64 = 1 << 30;
const ONE_Q31: i64 = 1 << 31;

/// The cube model tabulated over (ln load, amplitude) for one scene; see the module docs.
#[derive(Debug, Clone, PartialEq)]
pub struct CubeTable {
    /// The exact model the nodes come from; used outside the tabulated load range (`None`: a
    /// table from flash alone, [`CubeTable::from_flash`]).
    #[cfg(any(feature = "cube-exact", not(target_os = "none")))]
    exact: Option<CubeModel>,
    /// The contact model the nodes were computed with.
    contact_kind: ContactKind,
    /// Nodes per axis: 2^k + 1, 3..=17.
    side: u8,
    /// k = log2(side - 1), 1..=4.
    log2_cells: u8,
    /// ln F_n of the first row, Q6.26 bits.
    ln_load_low: i32,
    /// Row spacing in ln F_n, Q6.26 bits, > 0; the last row is at low + (side - 1) step.
    ln_load_step: i32,
    /// 2^(30 + b) / step rounded, b = the bit length of step (so in (2^30, 2^31]): (remainder x
    /// this) >> (b - 1) is the Q.31 fraction of a row step (a 32 x 32 -> 64-bit multiply).
    ln_load_reciprocal: u32,
    /// b - 1 (>= 20: step >= 1/4 / 16 in Q6.26), the shift that goes with `ln_load_reciprocal`.
    ln_load_shift: u8,
    /// F'/F at the nodes, Q2.30, row r (load) column c (amplitude) at r * side + c; the rest 0.
    nodes: [i32; MAX_NODES],
}

/// Where a value falls on an axis: the cell (index of its lower node, <= side - 2) and the
/// fraction of the cell (Q.31 for the load, Q.30 for the amplitude; the cell's end included).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Cell {
    index: usize,
    fraction: i64,
}

impl CubeTable {
    /// Tabulates `exact` over `load_range_n` (N, lo <= hi, as a scene's `contents`) with
    /// `side` nodes per axis (3, 5, 9 or 17). Errors: a side not of the form 2^k + 1 in
    /// 3..=17; a load range that is not finite and positive or whose widened ln bounds leave
    /// Q6.26 ([-32, 32)); the exact model's errors at a node; an active u-term or a row that
    /// is not non-increasing in the amplitude.
    #[cfg(any(feature = "cube-exact", not(target_os = "none")))]
    pub fn new(
        exact: CubeModel,
        load_range_n: (f64, f64),
        side: usize,
    ) -> Result<Self, ModelError> {
        let mut table = Self::layout(&exact, load_range_n, side)?;
        for row in 0..side {
            let ln = Q6_26::from_bits(table.ln_load_low + row as i32 * table.ln_load_step);
            let point = exact.scene().prepare(ln)?;
            for column in 0..side {
                let ratio = exact.ratio_prepared(&point, table.node_amplitude(column))?;
                table.nodes[row * side + column] = ratio.to_bits();
            }
        }
        table.check_rows()?;
        table.exact = Some(exact);
        Ok(table)
    }

    /// The table [`Self::new`] builds, with the nodes it computed given instead (`side`^2 Q2.30
    /// bits, row-major, as [`Self::nodes`] returns them): the build script computes them once
    /// per compiled scene into flash (`build.rs`, `crate::scene::builtin::cube_table_nodes`),
    /// and scene start copies them (about 300 instructions instead of 316,120 for 17 x 17).
    /// Errors: those of [`Self::new`] but the nodes' evaluation, and a node count that is not
    /// `side`^2.
    #[cfg(any(feature = "cube-exact", not(target_os = "none")))]
    pub fn with_nodes(
        exact: CubeModel,
        load_range_n: (f64, f64),
        side: usize,
        nodes: &[i32],
    ) -> Result<Self, ModelError> {
        let mut table = Self::layout(&exact, load_range_n, side)?.filled(nodes)?;
        table.exact = Some(exact);
        Ok(table)
    }

    /// The table of a compiled scene from its nodes in flash alone (as [`Self::with_nodes`],
    /// without the exact model): a load outside the tabulated range is an `OutOfDomain` error
    /// instead of an exact evaluation. The nodes' u-term and window checks were made when the
    /// build script computed them. Errors: those of [`Self::with_nodes`].
    pub fn from_flash(
        contact_kind: ContactKind,
        load_range_n: (f64, f64),
        side: usize,
        nodes: &[i32],
    ) -> Result<Self, ModelError> {
        Self::axes(contact_kind, load_range_n, side)?.filled(nodes)
    }

    /// This table with `nodes` (`side`^2 of them) copied in and its rows checked.
    fn filled(mut self, nodes: &[i32]) -> Result<Self, ModelError> {
        let side = self.side();
        let count = side * side;
        if nodes.len() != count {
            return Err(ModelError::OutOfDomain {
                input: "table nodes",
                reason: "a table of side S holds S x S nodes",
            });
        }
        self.nodes[..count].copy_from_slice(nodes);
        self.check_rows()?;
        Ok(self)
    }

    /// The nodes in use, Q2.30 bits, row-major (`side`^2 of them).
    pub fn nodes(&self) -> &[i32] {
        &self.nodes[..self.side() * self.side()]
    }

    /// The table of `side` nodes per axis over `load_range_n` with every node 0 and no exact
    /// model yet: the checks and the load axis of [`Self::new`].
    #[cfg(any(feature = "cube-exact", not(target_os = "none")))]
    fn layout(
        exact: &CubeModel,
        load_range_n: (f64, f64),
        side: usize,
    ) -> Result<Self, ModelError> {
        Self::check_side(side)?;
        if exact.scene().has_u_term()
            || exact.scene().quadrature().window() != super::quadrature::SlipWindow::SurfacesApart
        {
            return Err(ModelError::OutOfDomain {
                input: "x",
                reason: "a table needs F'/F monotone in the amplitude: contact at the node, surfaces-apart window",
            });
        }
        Self::axes(exact.scene().contact().scene().kind, load_range_n, side)
    }

    /// Nodes per axis must be 2^k + 1 in 3..=17.
    fn check_side(side: usize) -> Result<(), ModelError> {
        if !(3..=MAX_SIDE).contains(&side) || !(side - 1).is_power_of_two() {
            return Err(ModelError::OutOfDomain {
                input: "table side",
                reason: "nodes per axis must be 3, 5, 9 or 17",
            });
        }
        Ok(())
    }

    /// The axes of a table of `side` nodes per axis over `load_range_n`, every node 0.
    fn axes(
        contact_kind: ContactKind,
        load_range_n: (f64, f64),
        side: usize,
    ) -> Result<Self, ModelError> {
        Self::check_side(side)?;
        let (lo, hi) = load_range_n;
        if lo > hi {
            return Err(ModelError::OutOfDomain {
                input: "load range",
                reason: "the lower load must not exceed the upper one",
            });
        }
        let low = ln_load_from_si(lo)?.to_bits() as i64 - LN_LOAD_MARGIN as i64;
        let high = ln_load_from_si(hi)?.to_bits() as i64 + LN_LOAD_MARGIN as i64;
        let cells = (side - 1) as i64;
        // Round the span up to whole steps so every row sits on an exact Q6.26 value.
        let step = (high - low + cells - 1) / cells;
        let out_of_range = || ModelError::OutOfDomain {
            input: "load range",
            reason: "ln F_n of the widened range must lie in [-32, 32)",
        };
        let ln_load_low = i32::try_from(low).map_err(|_| out_of_range())?;
        i32::try_from(low + cells * step).map_err(|_| out_of_range())?;
        let ln_load_step = i32::try_from(step).map_err(|_| out_of_range())?; // > 0: span >= 1/4
        let bits = 32 - (step as u32).leading_zeros();
        let reciprocal = ((1u64 << (30 + bits)) + step as u64 / 2) / step as u64; // <= 2^31
        Ok(Self {
            #[cfg(any(feature = "cube-exact", not(target_os = "none")))]
            exact: None,
            contact_kind,
            side: side as u8,
            log2_cells: (side - 1).trailing_zeros() as u8,
            ln_load_low,
            ln_load_step,
            ln_load_reciprocal: reciprocal as u32,
            ln_load_shift: (bits - 1) as u8,
            nodes: [0; MAX_NODES],
        })
    }

    /// Every row non-increasing in the amplitude (the inversion's binary search needs it).
    fn check_rows(&self) -> Result<(), ModelError> {
        let side = self.side();
        for row in self.nodes[..side * side].chunks_exact(side) {
            if row.windows(2).any(|pair| pair[1] > pair[0]) {
                return Err(ModelError::OutOfDomain {
                    input: "x",
                    reason: "F'/F rises with the amplitude: not tabulable",
                });
            }
        }
        Ok(())
    }

    /// The exact model the table was built from (and falls back to); `None` for a table from
    /// flash alone ([`Self::from_flash`]).
    #[cfg(any(feature = "cube-exact", not(target_os = "none")))]
    pub fn exact(&self) -> Option<&CubeModel> {
        self.exact.as_ref()
    }

    /// The contact model of the nodes (elastic or elastic-plastic).
    pub fn contact_kind(&self) -> ContactKind {
        self.contact_kind
    }

    /// F'/F outside the tabulated load range: the exact model's, or an error for a table
    /// without one.
    #[cfg(any(feature = "cube-exact", not(target_os = "none")))]
    fn ratio_outside(&self, point: &OperatingPoint, amplitude: Q1_31) -> Result<Q2_30, ModelError> {
        self.exact
            .as_ref()
            .ok_or(OUTSIDE_FLASH_TABLE)?
            .ratio(point, amplitude)
    }

    /// F'/F outside the tabulated load range: without the exact model in the build, an error.
    #[cfg(not(any(feature = "cube-exact", not(target_os = "none"))))]
    fn ratio_outside(&self, _: &OperatingPoint, _: Q1_31) -> Result<Q2_30, ModelError> {
        Err(OUTSIDE_FLASH_TABLE)
    }

    /// The inversion outside the tabulated load range: the exact model's, or an error for a
    /// table without one.
    #[cfg(any(feature = "cube-exact", not(target_os = "none")))]
    fn invert_outside(
        &self,
        point: &OperatingPoint,
        target: Q2_30,
        start: Q1_31,
    ) -> Result<Inversion, ModelError> {
        self.exact
            .as_ref()
            .ok_or(OUTSIDE_FLASH_TABLE)?
            .invert_from(point, target, start)
    }

    /// The inversion outside the tabulated load range: without the exact model, an error.
    #[cfg(not(any(feature = "cube-exact", not(target_os = "none"))))]
    fn invert_outside(
        &self,
        _: &OperatingPoint,
        _: Q2_30,
        _: Q1_31,
    ) -> Result<Inversion, ModelError> {
        Err(OUTSIDE_FLASH_TABLE)
    }

    /// Nodes per axis.
    pub fn side(&self) -> usize {
        self.side as usize
    }

    /// The amplitude of column `column` (Q1.31 fraction of full scale; the last is `MAX`).
    pub fn node_amplitude(&self, column: usize) -> Q1_31 {
        if column + 1 >= self.side() {
            Q1_31::MAX
        } else {
            Q1_31::from_bits((column as i32) << (31 - self.log2_cells))
        }
    }

    /// The load of row `row` (N, f64, for tests and reports): e^(ln of the row).
    pub fn node_load_n(&self, row: usize) -> f64 {
        let ln = self.ln_load_low as i64 + row as i64 * self.ln_load_step as i64;
        libm::exp(ln as f64 / (1u64 << 26) as f64)
    }

    /// The node value at (`row`, `column`), F'/F in Q2.30; `None` outside the table.
    pub fn node(&self, row: usize, column: usize) -> Option<Q2_30> {
        (row < self.side() && column < self.side())
            .then(|| Q2_30::from_bits(self.nodes[row * self.side() + column]))
    }

    /// The tabulated range of ln(F_n / 1 N), Q6.26: [first row, last row].
    pub fn ln_load_range(&self) -> (Q6_26, Q6_26) {
        let last = self.ln_load_low + (self.side() as i32 - 1) * self.ln_load_step;
        (Q6_26::from_bits(self.ln_load_low), Q6_26::from_bits(last))
    }

    /// Whether `normal_force` is inside the tabulated range (else the exact model runs).
    /// Error: F_n <= 0.
    pub fn covers(&self, normal_force: Q16_16) -> Result<bool, ModelError> {
        Ok(self.load_cell(ln_load(normal_force)?).is_some())
    }

    /// The load cell of `ln_load`, `None` outside the tabulated range.
    fn load_cell(&self, ln_load: Q6_26) -> Option<Cell> {
        let offset = ln_load.to_bits() as i64 - self.ln_load_low as i64;
        let step = self.ln_load_step as u32;
        let last = self.side() as u32 - 1;
        if offset < 0 || offset > i64::from(last * step) {
            return None;
        }
        // 0 <= offset <= (side - 1) step < 2^31: one UDIV on the target.
        let offset = offset as u32;
        let index = offset / step;
        if index == last {
            return Some(Cell {
                index: last as usize - 1,
                fraction: ONE_Q31,
            });
        }
        let remainder = u64::from(offset - index * step); // < step
        let shift = self.ln_load_shift;
        let fraction =
            (remainder * u64::from(self.ln_load_reciprocal) + (1 << (shift - 1))) >> shift;
        Some(Cell {
            index: index as usize,
            fraction: fraction as i64,
        })
    }

    /// The amplitude cell of `amplitude` (Q2.30 in [0, 1]).
    fn amplitude_cell(&self, amplitude: i64) -> Cell {
        let shift = 30 - self.log2_cells as u32;
        let index = (amplitude >> shift) as usize;
        if index + 1 >= self.side() {
            return Cell {
                index: self.side() - 2,
                fraction: ONE_Q30,
            };
        }
        Cell {
            index,
            fraction: (amplitude << self.log2_cells) & (ONE_Q30 - 1),
        }
    }

    /// The column `column` interpolated at the load cell `load`, Q2.30 bits.
    fn column_at(&self, load: Cell, column: usize) -> i64 {
        let below = self.nodes[load.index * self.side() + column] as i64;
        let above = self.nodes[(load.index + 1) * self.side() + column] as i64;
        // |above - below| < 2^31 and fraction <= 2^31: the product fits i64.
        below + (((above - below) * load.fraction + (1 << 30)) >> 31)
    }

    /// F'/F at a load cell and amplitude (Q2.30 bits in [0, 1]), Q2.30 bits.
    fn interpolate(&self, load: Cell, amplitude: i64) -> i64 {
        let cell = self.amplitude_cell(amplitude);
        let left = self.column_at(load, cell.index);
        let right = self.column_at(load, cell.index + 1);
        left + (((right - left) * cell.fraction + (1 << 29)) >> 30)
    }
}

/// Q2.30 bits of an interpolated F'/F: a convex combination of node values in (0, 1], so it
/// fits; checked all the same (never wraps).
fn ratio_of(bits: i64) -> Result<Q2_30, ModelError> {
    i32::try_from(bits)
        .map(Q2_30::from_bits)
        .map_err(|_| ModelError::Overflow {
            quantity: "interpolated F'/F",
        })
}

impl FrictionModel for CubeTable {
    /// F'/F (Q2.30) at `amplitude` (Q1.31 fraction of full scale, rounded to Q2.30 as the exact
    /// model does), bilinear in (ln F_n, a) inside the tabulated load range, the exact model
    /// outside it. Errors: F_n <= 0; outside the range, the exact model's.
    fn ratio(&self, point: &OperatingPoint, amplitude: Q1_31) -> Result<Q2_30, ModelError> {
        let ln = ln_load(point.normal_force)?;
        let Some(load) = self.load_cell(ln) else {
            return self.ratio_outside(point, amplitude);
        };
        let a = amplitude.convert::<30>().map_err(fx_error("amplitude"))?;
        if a.to_bits() < 0 {
            return Err(ModelError::OutOfDomain {
                input: "amplitude",
                reason: "the amplitude fraction must be >= 0",
            });
        }
        ratio_of(self.interpolate(load, a.to_bits() as i64))
    }

    /// The amplitude whose interpolated F'/F is `target` at this load (see the module docs);
    /// the exact model's inversion outside the tabulated load range.
    fn invert(&self, point: &OperatingPoint, target: Q2_30) -> Result<Inversion, ModelError> {
        self.invert_from(point, target, Q1_31::ZERO)
    }

    /// [`Self::invert`]; the hint `start` serves the exact model's warm-started Newton iteration
    /// outside the tabulated range only (the table's search is direct: no iteration to start).
    fn invert_from(
        &self,
        point: &OperatingPoint,
        target: Q2_30,
        start: Q1_31,
    ) -> Result<Inversion, ModelError> {
        let ln = ln_load(point.normal_force)?;
        let Some(load) = self.load_cell(ln) else {
            return self.invert_outside(point, target, start);
        };
        let t = target.to_bits() as i64;
        let last = self.side() - 1;
        let natural = self.column_at(load, 0);
        if t >= natural {
            return Ok(Inversion {
                amplitude: Q1_31::ZERO,
                ratio: ratio_of(natural)?,
                reach: Reach::AboveNatural,
            });
        }
        let floor = self.column_at(load, last);
        if t <= floor {
            return Ok(Inversion {
                amplitude: Q1_31::MAX,
                ratio: ratio_of(floor)?,
                reach: Reach::BelowMinimum,
            });
        }
        // Invariant: row(low) > t >= row(high).
        let (mut low, mut high) = (0usize, last);
        while high - low > 1 {
            let middle = (low + high) / 2;
            if self.column_at(load, middle) > t {
                low = middle;
            } else {
                high = middle;
            }
        }
        let (left, right) = (self.column_at(load, low), self.column_at(load, high));
        // Solve left + (right - left) f = t on the segment: f = (left - t) / (left - right),
        // in Q.(30 - k) of the whole amplitude range, rounded up so the ratio is <= t + 1 ulp.
        let shift = 30 - self.log2_cells as u32;
        let drop = (left - right) as u64; // > 0
        let within = (((left - t) as u64) << shift).div_ceil(drop) as i64;
        let a30 = ((low as i64) << shift) + within;
        let amplitude = Q1_31::from_bits((a30 << 1).min(i32::MAX as i64) as i32);
        let a = amplitude.convert::<30>().map_err(fx_error("amplitude"))?;
        let ratio = ratio_of(self.interpolate(load, a.to_bits() as i64))?;
        Ok(Inversion {
            amplitude,
            ratio,
            reach: Reach::Reached,
        })
    }
}

#[cfg(test)]
#[path = "cube_table_tests.rs"]
mod tests;
