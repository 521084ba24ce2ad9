//! Domain randomisation: [`Randomization`] (the ranges) and [`EpisodeDraw`] (one episode's
//! values, drawn from the episode's seed).
//!
//! Every value is uniform in its range; a field left `None` keeps the nominal world's value.
//! [`Randomization::recommended`] holds the ranges of the reliability campaign's Monte Carlo:
//! +-20 % around MiaPURE's payload, COM height, roller friction, drive friction and IMU noise,
//! chosen before any training.

use super::error::GymError;
use ballbot_world::world::WorldParams;
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use rand_distr::{Distribution, Uniform};
use serde::{Deserialize, Serialize};

/// Longest sensor delay (s): 50 ms, twice the supervisor's stale-sample limit.
pub const MAX_SENSOR_DELAY_SECS: f64 = 0.05;

/// A closed interval `[lo, hi]`; a single number `x` is `[x, x]` (a fixed value).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(from = "RangeRepr", into = "[f64; 2]")]
pub struct Range {
    /// Lower end.
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum RangeRepr {
    Fixed(f64),
    Pair([f64; 2]),
}

impl From<RangeRepr> for Range {
    fn from(r: RangeRepr) -> Self {
        match r {
            RangeRepr::Fixed(x) => Self { lo: x, hi: x },
            RangeRepr::Pair([lo, hi]) => Self { lo, hi },
        }
    }
}

impl From<Range> for [f64; 2] {
    fn from(r: Range) -> Self {
        [r.lo, r.hi]
    }
}

impl From<f64> for Range {
    fn from(x: f64) -> Self {
        Self { lo: x, hi: x }
    }
}

impl From<(f64, f64)> for Range {
    fn from((lo, hi): (f64, f64)) -> Self {
        Self { lo, hi }
    }
}

impl Range {
    /// A value uniform in the range (the lower end when it is a single value).
    pub fn sample(&self, rng: &mut ChaCha8Rng) -> f64 {
        if self.hi > self.lo {
            Uniform::new_inclusive(self.lo, self.hi).map_or(self.lo, |u| u.sample(rng))
        } else {
            self.lo
        }
    }

    fn check(&self, field: &str, min: f64, max: f64) -> Result<(), GymError> {
        let text = format!("[{}, {}]", self.lo, self.hi);
        if !(self.lo.is_finite() && self.hi.is_finite() && self.lo <= self.hi) {
            return Err(GymError::invalid(
                field,
                "must be a finite range [lo, hi] with lo <= hi",
                text,
            ));
        }
        if self.lo < min || self.hi > max {
            return Err(GymError::invalid(field, "is outside its bounds", text));
        }
        Ok(())
    }
}

/// The ranges one episode's values are drawn from.
///
/// ```
/// use ballbot_gym::{EpisodeDraw, Randomization};
/// use ballbot_world::world::WorldParams;
/// let ranges = Randomization::recommended();
/// let world = WorldParams::miapure_60kg();
/// ranges.validate(&world)?;
/// let a = EpisodeDraw::sample(7, &ranges);
/// assert_eq!(a, EpisodeDraw::sample(7, &ranges));
/// let p = a.apply(&world);
/// assert!((p.robot.sagittal.body_mass_kg - world.robot.sagittal.body_mass_kg).abs() <= 12.0);
/// # Ok::<(), ballbot_gym::GymError>(())
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Randomization {
    /// Mass added to the body (kg; negative removes payload), on both planes.
    pub added_payload_kg: Option<Range>,
    /// The COM height above the ball centre (m), both planes.
    pub com_height_m: Option<Range>,
    /// The omniwheel-ball ("roller") friction coefficient mu.
    pub wheel_ball_friction: Option<Range>,
    /// The drive friction: each wheel's viscous damping (N m s/rad).
    pub wheel_damping_nm_s_per_rad: Option<Range>,
    /// Factor on the IMU noise (tilt and gyro standard deviations).
    pub imu_noise_factor: Option<Range>,
    /// Sensor delay (s, at most [`MAX_SENSOR_DELAY_SECS`]), rounded to physics steps: the
    /// observation, and in the `Velocity` task the controller's IMU and encoder samples, are
    /// this old.
    pub sensor_delay_secs: Option<Range>,
    /// The initial tilt from the vertical (rad, below the failure tilt), at a uniform direction.
    pub initial_tilt_rad: Option<Range>,
    /// Push disturbances: each push's impulse at the body's centre of mass (N s), horizontal,
    /// at a uniform direction.
    pub push_impulse_ns: Option<Range>,
    /// Time between pushes (s); the first push comes one interval after the start. Pushes need
    /// both this and `push_impulse_ns`.
    pub push_interval_secs: Option<Range>,
}

impl Randomization {
    /// The reliability campaign's Monte Carlo ranges, fixed before any training: +-20 % on
    /// MiaPURE's 60 kg payload (+-12 kg) and on its nominal COM height, roller friction, drive
    /// friction and IMU noise; a
    /// sensor delay of 0 to 5 ms (an assumption: a 2.5 ms outer period plus filter lag); and
    /// pushes of 0 to 20 N s (half the Monte Carlo's 40 N s test push) every 2 to 5 s. The
    /// initial tilt is left to the task ([`crate::EnvConfig::new`]).
    pub fn recommended() -> Self {
        let nominal = WorldParams::miapure_60kg();
        let scale = |x: f64| Some(Range::from((0.8 * x, 1.2 * x)));
        Self {
            added_payload_kg: Some((-12.0, 12.0).into()),
            com_height_m: scale(nominal.robot.sagittal.com_height_m),
            wheel_ball_friction: scale(nominal.robot.drivetrain.wheel_ball_friction),
            wheel_damping_nm_s_per_rad: scale(nominal.wheel_damping_nm_s_per_rad),
            imu_noise_factor: Some((0.8, 1.2).into()),
            sensor_delay_secs: Some((0.0, 0.005).into()),
            initial_tilt_rad: None,
            push_impulse_ns: Some((0.0, 20.0).into()),
            push_interval_secs: Some((2.0, 5.0).into()),
        }
    }

    /// `self` with every range `overrides` sets replaced.
    pub fn merged(&self, overrides: &Self) -> Self {
        let pick = |a: Option<Range>, b: Option<Range>| b.or(a);
        Self {
            added_payload_kg: pick(self.added_payload_kg, overrides.added_payload_kg),
            com_height_m: pick(self.com_height_m, overrides.com_height_m),
            wheel_ball_friction: pick(self.wheel_ball_friction, overrides.wheel_ball_friction),
            wheel_damping_nm_s_per_rad: pick(
                self.wheel_damping_nm_s_per_rad,
                overrides.wheel_damping_nm_s_per_rad,
            ),
            imu_noise_factor: pick(self.imu_noise_factor, overrides.imu_noise_factor),
            sensor_delay_secs: pick(self.sensor_delay_secs, overrides.sensor_delay_secs),
            initial_tilt_rad: pick(self.initial_tilt_rad, overrides.initial_tilt_rad),
            push_impulse_ns: pick(self.push_impulse_ns, overrides.push_impulse_ns),
            push_interval_secs: pick(self.push_interval_secs, overrides.push_interval_secs),
        }
    }

    /// Checks every range; the worlds at both ends of the ranges must be valid.
    pub fn validate(&self, world: &WorldParams) -> Result<(), GymError> {
        let inf = f64::INFINITY;
        let checks = [
            (
                "randomization.added_payload_kg",
                self.added_payload_kg,
                -inf,
            ),
            ("randomization.com_height_m", self.com_height_m, 0.0),
            (
                "randomization.wheel_ball_friction",
                self.wheel_ball_friction,
                0.0,
            ),
            (
                "randomization.wheel_damping_nm_s_per_rad",
                self.wheel_damping_nm_s_per_rad,
                0.0,
            ),
            ("randomization.imu_noise_factor", self.imu_noise_factor, 0.0),
            ("randomization.push_impulse_ns", self.push_impulse_ns, 0.0),
        ];
        for (field, range, min) in checks {
            if let Some(r) = range {
                r.check(field, min, inf)?;
            }
        }
        if let Some(r) = self.sensor_delay_secs {
            r.check(
                "randomization.sensor_delay_secs",
                0.0,
                MAX_SENSOR_DELAY_SECS,
            )?;
        }
        if let Some(r) = self.initial_tilt_rad {
            let max = world.failure.max_tilt_rad;
            r.check("randomization.initial_tilt_rad", 0.0, max)?;
            if r.hi >= max {
                return Err(GymError::invalid(
                    "randomization.initial_tilt_rad",
                    "must stay below world.failure.max_tilt_rad",
                    r.hi,
                ));
            }
        }
        if let Some(r) = self.push_interval_secs {
            r.check("randomization.push_interval_secs", 0.0, inf)?;
            if r.lo <= 0.0 {
                return Err(GymError::invalid(
                    "randomization.push_interval_secs",
                    "must be > 0",
                    r.lo,
                ));
            }
        }
        if let Some(r) = self.added_payload_kg {
            let body = world
                .robot
                .sagittal
                .body_mass_kg
                .min(world.robot.frontal.body_mass_kg);
            if body + r.lo <= 0.0 {
                return Err(GymError::invalid(
                    "randomization.added_payload_kg",
                    "must leave a positive body mass",
                    r.lo,
                ));
            }
        }
        for end in [false, true] {
            let draw = EpisodeDraw::at_end(self, end);
            draw.apply(world).validate()?;
        }
        Ok(())
    }
}

/// One episode's drawn values (nominal where the range is `None`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct EpisodeDraw {
    /// The episode's seed: it seeds these draws, the sensors' noise, the commands and pushes.
    pub seed: u64,
    /// Mass added to the body (kg).
    pub added_payload_kg: f64,
    /// COM height (m), `None`: nominal.
    pub com_height_m: Option<f64>,
    /// Roller friction, `None`: nominal.
    pub wheel_ball_friction: Option<f64>,
    /// Drive friction (N m s/rad), `None`: nominal.
    pub wheel_damping_nm_s_per_rad: Option<f64>,
    /// Factor on the IMU noise.
    pub imu_noise_factor: f64,
    /// Sensor delay (s).
    pub sensor_delay_secs: f64,
    /// Initial tilt `[about x, about y]` (rad).
    pub initial_tilt_rad: [f64; 2],
}

impl EpisodeDraw {
    /// The values of the episode seeded `seed` (always drawn in the same order, so adding a
    /// range does not change the others' draws).
    pub fn sample(seed: u64, ranges: &Randomization) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut draw = |r: Option<Range>| {
            // Draw even when unused, so that each field has its own place in the stream.
            let u = Range::from((0.0, 1.0)).sample(&mut rng);
            r.map(|r| r.lo + u * (r.hi - r.lo))
        };
        let added_payload_kg = draw(ranges.added_payload_kg).unwrap_or(0.0);
        let com_height_m = draw(ranges.com_height_m);
        let wheel_ball_friction = draw(ranges.wheel_ball_friction);
        let wheel_damping_nm_s_per_rad = draw(ranges.wheel_damping_nm_s_per_rad);
        let imu_noise_factor = draw(ranges.imu_noise_factor).unwrap_or(1.0);
        let sensor_delay_secs = draw(ranges.sensor_delay_secs).unwrap_or(0.0);
        let tilt = draw(ranges.initial_tilt_rad).unwrap_or(0.0);
        let direction = draw(Some((0.0, core::f64::consts::TAU).into())).unwrap_or(0.0);
        Self {
            seed,
            added_payload_kg,
            com_height_m,
            wheel_ball_friction,
            wheel_damping_nm_s_per_rad,
            imu_noise_factor,
            sensor_delay_secs,
            initial_tilt_rad: [tilt * direction.sin(), tilt * direction.cos()],
        }
    }

    /// Every range at its lower (`hi = false`) or upper end: the extremes `validate` checks.
    fn at_end(ranges: &Randomization, hi: bool) -> Self {
        let end = |r: Option<Range>| r.map(|r| if hi { r.hi } else { r.lo });
        Self {
            seed: 0,
            added_payload_kg: end(ranges.added_payload_kg).unwrap_or(0.0),
            com_height_m: end(ranges.com_height_m),
            wheel_ball_friction: end(ranges.wheel_ball_friction),
            wheel_damping_nm_s_per_rad: end(ranges.wheel_damping_nm_s_per_rad),
            imu_noise_factor: end(ranges.imu_noise_factor).unwrap_or(1.0),
            sensor_delay_secs: end(ranges.sensor_delay_secs).unwrap_or(0.0),
            initial_tilt_rad: [0.0, end(ranges.initial_tilt_rad).unwrap_or(0.0)],
        }
    }

    /// `nominal` with these values; the sensors are seeded with the episode's seed.
    pub fn apply(&self, nominal: &WorldParams) -> WorldParams {
        let mut w = *nominal;
        for plane in [&mut w.robot.sagittal, &mut w.robot.frontal] {
            plane.body_mass_kg += self.added_payload_kg;
            if let Some(h) = self.com_height_m {
                plane.com_height_m = h;
            }
        }
        if let Some(mu) = self.wheel_ball_friction {
            w.robot.drivetrain.wheel_ball_friction = mu;
        }
        if let Some(d) = self.wheel_damping_nm_s_per_rad {
            w.wheel_damping_nm_s_per_rad = d;
        }
        w.sensors.tilt_noise_rad *= self.imu_noise_factor;
        w.sensors.gyro_noise_rad_per_s *= self.imu_noise_factor;
        w.sensors.seed = self.seed;
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_lie_in_their_ranges_and_depend_on_the_seed() {
        let ranges = Randomization::recommended();
        let draws: Vec<_> = (0..200).map(|s| EpisodeDraw::sample(s, &ranges)).collect();
        for d in &draws {
            assert!((-12.0..=12.0).contains(&d.added_payload_kg));
            assert!((0.0..=0.005).contains(&d.sensor_delay_secs));
            assert_eq!(d.initial_tilt_rad, [0.0; 2]);
        }
        let mean = draws.iter().map(|d| d.added_payload_kg).sum::<f64>() / 200.0;
        assert!(mean.abs() < 2.0, "payload draws centred on 0, mean {mean}");
        assert_ne!(draws[0], draws[1]);
    }

    #[test]
    fn bad_ranges_name_the_field() {
        let world = WorldParams::miapure_60kg();
        let bad = Randomization {
            com_height_m: Some((0.5, 0.4).into()),
            ..Randomization::default()
        };
        let e = bad.validate(&world).unwrap_err().to_string();
        assert!(e.contains("randomization.com_height_m"), "{e}");
        let bad = Randomization {
            added_payload_kg: Some((-100.0, 0.0).into()),
            ..Randomization::default()
        };
        let e = bad.validate(&world).unwrap_err().to_string();
        assert!(e.contains("added_payload_kg"), "{e}");
        let bad = Randomization {
            sensor_delay_secs: Some((0.0, 0.2).into()),
            ..Randomization::default()
        };
        assert!(bad.validate(&world).is_err());
    }

    #[test]
    fn a_number_is_a_fixed_range_and_unknown_keys_are_rejected() {
        let r: Randomization =
            serde_json::from_str(r#"{"com_height_m": 0.5, "wheel_ball_friction": [0.5, 0.9]}"#)
                .unwrap();
        assert_eq!(r.com_height_m, Some((0.5, 0.5).into()));
        assert_eq!(r.wheel_ball_friction, Some((0.5, 0.9).into()));
        let e = serde_json::from_str::<Randomization>(r#"{"mu": 0.5}"#).unwrap_err();
        assert!(e.to_string().contains("unknown field `mu`"), "{e}");
    }
}
