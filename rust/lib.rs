//! imunoise core: pure Rust statistics, parsers and fitting, plus one binding layer.
//!
//! Everything outside `bindings` is plain Rust over slices and compiles and tests
//! without Python (`cargo test --no-default-features`). The `bindings` module is
//! the only place that knows pyo3 and numpy.

pub mod allan;
pub mod digest;
pub mod error;
pub mod fit;
pub mod interrupt;
mod memory;
pub mod records;
pub mod simd;
pub mod vn;

#[cfg(feature = "python")]
mod bindings;
