//! VectorNav VN-100 parsing (spec: VN-100 serial output formats).
//!
//! * [`checksum`] — XOR-8 and CRC-16/XMODEM.
//! * [`messages`] — the ASCII message and command tables.
//! * [`number`] — decimal fields, correctly rounded.
//! * [`ascii`] — the `$VN...*hh` sentences: field decoding.
//! * `shape` — sentences laid out like the last one of their type, checked and
//!   decoded in vector registers.
//! * [`binary`] — `0xFA` binary output packets: header, field sizes, decoding.
//! * [`stream`] — one reader that walks any byte stream (ASCII and binary
//!   interleaved), in chunks, accounting for every byte.
//! * [`write`] — writers for both formats (simulator, round-trip tests).
//! * [`issues`], [`table`], [`data`] — what a parse produces.
//!
//! Output is one column table per message type ([`Table`], struct of arrays of
//! `f64`); no heap object is made per record. Dependencies run one way:
//! `stream` → `shape`/`ascii`/`binary` → `messages`/`number`/`checksum` → `table`/`issues`.

pub mod ascii;
pub mod binary;
pub mod checksum;
pub mod data;
pub mod issues;
pub mod messages;
pub mod number;
pub(crate) mod shape;
pub mod stream;
pub mod table;
pub mod write;

pub use data::VnData;
pub use issues::{IssueKind, Issues, Location, FIRST_KEEP};
pub use table::Table;
