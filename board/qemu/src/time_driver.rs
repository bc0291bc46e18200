//! embassy-time driver on the Cortex-M SysTick timer of QEMU's mps2-an386.
//!
//! SysTick is a 24-bit down-counter clocked by the 25 MHz core clock. The driver runs it as a
//! one-shot countdown that is re-armed for the next alarm (or for the longest countdown when no
//! alarm is due), and keeps the total number of elapsed core cycles in `base`:
//!
//! `now = base + cycles counted in the current countdown`.
//!
//! Under `-icount shift=N` virtual time advances by 2^N ns per guest instruction, so the clock
//! (and everything timed with it) is deterministic. With `sleep=off`, a WFI jumps virtual time
//! straight to the next SysTick expiry.
//!
//! The firmware's clock leaves out the time spent in [`exclude`]: the simulated plant stands
//! for hardware that runs beside the CPU, so its own computation must not use up the control
//! period. `now = elapsed cycles - excluded cycles`.

use core::cell::RefCell;
use core::task::Waker;

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::{SCB, SYST};
use critical_section::{CriticalSection, Mutex};
use embassy_time_driver::{Driver, TICK_HZ};
use embassy_time_queue_utils::Queue;

/// Core clock of the mps2-an386 (QEMU's `SYSCLK_FRQ` for this machine), in Hz.
pub const CORE_CLOCK_HZ: u64 = 25_000_000;
const CYCLES_PER_TICK: u64 = CORE_CLOCK_HZ / TICK_HZ;
const _: () = assert!(
    CORE_CLOCK_HZ.is_multiple_of(TICK_HZ),
    "tick rate must divide the core clock"
);

/// Longest countdown the 24-bit SysTick can do, in core cycles.
const MAX_COUNTDOWN: u32 = 1 << 24;
/// Shortest countdown we program: SysTick needs a reload value of at least 1.
const MIN_COUNTDOWN: u32 = 2;
/// SCB ICSR bits: SysTick exception pending (read) and clear-pending (write).
const ICSR_PENDSTSET: u32 = 1 << 26;
const ICSR_PENDSTCLR: u32 = 1 << 25;

struct Clock {
    /// Core cycles elapsed when the current countdown started.
    base: u64,
    /// Reload value of the current countdown: it lasts `reload + 1` cycles.
    reload: u32,
    /// Time (ticks) of the next alarm, `u64::MAX` when none is set.
    alarm_at: u64,
    /// Largest time (cycles) handed out so far: `now` never goes backwards.
    last: u64,
    /// Cycles spent inside [`exclude`], left out of the firmware's clock.
    excluded: u64,
}

fn syst() -> &'static cortex_m::peripheral::syst::RegisterBlock {
    // SAFETY: SysTick is owned by this driver after `init`; reads of CVR have no side effects
    // and writes happen only inside critical sections.
    unsafe { &*SYST::PTR }
}

fn systick_pending() -> bool {
    // SAFETY: reading ICSR has no side effect.
    unsafe { (*SCB::PTR).icsr.read() & ICSR_PENDSTSET != 0 }
}

/// Cycles counted in a countdown whose counter reads `value`. A counter at 0 is at the start of
/// a countdown (just armed, or just wrapped).
fn counted(reload: u32, value: u32) -> u64 {
    if value == 0 {
        0
    } else {
        u64::from(reload) + 1 - u64::from(value)
    }
}

impl Clock {
    /// Core cycles elapsed since boot, excluded time included.
    fn elapsed_cycles(&self) -> u64 {
        let value = syst().cvr.read();
        if systick_pending() {
            // The countdown ended but the interrupt has not run yet: count the whole countdown,
            // then what the restarted counter has counted since (read again after the wrap).
            self.base + u64::from(self.reload) + 1 + counted(self.reload, syst().cvr.read())
        } else {
            self.base + counted(self.reload, value)
        }
    }

    /// The firmware's clock, in core cycles: elapsed minus excluded, never going backwards.
    fn now_cycles(&mut self) -> u64 {
        let cycles = self.elapsed_cycles().saturating_sub(self.excluded);
        self.last = self.last.max(cycles);
        self.last
    }

    fn now_ticks(&mut self) -> u64 {
        self.now_cycles() / CYCLES_PER_TICK
    }

    /// Starts a new countdown of `cycles` core cycles from now.
    fn arm(&mut self, cycles: u32) {
        let cycles = cycles.clamp(MIN_COUNTDOWN, MAX_COUNTDOWN);
        let now = self.elapsed_cycles();
        // SAFETY: inside the caller's critical section. Restart first, then drop the pending
        // interrupt: a countdown that ends between the read above and the restart (its last
        // cycles are already counted in `now`, up to the few cycles of this sequence) must not
        // leave its interrupt pending, or `on_interrupt` would count the new countdown as
        // ended and the clock would jump ahead by its length (up to 2^24 cycles).
        unsafe {
            syst().rvr.write(cycles - 1);
            syst().cvr.write(0);
            (*SCB::PTR).icsr.write(ICSR_PENDSTCLR);
        }
        self.base = now;
        self.reload = cycles - 1;
    }

    /// Sets the alarm; returns false (and sets nothing) when `at` is already due.
    fn set_alarm(&mut self, at: u64) -> bool {
        let now = self.now_cycles();
        let at_cycles = at.saturating_mul(CYCLES_PER_TICK);
        if at_cycles <= now {
            self.alarm_at = u64::MAX;
            return false;
        }
        self.alarm_at = at;
        if at != u64::MAX {
            self.arm(u32::try_from(at_cycles - now).unwrap_or(MAX_COUNTDOWN));
        }
        true
    }
}

struct SysTickDriver {
    clock: Mutex<RefCell<Clock>>,
    queue: Mutex<RefCell<Queue>>,
}

impl SysTickDriver {
    fn rearm(&self, cs: CriticalSection) {
        let mut clock = self.clock.borrow_ref_mut(cs);
        let mut queue = self.queue.borrow_ref_mut(cs);
        let mut next = queue.next_expiration(clock.now_ticks());
        while !clock.set_alarm(next) {
            next = queue.next_expiration(clock.now_ticks());
        }
    }

    fn on_interrupt(&self, cs: CriticalSection) {
        let due = {
            let mut clock = self.clock.borrow_ref_mut(cs);
            // The countdown that just ended lasted reload + 1 cycles; the hardware restarted it.
            clock.base += u64::from(clock.reload) + 1;
            let now = clock.now_ticks();
            if now >= clock.alarm_at {
                true
            } else {
                // Not due yet (alarm beyond one countdown, or no alarm): count down the rest.
                let remaining = match clock.alarm_at {
                    u64::MAX => MAX_COUNTDOWN,
                    at => u32::try_from(
                        at.saturating_mul(CYCLES_PER_TICK)
                            .saturating_sub(clock.now_cycles()),
                    )
                    .unwrap_or(MAX_COUNTDOWN),
                };
                clock.arm(remaining);
                false
            }
        };
        if due {
            self.rearm(cs);
            let mut clock = self.clock.borrow_ref_mut(cs);
            if clock.alarm_at == u64::MAX {
                clock.arm(MAX_COUNTDOWN);
            }
        }
    }
}

impl Driver for SysTickDriver {
    fn now(&self) -> u64 {
        critical_section::with(|cs| self.clock.borrow_ref_mut(cs).now_ticks())
    }

    fn schedule_wake(&self, at: u64, waker: &Waker) {
        critical_section::with(|cs| {
            let changed = self.queue.borrow_ref_mut(cs).schedule_wake(at, waker);
            if changed {
                self.rearm(cs);
            }
        })
    }
}

embassy_time_driver::time_driver_impl!(static DRIVER: SysTickDriver = SysTickDriver {
    clock: Mutex::new(RefCell::new(Clock { base: 0, reload: MAX_COUNTDOWN - 1, alarm_at: u64::MAX, last: 0, excluded: 0 })),
    queue: Mutex::new(RefCell::new(Queue::new())),
});

/// Core cycles (25 MHz) since boot. Under `-icount shift=N` one cycle is 40 ns of virtual time,
/// that is 40 / 2^N guest instructions.
pub fn cycles() -> u64 {
    critical_section::with(|cs| DRIVER.clock.borrow_ref_mut(cs).now_cycles())
}

/// Runs `work` with the firmware's clock stopped, interrupts masked: the time it takes is
/// left out of `now`, of every timer and of [`cycles`]. For the simulated plant only. `work`
/// must take less than one full countdown (2^24 cycles, 0.67 s of virtual time).
pub fn exclude<R>(work: impl FnOnce() -> R) -> R {
    critical_section::with(|cs| {
        let start = {
            let mut clock = DRIVER.clock.borrow_ref_mut(cs);
            // No countdown may end twice while interrupts are masked: start the longest one.
            clock.arm(MAX_COUNTDOWN);
            clock.elapsed_cycles()
        };
        let result = work();
        {
            let mut clock = DRIVER.clock.borrow_ref_mut(cs);
            let spent = clock.elapsed_cycles().saturating_sub(start);
            clock.excluded += spent;
        }
        DRIVER.rearm(cs);
        result
    })
}

/// Core cycles spent inside [`exclude`] since boot.
pub fn excluded_cycles() -> u64 {
    critical_section::with(|cs| DRIVER.clock.borrow_ref(cs).excluded)
}

/// Starts SysTick as the time base. Call once, before the executor runs.
pub fn init(mut syst: SYST) {
    syst.disable_counter();
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(MAX_COUNTDOWN - 1);
    syst.clear_current();
    syst.enable_interrupt();
    syst.enable_counter();
}

#[cortex_m_rt::exception]
fn SysTick() {
    critical_section::with(|cs| DRIVER.on_interrupt(cs));
}
