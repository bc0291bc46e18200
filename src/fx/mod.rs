//! Fixed-point arithmetic: formats and elementary functions used by the model's hot path.
