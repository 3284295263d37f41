//! A stream fed piece by piece, its rows handed out as they are decoded: for
//! logs larger than memory, written out while they are read.
//!
//! [`Pieces::feed`] parses the complete records of the bytes so far (a record
//! cut by the end of a piece waits for the next) with one [`Parser`], so issue
//! counts, first locations, binary configurations and line numbers run on across
//! pieces exactly as in one whole-stream parse; only the rows are moved out.
//! Each table handed out holds the rows decoded since the last call, and its
//! `missing` counts good rows of that piece. Cost: that of the parse, plus a copy
//! of a cut record's bytes and the first 64 KiB of the next piece, per piece.

use std::collections::BTreeMap;

use crate::error::CoreResult;
use crate::vn::stream::Parser;
use crate::vn::{Table, VnData};

/// Bytes of a new piece joined to a cut record to finish it (longer than any
/// record, so that the join nearly always completes it).
const BRIDGE: usize = 1 << 16;

/// Buffers kept by [`Pieces::give_back`]: one piece's rows is a few tens of MB, so
/// a bound keeps idle memory to a few pieces whatever the caller gives back.
pub const HANDED_BACK: usize = 2;

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
        let mut rest = data;
        if !self.carry.is_empty() {
            // The record cut by the last piece is finished from the first bytes of
            // this one; the piece itself is then parsed in place, not copied
            // behind the carry. Only a cut record longer than the bridge (noise
            // without a record end) falls back to joining the whole piece.
            let kept = self.carry.len();
            let bridge = data.len().min(BRIDGE);
            self.carry.extend_from_slice(&data[..bridge]);
            let used = self.parser.feed_block(&self.carry, false);
            if used >= kept {
                self.carry.clear();
                rest = &data[used - kept..];
            } else {
                self.carry.drain(..used);
                self.carry.extend_from_slice(&data[bridge..]);
                let used = self.parser.feed_block(&self.carry, false);
                self.carry.drain(..used);
                rest = &[];
            }
        }
        if !rest.is_empty() && self.parser.fail.is_none() {
            let used = self.parser.feed_block(rest, false);
            self.carry.extend_from_slice(&rest[used..]);
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

    /// Give back the value buffer of a table [`Pieces::feed`] returned, once its
    /// rows are used: the next piece's rows are decoded into it. At most
    /// [`HANDED_BACK`] are kept (one per table of a log, in practice one).
    pub fn give_back(&mut self, buffer: Vec<f64>) {
        self.parser.give_back(buffer, HANDED_BACK);
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
