//! Commissioning: what the loop's tuning needs, measured on the rig instead of declared.
//!
//! The `commission` command ([`crate::protocol::Command::Commission`]) runs, with the loop
//! open and the contact loaded and sliding:
//!
//! 1. **Resonance**: the resonance loop's search (`freq auto`, [`crate::resonance`]) at its own
//!    low amplitude, until it locks and tracks.
//! 2. **Burst**: the drive at half the controller's amplitude ceiling at the tracked frequency,
//!    until the current's amplitude is settled (it grows less than [`SETTLED_GROWTH`] per
//!    group for [`SETTLED_GROUPS`] groups). The resonance f0 is the drive frequency corrected by
//!    the motional detuning the resonance loop measures over the settled groups:
//!    `f0 = f (1 - d / 2Q)` with `d = (f - f0) / (f0 / 2Q)` ([`crate::resonance::detuning`]),
//!    averaged; its standard error is that of the mean.
//! 3. **Ring-down**: the drive off; the current's amplitude per group of four samples decays as
//!    `exp(-t / tau)` ([`crate::resonance::fit_ring_down`]); `Q = pi f0 tau`.
//! 4. **Natural friction**: the drive stays off for [`QUIET_TIME_CONSTANTS`] measured time
//!    constants (the envelope below `e^-10`), then mu0 is the mean of `|F_t| / F_n` over
//!    [`NATURAL_SAMPLES`] control periods, sliding and loaded, with its standard error.
//! 5. The cells' zero (the last `tare`), in newtons; their noise is measured by `tare` and
//!    fills [`CellZero::noise_rms_n`] where the tare gives it.
//!
//! Each result is checked against its physical range ([`check`]); one outside it refuses the
//! whole commissioning with the reason ([`Refusal`]). Accepted, the station reconfigures its
//! controller with the measured time constant and frequency; a scene with `commission = true`
//! is run with its declared f0, Q and mu replaced by the measured ones ([`commissioned_scene`]).
//!
//! Set-up arithmetic in `f64` (once per commissioning; the per-period work is integer sums and
//! a few `f64` additions while the friction loop is not running).

mod sequence;

pub use sequence::{Commissioning, PeriodInputs, Phase, Step};

use crate::scene::{ModelKind, Scene};

/// Drive band of the resonance, Hz (the `freq` command's range, the half-bridge's timer).
pub const RESONANCE_RANGE_HZ: (f64, f64) = (20_000.0, 60_000.0);

/// Quality factors commissioning accepts: below 5 the stack is no resonator the loop's
/// envelope model describes (its bandwidth is a tenth of f0); above 5000 the envelope would
/// take 80 ms at 20 kHz, longer than any loop here can wait.
pub const QUALITY_RANGE: (f64, f64) = (5.0, 5_000.0);

/// Natural friction coefficients accepted: (0, 2], the scene schema's range of mu.
pub const NATURAL_RANGE: (f64, f64) = (0.0, 2.0);

/// Growth of the current's group amplitude below which a group counts as settled: 1/128
/// (0.8 %) per group.
pub const SETTLED_GROWTH: f64 = 1.0 / 128.0;

/// Settled groups in a row that end the burst: 16 (64 drive periods, 1.6 ms at 40 kHz, twice
/// the reference stack's time constant: the detuning is averaged over that many windows).
pub const SETTLED_GROUPS: u32 = 16;

/// Time constants the drive stays off after the ring-down before mu0 is measured: the
/// envelope falls to `e^-10 = 4.5e-5` of the burst's, below the controller's 1e-3 threshold
/// for a drive that is off (`Settings::natural_max_drive`).
pub const QUIET_TIME_CONSTANTS: f64 = 10.0;

/// Control periods averaged for mu0: 1024 (0.1 s at 10 kHz). With 0.5 % FS cell noise on a
/// friction of half the tangential cell's full scale a sample scatters by 1 %; the mean of
/// 1024 by 0.03 %, a thirtieth of the 1 % friction accuracy the scenes ask for.
pub const NATURAL_SAMPLES: u32 = 1024;

/// A measured value and its standard error, in the value's unit.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Measured {
    /// The value.
    pub value: f64,
    /// Its standard error (>= 0).
    pub standard_error: f64,
}

/// One cell's zero as the last `tare` set it.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CellZero {
    /// The reading with no load, N, through the datasheet calibration (the offset `tare`
    /// removes).
    pub zero_n: f64,
    /// The cell's noise, N RMS, as the tare burst measured it; `None` until the tare measures
    /// it.
    pub noise_rms_n: Option<f64>,
}

/// What commissioning measured.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CommissionResult {
    /// The resonance f0, Hz, in [`RESONANCE_RANGE_HZ`].
    pub resonance_hz: Measured,
    /// The envelope time constant tau, s (`Q / (pi f0)`).
    pub time_constant_s: Measured,
    /// The quality factor `pi f0 tau`, in [`QUALITY_RANGE`] (its standard error from tau's and
    /// f0's).
    pub quality_factor: Measured,
    /// The natural friction coefficient mu0, in [`NATURAL_RANGE`].
    pub natural_coefficient: Measured,
    /// Ring-down points fitted.
    pub ring_down_points: u32,
    /// The normal cell's zero.
    pub normal: CellZero,
    /// The tangential cell's zero.
    pub tangential: CellZero,
}

/// Why commissioning gave no result: the step and the reason, with the offending value where
/// there is one (in the step's unit: Hz, s, 1, LSB or samples).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Refusal {
    /// The step that failed.
    pub step: Step,
    /// Why, in words.
    pub reason: &'static str,
    /// The value that was refused, NaN when there is none.
    pub value: f64,
}

impl Refusal {
    pub(crate) const fn new(step: Step, reason: &'static str, value: f64) -> Self {
        Self {
            step,
            reason,
            value,
        }
    }
}

/// Largest cell zero and noise accepted, N: what a Q16.16 newton reading holds.
pub const CELL_RANGE_N: f64 = 32_768.0;

/// Checks each result against its physical range, and names the first that is not in it:
/// f0 in the drive band [`RESONANCE_RANGE_HZ`]; Q in [`QUALITY_RANGE`] and equal to
/// `pi f0 tau` (to 1e-9: the sequence computes it so, and a stored result must agree); mu0 in
/// (0, 2] ([`NATURAL_RANGE`]); each standard error in [0, the width of its value's range] (an
/// error wider than the range measured nothing); at least [`MIN_RING_DOWN_POINTS`] ring-down
/// points; each cell's zero and noise within [`CELL_RANGE_N`], the noise not negative. NaN
/// and infinities fail every range.
///
/// [`MIN_RING_DOWN_POINTS`]: crate::resonance::MIN_RING_DOWN_POINTS
pub fn check(result: &CommissionResult) -> Result<(), Refusal> {
    let within = |x: f64, (lo, hi): (f64, f64)| x >= lo && x <= hi;
    let f0 = result.resonance_hz;
    let band = RESONANCE_RANGE_HZ;
    if !within(f0.value, band) {
        return Err(Refusal::new(
            Step::Resonance,
            "f0 outside the drive band 20-60 kHz",
            f0.value,
        ));
    }
    if !within(f0.standard_error, (0.0, band.1 - band.0)) {
        return Err(Refusal::new(
            Step::Resonance,
            "f0 error outside [0, 40 kHz]",
            f0.standard_error,
        ));
    }
    let q = result.quality_factor;
    if !within(q.value, QUALITY_RANGE) {
        return Err(Refusal::new(Step::RingDown, "Q outside [5, 5000]", q.value));
    }
    if !within(q.standard_error, (0.0, QUALITY_RANGE.1)) {
        return Err(Refusal::new(
            Step::RingDown,
            "Q error outside [0, 5000]",
            q.standard_error,
        ));
    }
    let tau = result.time_constant_s;
    let q_of_tau = core::f64::consts::PI * f0.value * tau.value;
    // NaN (a tau that is not finite) compares false: refused.
    let agrees = libm::fabs(q_of_tau - q.value) <= 1e-9 * q.value;
    if !agrees {
        return Err(Refusal::new(
            Step::RingDown,
            "Q is not pi f0 tau",
            tau.value,
        ));
    }
    let tau_max = QUALITY_RANGE.1 / (core::f64::consts::PI * band.0);
    if !within(tau.standard_error, (0.0, tau_max)) {
        return Err(Refusal::new(
            Step::RingDown,
            "tau error outside [0, 80 ms]",
            tau.standard_error,
        ));
    }
    if (result.ring_down_points as usize) < crate::resonance::MIN_RING_DOWN_POINTS {
        return Err(Refusal::new(
            Step::RingDown,
            "ring-down too short",
            f64::from(result.ring_down_points),
        ));
    }
    let mu0 = result.natural_coefficient;
    if !(mu0.value > NATURAL_RANGE.0 && mu0.value <= NATURAL_RANGE.1) {
        return Err(Refusal::new(Step::Natural, "mu0 outside (0, 2]", mu0.value));
    }
    if !within(mu0.standard_error, (0.0, NATURAL_RANGE.1)) {
        return Err(Refusal::new(
            Step::Natural,
            "mu0 error outside [0, 2]",
            mu0.standard_error,
        ));
    }
    // The zeros are read when the sequence starts, before its first step.
    for (cell, zero_reason, noise_reason) in [
        (
            &result.normal,
            "normal zero outside +-32768 N",
            "normal noise outside [0, 32768 N]",
        ),
        (
            &result.tangential,
            "tangential zero outside +-32768 N",
            "tangential noise outside [0, 32768 N]",
        ),
    ] {
        if !within(cell.zero_n, (-CELL_RANGE_N, CELL_RANGE_N)) {
            return Err(Refusal::new(Step::Resonance, zero_reason, cell.zero_n));
        }
        if let Some(noise) = cell.noise_rms_n
            && !within(noise, (0.0, CELL_RANGE_N))
        {
            return Err(Refusal::new(Step::Resonance, noise_reason, noise));
        }
    }
    Ok(())
}

/// `scene` with its declared resonance, quality factor, drive frequency and controller
/// friction coefficient replaced by the commissioned ones: the drive starts at the measured
/// f0 (no search), the envelope time constant is the measured one, and the controller's
/// model and mu0 prior take the measured mu0 at the scene's starting speed (the exponential
/// law's two coefficients scaled together, so its shape is kept). The plant's own parameters
/// are not in a scene's controller half, so they stay the truth the run is judged against.
pub fn commissioned_scene<'a>(scene: &Scene<'a>, result: &CommissionResult) -> Scene<'a> {
    let mut out = *scene;
    let f0 = result.resonance_hz.value;
    out.transducer.resonance_hz = f0;
    out.transducer.drive_hz = f0;
    out.transducer.quality_factor = result.quality_factor.value;
    out.transducer.shift.freq_auto = false;
    let speed = scene
        .sliding_velocity_m_per_s
        .first()
        .map_or(0.0, |p| libm::fabs(p.value));
    let declared = scene.controller.natural_coefficient(speed);
    let scale = result.natural_coefficient.value / declared;
    out.controller.mu = scene.controller.mu * scale;
    if scene.controller.kind == ModelKind::ExpCoulomb {
        out.controller.mu_static = scene.controller.mu_static.map(|mu_s| mu_s * scale);
    }
    out
}

#[cfg(test)]
mod tests;
