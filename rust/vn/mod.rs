//! VectorNav VN-100 parsing (spec: VN-100 serial output formats).
//!
//! * [`checksum`] — XOR-8 and CRC-16/XMODEM.
//! * [`ascii`] — the `$VN...*hh` sentences: message table, field decoding.
//! * [`binary`] — `0xFA` binary output packets: header, field sizes, decoding.
//! * [`stream`] — one reader that walks any byte stream (ASCII and binary
//!   interleaved), in chunks, accounting for every byte.
//! * [`write`] — writers for both formats (simulator, round-trip tests).
//!
//! Output is one column table per message type ([`Table`], struct of arrays of
//! `f64`); no heap object is made per record.

pub mod ascii;
pub mod binary;
pub mod checksum;
pub mod stream;
pub mod write;

use std::collections::BTreeMap;

/// What went wrong with a record (or, for `BytesSkipped`, with bytes between records).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IssueKind {
    BadChecksum = 0,
    MalformedField = 1,
    UnknownMessage = 2,
    TruncatedRecord = 3,
    BytesSkipped = 4,
    DeviceError = 5,
}

impl IssueKind {
    pub const ALL: [IssueKind; 6] = [
        IssueKind::BadChecksum,
        IssueKind::MalformedField,
        IssueKind::UnknownMessage,
        IssueKind::TruncatedRecord,
        IssueKind::BytesSkipped,
        IssueKind::DeviceError,
    ];

    pub fn name(self) -> &'static str {
        match self {
            IssueKind::BadChecksum => "bad_checksum",
            IssueKind::MalformedField => "malformed_field",
            IssueKind::UnknownMessage => "unknown_message",
            IssueKind::TruncatedRecord => "truncated_record",
            IssueKind::BytesSkipped => "bytes_skipped",
            IssueKind::DeviceError => "device_error",
        }
    }

    /// Kinds that make strict mode fail: damaged records. Unknown (well-formed)
    /// messages, device error reports and noise between records do not.
    pub fn fails_strict(self) -> bool {
        matches!(
            self,
            IssueKind::BadChecksum | IssueKind::MalformedField | IssueKind::TruncatedRecord
        )
    }
}

/// Where an issue happened: 0-based byte offset and 1-based line number.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Location {
    pub offset: u64,
    pub line: u64,
}

/// How many locations are kept per kind.
pub const FIRST_KEEP: usize = 5;

/// Issue counts (records, or bytes for `BytesSkipped`) and first locations.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Issues {
    pub counts: [u64; 6],
    pub first: [Vec<Location>; 6],
}

impl Issues {
    pub fn count(&self, kind: IssueKind) -> u64 {
        self.counts[kind as usize]
    }

    /// Whether a location for `kind` would still be kept.
    pub fn wants_location(&self, kind: IssueKind) -> bool {
        self.first[kind as usize].len() < FIRST_KEEP
    }

    fn merge(&mut self, other: &Issues, line_shift: u64) {
        for k in 0..6 {
            self.counts[k] += other.counts[k];
            for loc in &other.first[k] {
                if self.first[k].len() < FIRST_KEEP {
                    self.first[k].push(Location {
                        offset: loc.offset,
                        line: loc.line + line_shift,
                    });
                }
            }
        }
    }
}

/// One message type's decoded records: a row-major matrix of `f64`.
///
/// Row `r` holds the record's fields in `names` order at
/// `values[r * names.len()..(r + 1) * names.len()]`: one write stream per record
/// while parsing, and one array that the bindings hand to numpy without a copy
/// (columns and channel triples are views of it). `extra` columns (the appended
/// `T`/`S` fields of ASCII sentences) are created when first seen and hold NaN
/// for records that lack them. `missing` holds, for every damaged record of this
/// type (bad checksum or CRC, malformed field, truncated), the number of good
/// rows before it: where a sample of this stream was lost.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Table {
    pub names: Vec<String>,
    pub values: Vec<f64>,
    pub extra: Vec<(String, Vec<f64>)>,
    pub len: usize,
    pub missing: Vec<u64>,
}

impl Table {
    pub fn new(names: Vec<String>) -> Table {
        Table {
            names,
            values: Vec::new(),
            extra: Vec::new(),
            len: 0,
            missing: Vec::new(),
        }
    }

    /// Note a damaged record of this type after the rows pushed so far.
    pub(crate) fn note_missing(&mut self) {
        self.missing.push(self.len as u64);
    }

    /// Fields per record.
    #[inline]
    pub fn ncols(&self) -> usize {
        self.names.len()
    }

    /// Column `k` as a vector (a copy; for tests and small tables).
    pub fn column(&self, k: usize) -> Vec<f64> {
        let nc = self.ncols();
        if k >= nc {
            return Vec::new();
        }
        self.values.iter().skip(k).step_by(nc).copied().collect()
    }

    /// Make room for `rows` more rows.
    pub fn reserve(&mut self, rows: usize) {
        let want = (self.len + rows).saturating_mul(self.ncols());
        if self.values.capacity() < want {
            self.values.reserve(want - self.values.len());
            crate::memory::advise_huge_pages(&self.values);
        }
    }

    /// Append one record (`row.len() == ncols()`).
    #[inline]
    pub fn push_row(&mut self, row: &[f64]) {
        if self.values.capacity() - self.values.len() < row.len() {
            // Grow geometrically, with the huge-page advice for the new buffer.
            self.reserve(self.len.max(1024));
        }
        self.values.extend_from_slice(row);
        self.len += 1;
    }

    /// Set an extra column's value for the last pushed row.
    pub(crate) fn set_extra(&mut self, name: &str, value: f64) {
        let len = self.len;
        let col = match self.extra.iter().position(|(n, _)| n == name) {
            Some(k) => &mut self.extra[k].1,
            None => {
                self.extra.push((name.to_string(), Vec::new()));
                let last = self.extra.len() - 1;
                &mut self.extra[last].1
            }
        };
        col.resize(len.saturating_sub(1), f64::NAN);
        col.push(value);
    }

    /// Pad extra columns to the table length with NaN.
    pub fn finish(&mut self) {
        let len = self.len;
        for (_, col) in &mut self.extra {
            col.resize(len, f64::NAN);
        }
    }

    /// Give back capacity reserved beyond the rows decoded.
    pub fn shrink(&mut self) {
        let v = &mut self.values;
        if v.capacity() > v.len() + v.len() / 8 + 64 {
            v.shrink_to_fit();
        }
    }

    /// Append the rows of `parts`, in order, copying them on all cores: the
    /// pages of a fresh destination are then also first touched (and zeroed by
    /// the kernel) on all cores, which is most of the cost of a large table.
    /// If the table must grow, it makes room for `rows_hint` more rows (at
    /// least the rows appended).
    pub(crate) fn append_all(&mut self, mut parts: Vec<Table>, rows_hint: usize) {
        use rayon::prelude::*;
        let add: usize = parts.iter().map(|p| p.values.len()).sum();
        if self.values.capacity() - self.values.len() < add {
            let rows: usize = parts.iter().map(|p| p.len).sum();
            self.reserve(rows_hint.max(rows));
        }
        let old = self.values.len();
        if let Some(spare) = self.values.spare_capacity_mut().get_mut(..add) {
            let mut rest = spare;
            let mut slots = Vec::with_capacity(parts.len());
            for p in &parts {
                let (a, b) = rest.split_at_mut(p.values.len());
                slots.push(a);
                rest = b;
            }
            slots
                .into_par_iter()
                .zip(parts.par_iter())
                .for_each(|(dst, p)| {
                    for (d, s) in dst.iter_mut().zip(&p.values) {
                        d.write(*s);
                    }
                });
            // SAFETY: the slots partition exactly the `add` elements after
            // `old`, and each was filled from a part of its own length above.
            unsafe { self.values.set_len(old + add) };
            for p in &mut parts {
                p.values = Vec::new();
            }
        }
        // Extra columns and the row count (and the values, had the room above
        // been missing) part by part.
        for p in parts {
            self.append(p);
        }
    }

    fn append(&mut self, mut other: Table) {
        if self.values.capacity() - self.values.len() < other.values.len() {
            self.reserve(other.len.max(self.len));
        }
        self.values.append(&mut other.values);
        let shift = self.len as u64;
        self.missing.extend(other.missing.iter().map(|r| r + shift));
        self.finish();
        other.finish();
        for (name, col) in other.extra {
            if !self.extra.iter().any(|(n, _)| *n == name) {
                self.extra.push((name.clone(), vec![f64::NAN; self.len]));
            }
            if let Some((_, mine)) = self.extra.iter_mut().find(|(n, _)| *n == name) {
                mine.extend_from_slice(&col);
            }
        }
        self.len += other.len;
        self.finish();
    }
}

/// Everything a parse produced.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct VnData {
    /// Decoded tables by message name (`"VNYMR"`, `"VNERR"`, `"binary_14_3e00_3a00"` ...).
    pub tables: BTreeMap<String, Table>,
    /// Records decoded per message name, including command responses that carry no
    /// table (`"VNRRG"`, `"VNWRG"` ...).
    pub messages: BTreeMap<String, u64>,
    pub issues: Issues,
    /// Bytes in decoded records (ASCII sentences with their line end, binary packets).
    pub bytes_parsed: u64,
    /// Bytes in damaged or undecoded ASCII records (counted by record in `issues`).
    pub bytes_in_bad_records: u64,
    /// Bytes belonging to no record (`issues.counts[BytesSkipped]` is the same number).
    pub bytes_skipped: u64,
    pub bytes_total: u64,
    pub ascii_records: u64,
    pub binary_records: u64,
}

impl VnData {
    pub(crate) fn merge(&mut self, other: VnData, line_shift: u64) {
        for (name, table) in other.tables {
            match self.tables.get_mut(&name) {
                Some(t) => t.append(table),
                None => {
                    self.tables.insert(name, table);
                }
            }
        }
        for (name, n) in other.messages {
            *self.messages.entry(name).or_insert(0) += n;
        }
        self.issues.merge(&other.issues, line_shift);
        self.bytes_parsed += other.bytes_parsed;
        self.bytes_in_bad_records += other.bytes_in_bad_records;
        self.bytes_skipped += other.bytes_skipped;
        self.bytes_total += other.bytes_total;
        self.ascii_records += other.ascii_records;
        self.binary_records += other.binary_records;
    }
}
