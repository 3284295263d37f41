//! Large blocks on all cores, with exactly the result of the sequential
//! [`Parser::feed`]: pure-ASCII blocks are cut at newlines, blocks with binary
//! packets (found by the pieces of the first cut) at packets with a good CRC;
//! each piece gets a fresh parser and the
//! pieces are merged in order (locations shifted, runs of skipped bytes joined
//! across cuts, tables appended in one parallel copy).
//!
//! Cost: O(bytes / cores) for the pieces plus one parallel copy of the tables;
//! damaged binary streams fall back to sequential parsing from the damage on.

use rayon::prelude::*;

use crate::vn::binary::{self, HeaderScan};
use crate::vn::stream::parser::{Failure, Parser, MAX_LAYOUTS};
use crate::vn::{IssueKind, Location, Table, VnData, FIRST_KEEP};

/// What a piece parser of [`Parser::feed_block`] leaves: its data, a strict-mode
/// failure, its newlines, the end of its last run of skipped bytes and its
/// unused spare buffers.
type PieceResult = (VnData, Option<Failure>, u64, u64, Vec<Vec<f64>>);

/// Tables of several pieces by message name, to append in one parallel copy.
#[derive(Default)]
struct TableParts(Vec<(String, Vec<Table>)>);

impl TableParts {
    /// Move the tables out of a piece's result.
    fn take_from(&mut self, data: &mut VnData) {
        for (name, t) in std::mem::take(&mut data.tables) {
            match self.0.iter_mut().find(|(n, _)| *n == name) {
                Some((_, v)) => v.push(t),
                None => self.0.push((name, vec![t])),
            }
        }
    }

    /// Append them, in piece order, to the tables of `data`, reserving
    /// `scale` rows per row appended when a table has to grow; the parts' emptied
    /// buffers go to `spare`.
    fn flush(&mut self, data: &mut VnData, scale: f64, spare: &mut Vec<Vec<f64>>) {
        for (name, parts) in self.0.drain(..) {
            let rows: usize = parts.iter().map(|t| t.len).sum();
            let names = parts.first().map(|t| t.names.clone()).unwrap_or_default();
            let mine = data.tables.entry(name).or_insert_with(|| Table::new(names));
            spare.extend(mine.append_all(parts, (rows as f64 * scale) as usize));
        }
    }
}

/// Offset of the first packet at or after `from` (within `window` bytes) whose
/// header frames a fixed-size packet with a good CRC inside `buf`.
fn good_packet_at_or_after(buf: &[u8], from: usize, window: usize) -> Option<usize> {
    let end = from.saturating_add(window).min(buf.len());
    let mut i = from;
    while i < end {
        let at = i + buf.get(i..end)?.iter().position(|&c| c == 0xFA)?;
        if let HeaderScan::Ok(layout) = binary::parse_header(&buf[at..]) {
            if let Some(size) = layout.fixed_payload {
                let stop = at + 1 + layout.header.len() + size + 2;
                if stop <= buf.len() && binary::crc_ok(&buf[at..stop]) {
                    return Some(at);
                }
            }
        }
        i = at + 1;
    }
    None
}

/// Whether `byte` occurs in `buf`: blocks of 4 kB compared without a branch per
/// byte (vectorised), where `contains` tests one byte at a time.
fn has_byte(buf: &[u8], byte: u8) -> bool {
    buf.chunks(4096)
        .any(|block| block.iter().fold(false, |seen, &c| seen | (c == byte)))
}

impl Parser {
    /// The spare buffers split among `pieces` piece parsers (at most one each;
    /// more than a block's worth are not kept).
    fn lend_spare(&mut self, pieces: usize) -> Vec<Vec<Vec<f64>>> {
        self.spare.truncate(pieces);
        (0..pieces)
            .map(|_| self.spare.pop().into_iter().collect())
            .collect()
    }

    /// Parse a block, using all cores when it is large and pure ASCII.
    pub fn feed_block(&mut self, buf: &[u8], fin: bool) -> usize {
        if buf.len() < self.parallel_min || self.fail.is_some() {
            return self.feed(buf, fin);
        }
        // Once a block held binary packets, the next are scanned for them first
        // (a piece that finds one wastes the parse of the other pieces).
        if self.saw_binary && has_byte(buf, 0xFA) {
            return self.feed_block_binary(buf, fin);
        }
        // Everything up to the last newline is split into pieces at newlines and
        // parsed in parallel; only the tail after it (part of one line, which may
        // continue in the next block) is parsed sequentially and carried over.
        // A binary packet may hold a newline: a block with a 0xFA byte is cut at
        // packets instead. Each piece's parser notes a 0xFA it meets (every
        // one it holds), rather than one core scanning the block first.
        let end_nl = buf.iter().rposition(|&c| c == b'\n').map(|p| p + 1);
        let Some(end_nl) = end_nl.filter(|&e| !has_byte(&buf[e..], 0xFA)) else {
            return match has_byte(buf, 0xFA) {
                true => self.feed_block_binary(buf, fin),
                false => self.feed(buf, fin),
            };
        };
        let pieces = (rayon::current_num_threads() * 4).max(2);
        let step = end_nl / pieces;
        let mut cuts = vec![0usize];
        for p in 1..pieces {
            let from = (p * step).max(*cuts.last().unwrap_or(&0));
            if let Some(q) = buf[from..end_nl].iter().position(|&c| c == b'\n') {
                let cut = from + q + 1;
                if cut < end_nl && cut > *cuts.last().unwrap_or(&0) {
                    cuts.push(cut);
                }
            }
        }
        cuts.push(end_nl);
        let last = *cuts.last().unwrap_or(&0);
        let inner: Vec<(usize, usize)> = cuts.windows(2).map(|w| (w[0], w[1])).collect();
        let strict = self.strict;
        let fast = self.fast;
        let lent = self.lend_spare(inner.len());
        let results: Vec<Result<PieceResult, Vec<Vec<f64>>>> = inner
            .par_iter()
            .zip(lent)
            .map(|(&(a, b), spare)| {
                let piece = &buf[a..b];
                let mut p = Parser::with_size_hint(strict, piece.len() as u64);
                p.fast = fast;
                p.spare = spare;
                // One spare location, for a run of skipped bytes that turns out
                // to continue one from the previous piece.
                p.skip_keep = FIRST_KEEP + 1;
                p.ascii_piece = true;
                p.feed(piece, true);
                // `feed` consumed the whole piece and counted its newlines
                // (unless strict mode stopped it, when the count is not used).
                let nl = p.lines;
                match p.met_0xfa {
                    true => Err(p.spare),
                    false => Ok((p.data, p.fail, nl, p.skip_end, p.spare)),
                }
            })
            .collect();
        if results.iter().any(|r| r.is_err()) {
            for r in results {
                self.spare.extend(r.map_or_else(|spare| spare, |r| r.4));
            }
            self.saw_binary = true;
            return self.feed_block_binary(buf, fin);
        }
        let results = results.into_iter().flatten();
        // Lines before the block (kept current by `feed`).
        let mut line_shift = self.lines;
        let mut parts = TableParts::default();
        for ((a, b), (mut data, fail, nl, skip_end, unused)) in inner.iter().zip(results) {
            self.spare.extend(unused);
            let shift_offset = self.base + *a as u64;
            let skipped = &mut data.issues.first[IssueKind::BytesSkipped as usize];
            if self.skip_end == shift_offset && skipped.first().is_some_and(|l| l.offset == 0) {
                // The sequential parser would extend the previous run here.
                skipped.remove(0);
            }
            skipped.truncate(FIRST_KEEP);
            self.skip_end = if skip_end == (b - a) as u64 {
                self.base + *b as u64
            } else {
                u64::MAX
            };
            for locs in data.issues.first.iter_mut() {
                for l in locs.iter_mut() {
                    l.offset += shift_offset;
                }
            }
            parts.take_from(&mut data);
            self.data.merge(data, line_shift);
            if let Some(mut failure) = fail {
                failure.location = Location {
                    offset: failure.location.offset + shift_offset,
                    line: failure.location.line + line_shift,
                };
                self.fail = Some(failure);
                let scale = self.rows_scale(self.base, *b, buf.len());
                parts.flush(&mut self.data, scale, &mut self.spare);
                return buf.len();
            }
            line_shift += nl;
        }
        // The tables of all pieces, appended in one parallel copy.
        let scale = self.rows_scale(self.base, last, buf.len());
        parts.flush(&mut self.data, scale, &mut self.spare);
        // Continue sequentially from `last`.
        self.lines = line_shift;
        self.line_pos = self.base + last as u64;
        self.base += last as u64;
        last + self.feed(&buf[last..], fin)
    }

    /// Parse a block that holds binary packets on all cores, with exactly the
    /// result of [`Parser::feed`].
    ///
    /// The block is cut into pieces that start where a packet with a good CRC
    /// starts; each piece is parsed by a fresh parser. A piece is *clean* when
    /// its parser consumed it to the byte, found no issue of any kind (nothing
    /// skipped, no CRC failure pending), and its configurations fit the layout
    /// table: then the sequential parser, arriving at the piece's first byte,
    /// would frame the very same records (framing of good records does not
    /// depend on the parser's state) and end exactly at the next piece. Clean
    /// pieces are merged in order; from the first piece that is not clean on,
    /// the rest of the block is parsed sequentially, so damaged streams get the
    /// sequential answer by construction, at sequential speed.
    fn feed_block_binary(&mut self, buf: &[u8], fin: bool) -> usize {
        if !self.pending.is_empty() {
            // A good packet in any piece could confirm these: stay sequential.
            return self.feed(buf, fin);
        }
        let pieces = (rayon::current_num_threads() * 4).max(2);
        let step = buf.len() / pieces;
        let mut starts = vec![0usize];
        for p in 1..pieces {
            let from = (p * step).max(*starts.last().unwrap_or(&0) + 1);
            if from >= buf.len() {
                break;
            }
            if let Some(at) = good_packet_at_or_after(buf, from, step.max(1 << 12)) {
                if at > *starts.last().unwrap_or(&0) {
                    starts.push(at);
                }
            }
        }
        if starts.len() < 2 {
            return self.feed(buf, fin);
        }
        let bounds: Vec<(usize, usize)> = starts
            .iter()
            .enumerate()
            .map(|(k, &a)| (a, starts.get(k + 1).copied().unwrap_or(buf.len())))
            .collect();
        let last = bounds.len() - 1;
        let (strict, fast) = (self.strict, self.fast);
        let lent = self.lend_spare(bounds.len());
        let results: Vec<(Parser, usize)> = bounds
            .par_iter()
            .zip(lent)
            .enumerate()
            .map(|(k, (&(a, b), spare))| {
                let mut p = Parser::with_size_hint(strict, (b - a) as u64);
                p.fast = fast;
                p.spare = spare;
                let used = p.feed(&buf[a..b], fin && k == last);
                (p, used)
            })
            .collect();
        // The clean pieces from the start, as long as their configurations fit
        // the layout table the sequential parser would keep.
        let mut known: Vec<Vec<u8>> = self
            .layouts
            .iter()
            .map(|(l, _, _)| l.header.clone())
            .collect();
        let mut clean = Vec::new();
        let mut resume = None;
        for (k, (p, used)) in results.into_iter().enumerate() {
            let (a, b) = bounds[k];
            let ok = (k == last || used == b - a)
                && p.fail.is_none()
                && p.pending.is_empty()
                && p.data.issues.counts.iter().all(|&c| c == 0);
            let mut fits = ok;
            if ok {
                for (l, _, _) in &p.layouts {
                    if !known.contains(&l.header) {
                        known.push(l.header.clone());
                    }
                }
                fits = known.len() <= MAX_LAYOUTS;
            }
            if !fits {
                // Sequential from here: this piece starts where the clean ones
                // before it ended, with the state they left.
                resume = Some(a);
                break;
            }
            clean.push((p, used));
        }
        let consumed = self.absorb(clean, buf.len());
        match resume {
            Some(a) => a + self.feed(&buf[a..], fin),
            // The last piece may leave a record cut by the block end for the
            // next block.
            None => consumed,
        }
    }

    /// Merge clean pieces of a block, in order (see [`Parser::feed_block`]);
    /// their tables are appended on all cores. Returns the bytes they consumed.
    fn absorb(&mut self, pieces: Vec<(Parser, usize)>, block: usize) -> usize {
        let start = self.base;
        let mut binary_parts: Vec<(usize, Vec<Table>)> = Vec::new();
        let mut ascii_parts = TableParts::default();
        let mut consumed = 0usize;
        for (mut p, used) in pieces {
            self.spare.append(&mut p.spare);
            for (k_piece, (layout, name, table)) in p.layouts.drain(..).enumerate() {
                let k = match self
                    .layouts
                    .iter()
                    .position(|(l, _, _)| l.header == layout.header)
                {
                    Some(k) => k,
                    None => {
                        self.layouts.push((layout, name, Table::default()));
                        self.layouts.len() - 1
                    }
                };
                if p.good_layouts.contains(&k_piece) && !self.good_layouts.contains(&k) {
                    self.good_layouts.push(k);
                }
                if table.names.is_empty() {
                    continue;
                }
                match binary_parts.iter_mut().find(|(j, _)| *j == k) {
                    Some((_, parts)) => parts.push(table),
                    None => binary_parts.push((k, vec![table])),
                }
            }
            ascii_parts.take_from(&mut p.data);
            let lines = p.lines;
            self.merged_pieces += 1;
            self.data.merge(std::mem::take(&mut p.data), 0);
            self.lines += lines;
            self.base += used as u64;
            self.line_pos = self.base;
            consumed += used;
        }
        let scale = self.rows_scale(start, consumed, block);
        for (k, parts) in binary_parts {
            let mine = &mut self.layouts[k].2;
            if mine.names.is_empty() {
                *mine = Table::new(parts[0].names.clone());
            }
            let rows: usize = parts.iter().map(|t| t.len).sum();
            self.spare
                .extend(mine.append_all(parts, (rows as f64 * scale) as usize));
        }
        ascii_parts.flush(&mut self.data, scale, &mut self.spare);
        consumed
    }

    /// Rows to reserve per row decoded, when `done` bytes from absolute offset
    /// `start` gave them: the rest of the stream (by the size hint) at the same
    /// density, with 1 % slack.
    fn rows_scale(&self, start: u64, done: usize, block: usize) -> f64 {
        let left = self.size_hint.saturating_sub(start).max(block as u64) as f64;
        left / done.max(1) as f64 * 1.01
    }
}

#[cfg(test)]
mod tests {
    use super::has_byte;

    #[test]
    fn has_byte_finds_it_anywhere() {
        let mut buf = vec![b'$'; 3 * 4096 + 17];
        assert!(!has_byte(&buf, 0xFA) && !has_byte(&[], 0xFA));
        for at in [0, 4095, 4096, 2 * 4096 + 1, buf.len() - 1] {
            buf[at] = 0xFA;
            assert!(has_byte(&buf, 0xFA), "{at}");
            buf[at] = b'$';
        }
    }
}
