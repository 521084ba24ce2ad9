//! State estimation: IMU and wheel encoders -> the planar states of the sagittal, frontal and
//! spin models.
//!
//! # Sensor samples
//!
//! [`ImuSample`]: the body's attitude as ZYX Euler angles (yaw about world z, then pitch about
//! the new y, then roll about the new x: `R = Rz(yaw) Ry(pitch) Rx(roll)`, the convention of
//! nalgebra's `UnitQuaternion::from_euler_angles`) and the body angular velocity in body
//! coordinates (what a body-mounted gyro measures). [`ImuSample::from_quaternion`] converts a
//! quaternion attitude. [`EncoderSample`]: the three omniwheel speeds (rad/s, at the omniwheel,
//! positive as in [`crate::kinematics`]). Both carry a timestamp in microseconds of a monotonic
//! clock, so the safety supervisor can tell stale data (integer time: no precision loss
//! however long the robot runs).
//!
//! # IMU -> planar tilts
//!
//! The planes are fixed to the body (MODEL.md section 1): the sagittal plane (subscript y)
//! rotates about y, the frontal plane (subscript x) about x. With the ZYX angles the body's z
//! axis, seen in the heading frame (world rotated by yaw), is
//! `Ry(pitch) Rx(roll) e_z = [sin(pitch) cos(roll), -sin(roll), cos(pitch) cos(roll)]`: a
//! positive pitch leans it towards +x (sagittal +travel, `x = r phi_y`), a positive roll
//! towards -y (frontal +travel, `y = -r phi_x`). Both agree with the planar models' sign
//! (positive `theta` leans towards +travel), so
//!
//! ```text
//! theta_x = roll,  theta_y = pitch,  theta_z = yaw (unwrapped)
//! theta_dot = omega_body (gyro, body coordinates)
//! ```
//!
//! Pitch is exactly the tilt of the body axis projected on the sagittal plane; roll equals the
//! frontal projection to first order. Using the gyro rates as the planar tilt rates makes the
//! relative-rate relation of MODEL.md section 4 exact in body coordinates:
//! `omega_rel = omega_ball - omega_body`, so the ball rates are
//! `[phi_dot_x, phi_dot_y] = omega_rel[0..2] + [theta_dot_x, theta_dot_y]` with
//! `omega_rel = J^-1 psi_dot` from [`OmniKinematics`]. (Euler-angle rates differ from body
//! rates by terms of order angle x rate.)

use crate::check::lit;
use crate::kinematics::relative_rate_from_planar;
use crate::wip::{BALL_ANGLE, BALL_RATE, TILT, TILT_RATE, WipState};
use crate::{OmniKinematics, SpinState};
use nalgebra::{Quaternion, RealField, UnitQuaternion, Vector3};

/// One IMU reading.
///
/// ```
/// use ballbot_core::estimation::ImuSample;
/// use nalgebra::Vector3;
/// // Pitched 2 deg forward and tipping further at 0.1 rad/s, heading 90 deg.
/// let imu = ImuSample {
///     timestamp_us: 1_000_000,
///     roll_rad: 0.0,
///     pitch_rad: 2f64.to_radians(),
///     yaw_rad: core::f64::consts::FRAC_PI_2,
///     angular_velocity_rad_per_s: Vector3::new(0.0, 0.1, 0.0),
/// };
/// assert!(imu.is_finite());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImuSample<T: nalgebra::Scalar> {
    /// When it was measured, on the robot's monotonic clock (microseconds).
    pub timestamp_us: u64,
    /// Roll about body x (rad), ZYX convention.
    pub roll_rad: T,
    /// Pitch about body y (rad), ZYX convention.
    pub pitch_rad: T,
    /// Yaw (heading) about world z (rad), ZYX convention; any branch (e.g. (-pi, pi]).
    pub yaw_rad: T,
    /// Body angular velocity in body coordinates `[omega_x, omega_y, omega_z]` (rad/s).
    pub angular_velocity_rad_per_s: Vector3<T>,
}

impl<T: RealField + Copy> ImuSample<T> {
    /// An upright, still reading at time `timestamp_us`.
    ///
    /// ```
    /// use ballbot_core::estimation::ImuSample;
    /// let imu = ImuSample::<f64>::upright(2500);
    /// assert_eq!((imu.timestamp_us, imu.pitch_rad), (2500, 0.0));
    /// assert_eq!(imu.angular_velocity_rad_per_s.norm(), 0.0);
    /// ```
    pub fn upright(timestamp_us: u64) -> Self {
        Self {
            timestamp_us,
            roll_rad: T::zero(),
            pitch_rad: T::zero(),
            yaw_rad: T::zero(),
            angular_velocity_rad_per_s: Vector3::zeros(),
        }
    }

    /// A reading from a (not necessarily normalised) attitude quaternion `world_from_body` and
    /// the body angular velocity. A zero or non-finite quaternion gives non-finite angles,
    /// which the safety supervisor rejects.
    ///
    /// ```
    /// use ballbot_core::estimation::ImuSample;
    /// use nalgebra::{UnitQuaternion, Vector3};
    /// let q = UnitQuaternion::from_euler_angles(0.05, -0.02, 1.0);
    /// let imu = ImuSample::from_quaternion(7, q.quaternion(), Vector3::zeros());
    /// approx::assert_relative_eq!(imu.roll_rad, 0.05, epsilon = 1e-12);
    /// approx::assert_relative_eq!(imu.pitch_rad, -0.02, epsilon = 1e-12);
    /// approx::assert_relative_eq!(imu.yaw_rad, 1.0, epsilon = 1e-12);
    /// ```
    pub fn from_quaternion(
        timestamp_us: u64,
        world_from_body: &Quaternion<T>,
        angular_velocity_rad_per_s: Vector3<T>,
    ) -> Self {
        let norm = world_from_body.norm();
        let (roll_rad, pitch_rad, yaw_rad) = if norm.is_finite() && norm > lit(1e-6) {
            UnitQuaternion::new_unchecked(world_from_body / norm).euler_angles()
        } else {
            let nan = T::zero() / T::zero();
            (nan, nan, nan)
        };
        Self {
            timestamp_us,
            roll_rad,
            pitch_rad,
            yaw_rad,
            angular_velocity_rad_per_s,
        }
    }

    /// Whether every number in the reading is finite.
    ///
    /// ```
    /// use ballbot_core::estimation::ImuSample;
    /// let mut imu = ImuSample::<f64>::upright(0);
    /// assert!(imu.is_finite());
    /// imu.angular_velocity_rad_per_s[2] = f64::INFINITY;
    /// assert!(!imu.is_finite());
    /// ```
    pub fn is_finite(&self) -> bool {
        self.roll_rad.is_finite()
            && self.pitch_rad.is_finite()
            && self.yaw_rad.is_finite()
            && self
                .angular_velocity_rad_per_s
                .iter()
                .all(|x| x.is_finite())
    }
}

/// One reading of the three omniwheel encoders.
///
/// ```
/// use ballbot_core::estimation::EncoderSample;
/// use nalgebra::Vector3;
/// let speeds = Vector3::new(3.0, -1.5, -1.5);
/// let enc = EncoderSample { timestamp_us: 2500, wheel_speeds_rad_per_s: speeds };
/// assert!(enc.is_finite());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EncoderSample<T: nalgebra::Scalar> {
    /// When it was measured, on the robot's monotonic clock (microseconds).
    pub timestamp_us: u64,
    /// Omniwheel speeds `psi_dot_i` (rad/s, at the omniwheel, after the gearbox).
    pub wheel_speeds_rad_per_s: Vector3<T>,
}

impl<T: RealField + Copy> EncoderSample<T> {
    /// All wheels still at time `timestamp_us`.
    ///
    /// ```
    /// use ballbot_core::estimation::EncoderSample;
    /// let enc = EncoderSample::<f64>::still(0);
    /// assert_eq!(enc.wheel_speeds_rad_per_s, nalgebra::Vector3::zeros());
    /// ```
    pub fn still(timestamp_us: u64) -> Self {
        Self {
            timestamp_us,
            wheel_speeds_rad_per_s: Vector3::zeros(),
        }
    }

    /// Whether every speed is finite.
    ///
    /// ```
    /// use ballbot_core::estimation::EncoderSample;
    /// let mut enc = EncoderSample::<f64>::still(0);
    /// enc.wheel_speeds_rad_per_s[1] = f64::NAN;
    /// assert!(!enc.is_finite());
    /// ```
    pub fn is_finite(&self) -> bool {
        self.wheel_speeds_rad_per_s.iter().all(|x| x.is_finite())
    }
}

/// The three planar states of a ballbot.
///
/// ```
/// use ballbot_core::estimation::PlanarStates;
/// use ballbot_core::{BallbotParams, OmniKinematics};
/// let mut s = PlanarStates::<f64>::zeros();
/// // 1 m/s forward: the sagittal ball rate is the speed over the ball radius.
/// let r = BallbotParams::<f64>::miapure_60kg().sagittal.ball_radius_m;
/// s.sagittal[3] = 1.0 / r;
/// s.spin[1] = 0.5; // turning left at 0.5 rad/s
/// assert!(s.is_finite());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanarStates<T: nalgebra::Scalar> {
    /// Sagittal plane `[theta_y, phi_y, theta_dot_y, phi_dot_y]`.
    pub sagittal: WipState<T>,
    /// Frontal plane `[theta_x, phi_x, theta_dot_x, phi_dot_x]`.
    pub frontal: WipState<T>,
    /// Spin `[theta_z, theta_dot_z]` (heading unwrapped: continuous across +-pi).
    pub spin: SpinState<T>,
}

impl<T: RealField + Copy> PlanarStates<T> {
    /// All zero: upright, at rest, heading 0.
    ///
    /// ```
    /// use ballbot_core::estimation::PlanarStates;
    /// let s = PlanarStates::<f64>::zeros();
    /// assert!(s.sagittal.iter().chain(s.frontal.iter()).chain(s.spin.iter()).all(|x| *x == 0.0));
    /// ```
    pub fn zeros() -> Self {
        Self {
            sagittal: WipState::zeros(),
            frontal: WipState::zeros(),
            spin: SpinState::zeros(),
        }
    }

    /// Whether every entry is finite.
    ///
    /// ```
    /// use ballbot_core::estimation::PlanarStates;
    /// let mut s = PlanarStates::<f64>::zeros();
    /// assert!(s.is_finite());
    /// s.spin[0] = f64::NAN;
    /// assert!(!s.is_finite());
    /// ```
    pub fn is_finite(&self) -> bool {
        self.sagittal.iter().all(|x| x.is_finite())
            && self.frontal.iter().all(|x| x.is_finite())
            && self.spin.iter().all(|x| x.is_finite())
    }
}

/// Estimates the planar states from IMU and encoder samples.
///
/// Holds the last accepted values: when a sample is missing or rejected (`None`, or
/// non-finite), the previous tilt, rates and speeds are kept and the ball angles keep
/// integrating the held ball rates. The heading is unwrapped (continuous across +-pi) so that
/// the spin controller never sees a 2 pi jump. O(1), allocation-free, panic-free.
///
/// ```
/// use ballbot_core::estimation::{Estimator, PlanarStates, synthesize_sensors};
/// use ballbot_core::{BallbotParams, OmniKinematics};
/// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
/// let mut truth = PlanarStates::zeros();
/// truth.sagittal[0] = 0.05; // pitched forward
/// truth.sagittal[3] = 4.0; // ball rolling forward
/// let (imu, enc) = synthesize_sensors(&kin, &truth, 0);
/// let mut est = Estimator::new(kin);
/// let s = est.update(Some(&imu), Some(&enc), 0.0025);
/// approx::assert_relative_eq!(s.sagittal[3], 4.0, epsilon = 1e-12);
/// approx::assert_relative_eq!(s.sagittal[0], 0.05, epsilon = 1e-12);
/// # Ok::<(), ballbot_core::Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimator<T: nalgebra::Scalar> {
    kinematics: OmniKinematics<T>,
    states: PlanarStates<T>,
    last_yaw_rad: Option<T>,
}

impl<T: RealField + Copy> Estimator<T> {
    /// An estimator at rest, heading taken from the first IMU sample.
    ///
    /// ```
    /// use ballbot_core::estimation::{Estimator, PlanarStates};
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// let est = Estimator::new(kin);
    /// assert_eq!(*est.states(), PlanarStates::zeros());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn new(kinematics: OmniKinematics<T>) -> Self {
        Self {
            kinematics,
            states: PlanarStates::zeros(),
            last_yaw_rad: None,
        }
    }

    /// The kinematics it inverts.
    ///
    /// ```
    /// use ballbot_core::estimation::Estimator;
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// assert_eq!(Estimator::new(kin).kinematics(), &kin);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn kinematics(&self) -> &OmniKinematics<T> {
        &self.kinematics
    }

    /// The latest estimate.
    ///
    /// ```
    /// use ballbot_core::estimation::{Estimator, ImuSample};
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// let mut est = Estimator::new(kin);
    /// let imu = ImuSample { roll_rad: -0.01, ..ImuSample::upright(0) };
    /// let returned = est.update(Some(&imu), None, 0.0025);
    /// assert_eq!(*est.states(), returned);
    /// assert_eq!(est.states().frontal[0], -0.01); // theta_x = roll
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn states(&self) -> &PlanarStates<T> {
        &self.states
    }

    /// Forgets everything: back to rest, ball angles 0, heading from the next IMU sample.
    ///
    /// ```
    /// use ballbot_core::estimation::{EncoderSample, Estimator, PlanarStates};
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// use nalgebra::Vector3;
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// let mut est = Estimator::new(kin);
    /// let speeds = Vector3::new(5.0, -2.5, -2.5);
    /// let rolling = EncoderSample { timestamp_us: 0, wheel_speeds_rad_per_s: speeds };
    /// est.update(None, Some(&rolling), 0.0025);
    /// est.update(None, Some(&rolling), 0.0025);
    /// assert_ne!(*est.states(), PlanarStates::zeros()); // rolling: ball rates and angles
    /// est.reset();
    /// assert_eq!(*est.states(), PlanarStates::zeros());
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn reset(&mut self) {
        self.states = PlanarStates::zeros();
        self.last_yaw_rad = None;
    }

    /// Folds in the samples accepted this step (`None`: missing or rejected) and integrates
    /// the ball angles over `dt_secs` (trapezoidal; a non-finite or negative `dt_secs`
    /// integrates nothing). Non-finite samples are ignored.
    ///
    /// ```
    /// use ballbot_core::estimation::{Estimator, ImuSample};
    /// use ballbot_core::{BallbotParams, OmniKinematics};
    /// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
    /// let mut est = Estimator::new(kin);
    /// // The IMU's yaw wraps from +3.1 to -3.1 rad: the heading goes on continuously.
    /// let imu = ImuSample { yaw_rad: 3.1, ..ImuSample::upright(0) };
    /// est.update(Some(&imu), None, 0.0025);
    /// let imu = ImuSample { yaw_rad: -3.1, ..ImuSample::upright(2500) };
    /// let s = est.update(Some(&imu), None, 0.0025);
    /// approx::assert_relative_eq!(s.spin[0], 2.0 * core::f64::consts::PI - 3.1, epsilon = 1e-12);
    /// // A NaN sample is ignored: the last good attitude is held.
    /// let bad = ImuSample { pitch_rad: f64::NAN, ..ImuSample::upright(5000) };
    /// assert_eq!(est.update(Some(&bad), None, 0.0025), s);
    /// # Ok::<(), ballbot_core::Error>(())
    /// ```
    pub fn update(
        &mut self,
        imu: Option<&ImuSample<T>>,
        encoders: Option<&EncoderSample<T>>,
        dt_secs: T,
    ) -> PlanarStates<T> {
        let old_rate_x = self.states.frontal[BALL_RATE];
        let old_rate_y = self.states.sagittal[BALL_RATE];
        if let Some(imu) = imu.filter(|s| s.is_finite()) {
            let w = imu.angular_velocity_rad_per_s;
            self.states.frontal[TILT] = imu.roll_rad;
            self.states.frontal[TILT_RATE] = w[0];
            self.states.sagittal[TILT] = imu.pitch_rad;
            self.states.sagittal[TILT_RATE] = w[1];
            let heading = match self.last_yaw_rad {
                Some(last) => self.states.spin[0] + wrap_pi(imu.yaw_rad - last),
                None => imu.yaw_rad,
            };
            self.last_yaw_rad = Some(imu.yaw_rad);
            self.states.spin = SpinState::new(heading, w[2]);
        }
        if let Some(enc) = encoders.filter(|s| s.is_finite()) {
            let rel = self
                .kinematics
                .relative_rate_rad_per_s(&enc.wheel_speeds_rad_per_s);
            let rate_x = rel[0] + self.states.frontal[TILT_RATE];
            let rate_y = rel[1] + self.states.sagittal[TILT_RATE];
            if rate_x.is_finite() && rate_y.is_finite() {
                self.states.frontal[BALL_RATE] = rate_x;
                self.states.sagittal[BALL_RATE] = rate_y;
            }
        }
        if dt_secs.is_finite() && dt_secs > T::zero() {
            let half_dt = dt_secs * lit(0.5);
            let phi_x = self.states.frontal[BALL_ANGLE]
                + (old_rate_x + self.states.frontal[BALL_RATE]) * half_dt;
            let phi_y = self.states.sagittal[BALL_ANGLE]
                + (old_rate_y + self.states.sagittal[BALL_RATE]) * half_dt;
            if phi_x.is_finite() && phi_y.is_finite() {
                self.states.frontal[BALL_ANGLE] = phi_x;
                self.states.sagittal[BALL_ANGLE] = phi_y;
            }
        }
        self.states
    }
}

/// The ball's angular velocity about the body's z axis per unit of its body-x and body-y
/// rates, `k` with `omega_z = k[0] phi_dot_x + k[1] phi_dot_y` (body coordinates), for a ball
/// that does not spin about the vertical (the floor's torsional friction; MODEL.md section 3),
/// with the body at ZYX roll and pitch `roll_rad`, `pitch_rad`.
///
/// The vertical seen from the body is `g = [-sin(pitch), cos(pitch) sin(roll), cos(pitch)
/// cos(roll)]`; no vertical spin means `g . omega = 0`, so
/// `k = [tan(pitch) / cos(roll), -tan(roll)]`. Upright, `k = 0` and the relative rate of
/// MODEL.md section 4 (`omega_rel_z = -theta_dot_z`) holds; leaning, the rolling ball turns
/// about the body's z axis: at 3 m/s (26 rad/s) a 1 deg sideways lean gives 0.45 rad/s,
/// which the omniwheels measure like a yaw rate. Tilts beyond 84 deg (fallen) give `k = 0`.
///
/// ```
/// use ballbot_core::estimation::ball_body_z_rate_per_ball_rate;
/// // Rolling forward (phi_dot_y > 0) with the body rolled by +1 deg (leaning towards -y).
/// let k = ball_body_z_rate_per_ball_rate(1.0f64.to_radians(), 0.0);
/// approx::assert_relative_eq!(k[1] * 26.0, -26.0 * 1.0f64.to_radians().tan(), epsilon = 1e-12);
/// assert_eq!(k[0], 0.0);
/// ```
#[inline]
pub fn ball_body_z_rate_per_ball_rate<T: RealField + Copy>(roll_rad: T, pitch_rad: T) -> [T; 2] {
    ball_body_z_rate_per_ball_rate_sin_cos(roll_rad.sin_cos(), pitch_rad.sin_cos())
}

/// [`ball_body_z_rate_per_ball_rate`] from `(sin, cos)` of the roll and of the pitch, for a
/// caller that has them already (the 3D controller's plane models need them too).
#[inline]
pub(crate) fn ball_body_z_rate_per_ball_rate_sin_cos<T: RealField + Copy>(
    (sin_r, cos_r): (T, T),
    (sin_p, cos_p): (T, T),
) -> [T; 2] {
    let g_z = cos_p * cos_r;
    // Also false for NaN.
    if g_z > lit(0.1) {
        [sin_p / g_z, -sin_r / cos_r]
    } else {
        [T::zero(), T::zero()]
    }
}

/// `angle` moved into (-pi, pi] by one turn at most (enough for the change between two
/// samples; larger jumps are not a heading change a robot can make in one sample).
#[inline]
fn wrap_pi<T: RealField + Copy>(angle: T) -> T {
    if angle > T::pi() {
        angle - T::two_pi()
    } else if angle <= -T::pi() {
        angle + T::two_pi()
    } else {
        angle
    }
}

/// The exact sensor readings of a robot in the planar states `states` at `timestamp_us`: the
/// inverse of [`Estimator::update`] (yaw wrapped into (-pi, pi]). For simulators driving the
/// controller from planar plants, and for tests.
///
/// ```
/// use ballbot_core::estimation::{Estimator, PlanarStates, synthesize_sensors};
/// use ballbot_core::{BallbotParams, OmniKinematics};
/// let kin = OmniKinematics::from_ballbot(&BallbotParams::<f64>::miapure_60kg())?;
/// // Rolling diagonally while leaning and turning.
/// let mut truth = PlanarStates::zeros();
/// truth.sagittal[0] = 0.03;
/// truth.sagittal[3] = 5.0;
/// truth.frontal[2] = -0.2;
/// truth.frontal[3] = -2.0;
/// truth.spin[1] = 0.7;
/// let (imu, enc) = synthesize_sensors(&kin, &truth, 42);
/// assert_eq!((imu.timestamp_us, enc.timestamp_us), (42, 42));
/// // The estimator inverts it: rates and tilts come back.
/// let s = Estimator::new(kin).update(Some(&imu), Some(&enc), 0.0025);
/// let pairs = [
///     (s.sagittal[3], 5.0),
///     (s.frontal[3], -2.0),
///     (s.frontal[2], -0.2),
///     (s.spin[1], 0.7),
/// ];
/// for (got, want) in pairs {
///     approx::assert_relative_eq!(got, want, epsilon = 1e-12);
/// }
/// # Ok::<(), ballbot_core::Error>(())
/// ```
pub fn synthesize_sensors<T: RealField + Copy>(
    kinematics: &OmniKinematics<T>,
    states: &PlanarStates<T>,
    timestamp_us: u64,
) -> (ImuSample<T>, EncoderSample<T>) {
    let (sin, cos) = states.spin[0].sin_cos();
    let imu = ImuSample {
        timestamp_us,
        roll_rad: states.frontal[TILT],
        pitch_rad: states.sagittal[TILT],
        yaw_rad: sin.atan2(cos),
        angular_velocity_rad_per_s: Vector3::new(
            states.frontal[TILT_RATE],
            states.sagittal[TILT_RATE],
            states.spin[1],
        ),
    };
    let rel = relative_rate_from_planar(
        [states.frontal[BALL_RATE], states.sagittal[BALL_RATE]],
        [states.frontal[TILT_RATE], states.sagittal[TILT_RATE]],
        states.spin[1],
    );
    let enc = EncoderSample {
        timestamp_us,
        wheel_speeds_rad_per_s: kinematics.wheel_speeds_rad_per_s(&rel),
    };
    (imu, enc)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::BallbotParams;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    fn kin() -> OmniKinematics<f64> {
        OmniKinematics::from_ballbot(&BallbotParams::miapure_60kg()).unwrap()
    }

    fn states(v: [f64; 10]) -> PlanarStates<f64> {
        PlanarStates {
            sagittal: WipState::new(v[0], v[1], v[2], v[3]),
            frontal: WipState::new(v[4], v[5], v[6], v[7]),
            spin: SpinState::new(v[8], v[9]),
        }
    }

    proptest! {
        #[test]
        fn estimation_inverts_the_sensor_model_exactly(
            tilt in prop::array::uniform2(-0.3f64..0.3),
            tilt_rate in prop::array::uniform2(-3.0f64..3.0),
            ball_rate in prop::array::uniform2(-20.0f64..20.0),
            heading in -3.1f64..3.1,
            yaw_rate in -3.0f64..3.0,
        ) {
            let truth = states([
                tilt[0], 0.0, tilt_rate[0], ball_rate[0],
                tilt[1], 0.0, tilt_rate[1], ball_rate[1],
                heading, yaw_rate,
            ]);
            let (imu, enc) = synthesize_sensors(&kin(), &truth, 0);
            let mut est = Estimator::new(kin());
            let s = est.update(Some(&imu), Some(&enc), 0.0);
            for (a, b) in [(s.sagittal, truth.sagittal), (s.frontal, truth.frontal)] {
                for i in 0..4 {
                    prop_assert!((a[i] - b[i]).abs() <= 1e-12 * (1.0 + b[i].abs()));
                }
            }
            prop_assert!((s.spin - truth.spin).amax() <= 1e-12);
        }
    }

    #[test]
    fn pure_sagittal_travel_reads_only_wheels_two_and_three() {
        let mut truth = PlanarStates::zeros();
        truth.sagittal[BALL_RATE] = 5.0;
        let (_, enc) = synthesize_sensors(&kin(), &truth, 0);
        assert!(enc.wheel_speeds_rad_per_s[0].abs() < 1e-12);
        assert_relative_eq!(
            enc.wheel_speeds_rad_per_s[1],
            -enc.wheel_speeds_rad_per_s[2],
            epsilon = 1e-12
        );
    }

    #[test]
    fn heading_is_unwrapped_across_pi() {
        let mut est = Estimator::new(kin());
        let mut truth = PlanarStates::zeros();
        // Spin through two and a half turns in 0.1 rad steps.
        for k in 0..160 {
            truth.spin[0] = 3.0 + 0.1 * k as f64;
            let (imu, enc) = synthesize_sensors(&kin(), &truth, k);
            assert!(imu.yaw_rad.abs() <= core::f64::consts::PI);
            let s = est.update(Some(&imu), Some(&enc), 0.0025);
            assert_relative_eq!(s.spin[0], truth.spin[0], epsilon = 1e-9);
        }
        // Backwards too.
        for k in 0..160 {
            truth.spin[0] -= 0.1;
            let (imu, enc) = synthesize_sensors(&kin(), &truth, 200 + k);
            let s = est.update(Some(&imu), Some(&enc), 0.0025);
            assert_relative_eq!(s.spin[0], truth.spin[0], epsilon = 1e-9);
        }
    }

    #[test]
    fn ball_angles_integrate_the_ball_rates() {
        let mut est = Estimator::new(kin());
        let mut truth = PlanarStates::zeros();
        truth.sagittal[BALL_RATE] = 2.0;
        truth.frontal[BALL_RATE] = -1.0;
        let (imu, enc) = synthesize_sensors(&kin(), &truth, 0);
        // The first update jumps from rest to the rate (trapezoid: half a step's worth).
        est.update(Some(&imu), Some(&enc), 0.01);
        for _ in 0..100 {
            est.update(Some(&imu), Some(&enc), 0.01);
        }
        let s = est.states();
        assert_relative_eq!(s.sagittal[BALL_ANGLE], 2.0 * 1.005, epsilon = 1e-9);
        assert_relative_eq!(s.frontal[BALL_ANGLE], -1.005, epsilon = 1e-9);
    }

    #[test]
    fn missing_and_non_finite_samples_hold_the_last_estimate() {
        let mut est = Estimator::new(kin());
        let truth = states([0.05, 0.0, 0.1, 3.0, -0.02, 0.0, 0.2, -1.0, 0.5, 0.3]);
        let (imu, enc) = synthesize_sensors(&kin(), &truth, 0);
        let good = est.update(Some(&imu), Some(&enc), 0.0);
        let mut bad_imu = imu;
        bad_imu.pitch_rad = f64::NAN;
        let mut bad_enc = enc;
        bad_enc.wheel_speeds_rad_per_s[1] = f64::INFINITY;
        assert_eq!(est.update(Some(&bad_imu), Some(&bad_enc), 0.0), good);
        assert_eq!(est.update(None, None, f64::NAN), good);
        assert!(est.states().is_finite());
        est.reset();
        assert_eq!(*est.states(), PlanarStates::zeros());
    }

    #[test]
    fn quaternion_input_matches_euler_input() {
        let q = UnitQuaternion::from_euler_angles(-0.07, 0.11, -2.5);
        let imu = ImuSample::from_quaternion(3, &(q.quaternion() * 2.0), Vector3::zeros());
        assert_relative_eq!(imu.roll_rad, -0.07, epsilon = 1e-12);
        assert_relative_eq!(imu.pitch_rad, 0.11, epsilon = 1e-12);
        assert_relative_eq!(imu.yaw_rad, -2.5, epsilon = 1e-12);
        let zero =
            ImuSample::from_quaternion(3, &Quaternion::new(0.0, 0.0, 0.0, 0.0), Vector3::zeros());
        assert!(!zero.is_finite());
    }

    proptest! {
        #[test]
        fn ball_body_z_rate_keeps_the_rolling_ball_off_the_vertical(
            roll in -0.6f64..0.6,
            pitch in -0.6f64..0.6,
            rate in prop::array::uniform2(-50.0f64..50.0),
        ) {
            // A ball rolling about a horizontal world axis, seen from the body: its body-z
            // rate is k . its body-x, body-y rates.
            let body = UnitQuaternion::from_euler_angles(roll, pitch, 0.7);
            let world = Vector3::new(rate[0], rate[1], 0.0);
            let seen = body.inverse() * world;
            let k = ball_body_z_rate_per_ball_rate(roll, pitch);
            let z = k[0] * seen.x + k[1] * seen.y;
            prop_assert!((z - seen.z).abs() <= 1e-12 * (1.0 + world.norm()), "{z} vs {}", seen.z);
        }
    }

    #[test]
    fn ball_body_z_rate_is_zero_when_fallen_or_not_finite() {
        assert_eq!(ball_body_z_rate_per_ball_rate(1.5, 0.0), [0.0, 0.0]);
        assert_eq!(ball_body_z_rate_per_ball_rate(0.0, -1.5), [0.0, 0.0]);
        assert_eq!(ball_body_z_rate_per_ball_rate(f64::NAN, 0.1), [0.0, 0.0]);
    }

    #[test]
    fn positive_pitch_leans_towards_plus_x_and_positive_roll_towards_minus_y() {
        // The body z axis in the world for a pure pitch and a pure roll.
        let z = Vector3::<f64>::z();
        let pitched = UnitQuaternion::from_euler_angles(0.0, 0.1, 0.0) * z;
        assert!(pitched.x > 0.09 && pitched.y.abs() < 1e-12);
        let rolled = UnitQuaternion::from_euler_angles(0.1, 0.0, 0.0) * z;
        assert!(rolled.y < -0.09 && rolled.x.abs() < 1e-12);
    }
}
