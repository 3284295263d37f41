//! A stream fed piece by piece, its rows handed out as they are decoded: for
//! logs larger than memory, written out while they are read.
//!
//! [`Pieces::feed`] parses the complete records of the bytes so far (a record
//! cut by the end of a piece waits for the next) with one [`Parser`], so issue
//! counts, first locations, binary configurations and line numbers run on across
//! pieces exactly as in one whole-stream parse; only the rows are moved out.
//! Each table handed out holds the rows decoded since the last call, and its
//! `missing` counts good rows of that piece. Cost: that of the parse, plus one
//! copy of a cut record's bytes per piece.

use std::collections::BTreeMap;

use crate::error::CoreResult;
use crate::vn::stream::Parser;
use crate::vn::{Table, VnData};

/// The streaming parser: feed pieces, take their rows, finish for the summary.
pub struct Pieces {
    parser: Parser,
    /// Bytes of a record cut by the end of the last piece.
    carry: Vec<u8>,
    /// Rows handed out per table, added back to the message counts at the end.
    rows_out: BTreeMap<String, u64>,
}

impl Pieces {
    pub fn new(strict: bool) -> Pieces {
        Pieces {
            parser: Parser::new(strict),
            carry: Vec::new(),
            rows_out: BTreeMap::new(),
        }
    }

    /// Parse the complete records of `data` (after what an earlier piece left)
    /// and return their rows by table name. In strict mode the first damaged
    /// record is an error.
    pub fn feed(&mut self, data: &[u8]) -> CoreResult<BTreeMap<String, Table>> {
        if self.carry.is_empty() {
            let used = self.parser.feed_block(data, false);
            self.carry.extend_from_slice(&data[used..]);
        } else {
            self.carry.extend_from_slice(data);
            let used = self.parser.feed_block(&self.carry, false);
            self.carry.drain(..used);
        }
        self.check()?;
        Ok(self.take_rows())
    }

    /// Parse what is left (a cut record is now damaged) and return its rows with
    /// the summary of the whole stream: issues, byte accounting and message
    /// counts over every piece (its tables are the last rows only).
    pub fn finish(mut self) -> CoreResult<VnData> {
        let rest = std::mem::take(&mut self.carry);
        self.parser.feed_block(&rest, true);
        self.check()?;
        let mut data = self.parser.finish()?;
        data.tables
            .retain(|_, table| table.len > 0 || !table.missing.is_empty());
        for (name, rows) in self.rows_out {
            *data.messages.entry(name).or_insert(0) += rows;
        }
        Ok(data)
    }

    fn check(&mut self) -> CoreResult<()> {
        match self.parser.fail.take() {
            Some(failure) => Err(failure.into_error()),
            None => Ok(()),
        }
    }

    fn take_rows(&mut self) -> BTreeMap<String, Table> {
        let tables = self.parser.take_tables();
        for (name, table) in &tables {
            if name != "VNERR" {
                *self.rows_out.entry(name.clone()).or_insert(0) += table.len as u64;
            }
        }
        tables
    }
}
