//! The command line's own IO helpers (binary only): writing outputs safely.

pub mod outputs;
