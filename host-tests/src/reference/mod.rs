//! Independent double-precision reference of the friction model (host only).
