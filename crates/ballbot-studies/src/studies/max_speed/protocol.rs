//! The protocol of the maximum-speed study: the ramps, the search's bracket and grid, the
//! command shaper's limits, which headings and variants run, and the paper's values.

use crate::studies::driver::Bisection;
use crate::studies::ramp::RampParams;
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_world::world::WorldError;

/// The command-shaper limits used by the study instead of the core's defaults.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShaperLimits {
    /// Speed cap of each translation axis (m/s). Default 8 (above any ramp's top).
    pub max_speed_m_per_s: f64,
    /// Acceleration cap (m/s^2). Default 20 (above any ramp's acceleration).
    pub max_accel_m_per_s2: f64,
    /// Largest tilt command (rad). Default 0.5.
    pub max_tilt_command_rad: f64,
    /// Largest tilt-rate command (rad/s). Default 5.
    pub max_tilt_rate_command_rad_per_s: f64,
}

impl Default for ShaperLimits {
    fn default() -> Self {
        Self {
            max_speed_m_per_s: 8.0,
            max_accel_m_per_s2: 20.0,
            max_tilt_command_rad: 0.5,
            max_tilt_rate_command_rad_per_s: 5.0,
        }
    }
}

impl ShaperLimits {
    /// Writes these limits into a controller configuration (the jerk limit stays).
    pub fn apply(&self, config: &mut BallbotControllerConfig<f64>) {
        config.shaping.translation.max_value = self.max_speed_m_per_s;
        config.shaping.translation.max_rate_per_s = self.max_accel_m_per_s2;
        config.shaping.max_tilt_command_rad = self.max_tilt_command_rad;
        config.shaping.max_tilt_rate_command_rad_per_s = self.max_tilt_rate_command_rad_per_s;
    }
}

/// The protocol of one run of each metric.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaxSpeedProtocol {
    /// The slow ramp (maximum-speed metric). Default 0.25 m/s^2 to 6 m/s after 0.5 s at
    /// rest, samples every 10 ms (6 m/s: near the actuators' no-load speed, far above the
    /// paper's 2.3 m/s, so that the ramp's end rarely censors the result).
    pub slow_ramp: RampParams,
    /// Top speed of the ramps of the failing-acceleration search (m/s). Default 3.
    pub fast_top_m_per_s: f64,
    /// Searched accelerations (m/s^2), `[low, high]`. Default `[0.5, 3.0]`: with the core's
    /// jerk limit `j` (2 m/s^3) the shaped command of a ramp to the top speed `v` cannot
    /// accelerate faster than `sqrt(j v)` (2.45 m/s^2 to 3 m/s; the acceleration rises and
    /// falls at the jerk limit), so steeper ramps all give the same command.
    pub accel_bracket_m_per_s2: [f64; 2],
    /// Grid of the searched accelerations (m/s^2). Default 0.05.
    pub accel_resolution_m_per_s2: f64,
    /// Command-shaper limits.
    pub shaper: ShaperLimits,
}

impl MaxSpeedProtocol {
    /// Finest grid of the failing-acceleration search (m/s^2): finer grids only add runs
    /// (the bisection needs `log2((high - low) / resolution)` of them) and would overflow the
    /// integer grid for a zero resolution.
    pub const MIN_ACCEL_RESOLUTION_M_PER_S2: f64 = 1e-6;

    /// Checks the search bracket, its grid and the fast ramps' top speed (the slow ramp is
    /// checked by the run itself).
    ///
    /// ```
    /// use ballbot_studies::studies::max_speed::MaxSpeedProtocol;
    /// assert!(MaxSpeedProtocol::default().validate().is_ok());
    /// let bad = MaxSpeedProtocol { accel_resolution_m_per_s2: 0.0, ..Default::default() };
    /// let err = bad.validate().err().map(|e| e.to_string()).unwrap_or_default();
    /// assert!(err.contains("accel_resolution_m_per_s2"), "{err}");
    /// ```
    pub fn validate(&self) -> Result<(), WorldError> {
        let [low, high] = self.accel_bracket_m_per_s2;
        let invalid = |field, requirement| Err(WorldError::InvalidParameter { field, requirement });
        if !(self.accel_resolution_m_per_s2 >= Self::MIN_ACCEL_RESOLUTION_M_PER_S2
            && self.accel_resolution_m_per_s2.is_finite())
        {
            return invalid(
                "protocol.accel_resolution_m_per_s2",
                "must be finite and >= 1e-6 m/s^2",
            );
        }
        if !(low > 0.0 && high > low && high.is_finite()) {
            return invalid(
                "protocol.accel_bracket_m_per_s2",
                "need 0 < low < high < inf",
            );
        }
        if !(self.fast_top_m_per_s.is_finite() && self.fast_top_m_per_s > 0.0) {
            return invalid("protocol.fast_top_m_per_s", "must be finite and > 0");
        }
        Ok(())
    }

    /// The failing-acceleration search as the driver's grid bisection: the bracket's ends
    /// rounded to the grid of [`Self::accel_resolution_m_per_s2`] (the low end at least one
    /// step, the high end at least one step above it), both tried, the low one first.
    ///
    /// ```
    /// use ballbot_studies::studies::max_speed::MaxSpeedProtocol;
    /// let s = MaxSpeedProtocol::default().accel_search();
    /// assert_eq!((s.passing, s.failing, s.resolution), (0.5, 3.0, 0.05));
    /// assert!(s.try_passing && s.on_grid);
    /// ```
    pub fn accel_search(&self) -> Bisection {
        let res = self.accel_resolution_m_per_s2;
        let [low, high] = self.accel_bracket_m_per_s2;
        let lo = ((low / res).round() as i64).max(1);
        let hi = ((high / res).round() as i64).max(lo + 1);
        // On the grid, without the product's rounding noise (1.95, not 1.9500000000000002).
        let at = |k: i64| (k as f64 * res * 1e9).round() / 1e9;
        Bisection::grid(at(lo), at(hi), res)
    }
}

impl Default for MaxSpeedProtocol {
    fn default() -> Self {
        Self {
            slow_ramp: RampParams {
                accel_m_per_s2: 0.25,
                max_command_m_per_s: 6.0,
                settle_secs: 0.5,
                sample_every_secs: 0.01,
            },
            fast_top_m_per_s: 3.0,
            accel_bracket_m_per_s2: [0.5, 3.0],
            accel_resolution_m_per_s2: 0.05,
            shaper: ShaperLimits::default(),
        }
    }
}

/// Which headings and variants the study runs.
#[derive(Clone, Debug, PartialEq)]
pub struct MaxSpeedStudySettings {
    /// Run protocol.
    pub protocol: MaxSpeedProtocol,
    /// Headings with seeded slow-ramp trials (deg, body frame, 0 towards OW1). Default
    /// 0, 90, 180 (the paper's).
    pub trial_headings_deg: Vec<f64>,
    /// Seeds of the trials (one trial per seed). Default 1, 2, 3.
    pub seeds: Vec<u64>,
    /// Headings of the capability map (deg): one slow ramp (first seed) and one
    /// failing-acceleration search each. Default every 15 deg from 0 to 345.
    pub map_headings_deg: Vec<f64>,
    /// Headings of the sensitivity study (deg). Default 0 and 180.
    pub sensitivity_headings_deg: Vec<f64>,
    /// Roller-ball friction coefficients of the sensitivity study. Default 0.4, 0.6, 0.8.
    pub sensitivity_wheel_ball_friction: Vec<f64>,
    /// COM heights of the sensitivity study (m). Default 0.4, 0.5, 0.7.
    pub sensitivity_com_height_m: Vec<f64>,
    /// Worker threads; 0 uses every available core. Default 0.
    pub threads: usize,
}

impl MaxSpeedStudySettings {
    /// The full study (about 250 runs; a minute or two in a release build on two cores).
    pub fn paper() -> Self {
        Self {
            protocol: MaxSpeedProtocol::default(),
            trial_headings_deg: vec![0.0, 90.0, 180.0],
            seeds: vec![1, 2, 3],
            map_headings_deg: (0..24).map(|i| f64::from(i) * 15.0).collect(),
            sensitivity_headings_deg: vec![0.0, 180.0],
            sensitivity_wheel_ball_friction: vec![0.4, 0.6, 0.8],
            sensitivity_com_height_m: vec![0.4, 0.5, 0.7],
            threads: 0,
        }
    }

    /// The CI smoke variant: one trial at 0 and 180 deg with a short fast ramp (1 m/s^2 to
    /// 3 m/s) in place of the slow one, the search on a 0.2 m/s^2 grid between 1.0 and
    /// 3.0 m/s^2, no further map headings, no sensitivity.
    pub fn quick() -> Self {
        let defaults = MaxSpeedProtocol::default();
        let protocol = MaxSpeedProtocol {
            slow_ramp: RampParams {
                accel_m_per_s2: 1.0,
                max_command_m_per_s: 3.0,
                ..defaults.slow_ramp
            },
            accel_bracket_m_per_s2: [1.0, 3.0],
            accel_resolution_m_per_s2: 0.2,
            ..defaults
        };
        Self {
            protocol,
            trial_headings_deg: vec![0.0, 180.0],
            seeds: vec![1],
            map_headings_deg: vec![0.0, 180.0],
            sensitivity_headings_deg: Vec::new(),
            sensitivity_wheel_ball_friction: Vec::new(),
            sensitivity_com_height_m: Vec::new(),
            threads: 0,
        }
    }

    pub(super) fn validate(&self) -> Result<(), WorldError> {
        self.protocol.validate()?;
        let invalid = |field, requirement| Err(WorldError::InvalidParameter { field, requirement });
        if self.seeds.is_empty() {
            return invalid("seeds", "need at least one seed");
        }
        let positive = |x: &f64| x.is_finite() && *x > 0.0;
        if !self.sensitivity_wheel_ball_friction.iter().all(positive)
            || !self.sensitivity_com_height_m.iter().all(positive)
        {
            return invalid("sensitivity", "mu and COM heights must be > 0");
        }
        Ok(())
    }
}

/// A value the paper reports for MiaPURE's maximum speed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PaperMaxSpeed {
    /// Heading (deg).
    pub heading_deg: f64,
    /// Speed (m/s).
    pub speed_m_per_s: f64,
    /// Whether the paper gives only an upper bound ("less than").
    pub upper_bound: bool,
}

/// The paper's numbers (Sec. V, Fig. "acc"): below 0.6 m/s at 0 deg, 2.3 m/s at 180 deg; at
/// 90 deg it reports no number ("in between").
pub const PAPER_MAX_SPEED: [PaperMaxSpeed; 2] = [
    PaperMaxSpeed {
        heading_deg: 0.0,
        speed_m_per_s: 0.6,
        upper_bound: true,
    },
    PaperMaxSpeed {
        heading_deg: 180.0,
        speed_m_per_s: 2.3,
        upper_bound: false,
    },
];
