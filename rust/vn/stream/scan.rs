//! Framing of one ASCII sentence (spec §2): printable bytes from `$` to `*`,
//! 2 or 4 check characters, an optional line end; plus the line counting that
//! locations need. Cost: one pass over the sentence (a vectorisable search for
//! `*` first); `count_newlines` 64 bytes per step.

use crate::vn::ascii::MAX_SENTENCE;
use crate::vn::checksum;
use crate::vn::IssueKind;

/// What [`scan_ascii`] found at a `$`.
pub(super) enum Ascii {
    /// More input is needed to decide.
    Need,
    /// Not a sentence start: drop the `$` as noise.
    Noise,
    /// A record spanning `..end` with the given outcome.
    Record { end: usize, outcome: Outcome },
}

/// A framed sentence: its body (between `$` and `*`) to decode, or why it is damaged.
pub(super) enum Outcome {
    Good { body: (usize, usize) },
    Issue(IssueKind, String),
}

/// A byte of a check field: a hex digit, or `X` (`*XX`: checksum not sent).
fn is_check_char(c: u8) -> bool {
    c.is_ascii_hexdigit() || c == b'X'
}

/// Scan a sentence starting at `buf[i] == b'$'`.
pub(super) fn scan_ascii(buf: &[u8], i: usize, fin: bool) -> Ascii {
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

/// Number of `\n` bytes: 64 at a time into a byte counter, which compiles to a
/// few vector compares and adds per block (a plain `filter().count()` widens
/// every byte to 64 bits).
pub(super) fn count_newlines(buf: &[u8]) -> u64 {
    let mut blocks = buf.chunks_exact(64);
    let mut total = 0u64;
    for b in &mut blocks {
        total += b.iter().fold(0u8, |a, &c| a + (c == b'\n') as u8) as u64;
    }
    total + blocks.remainder().iter().filter(|&&c| c == b'\n').count() as u64
}

/// The end of a record at `end`, past an optional `\r` and `\n`.
pub(super) fn eat_eol(buf: &[u8], mut end: usize) -> usize {
    if buf.get(end) == Some(&b'\r') {
        end += 1;
    }
    if buf.get(end) == Some(&b'\n') {
        end += 1;
    }
    end
}
