//! A thread-mode executor loop that sleeps with WFI.
//!
//! QEMU implements WFE as a no-op, so embassy's stock thread executor (poll, then WFE) spins and
//! burns host time in a way that depends on the host. WFI really halts the virtual CPU until an
//! interrupt is pending; with `-icount sleep=off` QEMU then jumps virtual time to the next timer
//! event, which makes runs byte-identical and fast.

use core::sync::atomic::{AtomicBool, Ordering};

use embassy_executor::{Spawner, raw};

/// Set when a task was woken and the executor must poll again.
static WORK_PENDING: AtomicBool = AtomicBool::new(true);

/// Called by embassy when a task is woken (from a task or an interrupt handler).
#[unsafe(export_name = "__pender")]
fn pender(_context: *mut ()) {
    WORK_PENDING.store(true, Ordering::Release);
}

/// Runs `executor` forever after `init` has spawned the first tasks.
pub fn run(executor: &'static raw::Executor, init: impl FnOnce(Spawner)) -> ! {
    init(executor.spawner());
    loop {
        // SAFETY: `poll` is only ever called from this loop, in thread mode.
        unsafe { executor.poll() };
        // Decide to sleep with interrupts masked: a wake-up from an interrupt between the check
        // and the WFI leaves that interrupt pending, and a pending interrupt ends the WFI even
        // while PRIMASK masks it.
        cortex_m::interrupt::free(|_| {
            if !WORK_PENDING.swap(false, Ordering::AcqRel) {
                cortex_m::asm::wfi();
            }
        });
    }
}
