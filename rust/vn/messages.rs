//! The VN ASCII message table (spec §3.1, §3.2): every decoded asynchronous
//! message with its header, backing register and field names, and the command
//! headers that are recognised without a table.
//!
//! Adding a message is one row of [`MESSAGES`] (raise [`MAX_FIELDS`] if it is
//! longer); `field_counts_match_spec` checks the counts against the manual.
//! Lookups are linear scans of about 30 rows (the parser remembers the last one).

/// One asynchronous message type: header, backing register, field names in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MsgSpec {
    /// Header without `$`, e.g. `"VNYMR"`.
    pub id: &'static str,
    /// The measurement register whose read response has the same fields (0 if none).
    pub register: u16,
    /// Async data output type (register 6 value).
    pub ador: u16,
    pub fields: &'static [&'static str],
}

macro_rules! xyz {
    ($p:literal) => {
        [concat!($p, "_x"), concat!($p, "_y"), concat!($p, "_z")]
    };
}

const fn cat<const A: usize, const B: usize, const C: usize>(
    a: [&'static str; A],
    b: [&'static str; B],
) -> [&'static str; C] {
    let mut out = [""; C];
    let mut i = 0;
    while i < A {
        out[i] = a[i];
        i += 1;
    }
    while i < C {
        out[i] = b[i - A];
        i += 1;
    }
    out
}

const YPR: [&str; 3] = ["yaw", "pitch", "roll"];
const QUAT: [&str; 4] = ["qx", "qy", "qz", "qw"];
const MAG: [&str; 3] = xyz!("mag");
const ACC: [&str; 3] = xyz!("accel");
const GYR: [&str; 3] = xyz!("gyro");
const MA: [&str; 6] = cat(MAG, ACC);
const MAR: [&str; 9] = cat(MA, GYR);
const YMR: [&str; 12] = cat(YPR, MAR);
const QMR: [&str; 13] = cat(QUAT, MAR);
const YBA: [&str; 9] = cat(cat::<3, 3, 6>(YPR, xyz!("lin_accel")), GYR);
const YIA: [&str; 9] = cat(
    cat::<3, 3, 6>(YPR, ["lin_accel_n", "lin_accel_e", "lin_accel_d"]),
    GYR,
);
const IMU: [&str; 11] = cat(MAR, ["temperature", "pressure"]);
const DTV: [&str; 7] = cat(
    cat::<1, 3, 4>(["delta_time"], xyz!("delta_theta")),
    xyz!("delta_vel"),
);
const HVE: [&str; 3] = ["heave", "heave_rate", "delayed_heave"];
const QTM: [&str; 7] = cat(QUAT, MAG);
const QTA: [&str; 7] = cat(QUAT, ACC);
const QTR: [&str; 7] = cat(QUAT, GYR);
const QMA: [&str; 10] = cat(QUAT, MA);
const QAR: [&str; 10] = cat(QUAT, cat::<3, 3, 6>(ACC, GYR));
const DCM: [&str; 9] = [
    "dcm_0", "dcm_1", "dcm_2", "dcm_3", "dcm_4", "dcm_5", "dcm_6", "dcm_7", "dcm_8",
];
const YCM: [&str; 13] = cat(YMR, ["temperature"]);
const ICM: [&str; 12] = cat(
    cat::<3, 3, 6>(YPR, MAG),
    cat::<3, 3, 6>(xyz!("inertial_accel"), GYR),
);
const RAW: [&str; 10] = cat(
    cat::<3, 3, 6>(xyz!("mag_volt"), xyz!("accel_volt")),
    cat::<3, 1, 4>(xyz!("gyro_volt"), ["temperature_volt"]),
);
const CMV: [&str; 10] = cat(MAR, ["temperature"]);
const STV: [&str; 7] = cat(QUAT, xyz!("gyro_bias"));
const COV: [&str; 6] = cat(xyz!("att_var"), xyz!("gyro_bias_var"));

/// Every decoded message type: spec tables 3.1 (current firmware) and 3.2 (legacy).
pub static MESSAGES: &[MsgSpec] = &[
    MsgSpec {
        id: "VNYPR",
        register: 8,
        ador: 1,
        fields: &YPR,
    },
    MsgSpec {
        id: "VNQTN",
        register: 9,
        ador: 2,
        fields: &QUAT,
    },
    MsgSpec {
        id: "VNQMR",
        register: 15,
        ador: 8,
        fields: &QMR,
    },
    MsgSpec {
        id: "VNMAG",
        register: 17,
        ador: 10,
        fields: &MAG,
    },
    MsgSpec {
        id: "VNACC",
        register: 18,
        ador: 11,
        fields: &ACC,
    },
    MsgSpec {
        id: "VNGYR",
        register: 19,
        ador: 12,
        fields: &GYR,
    },
    MsgSpec {
        id: "VNMAR",
        register: 20,
        ador: 13,
        fields: &MAR,
    },
    MsgSpec {
        id: "VNYMR",
        register: 27,
        ador: 14,
        fields: &YMR,
    },
    MsgSpec {
        id: "VNYBA",
        register: 239,
        ador: 16,
        fields: &YBA,
    },
    MsgSpec {
        id: "VNYIA",
        register: 240,
        ador: 17,
        fields: &YIA,
    },
    MsgSpec {
        id: "VNIMU",
        register: 54,
        ador: 19,
        fields: &IMU,
    },
    MsgSpec {
        id: "VNDTV",
        register: 80,
        ador: 30,
        fields: &DTV,
    },
    MsgSpec {
        id: "VNHVE",
        register: 115,
        ador: 34,
        fields: &HVE,
    },
    // Legacy / internal types (spec §3.2).
    MsgSpec {
        id: "VNQTM",
        register: 0,
        ador: 3,
        fields: &QTM,
    },
    MsgSpec {
        id: "VNQTA",
        register: 0,
        ador: 4,
        fields: &QTA,
    },
    MsgSpec {
        id: "VNQTR",
        register: 0,
        ador: 5,
        fields: &QTR,
    },
    MsgSpec {
        id: "VNQMA",
        register: 0,
        ador: 6,
        fields: &QMA,
    },
    MsgSpec {
        id: "VNQAR",
        register: 0,
        ador: 7,
        fields: &QAR,
    },
    MsgSpec {
        id: "VNDCM",
        register: 0,
        ador: 9,
        fields: &DCM,
    },
    MsgSpec {
        id: "VNYCM",
        register: 0,
        ador: 15,
        fields: &YCM,
    },
    MsgSpec {
        id: "VNICM",
        register: 0,
        ador: 18,
        fields: &ICM,
    },
    MsgSpec {
        id: "VNRAW",
        register: 0,
        ador: 252,
        fields: &RAW,
    },
    MsgSpec {
        id: "VNCMV",
        register: 0,
        ador: 253,
        fields: &CMV,
    },
    MsgSpec {
        id: "VNSTV",
        register: 0,
        ador: 254,
        fields: &STV,
    },
    MsgSpec {
        id: "VNCOV",
        register: 0,
        ador: 255,
        fields: &COV,
    },
];

/// Commands and their responses: well-formed, decoded as "seen" without a
/// table, counted under their header (`$VNWRG,...` → `"VNWRG"`).
pub static COMMANDS: &[&str] = &[
    "VNRRG", "VNWRG", "VNWNV", "VNRFS", "VNRST", "VNTAR", "VNKMD", "VNKAD", "VNSGB", "VNASY",
    "VNBOM", "VNFWU", "VNCMD",
];

/// `$VNERR` codes defined by the manual (spec §4).
pub fn is_defined_error(code: u16) -> bool {
    (1..=0x0C).contains(&code) || code == 0xFF
}

/// The data message with header `id` (`b"VNYMR"`).
pub fn spec_by_id(id: &[u8]) -> Option<&'static MsgSpec> {
    MESSAGES.iter().find(|m| m.id.as_bytes() == id)
}

/// The data message whose fields are those of measurement register `reg`.
pub fn spec_by_register(reg: u16) -> Option<&'static MsgSpec> {
    MESSAGES
        .iter()
        .find(|m| m.register == reg && m.register != 0)
}

/// Most fields any message has (13) plus slack.
pub const MAX_FIELDS: usize = 16;

/// The command header `id` (`b"VNWRG"`), as the name it is counted under.
pub fn command_by_id(id: &[u8]) -> Option<&'static str> {
    COMMANDS.iter().copied().find(|c| c.as_bytes() == id)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_counts_match_spec() {
        let expect = [
            ("VNYPR", 3),
            ("VNQTN", 4),
            ("VNQMR", 13),
            ("VNMAG", 3),
            ("VNACC", 3),
            ("VNGYR", 3),
            ("VNMAR", 9),
            ("VNYMR", 12),
            ("VNYBA", 9),
            ("VNYIA", 9),
            ("VNIMU", 11),
            ("VNDTV", 7),
            ("VNQTM", 7),
            ("VNQTA", 7),
            ("VNQTR", 7),
            ("VNQMA", 10),
            ("VNQAR", 10),
            ("VNDCM", 9),
            ("VNYCM", 13),
            ("VNICM", 12),
            ("VNRAW", 10),
            ("VNCMV", 10),
            ("VNSTV", 7),
            ("VNCOV", 6),
        ];
        for (id, n) in expect {
            assert_eq!(
                spec_by_id(id.as_bytes()).map(|s| s.fields.len()),
                Some(n),
                "{id}"
            );
        }
    }

    #[test]
    fn commands_are_distinct_from_data_messages() {
        for c in COMMANDS {
            assert!(spec_by_id(c.as_bytes()).is_none(), "{c}");
            assert_eq!(command_by_id(c.as_bytes()), Some(*c));
        }
    }
}
