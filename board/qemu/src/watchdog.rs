//! The mps2-an386's CMSDK APB watchdog (0x4000_8000), as QEMU emulates it.
//!
//! The counter runs at the 25 MHz peripheral clock. When it reaches zero the watchdog raises its
//! interrupt (wired to NMI on this machine) and reloads; if the interrupt is still set at the
//! next zero, it resets the machine. So a firmware that stops feeding gets an NMI after one
//! timeout (the handler makes the drive safe and leaves a mark in RAM that survives the reset)
//! and a reset after two. Feeding clears the interrupt and reloads the counter.

use core::sync::atomic::{AtomicBool, Ordering};

const BASE: usize = 0x4000_8000;
const LOAD: usize = BASE;
const CONTROL: usize = BASE + 0x08;
const INTCLR: usize = BASE + 0x0C;
const LOCK: usize = BASE + 0xC00;

const CONTROL_INTEN: u32 = 1 << 0;
const CONTROL_RESEN: u32 = 1 << 1;
const UNLOCK_KEY: u32 = 0x1ACC_E551;

/// Peripheral clock of the watchdog, in Hz.
const CLOCK_HZ: u32 = 25_000_000;

/// Value left in RAM by the NMI handler just before the watchdog resets the machine.
const RESET_MARK: u32 = 0x5744_5254; // "WDRT"

/// RAM that the startup code does not initialise, so the mark survives a reset.
#[unsafe(link_section = ".uninit.sonolube_watchdog")]
static mut MARK: core::mem::MaybeUninit<u32> = core::mem::MaybeUninit::uninit();

static RUNNING: AtomicBool = AtomicBool::new(false);

fn write(address: usize, value: u32) {
    // SAFETY: a watchdog register address of this machine, written only by this module.
    unsafe { core::ptr::write_volatile(address as *mut u32, value) }
}

fn unlocked(f: impl FnOnce()) {
    critical_section::with(|_| {
        write(LOCK, UNLOCK_KEY);
        f();
        write(LOCK, 0);
    });
}

/// Whether the previous run ended in a watchdog reset; clears the mark.
pub fn take_reset_mark() -> bool {
    critical_section::with(|_| {
        let mark = core::ptr::addr_of_mut!(MARK);
        // SAFETY: MARK is only touched here and in the NMI handler, inside critical sections or
        // with the firmware stopped; any bit pattern is a valid u32.
        unsafe {
            let was = (*mark).assume_init_read() == RESET_MARK;
            (*mark).write(0);
            was
        }
    })
}

/// Starts the watchdog: an NMI after `timeout_ms` without a feed, a reset after twice that.
pub fn start(timeout_ms: u32) {
    let load = (CLOCK_HZ / 1000).saturating_mul(timeout_ms.max(1));
    unlocked(|| {
        write(LOAD, load);
        write(CONTROL, CONTROL_INTEN | CONTROL_RESEN);
    });
    RUNNING.store(true, Ordering::Release);
}

/// Feeds the watchdog: clears its interrupt and reloads the counter.
pub fn feed() {
    if RUNNING.load(Ordering::Acquire) {
        unlocked(|| write(INTCLR, 1));
    }
}

#[cortex_m_rt::exception]
unsafe fn NonMaskableInt() {
    // The loop stopped feeding: the drive goes safe now, the reset follows one timeout later.
    // No logging here: an NMI can interrupt the logger itself. The next boot reports the reset.
    crate::drive::force_safe();
    // SAFETY: see take_reset_mark; the firmware is about to be reset.
    unsafe { (*core::ptr::addr_of_mut!(MARK)).write(RESET_MARK) };
}
