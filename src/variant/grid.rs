//! The fixed grids of inputs every variant is measured on: errors on the host, instruction
//! counts in QEMU (the same points, so cost and error describe the same work).
//!
//! - A scene's operating grid ([`SceneGrid`]) covers what its `[contents]` state: loads over
//!   `load_range_n` ([`LOADS`] points, one when the range is a single load), sliding velocities
//!   over `velocity_range_m_per_s` ([`VELOCITIES`] points, likewise), and drive amplitudes
//!   k / [`AMPLITUDES`] for k = 1..=[`AMPLITUDES`] (amplitude 0 gives exactly 1 in every model).
//!   Points are in the controller's input formats: load Q16.16, velocity Q8.24, amplitude Q1.31
//!   (full scale is `Q1_31::MAX`, 1 - 2^-31). Every form gets the same point: the float forms
//!   and the reference its exact value.
//! - The kernels' grids: zeta over [-1, 1] for the Littmann law ([`littmann_inputs`]), and
//!   the Dahl state f over [-1, 1] times travels kappa |dx| over [0, 1.9] in both directions for
//!   the update ([`dahl_update_inputs`]): the domains the kernels serve, which contain every
//!   scene's.

use crate::fx::{Q1_31, Q2_30, Q8_24, Q16_16};
use crate::model::OperatingPoint;
use crate::scene::Scene;

/// Loads per scene when its load range is not a single value.
pub const LOADS: u32 = 5;
/// Sliding velocities per scene when its velocity range is not a single value.
pub const VELOCITIES: u32 = 3;
/// Drive amplitudes per operating point.
pub const AMPLITUDES: u32 = 24;

/// One operating point and amplitude, in the controller's formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GridPoint {
    /// Load (Q16.16 N) and sliding velocity (Q8.24 m/s).
    pub point: OperatingPoint,
    /// Drive amplitude, fraction of full scale, Q1.31 in (0, 1).
    pub amplitude: Q1_31,
}

impl GridPoint {
    /// Load in N (exact).
    pub fn load_n(&self) -> f64 {
        self.point.normal_force.to_f64()
    }

    /// Sliding velocity in m/s (exact).
    pub fn velocity_m_per_s(&self) -> f64 {
        self.point.sliding_velocity.to_f64()
    }

    /// Amplitude, fraction of full scale (exact).
    pub fn amplitude(&self) -> f64 {
        self.amplitude.to_f64()
    }
}

/// The operating grid of one scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneGrid {
    load: (f64, f64),
    velocity: (f64, f64),
    loads: u32,
    velocities: u32,
}

/// `count` values evenly spread over [lo, hi] (`count` >= 1; one value is `lo`).
fn spread(range: (f64, f64), count: u32, index: u32) -> f64 {
    if count <= 1 {
        range.0
    } else {
        range.0 + (range.1 - range.0) * f64::from(index) / f64::from(count - 1)
    }
}

impl SceneGrid {
    /// The grid of `scene`'s contents.
    pub fn new(scene: &Scene<'_>) -> Self {
        let c = &scene.contents;
        let count = |lo: f64, hi: f64, n: u32| if hi > lo { n } else { 1 };
        Self {
            load: (c.load_min_n, c.load_max_n),
            velocity: (c.velocity_min_m_per_s, c.velocity_max_m_per_s),
            loads: count(c.load_min_n, c.load_max_n, LOADS),
            velocities: count(c.velocity_min_m_per_s, c.velocity_max_m_per_s, VELOCITIES),
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        (self.loads * self.velocities * AMPLITUDES) as usize
    }

    /// Whether the grid is empty (never: every range has at least one value).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Point `index` (< [`Self::len`]), amplitude fastest, then velocity, then load; `None`
    /// beyond the end.
    pub fn get(&self, index: usize) -> Option<GridPoint> {
        if index >= self.len() {
            return None;
        }
        let index = index as u32;
        let amplitude = index % AMPLITUDES + 1;
        let velocity = (index / AMPLITUDES) % self.velocities;
        let load = index / (AMPLITUDES * self.velocities);
        let amplitude = if amplitude == AMPLITUDES {
            Q1_31::MAX
        } else {
            Q1_31::from_bits((((amplitude as u64) << 31) / AMPLITUDES as u64) as i32)
        };
        Some(GridPoint {
            point: OperatingPoint {
                normal_force: Q16_16::from_f64_saturating(spread(self.load, self.loads, load))
                    .value,
                sliding_velocity: Q8_24::from_f64_saturating(spread(
                    self.velocity,
                    self.velocities,
                    velocity,
                ))
                .value,
            },
            amplitude,
        })
    }

    /// Point `index`, or the last point beyond the end (for loops that must not fail).
    pub fn at(&self, index: usize) -> GridPoint {
        let last = self.len().saturating_sub(1);
        self.get(index.min(last)).unwrap_or(GridPoint {
            point: OperatingPoint {
                normal_force: Q16_16::ONE,
                sliding_velocity: Q8_24::ZERO,
            },
            amplitude: Q1_31::ZERO,
        })
    }

    /// Every point, in order.
    pub fn points(&self) -> impl Iterator<Item = GridPoint> + '_ {
        (0..self.len()).filter_map(|i| self.get(i))
    }
}

/// Littmann inputs: zeta = k / 1024 for k in -1024..=1024 (Q2.30, exact), then 1 - 2^-j and
/// -(1 - 2^-j) for j = 11..=30, where the slope of asin blows up.
pub const LITTMANN_POINTS: usize = 2049 + 40;

/// Littmann input `index` (< [`LITTMANN_POINTS`]), Q2.30.
pub fn littmann_input(index: usize) -> Q2_30 {
    const ONE: i32 = 1 << 30;
    if index < 2049 {
        Q2_30::from_bits((index as i32 - 1024) << 20)
    } else {
        let j = (index - 2049) / 2 + 11;
        let near = ONE - (ONE >> j);
        Q2_30::from_bits(if index.is_multiple_of(2) { near } else { -near })
    }
}

/// Every Littmann input.
pub fn littmann_inputs() -> impl Iterator<Item = Q2_30> {
    (0..LITTMANN_POINTS).map(littmann_input)
}

/// Dahl update travels kappa |dx|, Q2.30.
pub const DAHL_TRAVELS: [f64; 9] = [0.0, 1e-6, 1e-4, 1e-3, 0.01, 0.1, 0.5, 1.0, 1.9];
/// Dahl update states f = k / 32 - 1, k = 0..=64.
pub const DAHL_STATES: usize = 65;
/// Number of Dahl update inputs: states x travels x both directions.
pub const DAHL_UPDATE_POINTS: usize = DAHL_STATES * DAHL_TRAVELS.len() * 2;

/// A Dahl update input: the state f (Q2.30), the direction (true: forward, s = +1) and the
/// travel (Q2.30).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DahlUpdateInput {
    /// f = F / (mu W), Q2.30 in [-1, 1].
    pub state: Q2_30,
    /// Travel direction, true for v > 0.
    pub forward: bool,
    /// kappa |dx|, Q2.30 in [0, 2).
    pub travel: Q2_30,
}

/// Dahl update input `index` (< [`DAHL_UPDATE_POINTS`]).
pub fn dahl_update_input(index: usize) -> DahlUpdateInput {
    let state = index % DAHL_STATES;
    let rest = index / DAHL_STATES;
    let travel = DAHL_TRAVELS[(rest / 2) % DAHL_TRAVELS.len()];
    DahlUpdateInput {
        state: Q2_30::from_bits((((state as i64) << 25) - (1 << 30)) as i32),
        forward: rest.is_multiple_of(2),
        travel: Q2_30::from_f64_saturating(travel).value,
    }
}

/// Every Dahl update input.
pub fn dahl_update_inputs() -> impl Iterator<Item = DahlUpdateInput> {
    (0..DAHL_UPDATE_POINTS).map(dahl_update_input)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{SCENES, find};

    #[test]
    fn scene_grids_cover_the_stated_ranges() {
        for scene in SCENES {
            let grid = SceneGrid::new(scene);
            let points: std::vec::Vec<GridPoint> = grid.points().collect();
            assert_eq!(points.len(), grid.len());
            assert!(!grid.is_empty());
            let c = &scene.contents;
            let (mut lo, mut hi) = (f64::MAX, f64::MIN);
            for p in &points {
                lo = lo.min(p.load_n());
                hi = hi.max(p.load_n());
                assert!(p.amplitude() > 0.0 && p.amplitude() < 1.0);
                let v = p.velocity_m_per_s();
                assert!(v >= c.velocity_min_m_per_s - 1e-7 && v <= c.velocity_max_m_per_s + 1e-7);
            }
            assert!((lo - c.load_min_n).abs() < 2e-5, "{}", scene.name);
            assert!((hi - c.load_max_n).abs() < 2e-5, "{}", scene.name);
            assert!(grid.get(grid.len()).is_none());
        }
        let ramp = SceneGrid::new(find("load-ramp").unwrap());
        assert_eq!(ramp.len(), (LOADS * AMPLITUDES) as usize);
        let first = ramp.get(0).unwrap();
        assert_eq!(
            first.amplitude.to_bits() as u64,
            (1u64 << 31) / u64::from(AMPLITUDES)
        );
        assert_eq!(
            ramp.get(AMPLITUDES as usize - 1).unwrap().amplitude,
            Q1_31::MAX
        );
        assert_eq!(ramp.get(AMPLITUDES as usize).unwrap().load_n(), 90.0);
        let seatbelt = SceneGrid::new(find("seatbelt").unwrap());
        assert_eq!(seatbelt.len(), (LOADS * VELOCITIES * AMPLITUDES) as usize);
    }

    #[test]
    fn kernel_grids_cover_their_domains() {
        let zetas: std::vec::Vec<f64> = littmann_inputs().map(|z| z.to_f64()).collect();
        assert_eq!(zetas.len(), LITTMANN_POINTS);
        assert_eq!(zetas[0], -1.0);
        assert_eq!(zetas[2048], 1.0);
        assert!(zetas.iter().any(|&z| z > 0.999_999_99 && z < 1.0));
        assert!(zetas.iter().any(|&z| z < -0.999_999_99 && z > -1.0));
        let updates: std::vec::Vec<DahlUpdateInput> = dahl_update_inputs().collect();
        assert_eq!(updates.len(), DAHL_UPDATE_POINTS);
        assert_eq!(updates[0].state.to_f64(), -1.0);
        assert_eq!(updates[DAHL_STATES - 1].state.to_f64(), 1.0);
        assert!(updates.iter().any(|u| !u.forward));
        assert!(
            updates
                .iter()
                .any(|u| (u.travel.to_f64() - 1.9).abs() < 1e-9)
        );
    }
}
