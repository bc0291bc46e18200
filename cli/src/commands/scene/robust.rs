//! The robustness modes of `sonolube scene`: a scene (or every scene) over many noise seeds,
//! over the mismatch grid, over the operating envelope and over sensor noise levels.
//!
//! ```text
//! sonolube scene NAME --seeds N|A-B [--plot PATH.svg]
//! sonolube scene --all --seeds N|A-B [--plot PATH.svg]
//! sonolube scene NAME --mismatch [--seeds N|A-B]
//! sonolube scene NAME --envelope [--seeds N|A-B] [--out DIR]
//! sonolube scene NAME --noise [--seeds N|A-B]
//! sonolube scene NAME --resonators [--seeds N|A-B]
//! ```
//!
//! Each prints, per scene and criterion, the pass rate, the 50th, 90th and 99th percentiles
//! and the worst run; then the failed runs; and ends with a one-line summary. The exit status
//! is 0 only when every run passes every criterion (1 otherwise, 2 for a usage error). The
//! sweeps without `--seeds` run on the scene's own seed. `SONOLUBE_JOBS` caps the threads.

use std::path::Path;
use std::process::ExitCode;

use sonolube::scene::{Breakpoint, Criterion, FaultEvent, SCENES, Scene, TargetPoint};
use sonolube_sim::RunSummary;

pub use super::grid::GridDrive;
use super::grid::{
    ENVELOPE_LOADS_N, ENVELOPE_SPEEDS, NOISE_LEVELS_PCT, envelope_points, load_text, mismatch_runs,
    with_noise,
};
use super::spread;
use super::sweep::{
    Run, all_passed, criterion_stats, failures, percentile, run_all, stats_table, threads, value_of,
};
use crate::scene_file::scenes_dir;

/// Which robustness sweep.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sweep {
    /// Noise seeds only.
    Seeds,
    /// The mismatch grid ([`super::grid::Mismatch::grid`]), the transducer driven as said.
    Mismatch(GridDrive),
    /// The operating envelope ([`super::grid::envelope_points`]).
    Envelope,
    /// Sensor noise levels ([`NOISE_LEVELS_PCT`]).
    Noise,
    /// Other resonators: f0 in [`RESONATOR_F0_HZ`] x Q in [`RESONATOR_Q`] ([`Resonator`]).
    Resonators,
}

/// Parses `N` (seeds 1 to N) or `A-B` (A to B, inclusive); at most 100 000 seeds.
pub fn parse_seeds(text: &str) -> Result<Vec<u64>, String> {
    let bad = || format!("--seeds takes N or A-B (positive whole numbers), not '{text}'");
    let (from, to) = match text.split_once('-') {
        Some((a, b)) => (
            a.parse::<u64>().map_err(|_| bad())?,
            b.parse::<u64>().map_err(|_| bad())?,
        ),
        None => (1, text.parse::<u64>().map_err(|_| bad())?),
    };
    if from == 0 || to < from || to - from >= 100_000 {
        return Err(bad());
    }
    Ok((from..=to).collect())
}

fn seeds_text(seeds: &[u64]) -> String {
    match (seeds.first(), seeds.last()) {
        (Some(a), Some(b)) if a != b => format!("seeds {a}-{b}"),
        (Some(a), _) => format!("seed {a}"),
        _ => String::from("no seed"),
    }
}

/// Runs a sweep of the `scenes` (several only for [`Sweep::Seeds`]); `seeds` `None` means each
/// scene's own seed. `plot` writes the distributions' SVG; `out` receives the envelope files.
pub fn run(
    scenes: &[Scene<'_>],
    sweep: Sweep,
    seeds: Option<&[u64]>,
    plot: Option<&Path>,
    out: &Path,
) -> ExitCode {
    let jobs = threads();
    let mut passed_scenes = 0;
    let mut total_runs = 0;
    let mut failed_runs = 0;
    let mut infeasible_runs = 0;
    let mut all = Vec::new();
    for scene in scenes {
        let own = [scene.noise_seed];
        let seeds = seeds.unwrap_or(&own);
        let result = match sweep {
            Sweep::Seeds => {
                let runs: Vec<Run<'_>> = seeds.iter().map(|&s| Run::seeded(scene, s)).collect();
                println!("{}: {} runs, {}", scene.name, runs.len(), seeds_text(seeds));
                sweep_runs(scene, &runs, jobs)
            }
            Sweep::Mismatch(drive) => mismatch_sweep(scene, seeds, drive, jobs),
            Sweep::Noise => noise_sweep(scene, seeds, jobs),
            Sweep::Resonators => resonator_sweep(scene, seeds, jobs),
            Sweep::Envelope => envelope(scene, seeds, jobs, out),
        };
        match result {
            Ok(done) => {
                total_runs += done.results.len();
                infeasible_runs += done.infeasible;
                let failed = done.results.iter().filter(|r| !is_pass(r)).count();
                failed_runs += failed;
                if failed == 0 && done.infeasible == 0 {
                    passed_scenes += 1;
                }
                all.push((scene.name.to_string(), done));
            }
            Err(error) => {
                println!("  cannot sweep {}: {error}", scene.name);
                failed_runs += 1;
            }
        }
    }
    if let Some(path) = plot {
        let svg = spread::svg(&all);
        match std::fs::write(path, svg) {
            Ok(()) => println!("wrote {}", path.display()),
            Err(e) => {
                eprintln!("sonolube scene: {}: {e}", path.display());
                return ExitCode::FAILURE;
            }
        }
    }
    let infeasible = if infeasible_runs > 0 {
        format!("; {infeasible_runs} more infeasible, refused (reasons above)")
    } else {
        String::new()
    };
    println!(
        "{} of {} scenes passed every run; {} of {} runs failed{infeasible} ({}, {jobs} threads)",
        passed_scenes,
        scenes.len(),
        failed_runs,
        total_runs,
        seeds.map_or(String::from("own seeds"), seeds_text)
    );
    if failed_runs == 0 && infeasible_runs == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}

fn is_pass(result: &Result<RunSummary, String>) -> bool {
    result.as_ref().is_ok_and(RunSummary::passed)
}

/// A finished sweep of one scene: its criteria's statistics and the results.
pub struct Done {
    /// Per criterion.
    pub stats: Vec<super::sweep::CriterionStats>,
    /// Per run.
    pub results: Vec<Result<RunSummary, String>>,
    /// Runs refused before running because they cannot work (with the reason printed), not
    /// counted in `results`.
    pub infeasible: usize,
}

/// Runs `runs` of `scene` and prints their table and failures.
fn sweep_runs(scene: &Scene<'_>, runs: &[Run<'_>], jobs: usize) -> Result<Done, String> {
    let results = run_all(runs, jobs, scene.name);
    let stats = criterion_stats(scene, runs, &results);
    print!("{}", stats_table(&stats));
    for line in failures(runs, &results) {
        println!("  FAIL {line}");
    }
    println!(
        "  {} {}: {}/{} runs passed",
        if all_passed(&results) { "PASS" } else { "FAIL" },
        scene.name,
        results.iter().filter(|r| is_pass(r)).count(),
        results.len()
    );
    Ok(Done {
        stats,
        results,
        infeasible: 0,
    })
}

/// The noise sweep: the scene with both cells' noise at each level of [`NOISE_LEVELS_PCT`],
/// on every seed; prints the RMS error (first steady-RMS criterion) against the noise and the
/// growth between levels (error ratio over noise ratio, at most 1 when the error grows no
/// faster than the noise).
fn noise_sweep(scene: &Scene<'_>, seeds: &[u64], jobs: usize) -> Result<Done, String> {
    let rms_index = scene
        .criteria
        .iter()
        .position(|c| matches!(c, sonolube::scene::Criterion::SteadyRmsError { .. }))
        .ok_or("the scene has no steady RMS criterion to sweep")?;
    let runs: Vec<Run<'_>> = NOISE_LEVELS_PCT
        .iter()
        .flat_map(|&pct| seeds.iter().map(move |&seed| with_noise(scene, pct, seed)))
        .collect();
    println!(
        "{}: sensor noise sweep, both cells at {:?} % FS, {} runs, {}",
        scene.name,
        NOISE_LEVELS_PCT,
        runs.len(),
        seeds_text(seeds)
    );
    let results = run_all(&runs, jobs, scene.name);
    println!(
        "  {:>10} {:>12} {:>12} {:>12} {:>10} {:>8}",
        "noise % FS", "RMS mean %", "RMS p90 %", "RMS worst %", "growth", "pass"
    );
    let mut previous: Option<(f64, f64)> = None;
    for (level, chunk) in NOISE_LEVELS_PCT.iter().zip(results.chunks(seeds.len())) {
        let mut values: Vec<f64> = chunk
            .iter()
            .filter_map(|r| r.as_ref().ok())
            .filter_map(|s| s.verdicts.get(rms_index).and_then(|v| value_of(v.measured)))
            .collect();
        values.sort_by(f64::total_cmp);
        let mean = values.iter().sum::<f64>() / values.len().max(1) as f64;
        let growth = previous.map_or(String::from("-"), |(noise, error)| {
            format!("{:.2}", (mean / error) / (level / noise))
        });
        println!(
            "  {:>10} {:>12.3} {:>12.3} {:>12.3} {:>10} {:>8}",
            level,
            mean,
            percentile(&values, 90.0).unwrap_or(f64::NAN),
            values.last().copied().unwrap_or(f64::NAN),
            growth,
            format!(
                "{}/{}",
                chunk.iter().filter(|r| is_pass(r)).count(),
                chunk.len()
            )
        );
        previous = Some((*level, mean));
    }
    println!(
        "  (growth: RMS error ratio over noise ratio from the level above; <= 1 grows no faster than the noise)"
    );
    let stats = criterion_stats(scene, &runs, &results);
    Ok(Done {
        stats,
        results,
        infeasible: 0,
    })
}

/// Resonance frequencies of the resonator sweep, Hz (the stack's 20-60 kHz range, seed 003
/// Table 1).
pub const RESONATOR_F0_HZ: [f64; 5] = [20e3, 28e3, 40e3, 50e3, 60e3];
/// Quality factors of the resonator sweep.
pub const RESONATOR_Q: [f64; 5] = [30.0, 60.0, 100.0, 200.0, 300.0];

/// The scene's stack on another resonator (f0, Q), within the stack's ratings.
///
/// The stack keeps its clamped capacitance C0, its ratings (V_max, I_max), its motional
/// inductance L1 = Q R1 / w0 (the modal mass over the squared force factor) and its force
/// factor N (motional current per vibration velocity), both taken from the scene at its own
/// (f0, Q, R1) and full scale (V, x_a): N = (V / R1) / (w0 x_a). On the other resonator:
/// - R1 = w0 L1 / Q (the motional branch's loss at that f0 and Q);
/// - the full-scale voltage is the largest both ratings allow at resonance, V = min(V_max,
///   I_max / |1/R1 + j w0 C0|) (the scene loader's rule, `scene-toml` hardware.rs: the drive
///   must not exceed I_max at full command); the capacitive part alone is 2 pi f0 C0 V,
///   which is what I_max = 2 pi f C V means at each f0 (1.75 A at 60 kHz and V_max);
/// - the full-scale amplitude follows from the motional current: x_a = (V / R1) / (N w0),
///   so the full-scale vibration velocity stays near I_max / N wherever the current limits;
/// - the drive runs `freq auto` (search, then track) on the complex envelope, from the
///   nominal f0;
/// - the settle limit is max(the scene's, 2 tau), tau = 2 Q / w0 = Q / (pi f0), the envelope
///   time constant (physics-notes §7);
/// - the scene's timeline (its profiles' and targets' points after t = 0, its fault events and
///   its criteria windows, and its duration) moves later by the time the search's rule
///   allows it to lock ([`sonolube::resonance::ResonanceSettings::search_lock_bound_s`]):
///   the friction loop starts at the lock, so the scene's own start-up before its first
///   step (the loop's ramp) comes after it, and a search on a slow envelope takes longer
///   (105 ms at 20 kHz, Q 300: docs/resonance.md).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Resonator {
    /// Resonance f0, Hz.
    pub resonance_hz: f64,
    /// Quality factor.
    pub quality_factor: f64,
    /// Motional resistance R1, ohm.
    pub motional_resistance_ohm: f64,
    /// Full-scale voltage, V.
    pub full_scale_voltage_v: f64,
    /// Current at full scale at resonance, A.
    pub full_scale_current_a: f64,
    /// Capacitive current at V_max, 2 pi f0 C0 V_max, A.
    pub capacitive_current_at_max_v_a: f64,
    /// Full-scale vibration amplitude, m.
    pub full_scale_amplitude_m: f64,
    /// Envelope time constant Q / (pi f0), s.
    pub time_constant_s: f64,
    /// The settle limit, s.
    pub settle_s: f64,
    /// The search's time to lock by its rule, s (f0 anywhere in its +-10 % band).
    pub search_lock_s: f64,
    /// How much later the scene's timeline runs, s: the search's time, in whole control
    /// periods.
    pub lead_s: f64,
}

/// What [`Resonator::adapt`] changes in a scene, owned for the run's borrowed `Scene`.
#[derive(Debug, Clone, PartialEq)]
pub struct Adapted {
    criteria: Vec<Criterion>,
    normal_load_n: Vec<Breakpoint>,
    sliding_velocity_m_per_s: Vec<Breakpoint>,
    target: Vec<TargetPoint>,
    faults: Vec<FaultEvent>,
}

impl Resonator {
    /// The scene's stack on the resonator (`resonance_hz`, `quality_factor`).
    pub fn of(scene: &Scene<'_>, resonance_hz: f64, quality_factor: f64) -> Result<Self, String> {
        let t = &scene.transducer;
        let a = &scene.actuator;
        let w_scene = std::f64::consts::TAU * t.resonance_hz;
        let inductance_h = t.quality_factor * t.motional_resistance_ohm / w_scene;
        let force_factor = a.full_scale_voltage_v
            / t.motional_resistance_ohm
            / (w_scene * a.full_scale_amplitude_m);
        let w0 = std::f64::consts::TAU * resonance_hz;
        let r1 = w0 * inductance_h / quality_factor;
        let admittance = (1.0 / r1).hypot(w0 * t.clamped_capacitance_f);
        // Strictly within I_max after rounding (the loader refuses a current above it).
        let voltage = a
            .max_voltage_v
            .min(a.max_current_a / admittance * (1.0 - 1e-9));
        let amplitude = voltage / r1 / (force_factor * w0);
        let tau = quality_factor / (std::f64::consts::PI * resonance_hz);
        let scene_settle = scene.criteria.iter().find_map(|c| match c {
            Criterion::Settle { within_s, .. } => Some(*within_s),
            _ => None,
        });
        let settle_s = scene_settle
            .ok_or("the scene has no settle criterion to widen")?
            .max(2.0 * tau);
        let finite = [r1, voltage, amplitude, tau, settle_s];
        if finite.iter().any(|x| !x.is_finite() || *x <= 0.0) {
            return Err(format!(
                "the scene's transducer and actuator give no resonator at {resonance_hz} Hz, Q {quality_factor}"
            ));
        }
        let mut on_resonator = *scene;
        on_resonator.transducer.resonance_hz = resonance_hz;
        on_resonator.transducer.quality_factor = quality_factor;
        on_resonator.actuator.full_scale_voltage_v = voltage;
        let stack = sonolube::station::scene_stack(&on_resonator);
        let search_lock_s = sonolube::resonance::ResonanceSettings::around(&stack)
            .search_lock_bound_s()
            .map_err(|e| {
                format!("no resonance search at {resonance_hz} Hz, Q {quality_factor}: {e:?}")
            })?;
        // The friction loop starts at the lock: the scene's own start (its t = 0, where a
        // pinned run starts its loop and ramps up before the first step) moves there. Whole
        // control periods, so that the moved events fall on the same phase of the control
        // step as the scene's.
        let period_s = 1.0 / scene.control_rate_hz;
        let lead_s = (search_lock_s / period_s).ceil() * period_s;
        Ok(Self {
            search_lock_s,
            lead_s,
            resonance_hz,
            quality_factor,
            motional_resistance_ohm: r1,
            full_scale_voltage_v: voltage,
            full_scale_current_a: voltage * admittance,
            capacitive_current_at_max_v_a: w0 * t.clamped_capacitance_f * a.max_voltage_v,
            full_scale_amplitude_m: amplitude,
            time_constant_s: tau,
            settle_s,
        })
    }

    /// `scene` on this resonator, its criteria and timeline replaced by `adapted`
    /// ([`Self::adapt`]).
    pub fn apply<'a>(&self, scene: &Scene<'a>, adapted: &'a Adapted) -> Scene<'a> {
        let mut s = adapted.apply(scene, self.lead_s);
        s.transducer.resonance_hz = self.resonance_hz;
        s.transducer.drive_hz = self.resonance_hz;
        s.transducer.quality_factor = self.quality_factor;
        s.transducer.motional_resistance_ohm = self.motional_resistance_ohm;
        s.transducer.shift.bvd_envelope = true;
        s.transducer.shift.freq_auto = true;
        s.actuator.full_scale_voltage_v = self.full_scale_voltage_v;
        s.actuator.full_scale_amplitude_m = self.full_scale_amplitude_m;
        s
    }

    /// The scene's criteria with the settle limit at [`Self::settle_s`], and its timeline
    /// from its first event on later by [`Self::lead_s`].
    pub fn adapt(&self, scene: &Scene<'_>) -> Adapted {
        shifted(scene, self.lead_s, Some(self.settle_s))
    }

    /// Why this resonator cannot do what `scene` asks within the stack's ratings, if so:
    /// the largest reduction a target asks for against the largest the plant's steady state
    /// gives at full scale ([`reachable_reduction_pct`]; the voltage there is the largest
    /// V_max and I_max allow, C0's current included).
    pub fn infeasible(&self, scene: &Scene<'_>) -> Option<String> {
        let asked = scene
            .target
            .iter()
            .filter_map(|p| match p.target {
                sonolube::protocol::Target::Reduction { reduction_mpct } => {
                    Some(f64::from(reduction_mpct) * 1e-3)
                }
                _ => None,
            })
            .fold(0.0, f64::max);
        let reach = reachable_reduction_pct(scene);
        (reach < asked).then(|| {
            format!(
                "{}: infeasible within the stack's ratings: the target asks {asked:.1} % \
                 reduction; at full scale ({:.2} V, {:.3} A of I_max {} A, C0's {:.3} A at \
                 that voltage included) the plant reaches {reach:.1} %",
                self.label(),
                self.full_scale_voltage_v,
                self.full_scale_current_a,
                scene.actuator.max_current_a,
                std::f64::consts::TAU
                    * self.resonance_hz
                    * scene.transducer.clamped_capacitance_f
                    * self.full_scale_voltage_v,
            )
        })
    }

    fn label(&self) -> String {
        format!(
            "f0 {:.0} kHz, Q {:.0}",
            self.resonance_hz / 1e3,
            self.quality_factor
        )
    }
}

impl Adapted {
    /// `scene` with these criteria and this timeline, its duration `lead_s` longer (the lead
    /// [`shifted`] was given).
    pub fn apply<'a>(&'a self, scene: &Scene<'a>, lead_s: f64) -> Scene<'a> {
        Scene {
            duration_s: scene.duration_s + lead_s,
            normal_load_n: &self.normal_load_n,
            sliding_velocity_m_per_s: &self.sliding_velocity_m_per_s,
            target: &self.target,
            faults: &self.faults,
            criteria: &self.criteria,
            ..*scene
        }
    }
}

/// `scene`'s criteria and timeline for a `freq auto` run whose friction loop starts at the
/// search's lock: every point after t = 0 of its profiles, targets and faults, and its
/// criteria windows, later by `lead` s; the settle limit replaced by `settle_s` if given.
/// [`search_lead_s`] gives the lead the search's rule needs (other sweeps that run `freq auto`
/// on a scene written for a pinned drive can use both).
pub fn shifted(scene: &Scene<'_>, lead: f64, settle_s: Option<f64>) -> Adapted {
    let later = |t: f64| if t > 0.0 { t + lead } else { t };
    let breakpoints = |points: &[Breakpoint]| -> Vec<Breakpoint> {
        points
            .iter()
            .map(|p| Breakpoint {
                t_s: later(p.t_s),
                ..*p
            })
            .collect()
    };
    Adapted {
        criteria: scene
            .criteria
            .iter()
            .map(|c| match *c {
                Criterion::Settle { band_pct, within_s } => Criterion::Settle {
                    band_pct,
                    within_s: settle_s.unwrap_or(within_s),
                },
                Criterion::SteadyRmsError {
                    max_pct,
                    from_s,
                    to_s,
                } => Criterion::SteadyRmsError {
                    max_pct,
                    from_s: from_s + lead,
                    to_s: to_s + lead,
                },
                Criterion::TrackingError {
                    max_pct,
                    from_s,
                    to_s,
                } => Criterion::TrackingError {
                    max_pct,
                    from_s: from_s + lead,
                    to_s: to_s + lead,
                },
                other => other,
            })
            .collect(),
        normal_load_n: breakpoints(scene.normal_load_n),
        sliding_velocity_m_per_s: breakpoints(scene.sliding_velocity_m_per_s),
        target: scene
            .target
            .iter()
            .map(|p| TargetPoint {
                at_s: later(p.at_s),
                ..*p
            })
            .collect(),
        faults: scene
            .faults
            .iter()
            .map(|f| FaultEvent {
                at_s: later(f.at_s),
                ..*f
            })
            .collect(),
    }
}

/// The time `freq auto`'s search needs on `scene`'s declared stack by its rule
/// ([`sonolube::resonance::ResonanceSettings::search_lock_bound_s`]), in whole control
/// periods: the lead [`shifted`] gives a scene so that its own start comes after the lock.
pub fn search_lead_s(scene: &Scene<'_>) -> Result<f64, String> {
    let stack = sonolube::station::scene_stack(scene);
    let lock_s = sonolube::resonance::ResonanceSettings::around(&stack)
        .search_lock_bound_s()
        .map_err(|e| format!("no resonance search on the scene's stack: {e:?}"))?;
    let period_s = 1.0 / scene.control_rate_hz;
    Ok((lock_s / period_s).ceil() * period_s)
}

/// The mismatch grid on `scene` driven as `drive` says ([`mismatch_runs`]).
fn mismatch_sweep(
    scene: &Scene<'_>,
    seeds: &[u64],
    drive: GridDrive,
    jobs: usize,
) -> Result<Done, String> {
    // Under `freq auto` the grid judges the friction loop from the search's lock
    // on: the scene's timeline starts the lead the search's rule needs later (a
    // scene written for a pinned drive), as the resonator sweep does.
    let lead = match drive {
        GridDrive::FreqAuto => search_lead_s(scene)?,
        GridDrive::Pinned => 0.0,
    };
    let adapted = shifted(scene, lead, None);
    let base = adapted.apply(scene, lead);
    let runs = mismatch_runs(&base, seeds, drive);
    println!(
        "{}: mismatch grid (plant mu x0.7/1/1.3, k_t x0.5/1/2, cell gain -2/0/+2 %, \
         resonance -0.5/0/+0.5 % of f0), {}, {} runs, {}, timeline {:.1} ms later \
         (the search's lock)",
        scene.name,
        drive.text(),
        runs.len(),
        seeds_text(seeds),
        lead * 1e3
    );
    sweep_runs(&base, &runs, jobs)
}

/// The resonator sweep: the scene on every (f0, Q) of [`RESONATOR_F0_HZ`] x [`RESONATOR_Q`]
/// ([`Resonator`]), on every seed; a table of the resonators and their verdicts.
fn resonator_sweep(scene: &Scene<'_>, seeds: &[u64], jobs: usize) -> Result<Done, String> {
    let mut resonators = Vec::new();
    for f0 in RESONATOR_F0_HZ {
        for q in RESONATOR_Q {
            resonators.push(Resonator::of(scene, f0, q)?);
        }
    }
    let adapted: Vec<Adapted> = resonators.iter().map(|r| r.adapt(scene)).collect();
    let mut runs = Vec::new();
    // Per resonator: its first run's index, or why it cannot work (no runs).
    let mut first_run: Vec<Result<usize, String>> = Vec::new();
    for (resonator, adapted) in resonators.iter().zip(&adapted) {
        let changed = resonator.apply(scene, adapted);
        if let Some(reason) = resonator.infeasible(&changed) {
            first_run.push(Err(reason));
            continue;
        }
        first_run.push(Ok(runs.len()));
        for &seed in seeds {
            runs.push(Run {
                label: if seeds.len() > 1 {
                    format!("{}, seed {seed}", resonator.label())
                } else {
                    resonator.label()
                },
                scene: Scene {
                    noise_seed: seed,
                    ..changed
                },
                calibration: sonolube_sim::COMMISSIONED,
            });
        }
    }
    let infeasible: Vec<&String> = first_run.iter().filter_map(|r| r.as_ref().err()).collect();
    println!(
        "{}: resonators f0 {:?} kHz x Q {:?}, drive freq auto (search, then track), full scale \
         within V_max {} V and I_max {} A, settle limit max(the scene's, 2 tau), the scene's \
         timeline later when the search's rule needs it, {} runs ({} resonators infeasible, \
         not run), {}",
        scene.name,
        RESONATOR_F0_HZ.map(|f| f / 1e3),
        RESONATOR_Q,
        scene.actuator.max_voltage_v,
        scene.actuator.max_current_a,
        runs.len(),
        infeasible.len(),
        seeds_text(seeds)
    );
    let results = run_all(&runs, jobs, "resonators");
    println!(
        "  {:>6} {:>4} {:>8} {:>7} {:>7} {:>7} {:>8} {:>8} {:>8} {:>9} {:>9} {:>9} {:>9} {:>6}  \
         measured (worst seed)",
        "f0 kHz",
        "Q",
        "tau ms",
        "R1 ohm",
        "V fs",
        "I fs A",
        "Ic@Vmax",
        "x_a um",
        "reach %",
        "search ms",
        "later ms",
        "settle ms",
        "limit ms",
        "pass",
    );
    for ((resonator, first), adapted) in resonators.iter().zip(&first_run).zip(&adapted) {
        let reach = reachable_reduction_pct(&resonator.apply(scene, adapted));
        let chunk = match first {
            Ok(k) => &results[*k..*k + seeds.len()],
            Err(_) => &results[0..0],
        };
        let passed = chunk.iter().filter(|r| is_pass(r)).count();
        let worst = chunk.iter().find(|r| !is_pass(r)).or(chunk.first());
        let at_limit_ms = worst
            .and_then(|r| r.as_ref().ok())
            .map_or(f64::NAN, |s| f64::from(s.time_at_limit_s) * 1e3);
        let measured = match first {
            Err(_) => String::from("infeasible (below)"),
            Ok(_) => worst.map_or(String::new(), |r| match r {
                Ok(summary) => summary
                    .verdicts
                    .iter()
                    .map(|v| {
                        let (name, _, unit) = super::sweep::criterion_name(&v.criterion);
                        match value_of(v.measured) {
                            Some(x) => format!("{name} {x:.2} {unit}"),
                            None => format!("{name} -"),
                        }
                    })
                    .collect::<Vec<_>>()
                    .join(", "),
                Err(error) => error.clone(),
            }),
        };
        let pass = match first {
            Ok(_) => format!("{passed}/{}", chunk.len()),
            Err(_) => String::from("infeas"),
        };
        println!(
            "  {:>6.0} {:>4.0} {:>8.3} {:>7.3} {:>7.2} {:>7.3} {:>8.3} {:>8.3} {:>8.1} {:>9.2} {:>9.2} \
             {:>9.2} {:>9.1} {:>6}  {}",
            resonator.resonance_hz / 1e3,
            resonator.quality_factor,
            resonator.time_constant_s * 1e3,
            resonator.motional_resistance_ohm,
            resonator.full_scale_voltage_v,
            resonator.full_scale_current_a,
            resonator.capacitive_current_at_max_v_a,
            resonator.full_scale_amplitude_m * 1e6,
            reach,
            resonator.search_lock_s * 1e3,
            resonator.lead_s * 1e3,
            resonator.settle_s * 1e3,
            at_limit_ms,
            pass,
            measured
        );
    }
    println!(
        "  (reach: the largest reduction the plant's steady state gives at full scale at the \
         scene's first load and speed; search: the time the resonance search's rule allows it \
         to lock, f0 anywhere in +-10 %; later: how much later the scene's timeline runs, the \
         friction loop starting at the lock; limit: time with the drive at its ceiling)"
    );
    let stats = criterion_stats(scene, &runs, &results);
    print!("{}", stats_table(&stats));
    println!("  (the settle row's limit is the scene's; each run is judged on its own, above)");
    for line in failures(&runs, &results) {
        println!("  FAIL {line}");
    }
    for reason in &infeasible {
        println!("  INFEASIBLE {reason}");
    }
    Ok(Done {
        stats,
        results,
        infeasible: infeasible.len() * seeds.len(),
    })
}

/// The largest friction reduction, %, the plant's steady-state model gives at full amplitude
/// at the scene's first load and speed (NaN when it cannot be evaluated).
fn reachable_reduction_pct(scene: &Scene<'_>) -> f64 {
    use sonolube::fx::{Q1_31, Q8_24, Q16_16};
    use sonolube::model::{AnyModel, FrictionModel, OperatingPoint};
    let (Some(load), Some(speed)) = (
        scene.normal_load_n.first(),
        scene.sliding_velocity_m_per_s.first(),
    ) else {
        return f64::NAN;
    };
    let point = OperatingPoint {
        normal_force: Q16_16::from_f64_saturating(load.value).value,
        sliding_velocity: Q8_24::from_f64_saturating(speed.value).value,
    };
    AnyModel::new(scene, &scene.plant)
        .ok()
        .and_then(|model| model.ratio(&point, Q1_31::MAX).ok())
        .map_or(f64::NAN, |ratio| 100.0 * (1.0 - ratio.to_f64()))
}

/// The envelope sweep: a scene file per point, written to `out/envelope/`, run on every seed.
fn envelope(scene: &Scene<'_>, seeds: &[u64], jobs: usize, out: &Path) -> Result<Done, String> {
    if scene.name != "reference" {
        return Err(String::from(
            "the envelope is made from the reference scene's file: run it on 'reference'",
        ));
    }
    let template = std::fs::read_to_string(scenes_dir().join("reference.toml"))
        .map_err(|e| format!("scenes/reference.toml: {e}"))?;
    let points = envelope_points(&template, scene)?;
    let dir = out.join("envelope");
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut loaded = Vec::new();
    for point in &points {
        let file = load_text(&point.toml, "envelope")?;
        let path = dir.join(format!("{}.toml", file.scene().name));
        std::fs::write(&path, &point.toml).map_err(|e| format!("{}: {e}", path.display()))?;
        loaded.push(file);
    }
    let mut runs = Vec::new();
    for (point, file) in points.iter().zip(&loaded) {
        for &seed in seeds {
            let mut run = Run::seeded(&file.scene(), seed);
            run.label = format!(
                "{} N, {} m/s, {:.1} % of {:.1} % reachable, seed {seed}",
                point.load_n, point.speed_m_per_s, point.reduction_pct, point.reachable_pct
            );
            runs.push(run);
        }
    }
    println!(
        "{}: operating envelope, loads {:?} N x speeds {:?} m/s x targets 10/35/60 % of the \
         reachable reduction, {} scene files in {}, {} runs, {}",
        scene.name,
        ENVELOPE_LOADS_N,
        ENVELOPE_SPEEDS,
        points.len(),
        dir.display(),
        runs.len(),
        seeds_text(seeds)
    );
    // What `sonolube scene --file` refuses before running is not run here either: the point
    // is listed with the reason and counted apart (the feasibility check is seed-independent).
    let outcome = run_feasible(&runs, jobs, "envelope");
    let stats = criterion_stats(scene, &outcome.runs, &outcome.results);
    print!("{}", stats_table(&stats));
    // Pass counts per (load, speed).
    println!(
        "  runs passed per load (rows, N) and speed (columns, m/s), of those the feasibility \
         check accepts (refused ones after the +):"
    );
    print!("  {:>6}", "");
    for speed in ENVELOPE_SPEEDS {
        print!(" {speed:>10}");
    }
    println!();
    let per_point = seeds.len() * super::grid::ENVELOPE_SHARES.len();
    for (row, load) in ENVELOPE_LOADS_N.iter().enumerate() {
        print!("  {load:>6}");
        for column in 0..ENVELOPE_SPEEDS.len() {
            let start = (row * ENVELOPE_SPEEDS.len() + column) * per_point;
            let chunk = &outcome.all[start..start + per_point];
            let accepted = || chunk.iter().filter(|(_, refused)| !refused);
            let ok = accepted().filter(|(r, _)| is_pass(r)).count();
            let ran = accepted().count();
            let refused = per_point - ran;
            let cell = if refused > 0 {
                format!("{ok}/{ran}+{refused}")
            } else {
                format!("{ok}/{ran}")
            };
            print!(" {cell:>10}");
        }
        println!();
    }
    for line in failures(&outcome.runs, &outcome.results) {
        println!("  FAIL {line}");
    }
    for line in &outcome.refused {
        println!("  INFEASIBLE {line}");
    }
    println!("  {}", outcome.check_measured());
    noise_prediction(scene, &points, &loaded, seeds.len(), &outcome.all);
    // What limits the misses: the same runs with both cells' noise at zero, and with cells a
    // user would size to the load (same noise in % FS).
    rerun(
        &runs,
        jobs,
        without_cell_noise,
        "without noise",
        "with both cells' noise at zero (noise_rms_pct_fs = 0)",
    );
    rerun(
        &runs,
        jobs,
        with_cells_sized_to_the_load,
        "with sized cells",
        &format!(
            "with cells sized to the load (normal {CELL_MARGIN} x the load, tangential \
             {CELL_MARGIN} x the plant's natural friction, noise still in % FS)"
        ),
    );
    let infeasible = outcome.refused.len();
    Ok(Done {
        stats,
        results: outcome.results,
        infeasible,
    })
}

/// The runs of a sweep split by the feasibility check: every run is run, so that the check
/// itself is measured (a refused run that passes is a refusal the check should not have made).
struct Feasible<'a> {
    /// The runs the check accepts.
    runs: Vec<Run<'a>>,
    /// Their results, in the order of `runs`.
    results: Vec<Result<RunSummary, String>>,
    /// Every run's result in the sweep's order, and whether the check refused it.
    all: Vec<(Result<RunSummary, String>, bool)>,
    /// `label: reason` of each refused run.
    refused: Vec<String>,
    /// How many refused runs passed all the same.
    refused_but_passed: usize,
    /// Accepted runs with a warning, and how many of them passed.
    warned: (usize, usize),
}

impl Feasible<'_> {
    /// How the feasibility check's verdicts compare with the runs: refused, warned, clean.
    fn check_measured(&self) -> String {
        let passed = self.results.iter().filter(|r| is_pass(r)).count();
        let (warned, warned_passed) = self.warned;
        format!(
            "the feasibility check (all runs run, to measure it): {} refused, {} of them passed \
             all the same; {warned} accepted with a warning, {warned_passed} passed; {} accepted \
             without one, {} passed",
            self.refused.len(),
            self.refused_but_passed,
            self.runs.len() - warned,
            passed - warned_passed
        )
    }
}

/// Runs every run of `runs` and splits them by the feasibility check
/// ([`super::sweep::refusal`], what `sonolube scene --file` refuses before running).
fn run_feasible<'a>(runs: &[Run<'a>], jobs: usize, what: &str) -> Feasible<'a> {
    use super::sweep::Feasibility;
    let checks: Vec<Feasibility> = runs
        .iter()
        .map(|r| super::sweep::feasibility(&r.scene))
        .collect();
    let results = run_all(runs, jobs, what);
    let mut outcome = Feasible {
        runs: Vec::new(),
        results: Vec::new(),
        all: Vec::new(),
        refused: Vec::new(),
        refused_but_passed: 0,
        warned: (0, 0),
    };
    for ((run, check), result) in runs.iter().zip(&checks).zip(results) {
        match check {
            Feasibility::Accepted { warnings } => {
                if *warnings > 0 {
                    outcome.warned.0 += 1;
                    outcome.warned.1 += usize::from(is_pass(&result));
                }
                outcome.runs.push(run.clone());
                outcome.results.push(result.clone());
            }
            Feasibility::Refused(why) => {
                let verdict = if is_pass(&result) {
                    outcome.refused_but_passed += 1;
                    "passed all the same"
                } else {
                    "failed, as refused"
                };
                outcome
                    .refused
                    .push(format!("{} ({verdict}): {why}", run.label));
            }
        }
        outcome
            .all
            .push((result, matches!(check, Feasibility::Refused(_))));
    }
    outcome
}

/// Below 1 N the cells' noise, not the physics, limits the steady error: for each such load
/// the RMS error the noise predicts through the loop
/// ([`sonolube::control::steady_noise_rms_error`]: the steady PI's share of the measured
/// ratio's noise and mu0's standard error after its learning, from the point's tuning, cells
/// and target) beside the measured RMS error (mean and worst of the load's runs).
fn noise_prediction(
    scene: &Scene<'_>,
    points: &[super::grid::EnvelopePoint],
    loaded: &[crate::scene_file::LoadedScene],
    seeds: usize,
    results: &[(Result<RunSummary, String>, bool)],
) {
    let Some(rms_index) = scene
        .criteria
        .iter()
        .position(|c| matches!(c, sonolube::scene::Criterion::SteadyRmsError { .. }))
    else {
        return;
    };
    println!(
        "  below 1 N, RMS error the cells' noise predicts (steady PI and mu0's learning) and measured:"
    );
    println!(
        "  {:>6} {:>14} {:>14} {:>14}",
        "load N", "predicted %", "measured mean %", "measured worst %"
    );
    for load in ENVELOPE_LOADS_N.iter().filter(|&&l| l < 1.0) {
        let mut predicted = Vec::new();
        let mut measured = Vec::new();
        for (k, (point, file)) in points.iter().zip(loaded).enumerate() {
            if point.load_n != *load {
                continue;
            }
            let point_scene = file.scene();
            let settings = sonolube::control::controller_settings(&point_scene);
            // mu0 is learned from the sliding debounce to the first target change.
            let change_s = point_scene
                .target
                .iter()
                .map(|p| p.at_s)
                .find(|&t| t > 0.0)
                .unwrap_or(point_scene.duration_s);
            let learn_s = (change_s - settings.sliding_debounce_s).max(settings.natural_learn_s);
            let friction_n = (1.0 - point.reduction_pct / 100.0) * settings.natural_prior * load;
            predicted.push(
                100.0
                    * sonolube::control::steady_noise_rms_error(
                        &settings,
                        settings.tangential_noise_n,
                        settings.normal_noise_n,
                        friction_n,
                        *load,
                        learn_s,
                    ),
            );
            for (r, _) in &results[k * seeds..(k + 1) * seeds] {
                let Ok(r) = r else { continue };
                if let Some(v) = r.verdicts.get(rms_index).and_then(|v| value_of(v.measured)) {
                    measured.push(v);
                }
            }
        }
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
        println!(
            "  {:>6} {:>14.3} {:>14.3} {:>14.3}",
            load,
            mean(&predicted),
            mean(&measured),
            measured.iter().copied().fold(f64::NAN, f64::max)
        );
    }
}

/// Runs `runs` again, each changed by `change`, and prints how many pass (`what` says how
/// they were changed) and the failures (tagged `tag`).
fn rerun<'a>(
    runs: &[Run<'a>],
    jobs: usize,
    change: fn(&Run<'a>) -> Run<'a>,
    tag: &str,
    what: &str,
) {
    let changed: Vec<Run<'a>> = runs.iter().map(change).collect();
    let outcome = run_feasible(&changed, jobs, &format!("envelope, {tag}"));
    let passed = outcome.results.iter().filter(|r| is_pass(r)).count();
    let refused = if outcome.refused.is_empty() {
        String::new()
    } else {
        format!(
            ", {} more refused by the feasibility check ({} of them passed all the same)",
            outcome.refused.len(),
            outcome.refused_but_passed
        )
    };
    println!(
        "  the same {} runs {what}: {passed}/{} pass{refused}",
        changed.len(),
        outcome.runs.len()
    );
    println!("    {}", outcome.check_measured());
    for line in failures(&outcome.runs, &outcome.results) {
        println!("  FAIL {tag}: {line}");
    }
    for line in &outcome.refused {
        println!("  INFEASIBLE {tag}: {line}");
    }
}

/// Full scale of a cell sized to the load, over the largest force it reads.
const CELL_MARGIN: f64 = 2.5;

/// `run` with its cells sized to its largest normal load `W` (the contents' top): the normal
/// cell's full scale [`CELL_MARGIN`] `W`, the tangential cell's [`CELL_MARGIN`] `mu W` with the
/// plant's mu; their noise, in % of full scale, kept.
fn with_cells_sized_to_the_load<'a>(run: &Run<'a>) -> Run<'a> {
    let mut sized = run.clone();
    let load = run.scene.contents.load_max_n;
    sized.scene.normal_cell.full_scale_n = CELL_MARGIN * load;
    sized.scene.tangential_cell.full_scale_n = CELL_MARGIN * run.scene.plant.mu * load;
    sized.label = format!("{} (cells sized to the load)", run.label);
    sized
}

/// `run` with both load cells' noise at zero, everything else kept.
fn without_cell_noise<'a>(run: &Run<'a>) -> Run<'a> {
    let mut quiet = run.clone();
    quiet.scene.normal_cell.noise_rms_pct_fs = 0.0;
    quiet.scene.tangential_cell.noise_rms_pct_fs = 0.0;
    quiet.label = format!("{} (cells without noise)", run.label);
    quiet
}

/// The built-in scenes.
pub fn builtin() -> Vec<Scene<'static>> {
    SCENES.to_vec()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_quiet_twin_of_a_run_changes_the_cells_noise_only() {
        let scene = sonolube::scene::find("reference").expect("built in");
        let run = Run::seeded(scene, 7);
        let quiet = without_cell_noise(&run);
        assert_eq!(quiet.scene.normal_cell.noise_rms_pct_fs, 0.0);
        assert_eq!(quiet.scene.tangential_cell.noise_rms_pct_fs, 0.0);
        assert!(scene.normal_cell.noise_rms_pct_fs > 0.0);
        let restored = Scene {
            normal_cell: scene.normal_cell,
            tangential_cell: scene.tangential_cell,
            ..quiet.scene
        };
        assert_eq!(restored, run.scene);
        assert_eq!(quiet.calibration, run.calibration);
    }

    #[test]
    fn sized_cells_follow_the_load_and_keep_their_noise() {
        let scene = sonolube::scene::find("reference").expect("built in");
        let run = Run::seeded(scene, 7);
        let sized = with_cells_sized_to_the_load(&run);
        let load = scene.contents.load_max_n;
        assert!((sized.scene.normal_cell.full_scale_n - 2.5 * load).abs() < 1e-12);
        let friction = scene.plant.mu * load;
        assert!((sized.scene.tangential_cell.full_scale_n - 2.5 * friction).abs() < 1e-12);
        assert_eq!(
            sized.scene.normal_cell.noise_rms_pct_fs,
            scene.normal_cell.noise_rms_pct_fs
        );
        assert_eq!(sized.scene.plant, scene.plant);
        assert_eq!(sized.scene.contents, scene.contents);
    }

    /// On the scene's own resonator the derived stack is the scene's (R1, and the full scale
    /// within 1 % where the scene's 5.25 V sits just under the current limit); elsewhere both
    /// ratings hold, and the settle limit is 2 tau once that exceeds the scene's.
    #[test]
    fn resonators_keep_the_stack_within_its_ratings() {
        let scene = sonolube::scene::find("reference").expect("built in");
        let own = Resonator::of(scene, 40e3, 100.0).unwrap();
        assert!((own.motional_resistance_ohm - 3.1).abs() < 1e-9);
        assert!((own.full_scale_voltage_v / 5.25 - 1.0).abs() < 0.01);
        let ratio = own.full_scale_amplitude_m / scene.actuator.full_scale_amplitude_m;
        assert!((ratio - own.full_scale_voltage_v / 5.25).abs() < 1e-9);
        assert!((own.time_constant_s - 0.796e-3).abs() < 1e-6);
        assert_eq!(own.settle_s, 3e-3);
        for f0 in RESONATOR_F0_HZ {
            for q in RESONATOR_Q {
                let r = Resonator::of(scene, f0, q).unwrap();
                assert!(r.full_scale_voltage_v <= scene.actuator.max_voltage_v);
                assert!(r.full_scale_current_a <= scene.actuator.max_current_a);
                assert!(
                    (r.settle_s - (2.0 * q / (std::f64::consts::PI * f0)).max(3e-3)).abs() < 1e-15
                );
                let adapted = r.adapt(scene);
                let run = r.apply(scene, &adapted);
                // The scene's start-up comes after the search's rule allows it to lock.
                assert!(r.lead_s >= r.search_lock_s && r.lead_s < r.search_lock_s + 1e-4);
                assert!((run.target[1].at_s - scene.target[1].at_s - r.lead_s).abs() < 1e-12);
                assert!((run.duration_s - scene.duration_s - r.lead_s).abs() < 1e-12);
                assert!(run.transducer.shift.freq_auto && run.transducer.shift.bvd_envelope);
                assert_eq!(run.transducer.drive_hz, f0);
                assert_eq!(run.plant, scene.plant);
            }
        }
        // The capacitive current at V_max is I_max at 60 kHz (seed 003 Table 1).
        let top = Resonator::of(scene, 60e3, 100.0).unwrap();
        assert!((top.capacitive_current_at_max_v_a - 1.75).abs() < 0.01);
    }

    #[test]
    fn seeds_parse_as_a_count_or_a_range_and_refuse_the_rest() {
        assert_eq!(parse_seeds("3"), Ok(vec![1, 2, 3]));
        assert_eq!(parse_seeds("7-9"), Ok(vec![7, 8, 9]));
        for bad in ["0", "", "x", "5-2", "-3", "1-", "0-4", "1-200000"] {
            assert!(parse_seeds(bad).is_err(), "{bad}");
        }
    }
}
