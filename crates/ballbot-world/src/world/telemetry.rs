//! Per-step telemetry of the world: contact forces, slip, poses.
//!
//! The records derive `serde` and [`schemars::JsonSchema`]: logs write them as they are
//! (`ballbot_log::world::WorldTelemetryMsg`), so the log schema is this type's and cannot
//! drift from it. Vectors travel as `[x, y, z]`, orientations as `{x, y, z, w}` (Foxglove's
//! quaternion layout).

use super::driver::DriverLimit;
use nalgebra::{UnitQuaternion, Vector3};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// One omniwheel in one step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct WheelTelemetry {
    /// Normal force `N_i` of the wheel on the ball (N), from the compliant contact.
    pub normal_force_n: f64,
    /// Traction `F_i` the wheel applies to the ball along its rolling direction (N).
    pub traction_n: f64,
    /// Traction the contact would need to keep sticking (N).
    pub traction_demand_n: f64,
    /// Force `F_a,i` the wheel applies to the ball along its axle (N): the rollers' rolling
    /// and pin losses (0 with free rollers).
    pub axle_force_n: f64,
    /// Friction-cone utilisation `|(F_i, F_a,i)| / (mu N_i)`, 0 when lifted off.
    pub cone_utilisation: f64,
    /// Slip speed along the rolling direction, ball surface minus wheel rim (m/s).
    pub slip_speed_m_per_s: f64,
    /// Whether the contact slides (traction demand beyond the friction cone).
    pub slipping: bool,
    /// Torque the actuator delivered at the wheel after its driver's limits (N m).
    pub motor_torque_nm: f64,
    /// The driver's q-axis motor current (A).
    pub driver_current_a: f64,
    /// Which driver limit shaped the torque (`disarmed` once the driver has tripped).
    pub driver_limit: DriverLimit,
    /// Wheel speed relative to the body (rad/s).
    pub speed_rad_per_s: f64,
    /// Wheel angle relative to the body (rad).
    pub angle_rad: f64,
    /// The motor side's speed relative to the body, the rotor's over the gear ratio (rad/s):
    /// what the encoder and the driver see. Equal to `speed_rad_per_s` when the drivetrain is
    /// rigid ([`crate::world::transmission`]).
    #[serde(default)]
    pub motor_speed_rad_per_s: f64,
    /// The motor side's angle relative to the body, the rotor's over the gear ratio (rad).
    #[serde(default)]
    pub motor_angle_rad: f64,
    /// Torque the coupling passes from motor side to wheel (N m; when rigid, the torque the
    /// motor side passes to the wheel).
    #[serde(default)]
    pub coupling_torque_nm: f64,
    /// Gearbox friction torque on the motor side (N m, > 0 opposing forward speed).
    #[serde(default)]
    pub gearbox_friction_nm: f64,
}

/// Everything the world reports after one step, in world coordinates (z up).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct StepTelemetry {
    /// Simulated time at the end of the step (s).
    pub time_secs: f64,
    /// The omniwheels OW1, OW2, OW3 ([`super::wheel_name`]).
    pub wheels: [WheelTelemetry; 3],
    /// Ball centre `[x, y, z]` (m).
    #[serde(with = "xyz")]
    #[schemars(with = "[f64; 3]")]
    pub ball_position_m: Vector3<f64>,
    /// Ball orientation, world from ball (rolling shows as its rotation).
    #[serde(with = "xyzw")]
    #[schemars(with = "xyzw::Quaternion")]
    pub ball_orientation: UnitQuaternion<f64>,
    /// Ball velocity `[x, y, z]` (m/s).
    #[serde(with = "xyz")]
    #[schemars(with = "[f64; 3]")]
    pub ball_velocity_m_per_s: Vector3<f64>,
    /// Ball angular velocity `[x, y, z]` (rad/s).
    #[serde(with = "xyz")]
    #[schemars(with = "[f64; 3]")]
    pub ball_angular_velocity_rad_per_s: Vector3<f64>,
    /// Body frame origin (the nominal ball centre in the body) `[x, y, z]` (m).
    #[serde(with = "xyz")]
    #[schemars(with = "[f64; 3]")]
    pub body_position_m: Vector3<f64>,
    /// Body orientation, world from body.
    #[serde(with = "xyzw")]
    #[schemars(with = "xyzw::Quaternion")]
    pub body_orientation: UnitQuaternion<f64>,
    /// Body angular velocity in the body frame `[x, y, z]` (rad/s).
    #[serde(with = "xyz")]
    #[schemars(with = "[f64; 3]")]
    pub body_rate_rad_per_s: Vector3<f64>,
    /// Body tilt about the body-aligned horizontal axes `[theta_x, theta_y]` (rad).
    pub tilt_rad: [f64; 2],
    /// Vertical force of the floor on the ball (N): every contact patch's normal force and
    /// friction, bumps and steps included ([`crate::world::floor`]).
    pub floor_force_n: f64,
}

impl StepTelemetry {
    /// The ball's velocity in the body's yaw frame (m/s): the world velocity turned by minus
    /// the body's yaw, the frame velocity commands are given in.
    pub fn ball_velocity_yaw_frame_m_per_s(&self) -> Vector3<f64> {
        let (_, _, yaw) = self.body_orientation.euler_angles();
        nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), -yaw) * self.ball_velocity_m_per_s
    }

    /// Feeds every field's bits into an FNV-1a 64-bit hash: equal hashes mean bit-identical
    /// telemetry (the determinism check).
    pub fn hash_into(&self, hash: &mut u64) {
        let mut eat = |x: f64| fnv1a(hash, x.to_bits());
        eat(self.time_secs);
        for w in &self.wheels {
            eat(w.normal_force_n);
            eat(w.traction_n);
            eat(w.traction_demand_n);
            eat(w.axle_force_n);
            eat(w.cone_utilisation);
            eat(w.slip_speed_m_per_s);
            eat(f64::from(u8::from(w.slipping)));
            eat(w.motor_torque_nm);
            eat(w.driver_current_a);
            eat(f64::from(w.driver_limit as u8));
            eat(w.speed_rad_per_s);
            eat(w.angle_rad);
            eat(w.motor_speed_rad_per_s);
            eat(w.motor_angle_rad);
            eat(w.coupling_torque_nm);
            eat(w.gearbox_friction_nm);
        }
        for v in [
            &self.ball_position_m,
            &self.ball_velocity_m_per_s,
            &self.ball_angular_velocity_rad_per_s,
            &self.body_position_m,
            &self.body_rate_rad_per_s,
        ] {
            v.iter().for_each(|&x| eat(x));
        }
        for q in [&self.ball_orientation, &self.body_orientation] {
            q.coords.iter().for_each(|&x| eat(x));
        }
        eat(self.tilt_rad[0]);
        eat(self.tilt_rad[1]);
        eat(self.floor_force_n);
    }
}

/// The FNV-1a offset basis: start value of a telemetry hash.
pub const FNV_OFFSET_BASIS: u64 = 0xcbf2_9ce4_8422_2325;

fn fnv1a(hash: &mut u64, word: u64) {
    for byte in word.to_le_bytes() {
        *hash ^= u64::from(byte);
        *hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
    }
}

/// A vector as `[x, y, z]`.
mod xyz {
    use nalgebra::Vector3;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub(super) fn serialize<S: Serializer>(v: &Vector3<f64>, s: S) -> Result<S::Ok, S::Error> {
        [v.x, v.y, v.z].serialize(s)
    }

    pub(super) fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vector3<f64>, D::Error> {
        let [x, y, z] = <[f64; 3]>::deserialize(d)?;
        Ok(Vector3::new(x, y, z))
    }
}

/// A unit quaternion as `{x, y, z, w}`, the field layout of Foxglove's `Quaternion`.
mod xyzw {
    use nalgebra::UnitQuaternion;
    use schemars::JsonSchema;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    /// A quaternion representing a rotation in 3D space (x, y, z vector part, w scalar part).
    #[derive(Serialize, Deserialize, JsonSchema)]
    pub(super) struct Quaternion {
        /// x value.
        x: f64,
        /// y value.
        y: f64,
        /// z value.
        z: f64,
        /// w value.
        w: f64,
    }

    pub(super) fn serialize<S: Serializer>(
        q: &UnitQuaternion<f64>,
        s: S,
    ) -> Result<S::Ok, S::Error> {
        let (x, y, z, w) = (q.i, q.j, q.k, q.w);
        Quaternion { x, y, z, w }.serialize(s)
    }

    /// As written (not normalised again), so that a record reads back bit for bit.
    pub(super) fn deserialize<'de, D: Deserializer<'de>>(
        d: D,
    ) -> Result<UnitQuaternion<f64>, D::Error> {
        let Quaternion { x, y, z, w } = Quaternion::deserialize(d)?;
        Ok(UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(
            w, x, y, z,
        )))
    }
}
