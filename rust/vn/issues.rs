//! What can go wrong in a VectorNav stream, and where it went wrong first.
//!
//! One [`IssueKind`] per class of damage, counted per record (per byte for
//! `bytes_skipped`), with the first [`FIRST_KEEP`] locations of each kind.
//! [`IssueKind::ALL`] in this order is the list the Python side shows
//! (`_core.vn.ISSUE_KINDS`). Cost: O(1) per issue.

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

    pub(crate) fn merge(&mut self, other: &Issues, line_shift: u64) {
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
