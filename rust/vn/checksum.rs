//! The two VectorNav integrity checks (spec §2.2, §2.3).
//!
//! * 8-bit checksum: XOR of every byte between `$` and `*`.
//! * CRC-16 with polynomial 0x1021, initial value 0, no reflection, no final XOR
//!   ("CRC-16/XMODEM"; VectorNav calls it CRC16-CCITT). Used by ASCII sentences
//!   with a 4-digit check field and by every binary packet; running it over a
//!   binary packet *including* its big-endian CRC yields 0 for a good packet.

/// XOR of all bytes.
#[inline]
pub fn xor8(bytes: &[u8]) -> u8 {
    // Fold 32 bytes at a time (vector registers), then 8 (one word): XOR is
    // associative, so the bytes of the folded block XOR together to the same value.
    let (blocks, rest) = bytes.as_chunks::<32>();
    let mut lanes = [0u64; 4];
    for block in blocks {
        for (lane, word) in lanes.iter_mut().zip(block.as_chunks::<8>().0) {
            *lane ^= u64::from_le_bytes(*word);
        }
    }
    let folded = lanes[0] ^ lanes[1] ^ lanes[2] ^ lanes[3];
    let mut chunks = rest.chunks_exact(8);
    let mut acc = folded;
    for c in &mut chunks {
        let mut w = [0u8; 8];
        w.copy_from_slice(c);
        acc ^= u64::from_le_bytes(w);
    }
    let mut x = 0u8;
    for b in acc.to_le_bytes() {
        x ^= b;
    }
    for &b in chunks.remainder() {
        x ^= b;
    }
    x
}

const fn make_tables() -> [[u16; 256]; 8] {
    let mut t = [[0u16; 256]; 8];
    let mut i = 0;
    while i < 256 {
        let mut crc = (i as u16) << 8;
        let mut k = 0;
        while k < 8 {
            crc = if crc & 0x8000 != 0 {
                (crc << 1) ^ 0x1021
            } else {
                crc << 1
            };
            k += 1;
        }
        t[0][i] = crc;
        i += 1;
    }
    // Slicing-by-8: t[k][i] is the CRC of byte i followed by k zero bytes.
    let mut k = 1;
    while k < 8 {
        let mut i = 0;
        while i < 256 {
            let prev = t[k - 1][i];
            t[k][i] = (prev << 8) ^ t[0][(prev >> 8) as usize];
            i += 1;
        }
        k += 1;
    }
    t
}

static CRC_TABLES: [[u16; 256]; 8] = make_tables();

/// CRC-16/XMODEM continued from `crc` over `bytes`.
#[inline]
pub fn crc16_update(mut crc: u16, bytes: &[u8]) -> u16 {
    let t = &CRC_TABLES;
    let mut chunks = bytes.chunks_exact(8);
    for c in &mut chunks {
        // One 8-byte load; the CRC so far is XOR-ed into the first two bytes
        // (big-endian order: the CRC is not reflected).
        let mut w = [0u8; 8];
        w.copy_from_slice(c);
        let v = u64::from_be_bytes(w) ^ ((crc as u64) << 48);
        let b = |k: u32| ((v >> (56 - 8 * k)) & 0xFF) as usize;
        crc = t[7][b(0)]
            ^ t[6][b(1)]
            ^ t[5][b(2)]
            ^ t[4][b(3)]
            ^ t[3][b(4)]
            ^ t[2][b(5)]
            ^ t[1][b(6)]
            ^ t[0][b(7)];
    }
    for &b in chunks.remainder() {
        crc = (crc << 8) ^ t[0][((crc >> 8) as u8 ^ b) as usize];
    }
    crc
}

/// CRC-16/XMODEM of `bytes` (init 0).
#[inline]
pub fn crc16(bytes: &[u8]) -> u16 {
    crc16_update(0, bytes)
}

/// The bitwise reference definition of the spec (§2.3), for tests.
pub fn crc16_bitwise(bytes: &[u8]) -> u16 {
    let mut crc: u16 = 0;
    for &b in bytes {
        crc ^= (b as u16) << 8;
        for _ in 0..8 {
            crc = if crc & 0x8000 != 0 {
                (crc << 1) ^ 0x1021
            } else {
                crc << 1
            };
        }
    }
    crc
}

/// Outcome of checking an ASCII sentence's check field.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Check {
    /// 2 hex digits matched the XOR-8 checksum.
    Xor8,
    /// 4 hex digits matched the CRC-16.
    Crc16,
    /// `XX`, `XXXX` or an empty field: the sender asked for no check.
    Unchecked,
}

fn hex_val(c: u8) -> Option<u16> {
    match c {
        b'0'..=b'9' => Some((c - b'0') as u16),
        b'a'..=b'f' => Some((c - b'a' + 10) as u16),
        b'A'..=b'F' => Some((c - b'A' + 10) as u16),
        _ => None,
    }
}

/// Parse `digits` as hexadecimal (1..=4 digits).
pub fn parse_hex(digits: &[u8]) -> Option<u16> {
    if digits.is_empty() || digits.len() > 4 {
        return None;
    }
    let mut v = 0u16;
    for &c in digits {
        v = (v << 4) | hex_val(c)?;
    }
    Some(v)
}

/// Verify `body` (bytes between `$` and `*`) against a check field of 2 or 4 hex
/// digits (chosen by length) or a no-check wildcard. `None` on mismatch or on a
/// field of another length.
pub fn verify(body: &[u8], field: &[u8]) -> Option<Check> {
    match field {
        b"" | b"XX" | b"XXXX" => Some(Check::Unchecked),
        f if f.len() == 2 => (parse_hex(f)? == xor8(body) as u16).then_some(Check::Xor8),
        f if f.len() == 4 => (parse_hex(f)? == crc16(body)).then_some(Check::Crc16),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crc_check_value() {
        assert_eq!(crc16(b"123456789"), 0x31C3);
        assert_eq!(crc16_bitwise(b"123456789"), 0x31C3);
    }

    #[test]
    fn table_matches_bitwise() {
        let data: Vec<u8> = (0..1000u32)
            .map(|i| (i.wrapping_mul(2654435761) >> 13) as u8)
            .collect();
        for len in 0..200 {
            for start in [0usize, 1, 3, 7] {
                let s = &data[start..start + len];
                assert_eq!(crc16(s), crc16_bitwise(s));
            }
        }
    }

    #[test]
    fn xor8_matches_the_byte_fold() {
        let data: Vec<u8> = (0..400u32)
            .map(|i| (i.wrapping_mul(2654435761) >> 11) as u8)
            .collect();
        for len in 0..330 {
            for start in [0usize, 1, 5, 31] {
                let s = &data[start..start + len];
                assert_eq!(xor8(s), s.iter().fold(0, |a, &b| a ^ b), "len {len}");
            }
        }
    }

    #[test]
    fn spec_xor8() {
        let body = b"VNYMR,+100.949,-007.330,+000.715,-00.0049,-00.2449,+00.5397,-01.258,-00.100,-09.701,-00.000018,+00.001122,-00.000551";
        assert_eq!(xor8(body), 0x69);
        assert_eq!(crc16(body), 0xC251);
        assert_eq!(xor8(b"VNERR,03"), 0x72);
        assert_eq!(crc16(b"VNRRG,15"), 0x92EA);
        assert_eq!(crc16(b"VNRRG,54"), 0x4E0F);
        assert_eq!(crc16(b"VNRRG,01"), 0xE15F);
        assert_eq!(crc16(b"VNWRG,06,14"), 0x1CB5);
        assert_eq!(crc16(b"VNWRG,07,40"), 0xD570);
        assert_eq!(xor8(b"VNWRG,06,14"), 0x59);
        assert_eq!(verify(body, b"69"), Some(Check::Xor8));
        assert_eq!(verify(body, b"c251"), Some(Check::Crc16));
        assert_eq!(verify(body, b"68"), None);
        assert_eq!(verify(body, b"XX"), Some(Check::Unchecked));
        assert_eq!(verify(body, b"693"), None);
    }

    #[test]
    fn binary_crc_zero() {
        let b1: [u8; 26] = [
            0xFA, 0x01, 0x09, 0x00, 0x70, 0x05, 0x00, 0x03, 0x0A, 0x00, 0x00, 0x00, 0x48, 0x0E,
            0x2C, 0x42, 0x08, 0x4C, 0x37, 0xC1, 0x10, 0x38, 0x8B, 0xC2, 0xD4, 0xCB,
        ];
        assert_eq!(crc16(&b1[1..24]), 0xD4CB);
        assert_eq!(crc16(&b1[1..]), 0);
    }
}
