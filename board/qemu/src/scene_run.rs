//! Runs a scene closed loop on the firmware: the simulated plant, the sensing chain and the
//! controller of `sonolube::sim` (the same code as `sonolube scene` on the host), then prints the
//! run's verdicts.
//!
//! Simulated time is the plant's own (one control period per step), so the plant's cost does
//! not count against the control rate. Only the control phase (sensing, estimate, model,
//! controller, drive command) is timed, with the SysTick core-cycle clock: under
//! `-icount shift=0` one core cycle of the 25 MHz clock is 40 guest instructions.

use sonolube::scene::Scene;
use sonolube::sim::{ClosedLoop, Measured};

use crate::time_driver;

/// Guest instructions per 25 MHz core cycle under `-icount shift=0` (40 ns per cycle).
const INSTRUCTIONS_PER_CYCLE: u64 = 40;

/// Runs `scene` to its end; returns whether every criterion passed.
pub async fn run(scene: &'static Scene<'static>) -> bool {
    let mut closed_loop = match ClosedLoop::new(scene) {
        Ok(closed_loop) => closed_loop,
        Err(error) => {
            defmt::error!("scene {=str} cannot run: {}", scene.name, error);
            return false;
        }
    };
    defmt::info!(
        "scene {=str}: {=u32} steps at {=f64} Hz",
        scene.name,
        scene.step_count(),
        scene.control_rate_hz
    );
    let (mut steps, mut total, mut longest) = (0u64, 0u64, 0u64);
    while !closed_loop.is_finished() {
        if closed_loop.plant_phase().is_none() {
            break;
        }
        let start = time_driver::cycles();
        let control = closed_loop.control_phase();
        let cycles = time_driver::cycles().saturating_sub(start);
        if control.is_none() || closed_loop.finish_step().is_none() {
            break;
        }
        steps += 1;
        total += cycles;
        longest = longest.max(cycles);
        // Let the heartbeat and the watchdog keeper run between steps.
        embassy_futures::yield_now().await;
    }
    let summary = closed_loop.summary();
    if let Some(mean) = (total * INSTRUCTIONS_PER_CYCLE).checked_div(steps) {
        defmt::info!(
            "control phase: mean {=u64} max {=u64} instructions per step ({=u64} steps, -icount shift=0)",
            mean,
            longest * INSTRUCTIONS_PER_CYCLE,
            steps
        );
    }
    for verdict in &summary.verdicts {
        let passed = if verdict.passed { "PASS" } else { "FAIL" };
        match verdict.measured {
            Measured::Seconds(s) => {
                defmt::info!(
                    "{=str} {} measured {=f32} ms",
                    passed,
                    verdict.criterion,
                    s * 1e3
                )
            }
            Measured::Percent(p) => {
                defmt::info!("{=str} {} measured {=f32} %", passed, verdict.criterion, p)
            }
            Measured::Periods(n) => {
                defmt::info!(
                    "{=str} {} measured {=u32} periods",
                    passed,
                    verdict.criterion,
                    n
                )
            }
            other => defmt::info!("{=str} {} measured {}", passed, verdict.criterion, other),
        }
    }
    let passed = summary.passed();
    defmt::info!(
        "scene {=str}: {=str} ({=u32} steps judged)",
        scene.name,
        if passed { "PASS" } else { "FAIL" },
        summary.steps
    );
    passed
}
