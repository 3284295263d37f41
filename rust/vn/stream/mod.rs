//! One reader for any VectorNav byte stream: ASCII sentences and binary packets,
//! interleaved, with noise between them.
//!
//! Every input byte ends up in exactly one of three places: a decoded record
//! (`bytes_parsed`), a damaged or undecoded ASCII record (`bytes_in_bad_records`,
//! counted per record as `bad_checksum`, `malformed_field`, `unknown_message`,
//! `truncated_record` or `device_error`), or the `bytes_skipped` count (noise,
//! including the bytes of binary candidates that failed their CRC; such a
//! candidate is also counted as `bad_checksum` when its header is one that has
//! framed a good packet before, and as `truncated_record` when the stream ends
//! inside it).
//!
//! Framing rules (spec §1, §2, §5): at `0xFA` try a binary packet (validate by
//! CRC, on failure drop one byte); at `$` try a sentence: printable bytes up to
//! `*`, 2 or 4 hex digits (or `XX`), then an optional `\r` and `\n`. A sentence
//! cut by a control byte, another `$` or the end of input is `truncated_record`.
//!
//! Large pure-ASCII blocks are split at newlines and parsed on all cores, then
//! concatenated in order.
//!
//! * [`scan`] — framing of one ASCII sentence, line ends and newline counting.
//! * [`parser`] — the sequential [`Parser`]: framing, decoding, issues, locations.
//! * [`parallel`] — the same result on all cores for large blocks.
//! * [`reader`] — whole buffers, readers and files in chunks.
//! * [`pieces`] — a stream fed piece by piece, its rows handed out as they come.

mod parallel;
mod parser;
mod pieces;
mod reader;
mod scan;
#[cfg(test)]
mod tests;

pub use parser::{Failure, Parser};
pub use pieces::{Pieces, HANDED_BACK};
pub use reader::{
    parse_bytes, parse_bytes_with, parse_file, parse_reader, parse_reader_with, CHUNK,
};
