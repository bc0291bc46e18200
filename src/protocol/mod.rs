//! The command and telemetry line protocol spoken over the UART.
