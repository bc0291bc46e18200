//! The plant's Dahl contact integrated in time (physics-notes §2): the state f = F / (mu W) is
//! carried from substep to substep and stepped through every vibration period with the core's
//! exact relaxation, so the contact has its own memory (relaxation length x_r = mu W / k_t,
//! 18 um for seed 003's k_t = 0.056 N/um at W = 4.155 N: about 0.5 ms at 0.038 m/s, as slow as
//! the loop). The friction a substep hands to the cells is the time average of mu W f over the
//! substep, not the periodic steady state.
//!
//! # The integration
//!
//! dz/dt = v (1 - (k_t z / F_c) sgn v)^alpha, F = k_t z, F_c = mu W, v = v_s + v_a cos(theta),
//! v_a = omega x_a, theta the vibration phase (carried across substeps, advanced at the drive
//! frequency). Along a stretch travelled in one direction s the gap g = 1 - s f relaxes exactly
//! in the travel (`sonolube::model::dahl::update` for alpha = 1, [`RelaxLaw`] otherwise), so
//! the state at the nodes is exact whatever their spacing (no step-size limit, however stiff
//! the contact). The stretches run between the turning points cos theta = -zeta (zeta =
//! v_s / v_a, |zeta| < 1); without reversal (|v_s| >= v_a) they are the two half periods.
//!
//! Nodes: [`NODES_PER_STRETCH`] per stretch, at h_j = L m(j/n), m(x) = x^2 (1 + x) / 2 (the
//! core's quadrature grid, clustered at the turning point where the travel grows like h^2 and
//! g falls fastest; uniform without reversal), plus the substep's own ends. Travel between two
//! nodes: dx = (v_s / omega) d theta + x_a (sin theta_b - sin theta_a), the sines from the core's
//! `fx::sin_cos` (1e-9 absolute). Time average over an interval: the decay exponent taken
//! linear in the phase, mean g = g_a (1 - e^-y) / y (the logarithmic mean, by its series below
//! y = 1/32), or for alpha < 1 g^p linear (p = 1 - alpha; g^p is exactly linear in the travel),
//! g_a phi((1 + p) y) / phi(p y). The error of that rule is the only approximation; its
//! convergence with the node count, measured against an adaptive f64 integration of the ODE
//! (`host-tests/tests/plant_dahl_in_time.rs`), sets [`NODES_PER_STRETCH`].
//!
//! # Load, speed and amplitude changes
//!
//! They enter through the geometry of each substep (zeta, kappa = k_t / (mu W), x_a): the
//! state itself is carried. A load change keeps the elastic force F = k_t z continuous, so f
//! scales by W_old / W_new. For alpha = 1 the Dahl law is defined beyond the Coulomb level
//! (g < 0 relaxes exactly as g > 0: a force above mu W decays over the relaxation length,
//! `dahl::update`), so f is kept as scaled up to the Q2.30 format's limit |f| < 2, and clamped
//! there (a load drop by more than half with the force at the old Coulomb level), counted in
//! [`DahlState::clamped_load_drops`]. For alpha != 1, (1 - s f)^alpha has no real value for
//! s f > 1 (physics-notes §2: clamp g >= 0): f is clamped to [-1, 1] and the clamp counted.
//! At zero load the contact carries no force: f = 0 (and stays 0 when the load returns).
//!
//! # Cost
//!
//! Per interval: one `sin_cos` (36 instructions), one `dahl::update` (44), and about twenty
//! f32 operations; 2 [`NODES_PER_STRETCH`] intervals per vibration period, plus one per
//! substep end. Per substep: one `acosf`, one division. All arithmetic is integer, f32 and
//! `libm`: the same bits on the host and in the firmware.

use core::f32::consts::TAU;

use sonolube::fx::{Q2_30, Q3_29, sin_cos};
use sonolube::model::ModelError;
use sonolube::model::dahl;
use sonolube::model::dahl_relax::{Decay, RelaxLaw, relaxed};

/// Nodes per stretch between turning points (two stretches per vibration period). Chosen by
/// the convergence measured against the f64 integration of the ODE
/// (`cargo test -p sonolube-host --test plant_dahl_in_time -- --nocapture`): the worst error of
/// the time-averaged friction falls as 1/n^2, and at 32 it is 3.5e-4 mu W on the stiff contact
/// of the `reference` scene (k_t = 2e7 N/m; 1.4e-3 at 16) and 4e-6 on the compliant one: below
/// the 6.2e-4 that the core's steady-state model (64 nodes per period), the memoryless plant's
/// model, has against the exact steady state.
pub const NODES_PER_STRETCH: u32 = 32;

/// One turn of phase, in units of the u32 phase (turns x 2^32).
const TURN: u64 = 1 << 32;

/// Radians per unit of the u32 phase.
const RAD_PER_UNIT: f32 = TAU / 4_294_967_296.0;

/// 1.0 in Q2.30 bits.
const ONE_Q30: i64 = 1 << 30;

/// Below this travel exponent an interval's mean uses the series of (1 - e^-y) / y.
const SERIES_BELOW: f32 = 1.0 / 32.0;

/// The time-integrated Dahl state of the plant's contact.
#[derive(Debug, Clone, PartialEq)]
pub struct DahlState {
    law: RelaxLaw,
    /// p = 1 - alpha (the interval mean of the power law).
    p: f32,
    /// mu, > 0.
    mu: f32,
    /// k_t in N/m, > 0.
    stiffness_n_per_m: f32,
    /// x_a at amplitude 1, m.
    full_scale_amplitude_m: f32,
    /// f = F / (mu W), Q2.30: [-1, 1] in a steady state, up to the format's +-2 after a load
    /// drop (alpha = 1 only).
    force_ratio: Q2_30,
    /// Vibration phase now, turns x 2^32 (0 = the velocity crest).
    phase: u32,
    /// The load f was last referred to, N (0: no load, f = 0).
    load_n: f32,
    clamped_load_drops: u32,
    /// Nodes per stretch ([`NODES_PER_STRETCH`] unless set for a convergence measurement).
    nodes: u32,
    /// The last substeps walked (ring; `newest` is the latest).
    history: [Option<Record>; HISTORY],
    newest: usize,
}

/// Substeps recorded for [`DahlState::period_mean`]: a period of up to 7 substeps is averaged
/// whole (5.7 kHz at 25 us substeps), a longer one over 7 substeps.
const HISTORY: usize = 8;

/// A substep as walked: its start and its drive.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Record {
    start_force_ratio: Q2_30,
    start_phase: u32,
    drive: Drive,
    span: u64,
    /// The load f was referred to over the substep, N.
    load_n: f32,
}

/// The geometry of one substep's drive.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Drive {
    /// Turning phase T1 (turns x 2^32) of a reversing drive: forward on (-T1, T1); `None`
    /// without reversal.
    turning: Option<u64>,
    /// sgn(v_s) > 0 for a drive without reversal.
    forward: bool,
    /// v_s / omega, m per radian.
    slide_m_per_rad: f32,
    /// x_a, m.
    amplitude_m: f32,
    /// kappa = k_t / (mu W), 1/m.
    kappa_per_m: f32,
}

/// A stretch travelled in one direction.
#[derive(Debug, Clone, Copy)]
struct Stretch {
    start: u32,
    length: u64,
    forward: bool,
    clustered: bool,
    nodes: u32,
}

impl Stretch {
    /// Node j of the stretch (j = n is its end), as an offset from its start.
    fn node(&self, j: u32) -> u64 {
        if j >= self.nodes {
            return self.length;
        }
        let x = j as f32 / self.nodes as f32;
        let m = if self.clustered {
            0.5 * x * x * (1.0 + x)
        } else {
            x
        };
        ((m * self.length as f32) as u64).min(self.length)
    }
}

impl DahlState {
    /// The state of a contact with friction coefficient `mu` (> 0), tangential stiffness
    /// `stiffness_n_per_m` (> 0), shape exponent `alpha` (in (0, 20]) and the actuator's
    /// full-scale amplitude (m, > 0), sliding steadily at `velocity_m_per_s` under
    /// `normal_n` without vibration: f = sgn(v) (0 when nothing slides or nothing loads).
    pub fn new(
        mu: f64,
        stiffness_n_per_m: f64,
        alpha: f64,
        full_scale_amplitude_m: f64,
        normal_n: f32,
        velocity_m_per_s: f32,
    ) -> Result<Self, ModelError> {
        let law = RelaxLaw::new(alpha)?;
        for (value, input) in [
            (mu, "mu"),
            (stiffness_n_per_m, "k_t"),
            (full_scale_amplitude_m, "x_a"),
        ] {
            sonolube::model::scaled_from_f64(value, input)?;
        }
        let loaded = normal_n > 0.0 && normal_n.is_finite();
        let force_ratio = if !loaded || velocity_m_per_s == 0.0 || velocity_m_per_s.is_nan() {
            Q2_30::ZERO
        } else if velocity_m_per_s > 0.0 {
            Q2_30::ONE
        } else {
            Q2_30::from_bits(-(1 << 30))
        };
        Ok(Self {
            law,
            p: (1.0 - alpha) as f32,
            mu: mu as f32,
            stiffness_n_per_m: stiffness_n_per_m as f32,
            full_scale_amplitude_m: full_scale_amplitude_m as f32,
            force_ratio,
            phase: 0,
            load_n: if loaded { normal_n } else { 0.0 },
            clamped_load_drops: 0,
            nodes: NODES_PER_STRETCH,
            history: [None; HISTORY],
            newest: 0,
        })
    }

    /// The same state with `nodes` nodes per stretch (clamped to 1..=1024): for measuring the
    /// convergence that sets [`NODES_PER_STRETCH`].
    pub fn with_nodes_per_stretch(self, nodes: u32) -> Self {
        Self {
            nodes: nodes.clamp(1, 1024),
            ..self
        }
    }

    /// f = F / (mu W) now, Q2.30.
    pub fn force_ratio(&self) -> Q2_30 {
        self.force_ratio
    }

    /// The friction force now, N (signed): mu W f.
    pub fn force_n(&self) -> f32 {
        self.mu * self.load_n * self.force_ratio.to_f32()
    }

    /// How many load changes clamped f (module docs).
    pub fn clamped_load_drops(&self) -> u32 {
        self.clamped_load_drops
    }

    /// Advances the contact by `dt_s` with the load `normal_n` (N), the sliding velocity
    /// `velocity_m_per_s` (m/s, signed), the vibration amplitude `amplitude` (fraction of full
    /// scale, clamped to [0, 1], NaN as 0) and the vibration frequency `frequency_hz` held.
    /// Returns the time average of the force over the last vibration period ending with the
    /// step, in units of the present mu W (over the step itself without vibration; f at the end
    /// when the step is empty).
    /// Non-finite or non-positive loads unload the contact (f = 0); a non-finite velocity
    /// counts as no sliding; a non-finite or non-positive frequency as no vibration.
    pub fn advance(
        &mut self,
        normal_n: f32,
        velocity_m_per_s: f32,
        amplitude: f32,
        frequency_hz: f32,
        dt_s: f32,
    ) -> f32 {
        let vibrating = frequency_hz.is_finite() && frequency_hz > 0.0;
        let span = if vibrating && dt_s > 0.0 {
            phase_span(frequency_hz * dt_s)
        } else {
            0
        };
        if !(normal_n > 0.0 && normal_n.is_finite()) {
            self.force_ratio = Q2_30::ZERO;
            self.load_n = 0.0;
            self.history = [None; HISTORY];
            self.phase = self.phase.wrapping_add(span as u32);
            return 0.0;
        }
        self.refer_to_load(normal_n);
        let v = if velocity_m_per_s.is_finite() {
            velocity_m_per_s
        } else {
            0.0
        };
        let amplitude = if amplitude.is_nan() {
            0.0
        } else {
            amplitude.clamp(0.0, 1.0)
        };
        let kappa_per_m = self.stiffness_n_per_m / (self.mu * normal_n);
        let amplitude_m = if vibrating {
            amplitude * self.full_scale_amplitude_m
        } else {
            0.0
        };
        if dt_s.is_nan() || dt_s <= 0.0 {
            return self.force_ratio.to_f32();
        }
        if amplitude_m <= 0.0 || span == 0 {
            // No vibration: one stretch of travel |v| dt, exact for any law whose decay is
            // linear in time (alpha = 1), and the same rule as every interval otherwise; no
            // ripple to average out, and the history restarts.
            let (mean, next) = self.interval(kappa_per_m * libm::fabsf(v) * dt_s, v > 0.0);
            self.force_ratio = next;
            self.phase = self.phase.wrapping_add(span as u32);
            self.history = [None; HISTORY];
            return mean;
        }
        let omega = TAU * frequency_hz;
        let v_a = omega * amplitude_m;
        let turning = if libm::fabsf(v) < v_a {
            // cos theta1 = -zeta: T1 in (0, 1/2) turn, kept off both ends so that neither
            // stretch is empty.
            let turns = libm::acosf(-v / v_a) / TAU;
            Some(((turns * TURN as f32) as u64).clamp(1, TURN / 2 - 1))
        } else {
            None
        };
        let drive = Drive {
            turning,
            forward: v > 0.0,
            slide_m_per_rad: v / omega,
            amplitude_m,
            kappa_per_m,
        };
        self.newest = (self.newest + 1) % HISTORY;
        self.history[self.newest] = Some(Record {
            start_force_ratio: self.force_ratio,
            start_phase: self.phase,
            drive,
            span,
            load_n: self.load_n,
        });
        let (whole, tail) = self.walk(&drive, span, span.saturating_sub(TURN));
        self.period_mean(span, whole, tail)
    }

    /// Refers f to the load `normal_n` (> 0): F continuous, f scaled by W_old / W_new.
    fn refer_to_load(&mut self, normal_n: f32) {
        if normal_n == self.load_n {
            return;
        }
        let old = self.load_n;
        self.load_n = normal_n;
        if old <= 0.0 || self.force_ratio == Q2_30::ZERO {
            self.force_ratio = Q2_30::ZERO;
            return;
        }
        let scaled = self.force_ratio.to_f32() * (old / normal_n);
        let limit = match self.law {
            RelaxLaw::Exponential => 2.0 - 1.0 / ONE_Q30 as f32 * 128.0,
            RelaxLaw::Power { .. } => 1.0,
        };
        let kept = if libm::fabsf(scaled) > limit {
            self.clamped_load_drops = self.clamped_load_drops.saturating_add(1);
            if scaled > 0.0 { limit } else { -limit }
        } else {
            scaled
        };
        let bits = libm::roundf(kept * ONE_Q30 as f32) as i64;
        self.force_ratio = Q2_30::from_bits(bits.clamp(-2 * ONE_Q30 + 1, 2 * ONE_Q30 - 1) as i32);
    }

    /// The stretch holding the phase `phase` for `drive`.
    fn stretch_at(&self, drive: &Drive, phase: u32) -> Stretch {
        match drive.turning {
            Some(t1) => {
                let forward_start = (TURN - t1) as u32;
                let forward_length = 2 * t1;
                let offset = phase.wrapping_sub(forward_start) as u64;
                if offset < forward_length {
                    Stretch {
                        start: forward_start,
                        length: forward_length,
                        forward: true,
                        clustered: true,
                        nodes: self.nodes,
                    }
                } else {
                    Stretch {
                        start: t1 as u32,
                        length: TURN - forward_length,
                        forward: false,
                        clustered: true,
                        nodes: self.nodes,
                    }
                }
            }
            None => Stretch {
                start: if phase < 1 << 31 { 0 } else { 1 << 31 },
                length: TURN / 2,
                forward: drive.forward,
                clustered: false,
                nodes: self.nodes,
            },
        }
    }

    /// Steps the state through `span` (turns x 2^32) of drive phase; returns the integrals of
    /// f over the whole span and over its part from `tail_start` (phase units from the start)
    /// on, in f x phase units.
    fn walk(&mut self, drive: &Drive, span: u64, tail_start: u64) -> (f32, f32) {
        let mut remaining = span;
        let mut weighted = 0.0f32;
        let mut tail = 0.0f32;
        let mut done = 0u64;
        let mut sin_here = sin_bits(self.phase);
        while remaining > 0 {
            let stretch = self.stretch_at(drive, self.phase);
            let mut within = self.phase.wrapping_sub(stretch.start) as u64;
            let mut j = 1;
            while j < stretch.nodes && stretch.node(j) <= within {
                j += 1;
            }
            loop {
                let mut target = stretch.node(j).min(within + remaining);
                if done < tail_start {
                    // The tail's start is a node too.
                    target = target.min(within + (tail_start - done));
                }
                let step = target - within;
                let next_phase = self.phase.wrapping_add(step as u32);
                let sin_next = sin_bits(next_phase);
                let d_theta = step as f32 * RAD_PER_UNIT;
                let d_sin = (sin_next - sin_here) as f32 * (1.0 / 2_147_483_648.0);
                let travel = drive.slide_m_per_rad * d_theta + drive.amplitude_m * d_sin;
                let along = if stretch.forward { travel } else { -travel };
                let (mean, next) =
                    self.interval(drive.kappa_per_m * along.max(0.0), stretch.forward);
                weighted += mean * step as f32;
                if done >= tail_start {
                    tail += mean * step as f32;
                }
                self.force_ratio = next;
                self.phase = next_phase;
                sin_here = sin_next;
                remaining -= step;
                done += step;
                within = target;
                if remaining == 0 || within >= stretch.length {
                    break;
                }
                if stretch.node(j) <= within {
                    j += 1;
                }
            }
        }
        (weighted, tail)
    }

    /// The mean of f over the last vibration period (one turn of phase) ending now, after a
    /// substep walked with `drive` over `span` whose whole integral is `whole` and whose
    /// last turn's integral is `tail`: a substep shorter than a period reaches back into the
    /// substeps before it, walked again from their recorded start (the same bits), as far as
    /// the history holds.
    fn period_mean(&self, span: u64, whole: f32, tail: f32) -> f32 {
        if span >= TURN {
            return tail / TURN as f32;
        }
        // The records before this substep's (newest first) and how much of each counts (its
        // last part), until a turn is covered.
        let mut needed = TURN - span;
        let mut reach: [Option<(Record, u64)>; HISTORY] = [None; HISTORY];
        let mut count = 0;
        for back in 1..HISTORY {
            if needed == 0 {
                break;
            }
            let index = (self.newest + HISTORY - back) % HISTORY;
            let Some(record) = self.history[index] else {
                break;
            };
            let take = record.span.min(needed);
            reach[count] = Some((record, take));
            count += 1;
            needed -= take;
        }
        let mut integral = whole;
        let mut covered = span;
        // Oldest first, each walked again from its recorded start; only its last `take` counts.
        for (record, take) in reach[..count].iter().rev().flatten() {
            let mut shadow = DahlState {
                force_ratio: record.start_force_ratio,
                phase: record.start_phase,
                history: [None; HISTORY],
                ..self.clone()
            };
            let (_, part) = shadow.walk(&record.drive, record.span, record.span - take);
            // The force is what is averaged: f of an earlier load counts as mu W_then f.
            integral += part * (record.load_n / self.load_n);
            covered += take;
        }
        integral / covered as f32
    }

    /// One interval of travel exponent `y` (>= 0) in direction `forward`: the mean of f over
    /// it (module docs) and f at its end.
    fn interval(&self, y: f32, forward: bool) -> (f32, Q2_30) {
        let s: i64 = if forward { 1 } else { -1 };
        let f = self.force_ratio;
        let gap_bits = ONE_Q30 - s * f.to_bits() as i64; // 1 - s f, Q.30: [-1, 3]
        let gap = gap_bits as f32 / ONE_Q30 as f32;
        if y.is_nan() || y <= 0.0 {
            return (f.to_f32(), f);
        }
        match self.law {
            RelaxLaw::Exponential => {
                let next = if y < 2.0 {
                    dahl::update(f, forward, Q2_30::from_bits(round_bits(y, 30)))
                } else {
                    // Q8.24, saturated at 128 (e^-128 is below every format's resolution).
                    dahl::update(
                        f,
                        forward,
                        sonolube::fx::Q8_24::from_bits(round_bits(y, 24)),
                    )
                }
                .unwrap_or(f); // y >= 0: never Err
                let next_gap = (ONE_Q30 - s * next.to_bits() as i64) as f32 / ONE_Q30 as f32;
                let mean_gap = if y < SERIES_BELOW {
                    gap * series_phi(y)
                } else {
                    (gap - next_gap) / y
                };
                (s as f32 * (1.0 - mean_gap), next)
            }
            RelaxLaw::Power { .. } => {
                // f in [-1, 1] here (clamped on load changes): g0 in [0, 2], Q3.29.
                let g0 = Q3_29::from_bits(((gap_bits.clamp(0, 2 * ONE_Q30) + 1) >> 1) as i32);
                let Some(factor) = self.law.stretch_factor(g0) else {
                    return (f.to_f32(), f); // g = 0: f = s, and it stays there
                };
                let decay = match sonolube::model::scaled_from_f64(f64::from(y), "y") {
                    Ok(y) => self.law.decay(Some(y), factor),
                    Err(_) => Decay::None,
                };
                let g1 = relaxed(g0, decay).unwrap_or(g0);
                let next_bits = s * (ONE_Q30 - 2 * g1.to_bits() as i64);
                let next = Q2_30::from_bits(next_bits.clamp(-ONE_Q30, ONE_Q30) as i32);
                let g0f = g0.to_f32();
                let g1f = g1.to_f32();
                let mean_gap = if g1f <= 0.0 {
                    // g^p linear in h down to 0 (alpha < 1): the mean is g0 p / (1 + p).
                    g0f * self.p / (1.0 + self.p)
                } else {
                    let x = libm::logf(g0f / g1f).max(0.0);
                    if self.p > 0.0 {
                        g0f * phi((1.0 + self.p) * x) / phi(self.p * x)
                    } else {
                        g0f * phi(x)
                    }
                };
                (s as f32 * (1.0 - mean_gap), next)
            }
        }
    }
}

/// Phase span of `turns` turns, turns x 2^32 (whole turns included; saturating far beyond any
/// substep).
fn phase_span(turns: f32) -> u64 {
    if turns.is_nan() || turns <= 0.0 {
        return 0;
    }
    let whole = libm::floorf(turns);
    let fraction = ((turns - whole) * TURN as f32) as u64;
    ((whole as u64).min(1 << 20) << 32) + fraction.min(TURN - 1)
}

/// sin of the phase, Q1.31 bits widened.
fn sin_bits(phase: u32) -> i64 {
    sin_cos(phase).0.to_bits() as i64
}

/// `y` (>= 0) in a Q.`frac` format's bits, rounded to nearest; saturating at i32::MAX.
fn round_bits(y: f32, frac: i32) -> i32 {
    (y * libm::ldexpf(1.0, frac) + 0.5) as i32
}

/// (1 - e^-y) / y for 0 <= y < 1/32 by its series (error y^4 / 120 < 8.5e-9).
fn series_phi(y: f32) -> f32 {
    1.0 - y * (0.5 - y * (1.0 / 6.0 - y * (1.0 / 24.0)))
}

/// (1 - e^-y) / y for y >= 0.
fn phi(y: f32) -> f32 {
    if y < SERIES_BELOW {
        series_phi(y)
    } else {
        -libm::expm1f(-y) / y
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Seed 003's contact with the `compliant` scene's plant values (mu 0.24, k_t 4.48e4 N/m)
    /// and the stack's full-scale amplitude 0.4756 um.
    fn compliant(alpha: f64) -> DahlState {
        DahlState::new(0.24, 4.48e4, alpha, 0.4756e-6, 4.155, 0.038).unwrap()
    }

    /// Without vibration f relaxes exponentially in the travel: from f = -1 (sliding the other
    /// way) the state after a time t is 1 - 2 e^(-kappa v t), and the mean over the step is
    /// 1 - 2 (1 - e^-Y) / Y, Y = kappa v t.
    #[test]
    fn without_vibration_the_state_follows_the_closed_form() {
        let mut state = compliant(1.0);
        state.advance(4.155, -0.038, 0.0, 40e3, 5e-3);
        assert!(state.force_ratio().to_f64() < -0.999);
        let start = state.force_ratio().to_f64();
        let kappa = 4.48e4 / (0.24 * 4.155f64);
        let dt = 2.5e-5;
        let mut y_total = 0.0;
        for _ in 0..40 {
            let f_before = state.force_ratio().to_f64();
            let mean = state.advance(4.155, 0.038, 0.0, 40e3, dt as f32) as f64;
            let y = kappa * 0.038 * dt;
            y_total += y;
            let want_end = 1.0 + (start - 1.0) * (-y_total).exp();
            let want_mean = 1.0 + (f_before - 1.0) * (1.0 - (-y).exp()) / y;
            assert!((state.force_ratio().to_f64() - want_end).abs() < 1e-5);
            assert!((mean - want_mean).abs() < 1e-5, "{mean} vs {want_mean}");
        }
    }

    /// A load change keeps F = mu W f continuous; a drop by more than half from the Coulomb
    /// level is clamped at the format's limit and counted; alpha != 1 clamps at the level.
    #[test]
    fn a_load_change_keeps_the_force_continuous() {
        let mut state = compliant(1.0);
        let before = state.force_n();
        state.advance(3.0, 0.038, 0.0, 40e3, 0.0);
        assert!((state.force_n() - before).abs() < 1e-6 * before);
        assert_eq!(state.clamped_load_drops(), 0);
        state.advance(1.0, 0.038, 0.0, 40e3, 0.0);
        assert!(state.force_ratio().to_f64() > 1.99);
        assert_eq!(state.clamped_load_drops(), 1);
        let mut power = compliant(0.5);
        power.advance(3.0, 0.038, 0.0, 40e3, 0.0);
        assert_eq!(power.force_ratio(), Q2_30::ONE);
        assert_eq!(power.clamped_load_drops(), 1);
        // Unloading removes the force; it stays 0 when the load returns.
        state.advance(0.0, 0.038, 0.3, 40e3, 2.5e-5);
        assert_eq!(state.force_ratio(), Q2_30::ZERO);
        state.advance(4.155, 0.038, 0.0, 40e3, 0.0);
        assert_eq!(state.force_ratio(), Q2_30::ZERO);
        // Bad inputs never panic nor leave the format's range.
        for (w, v, a, f, dt) in [
            (f32::NAN, 0.038, 0.5, 40e3, 2.5e-5),
            (4.0, f32::NAN, f32::NAN, f32::INFINITY, 2.5e-5),
            (4.0, 1e9, 1.0, 40e3, 1.0),
            (1e-30, 0.038, 1.0, 1e9, 2.5e-5),
            (4.0, 0.038, 1.0, 40e3, f32::NAN),
        ] {
            let mean = state.advance(w, v, a, f, dt);
            assert!(mean.is_finite() && mean.abs() <= 2.0);
        }
        assert!(DahlState::new(0.0, 4.48e4, 1.0, 1e-6, 4.0, 0.038).is_err());
        assert!(DahlState::new(0.2, 4.48e4, 0.0, 1e-6, 4.0, 0.038).is_err());
    }

    /// Under vibration the state settles to the periodic steady state: the mean over a whole
    /// period stops changing, and a backward slide mirrors a forward one.
    #[test]
    fn the_state_settles_and_is_odd_in_the_velocity() {
        let mut forward = compliant(1.0);
        let mut backward = DahlState::new(0.24, 4.48e4, 1.0, 0.4756e-6, 4.155, -0.038).unwrap();
        let mut last = 0.0;
        for _ in 0..2000 {
            last = forward.advance(4.155, 0.038, 0.5, 40e3, 2.5e-5);
            let mirrored = backward.advance(4.155, -0.038, 0.5, 40e3, 2.5e-5);
            // The mirror runs half a period apart (v_s + v_a cos(theta) = -(|v_s| + v_a cos(theta
            // + pi))): equal up to that shift once settled, not bit for bit.
            assert!(mirrored.is_finite());
        }
        let next = forward.advance(4.155, 0.038, 0.5, 40e3, 2.5e-5);
        assert!((next - last).abs() < 1e-5);
        assert!(next > 0.0 && next < 1.0);
        let mirrored = backward.advance(4.155, -0.038, 0.5, 40e3, 2.5e-5);
        assert!((mirrored + next).abs() < 1e-3, "{mirrored} vs {next}");
    }
}
