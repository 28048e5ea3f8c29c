//! Criterion benches across the roar crates live in `benches/`; this library is empty on purpose.
