//! The mps2-an386's interrupts this firmware uses, and their dispatch.
//!
//! Without a device crate, cortex-m-rt points every interrupt vector at `DefaultHandler`, which
//! gets the IRQ number: it calls the UART driver for IRQs 0 and 1 and polls the control
//! executor for [`CONTROL`], a line no emulated device drives, pended by software only.

use cortex_m::interrupt::InterruptNumber;
use cortex_m::peripheral::NVIC;

/// UART0 receive.
pub const UART0_RX: u16 = 0;
/// UART0 send.
pub const UART0_TX: u16 = 1;
/// The control executor's interrupt (no emulated device uses it).
pub const CONTROL: u16 = 31;

/// Priorities (lower is more urgent; QEMU implements all 8 bits): the control loop first, the
/// UART below it.
pub const CONTROL_PRIORITY: u8 = 0x40;
/// See [`CONTROL_PRIORITY`].
pub const UART_PRIORITY: u8 = 0x80;

/// An IRQ number for the NVIC.
#[derive(Clone, Copy)]
pub struct Irq(pub u16);

// SAFETY: every value this firmware makes is a valid IRQ number of the mps2-an386 (< 32).
unsafe impl InterruptNumber for Irq {
    fn number(self) -> u16 {
        self.0
    }
}

/// Sets the IRQ's priority and unmasks it.
pub fn enable(irq: u16) {
    let priority = if irq == CONTROL {
        CONTROL_PRIORITY
    } else {
        UART_PRIORITY
    };
    // SAFETY: stealing the NVIC only to set a priority and unmask; the handlers are ready.
    unsafe {
        let mut nvic = cortex_m::Peripherals::steal().NVIC;
        nvic.set_priority(Irq(irq), priority);
        NVIC::unmask(Irq(irq));
    }
}

#[cortex_m_rt::exception]
unsafe fn DefaultHandler(irqn: i16) {
    match irqn {
        0 => crate::uart::on_rx_interrupt(),
        1 => crate::uart::on_tx_interrupt(),
        31 => crate::executor::on_control_interrupt(),
        _ => {
            crate::drive::force_safe();
            defmt::error!("unexpected exception {=i16}", irqn);
            crate::exit::exit(crate::exit::FAULT);
        }
    }
}
