//! Per-step telemetry of the world: contact forces, slip, poses.

use nalgebra::{UnitQuaternion, Vector3};

/// One omniwheel in one step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WheelTelemetry {
    /// Normal force `N_i` (N), from the compliant contact.
    pub normal_force_n: f64,
    /// Traction `F_i` the wheel applies to the ball along its rolling direction (N).
    pub traction_n: f64,
    /// Traction the contact would need to keep sticking (N).
    pub traction_demand_n: f64,
    /// `|F_i| / (mu N_i)`, 0 when lifted off.
    pub cone_utilisation: f64,
    /// Slip speed along the rolling direction, ball surface minus wheel rim (m/s).
    pub slip_speed_m_per_s: f64,
    /// Whether the demand exceeded the friction cone (the contact slides).
    pub slipping: bool,
    /// Torque the actuator delivered at the wheel after its torque-speed limit (N m).
    pub motor_torque_nm: f64,
    /// Wheel speed relative to the body (rad/s).
    pub speed_rad_per_s: f64,
    /// Wheel angle relative to the body (rad).
    pub angle_rad: f64,
}

/// Everything the world reports after one step, in world coordinates (z up).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepTelemetry {
    /// Simulated time at the end of the step (s).
    pub time_s: f64,
    /// The three omniwheels.
    pub wheels: [WheelTelemetry; 3],
    /// Ball centre (m).
    pub ball_position_m: Vector3<f64>,
    /// Ball orientation, world from ball.
    pub ball_orientation: UnitQuaternion<f64>,
    /// Ball velocity (m/s).
    pub ball_velocity_m_per_s: Vector3<f64>,
    /// Ball angular velocity (rad/s).
    pub ball_angular_velocity_rad_per_s: Vector3<f64>,
    /// Body frame origin (the nominal ball centre in the body) (m).
    pub body_position_m: Vector3<f64>,
    /// Body orientation, world from body.
    pub body_orientation: UnitQuaternion<f64>,
    /// Body angular velocity in the body frame (rad/s).
    pub body_rate_rad_per_s: Vector3<f64>,
    /// Body tilt about the body-aligned horizontal axes, `[theta_x, theta_y]` (rad).
    pub tilt_rad: [f64; 2],
    /// Normal force of the floor on the ball (N).
    pub floor_force_n: f64,
}

impl StepTelemetry {
    /// Feeds every field's bits into an FNV-1a 64-bit hash: equal hashes mean bit-identical
    /// telemetry (the determinism check).
    pub fn hash_into(&self, hash: &mut u64) {
        let mut eat = |x: f64| fnv1a(hash, x.to_bits());
        eat(self.time_s);
        for w in &self.wheels {
            eat(w.normal_force_n);
            eat(w.traction_n);
            eat(w.traction_demand_n);
            eat(w.cone_utilisation);
            eat(w.slip_speed_m_per_s);
            eat(f64::from(u8::from(w.slipping)));
            eat(w.motor_torque_nm);
            eat(w.speed_rad_per_s);
            eat(w.angle_rad);
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
