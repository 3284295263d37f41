//! A file of fixed-size records of `f64` grown by appending rows: the data part of
//! a `.npy` file (a structured array of float64 fields, or a plain float64 array)
//! after a header that the caller wrote and rewrites when the row count is known.
//!
//! Each record is the concatenation of one row of every [`Columns`] block (a
//! strided view of a matrix, e.g. three adjacent columns of the parser's
//! row-major table): rows are gathered into a buffer of [`GATHER_BYTES`] that stays
//! in cache and written from it, so a piece's rows reach the file in one copy,
//! and hashed from it too ([`HeadLast`]: the file's BLAKE3 digest, the header
//! joining it at the end), so the data need not be read again for the digest.
//! Cost: O(values appended); memory: the buffer.

use std::fs::File;
use std::io::Write;
use std::path::Path;

use crate::digest::HeadLast;
use crate::error::{CoreError, CoreResult};

/// Bytes gathered before each write (a cache-sized buffer: larger ones only add
/// page faults, smaller ones more system calls).
pub const GATHER_BYTES: usize = 1 << 20;

/// `width` adjacent values per row, row `r`'s `k`-th at
/// `data[r * row_stride + k * col_stride]`.
#[derive(Debug, Clone, Copy)]
pub struct Columns<'a> {
    data: &'a [f64],
    rows: usize,
    row_stride: usize,
    col_stride: usize,
    width: usize,
}

impl<'a> Columns<'a> {
    /// A block of `rows` rows of `width` values; an error unless every value it
    /// names lies inside `data`.
    pub fn new(
        data: &'a [f64],
        rows: usize,
        width: usize,
        row_stride: usize,
        col_stride: usize,
    ) -> CoreResult<Columns<'a>> {
        let last = if rows == 0 || width == 0 {
            None
        } else {
            (rows - 1).checked_mul(row_stride).and_then(|a| {
                (width - 1)
                    .checked_mul(col_stride)
                    .and_then(|b| a.checked_add(b))
            })
        };
        let inside = match last {
            None => true,
            Some(k) => k < data.len(),
        };
        if !inside || (rows > 0 && width > 0 && last.is_none()) {
            return Err(CoreError::InvalidArgument(format!(
                "a block of {rows} rows x {width} values (strides {row_stride}, {col_stride}) \
                 does not fit in {} values",
                data.len()
            )));
        }
        Ok(Columns {
            data,
            rows,
            row_stride,
            col_stride,
            width,
        })
    }

    pub fn rows(&self) -> usize {
        self.rows
    }

    pub fn width(&self) -> usize {
        self.width
    }

    /// Append row `r`'s values to `out` as little-endian bytes.
    #[inline(always)]
    fn put_row(&self, r: usize, out: &mut Vec<u8>) {
        let start = r * self.row_stride;
        if self.col_stride == 1 {
            for v in &self.data[start..start + self.width] {
                out.extend_from_slice(&v.to_le_bytes());
            }
        } else {
            for k in 0..self.width {
                out.extend_from_slice(&self.data[start + k * self.col_stride].to_le_bytes());
            }
        }
    }
}

/// Records appended to the end of an existing file.
pub struct RecordFile {
    file: File,
    /// Values per record (the sum of the blocks' widths of every append).
    width: usize,
    rows: u64,
    buffer: Vec<u8>,
    digest: HeadLast,
}

fn io_error(path: &Path, what: &str, e: std::io::Error) -> CoreError {
    CoreError::Io {
        kind: e.kind(),
        message: format!("cannot {what} {}: {e}", path.display()),
    }
}

impl RecordFile {
    /// Opens `path` (which must exist: the caller wrote its header, whose length
    /// [`RecordFile::digest`] expects again) to append records of `width` values.
    pub fn append_to(path: &Path, width: usize) -> CoreResult<RecordFile> {
        if width == 0 {
            return Err(CoreError::InvalidArgument(
                "a record needs at least one value".into(),
            ));
        }
        let file = std::fs::OpenOptions::new()
            .append(true)
            .open(path)
            .map_err(|e| io_error(path, "open", e))?;
        let head = file
            .metadata()
            .map_err(|e| io_error(path, "stat", e))?
            .len();
        let head = usize::try_from(head).map_err(|_| {
            CoreError::InvalidArgument(format!("{} has a header of {head} bytes", path.display()))
        })?;
        Ok(RecordFile {
            file,
            width,
            rows: 0,
            buffer: Vec::with_capacity(GATHER_BYTES),
            digest: HeadLast::new(head),
        })
    }

    /// Rows appended so far.
    pub fn rows(&self) -> u64 {
        self.rows
    }

    /// Append one record per row of the blocks: row `r` of every block, in
    /// order. Every block must have the same rows and their widths must add up to
    /// the record's.
    pub fn append(&mut self, blocks: &[Columns<'_>]) -> CoreResult<()> {
        let rows = blocks.first().map_or(0, |b| b.rows);
        let width: usize = blocks.iter().map(|b| b.width).sum();
        if width != self.width || blocks.iter().any(|b| b.rows != rows) {
            let shapes: Vec<(usize, usize)> = blocks.iter().map(|b| (b.rows, b.width)).collect();
            return Err(CoreError::InvalidArgument(format!(
                "records of {} values need blocks of equal rows whose widths add up to it; \
                 got (rows, width) {shapes:?}",
                self.width
            )));
        }
        let per_write = (GATHER_BYTES / (8 * width)).max(1);
        let mut r = 0;
        while r < rows {
            let end = (r + per_write).min(rows);
            self.buffer.clear();
            for row in r..end {
                for b in blocks {
                    b.put_row(row, &mut self.buffer);
                }
            }
            self.file
                .write_all(&self.buffer)
                .map_err(|e| CoreError::Io {
                    kind: e.kind(),
                    message: format!("cannot write records: {e}"),
                })?;
            self.digest.update(&self.buffer);
            r = end;
        }
        self.rows += rows as u64;
        Ok(())
    }

    /// The BLAKE3 digest of the file: `head`, which must be as long as the header
    /// was at opening (the caller rewrites it in place), then every record.
    pub fn digest(&self, head: &[u8]) -> CoreResult<blake3::Hash> {
        self.digest.finish(head)
    }

    /// Start writing the bytes appended so far to disk, without waiting: the
    /// final flush of a large file then finds little left to write.
    pub fn start_writeback(&self) {
        #[cfg(target_os = "linux")]
        {
            use std::os::fd::AsRawFd;
            extern "C" {
                fn sync_file_range(fd: i32, offset: i64, nbytes: i64, flags: u32) -> i32;
            }
            const SYNC_FILE_RANGE_WRITE: u32 = 2;
            // SAFETY: a plain system call on a descriptor this struct owns; a
            // failure only means the final flush does the work.
            unsafe {
                sync_file_range(self.file.as_raw_fd(), 0, 0, SYNC_FILE_RANGE_WRITE);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_interleave_the_blocks() {
        let dir = std::env::temp_dir().join(format!("imunoise-records-{}", std::process::id()));
        std::fs::write(&dir, b"HEAD").unwrap();
        // A row-major 4 x 5 table; records take columns 3..5 then 0.
        let table: Vec<f64> = (0..20).map(|v| v as f64).collect();
        let tail = Columns::new(&table[3..], 4, 2, 5, 1).unwrap();
        let first = Columns::new(&table, 4, 1, 5, 1).unwrap();
        let mut f = RecordFile::append_to(&dir, 3).unwrap();
        f.append(&[tail, first]).unwrap();
        f.append(&[tail, first]).unwrap();
        assert_eq!(f.rows(), 8);
        f.start_writeback();
        let digest = f.digest(b"HEAD").unwrap();
        drop(f);
        let bytes = std::fs::read(&dir).unwrap();
        assert_eq!(digest, blake3::hash(&bytes));
        std::fs::remove_file(&dir).unwrap();
        assert_eq!(&bytes[..4], b"HEAD");
        let got: Vec<f64> = bytes[4..]
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect();
        let one = [3., 4., 0., 8., 9., 5., 13., 14., 10., 18., 19., 15.];
        assert_eq!(got, [one, one].concat());
    }

    #[test]
    fn blocks_outside_their_data_and_bad_widths_are_refused() {
        let v = [0.0; 10];
        assert!(Columns::new(&v, 4, 3, 3, 1).is_err());
        assert!(Columns::new(&v, 3, 3, 3, 1).is_ok());
        assert!(Columns::new(&v, 2, 1, usize::MAX, 1).is_err());
        assert!(Columns::new(&v, 0, 3, 100, 1).is_ok());
        let path = std::env::temp_dir().join(format!("imunoise-records-w{}", std::process::id()));
        std::fs::write(&path, b"").unwrap();
        let mut f = RecordFile::append_to(&path, 4).unwrap();
        let b = Columns::new(&v, 3, 3, 3, 1).unwrap();
        assert!(f.append(&[b]).is_err());
        let c = Columns::new(&v, 2, 1, 1, 1).unwrap();
        assert!(f.append(&[b, c]).is_err());
        std::fs::remove_file(&path).unwrap();
        assert!(RecordFile::append_to(&path, 4).is_err());
    }
}
