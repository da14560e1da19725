//! `sensor_msgs/msg/JointState` in ROS 2's CDR encoding, written by hand (a few lines; no
//! ROS and no CDR crate needed), for `/joints`.
//!
//! Why a ROS 2 message in a protobuf recording: Rerun (0.41, the newest when this was
//! written) decodes a few well-known message types of an MCAP file into its own archetypes
//! and shows them with no configuration. Our own protobuf messages become one struct
//! component each, which it plots only through a hand-made blueprint; no Foxglove protobuf
//! schema maps to its `Scalars`, but `sensor_msgs/msg/JointState` does: each of `position`,
//! `velocity` and `effort` becomes an entity with one series per joint name. The spline
//! coupling of a disc is a one-degree-of-freedom joint between shaft and disc, so the
//! mapping is natural: position = relative angle, velocity = relative speed, effort = the
//! tooth load. Foxglove and PlotJuggler decode the message as well (`/joints.effort[0]`).
//!
//! Wire format (OMG CDR, little endian, "XCDR1" as ROS 2 writes it): the 4-byte
//! encapsulation header `00 01 00 00`, then the fields in order, each primitive aligned to
//! its size counted from the end of the header; a string is a `u32` length that counts a
//! trailing NUL, the bytes and the NUL; a sequence is a `u32` count and the elements.

/// Schema name of `/joints`.
pub const JOINT_STATE: &str = "sensor_msgs/msg/JointState";

/// The `ros2msg` schema text of [`JOINT_STATE`] with its dependencies, as ROS 2 tools
/// write it into MCAP files (`=` separator lines, `MSG:` headers).
pub const JOINT_STATE_SCHEMA: &str = "\
std_msgs/Header header
string[] name
float64[] position
float64[] velocity
float64[] effort
================================================================================
MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id
================================================================================
MSG: builtin_interfaces/Time
int32 sec
uint32 nanosec
";

/// A little-endian CDR writer.
struct Cdr<'a>(&'a mut Vec<u8>);

impl Cdr<'_> {
    /// Pads with zeros until the body (after the 4-byte header) is a multiple of `n` long.
    fn align(&mut self, n: usize) {
        while !(self.0.len() - 4).is_multiple_of(n) {
            self.0.push(0);
        }
    }
    fn u32(&mut self, v: u32) {
        self.align(4);
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn f64(&mut self, v: f64) {
        self.align(8);
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn string(&mut self, s: &str) {
        self.u32(s.len() as u32 + 1);
        self.0.extend_from_slice(s.as_bytes());
        self.0.push(0);
    }
    fn f64s(&mut self, v: &[f64]) {
        self.u32(v.len() as u32);
        for &x in v {
            self.f64(x);
        }
    }
}

/// Encodes a `JointState` at `log_time_ns` (ns) into `out` (cleared first): no frame id,
/// joints `names` with the given `position`, `velocity`, `effort` (each empty or one per
/// name).
pub fn joint_state(
    out: &mut Vec<u8>,
    log_time_ns: u64,
    names: &[String],
    position: &[f64],
    velocity: &[f64],
    effort: &[f64],
) {
    out.clear();
    out.extend_from_slice(&[0, 1, 0, 0]);
    let mut w = Cdr(out);
    let sec = (log_time_ns / 1_000_000_000).min(i32::MAX as u64) as i32;
    w.u32(sec as u32);
    w.u32((log_time_ns % 1_000_000_000) as u32);
    w.string("");
    w.u32(names.len() as u32);
    for n in names {
        w.string(n);
    }
    w.f64s(position);
    w.f64s(velocity);
    w.f64s(effort);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bytes of a small message, laid out by hand from the CDR rules: header, stamp,
    /// empty frame id, two names, an empty position, a velocity and an effort aligned to 8.
    #[test]
    fn joint_state_bytes_follow_cdr() {
        let mut out = Vec::new();
        let names = ["a".to_string(), "bc".to_string()];
        joint_state(
            &mut out,
            2_000_000_003,
            &names,
            &[],
            &[1.5, -2.0],
            &[3.0, 4.0],
        );
        let mut want: Vec<u8> = vec![0, 1, 0, 0];
        want.extend(2u32.to_le_bytes()); // sec
        want.extend(3u32.to_le_bytes()); // nanosec
        want.extend(1u32.to_le_bytes()); // frame_id "" (length with NUL)
        want.extend([0, 0, 0, 0]); // NUL + padding to 4
        want.extend(2u32.to_le_bytes()); // two names
        want.extend(2u32.to_le_bytes());
        want.extend(b"a\0");
        want.extend([0, 0]); // padding
        want.extend(3u32.to_le_bytes());
        want.extend(b"bc\0");
        want.push(0); // padding
        want.extend(0u32.to_le_bytes()); // position: empty
        want.extend(2u32.to_le_bytes()); // velocity: two, ending at body offset 44
        want.extend([0, 0, 0, 0]); // align to 8
        for x in [1.5f64, -2.0] {
            want.extend(x.to_le_bytes());
        }
        want.extend(2u32.to_le_bytes()); // effort, ending at body offset 68
        want.extend([0, 0, 0, 0]); // align to 8
        for x in [3.0f64, 4.0] {
            want.extend(x.to_le_bytes());
        }
        assert_eq!(out, want);
    }
}
