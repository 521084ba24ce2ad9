//! The observation: what the robot's own sensors give, bounded as the sensors saturate.
//!
//! | index | entry | unit | bound |
//! |---|---|---|---|
//! | 0, 1 | IMU roll, pitch | rad | +-pi/2 |
//! | 2 | IMU yaw | rad | +-pi |
//! | 3..6 | gyro, body frame | rad/s | +-34.9 (the BMI088's +-2000 deg/s range) |
//! | 6..9 | wheel speeds (encoders) | rad/s | +-2 no-load speed |
//! | 9..12 | command `vx, vy, yaw rate` | m/s, rad/s | the command ranges |
//! | 12..15 | last action (optional) | 1 | +-1 |
//!
//! Values outside a bound are clipped to it (a saturated sensor), so every observation lies in
//! its box.

use super::config::EnvConfig;
use ballbot_world::world::Measurement;

/// The gyro's measuring range (rad/s): the BMI088's +-2000 deg/s.
pub const GYRO_RANGE_RAD_PER_S: f64 = 2000.0 * core::f64::consts::PI / 180.0;

/// Length of the observation without (12) and with (15) the last action.
///
/// ```
/// use ballbot_gym::{EnvConfig, Task, observation_len};
/// let mut config = EnvConfig::new(Task::Balance);
/// assert_eq!(observation_len(&config), 12);
/// config.last_action_in_observation = true;
/// assert_eq!(observation_len(&config), 15);
/// ```
pub fn observation_len(config: &EnvConfig) -> usize {
    if config.last_action_in_observation {
        15
    } else {
        12
    }
}

/// The observation box's upper bounds (the lower ones are their negatives).
pub fn observation_high(config: &EnvConfig) -> Vec<f32> {
    let half_pi = core::f64::consts::FRAC_PI_2;
    let wheel = 2.0
        * config
            .world
            .robot
            .drivetrain
            .actuator
            .no_load_speed_rad_per_s;
    let c = &config.commands;
    let mut high = vec![
        half_pi,
        half_pi,
        core::f64::consts::PI,
        GYRO_RANGE_RAD_PER_S,
        GYRO_RANGE_RAD_PER_S,
        GYRO_RANGE_RAD_PER_S,
        wheel,
        wheel,
        wheel,
        c.max_speed_m_per_s,
        c.max_speed_m_per_s,
        c.max_yaw_rate_rad_per_s,
    ];
    if config.last_action_in_observation {
        high.extend([1.0; 3]);
    }
    high.into_iter().map(|x| x as f32).collect()
}

/// Writes the observation of measurement `m` into `out` (length [`observation_len`]),
/// clipped to `high`.
pub(crate) fn observe(
    out: &mut [f32],
    high: &[f32],
    m: &Measurement,
    command: [f64; 3],
    last_action: [f64; 3],
) {
    let values = [
        m.tilt_rad[0],
        m.tilt_rad[1],
        m.yaw_rad,
        m.body_rate_rad_per_s[0],
        m.body_rate_rad_per_s[1],
        m.body_rate_rad_per_s[2],
        m.wheel_speed_rad_per_s[0],
        m.wheel_speed_rad_per_s[1],
        m.wheel_speed_rad_per_s[2],
        command[0],
        command[1],
        command[2],
        last_action[0],
        last_action[1],
        last_action[2],
    ];
    for ((o, &v), &h) in out.iter_mut().zip(values.iter()).zip(high) {
        // A non-finite reading (none is expected from the world) reads as zero.
        let v = if v.is_finite() { v as f32 } else { 0.0 };
        *o = v.clamp(-h, h);
    }
}
