//! Test fixture: a Butterworth-Van Dyke resonator in f64 whose motional current either follows
//! the drive frequency at once (as `sonolube_sim::plant` does) or lags by the envelope time constant
//! (the complex envelope of a real series RLC branch), to check the loops on both.

use std::f64::consts::TAU;

use super::lockin::Demodulated;
use super::phasor::Phasor;
use crate::drive::{Amplitude, Frequency};
use crate::fx::Q2_30;

/// How the motional current responds to a change of drive frequency.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Dynamics {
    /// Amplitude through a first-order envelope, phase at once (`sonolube_sim::plant`'s model).
    InstantPhase,
    /// Complex envelope of the series branch: `2 L1 da/dt = V - Z(f) a`.
    Lagged,
}

/// The reference stack (scenes/reference.toml) on the NUCLEO current sense.
#[derive(Debug, Clone)]
pub(crate) struct Resonator {
    pub f0_hz: f64,
    pub drift_hz_per_s: f64,
    pub q: f64,
    pub r1: f64,
    pub c0: f64,
    pub v_fs: f64,
    pub a_fs: f64,
    pub dynamics: Dynamics,
    pub t_s: f64,
    /// Motional current, A, as (re, im) relative to the voltage.
    motional: (f64, f64),
}

impl Resonator {
    pub fn reference(dynamics: Dynamics) -> Self {
        Self {
            f0_hz: 40_000.0,
            drift_hz_per_s: 0.0,
            q: 100.0,
            r1: 3.1,
            c0: 300e-9,
            v_fs: 5.25,
            a_fs: 6.6,
            dynamics,
            t_s: 0.0,
            motional: (0.0, 0.0),
        }
    }

    pub fn resonance_hz(&self) -> f64 {
        self.f0_hz + self.drift_hz_per_s * self.t_s
    }

    /// Settles the motional current at `drive_hz` and `amplitude`.
    pub fn settle(&mut self, drive_hz: f64, amplitude: f64) {
        self.motional = self.settled(drive_hz, amplitude);
    }

    fn settled(&self, drive_hz: f64, amplitude: f64) -> (f64, f64) {
        let f0 = self.resonance_hz();
        let x = self.q * (drive_hz / f0 - f0 / drive_hz);
        let i = amplitude * self.v_fs / self.r1 / (1.0 + x * x);
        (i, -i * x)
    }

    /// Advances by `dt_s` with the drive held; exact for both dynamics.
    pub fn advance(&mut self, drive_hz: f64, amplitude: f64, dt_s: f64) {
        let f0 = self.resonance_hz();
        let (sr, si) = self.settled(drive_hz, amplitude);
        let tau = self.q / (std::f64::consts::PI * f0);
        self.motional = match self.dynamics {
            Dynamics::InstantPhase => {
                let x = self.q * (drive_hz / f0 - f0 / drive_hz);
                let settled = sr.hypot(si);
                let now = self.motional.0.hypot(self.motional.1);
                let magnitude = settled + (now - settled) * (-dt_s / tau).exp();
                let phase = -x.atan();
                (magnitude * phase.cos(), magnitude * phase.sin())
            }
            Dynamics::Lagged => {
                // lambda = (R1 + j X) / (2 L1) = (1 + j x) / tau.
                let x = self.q * (drive_hz / f0 - f0 / drive_hz);
                let decay = (-dt_s / tau).exp();
                let (c, s) = ((x * dt_s / tau).cos(), -(x * dt_s / tau).sin());
                let (dr, di) = (self.motional.0 - sr, self.motional.1 - si);
                (
                    sr + decay * (dr * c - di * s),
                    si + decay * (dr * s + di * c),
                )
            }
        };
        self.t_s += dt_s;
    }

    /// The measured current (motional plus C0's), fraction of full scale, (re, im).
    pub fn current_fs(&self, drive_hz: f64, amplitude: f64) -> (f64, f64) {
        let capacitive = TAU * drive_hz * self.c0 * amplitude * self.v_fs;
        (
            self.motional.0 / self.a_fs,
            (self.motional.1 + capacitive) / self.a_fs,
        )
    }

    /// Runs one window of `samples` at `sample_rate_hz` (10 substeps) and returns the
    /// window's mean current as the lock-in would report it.
    pub fn window(
        &mut self,
        drive: Frequency,
        amplitude: Amplitude,
        samples: u32,
        sample_rate_hz: f64,
    ) -> Demodulated {
        let hz = f64::from(drive.millihertz()) / 1000.0;
        let a = amplitude.fraction().to_f64();
        let dt = f64::from(samples) / sample_rate_hz / 10.0;
        let (mut re, mut im) = (0.0, 0.0);
        for _ in 0..10 {
            self.advance(hz, a, dt);
            let (r, i) = self.current_fs(hz, a);
            re += r / 10.0;
            im += i / 10.0;
        }
        Demodulated {
            phasor: Phasor::new(Q2_30::from_f64(re).unwrap(), Q2_30::from_f64(im).unwrap()),
            samples,
        }
    }
}

/// Samples in a window of 4 drive periods at 1 MSPS (as the lock-in computes it).
pub(crate) fn window_samples(drive: Frequency) -> u32 {
    (4.0e9 / f64::from(drive.millihertz())).round() as u32
}
