//! The sequential parser: frames records at `$` and `0xFA`, decodes them into
//! tables, counts issues with their first locations and keeps the byte
//! accounting of [`crate::vn::stream`]. Blocks may end inside a record: unless
//! told the input ends, [`Parser::feed`] leaves it for the next block.
//!
//! Cost: O(bytes); locations count newlines only up to the issue (lazily), so a
//! clean stream never counts lines except once per block.

use std::collections::BTreeMap;

use crate::error::{CoreError, CoreResult};
use crate::vn::ascii::{self, Decoded};
use crate::vn::binary::{self, HeaderScan, Layout};
use crate::vn::messages::{spec_by_id, MsgSpec};
use crate::vn::shape::Shape;
use crate::vn::stream::scan::{count_newlines, eat_eol, scan_ascii, Ascii, Outcome};
use crate::vn::{IssueKind, Location, Table, VnData, FIRST_KEEP};

/// Below this a block is parsed on one thread (the default of
/// [`Parser::with_parallel_min`]; the parallel path is in `parallel.rs`).
pub(super) const PARALLEL_MIN: usize = 1 << 20;

/// Layouts remembered per reader (distinct binary configurations).
pub(super) const MAX_LAYOUTS: usize = 16;
/// CRC failures remembered before their configuration is confirmed.
const MAX_PENDING: usize = 64;
/// Sentence shapes remembered per parser (message types interleaved).
const MAX_SHAPES: usize = 4;

/// A strict-mode failure: the first damaged record.
#[derive(Debug, Clone, PartialEq)]
pub struct Failure {
    pub kind: IssueKind,
    pub location: Location,
    pub reason: String,
}

impl Failure {
    /// The error a strict parse returns; its text reads
    /// `line L (byte offset O): kind: reason`.
    pub fn into_error(self) -> CoreError {
        CoreError::Parse {
            kind: self.kind.name(),
            line: Some(self.location.line),
            offset: Some(self.location.offset),
            reason: self.reason,
        }
    }
}

/// Count one record of `key` without allocating once the key exists.
fn bump(map: &mut BTreeMap<String, u64>, key: &str) {
    match map.get_mut(key) {
        Some(n) => *n += 1,
        None => {
            map.insert(key.to_string(), 1);
        }
    }
}

/// Sequential parser state. Offsets passed in are relative to the current block;
/// `base` is the absolute offset of the block start.
pub struct Parser {
    pub(super) strict: bool,
    pub(super) size_hint: u64,
    pub data: VnData,
    /// Absolute offset of the current block's first byte.
    pub(super) base: u64,
    /// Newlines counted before absolute offset `line_pos` (for locations).
    pub(super) lines: u64,
    pub(super) line_pos: u64,
    /// End (absolute) of the current run of skipped bytes, to record each run once.
    pub(super) skip_end: u64,
    /// Binary configurations seen: layout, table name, decoded rows (moved to
    /// `data.tables` by `finish`).
    pub(super) layouts: Vec<(Layout, String, Table)>,
    /// Indices into `layouts` of configurations that framed a good packet.
    pub(super) good_layouts: Vec<usize>,
    /// CRC failures of configurations not (yet) seen in a good packet: counted as
    /// `bad_checksum` once the configuration frames a good packet.
    pub(super) pending: Vec<(usize, Location)>,
    /// First damaged record in strict mode: kind, location, reason.
    pub fail: Option<Failure>,
    /// Message type of the last sentence taken by the fast path.
    pub(super) last_spec: Option<&'static MsgSpec>,
    /// Shapes of the last sentences of up to [`MAX_SHAPES`] message types.
    pub(super) shapes: Vec<Shape>,
    /// Sentences of the fast path since the last one a shape took.
    pub(super) shape_misses: u32,
    /// Sentences a shape took (for tests).
    #[cfg(test)]
    pub(super) shape_hits: u64,
    /// Whether common sentences take [`ascii::fast_sentence`] (off only to check
    /// that the result is the same without it).
    pub(super) fast: bool,
    /// Blocks at least this long are parsed on all cores.
    pub(super) parallel_min: usize,
    /// Whether a block parsed on all cores held a 0xFA byte.
    pub(super) saw_binary: bool,
    /// Whether `feed` met a 0xFA byte: every byte outside the records it
    /// decodes passes its main loop, and no ASCII record holds one.
    pub(super) met_0xfa: bool,
    /// A piece of a block cut at newlines: its result is dropped once it
    /// meets a 0xFA, so it stops there.
    pub(super) ascii_piece: bool,
    /// Pieces parsed on other cores and merged (for tests).
    pub(super) merged_pieces: u64,
    /// Locations kept for runs of skipped bytes (one more in a piece of a
    /// parallel parse, see [`Parser::feed_block`]).
    pub(super) skip_keep: usize,
    /// Emptied value buffers of merged pieces, lent to the next block's pieces:
    /// memory already mapped is filled at once, a fresh buffer page-faults.
    pub(super) spare: Vec<Vec<f64>>,
    /// Value buffers of tables handed out by [`Parser::take_tables`] and given
    /// back once their rows were used ([`super::Pieces::give_back`]): the next
    /// piece's tables fill them, where fresh ones are zeroed page by page.
    pub(super) handed_back: Vec<Vec<f64>>,
}

impl Parser {
    pub fn new(strict: bool) -> Parser {
        Parser::with_size_hint(strict, 0)
    }

    /// A parser for a stream of about `size_hint` bytes: tables reserve their
    /// rows once (untouched capacity costs address space, not memory).
    pub fn with_size_hint(strict: bool, size_hint: u64) -> Parser {
        Parser {
            size_hint,
            strict,
            data: VnData::default(),
            base: 0,
            lines: 0,
            line_pos: 0,
            skip_end: u64::MAX,
            layouts: Vec::new(),
            good_layouts: Vec::new(),
            pending: Vec::new(),
            fail: None,
            last_spec: None,
            shapes: Vec::new(),
            shape_misses: 0,
            #[cfg(test)]
            shape_hits: 0,
            fast: true,
            parallel_min: PARALLEL_MIN,
            saw_binary: false,
            met_0xfa: false,
            ascii_piece: false,
            merged_pieces: 0,
            skip_keep: FIRST_KEEP,
            spare: Vec::new(),
            handed_back: Vec::new(),
        }
    }

    /// The same parser without the ASCII fast path: every sentence goes through
    /// the general scanner and decoder. For equivalence tests and fuzzing.
    pub fn without_fast_path(mut self) -> Parser {
        self.fast = false;
        self
    }

    /// The same parser, splitting blocks of at least `bytes` bytes across cores
    /// (default 1 MiB). Small values exercise the parallel paths on small inputs
    /// (equivalence tests, fuzzing); the result never depends on it.
    pub fn with_parallel_min(mut self, bytes: usize) -> Parser {
        self.parallel_min = bytes;
        self
    }

    /// Rows to reserve for a table whose records are `len` bytes long.
    fn rows_hint(&self, len: usize) -> usize {
        let left = self.size_hint.saturating_sub(self.base);
        (left / len.max(1) as u64).min(1 << 32) as usize
    }

    /// An empty table for message `spec`, in a spare buffer when there is one.
    fn new_table(&mut self, spec: &MsgSpec) -> Table {
        let names = spec.fields.iter().map(|s| s.to_string()).collect();
        Table::with_buffer(names, self.spare.pop().unwrap_or_default())
    }

    fn location(&mut self, buf: &[u8], i: usize) -> Location {
        let abs = self.base + i as u64;
        if abs >= self.line_pos {
            let from = (self.line_pos.saturating_sub(self.base)) as usize;
            let from = from.min(i);
            self.lines += count_newlines(&buf[from..i]);
            self.line_pos = abs;
        }
        Location {
            offset: abs,
            line: self.lines + 1,
        }
    }

    fn issue(&mut self, buf: &[u8], i: usize, kind: IssueKind, reason: &str) {
        let fails = self.strict && kind.fails_strict() && self.fail.is_none();
        let wants = self.data.issues.wants_location(kind);
        if fails || wants {
            let loc = self.location(buf, i);
            if wants {
                self.data.issues.first[kind as usize].push(loc);
            }
            if fails {
                self.fail = Some(Failure {
                    kind,
                    location: loc,
                    reason: reason.to_string(),
                });
            }
        }
        self.data.issues.counts[kind as usize] += 1;
    }

    fn skip(&mut self, buf: &[u8], i: usize, n: usize) {
        let abs = self.base + i as u64;
        if abs != self.skip_end {
            let kind = IssueKind::BytesSkipped;
            if self.data.issues.first[kind as usize].len() < self.skip_keep {
                let loc = self.location(buf, i);
                self.data.issues.first[kind as usize].push(loc);
            }
        }
        self.skip_end = abs + n as u64;
        self.data.issues.counts[IssueKind::BytesSkipped as usize] += n as u64;
        self.data.bytes_skipped += n as u64;
    }

    fn push_ascii(&mut self, decoded: Decoded, buf: &[u8], i: usize, len: usize) {
        match decoded {
            Decoded::Data {
                spec,
                values,
                count,
                status,
            } => {
                if !self.data.tables.contains_key(spec.id) {
                    let mut table = self.new_table(spec);
                    table.reserve(self.rows_hint(len));
                    self.data.tables.insert(spec.id.to_string(), table);
                }
                let Some(table) = self.data.tables.get_mut(spec.id) else {
                    return;
                };
                table.push_row(&values[..spec.fields.len()]);
                if let Some(c) = count {
                    table.set_extra("serial_count", c);
                }
                if let Some(s) = status {
                    table.set_extra("status", s);
                }
                self.data.bytes_parsed += len as u64;
                self.data.ascii_records += 1;
            }
            Decoded::Command(id) => {
                bump(&mut self.data.messages, id);
                self.data.bytes_parsed += len as u64;
                self.data.ascii_records += 1;
            }
            Decoded::DeviceError(code) => {
                let table = self
                    .data
                    .tables
                    .entry("VNERR".to_string())
                    .or_insert_with(|| Table::new(vec!["code".to_string()]));
                table.push_row(&[code as f64]);
                self.issue(buf, i, IssueKind::DeviceError, "device error report");
                self.data.bytes_in_bad_records += len as u64;
            }
            Decoded::Unknown => {
                self.issue(
                    buf,
                    i,
                    IssueKind::UnknownMessage,
                    "message type not decoded",
                );
                self.data.bytes_in_bad_records += len as u64;
            }
            Decoded::Malformed(reason) => {
                self.issue(buf, i, IssueKind::MalformedField, &reason);
                self.note_ascii_missing(buf, i);
                self.data.bytes_in_bad_records += len as u64;
            }
        }
    }

    /// A damaged sentence at `buf[i] == b'$'`: when its message type can still be
    /// read (`$VNxxx` then `,` or `*`), one sample of that stream is missing here.
    fn note_ascii_missing(&mut self, buf: &[u8], i: usize) {
        let Some(head) = buf.get(i + 1..i + 7) else {
            return;
        };
        if head[5] != b',' && head[5] != b'*' {
            return;
        }
        let Some(spec) = spec_by_id(&head[..5]) else {
            return;
        };
        self.data
            .tables
            .entry(spec.id.to_string())
            .or_insert_with(|| Table::new(spec.fields.iter().map(|s| s.to_string()).collect()))
            .note_missing();
    }

    fn layout_index(&mut self, buf: &[u8], i: usize) -> Result<usize, bool> {
        // Fast path: a known header.
        for (k, (l, _, _)) in self.layouts.iter().enumerate() {
            let h = &l.header;
            if buf.get(i + 1..i + 1 + h.len()) == Some(h.as_slice()) {
                return Ok(k);
            }
        }
        match binary::parse_header(&buf[i..]) {
            HeaderScan::Incomplete => Err(true),
            HeaderScan::Invalid => Err(false),
            HeaderScan::Ok(layout) => {
                if self.layouts.len() >= MAX_LAYOUTS {
                    // Forget configurations that never framed a good packet.
                    let keep: Vec<usize> = self.good_layouts.clone();
                    if keep.len() >= MAX_LAYOUTS {
                        return Err(false);
                    }
                    let mut kept = Vec::new();
                    for (k, entry) in self.layouts.drain(..).enumerate() {
                        if keep.contains(&k) {
                            kept.push(entry);
                        }
                    }
                    self.layouts = kept;
                    self.pending.clear();
                    self.good_layouts = (0..self.layouts.len()).collect();
                }
                let name = layout.table_name();
                self.layouts.push((layout, name, Table::default()));
                Ok(self.layouts.len() - 1)
            }
        }
    }

    /// Parse `buf` (absolute offset `self.base`). Returns the number of bytes
    /// consumed; unless `fin`, a record cut by the end of `buf` is left for the
    /// next call (at most [`binary::MAX_PACKET`] bytes).
    pub fn feed(&mut self, buf: &[u8], fin: bool) -> usize {
        let n = buf.len();
        let mut i = 0usize;
        // Once per block: the level cannot change the values, only their speed.
        let level = crate::simd::level();
        while i < n {
            if self.fail.is_some() {
                return n;
            }
            match buf[i] {
                b'$' if self.fast && self.fast_ascii(buf, &mut i, level) => {}
                b'$' => match scan_ascii(buf, i, fin) {
                    Ascii::Need => break,
                    Ascii::Noise => {
                        self.skip(buf, i, 1);
                        i += 1;
                    }
                    Ascii::Record { end, outcome } => {
                        let len = end - i;
                        match outcome {
                            Outcome::Good { body } => {
                                let d = ascii::decode(&buf[body.0..body.1]);
                                self.push_ascii(d, buf, i, len);
                            }
                            Outcome::Issue(kind, reason) => {
                                self.issue(buf, i, kind, &reason);
                                self.note_ascii_missing(buf, i);
                                self.data.bytes_in_bad_records += len as u64;
                            }
                        }
                        i = end;
                    }
                },
                0xFA => {
                    self.met_0xfa = true;
                    if self.ascii_piece {
                        return n;
                    }
                    match self.binary_at(buf, i, fin) {
                        None => break,
                        Some(next) => i = next,
                    }
                }
                _ => {
                    let j = buf[i..]
                        .iter()
                        .position(|&c| c == b'$' || c == 0xFA)
                        .map_or(n, |p| i + p);
                    self.skip(buf, i, j - i);
                    i = j;
                }
            }
        }
        // Keep the line count current up to the consumed end: the next block
        // no longer sees these bytes.
        let from = (self.line_pos.saturating_sub(self.base) as usize).min(i);
        self.lines += count_newlines(&buf[from..i]);
        self.base += i as u64;
        self.line_pos = self.base;
        self.data.bytes_total += i as u64;
        i
    }

    /// The common sentence ([`ascii::fast_sentence`]) at `buf[*i] == b'$'`:
    /// decoded and `*i` moved past it, or `false` with nothing changed.
    #[inline]
    fn fast_ascii(&mut self, buf: &[u8], i: &mut usize, level: crate::simd::Level) -> bool {
        let b = &buf[*i..];
        let (spec, star) = match self.shaped(b, level) {
            Some(hit) => {
                self.shape_misses = 0;
                #[cfg(test)]
                {
                    self.shape_hits += 1;
                }
                hit
            }
            None => {
                let Some((spec, values, star)) = ascii::fast_sentence(b, self.last_spec, level)
                else {
                    return false;
                };
                self.learn_shape(b, spec, star, level);
                let len = eat_eol(b, star + 3);
                let table = match self.data.tables.get_mut(spec.id) {
                    Some(t) => t,
                    None => {
                        let mut table = self.new_table(spec);
                        table.reserve(self.rows_hint(len));
                        self.data.tables.entry(spec.id.to_string()).or_insert(table)
                    }
                };
                table.push_row(&values[..spec.fields.len()]);
                (spec, star)
            }
        };
        self.last_spec = Some(spec);
        let end = eat_eol(buf, *i + star + 3);
        // The line count follows the sentences (its only newline is its line
        // end), so that the block's end has no bytes left to count.
        let at = self.base + *i as u64;
        if self.line_pos < at {
            let from = (self.line_pos - self.base) as usize;
            self.lines += count_newlines(&buf[from..*i]);
        }
        self.lines += (buf[end - 1] == b'\n') as u64;
        self.line_pos = self.base + end as u64;
        self.data.bytes_parsed += (end - *i) as u64;
        self.data.ascii_records += 1;
        *i = end;
        true
    }

    /// The sentence at `b`, appended to its table by the shape of its message
    /// type: its spec and the offset of its `*`, or `None` with nothing changed.
    #[inline(always)]
    fn shaped(&mut self, b: &[u8], level: crate::simd::Level) -> Option<(&'static MsgSpec, usize)> {
        let id = b.get(1..6)?;
        let k = self
            .shapes
            .iter()
            .position(|s| s.spec.id.as_bytes() == id)?;
        let (spec, star) = (self.shapes[k].spec, self.shapes[k].star);
        let len = eat_eol(b, star + 3);
        if b.len() < crate::vn::shape::WINDOW {
            return None;
        }
        let shape = &self.shapes[k];
        let table = match self.data.tables.get_mut(spec.id) {
            Some(t) => t,
            None => {
                let mut table = Table::with_buffer(
                    spec.fields.iter().map(|s| s.to_string()).collect(),
                    self.spare.pop().unwrap_or_default(),
                );
                let left = self.size_hint.saturating_sub(self.base);
                table.reserve((left / len.max(1) as u64).min(1 << 32) as usize);
                self.data.tables.entry(spec.id.to_string()).or_insert(table)
            }
        };
        // SAFETY: push_with's pointer has room for SCRATCH = MAX_FIELDS values,
        // all parse_into writes; it writes every lane when it returns true.
        let pushed = unsafe { table.push_with(|dst| shape.parse_into(b, level, dst)) };
        pushed.then_some((spec, star))
    }

    /// Learn the shape of a sentence the fast path took without one, at the
    /// first miss and then at the 2nd, 4th, 8th ... and every 64th: a stream
    /// of fixed-width sentences changes shape rarely and relearns at once,
    /// one of varying widths does not pay for learning every sentence.
    #[cold]
    fn learn_shape(
        &mut self,
        b: &[u8],
        spec: &'static MsgSpec,
        star: usize,
        level: crate::simd::Level,
    ) {
        self.shape_misses = self.shape_misses.saturating_add(1);
        let m = self.shape_misses;
        if !m.is_power_of_two() && !m.is_multiple_of(64) {
            return;
        }
        let Some(shape) = Shape::learn(b, spec, star, level) else {
            return;
        };
        match self.shapes.iter().position(|s| s.spec.id == spec.id) {
            Some(k) => self.shapes[k] = shape,
            None if self.shapes.len() < MAX_SHAPES => self.shapes.push(shape),
            None => {
                self.shapes.remove(0);
                self.shapes.push(shape);
            }
        }
    }

    /// Try a binary packet at `buf[i] == 0xFA`; `None` means "need more input".
    fn binary_at(&mut self, buf: &[u8], i: usize, fin: bool) -> Option<usize> {
        let n = buf.len();
        let k = match self.layout_index(buf, i) {
            Ok(k) => k,
            Err(true) if !fin => return None,
            Err(_) => {
                self.skip(buf, i, 1);
                return Some(i + 1);
            }
        };
        let hl = 1 + self.layouts[k].0.header.len();
        let size = match binary::payload_size(&self.layouts[k].0, &buf[i + hl..]) {
            Ok(s) => s,
            Err(true) if !fin => return None,
            Err(_) => {
                self.skip(buf, i, 1);
                return Some(i + 1);
            }
        };
        let end = i + hl + size + 2;
        if end > n {
            if !fin {
                return None;
            }
            if self.good_layouts.contains(&k) {
                self.issue(
                    buf,
                    i,
                    IssueKind::TruncatedRecord,
                    "input ends inside a binary packet",
                );
                self.layouts[k].2.note_missing();
                self.data.bytes_in_bad_records += (n - i) as u64;
                return Some(n);
            }
            self.skip(buf, i, 1);
            return Some(i + 1);
        }
        if !binary::crc_ok(&buf[i..end]) {
            if self.good_layouts.contains(&k) {
                let reason = "binary packet CRC mismatch";
                // The record is counted; its bytes are re-scanned (resync one byte).
                self.issue(buf, i, IssueKind::BadChecksum, reason);
                self.layouts[k].2.note_missing();
            } else if self.pending.len() < MAX_PENDING {
                let loc = self.location(buf, i);
                self.pending.push((k, loc));
            }
            self.skip(buf, i, 1);
            return Some(i + 1);
        }
        if !self.good_layouts.contains(&k) {
            self.good_layouts.push(k);
            let kind = IssueKind::BadChecksum;
            for (_, loc) in self.pending.iter().filter(|(p, _)| *p == k) {
                if self.data.issues.wants_location(kind) {
                    self.data.issues.first[kind as usize].push(*loc);
                }
                self.data.issues.counts[kind as usize] += 1;
                if self.strict && self.fail.is_none() {
                    self.fail = Some(Failure {
                        kind,
                        location: *loc,
                        reason: "binary packet CRC mismatch".to_string(),
                    });
                }
            }
            self.pending.retain(|(p, _)| *p != k);
        }
        let buffer = match self.layouts[k].2.names.is_empty() {
            true => self.spare.pop().unwrap_or_default(),
            false => Vec::new(),
        };
        let (layout, _, table) = &mut self.layouts[k];
        if table.names.is_empty() {
            *table = Table::with_buffer(layout.column_names(), buffer);
            let rows = (self.size_hint.saturating_sub(self.base + i as u64) / (end - i) as u64)
                .min(1 << 32) as usize;
            table.reserve(rows);
        }
        binary::decode_into(layout, &buf[i + hl..i + hl + size], table);
        self.data.bytes_parsed += (end - i) as u64;
        self.data.binary_records += 1;
        Some(end)
    }

    /// Take `buffer` for the values of the next rows: an empty table with less
    /// room swaps it in at once (its own buffer is kept instead), else it waits
    /// for [`Parser::take_tables`]; at most `keep` buffers wait.
    pub(super) fn give_back(&mut self, mut buffer: Vec<f64>, keep: usize) {
        if buffer.capacity() == 0 {
            return;
        }
        let empty = self
            .data
            .tables
            .values_mut()
            .chain(self.layouts.iter_mut().map(|(_, _, t)| t))
            .filter(|t| t.len == 0 && !t.names.is_empty())
            .min_by_key(|t| t.values.capacity());
        if let Some(table) = empty {
            if table.values.capacity() < buffer.capacity() {
                buffer.clear();
                std::mem::swap(&mut table.values, &mut buffer);
            }
        }
        if buffer.capacity() > 0 && self.handed_back.len() < keep {
            self.handed_back.push(buffer);
        }
    }

    /// Move out the rows decoded so far, by table name (ASCII message types and
    /// binary configurations), padded as [`Parser::finish`] pads them; parsing
    /// goes on with empty tables of the same columns (see [`super::Pieces`]).
    pub fn take_tables(&mut self) -> BTreeMap<String, Table> {
        let mut out = BTreeMap::new();
        // A table that took rows gets a buffer given back (the largest first:
        // the busiest table); an empty one keeps its own.
        self.handed_back.sort_by_key(|b| b.capacity());
        for (name, table) in self.data.tables.iter_mut() {
            let buffer = match table.len {
                0 => std::mem::take(&mut table.values),
                _ => self.handed_back.pop().unwrap_or_default(),
            };
            let fresh = Table::with_buffer(table.names.clone(), buffer);
            out.insert(name.clone(), std::mem::replace(table, fresh));
        }
        for (_, name, table) in self.layouts.iter_mut() {
            if !table.names.is_empty() {
                let buffer = match table.len {
                    0 => std::mem::take(&mut table.values),
                    _ => self.handed_back.pop().unwrap_or_default(),
                };
                let fresh = Table::with_buffer(table.names.clone(), buffer);
                out.insert(name.clone(), std::mem::replace(table, fresh));
            }
        }
        out.retain(|_, table| table.len > 0 || !table.missing.is_empty());
        for table in out.values_mut() {
            table.finish();
        }
        out
    }

    /// Finish: pad tables and turn a strict-mode failure into an error.
    pub fn finish(mut self) -> CoreResult<VnData> {
        if let Some(failure) = self.fail.take() {
            return Err(failure.into_error());
        }
        for (_, name, table) in self.layouts.drain(..) {
            if table.len > 0 {
                self.data.tables.insert(name, table);
            }
        }
        for (name, t) in self.data.tables.iter_mut() {
            t.finish();
            t.shrink();
            if name != "VNERR" {
                self.data.messages.insert(name.clone(), t.len as u64);
            }
        }
        Ok(self.data)
    }
}
