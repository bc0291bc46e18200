//! What a scripted scene run prints at its end: each criterion's verdict and value (the same
//! metrics as `sonolube scene` on the host), the control step's cost and the CPU load.
//!
//! The control part of a step is timed with the SysTick core-cycle clock of the 25 MHz
//! mps2-an386. Under `-icount shift=N` one guest instruction takes 2^N ns of virtual time and
//! one core cycle 40 ns, so one cycle is 40 / 2^N instructions: at shift 2 (250 M
//! instructions/s, the runner's default) a 10 kHz period holds 25,000 instructions, at shift 3
//! (125 M/s) 12,500; the G474 at 170 MHz does about 125-170 M instructions/s. The CPU load counts every cycle the CPU did not sleep in WFI (control, console,
//! telemetry, executors), the simulated plant excluded ([`crate::time_driver::exclude`]).

use sonolube_app::control::LoopStats;
use sonolube_sim::{Measured, RunSummary};

use crate::time_driver::CORE_CLOCK_HZ;

/// Prints the control step's cost and the CPU load; `icount_shift` converts cycles to guest
/// instructions when the runner told it.
pub fn cpu(stats: &LoopStats, busy_cycles: u64, elapsed_cycles: u64, icount_shift: Option<u8>) {
    let mean = stats.control_cycles_mean();
    let max = u64::from(stats.control_cycles_max);
    let ns = |cycles: u64| cycles * 1_000_000_000 / CORE_CLOCK_HZ;
    defmt::info!(
        "control step: mean {=u64} ns, max {=u64} ns over {=u32} steps, {=u32} overruns",
        ns(mean),
        ns(max),
        stats.steps,
        stats.overruns
    );
    if let Some(shift) = icount_shift {
        let per_cycle = instructions_per_cycle(shift);
        defmt::info!(
            "control step: mean {=u64} max {=u64} instructions (-icount shift={=u8}, {=u64} instructions per cycle)",
            mean * per_cycle,
            max * per_cycle,
            shift,
            per_cycle
        );
    }
    if let Some(permille) = (busy_cycles * 1000).checked_div(elapsed_cycles) {
        defmt::info!(
            "cpu load: {=u64}.{=u64} % busy over {=u64} us (control, console, telemetry, executors; plant excluded)",
            permille / 10,
            permille % 10,
            ns(elapsed_cycles) / 1000
        );
    }
}

/// Guest instructions per 25 MHz core cycle (40 ns) under `-icount shift=N` (2^N ns per
/// instruction).
fn instructions_per_cycle(shift: u8) -> u64 {
    40u64 >> shift.min(5)
}

/// Prints what the simulated plant and the judge cost per step (left out of the firmware's
/// clock), for the record: it is QEMU's work, not the firmware's.
pub fn plant(stats: &LoopStats, excluded_cycles: u64, icount_shift: Option<u8>) {
    if let (Some(shift), Some(per_step)) = (
        icount_shift,
        excluded_cycles.checked_div(u64::from(stats.steps)),
    ) {
        defmt::info!(
            "simulated plant and judge: {=u64} instructions per step (not firmware time)",
            per_step * instructions_per_cycle(shift)
        );
    }
}

/// Prints each verdict and the scene's; returns whether every criterion passed.
pub fn verdicts(scene: &str, summary: &RunSummary) -> bool {
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
                    "{=str} {} measured {=u32} period(s)",
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
        scene,
        if passed { "PASS" } else { "FAIL" },
        summary.steps
    );
    passed
}
