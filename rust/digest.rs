//! The fingerprint of a file's content (what convert's metadata records to tie
//! itself to the data it describes): size, modification time and BLAKE3 digest.
//!
//! [`fingerprint`] maps a file and hashes it in blocks of [`BLOCK_BYTES`], each by
//! every thread of the pool (BLAKE3's tree splits one block across threads), with
//! the interrupt checked between blocks. Cost: O(bytes) reads of the page cache, no
//! copy; memory: the mapping only. [`HeadLast`] hashes a file as it is written
//! whose first bytes (a header) are known only at the end.

use std::fs::File;
use std::path::Path;
use std::time::{SystemTime, UNIX_EPOCH};

use blake3::hazmat::{
    merge_subtrees_non_root, merge_subtrees_root, ChainingValue, HasherExt, Mode,
};
use blake3::{Hasher, CHUNK_LEN};

use crate::error::{CoreError, CoreResult};
use crate::interrupt::Interrupt;

/// Bytes hashed between two looks at the interrupt (a few milliseconds of
/// hashing; large enough that each block still spreads over every thread).
pub const BLOCK_BYTES: usize = 16 << 20;

/// What identifies a file's content: a rename keeps all three, a copy keeps
/// `bytes` and `blake3`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Fingerprint {
    pub bytes: u64,
    /// Modification time, nanoseconds since the Unix epoch (negative before it),
    /// as Python's `os.stat().st_mtime_ns`.
    pub mtime_ns: i128,
    /// The BLAKE3 digest (32 bytes) as 64 lowercase hex digits.
    pub blake3: String,
}

fn io_error(path: &Path, what: &str, e: std::io::Error) -> CoreError {
    CoreError::Io {
        kind: e.kind(),
        message: format!("cannot {what} {}: {e}", path.display()),
    }
}

/// `time` in nanoseconds since the epoch, negative before it.
fn nanos_since_epoch(time: SystemTime) -> i128 {
    match time.duration_since(UNIX_EPOCH) {
        Ok(after) => after.as_nanos() as i128,
        Err(before) => -(before.duration().as_nanos() as i128),
    }
}

/// The [`Fingerprint`] of the file at `path`: size and time from the open file,
/// then its first `bytes` bytes hashed, one mapped block at a time.
pub fn fingerprint(path: &Path, stop: &Interrupt) -> CoreResult<Fingerprint> {
    let file = File::open(path).map_err(|e| io_error(path, "open", e))?;
    let meta = file.metadata().map_err(|e| io_error(path, "stat", e))?;
    let mtime = meta.modified().map_err(|e| io_error(path, "stat", e))?;
    let bytes = meta.len();
    let mut hasher = blake3::Hasher::new();
    let mut offset = 0u64;
    while offset < bytes {
        stop.check()?;
        let len = (bytes - offset).min(BLOCK_BYTES as u64) as usize;
        // Each block mapped with its pages populated at once: faulting them in
        // one by one took longer than hashing them. SAFETY: the mapping is
        // read-only and private to this loop. A file truncated by another process
        // while it is hashed ends the process (SIGBUS), as it would the readers,
        // which map the same files with numpy; convert hashes only its own
        // unique temporaries.
        let map = unsafe {
            memmap2::MmapOptions::new()
                .offset(offset)
                .len(len)
                .populate()
                .map(&file)
        }
        .map_err(|e| io_error(path, "map", e))?;
        hasher.update_rayon(&map);
        offset += len as u64;
    }
    Ok(Fingerprint {
        bytes,
        mtime_ns: nanos_since_epoch(mtime),
        blake3: hasher.finalize().to_hex().to_string(),
    })
}

/// The BLAKE3 digest of a file of a head of `head` bytes, written last, and a body
/// appended in order: the body is hashed as it comes, the head at [`HeadLast::finish`].
///
/// BLAKE3's tree over 1 KiB chunks: the head lies in the first `lead` chunks (a
/// power of two), whose bytes are kept; each following span of chunks
/// `[lead·2^k, lead·2^(k+1))` is a subtree of the whole file's tree whatever its
/// final length (the last one, possibly short, the root's right child), hashed by
/// a hasher of its own. Memory: the first `lead` chunks.
pub struct HeadLast {
    head: usize,
    /// The file's first `lead * CHUNK_LEN` bytes: the head's zeros, then the body.
    first: Vec<u8>,
    lead: u64,
    /// Chaining values of the finished spans, in order.
    spans: Vec<ChainingValue>,
    /// The span being filled: its hasher and the file offset where it ends.
    current: Option<(Hasher, u64)>,
    /// Bytes of the file so far, head included.
    len: u64,
}

impl HeadLast {
    /// A hasher of a file whose first `head` bytes come at [`HeadLast::finish`].
    pub fn new(head: usize) -> HeadLast {
        let lead = (head.div_ceil(CHUNK_LEN).max(1)).next_power_of_two() as u64;
        let mut first = Vec::with_capacity(lead as usize * CHUNK_LEN);
        first.resize(head, 0);
        HeadLast {
            head,
            first,
            lead,
            spans: Vec::new(),
            current: None,
            len: head as u64,
        }
    }

    /// Hash the next `body` bytes of the file.
    pub fn update(&mut self, mut body: &[u8]) {
        let lead_bytes = self.lead * CHUNK_LEN as u64;
        while !body.is_empty() {
            let n = if self.len < lead_bytes {
                let n = body.len().min((lead_bytes - self.len) as usize);
                self.first.extend_from_slice(&body[..n]);
                n
            } else {
                // a span starts only when bytes come for it: the last one is never empty
                if matches!(self.current, Some((_, end)) if end == self.len) {
                    let (done, _) = self.current.take().expect("matched");
                    self.spans.push(done.finalize_non_root());
                }
                let (hasher, end) = self.current.get_or_insert_with(|| {
                    let mut hasher = Hasher::new();
                    hasher.set_input_offset(self.len);
                    (hasher, 2 * self.len)
                });
                let n = body.len().min((*end - self.len) as usize);
                hasher.update(&body[..n]);
                n
            };
            self.len += n as u64;
            body = &body[n..];
        }
    }

    /// The digest of the whole file, `head` being its first bytes; an error
    /// unless `head` has the length given to [`HeadLast::new`].
    pub fn finish(&self, head: &[u8]) -> CoreResult<blake3::Hash> {
        if head.len() != self.head {
            return Err(CoreError::InvalidArgument(format!(
                "the head must have the {} bytes announced; got {}",
                self.head,
                head.len()
            )));
        }
        let mut lead = Hasher::new();
        lead.update(head).update(&self.first[self.head..]);
        let Some((last, _)) = &self.current else {
            return Ok(lead.finalize()); // the whole file lies in the first chunks
        };
        let left = self
            .spans
            .iter()
            .fold(lead.finalize_non_root(), |left, span| {
                merge_subtrees_non_root(&left, span, Mode::Hash)
            });
        Ok(merge_subtrees_root(
            &left,
            &last.finalize_non_root(),
            Mode::Hash,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interrupt::NEVER;

    /// The official test vectors' input: byte i is i mod 251.
    fn pattern(n: usize) -> Vec<u8> {
        (0..n).map(|i| (i % 251) as u8).collect()
    }

    fn fingerprint_of(data: &[u8], name: &str, stop: &Interrupt) -> CoreResult<Fingerprint> {
        let path =
            std::env::temp_dir().join(format!("imunoise-digest-{name}-{}", std::process::id()));
        std::fs::write(&path, data).unwrap();
        let mark = fingerprint(&path, stop);
        std::fs::remove_file(&path).unwrap();
        mark
    }

    #[test]
    fn digests_match_the_official_test_vectors() {
        // BLAKE3's test_vectors/test_vectors.json: the first 32 bytes of "hash"
        // for inputs of 0, 1, 1025 and 102400 bytes of the pattern.
        let vectors = [
            (
                0,
                "af1349b9f5f9a1a6a0404dea36dcc9499bcb25c9adc112b7cc9a93cae41f3262",
            ),
            (
                1,
                "2d3adedff11b61f14c886e35afa036736dcd87a74d27b5c1510225d0f592e213",
            ),
            (
                1025,
                "d00278ae47eb27b34faecf67b4fe263f82d5412916c1ffd97c8cb7fb814b8444",
            ),
            (
                102400,
                "bc3e3d41a1146b069abffad3c0d44860cf664390afce4d9661f7902e7943e085",
            ),
        ];
        for (n, hex) in vectors {
            let mark = fingerprint_of(&pattern(n), "vector", &NEVER).unwrap();
            assert_eq!(
                (mark.bytes, mark.blake3.as_str()),
                (n as u64, hex),
                "{n} bytes"
            );
        }
    }

    #[test]
    fn a_file_of_several_blocks_hashes_as_one_piece() {
        let data = pattern(2 * BLOCK_BYTES + 12345);
        let mark = fingerprint_of(&data, "blocks", &NEVER).unwrap();
        assert_eq!(mark.blake3, blake3::hash(&data).to_hex().as_str());
    }

    #[test]
    fn size_and_time_are_the_files() {
        let path = std::env::temp_dir().join(format!("imunoise-digest-t-{}", std::process::id()));
        std::fs::write(&path, b"abc").unwrap();
        let mark = fingerprint(&path, &NEVER).unwrap();
        let modified = std::fs::metadata(&path).unwrap().modified().unwrap();
        std::fs::remove_file(&path).unwrap();
        assert_eq!(mark.bytes, 3);
        assert_eq!(mark.mtime_ns, nanos_since_epoch(modified));
        assert!(matches!(
            fingerprint(&path, &NEVER),
            Err(CoreError::Io {
                kind: std::io::ErrorKind::NotFound,
                ..
            })
        ));
        let before = UNIX_EPOCH - std::time::Duration::from_nanos(5);
        assert_eq!(nanos_since_epoch(before), -5);
    }

    #[test]
    fn a_raised_interrupt_stops_the_hash() {
        let stop = Interrupt::new();
        stop.raise();
        assert_eq!(
            fingerprint_of(b"x", "stop", &stop),
            Err(CoreError::Interrupted)
        );
    }

    #[test]
    fn a_head_written_last_gives_the_whole_files_digest() {
        // lengths about each boundary of the tree: chunks, lead, spans of 2^k chunks
        let heads = [0, 1, 192, 1023, 1024, 1500, 2049, 5000];
        let mut lengths = vec![0, 1, 1000];
        for k in 0..8 {
            let b = CHUNK_LEN << k;
            lengths.extend([b - 1, b, b + 1, b + 1000]);
        }
        lengths.push(3 * (CHUNK_LEN << 8) + 17);
        let file = pattern(lengths.iter().max().unwrap() + heads.iter().max().unwrap());
        for head in heads {
            for &body in &lengths {
                let whole = &file[..head + body];
                for piece in [1, 333, 4096, usize::MAX] {
                    let mut h = HeadLast::new(head);
                    for part in whole[head..].chunks(piece.min(body.max(1))) {
                        h.update(part);
                    }
                    let got = h.finish(&whole[..head]).unwrap();
                    assert_eq!(
                        got,
                        blake3::hash(whole),
                        "head {head}, body {body}, pieces {piece}"
                    );
                }
            }
        }
        assert!(HeadLast::new(3).finish(b"ab").is_err());
    }
}
