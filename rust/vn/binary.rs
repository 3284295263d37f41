//! VN binary output packets (spec §5): `0xFA`, group byte(s), field word(s),
//! payload, big-endian CRC-16.
//!
//! There is no length byte: the length follows from the header and the size of
//! every selected field, so a header with an unknown field bit cannot be framed
//! and the reader resynchronises one byte later.

use crate::vn::checksum::crc16;
use crate::vn::Table;

/// The SDK caps `0xFA` packets at 2000 bytes (spec §5.1).
pub const MAX_PACKET: usize = 2000;
/// At most this many group bytes (extension bit 7) and words per group (bit 15).
const MAX_GROUP_BYTES: usize = 3;
const MAX_WORDS: usize = 2;

/// How a field's bytes become columns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// `n` little-endian f32.
    F32(usize),
    /// `n` little-endian f64.
    F64(usize),
    /// u64 nanoseconds, output in seconds.
    Nanos,
    U32,
    U16,
    U8,
    /// i8 year-2000, u8 month, day, hour, minute, second, u16 ms.
    TimeUtc,
    /// Bytes of this size that are framed but not decoded.
    Opaque,
    /// GNSS SatInfo: 2 + 8·N bytes, N = first byte (opaque).
    SatInfo,
    /// GNSS RawMeas: 12 + 28·N bytes, N = byte at offset 10 (opaque).
    RawMeas,
}

/// One field of one group: wire size, decoding and column names.
#[derive(Debug, Clone, Copy)]
pub struct FieldSpec {
    pub name: &'static str,
    pub size: usize,
    pub kind: Kind,
    pub columns: &'static [&'static str],
}

const fn f(
    name: &'static str,
    size: usize,
    kind: Kind,
    columns: &'static [&'static str],
) -> Option<FieldSpec> {
    Some(FieldSpec {
        name,
        size,
        kind,
        columns,
    })
}

const fn opaque(size: usize) -> Option<FieldSpec> {
    Some(FieldSpec {
        name: "reserved",
        size,
        kind: Kind::Opaque,
        columns: &[],
    })
}

use Kind::*;

const YPR: &[&str] = &["yaw", "pitch", "roll"];
const QUAT: &[&str] = &["qx", "qy", "qz", "qw"];

/// Common group (group bit 0), field bits 0..14.
pub static COMMON: [Option<FieldSpec>; 15] = [
    f("TimeStartup", 8, Nanos, &["time_startup"]),
    f("TimeGps", 8, Nanos, &["time_gps"]),
    f("TimeSyncIn", 8, Nanos, &["time_syncin"]),
    f("YawPitchRoll", 12, F32(3), YPR),
    f("Quaternion", 16, F32(4), QUAT),
    f("AngularRate", 12, F32(3), &["gyro_x", "gyro_y", "gyro_z"]),
    f("Position", 24, F64(3), &["lat", "lon", "alt"]),
    f("Velocity", 12, F32(3), &["vel_n", "vel_e", "vel_d"]),
    f("Accel", 12, F32(3), &["accel_x", "accel_y", "accel_z"]),
    f(
        "Imu",
        24,
        F32(6),
        &[
            "uncomp_accel_x",
            "uncomp_accel_y",
            "uncomp_accel_z",
            "uncomp_gyro_x",
            "uncomp_gyro_y",
            "uncomp_gyro_z",
        ],
    ),
    f(
        "MagPres",
        20,
        F32(5),
        &["mag_x", "mag_y", "mag_z", "temperature", "pressure"],
    ),
    f(
        "DeltaThetaVel",
        28,
        F32(7),
        &[
            "delta_time",
            "delta_theta_x",
            "delta_theta_y",
            "delta_theta_z",
            "delta_vel_x",
            "delta_vel_y",
            "delta_vel_z",
        ],
    ),
    f("VpeStatus", 2, U16, &["vpe_status"]),
    f("SyncInCnt", 4, U32, &["syncin_count"]),
    f("TimeGpsPps", 8, Nanos, &["time_pps"]),
];

/// Time group (group bit 1).
pub static TIME: [Option<FieldSpec>; 10] = [
    f("TimeStartup", 8, Nanos, &["time_startup"]),
    f("TimeGps", 8, Nanos, &["time_gps"]),
    f("GpsTow", 8, Nanos, &["gps_tow"]),
    f("GpsWeek", 2, U16, &["gps_week"]),
    f("TimeSyncIn", 8, Nanos, &["time_syncin"]),
    f("TimeGpsPps", 8, Nanos, &["time_pps"]),
    f(
        "TimeUtc",
        8,
        TimeUtc,
        &[
            "utc_year",
            "utc_month",
            "utc_day",
            "utc_hour",
            "utc_minute",
            "utc_second",
            "utc_ms",
        ],
    ),
    f("SyncInCnt", 4, U32, &["syncin_count"]),
    f("SyncOutCnt", 4, U32, &["syncout_count"]),
    f("TimeStatus", 1, U8, &["time_status"]),
];

/// IMU group (group bit 2).
pub static IMU: [Option<FieldSpec>; 13] = [
    f("ImuStatus", 2, U16, &["imu_status"]),
    f(
        "UncompMag",
        12,
        F32(3),
        &["uncomp_mag_x", "uncomp_mag_y", "uncomp_mag_z"],
    ),
    f(
        "UncompAccel",
        12,
        F32(3),
        &["uncomp_accel_x", "uncomp_accel_y", "uncomp_accel_z"],
    ),
    f(
        "UncompGyro",
        12,
        F32(3),
        &["uncomp_gyro_x", "uncomp_gyro_y", "uncomp_gyro_z"],
    ),
    f("Temp", 4, F32(1), &["temperature"]),
    f("Pres", 4, F32(1), &["pressure"]),
    f(
        "DeltaTheta",
        16,
        F32(4),
        &[
            "delta_time",
            "delta_theta_x",
            "delta_theta_y",
            "delta_theta_z",
        ],
    ),
    f(
        "DeltaVel",
        12,
        F32(3),
        &["delta_vel_x", "delta_vel_y", "delta_vel_z"],
    ),
    f("Mag", 12, F32(3), &["mag_x", "mag_y", "mag_z"]),
    f("Accel", 12, F32(3), &["accel_x", "accel_y", "accel_z"]),
    f("AngularRate", 12, F32(3), &["gyro_x", "gyro_y", "gyro_z"]),
    f("SensSat", 2, U16, &["sens_sat"]),
    opaque(40),
];

/// Attitude group (group bit 4).
pub static ATTITUDE: [Option<FieldSpec>; 14] = [
    f("VpeStatus", 2, U16, &["vpe_status"]),
    f("YawPitchRoll", 12, F32(3), YPR),
    f("Quaternion", 16, F32(4), QUAT),
    f(
        "DCM",
        36,
        F32(9),
        &[
            "dcm_0", "dcm_1", "dcm_2", "dcm_3", "dcm_4", "dcm_5", "dcm_6", "dcm_7", "dcm_8",
        ],
    ),
    f("MagNed", 12, F32(3), &["mag_n", "mag_e", "mag_d"]),
    f("AccelNed", 12, F32(3), &["accel_n", "accel_e", "accel_d"]),
    f(
        "LinearAccelBody",
        12,
        F32(3),
        &["lin_accel_x", "lin_accel_y", "lin_accel_z"],
    ),
    f(
        "LinearAccelNed",
        12,
        F32(3),
        &["lin_accel_n", "lin_accel_e", "lin_accel_d"],
    ),
    f("YprU", 12, F32(3), &["yaw_u", "pitch_u", "roll_u"]),
    opaque(12),
    opaque(28),
    opaque(24),
    f(
        "Heave",
        12,
        F32(3),
        &["heave", "heave_rate", "delayed_heave"],
    ),
    f("AttU", 4, F32(1), &["att_u"]),
];

/// GNSS groups (bits 3, 6 and SDK index 12): framed, not decoded. Index is the
/// SDK field number (second word = 16 + bit).
static GNSS: [Option<FieldSpec>; 19] = [
    opaque(8),
    opaque(8),
    opaque(2),
    opaque(1),
    opaque(1),
    opaque(24),
    opaque(24),
    opaque(12),
    opaque(12),
    opaque(12),
    opaque(4),
    opaque(4),
    opaque(2),
    opaque(28),
    Some(FieldSpec {
        name: "SatInfo",
        size: 2,
        kind: SatInfo,
        columns: &[],
    }),
    None,
    Some(FieldSpec {
        name: "RawMeas",
        size: 12,
        kind: RawMeas,
        columns: &[],
    }),
    opaque(2),
    opaque(8),
];

/// INS group (bit 5): framed, not decoded.
static INS: [Option<FieldSpec>; 13] = [
    opaque(2),
    opaque(24),
    opaque(24),
    opaque(12),
    opaque(12),
    opaque(12),
    opaque(12),
    opaque(12),
    opaque(12),
    opaque(4),
    opaque(4),
    opaque(68),
    opaque(64),
];

/// Group name used to qualify column names.
pub fn group_name(group: usize) -> &'static str {
    match group {
        0 => "common",
        1 => "time",
        2 => "imu",
        3 => "gnss",
        4 => "attitude",
        5 => "ins",
        6 => "gnss2",
        12 => "gnss3",
        _ => "unknown",
    }
}

/// The groups whose fields the writer offers by name (Common, Time, IMU,
/// Attitude: an IMU's own outputs). GNSS and INS packets are still decoded
/// when read.
pub const DECODABLE_GROUPS: [usize; 4] = [0, 1, 2, 4];

/// The named fields of `group` as (field number, spec), reserved slots left out.
pub fn named_fields(group: usize) -> impl Iterator<Item = (usize, &'static FieldSpec)> {
    (0..16 * MAX_WORDS)
        .filter_map(move |k| field_spec(group, k).map(|spec| (k, spec)))
        .filter(|(_, spec)| spec.name != "reserved")
}

/// Field spec for SDK group index `group` and SDK field number `field`
/// (word `w`, bit `b` → `16·w + b`).
pub fn field_spec(group: usize, field: usize) -> Option<&'static FieldSpec> {
    let table: &[Option<FieldSpec>] = match group {
        0 => &COMMON,
        1 => &TIME,
        2 => &IMU,
        3 | 6 | 12 => &GNSS,
        4 => &ATTITUDE,
        5 => &INS,
        _ => return None,
    };
    table.get(field)?.as_ref()
}

/// Parsed header: the selected fields in payload order.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// Header bytes after the sync byte (group bytes and field words).
    pub header: Vec<u8>,
    /// (group, field number) in payload order.
    pub fields: Vec<(usize, usize)>,
    /// Payload size if no variable-size field is selected.
    pub fixed_payload: Option<usize>,
}

impl Layout {
    /// Column names, qualified by group (`"common.yaw"`).
    pub fn column_names(&self) -> Vec<String> {
        let mut names = Vec::new();
        for &(g, k) in &self.fields {
            if let Some(spec) = field_spec(g, k) {
                for c in spec.columns {
                    names.push(format!("{}.{}", group_name(g), c));
                }
            }
        }
        names
    }

    /// Table name: `binary_` + the header bytes in hex.
    pub fn table_name(&self) -> String {
        let mut s = String::from("binary_");
        for b in &self.header {
            s.push_str(&format!("{b:02x}"));
        }
        s
    }
}

/// Result of trying to read a header at `buf[0] == 0xFA`.
#[derive(Debug, PartialEq)]
pub enum HeaderScan {
    /// The buffer ends inside the header.
    Incomplete,
    /// Unknown group or field bit, or too many extension bytes: not a packet.
    Invalid,
    Ok(Layout),
}

/// Parse the header of a candidate packet starting at `buf[0]` (the sync byte).
pub fn parse_header(buf: &[u8]) -> HeaderScan {
    let mut j = 1;
    let mut groups: Vec<u8> = Vec::with_capacity(1);
    loop {
        let Some(&g) = buf.get(j) else {
            return HeaderScan::Incomplete;
        };
        groups.push(g);
        j += 1;
        if g & 0x80 == 0 {
            break;
        }
        if groups.len() >= MAX_GROUP_BYTES {
            return HeaderScan::Invalid;
        }
    }
    if groups.iter().all(|&g| g & 0x7F == 0) {
        return HeaderScan::Invalid;
    }
    let mut fields = Vec::new();
    let mut fixed = Some(0usize);
    for (byte_no, &gb) in groups.iter().enumerate() {
        for bit in 0..7 {
            if gb & (1 << bit) == 0 {
                continue;
            }
            let group = 8 * byte_no + bit;
            let mut word_no = 0;
            loop {
                let (Some(&lo), Some(&hi)) = (buf.get(j), buf.get(j + 1)) else {
                    return HeaderScan::Incomplete;
                };
                let w = u16::from_le_bytes([lo, hi]);
                j += 2;
                for fbit in 0..15 {
                    if w & (1 << fbit) != 0 {
                        let k = 16 * word_no + fbit;
                        let Some(spec) = field_spec(group, k) else {
                            return HeaderScan::Invalid;
                        };
                        if matches!(spec.kind, SatInfo | RawMeas) {
                            fixed = None;
                        }
                        fixed = fixed.map(|s| s + spec.size);
                        fields.push((group, k));
                    }
                }
                word_no += 1;
                if w & 0x8000 == 0 {
                    break;
                }
                if word_no >= MAX_WORDS {
                    return HeaderScan::Invalid;
                }
            }
        }
    }
    HeaderScan::Ok(Layout {
        header: buf[1..j].to_vec(),
        fields,
        fixed_payload: fixed,
    })
}

/// Payload size of `layout` for the payload starting at `payload` (which may be
/// shorter than the packet). `Err(true)` if more bytes are needed to tell,
/// `Err(false)` if the size exceeds [`MAX_PACKET`].
pub fn payload_size(layout: &Layout, payload: &[u8]) -> Result<usize, bool> {
    if let Some(s) = layout.fixed_payload {
        return if s + layout.header.len() + 3 > MAX_PACKET {
            Err(false)
        } else {
            Ok(s)
        };
    }
    let mut off = 0usize;
    for &(g, k) in &layout.fields {
        let spec = field_spec(g, k).ok_or(false)?;
        let size = match spec.kind {
            SatInfo => 2 + 8 * (*payload.get(off).ok_or(true)? as usize),
            RawMeas => 12 + 28 * (*payload.get(off + 10).ok_or(true)? as usize),
            _ => spec.size,
        };
        off += size;
        if off + layout.header.len() + 3 > MAX_PACKET {
            return Err(false);
        }
    }
    Ok(off)
}

/// Whether `packet` (sync byte through CRC) has a good CRC.
#[inline]
pub fn crc_ok(packet: &[u8]) -> bool {
    packet.len() >= 3 && crc16(&packet[1..]) == 0
}

#[inline]
fn f32_at(p: &[u8], off: usize) -> f64 {
    match p.get(off..off + 4) {
        Some(b) => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        None => f64::NAN,
    }
}

/// Decode a CRC-checked payload as one row of `table` (whose columns are
/// [`Layout::column_names`]). Returns `TimeStartup` in seconds if present.
pub fn decode_into(layout: &Layout, payload: &[u8], table: &mut Table) -> Option<f64> {
    let nc = table.ncols();
    if table.values.capacity() - table.values.len() < nc {
        table.reserve(table.len.max(1024));
    }
    let start = table.values.len();
    let out = &mut table.values;
    let mut off = 0usize;
    let mut col = 0usize;
    let mut time = None;
    let mut push = |col: &mut usize, v: f64| {
        out.push(v);
        *col += 1;
    };
    for &(g, k) in &layout.fields {
        let Some(spec) = field_spec(g, k) else {
            continue;
        };
        let p = payload.get(off..).unwrap_or(&[]);
        let size = match spec.kind {
            F32(n) => {
                for i in 0..n {
                    push(&mut col, f32_at(p, 4 * i));
                }
                spec.size
            }
            F64(n) => {
                for i in 0..n {
                    let v = p
                        .get(8 * i..8 * i + 8)
                        .and_then(|b| b.try_into().ok())
                        .map_or(f64::NAN, f64::from_le_bytes);
                    push(&mut col, v);
                }
                spec.size
            }
            Nanos => {
                let ns = p
                    .get(..8)
                    .and_then(|b| b.try_into().ok())
                    .map_or(0, u64::from_le_bytes);
                let s = ns as f64 * 1e-9;
                if spec.name == "TimeStartup" && time.is_none() {
                    time = Some(s);
                }
                push(&mut col, s);
                spec.size
            }
            U32 => {
                let v = p
                    .get(..4)
                    .and_then(|b| b.try_into().ok())
                    .map_or(0, u32::from_le_bytes);
                push(&mut col, v as f64);
                spec.size
            }
            U16 => {
                let v = p
                    .get(..2)
                    .and_then(|b| b.try_into().ok())
                    .map_or(0, u16::from_le_bytes);
                push(&mut col, v as f64);
                spec.size
            }
            U8 => {
                push(&mut col, p.first().copied().unwrap_or(0) as f64);
                spec.size
            }
            TimeUtc => {
                let b = |i: usize| p.get(i).copied().unwrap_or(0);
                push(&mut col, b(0) as i8 as f64 + 2000.0);
                for i in 1..6 {
                    push(&mut col, b(i) as f64);
                }
                push(&mut col, u16::from_le_bytes([b(6), b(7)]) as f64);
                spec.size
            }
            Opaque => spec.size,
            SatInfo => 2 + 8 * p.first().copied().unwrap_or(0) as usize,
            RawMeas => 12 + 28 * p.get(10).copied().unwrap_or(0) as usize,
        };
        off += size;
    }
    // Exactly one value per column, whatever the payload held.
    table.values.resize(start + nc, f64::NAN);
    table.len += 1;
    time
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hex(s: &str) -> Vec<u8> {
        let s: String = s
            .chars()
            .filter(|c| !c.is_whitespace() && *c != '|')
            .collect();
        (0..s.len())
            .step_by(2)
            .map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap())
            .collect()
    }

    fn decode(bytes: &[u8]) -> (Layout, Vec<String>, Vec<f64>, Option<f64>) {
        let HeaderScan::Ok(layout) = parse_header(bytes) else {
            panic!("header")
        };
        let hl = 1 + layout.header.len();
        let size = payload_size(&layout, &bytes[hl..]).unwrap();
        assert_eq!(hl + size + 2, bytes.len());
        assert!(crc_ok(bytes));
        let names = layout.column_names();
        let mut table = Table::new(names.clone());
        let t = decode_into(&layout, &bytes[hl..hl + size], &mut table);
        let vals = table.values.clone();
        (layout, names, vals, t)
    }

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    #[test]
    fn b1() {
        let p = hex(
            "FA 01 09 00 | 70 05 00 03 0A 00 00 00 | 48 0E 2C 42 08 4C 37 C1 10 38 8B C2 | D4 CB",
        );
        let (_, names, v, t) = decode(&p);
        assert_eq!(
            names,
            [
                "common.time_startup",
                "common.yaw",
                "common.pitch",
                "common.roll"
            ]
        );
        assert!(close(t.unwrap(), 43.000006, 1e-9));
        assert!(close(v[1], 43.013947, 1e-6) && close(v[2], -11.456062, 1e-6));
        assert!(close(v[3], -69.609497, 1e-5));
    }

    #[test]
    fn b2_b3_sizes() {
        let b2 = hex("FA 01 28 05 A8 02 C3 3F E7 89 B0 42 3D A9 6A C1 D0 83 54 3A 92 3E 0B BB 1C 25 30 BA 04 7D 1C 41 3B B2 83 3D 4E EA 9C BE F1 BD 93 BE A4 55 8C BD 26 C7 77 3E F4 28 E6 41 57 CE C1 42 C0 E9");
        let (_, names, v, _) = decode(&b2);
        assert_eq!(names.len(), 14);
        assert!(close(v[12], 28.769997, 1e-5) && close(v[13], 96.903008, 1e-5));
        let hdr = parse_header(&hex("fa143e003a00"));
        let HeaderScan::Ok(l) = hdr else { panic!() };
        assert_eq!(l.fixed_payload, Some(124 - 8));
        // Synthetic B: Time group.
        let b = hex("fa 02 81 01 00 f2 05 2a 01 00 00 00 11 00 00 00 03 00 00 00 83 71");
        let (_, names, v, t) = decode(&b);
        assert_eq!(
            names,
            [
                "time.time_startup",
                "time.syncin_count",
                "time.syncout_count"
            ]
        );
        assert_eq!((t, v[1], v[2]), (Some(5.0), 17.0, 3.0));
        // B4 corrected.
        let b4 = hex("FA 05 08 00 10 00 A4 15 02 42 4D DF EB 3F F6 1A 36 BE BF 2D A4 41 AF 1A");
        let (_, names, v, _) = decode(&b4);
        assert_eq!(
            names,
            [
                "common.yaw",
                "common.pitch",
                "common.roll",
                "imu.temperature"
            ]
        );
        assert!(close(v[3], 20.522337, 1e-5));
    }

    #[test]
    fn rejects_unknown_bits() {
        assert_eq!(parse_header(&hex("fa 01 00 80 01 00")), HeaderScan::Invalid);
        assert_eq!(parse_header(&hex("fa 00")), HeaderScan::Invalid);
        assert_eq!(parse_header(&hex("fa 80 80 80 01")), HeaderScan::Invalid);
        assert_eq!(parse_header(&hex("fa 01 00")), HeaderScan::Incomplete);
    }
}
