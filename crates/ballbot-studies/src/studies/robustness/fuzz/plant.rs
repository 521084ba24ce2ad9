//! The fuzzer's plant: the core's three planar models (frontal and sagittal WIP, spin)
//! coupled through the omniwheel kinematics, integrated with RK4 at the inner rate. Cheap
//! (no contacts), so that millions of controller steps run in seconds while the controller
//! really balances and drives.

use ballbot_core::estimation::{
    EncoderSample, ImuSample, PlanarStates, ball_body_z_rate_per_ball_rate, synthesize_sensors,
};
use ballbot_core::kinematics::relative_rate_from_planar;
use ballbot_core::wip::{BALL_RATE, TILT, TILT_RATE};
use ballbot_core::{BallbotParams, Error, OmniKinematics, Spin, Wip, rk4_step};
use nalgebra::{Vector2, Vector3};

/// The coupled planar plant (see the module docs).
#[derive(Clone, Copy, Debug)]
pub struct Plant {
    kin: OmniKinematics<f64>,
    frontal: Wip<f64>,
    sagittal: Wip<f64>,
    spin: Spin<f64>,
    /// The states.
    pub states: PlanarStates<f64>,
}

impl Plant {
    /// `robot` upright and at rest.
    pub fn new(robot: &BallbotParams<f64>) -> Result<Self, Error> {
        Ok(Self {
            kin: OmniKinematics::from_ballbot(robot)?,
            frontal: Wip::new(robot.frontal)?,
            sagittal: Wip::new(robot.sagittal)?,
            spin: Spin::new(robot.spin)?,
            states: PlanarStates::zeros(),
        })
    }

    /// What the IMU and encoders would read now: the encoders with the ball not spinning
    /// about the vertical ([`Self::wheel_speeds`]).
    pub fn sensors(&self, now_us: u64) -> (ImuSample<f64>, EncoderSample<f64>) {
        let (imu, mut encoders) = synthesize_sensors(&self.kin, &self.states, now_us);
        encoders.wheel_speeds_rad_per_s = self.wheel_speeds();
        (imu, encoders)
    }

    /// The omniwheel speeds (rad/s) the motor drivers measure, for a ball that does not
    /// spin about the vertical: leaning, the rolling ball turns about the body's z axis by
    /// `k . [phi_dot_x, phi_dot_y]` ([`ball_body_z_rate_per_ball_rate`]), as the
    /// controller's estimator and slip monitor assume. (The small-tilt form of
    /// [`synthesize_sensors`] leaves that out: a lean of 0.1 rad at 2 m/s then reads as a
    /// 1.7 rad/s slip of the ball about the body's z axis, and the slip monitor flagged it on
    /// this slip-free plant: the fuzzer's `slip_clears` invariant.)
    pub fn wheel_speeds(&self) -> Vector3<f64> {
        let s = &self.states;
        let mut rel = relative_rate_from_planar(
            [s.frontal[BALL_RATE], s.sagittal[BALL_RATE]],
            [s.frontal[TILT_RATE], s.sagittal[TILT_RATE]],
            s.spin[1],
        );
        let k = ball_body_z_rate_per_ball_rate(s.frontal[TILT], s.sagittal[TILT]);
        rel[2] += k[0] * s.frontal[BALL_RATE] + k[1] * s.sagittal[BALL_RATE];
        self.kin.wheel_speeds_rad_per_s(&rel)
    }

    /// One step of `dt_secs` under the omniwheel torques (N m).
    pub fn step(&mut self, wheel_torques_nm: &Vector3<f64>, dt_secs: f64) {
        let tau = self.kin.planar_torque_nm(wheel_torques_nm);
        let s = &mut self.states;
        s.frontal = rk4_step(|x| self.frontal.derivative(x, tau[0]), &s.frontal, dt_secs);
        s.sagittal = rk4_step(
            |x| self.sagittal.derivative(x, tau[1]),
            &s.sagittal,
            dt_secs,
        );
        s.spin = rk4_step(|x| self.spin.derivative(x, tau[2]), &s.spin, dt_secs);
    }

    /// A push: a horizontal impulse `[frontal, sagittal]` (N s) on the body at its centre of
    /// mass, in each plane's own direction. In a plane with `x = r phi + l sin(theta)` the
    /// position of the centre of mass, the generalised velocities jump by
    /// `M(theta)^-1 J [l cos(theta), r]`.
    pub fn push(&mut self, impulse_n_s: [f64; 2]) {
        let planes = [
            (&self.frontal, &mut self.states.frontal, impulse_n_s[0]),
            (&self.sagittal, &mut self.states.sagittal, impulse_n_s[1]),
        ];
        for (wip, s, j) in planes {
            let p = wip.params();
            let q = Vector2::new(j * p.com_height_m * s[TILT].cos(), j * p.ball_radius_m);
            if let Some(inverse) = wip.mass_matrix(s[TILT]).try_inverse() {
                let dq = inverse * q;
                s[TILT_RATE] += dq[0];
                s[BALL_RATE] += dq[1];
            }
        }
    }

    /// The body's tilt from the vertical (rad): `acos(cos(roll) cos(pitch))`, the planes'
    /// tilts being the IMU's roll and pitch.
    pub fn tilt_from_vertical_rad(&self) -> f64 {
        tilt_from_vertical_rad(self.states.frontal[TILT], self.states.sagittal[TILT])
    }

    /// The ball's speed over the floor (m/s).
    pub fn ball_speed_m_per_s(&self) -> f64 {
        let s = &self.states;
        (s.frontal[BALL_RATE] * self.frontal.params().ball_radius_m)
            .hypot(s.sagittal[BALL_RATE] * self.sagittal.params().ball_radius_m)
    }

    /// Whether the body has fallen past `limit_rad` from the vertical (or the state is no
    /// longer finite).
    pub fn fallen(&self, limit_rad: f64) -> bool {
        let tilt = self.tilt_from_vertical_rad();
        tilt.is_nan() || tilt >= limit_rad
    }

    /// Back upright and at rest (after a fall: the fuzzer goes on with a standing robot).
    pub fn reset(&mut self) {
        self.states = PlanarStates::zeros();
    }
}

/// The tilt from the vertical (rad) of a body at `roll_rad` and `pitch_rad` (ZYX Euler
/// angles): the angle between its axis and the vertical, `acos(cos(roll) cos(pitch))`; NaN
/// for a non-finite attitude.
pub fn tilt_from_vertical_rad(roll_rad: f64, pitch_rad: f64) -> f64 {
    (roll_rad.cos() * pitch_rad.cos()).clamp(-1.0, 1.0).acos()
}
