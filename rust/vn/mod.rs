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

/// One message type's decoded records as columns of `f64`.
///
/// `columns[k]` holds field `names[k]` for every record. `extra` columns (the
/// appended `T`/`S` fields of ASCII sentences) are created when first seen and
/// hold NaN for records that lack them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Table {
    pub names: Vec<String>,
    pub columns: Vec<Vec<f64>>,
    pub extra: Vec<(String, Vec<f64>)>,
    pub len: usize,
}

impl Table {
    pub fn new(names: Vec<String>) -> Table {
        let columns = names.iter().map(|_| Vec::new()).collect();
        Table {
            names,
            columns,
            extra: Vec::new(),
            len: 0,
        }
    }

    /// Make room for `rows` more rows in every column.
    pub fn reserve(&mut self, rows: usize) {
        let want = self.len + rows;
        for c in &mut self.columns {
            if c.capacity() < want {
                c.reserve(want - c.len());
            }
        }
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
        for c in &mut self.columns {
            if c.capacity() > c.len() + c.len() / 8 + 64 {
                c.shrink_to_fit();
            }
        }
    }

    fn append(&mut self, mut other: Table) {
        for (mine, theirs) in self.columns.iter_mut().zip(other.columns.iter_mut()) {
            mine.append(theirs);
        }
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
