//! UART0 of the mps2-an386 (an ARM CMSDK APB UART at 0x4000_4000), interrupt-driven, as
//! `embedded_io_async` read and write halves for the console.
//!
//! QEMU connects it to the host character device of its first `-serial` option (a Unix
//! socket in the command test, `null` otherwise). The CMSDK UART holds one byte each way.
//! Received bytes go from the RX interrupt (IRQ 0) into a 256-byte pipe; when the pipe is full
//! the RX interrupt is switched off and the byte stays in the UART, so QEMU stops taking input
//! from the host (flow control: no byte is lost). Sending waits for the TX interrupt (IRQ 1)
//! only while the UART's one-byte buffer is full.

use core::future::poll_fn;
use core::ptr::{read_volatile, write_volatile};
use core::task::Poll;

use cortex_m::peripheral::NVIC;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::pipe::Pipe;
use embassy_sync::waitqueue::AtomicWaker;

use crate::irq::{Irq, UART0_RX, UART0_TX};
use crate::time_driver::CORE_CLOCK_HZ;

const BASE: usize = 0x4000_4000;
const DATA: usize = 0x00;
const STATE: usize = 0x04;
const CTRL: usize = 0x08;
/// Interrupt status (read) and clear (write 1).
const INT: usize = 0x0C;
const BAUDDIV: usize = 0x10;

const STATE_TX_FULL: u32 = 1 << 0;
const STATE_RX_FULL: u32 = 1 << 1;
const CTRL_TX_ENABLE: u32 = 1 << 0;
const CTRL_RX_ENABLE: u32 = 1 << 1;
const CTRL_TX_INT: u32 = 1 << 2;
const CTRL_RX_INT: u32 = 1 << 3;
const INT_TX: u32 = 1 << 0;
const INT_RX: u32 = 1 << 1;

/// Line rate of the console (QEMU does not pace the bytes; a real UART would).
pub const BAUD: u32 = 115_200;

static RX: Pipe<CriticalSectionRawMutex, 256> = Pipe::new();
static TX_WAKER: AtomicWaker = AtomicWaker::new();

fn read(offset: usize) -> u32 {
    // SAFETY: an aligned register of the UART0 block, which this module alone uses.
    unsafe { read_volatile((BASE + offset) as *const u32) }
}

fn write(offset: usize, value: u32) {
    // SAFETY: as in `read`.
    unsafe { write_volatile((BASE + offset) as *mut u32, value) }
}

fn modify_ctrl(set: u32, clear: u32) {
    critical_section::with(|_| write(CTRL, (read(CTRL) & !clear) | set));
}

/// The receive half.
pub struct UartRx(());
/// The send half.
pub struct UartTx(());

/// Sets UART0 up (115200 baud, both directions, RX interrupt on) and returns its halves.
/// Call once, before the executor runs.
pub fn init() -> (UartRx, UartTx) {
    write(BAUDDIV, (CORE_CLOCK_HZ / u64::from(BAUD)) as u32);
    write(INT, INT_TX | INT_RX);
    write(CTRL, CTRL_TX_ENABLE | CTRL_RX_ENABLE | CTRL_RX_INT);
    crate::irq::enable(UART0_RX);
    crate::irq::enable(UART0_TX);
    (UartRx(()), UartTx(()))
}

/// IRQ 0: moves received bytes into the pipe while it has room.
pub fn on_rx_interrupt() {
    write(INT, INT_RX);
    while read(STATE) & STATE_RX_FULL != 0 {
        if RX.free_capacity() == 0 {
            // Leave the byte in the UART: QEMU holds the rest until the reader makes room.
            modify_ctrl(0, CTRL_RX_INT);
            return;
        }
        let byte = read(DATA) as u8;
        let _ = RX.try_write(&[byte]);
    }
}

/// IRQ 1: the one-byte buffer has room again.
pub fn on_tx_interrupt() {
    write(INT, INT_TX);
    modify_ctrl(0, CTRL_TX_INT);
    TX_WAKER.wake();
}

impl embedded_io_async::ErrorType for UartRx {
    /// The CMSDK UART as emulated reports no errors.
    type Error = core::convert::Infallible;
}

impl embedded_io_async::ErrorType for UartTx {
    /// The CMSDK UART as emulated reports no errors.
    type Error = core::convert::Infallible;
}

impl embedded_io_async::Read for UartRx {
    /// Waits for at least one byte; cancel-safe (bytes stay in the pipe until taken).
    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, Self::Error> {
        let count = RX.read(buf).await;
        if read(CTRL) & CTRL_RX_INT == 0 {
            // The interrupt was off for lack of room: switch it on and drain what waits.
            modify_ctrl(CTRL_RX_INT, 0);
            NVIC::pend(Irq(UART0_RX));
        }
        Ok(count)
    }
}

impl embedded_io_async::Write for UartTx {
    async fn write(&mut self, buf: &[u8]) -> Result<usize, Self::Error> {
        let Some(&first) = buf.first() else {
            return Ok(0);
        };
        poll_fn(|cx| {
            TX_WAKER.register(cx.waker());
            // Interrupt on before the check: a buffer that empties in between still wakes us.
            modify_ctrl(CTRL_TX_INT, 0);
            if read(STATE) & STATE_TX_FULL == 0 {
                modify_ctrl(0, CTRL_TX_INT);
                Poll::Ready(())
            } else {
                Poll::Pending
            }
        })
        .await;
        write(DATA, u32::from(first));
        Ok(1)
    }

    /// The emulated UART sends a byte as soon as its buffer takes it: nothing to wait for.
    async fn flush(&mut self) -> Result<(), Self::Error> {
        Ok(())
    }
}
