//! Entry points: a whole buffer, the complete records at the start of a buffer,
//! a reader or a file in chunks. Chunks are joined without copying them (the
//! unconsumed tail of one is placed in a gap in front of the next), and the
//! next chunk is read while the current one is parsed.
//!
//! Cost: O(bytes); memory ≈ the output tables plus two chunks.

use std::io::Read;

use crate::error::{CoreError, CoreResult};
use crate::vn::stream::Parser;
use crate::vn::VnData;

/// Chunk size for reading files.
pub const CHUNK: usize = 8 << 20;

/// Parse a whole in-memory stream.
pub fn parse_bytes(data: &[u8], strict: bool) -> CoreResult<VnData> {
    parse_bytes_with(Parser::with_size_hint(strict, data.len() as u64), data)
}

/// [`parse_bytes`] with a configured parser (see [`Parser::with_parallel_min`]).
pub fn parse_bytes_with(mut p: Parser, data: &[u8]) -> CoreResult<VnData> {
    let mut pos = 0usize;
    while pos < data.len() {
        let end = (pos + CHUNK).min(data.len());
        let fin = end == data.len();
        let used = p.feed_block(&data[pos..end], fin);
        if p.fail.is_some() {
            break;
        }
        if used == 0 && !fin {
            // A record straddles the chunk end: extend by one more chunk.
            let end2 = (end + CHUNK).min(data.len());
            let used2 = p.feed_block(&data[pos..end2], end2 == data.len());
            pos += used2;
            if used2 == 0 {
                break;
            }
            continue;
        }
        pos += used;
    }
    p.finish()
}

/// Room kept in front of each chunk buffer for the unconsumed tail of the
/// previous chunk (a record cut by the chunk end), so that it is joined to the
/// next chunk without copying the chunk.
const GAP: usize = 1 << 16;

/// Append up to `want` bytes from `reader` to `buf` (without zeroing them first):
/// bytes read, and whether the reader reported its end.
fn fill<R: Read>(reader: &mut R, buf: &mut Vec<u8>, want: usize) -> CoreResult<(usize, bool)> {
    let got = reader.by_ref().take(want as u64).read_to_end(buf)?;
    Ok((got, got < want))
}

/// Parse a stream from a reader in chunks of [`CHUNK`] bytes, calling
/// `progress(bytes_done, total)` after each chunk.
///
/// The next chunk is read while the current one is parsed; the parser sees
/// the same sequence of blocks (previous tail + next chunk) as a plain
/// read-then-parse loop.
pub fn parse_reader<R: Read + Send>(
    reader: R,
    total: u64,
    strict: bool,
    progress: &mut dyn FnMut(u64, u64) -> CoreResult<()>,
) -> CoreResult<VnData> {
    let p = Parser::with_size_hint(strict, total);
    parse_reader_with(p, reader, total, CHUNK, progress)
}

/// [`parse_reader`] with a configured parser and chunk size (small chunks and
/// a small [`Parser::with_parallel_min`] exercise every path on small inputs).
pub fn parse_reader_with<R: Read + Send>(
    mut p: Parser,
    mut reader: R,
    total: u64,
    chunk: usize,
    progress: &mut dyn FnMut(u64, u64) -> CoreResult<()>,
) -> CoreResult<VnData> {
    let chunk = chunk.max(1);
    let mut cur: Vec<u8> = Vec::with_capacity(GAP + chunk);
    let mut next: Vec<u8> = Vec::with_capacity(GAP + chunk);
    for b in [&mut cur, &mut next] {
        crate::memory::advise_huge_pages(b);
        b.resize(GAP, 0);
    }
    let (mut got, mut eof) = fill(&mut reader, &mut cur, chunk)?;
    let mut from = GAP;
    let mut done: u64 = 0;
    loop {
        done += got as u64;
        let block = &cur[from..];
        let (used, ahead) = if eof {
            (p.feed_block(block, true), Ok((0, true)))
        } else {
            next.truncate(GAP);
            rayon::join(
                || p.feed_block(block, false),
                || fill(&mut reader, &mut next, chunk),
            )
        };
        progress(done, total.max(done))?;
        if eof || p.fail.is_some() {
            break;
        }
        (got, eof) = ahead?;
        let left = &cur[from + used..];
        if left.len() <= GAP {
            from = GAP - left.len();
            next[from..GAP].copy_from_slice(left);
        } else {
            // A tail longer than the gap (a record longer than a chunk so far).
            let mut joined = Vec::with_capacity(left.len() + next.len());
            joined.extend_from_slice(left);
            joined.extend_from_slice(&next[GAP..]);
            next = joined;
            from = 0;
        }
        std::mem::swap(&mut cur, &mut next);
        if next.len() < GAP {
            next.resize(GAP, 0);
        }
    }
    p.finish()
}

/// Parse a file in chunks (memory ≈ the output tables plus one chunk).
pub fn parse_file(
    path: &std::path::Path,
    strict: bool,
    progress: &mut dyn FnMut(u64, u64) -> CoreResult<()>,
) -> CoreResult<VnData> {
    let file = std::fs::File::open(path).map_err(|e| CoreError::Io {
        kind: e.kind(),
        message: format!("cannot open {}: {e}", path.display()),
    })?;
    let total = file.metadata().map(|m| m.len()).unwrap_or(0);
    parse_reader(file, total, strict, progress)
}
