//! The `version` and `status` replies read into typed values, field by field, with the
//! protocol's own decoders (`decode_u32`, `decode_target`, ...). A missing or undecodable
//! field is an error that names it.

use sonolube::protocol::TargetRange;
use sonolube::protocol::{
    NONE, Payload, Reply, SupervisorState, Target, decode_i32, decode_target, decode_u32,
};

use super::inbox::ReplyLine;

/// The fields of a `status` reply, in the protocol's scaled units.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Status {
    /// Supervisor state.
    pub state: SupervisorState,
    /// Selected scene, `None` for `none`.
    pub scene: Option<String>,
    /// Friction target, if set.
    pub target: Option<Target>,
    /// Friction coefficient estimate, ppm.
    pub friction_coef_ppm: u32,
    /// Normal force, mN.
    pub normal_force_mn: i32,
    /// Tangential force, mN.
    pub tangential_force_mn: i32,
    /// Drive amplitude, ppm of full scale.
    pub drive_amplitude_ppm: u32,
    /// Drive frequency, cHz.
    pub drive_freq_chz: u32,
    /// Control-loop overruns since boot.
    pub overruns: u32,
    /// Telemetry records lost since boot.
    pub lost: u32,
    /// Latched fault, `None` for `none`.
    pub fault: Option<String>,
    /// The resonance loop's state, `None` for `none` (no loop).
    pub lock: Option<String>,
    /// The motional current's phase to the voltage, mdeg; `None` for `undefined`.
    pub phase_mdeg: Option<i32>,
    /// `ok` or `target-unreachable` (protocol 2).
    pub reach: String,
    /// With `target-unreachable`, the value the full drive reaches now.
    pub reachable: Option<Target>,
    /// `near`, `far` or `unknown`: the drive frequency against the resonance.
    pub resonance: String,
    /// `commissioned` or `declared`: the values the loop runs on (protocol 3).
    pub values: String,
    /// Keys the reply carried that this protocol version does not document.
    pub extra_keys: Vec<String>,
}

/// The fields of a `version` reply.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Version {
    /// Firmware version.
    pub firmware: String,
    /// Board name.
    pub board: String,
    /// Protocol version.
    pub protocol: u16,
}

/// The keys of a `status` reply, in order.
pub const STATUS_KEYS: [&str; 17] = [
    "state",
    "scene",
    "target",
    "mu",
    "normal_n",
    "tangential_n",
    "amp",
    "freq_hz",
    "overruns",
    "lost",
    "fault",
    "lock",
    "phase_deg",
    "reach",
    "reachable",
    "resonance",
    "values",
];

/// The payload of an `ok` reply, or what the reply was instead.
pub fn ok_payload(reply: &ReplyLine) -> Result<Payload<'_>, String> {
    match reply.decode() {
        Ok(Reply::Ok(payload)) => Ok(payload),
        Ok(Reply::Err(_)) => Err(format!("got {:?}", reply.text)),
        Err(error) => Err(format!("malformed reply {:?} ({error:?})", reply.text)),
    }
}

fn field<'a>(payload: &Payload<'a>, key: &str) -> Result<&'a str, String> {
    payload
        .get(key)
        .ok_or_else(|| format!("no {key}= field in {:?}", payload.as_str()))
}

fn number<T, E: std::fmt::Debug>(
    payload: &Payload<'_>,
    key: &str,
    decimals: u8,
    decode: fn(&str, u8) -> Result<T, E>,
) -> Result<T, String> {
    let text = field(payload, key)?;
    decode(text, decimals).map_err(|e| format!("{key}={text}: {e:?}"))
}

fn optional_word(text: &str) -> Option<String> {
    (text != NONE).then(|| text.to_string())
}

/// Reads a `status` reply.
pub fn decode_status(reply: &ReplyLine) -> Result<Status, String> {
    let payload = ok_payload(reply)?;
    let state_text = field(&payload, "state")?;
    let state = SupervisorState::from_name(state_text)
        .ok_or_else(|| format!("state={state_text} is not a state"))?;
    let target_text = field(&payload, "target")?;
    let target = decode_target(target_text).map_err(|e| format!("target={target_text}: {e:?}"))?;
    Ok(Status {
        state,
        scene: optional_word(field(&payload, "scene")?),
        target,
        friction_coef_ppm: number(&payload, "mu", 6, decode_u32)?,
        normal_force_mn: number(&payload, "normal_n", 3, decode_i32)?,
        tangential_force_mn: number(&payload, "tangential_n", 3, decode_i32)?,
        drive_amplitude_ppm: number(&payload, "amp", 6, decode_u32)?,
        drive_freq_chz: number(&payload, "freq_hz", 2, decode_u32)?,
        overruns: number(&payload, "overruns", 0, decode_u32)?,
        lost: number(&payload, "lost", 0, decode_u32)?,
        fault: optional_word(field(&payload, "fault")?),
        lock: optional_word(field(&payload, "lock")?),
        phase_mdeg: match field(&payload, "phase_deg")? {
            "undefined" => None,
            _ => Some(number(&payload, "phase_deg", 3, decode_i32)?),
        },
        reach: field(&payload, "reach")?.to_string(),
        reachable: {
            let text = field(&payload, "reachable")?;
            decode_target(text).map_err(|e| format!("reachable={text}: {e:?}"))?
        },
        resonance: field(&payload, "resonance")?.to_string(),
        values: match field(&payload, "values")? {
            word @ ("commissioned" | "declared") => word.to_string(),
            other => return Err(format!("values={other} is not commissioned or declared")),
        },
        extra_keys: payload
            .pairs()
            .map(|(key, _)| key)
            .filter(|key| !STATUS_KEYS.contains(key))
            .map(str::to_string)
            .collect(),
    })
}

/// Reads a `version` reply.
pub fn decode_version(reply: &ReplyLine) -> Result<Version, String> {
    let payload = ok_payload(reply)?;
    let protocol = number(&payload, "protocol", 0, decode_u32)?;
    Ok(Version {
        firmware: field(&payload, "firmware")?.to_string(),
        board: field(&payload, "board")?.to_string(),
        protocol: u16::try_from(protocol).map_err(|_| format!("protocol={protocol} > 65535"))?,
    })
}

/// A scaled integer written with `decimals` fraction digits, as the protocol prints it
/// (`150000`, 6 → `0.150000`; `-12480`, 3 → `-12.480`).
pub fn fixed(value: i64, decimals: u8) -> String {
    if decimals == 0 {
        return value.to_string();
    }
    let scale = 10u64.pow(u32::from(decimals));
    let magnitude = value.unsigned_abs();
    let sign = if value < 0 { "-" } else { "" };
    format!(
        "{sign}{}.{:0width$}",
        magnitude / scale,
        magnitude % scale,
        width = usize::from(decimals)
    )
}

/// A target as the protocol writes it: `coef:0.150000`, or `none`.
pub fn target_text(target: Option<&Target>) -> String {
    match target {
        None => NONE.to_string(),
        Some(target) => format!(
            "{}:{}",
            target.kind(),
            fixed(target.scaled_value(), target.quantity().decimals)
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reply(text: &str) -> ReplyLine {
        ReplyLine { text: text.into() }
    }

    #[test]
    fn status_fields_decode() {
        let status = decode_status(&reply(
            "ok state=running scene=demo target=coef:0.150000 mu=0.151000 normal_n=40.000 \
             tangential_n=-6.040 amp=0.523000 freq_hz=40000.00 overruns=0 lost=3 fault=none \
             lock=locked phase_deg=-0.250 reach=target-unreachable reachable=coef:0.180000 \
             resonance=near values=commissioned",
        ))
        .unwrap();
        assert_eq!(status.state, SupervisorState::Running);
        assert_eq!(status.scene.as_deref(), Some("demo"));
        assert_eq!(status.target, Some(Target::Coef { coef_ppm: 150_000 }));
        assert_eq!(status.friction_coef_ppm, 151_000);
        assert_eq!(status.tangential_force_mn, -6_040);
        assert_eq!(status.drive_amplitude_ppm, 523_000);
        assert_eq!(status.drive_freq_chz, 4_000_000);
        assert_eq!((status.overruns, status.lost), (0, 3));
        assert_eq!(status.fault, None);
        assert_eq!(status.lock.as_deref(), Some("locked"));
        assert_eq!(status.phase_mdeg, Some(-250));
        assert_eq!(status.reach, "target-unreachable");
        assert_eq!(status.reachable, Some(Target::Coef { coef_ppm: 180_000 }));
        assert_eq!(status.resonance, "near");
        assert_eq!(status.values, "commissioned");
        assert!(status.extra_keys.is_empty());
        // The signed kind (issue 27), and a malformed one named.
        let line = "ok state=running scene=horn-motor target=net-force:-5.000 mu=0.151000 \
                    normal_n=40.000 tangential_n=5.010 amp=0.523000 freq_hz=20000.00 overruns=0 \
                    lost=0 fault=none lock=pinned phase_deg=undefined reach=ok reachable=none \
                    resonance=near values=declared";
        let status = decode_status(&reply(line)).unwrap();
        assert_eq!(status.target, Some(Target::NetForce { force_mn: -5_000 }));
        let error = decode_status(&reply(&line.replace("-5.000", "-5.0001"))).unwrap_err();
        assert!(error.contains("target=net-force:-5.0001"), "{error}");
    }

    #[test]
    fn missing_or_bad_fields_are_named() {
        let full = "ok state=idle scene=none target=none mu=0.240000 normal_n=40.000 \
                    tangential_n=9.600 amp=0.000000 freq_hz=40000.00 overruns=0 lost=0 fault=none \
                    lock=pinned phase_deg=undefined reach=ok reachable=none resonance=unknown \
                    values=declared";
        assert!(decode_status(&reply(full)).is_ok());
        for key in STATUS_KEYS {
            let without: Vec<&str> = full
                .split(' ')
                .filter(|word| !word.starts_with(&format!("{key}=")))
                .collect();
            let error = decode_status(&reply(&without.join(" "))).unwrap_err();
            assert!(error.contains(key), "{key}: {error}");
        }
        let error =
            decode_status(&reply(&full.replace("mu=0.240000", "mu=0.2400001"))).unwrap_err();
        assert!(error.starts_with("mu="), "{error}");
        let error = decode_status(&reply(&full.replace("idle", "asleep"))).unwrap_err();
        assert!(error.contains("asleep"), "{error}");
        let error =
            decode_status(&reply(&full.replace("values=declared", "values=guessed"))).unwrap_err();
        assert!(error.starts_with("values=guessed"), "{error}");
        assert!(decode_status(&reply("err 1 unknown-command x")).is_err());
        assert!(decode_status(&reply("ok a")).is_err());
    }

    #[test]
    fn version_fields_decode() {
        let version = decode_version(&reply("ok firmware=0.1.0 board=qemu protocol=1")).unwrap();
        assert_eq!(
            version,
            Version {
                firmware: "0.1.0".into(),
                board: "qemu".into(),
                protocol: 1
            }
        );
        assert!(decode_version(&reply("ok firmware=0.1.0 board=qemu")).is_err());
        assert!(decode_version(&reply("ok firmware=0.1.0 board=qemu protocol=70000")).is_err());
    }

    #[test]
    fn fixed_point_text() {
        assert_eq!(fixed(150_000, 6), "0.150000");
        assert_eq!(fixed(-12_480, 3), "-12.480");
        assert_eq!(fixed(4_000_000, 2), "40000.00");
        assert_eq!(fixed(7, 0), "7");
        assert_eq!(fixed(i64::MIN, 3), "-9223372036854775.808");
        assert_eq!(
            target_text(Some(&Target::Reduction {
                reduction_mpct: 40_000
            })),
            "reduction:40.000"
        );
        assert_eq!(
            target_text(Some(&Target::NetForce { force_mn: -5_250 })),
            "net-force:-5.250"
        );
        assert_eq!(target_text(None), "none");
    }
}
