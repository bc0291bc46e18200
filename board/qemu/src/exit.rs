//! Ending a QEMU run: drive output safe first, then a semihosting exit code.
//!
//! QEMU runs with `-semihosting-config enable=on,target=native`, so the code given to
//! `SYS_EXIT_EXTENDED` becomes the exit status of `qemu-system-arm` (and of `cargo run`).

use core::sync::atomic::{AtomicBool, Ordering};

use crate::drive;

/// Exit status of a run whose self-checks all passed.
pub const PASS: i32 = 0;
/// Exit status of a run whose self-check failed.
pub const SELFCHECK_FAILED: i32 = 1;
/// Exit status of the boot that follows a watchdog reset.
pub const WATCHDOG_RESET: i32 = 2;
/// Exit status after a HardFault or an unexpected exception.
pub const FAULT: i32 = 3;
/// Exit status of a run whose power was cut on purpose (`cut=N`, see `flash.rs`).
pub const POWER_CUT: i32 = 4;
/// Exit status after a panic (the same number a panicking Rust program uses on a host).
pub const PANIC: i32 = 101;

/// Ends the QEMU process with `code`, after putting the drive output in its safe state.
pub fn exit(code: i32) -> ! {
    drive::force_safe();
    semihosting::process::exit(code)
}

static PANICKING: AtomicBool = AtomicBool::new(false);

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    // The drive goes safe before anything else can go wrong (logging may itself fail).
    drive::force_safe();
    if !PANICKING.swap(true, Ordering::AcqRel) {
        // `drive::state()` is the plant's input: the simulated plant reads its drive here.
        defmt::error!(
            "drive output safe, the plant's drive input is {}; panic: {}",
            drive::state(),
            defmt::Display2Format(info)
        );
    }
    semihosting::process::exit(PANIC)
}

#[cortex_m_rt::exception]
unsafe fn HardFault(frame: &cortex_m_rt::ExceptionFrame) -> ! {
    drive::force_safe();
    defmt::error!(
        "drive output safe; HardFault at pc {=u32:#010x}",
        frame.pc()
    );
    semihosting::process::exit(FAULT)
}
