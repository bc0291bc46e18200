//! The two executors: a thread-mode loop that sleeps with WFI, and the control executor,
//! polled from a software-pended interrupt at a higher priority ([`crate::irq::CONTROL`]).
//!
//! QEMU implements WFE as a no-op, so embassy's stock thread executor (poll, then WFE) spins and
//! burns host time in a way that depends on the host. WFI really halts the virtual CPU until an
//! interrupt is pending; with `-icount sleep=off` QEMU then jumps virtual time to the next timer
//! event, which makes runs byte-identical and fast.
//!
//! The control task runs in the interrupt executor, so a long command or telemetry line in the
//! thread executor delays it by at most an interrupt entry, never by a whole task poll.

use core::sync::atomic::{AtomicBool, Ordering};

use cortex_m::peripheral::NVIC;
use embassy_executor::{SendSpawner, Spawner, raw};
use static_cell::StaticCell;

use crate::irq::{CONTROL, Irq};

/// Core cycles (firmware clock) the CPU slept in WFI since boot.
static IDLE_CYCLES: critical_section::Mutex<core::cell::Cell<u64>> =
    critical_section::Mutex::new(core::cell::Cell::new(0));

/// Core cycles the CPU has slept in WFI since boot (firmware clock: the simulated plant's
/// time is not in it): the CPU load is the rest.
pub fn idle_cycles() -> u64 {
    critical_section::with(|cs| IDLE_CYCLES.borrow(cs).get())
}

/// Set when a thread-mode task was woken and the executor must poll again.
static WORK_PENDING: AtomicBool = AtomicBool::new(true);

/// Context of the control executor's pender (any non-null value; the thread executor's is
/// null).
const CONTROL_CONTEXT: usize = 1 + CONTROL as usize;

static CONTROL_EXECUTOR: StaticCell<raw::Executor> = StaticCell::new();
/// The control executor, once started.
static CONTROL_READY: AtomicBool = AtomicBool::new(false);
static mut CONTROL_REF: Option<&'static raw::Executor> = None;

/// Called by embassy when a task is woken (from a task or an interrupt handler).
#[unsafe(export_name = "__pender")]
fn pender(context: *mut ()) {
    if context as usize == CONTROL_CONTEXT {
        NVIC::pend(Irq(CONTROL));
    } else {
        WORK_PENDING.store(true, Ordering::Release);
    }
}

/// Starts the control executor and returns its spawner. Call once, from `main`.
pub fn start_control() -> Option<SendSpawner> {
    let executor = CONTROL_EXECUTOR.try_init(raw::Executor::new(CONTROL_CONTEXT as *mut ()))?;
    // SAFETY: written once here, before the interrupt that reads it is enabled.
    unsafe { CONTROL_REF = Some(executor) };
    CONTROL_READY.store(true, Ordering::Release);
    crate::irq::enable(CONTROL);
    NVIC::pend(Irq(CONTROL));
    Some(executor.spawner().make_send())
}

/// The control interrupt: polls the control executor.
pub fn on_control_interrupt() {
    if !CONTROL_READY.load(Ordering::Acquire) {
        return;
    }
    // SAFETY: set once before the interrupt was enabled, never changed after.
    if let Some(executor) = unsafe { CONTROL_REF } {
        // SAFETY: `poll` is only ever called from this interrupt, which does not nest.
        unsafe { executor.poll() };
    }
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
        critical_section::with(|cs| {
            if !WORK_PENDING.swap(false, Ordering::AcqRel) {
                let asleep = crate::time_driver::cycles();
                cortex_m::asm::wfi();
                let slept = crate::time_driver::cycles().saturating_sub(asleep);
                let idle = IDLE_CYCLES.borrow(cs);
                idle.set(idle.get() + slept);
            }
        });
    }
}
