//! The command console on the ST-LINK virtual COM port: USART2 on PA2 (TX) / PA3 (RX), AF7,
//! 115200 baud 8N1 (the board's default wiring of the virtual COM port). Interrupt-driven and
//! buffered, so a slow host only fills the buffers; `sonolube_app::console::serve` runs on the
//! two halves.

use embassy_stm32::Peri;
use embassy_stm32::peripherals::{PA2, PA3, USART2};
use embassy_stm32::usart::{self, BufferedUart, BufferedUartRx, BufferedUartTx};
use static_cell::StaticCell;

use crate::Irqs;

/// Console baud rate.
pub const BAUD: u32 = 115_200;

/// Transmit buffer: a reply (320 bytes at most) plus a telemetry line (256) in flight.
const TX_BUFFER: usize = 640;
/// Receive buffer: a few command lines (96 bytes each at most) typed ahead.
const RX_BUFFER: usize = 256;

static TX: StaticCell<[u8; TX_BUFFER]> = StaticCell::new();
static RX: StaticCell<[u8; RX_BUFFER]> = StaticCell::new();

/// USART2 configured and split into its receive and transmit halves. Call once.
pub fn init(
    usart: Peri<'static, USART2>,
    tx_pin: Peri<'static, PA2>,
    rx_pin: Peri<'static, PA3>,
) -> Result<(BufferedUartRx<'static>, BufferedUartTx<'static>), usart::ConfigError> {
    let mut config = usart::Config::default();
    config.baudrate = BAUD;
    config.data_bits = usart::DataBits::DataBits8;
    config.parity = usart::Parity::ParityNone;
    config.stop_bits = usart::StopBits::STOP1;
    let tx_buffer = TX.init([0; TX_BUFFER]);
    let rx_buffer = RX.init([0; RX_BUFFER]);
    let uart = BufferedUart::new(usart, rx_pin, tx_pin, tx_buffer, rx_buffer, Irqs, config)?;
    let (tx, rx) = uart.split();
    Ok((rx, tx))
}
