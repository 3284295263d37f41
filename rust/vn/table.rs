//! One message type's decoded records as a row-major `f64` matrix ([`Table`]).
//!
//! Cost: one `push_row` is a copy of the record's fields into a vector that grows
//! geometrically; merging pieces of a parallel parse copies them on all cores.

/// Values [`Table::push_with`] may write at the end of a table.
pub(crate) const SCRATCH: usize = crate::vn::messages::MAX_FIELDS;

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

    /// An empty table whose values go into `buffer` (cleared; its capacity kept):
    /// a buffer recycled from an earlier piece of a parallel parse is memory
    /// already mapped, where a fresh one is zeroed page by page by the kernel.
    pub(crate) fn with_buffer(names: Vec<String>, mut buffer: Vec<f64>) -> Table {
        buffer.clear();
        Table {
            values: buffer,
            ..Table::new(names)
        }
    }

    /// Make room for `rows` more rows (and the scratch of [`Table::push_with`]).
    pub fn reserve(&mut self, rows: usize) {
        let want = (self.len + rows)
            .saturating_mul(self.ncols())
            .saturating_add(SCRATCH);
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

    /// Append one record that `fill` writes at the pointer it gets: room for
    /// [`SCRATCH`] values, of which the first `ncols()` are the record (the
    /// rest may be overwritten by the next one). Nothing is appended when
    /// `fill` returns `false`. Vector kernels store their lanes in place so,
    /// without a copy through a temporary.
    ///
    /// # Safety
    /// `fill` writes at most `SCRATCH` values at the pointer, and all of the
    /// first `ncols()` when it returns `true`.
    #[inline]
    pub(crate) unsafe fn push_with(&mut self, fill: impl FnOnce(*mut f64) -> bool) -> bool {
        if self.values.capacity() - self.values.len() < SCRATCH {
            self.reserve(self.len.max(1024));
        }
        let dst = self.values.spare_capacity_mut().as_mut_ptr().cast::<f64>();
        if !fill(dst) {
            return false;
        }
        // SAFETY: the first ncols() spare values were written by `fill`.
        unsafe { self.values.set_len(self.values.len() + self.ncols()) };
        self.len += 1;
        true
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
    /// least the rows appended). Returns the parts' emptied value buffers, for
    /// reuse.
    pub(crate) fn append_all(&mut self, mut parts: Vec<Table>, rows_hint: usize) -> Vec<Vec<f64>> {
        use rayon::prelude::*;
        let add: usize = parts.iter().map(|p| p.values.len()).sum();
        if self.values.capacity() - self.values.len() < add {
            let rows: usize = parts.iter().map(|p| p.len).sum();
            self.reserve(rows_hint.max(rows));
        }
        let old = self.values.len();
        let mut emptied = Vec::with_capacity(parts.len());
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
                let mut buffer = std::mem::take(&mut p.values);
                buffer.clear();
                emptied.push(buffer);
            }
        }
        // Extra columns and the row count (and the values, had the room above
        // been missing) part by part.
        for p in parts {
            self.append(p);
        }
        emptied
    }

    pub(crate) fn append(&mut self, mut other: Table) {
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
