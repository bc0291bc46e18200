//! Many runs of scenes at once: the parallel runner, the per-criterion statistics (pass rate,
//! percentiles, worst case and the run it came from) and their text.
//!
//! A run here writes no CSV or SVG: it keeps the judge's [`RunSummary`] only. Runs are shared
//! out over every core (`std::thread::available_parallelism`, scoped threads taking the next
//! run from an atomic counter) and their results are put back in the order of the runs, so the
//! text is the same whatever the number of threads. A progress bar goes to stderr, only when it
//! is a terminal.

use std::io::{IsTerminal as _, Write as _};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use sonolube::scene::{Criterion, Scene};
use sonolube_sim::{COMMISSIONED, CellCalibration, ClosedLoop, Measured, RunSummary};

use super::report::num;

/// One run of a sweep: a scene (possibly changed from a shipped one), how its cells are
/// calibrated, and a label naming what was changed (`seed 12`, `mu x1.3 k_t x0.5 ...`).
#[derive(Debug, Clone)]
pub struct Run<'a> {
    /// What this run changed, for the worst-case column.
    pub label: String,
    /// The scene as run.
    pub scene: Scene<'a>,
    /// The cells' calibration before the run.
    pub calibration: CellCalibration,
}

impl<'a> Run<'a> {
    /// `scene` on noise seed `seed`, commissioned cells.
    pub fn seeded(scene: &Scene<'a>, seed: u64) -> Self {
        Run {
            label: format!("seed {seed}"),
            scene: Scene {
                noise_seed: seed,
                ..*scene
            },
            calibration: COMMISSIONED,
        }
    }
}

/// Runs `scene` to its end with its own controller settings, the model variant `sonolube
/// scene` runs it with ([`crate::speed::table_rs::select_on_host`]: the firmware's choice for
/// a built-in scene, one measured on the host for a scene file) and `calibration`; the
/// summary, or why it cannot run.
pub fn summary_of(scene: &Scene<'_>, calibration: CellCalibration) -> Result<RunSummary, String> {
    let selection = crate::speed::table_rs::select_on_host(scene)?;
    let mut sim = ClosedLoop::with_selection_calibrated(scene, selection, calibration)
        .map_err(|e| format!("cannot build the run: {e:?}"))?;
    Ok(sim.run())
}

/// What the feasibility check says of a scene before it runs.
pub enum Feasibility {
    /// Accepted, with this many warnings.
    Accepted { warnings: usize },
    /// Refused, with the reason.
    Refused(String),
}

/// The feasibility check of `scene` against its controller's model, as `sonolube scene
/// --file` applies it before running (`sonolube::scene::feasibility`); a run that cannot be
/// built is refused with the reason.
pub fn feasibility(scene: &Scene<'_>) -> Feasibility {
    let selection = match crate::speed::table_rs::select_on_host(scene) {
        Ok(selection) => selection,
        Err(error) => return Feasibility::Refused(error),
    };
    let sim = match ClosedLoop::with_selection(scene, selection) {
        Ok(sim) => sim,
        Err(error) => return Feasibility::Refused(format!("cannot build the run: {error:?}")),
    };
    let check = sonolube::scene::feasibility::check(scene, sim.station().model());
    match check.refusal() {
        Some(refusal) => Feasibility::Refused(refusal.to_string()),
        None => Feasibility::Accepted {
            warnings: check.warnings().count(),
        },
    }
}

/// Threads a sweep uses: every core, or `SONOLUBE_JOBS` when set to a positive number.
pub fn threads() -> usize {
    std::env::var("SONOLUBE_JOBS")
        .ok()
        .and_then(|v| v.parse::<usize>().ok())
        .filter(|&n| n > 0)
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}

/// Runs every run of `runs` over `threads` threads; results in the order of `runs`. `what`
/// names the sweep on the progress bar.
pub fn run_all(runs: &[Run<'_>], threads: usize, what: &str) -> Vec<Result<RunSummary, String>> {
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<Result<RunSummary, String>>>> =
        Mutex::new(vec![None; runs.len()]);
    let bar = Progress::new(what, runs.len());
    std::thread::scope(|scope| {
        for _ in 0..threads.clamp(1, runs.len().max(1)) {
            scope.spawn(|| {
                loop {
                    let index = next.fetch_add(1, Ordering::Relaxed);
                    let Some(run) = runs.get(index) else { break };
                    let result = summary_of(&run.scene, run.calibration);
                    if let Ok(mut all) = results.lock() {
                        all[index] = Some(result);
                    }
                    bar.show(done.fetch_add(1, Ordering::Relaxed) + 1);
                }
            });
        }
    });
    bar.finish();
    results
        .into_inner()
        .unwrap_or_default()
        .into_iter()
        .map(|r| r.unwrap_or_else(|| Err(String::from("the run's thread ended early"))))
        .collect()
}

/// A progress bar on stderr, drawn only when stderr is a terminal.
struct Progress {
    what: String,
    total: usize,
    tty: bool,
    started: Instant,
    drawn: Mutex<usize>,
}

impl Progress {
    fn new(what: &str, total: usize) -> Self {
        Progress {
            what: what.to_string(),
            total,
            tty: std::io::stderr().is_terminal() && total > 1,
            started: Instant::now(),
            drawn: Mutex::new(0),
        }
    }

    fn show(&self, done: usize) {
        if !self.tty {
            return;
        }
        // Redraw on each whole percent only.
        let Ok(mut drawn) = self.drawn.lock() else {
            return;
        };
        let percent = done * 100 / self.total.max(1);
        if percent == *drawn && done != self.total {
            return;
        }
        *drawn = percent;
        let width = 30;
        let filled = done * width / self.total.max(1);
        let elapsed = self.started.elapsed().as_secs_f64();
        let left = if done > 0 {
            elapsed * (self.total - done) as f64 / done as f64
        } else {
            0.0
        };
        let mut err = std::io::stderr().lock();
        let _ = write!(
            err,
            "\r{} [{}{}] {done}/{} {elapsed:.0} s, ~{left:.0} s left ",
            self.what,
            "#".repeat(filled),
            ".".repeat(width - filled),
            self.total
        );
        let _ = err.flush();
    }

    fn finish(&self) {
        if self.tty {
            let mut err = std::io::stderr().lock();
            let _ = write!(err, "\r{}\r", " ".repeat(self.what.len() + 70));
            let _ = err.flush();
        }
    }
}

/// The unit a criterion's values are shown in, and their value in it (`None` when the run
/// measured no value: never settled, undefined, nothing to measure).
pub fn value_of(measured: Measured) -> Option<f64> {
    match measured {
        Measured::Seconds(s) => Some(f64::from(s) * 1e3),
        Measured::Percent(p) => Some(f64::from(p)),
        Measured::Periods(n) => Some(f64::from(n)),
        Measured::Never | Measured::Undefined | Measured::Nothing => None,
    }
}

/// A criterion's short name, limit and unit: `("settle", 3.0, "ms")`.
pub fn criterion_name(criterion: &Criterion) -> (&'static str, f64, &'static str) {
    match *criterion {
        Criterion::Settle { within_s, .. } => ("settle", within_s * 1e3, "ms"),
        Criterion::Overshoot { max_pct } => ("overshoot", max_pct, "%"),
        Criterion::SteadyRmsError { max_pct, .. } => ("RMS error", max_pct, "%"),
        Criterion::TrackingError { max_pct, .. } => ("|error|", max_pct, "%"),
        Criterion::FaultReaction { within_periods } => {
            ("fault reaction", f64::from(within_periods), "periods")
        }
    }
}

/// The statistics of one criterion over the runs of a sweep.
#[derive(Debug, Clone)]
pub struct CriterionStats {
    /// Short name (`settle`).
    pub name: &'static str,
    /// The criterion's limit, in `unit`.
    pub limit: f64,
    /// `ms`, `%` or `periods`.
    pub unit: &'static str,
    /// Runs that passed it.
    pub passed: usize,
    /// Runs judged.
    pub runs: usize,
    /// Measured values, sorted ascending (runs with no value are left out and failed).
    pub values: Vec<f64>,
    /// The worst run: its value (`None`: no value) and label.
    pub worst: Option<(Option<f64>, String)>,
}

impl CriterionStats {
    /// The `p`-th percentile (0-100) of the measured values, nearest rank; `None` without
    /// values.
    pub fn percentile(&self, p: f64) -> Option<f64> {
        percentile(&self.values, p)
    }
}

/// The `p`-th percentile (0-100) of ascending `sorted`, nearest rank; `None` when empty.
pub fn percentile(sorted: &[f64], p: f64) -> Option<f64> {
    if sorted.is_empty() || !(0.0..=100.0).contains(&p) {
        return None;
    }
    let rank = ((p / 100.0) * sorted.len() as f64).ceil() as usize;
    sorted.get(rank.clamp(1, sorted.len()) - 1).copied()
}

/// The statistics of each criterion of a sweep of one scene: `results[i]` is the run of
/// `runs[i]`. Runs that could not run count as failed on every criterion.
pub fn criterion_stats(
    scene: &Scene<'_>,
    runs: &[Run<'_>],
    results: &[Result<RunSummary, String>],
) -> Vec<CriterionStats> {
    scene
        .criteria
        .iter()
        .enumerate()
        .map(|(index, criterion)| {
            let (name, limit, unit) = criterion_name(criterion);
            let mut stats = CriterionStats {
                name,
                limit,
                unit,
                passed: 0,
                runs: results.len(),
                values: Vec::new(),
                worst: None,
            };
            let mut worst_key = f64::NEG_INFINITY;
            for (run, result) in runs.iter().zip(results) {
                let verdict = result.as_ref().ok().and_then(|s| s.verdicts.get(index));
                let value = verdict.and_then(|v| value_of(v.measured));
                if verdict.is_some_and(|v| v.passed) {
                    stats.passed += 1;
                }
                if let Some(v) = value {
                    stats.values.push(v);
                }
                // A run with no value is worse than any value.
                let key = value.unwrap_or(f64::INFINITY);
                if key > worst_key {
                    worst_key = key;
                    stats.worst = Some((value, run.label.clone()));
                }
            }
            stats.values.sort_by(f64::total_cmp);
            stats
        })
        .collect()
}

/// The table of a sweep: one line per criterion with its pass rate, percentiles and worst run.
pub fn stats_table(stats: &[CriterionStats]) -> String {
    let mut text = format!(
        "  {:<26} {:>9} {:>9} {:>9} {:>9}  {}\n",
        "criterion", "pass", "p50", "p90", "p99", "worst (run)"
    );
    for s in stats {
        let cell = |v: Option<f64>| v.map_or(String::from("-"), |v| format!("{v:.3}"));
        let worst = match &s.worst {
            Some((Some(v), label)) => format!("{v:.3} {} ({label})", s.unit),
            Some((None, label)) => format!("no value ({label})"),
            None => String::from("-"),
        };
        text.push_str(&format!(
            "  {:<26} {:>9} {:>9} {:>9} {:>9}  {worst}\n",
            format!("{} (max {} {})", s.name, num(s.limit), s.unit),
            format!("{}/{}", s.passed, s.runs),
            cell(s.percentile(50.0)),
            cell(s.percentile(90.0)),
            cell(s.percentile(99.0)),
        ));
    }
    text
}

/// Whether every run passed every criterion.
pub fn all_passed(results: &[Result<RunSummary, String>]) -> bool {
    results
        .iter()
        .all(|r| r.as_ref().is_ok_and(RunSummary::passed))
}

/// The labels of the runs that failed, with the failed criteria (or why they could not run).
pub fn failures(runs: &[Run<'_>], results: &[Result<RunSummary, String>]) -> Vec<String> {
    runs.iter()
        .zip(results)
        .filter_map(|(run, result)| match result {
            Err(error) => Some(format!("{}: {error}", run.label)),
            Ok(summary) if !summary.passed() => {
                let failed: Vec<String> = summary
                    .verdicts
                    .iter()
                    .filter(|v| !v.passed)
                    .map(|v| {
                        let (name, limit, unit) = criterion_name(&v.criterion);
                        let value = value_of(v.measured)
                            .map_or(String::from("no value"), |x| format!("{x:.3}"));
                        format!("{name} {value} (max {} {unit})", num(limit))
                    })
                    .collect();
                Some(format!("{}: {}", run.label, failed.join(", ")))
            }
            Ok(_) => None,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use sonolube::scene::find;

    #[test]
    fn percentiles_are_nearest_rank() {
        let v: Vec<f64> = (1..=100).map(f64::from).collect();
        assert_eq!(percentile(&v, 50.0), Some(50.0));
        assert_eq!(percentile(&v, 90.0), Some(90.0));
        assert_eq!(percentile(&v, 99.0), Some(99.0));
        assert_eq!(percentile(&v, 100.0), Some(100.0));
        assert_eq!(percentile(&v, 0.0), Some(1.0));
        assert_eq!(percentile(&[], 50.0), None);
        assert_eq!(percentile(&[2.0], 150.0), None);
    }

    #[test]
    fn a_parallel_sweep_gives_the_results_of_serial_runs_in_order() {
        let scene = find("reference").expect("built in");
        let runs: Vec<Run<'_>> = (1..=4).map(|seed| Run::seeded(scene, seed)).collect();
        let parallel = run_all(&runs, 3, "test");
        for (run, result) in runs.iter().zip(&parallel) {
            let serial = summary_of(&run.scene, run.calibration).expect("runs");
            assert_eq!(result.as_ref().expect("runs"), &serial, "{}", run.label);
        }
        // Different seeds give different noise, hence different measured values.
        let rms = |r: &Result<RunSummary, String>| r.as_ref().expect("runs").verdicts[2].measured;
        assert_ne!(rms(&parallel[0]), rms(&parallel[1]));
    }

    #[test]
    fn the_stats_count_failures_and_name_the_worst_run() {
        let scene = find("reference").expect("built in");
        // A 0.1 ms settle limit no run meets.
        let strict = [Criterion::Settle {
            band_pct: 2.0,
            within_s: 1e-4,
        }];
        let strict_scene = Scene {
            criteria: &strict,
            ..*scene
        };
        let runs: Vec<Run<'_>> = (1..=3).map(|s| Run::seeded(&strict_scene, s)).collect();
        let results = run_all(&runs, 2, "test");
        let stats = criterion_stats(&strict_scene, &runs, &results);
        assert_eq!(stats.len(), 1);
        assert_eq!((stats[0].passed, stats[0].runs), (0, 3));
        assert!(!all_passed(&results));
        assert_eq!(failures(&runs, &results).len(), 3);
        let (worst, label) = stats[0].worst.clone().expect("a worst run");
        let top = stats[0].values.last().copied();
        assert_eq!(worst, top, "{label}");
        assert!(label.starts_with("seed "));
    }
}
