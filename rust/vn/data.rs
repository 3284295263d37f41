//! Everything a parse produced ([`VnData`]): tables, message counts, issues and
//! the byte accounting, and how the results of consecutive pieces add up.

use std::collections::BTreeMap;

use crate::vn::{Issues, Table};

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
