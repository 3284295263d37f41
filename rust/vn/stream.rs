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

use std::io::Read;

use rayon::prelude::*;

use crate::error::{CoreError, CoreResult};
use crate::vn::ascii::{self, Decoded};
use crate::vn::binary::{self, HeaderScan, Layout};
use crate::vn::checksum;
use crate::vn::{IssueKind, Location, Table, VnData, FIRST_KEEP};

/// The 2024 SDK rejects ASCII packets longer than this (spec §2.1).
pub const MAX_SENTENCE: usize = 320;
/// Below this a block is parsed on one thread.
const PARALLEL_MIN: usize = 1 << 20;
/// Chunk size for reading files.
pub const CHUNK: usize = 8 << 20;
/// Layouts remembered per reader (distinct binary configurations).
const MAX_LAYOUTS: usize = 16;
/// CRC failures remembered before their configuration is confirmed.
const MAX_PENDING: usize = 64;

/// A strict-mode failure: kind, location, reason.
pub type Failure = (IssueKind, Location, String);

enum Ascii {
    /// More input is needed to decide.
    Need,
    /// Not a sentence start: drop the `$` as noise.
    Noise,
    /// A record spanning `..end` with the given outcome.
    Record { end: usize, outcome: Outcome },
}

enum Outcome {
    Good { body: (usize, usize) },
    Issue(IssueKind, String),
}

fn is_check_char(c: u8) -> bool {
    c.is_ascii_hexdigit() || c == b'X'
}

/// Scan a sentence starting at `buf[i] == b'$'`.
fn scan_ascii(buf: &[u8], i: usize, fin: bool) -> Ascii {
    let n = buf.len();
    let is_vn = buf.get(i + 1) == Some(&b'V') && buf.get(i + 2) == Some(&b'N');
    let limit = (i + MAX_SENTENCE).min(n);
    // Common case first: find '*' and check the bytes before it in one
    // branch-free pass; fall back to the byte loop to locate a bad byte.
    let mut j = i + 1;
    if let Some(p) = buf[i + 1..limit].iter().position(|&c| c == b'*') {
        let bad = buf[i + 1..i + 1 + p].iter().fold(false, |acc, &c| {
            acc | (c == b'$') | !(0x20..=0x7E).contains(&c)
        });
        if !bad {
            j = i + 1 + p;
        }
    }
    while j < limit {
        let c = buf[j];
        if c == b'*' {
            break;
        }
        if c == b'$' || !(0x20..=0x7E).contains(&c) {
            return if is_vn {
                // A line end that cuts the sentence belongs to it.
                let end = if c == b'\r' || c == b'\n' {
                    eat_eol(buf, j)
                } else {
                    j
                };
                if !fin && end == n {
                    return Ascii::Need;
                }
                Ascii::Record {
                    end,
                    outcome: Outcome::Issue(
                        IssueKind::TruncatedRecord,
                        format!("sentence cut short by byte 0x{c:02X} before its checksum"),
                    ),
                }
            } else {
                Ascii::Noise
            };
        }
        j += 1;
    }
    if j >= limit {
        if limit == n && n - i < MAX_SENTENCE {
            if !fin {
                return Ascii::Need;
            }
            return if is_vn {
                Ascii::Record {
                    end: n,
                    outcome: Outcome::Issue(
                        IssueKind::TruncatedRecord,
                        "input ends inside a sentence".to_string(),
                    ),
                }
            } else {
                Ascii::Noise
            };
        }
        return if is_vn {
            Ascii::Record {
                end: limit,
                outcome: Outcome::Issue(
                    IssueKind::MalformedField,
                    format!("no '*' within {MAX_SENTENCE} bytes of '$'"),
                ),
            }
        } else {
            Ascii::Noise
        };
    }
    // buf[j] == '*'
    let star = j;
    let mut k = star + 1;
    while k < n && k < star + 5 && is_check_char(buf[k]) {
        k += 1;
    }
    if !fin && k + 2 > n {
        return Ascii::Need;
    }
    let body = &buf[i + 1..star];
    let digits = &buf[star + 1..k];
    let after = buf.get(k).copied();
    // Four or more check characters: CRC-16 only (a fall-back to XOR-8 on the
    // first two would accept 1 in 256 damaged CRC sentences). Two or three:
    // XOR-8 on the first two (a third is trailing text).
    let mut used = None;
    if digits.len() >= 4 {
        if checksum::verify(body, &digits[..4]).is_some() {
            used = Some(4);
        }
    } else if digits.len() >= 2 {
        if checksum::verify(body, &digits[..2]).is_some() {
            used = Some(2);
        }
    } else if digits.is_empty() && matches!(after, None | Some(b'\r') | Some(b'\n')) {
        used = Some(0);
    }
    let Some(used) = used else {
        if !is_vn {
            return Ascii::Noise;
        }
        let field = if digits.len() >= 4 {
            &digits[..4]
        } else {
            &digits[..digits.len().min(2)]
        };
        let reason = match field.len() {
            2 | 4 if field != b"XX" && field != b"XXXX" => format!(
                "checksum mismatch: field {} but XOR-8 is {:02X} and CRC-16 is {:04X}",
                String::from_utf8_lossy(field),
                checksum::xor8(body),
                checksum::crc16(body)
            ),
            _ => format!(
                "check field {:?} is not 2 or 4 hex digits",
                String::from_utf8_lossy(field)
            ),
        };
        let end = star + 1 + field.len();
        return Ascii::Record {
            end: eat_eol(buf, end),
            outcome: Outcome::Issue(IssueKind::BadChecksum, reason),
        };
    };
    let end = eat_eol(buf, star + 1 + used);
    Ascii::Record {
        end,
        outcome: Outcome::Good {
            body: (i + 1, star),
        },
    }
}

/// Count one record of `key` without allocating once the key exists.
fn bump(map: &mut std::collections::BTreeMap<String, u64>, key: &str) {
    match map.get_mut(key) {
        Some(n) => *n += 1,
        None => {
            map.insert(key.to_string(), 1);
        }
    }
}

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
    /// `scale` rows per row appended when a table has to grow.
    fn flush(&mut self, data: &mut VnData, scale: f64) {
        for (name, parts) in self.0.drain(..) {
            let rows: usize = parts.iter().map(|t| t.len).sum();
            let names = parts.first().map(|t| t.names.clone()).unwrap_or_default();
            let mine = data.tables.entry(name).or_insert_with(|| Table::new(names));
            mine.append_all(parts, (rows as f64 * scale) as usize);
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

/// Number of `\n` bytes: 64 at a time into a byte counter, which compiles to a
/// few vector compares and adds per block (a plain `filter().count()` widens
/// every byte to 64 bits).
pub fn count_newlines(buf: &[u8]) -> u64 {
    let mut blocks = buf.chunks_exact(64);
    let mut total = 0u64;
    for b in &mut blocks {
        total += b.iter().fold(0u8, |a, &c| a + (c == b'\n') as u8) as u64;
    }
    total + blocks.remainder().iter().filter(|&&c| c == b'\n').count() as u64
}

fn eat_eol(buf: &[u8], mut end: usize) -> usize {
    if buf.get(end) == Some(&b'\r') {
        end += 1;
    }
    if buf.get(end) == Some(&b'\n') {
        end += 1;
    }
    end
}

/// Sequential parser state. Offsets passed in are relative to the current block;
/// `base` is the absolute offset of the block start.
pub struct Parser {
    strict: bool,
    size_hint: u64,
    pub data: VnData,
    /// Absolute offset of the current block's first byte.
    base: u64,
    /// Newlines counted before absolute offset `line_pos` (for locations).
    lines: u64,
    line_pos: u64,
    /// End (absolute) of the current run of skipped bytes, to record each run once.
    skip_end: u64,
    /// Binary configurations seen: layout, table name, decoded rows (moved to
    /// `data.tables` by `finish`).
    layouts: Vec<(Layout, String, Table)>,
    /// Indices into `layouts` of configurations that framed a good packet.
    good_layouts: Vec<usize>,
    /// CRC failures of configurations not (yet) seen in a good packet: counted as
    /// `bad_checksum` once the configuration frames a good packet.
    pending: Vec<(usize, Location)>,
    /// First damaged record in strict mode: kind, location, reason.
    pub fail: Option<Failure>,
    /// Message type of the last sentence taken by the fast path.
    last_spec: Option<&'static ascii::MsgSpec>,
    /// Whether common sentences take [`ascii::fast_sentence`] (off only to check
    /// that the result is the same without it).
    fast: bool,
    /// Blocks at least this long are parsed on all cores.
    parallel_min: usize,
    /// Pieces parsed on other cores and merged (for tests).
    merged_pieces: u64,
    /// Locations kept for runs of skipped bytes (one more in a piece of a
    /// parallel parse, see [`Parser::feed_block`]).
    skip_keep: usize,
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
            fast: true,
            parallel_min: PARALLEL_MIN,
            merged_pieces: 0,
            skip_keep: FIRST_KEEP,
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
                self.fail = Some((kind, loc, reason.to_string()));
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
                    let mut table = Table::new(spec.fields.iter().map(|s| s.to_string()).collect());
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
        let Some(spec) = ascii::spec_by_id(&head[..5]) else {
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
        while i < n {
            if self.fail.is_some() {
                return n;
            }
            match buf[i] {
                b'$' if self.fast && self.fast_ascii(buf, &mut i) => {}
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
                0xFA => match self.binary_at(buf, i, fin) {
                    None => break,
                    Some(next) => i = next,
                },
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
    fn fast_ascii(&mut self, buf: &[u8], i: &mut usize) -> bool {
        let Some((spec, values, star)) = ascii::fast_sentence(&buf[*i..], self.last_spec) else {
            return false;
        };
        self.last_spec = Some(spec);
        let end = eat_eol(buf, *i + star + 3);
        let len = end - *i;
        let table = match self.data.tables.get_mut(spec.id) {
            Some(t) => t,
            None => {
                let mut table = Table::new(spec.fields.iter().map(|s| s.to_string()).collect());
                table.reserve(self.rows_hint(len));
                self.data.tables.entry(spec.id.to_string()).or_insert(table)
            }
        };
        table.push_row(&values[..spec.fields.len()]);
        self.data.bytes_parsed += len as u64;
        self.data.ascii_records += 1;
        *i = end;
        true
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
                    self.fail = Some((kind, *loc, "binary packet CRC mismatch".to_string()));
                }
            }
            self.pending.retain(|(p, _)| *p != k);
        }
        let (layout, _, table) = &mut self.layouts[k];
        if table.names.is_empty() {
            *table = Table::new(layout.column_names());
            let rows = (self.size_hint.saturating_sub(self.base + i as u64) / (end - i) as u64)
                .min(1 << 32) as usize;
            table.reserve(rows);
        }
        binary::decode_into(layout, &buf[i + hl..i + hl + size], table);
        self.data.bytes_parsed += (end - i) as u64;
        self.data.binary_records += 1;
        Some(end)
    }

    /// Parse a block, using all cores when it is large and pure ASCII.
    pub fn feed_block(&mut self, buf: &[u8], fin: bool) -> usize {
        if buf.len() < self.parallel_min || self.fail.is_some() {
            return self.feed(buf, fin);
        }
        if buf.contains(&0xFA) {
            return self.feed_block_binary(buf, fin);
        }
        // Everything up to the last newline is split into pieces at newlines and
        // parsed in parallel; only the tail after it (part of one line, which may
        // continue in the next block) is parsed sequentially and carried over.
        let Some(end_nl) = buf.iter().rposition(|&c| c == b'\n').map(|p| p + 1) else {
            return self.feed(buf, fin);
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
        let results: Vec<(VnData, Option<Failure>, u64, u64)> = inner
            .par_iter()
            .map(|&(a, b)| {
                let piece = &buf[a..b];
                let mut p = Parser::with_size_hint(strict, piece.len() as u64);
                p.fast = fast;
                // One spare location, for a run of skipped bytes that turns out
                // to continue one from the previous piece.
                p.skip_keep = FIRST_KEEP + 1;
                p.feed(piece, true);
                // `feed` consumed the whole piece and counted its newlines
                // (unless strict mode stopped it, when the count is not used).
                let nl = p.lines;
                (p.data, p.fail, nl, p.skip_end)
            })
            .collect();
        // Lines before the block (kept current by `feed`).
        let mut line_shift = self.lines;
        let mut parts = TableParts::default();
        for ((a, b), (mut data, fail, nl, skip_end)) in inner.iter().zip(results) {
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
            if let Some((kind, loc, reason)) = fail {
                let loc = Location {
                    offset: loc.offset + shift_offset,
                    line: loc.line + line_shift,
                };
                self.fail = Some((kind, loc, reason));
                let scale = self.rows_scale(self.base, *b, buf.len());
                parts.flush(&mut self.data, scale);
                return buf.len();
            }
            line_shift += nl;
        }
        // The tables of all pieces, appended in one parallel copy.
        let scale = self.rows_scale(self.base, last, buf.len());
        parts.flush(&mut self.data, scale);
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
        let results: Vec<(Parser, usize)> = bounds
            .par_iter()
            .enumerate()
            .map(|(k, &(a, b))| {
                let mut p = Parser::with_size_hint(strict, (b - a) as u64);
                p.fast = fast;
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
            mine.append_all(parts, (rows as f64 * scale) as usize);
        }
        ascii_parts.flush(&mut self.data, scale);
        consumed
    }

    /// Rows to reserve per row decoded, when `done` bytes from absolute offset
    /// `start` gave them: the rest of the stream (by the size hint) at the same
    /// density, with 1 % slack.
    fn rows_scale(&self, start: u64, done: usize, block: usize) -> f64 {
        let left = self.size_hint.saturating_sub(start).max(block as u64) as f64;
        left / done.max(1) as f64 * 1.01
    }

    /// Finish: pad tables and turn a strict-mode failure into an error.
    pub fn finish(mut self) -> CoreResult<VnData> {
        if let Some((kind, loc, reason)) = self.fail.take() {
            return Err(CoreError::Parse(format!(
                "line {} (byte offset {}): {}: {}",
                loc.line,
                loc.offset,
                kind.name(),
                reason
            )));
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

/// Parse the complete records at the start of `data`, one piece of a longer
/// stream: returns the number of bytes consumed and the records decoded from
/// them. Unless `fin`, a record cut by the end of `data` is not consumed; the
/// caller passes it again at the start of the next piece. Locations in the
/// result are relative to `data` (offset 0, line 1).
pub fn parse_prefix(data: &[u8], strict: bool, fin: bool) -> CoreResult<(usize, VnData)> {
    let mut p = Parser::with_size_hint(strict, data.len() as u64);
    let used = p.feed_block(data, fin);
    p.finish().map(|d| (used, d))
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
    let file = std::fs::File::open(path)
        .map_err(|e| CoreError::Io(format!("cannot open {}: {e}", path.display())))?;
    let total = file.metadata().map(|m| m.len()).unwrap_or(0);
    parse_reader(file, total, strict, progress)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const A1: &[u8] = b"$VNYMR,+100.949,-007.330,+000.715,-00.0049,-00.2449,+00.5397,-01.258,-00.100,-09.701,-00.000018,+00.001122,-00.000551*69\r\n";
    const B1: [u8; 26] = [
        0xFA, 0x01, 0x09, 0x00, 0x70, 0x05, 0x00, 0x03, 0x0A, 0x00, 0x00, 0x00, 0x48, 0x0E, 0x2C,
        0x42, 0x08, 0x4C, 0x37, 0xC1, 0x10, 0x38, 0x8B, 0xC2, 0xD4, 0xCB,
    ];

    /// Test vector B2 of the spec: a second binary configuration.
    fn binary_b2() -> Vec<u8> {
        let hex = "FA0128 05A802C33FE789B0423DA96AC1D083543A923E0BBB1C2530BA047D1C413BB2833D4EEA9CBEF1BD93BEA4558CBD26C7773EF428E641 57CEC142C0E9";
        let h: String = hex.chars().filter(|c| !c.is_whitespace()).collect();
        (0..h.len())
            .step_by(2)
            .map(|i| u8::from_str_radix(&h[i..i + 2], 16).unwrap_or(0))
            .collect()
    }

    fn accounted(d: &VnData, n: usize) -> bool {
        d.bytes_total == n as u64
            && d.bytes_parsed + d.bytes_in_bad_records + d.bytes_skipped == n as u64
            && d.issues.count(IssueKind::BytesSkipped) == d.bytes_skipped
    }

    #[test]
    fn spec_sentences() {
        let text = b"$VNYPR,+010.071,+000.278,-002.026*60\r\n\
$VNYPR,+010.071,+000.278,-002.026,T1162704*2F\r\n\
$VNYPR,+010.071,+000.278,-002.026,S0000*1F\n\
$VNRRG,27,+006.380,+000.023,-001.953,+1.0640,-0.2531,+3.0614,+00.005,+00.344,-09.758,-0.001222,-0.000450,-0.001218*4F\r\n\
$VNERR,03*72\r\n$VNWNV*57\r\n$VNRRG,15*92EA\r\n\
$VNQMR,-0.017057,-0.000767,+0.056534,+0.998255,+1.0670,-0.2568,+3.0696,-00.019,+00.320,-09.802,-0.002801,-0.001186,-0.001582*65\r\n\
$VNERR,12*72\r\n";
        let d = parse_bytes(text, false).unwrap();
        assert!(accounted(&d, text.len()));
        let ypr = &d.tables["VNYPR"];
        assert_eq!(ypr.len, 3);
        assert_eq!(ypr.column(0), vec![10.071; 3]);
        let t = &ypr
            .extra
            .iter()
            .find(|(n, _)| n == "serial_count")
            .unwrap()
            .1;
        assert!(t[0].is_nan() && t[1] == 1162704.0 && t[2].is_nan());
        assert_eq!(d.tables["VNYMR"].column(0), vec![6.380]);
        assert_eq!(d.issues.count(IssueKind::DeviceError), 1);
        assert_eq!(d.issues.count(IssueKind::BadChecksum), 1);
        assert_eq!(d.issues.count(IssueKind::MalformedField), 1);
        assert_eq!(d.messages["VNWNV"], 1);
        assert_eq!(d.messages["VNRRG"], 1);
        assert_eq!(d.issues.first[IssueKind::BadChecksum as usize][0].line, 8);
        let err = parse_bytes(text, true).unwrap_err();
        assert!(err.to_string().starts_with("line 8 "), "{err}");
    }

    #[test]
    fn interleaved_and_truncated() {
        let mut s = Vec::new();
        s.extend_from_slice(b"noise");
        s.extend_from_slice(&B1);
        s.extend_from_slice(A1);
        s.extend_from_slice(&B1);
        s.extend_from_slice(&A1[..50]);
        s.extend_from_slice(&B1);
        s.extend_from_slice(&B1[..20]);
        let d = parse_bytes(&s, false).unwrap();
        assert!(accounted(&d, s.len()));
        assert_eq!(d.binary_records, 3);
        assert_eq!(d.ascii_records, 1);
        assert_eq!(d.issues.count(IssueKind::TruncatedRecord), 2);
        assert_eq!(d.issues.count(IssueKind::BytesSkipped), 5);
        // Corrupt the CRC of the second packet: counted, neighbours kept.
        let mut bad = s.clone();
        bad[5 + 26 + A1.len() + 25] ^= 1;
        let d = parse_bytes(&bad, false).unwrap();
        assert_eq!(d.binary_records, 2);
        assert_eq!(d.issues.count(IssueKind::BadChecksum), 1);
        assert!(accounted(&d, s.len()));
    }

    #[test]
    fn damaged_records_mark_missing_rows() {
        // Good, bad checksum, good, truncated, malformed, good, unknown type, good:
        // three samples of the $VNYMR stream lost, after rows 1, 2 and 2.
        let mut bad_sum = A1.to_vec();
        bad_sum[10] = b'9';
        let malformed = b"$VNYMR,1,2*XX\r\n";
        let parts: [&[u8]; 9] = [
            A1,
            &bad_sum,
            A1,
            &A1[..40],
            b"\r\n",
            malformed,
            A1,
            b"$VNXYZ,1*00\r\n",
            A1,
        ];
        let s = parts.concat();
        let whole = parse_bytes(&s, false).unwrap();
        let ymr = &whole.tables["VNYMR"];
        assert_eq!(ymr.len, 4);
        assert_eq!(ymr.missing, vec![1, 2, 2]);
        // The same in pieces on all cores.
        let par = parse_bytes_with(Parser::new(false).with_parallel_min(64), &s).unwrap();
        assert_eq!(par.tables["VNYMR"].missing, ymr.missing);
        // A binary packet with a bad CRC between good ones of its configuration.
        let mut b = Vec::new();
        b.extend_from_slice(&B1);
        let mut broken = B1;
        broken[20] ^= 1;
        b.extend_from_slice(&broken);
        b.extend_from_slice(&B1);
        let d = parse_bytes(&b, false).unwrap();
        let table = d.tables.values().find(|t| t.len == 2).unwrap();
        assert_eq!(table.missing, vec![1]);
    }

    /// Mutates `s` by (position, byte, operation) edits: 0 inserts the byte, 1
    /// removes one, 2 overwrites one (positions wrap around the current length).
    fn apply_edits(s: &mut Vec<u8>, edits: &[(u16, u8, u8)]) {
        for &(pos, byte, op) in edits {
            let i = pos as usize % (s.len() + 1);
            match op {
                0 => s.insert(i, byte),
                1 if i < s.len() => {
                    s.remove(i);
                }
                _ if i < s.len() => s[i] = byte,
                _ => {}
            }
        }
    }

    /// `records` ASCII sentences with a binary packet before every `every`-th one.
    fn interleaved(records: usize, every: usize) -> Vec<u8> {
        let mut s = Vec::new();
        for k in 0..records {
            if k % every == 0 {
                s.extend_from_slice(&B1);
            }
            s.extend_from_slice(A1);
        }
        s
    }

    #[test]
    fn chunked_reader_equals_whole() {
        let s = interleaved(5000, 7);
        let whole = parse_bytes(&s, false).unwrap();
        struct Slow<'a>(&'a [u8], usize);
        impl std::io::Read for Slow<'_> {
            fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
                let n = buf.len().min(self.1).min(self.0.len());
                buf[..n].copy_from_slice(&self.0[..n]);
                self.0 = &self.0[n..];
                Ok(n)
            }
        }
        let mut calls = 0;
        let chunked = parse_reader(Slow(&s, 977), s.len() as u64, false, &mut |_, _| {
            calls += 1;
            Ok(())
        })
        .unwrap();
        assert_eq!(whole, chunked);
        assert_eq!(whole.tables["VNYMR"].len, 5000);
        assert!(calls >= 1);
    }

    #[test]
    fn prefixes_add_up_to_the_whole() {
        let s = interleaved(3000, 5);
        let whole = parse_bytes(&s, false).unwrap();
        for piece in [61usize, 1000, 4096] {
            let (mut pos, mut rows, mut packets, mut total) = (0usize, 0usize, 0u64, 0u64);
            let mut want = piece;
            loop {
                let end = (pos + want).min(s.len());
                let fin = end == s.len();
                let (used, d) = parse_prefix(&s[pos..end], false, fin).unwrap();
                rows += d.tables.get("VNYMR").map_or(0, |t| t.len);
                packets += d.binary_records;
                total += d.bytes_total;
                assert_eq!(d.issues.counts.iter().sum::<u64>(), 0);
                // A piece shorter than a record consumes nothing: offer more.
                want = if used == 0 { want * 2 } else { piece };
                pos += used;
                if fin {
                    break;
                }
            }
            assert_eq!(rows, whole.tables["VNYMR"].len);
            assert_eq!(packets, whole.binary_records);
            assert_eq!(total, s.len() as u64);
        }
    }

    #[test]
    fn parallel_binary_takes_clean_pieces() {
        let b2 = binary_b2();
        let mut s = Vec::new();
        for k in 0..30_000 {
            s.extend_from_slice(if k % 3 == 0 { &b2 } else { &B1 });
            if k % 1000 == 0 {
                s.extend_from_slice(A1);
            }
        }
        let want = format!("{:?}", reference(&s, false).unwrap());
        let mut p = Parser::with_size_hint(false, s.len() as u64);
        let used = p.feed_block(&s, true);
        assert_eq!(used, s.len());
        assert!(p.merged_pieces >= 2, "{}", p.merged_pieces);
        assert_eq!(format!("{:?}", p.finish().unwrap()), want);
        // Damage in the middle: pieces before it are merged, the rest is sequential.
        let half = s.len() / 2;
        let mid = half + s[half..].iter().position(|&c| c == 0xFA).unwrap_or(0) + 6;
        s[mid] ^= 0x55;
        let want = format!("{:?}", reference(&s, false).unwrap());
        let mut p = Parser::with_size_hint(false, s.len() as u64);
        p.feed_block(&s, true);
        assert!(p.merged_pieces >= 1);
        let got = p.finish().unwrap();
        assert_eq!(got.issues.count(IssueKind::BadChecksum), 1);
        assert_eq!(format!("{got:?}"), want);
    }

    #[test]
    fn parallel_equals_sequential() {
        let mut s = Vec::new();
        for k in 0..40_000u32 {
            if k % 1000 == 3 {
                s.extend_from_slice(&A1[..60]);
                s.push(b'\n');
            }
            s.extend_from_slice(A1);
        }
        let par = parse_bytes(&s, false).unwrap();
        let mut p = Parser::new(false);
        p.feed(&s, true);
        let seq = p.finish().unwrap();
        assert_eq!(par, seq);
        assert_eq!(par.tables["VNYMR"].len, 40_000);
        assert_eq!(par.issues.count(IssueKind::TruncatedRecord), 40);
        let err = parse_bytes(&s, true).unwrap_err().to_string();
        assert!(err.starts_with("line 4 "), "{err}");
    }

    /// Sequential parse without the ASCII fast path: the reference behaviour.
    fn reference(data: &[u8], strict: bool) -> CoreResult<VnData> {
        let mut p = Parser::new(strict).without_fast_path();
        p.feed(data, true);
        p.finish()
    }

    /// A number as text: sign, digits, dot, digits, in every combination the
    /// grammar allows and some it does not (empty, 20+ digits, stray bytes).
    fn number() -> impl Strategy<Value = String> {
        (
            prop_oneof![Just(""), Just("+"), Just("-")],
            "[0-9]{0,21}",
            prop_oneof![Just(""), Just(".")],
            "[0-9]{0,24}",
            prop_oneof![8 => Just(""), 1 => Just("e3"), 1 => Just("x")],
        )
            .prop_map(|(s, a, d, b, t)| format!("{s}{a}{d}{b}{t}"))
    }

    /// Sentences of random message types with random fields, then checksum or
    /// CRC (right, wrong or `XX`), appended T/S fields and line ends.
    fn sentences() -> impl Strategy<Value = Vec<u8>> {
        let one = (
            0..ascii::MESSAGES.len() + 2,
            proptest::collection::vec(number(), 0..15),
            0u8..6,
            prop_oneof![Just(""), Just(",T123"), Just(",S00A1"), Just(",T1,S0001")],
            prop_oneof![
                Just("\r\n"),
                Just("\n"),
                Just(""),
                Just("\r"),
                Just("7"),
                Just("X")
            ],
            any::<bool>(),
        )
            .prop_map(|(m, fields, check, tail, eol, exact)| {
                let id = match ascii::MESSAGES.get(m) {
                    Some(spec) => spec.id,
                    None if m == ascii::MESSAGES.len() => "VNRRG",
                    None => "VNGPS",
                };
                let mut body = id.to_string();
                let n = ascii::MESSAGES
                    .get(m)
                    .map_or(fields.len(), |s| s.fields.len());
                let take = if exact {
                    n.min(fields.len())
                } else {
                    fields.len()
                };
                for f in fields.iter().take(take) {
                    body.push(',');
                    body.push_str(f);
                }
                if exact {
                    for _ in take..n {
                        body.push_str(",+1.5");
                    }
                }
                body.push_str(tail);
                let x = checksum::xor8(body.as_bytes());
                let c = checksum::crc16(body.as_bytes());
                let field = match check {
                    0 | 1 => format!("{x:02X}"),
                    2 => format!("{x:02x}"),
                    3 => format!("{c:04X}"),
                    4 => format!("{:02X}", x ^ 1),
                    _ => "XX".to_string(),
                };
                format!("${body}*{field}{eol}").into_bytes()
            });
        proptest::collection::vec(one, 1..40).prop_map(|v| v.concat())
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

        #[test]
        fn fast_path_agrees(s in sentences(), cut in any::<u16>()) {
            // Debug text compares NaN padding and the sign of zero exactly.
            let text = |d: CoreResult<VnData>| match d {
                Ok(d) => format!("{d:?}"),
                Err(e) => e.to_string(),
            };
            let want = text(reference(&s, false));
            prop_assert_eq!(text(parse_bytes(&s, false)), want.clone());
            let mut p = Parser::new(false);
            p.feed(&s, true);
            prop_assert_eq!(text(p.finish()), want);
            // Cut anywhere: what is consumed and decoded agrees too.
            let cut = cut as usize % (s.len() + 1);
            let (mut a, mut b) = (Parser::new(false), Parser::new(false).without_fast_path());
            prop_assert_eq!(a.feed(&s[..cut], false), b.feed(&s[..cut], false));
            prop_assert_eq!(text(a.finish()), text(b.finish()));
            prop_assert_eq!(text(parse_bytes(&s, true)), text(reference(&s, true)));
        }

        #[test]
        fn parallel_binary_equals_sequential(
            kinds in proptest::collection::vec(0u8..5, 20..200),
            edits in proptest::collection::vec((any::<u16>(), any::<u8>(), 0u8..3), 0..8),
            min in 0usize..3000,
        ) {
            // Packets of two configurations, sentences and noise, then damage.
            let b2 = binary_b2();
            let mut s = Vec::new();
            for k in kinds {
                match k {
                    0 | 1 => s.extend_from_slice(&B1),
                    2 => s.extend_from_slice(&b2),
                    3 => s.extend_from_slice(A1),
                    _ => s.extend_from_slice(b"\xfa\x01noise\n"),
                }
            }
            apply_edits(&mut s, &edits);
            let text = |d: CoreResult<VnData>| match d {
                Ok(d) => format!("{d:?}"),
                Err(e) => e.to_string(),
            };
            for strict in [false, true] {
                let par = parse_bytes_with(Parser::new(strict).with_parallel_min(min), &s);
                prop_assert_eq!(text(par), text(reference(&s, strict)));
            }
            // In pieces too, as the file reader feeds them.
            let mut r = Parser::new(false).with_parallel_min(min);
            let mut pos = 0;
            while pos < s.len() {
                let end = (pos + 700).min(s.len());
                let used = r.feed_block(&s[pos..end], end == s.len());
                pos += if used == 0 && end < s.len() {
                    r.feed_block(&s[pos..s.len()], true)
                } else {
                    used
                };
            }
            prop_assert_eq!(text(r.finish()), text(reference(&s, false)));
        }

        #[test]
        fn small_chunks_equal_whole(
            kinds in proptest::collection::vec(0u8..6, 1..300),
            chunk in 1usize..400,
            flip in any::<u16>(),
        ) {
            let b2 = binary_b2();
            let mut s = Vec::new();
            for k in kinds {
                match k {
                    0 => s.extend_from_slice(&B1),
                    1 => s.extend_from_slice(&b2),
                    2 | 3 => s.extend_from_slice(A1),
                    4 => s.extend_from_slice(&A1[..40]),
                    _ => s.extend_from_slice(b"$VNRRG,05,115200*5C\n"),
                }
            }
            let at = flip as usize % s.len();
            s[at] ^= 0x20;
            let want = format!("{:?}", reference(&s, false));
            for min in [0usize, 1 << 20] {
                let p = Parser::with_size_hint(false, s.len() as u64).with_parallel_min(min);
                let mut calls = 0u64;
                let got = parse_reader_with(p, &s[..], s.len() as u64, chunk, &mut |d, t| {
                    calls += 1;
                    assert!(d <= t);
                    Ok(())
                });
                let got = format!("{got:?}");
                if got != want {
                    let k = got.bytes().zip(want.bytes()).take_while(|(a, b)| a == b).count();
                    panic!("min {min}: got {} want {}", &got[k.saturating_sub(200)..(k + 300).min(got.len())], &want[k.saturating_sub(200)..(k + 300).min(want.len())]);
                }
                prop_assert!(calls >= (s.len() / chunk) as u64);
            }
        }

        #[test]
        fn random_bytes_are_accounted(data in proptest::collection::vec(any::<u8>(), 0..3000)) {
            let d = parse_bytes(&data, false).unwrap();
            prop_assert!(accounted(&d, data.len()));
        }

        #[test]
        fn mutated_streams_are_accounted(
            edits in proptest::collection::vec((any::<u16>(), any::<u8>(), 0u8..3), 0..20)
        ) {
            let mut s = Vec::new();
            for _ in 0..10 {
                s.extend_from_slice(A1);
                s.extend_from_slice(&B1);
            }
            apply_edits(&mut s, &edits);
            let d = parse_bytes(&s, false).unwrap();
            prop_assert!(accounted(&d, s.len()));
            let _ = parse_bytes(&s, true);
        }
    }
}
