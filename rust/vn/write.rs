//! Writers for VN ASCII sentences (any message type, XOR-8 or CRC-16) and VN
//! binary packets (any group/field selection). Used by the simulator, the
//! benchmarks and the round-trip tests.

use std::io::Write as _;

use crate::error::{CoreError, CoreResult};
use crate::vn::binary::{self, field_spec, HeaderScan, Kind, Layout};
use crate::vn::checksum::{crc16, xor8};
use crate::vn::messages::{spec_by_id, MESSAGES};

/// Which check an ASCII writer appends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AsciiCheck {
    Xor8,
    Crc16,
}

/// Default (integer digits, decimals) of a field, as a VN-100 prints it (spec
/// §7.1 examples: `+100.949`, `-00.0049`, `-01.258`, `-00.000018`, `+0.021375`).
pub fn default_format(field: &str) -> (usize, usize) {
    match field {
        "yaw" | "pitch" | "roll" => (3, 3),
        "qx" | "qy" | "qz" | "qw" => (1, 6),
        "temperature" => (2, 1),
        "pressure" => (3, 3),
        "delta_time" => (1, 6),
        _ if field.starts_with("mag") => (2, 4),
        _ if field.starts_with("accel") || field.starts_with("lin_accel") => (2, 3),
        _ if field.starts_with("inertial_accel") => (2, 3),
        _ if field.starts_with("delta_theta") || field.starts_with("delta_vel") => (3, 3),
        _ => (2, 6),
    }
}

fn check_len(name: &str, len: usize, n: usize) -> CoreResult<()> {
    if len != n {
        return Err(CoreError::InvalidArgument(format!(
            "column {name} has {len} values; expected {n} (one per record)"
        )));
    }
    Ok(())
}

/// Write `n` sentences of message `id` (e.g. `"VNYMR"`) from `columns` in the
/// message's field order. `decimals` overrides the printed decimals per field;
/// `count`/`status` add the appended `T`/`S` fields (spec §2.5; `S` first, as
/// the manual says).
pub fn write_ascii(
    id: &str,
    columns: &[&[f64]],
    decimals: Option<&[usize]>,
    count: Option<&[f64]>,
    status: Option<&[f64]>,
    check: AsciiCheck,
    eol: &[u8],
) -> CoreResult<Vec<u8>> {
    let spec = spec_by_id(id.as_bytes()).ok_or_else(|| {
        let known: Vec<&str> = MESSAGES.iter().map(|m| m.id).collect();
        CoreError::InvalidArgument(format!("message must be one of {known:?}; got {id:?}"))
    })?;
    let nf = spec.fields.len();
    if columns.len() != nf {
        return Err(CoreError::InvalidArgument(format!(
            "{id} needs {nf} columns ({:?}); got {}",
            spec.fields,
            columns.len()
        )));
    }
    let n = columns.first().map_or(0, |c| c.len());
    for (k, c) in columns.iter().enumerate() {
        check_len(spec.fields[k], c.len(), n)?;
    }
    if let Some(c) = count {
        check_len("count", c.len(), n)?;
    }
    if let Some(s) = status {
        check_len("status", s.len(), n)?;
    }
    let defaults: Vec<(usize, usize)> = spec.fields.iter().map(|f| default_format(f)).collect();
    let dec: Vec<usize> = match decimals {
        Some(d) if d.len() == nf => d.iter().map(|&x| x.min(15)).collect(),
        Some(d) => {
            return Err(CoreError::InvalidArgument(format!(
                "decimals must have {nf} entries for {id}; got {}",
                d.len()
            )))
        }
        None => defaults.iter().map(|&(_, d)| d).collect(),
    };
    let mut out = Vec::with_capacity(n * (8 + 11 * nf));
    let mut line: Vec<u8> = Vec::with_capacity(256);
    for r in 0..n {
        line.clear();
        line.extend_from_slice(spec.id.as_bytes());
        for k in 0..nf {
            let v = columns[k][r];
            if !v.is_finite() {
                return Err(CoreError::InvalidArgument(format!(
                    "{} value at record {r} is not finite: {v}",
                    spec.fields[k]
                )));
            }
            let p = dec[k];
            // Zero-padded with an explicit sign, like the sensor: +000.715.
            let width = defaults[k].0 + p + if p > 0 { 2 } else { 1 };
            let _ = write!(line, ",{v:+0width$.p$}");
        }
        if let Some(s) = status {
            let v = s[r];
            if !(0.0..=65535.0).contains(&v) {
                return Err(CoreError::InvalidArgument(format!(
                    "status at record {r} must be in 0..=65535; got {v}"
                )));
            }
            let _ = write!(line, ",S{:04X}", v as u16);
        }
        if let Some(c) = count {
            let v = c[r];
            if !(v.is_finite() && v >= 0.0 && v.fract() == 0.0) {
                return Err(CoreError::InvalidArgument(format!(
                    "count at record {r} must be a non-negative integer; got {v}"
                )));
            }
            let _ = write!(line, ",T{:010}", v as u64);
        }
        out.push(b'$');
        out.extend_from_slice(&line);
        let _ = match check {
            AsciiCheck::Xor8 => write!(out, "*{:02X}", xor8(&line)),
            AsciiCheck::Crc16 => write!(out, "*{:04X}", crc16(&line)),
        };
        out.extend_from_slice(eol);
    }
    Ok(out)
}

/// Build the binary header for a selection: `(group index, field mask)` pairs,
/// group index as in the 2024 SDK (0 Common, 1 Time, 2 IMU, 4 Attitude ...), mask
/// bit k = field k (bits 16..30 go into a second field word).
pub fn binary_layout(selection: &[(usize, u32)]) -> CoreResult<Layout> {
    let mut sel: Vec<(usize, u32)> = selection.iter().copied().filter(|&(_, m)| m != 0).collect();
    sel.sort_by_key(|&(g, _)| g);
    if sel.is_empty() {
        return Err(CoreError::InvalidArgument(
            "selection must select at least one field".into(),
        ));
    }
    let mut groups = [0u8; 3];
    let mut nbytes = 0;
    for w in sel.windows(2) {
        if w[0].0 == w[1].0 {
            return Err(CoreError::InvalidArgument(format!(
                "group {} selected twice",
                w[0].0
            )));
        }
    }
    for &(g, mask) in &sel {
        if g % 8 == 7 || g >= 24 {
            return Err(CoreError::InvalidArgument(format!(
                "group index {g} is not a group"
            )));
        }
        if mask & 0x8000 != 0 || mask >> 31 != 0 {
            return Err(CoreError::InvalidArgument(format!(
                "field mask 0x{mask:X} of group {g} sets an extension bit (15 or 31)"
            )));
        }
        groups[g / 8] |= 1 << (g % 8);
        nbytes = nbytes.max(g / 8 + 1);
    }
    let mut header = vec![0xFAu8];
    for (b, &gb) in groups.iter().enumerate().take(nbytes) {
        header.push(if b + 1 < nbytes { gb | 0x80 } else { gb });
    }
    for &(_, mask) in &sel {
        let lo = (mask & 0x7FFF) as u16;
        let hi = ((mask >> 16) & 0x7FFF) as u16;
        if hi != 0 {
            header.extend_from_slice(&(lo | 0x8000).to_le_bytes());
            header.extend_from_slice(&hi.to_le_bytes());
        } else {
            header.extend_from_slice(&lo.to_le_bytes());
        }
    }
    match binary::parse_header(&header) {
        HeaderScan::Ok(layout) => Ok(layout),
        _ => Err(CoreError::InvalidArgument(format!(
            "selection {sel:?} has a field bit with no known size"
        ))),
    }
}

#[allow(clippy::needless_range_loop)] // one packet per record index across columns
/// Write `n` binary packets for `layout` from columns in
/// [`Layout::column_names`] order. Opaque fields are written as zeros (variable
/// GNSS fields with a count of 0); times are given in seconds.
pub fn write_binary(layout: &Layout, columns: &[&[f64]]) -> CoreResult<Vec<u8>> {
    let names = layout.column_names();
    if columns.len() != names.len() {
        return Err(CoreError::InvalidArgument(format!(
            "this selection needs {} columns ({names:?}); got {}",
            names.len(),
            columns.len()
        )));
    }
    let n = columns.first().map_or(0, |c| c.len());
    for (k, c) in columns.iter().enumerate() {
        check_len(&names[k], c.len(), n)?;
    }
    let size = binary::payload_size(layout, &[0u8; 16]).map_err(|_| {
        CoreError::InvalidArgument("selection exceeds the 2000-byte packet limit".into())
    })?;
    let plen = 1 + layout.header.len() + size + 2;
    let mut out = Vec::with_capacity(n * plen);
    for r in 0..n {
        let start = out.len();
        out.push(0xFA);
        out.extend_from_slice(&layout.header);
        let mut col = 0usize;
        let next = |col: &mut usize| -> f64 {
            let v = columns[*col][r];
            *col += 1;
            v
        };
        for &(g, k) in &layout.fields {
            let Some(spec) = field_spec(g, k) else {
                continue;
            };
            match spec.kind {
                Kind::F32(m) => {
                    for _ in 0..m {
                        out.extend_from_slice(&(next(&mut col) as f32).to_le_bytes());
                    }
                }
                Kind::F64(m) => {
                    for _ in 0..m {
                        out.extend_from_slice(&next(&mut col).to_le_bytes());
                    }
                }
                Kind::Nanos => {
                    let ns = (next(&mut col) * 1e9).round().max(0.0) as u64;
                    out.extend_from_slice(&ns.to_le_bytes());
                }
                Kind::U32 => {
                    let v = next(&mut col).round().clamp(0.0, u32::MAX as f64) as u32;
                    out.extend_from_slice(&v.to_le_bytes());
                }
                Kind::U16 => {
                    let v = next(&mut col).round().clamp(0.0, 65535.0) as u16;
                    out.extend_from_slice(&v.to_le_bytes());
                }
                Kind::U8 => out.push(next(&mut col).round().clamp(0.0, 255.0) as u8),
                Kind::TimeUtc => {
                    let year = (next(&mut col) - 2000.0).round().clamp(-128.0, 127.0) as i8;
                    out.push(year as u8);
                    for _ in 0..5 {
                        out.push(next(&mut col).round().clamp(0.0, 255.0) as u8);
                    }
                    let ms = next(&mut col).round().clamp(0.0, 65535.0) as u16;
                    out.extend_from_slice(&ms.to_le_bytes());
                }
                Kind::Opaque => out.extend(std::iter::repeat_n(0u8, spec.size)),
                Kind::SatInfo => out.extend_from_slice(&[0u8; 2]),
                Kind::RawMeas => out.extend_from_slice(&[0u8; 12]),
            }
        }
        let crc = crc16(&out[start + 1..]);
        out.extend_from_slice(&crc.to_be_bytes());
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vn::stream::parse_bytes;

    #[test]
    fn ascii_matches_spec_vector() {
        let cols: Vec<Vec<f64>> = [
            100.949, -7.330, 0.715, -0.0049, -0.2449, 0.5397, -1.258, -0.100, -9.701, -0.000018,
            0.001122, -0.000551,
        ]
        .iter()
        .map(|&v| vec![v])
        .collect();
        let refs: Vec<&[f64]> = cols.iter().map(|c| c.as_slice()).collect();
        let out = write_ascii("VNYMR", &refs, None, None, None, AsciiCheck::Xor8, b"\r\n").unwrap();
        assert_eq!(
            out,
            b"$VNYMR,+100.949,-007.330,+000.715,-00.0049,-00.2449,+00.5397,-01.258,-00.100,-09.701,-00.000018,+00.001122,-00.000551*69\r\n"
        );
        let out =
            write_ascii("VNYMR", &refs, None, None, None, AsciiCheck::Crc16, b"\r\n").unwrap();
        assert!(out.ends_with(b"*C251\r\n"));
    }

    #[test]
    fn binary_matches_synthetic_a() {
        let layout = binary_layout(&[(0, 0x0001), (2, 0x000C), (4, 0x0014)]).unwrap();
        assert_eq!(layout.header, [0x15, 0x01, 0x00, 0x0C, 0x00, 0x14, 0x00]);
        let vals = [
            123.456789, 0.1, -0.2, -9.81, 0.001, -0.002, 0.003, -0.017386, -0.000303, 0.05549,
            0.998308, 0.25, 0.01, 0.42,
        ];
        let cols: Vec<Vec<f64>> = vals.iter().map(|&v| vec![v]).collect();
        let refs: Vec<&[f64]> = cols.iter().map(|c| c.as_slice()).collect();
        let out = write_binary(&layout, &refs).unwrap();
        assert_eq!(out.len(), 70);
        assert_eq!(&out[68..], &[0x24, 0x99]);
        let data = parse_bytes(&out, true).unwrap();
        assert_eq!(data.binary_records, 1);
    }
}
