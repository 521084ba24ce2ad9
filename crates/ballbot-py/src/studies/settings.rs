//! The settings of the paper's studies as the study functions take them: one struct per
//! settings class of `ballbot._settings` (generated from their schemas, [`crate::mirror`]).
//!
//! Each study function builds its struct from its keyword arguments (a struct literal, so a
//! keyword the struct lacks, or a field no keyword fills, does not compile) and applies it to
//! the Rust protocol. `None` keeps the protocol's own value. The Python classes check each
//! field as `x-python-check` names (`_settings_base.py`); the range checks that depend on
//! other fields stay with the Rust protocol.

use schemars::JsonSchema;
use serde::Serialize;

/// Settings of the maximum-speed study (`ballbot_sim::studies::max_speed`); the lists are
/// stored as tuples.
#[derive(Clone, Debug, Default, PartialEq, Serialize, JsonSchema)]
#[serde(default)]
#[schemars(rename = "MaxSpeedSettings", extend("x-python-settings" = true))]
pub(crate) struct MaxSpeedSettings {
    /// Start from the CI variant (one trial at 0 and 180 deg, a coarse search, no sensitivity)
    /// instead of the paper's (3 seeds at 0, 90, 180 deg, the map every 15 deg, mu 0.4/0.6/0.8,
    /// COM height 0.4/0.5/0.7 m).
    pub quick: bool,
    /// Headings of the seeded slow-ramp trials (deg, body frame; 0 towards OW1).
    #[schemars(extend("x-python-type" = "Sequence[float]", "x-python-check" = "numbers"))]
    pub trial_headings_deg: Option<Vec<f64>>,
    /// Sensor-noise seeds of the trials (at least one).
    #[schemars(extend("x-python-type" = "Sequence[int]", "x-python-check" = "seeds"))]
    pub seeds: Option<Vec<u64>>,
    /// Headings of the capability map (deg).
    #[schemars(extend("x-python-type" = "Sequence[float]", "x-python-check" = "numbers"))]
    pub map_headings_deg: Option<Vec<f64>>,
    /// Headings of the mu / COM-height sensitivity (deg).
    #[schemars(extend("x-python-type" = "Sequence[float]", "x-python-check" = "numbers"))]
    pub sensitivity_headings_deg: Option<Vec<f64>>,
    /// Wheel-ball friction coefficients of the sensitivity.
    #[schemars(extend("x-python-type" = "Sequence[float]", "x-python-check" = "numbers"))]
    pub sensitivity_wheel_ball_friction: Option<Vec<f64>>,
    /// Centre-of-mass heights of the sensitivity (m).
    #[schemars(extend("x-python-type" = "Sequence[float]", "x-python-check" = "numbers"))]
    pub sensitivity_com_height_m: Option<Vec<f64>>,
    /// Rust worker threads (0: every core).
    #[schemars(extend("x-python-check" = "count_from_0"))]
    pub threads: usize,
    /// Top speed of the fast ramps of the failing-acceleration search (m/s; protocol 3.0).
    #[schemars(extend("x-python-check" = "positive"))]
    pub fast_top_m_per_s: Option<f64>,
    /// Search bracket `(low, high)` of the ramp acceleration (m/s^2; protocol (0.5, 3.0));
    /// needs `0 < low < high`.
    #[schemars(extend("x-python-type" = "tuple[float, float]", "x-python-check" = "bracket"))]
    pub accel_bracket_m_per_s2: Option<(f64, f64)>,
    /// Grid of the search (m/s^2; protocol 0.05).
    #[schemars(extend("x-python-check" = "positive"))]
    pub accel_resolution_m_per_s2: Option<f64>,
}

/// The braking protocol (`ballbot_sim::studies::world_braking::BrakingParams`).
#[derive(Clone, Debug, PartialEq, Serialize, JsonSchema)]
#[serde(default)]
#[schemars(rename = "BrakingSettings", extend("x-python-settings" = true))]
pub(crate) struct BrakingSettings {
    /// Cruise speed before braking (m/s; protocol 1.4, the paper).
    #[schemars(extend("x-python-check" = "positive"))]
    pub cruise_speed_m_per_s: Option<f64>,
    /// Acceleration of the jerk-limited approach ramp (m/s^2; protocol 0.5).
    #[schemars(extend("x-python-check" = "positive"))]
    pub approach_accel_m_per_s2: Option<f64>,
    /// Standing still before the ramp (s; protocol 0.5).
    #[schemars(extend("x-python-check" = "non_negative"))]
    pub settle_secs: Option<f64>,
    /// Cruising before braking (s; protocol 2.5).
    #[schemars(extend("x-python-check" = "non_negative"))]
    pub cruise_secs: Option<f64>,
    /// Tilt bound of the planned braking trajectory (rad; protocol 15 deg).
    #[schemars(extend("x-python-check" = "positive"))]
    pub trajectory_tilt_limit_rad: Option<f64>,
    /// Intervals of the braking trajectory's discretisation (protocol 100).
    #[schemars(extend("x-python-check" = "count_from_2"))]
    pub intervals: Option<usize>,
    /// Sampling period of the returned series (s; protocol 0.01).
    #[schemars(extend("x-python-check" = "positive"))]
    pub sample_every_secs: Option<f64>,
    /// What the trajectory command feeds forward: `FULL` (the paper) or `CORE` (ablation).
    #[schemars(extend(
        "x-python-type" = "Union[Feedforward, str]",
        "x-python-default" = "Feedforward.FULL",
        "x-python-check" = "feedforward"
    ))]
    pub feedforward: String,
    /// The world's stop rules: `"all"` (the paper protocol's), `"none"`, or some of
    /// `tilt,slip,lift-off,driver-trip`; `"tilt,slip,driver-trip"` is the summary's
    /// `world_braking.lift_off_rule_relaxed`. Stored in canonical form.
    #[schemars(extend("x-python-check" = "stop_on"))]
    pub stop_on: String,
}

impl Default for BrakingSettings {
    fn default() -> Self {
        Self {
            cruise_speed_m_per_s: None,
            approach_accel_m_per_s2: None,
            settle_secs: None,
            cruise_secs: None,
            trajectory_tilt_limit_rad: None,
            intervals: None,
            sample_every_secs: None,
            feedforward: "full".into(),
            stop_on: "all".into(),
        }
    }
}

/// The push-recovery protocol (`ballbot_sim::studies::push::PushParams`).
#[derive(Clone, Debug, PartialEq, Serialize, JsonSchema)]
#[serde(default)]
#[schemars(rename = "PushSettings", extend("x-python-settings" = true))]
pub(crate) struct PushSettings {
    /// How long the impulse is spread over (s, >= 0 and < `observe_secs`; protocol 0.1).
    #[schemars(extend("x-python-check" = "non_negative"))]
    pub push_duration_secs: Option<f64>,
    /// Standing still before the push (s; protocol 1.0).
    #[schemars(extend("x-python-check" = "non_negative"))]
    pub settle_secs: Option<f64>,
    /// Watching after the push (s; protocol 4.0).
    #[schemars(extend("x-python-check" = "positive"))]
    pub observe_secs: Option<f64>,
    /// At rest from this long after the push on (s; protocol 3.0); below `observe_secs`.
    #[schemars(extend("x-python-check" = "non_negative"))]
    pub rest_within_secs: Option<f64>,
    /// Sampling period of the returned series (s; protocol 0.01).
    #[schemars(extend("x-python-check" = "positive"))]
    pub sample_every_secs: Option<f64>,
    /// The world's stop rules: `"all"` (the protocol's), `"none"`, or some of
    /// `tilt,slip,lift-off,driver-trip`; `"tilt,driver-trip"` is the summary's
    /// `world_push.rules_relaxed`. Stored in canonical form.
    #[schemars(extend("x-python-check" = "stop_on"))]
    pub stop_on: String,
}

impl Default for PushSettings {
    fn default() -> Self {
        Self {
            push_duration_secs: None,
            settle_secs: None,
            observe_secs: None,
            rest_within_secs: None,
            sample_every_secs: None,
            stop_on: "all".into(),
        }
    }
}

/// One maximum-speed ramp in the 3D world (`max_speed_ramp`) and the controller's
/// command-shaping overrides (`None` keeps the designed cap: 1.0 m/s^2, 2.0 m/s^3, 0.2 rad,
/// 1.0 rad/s; the speed cap `None` is the ramp's top `max_command_m_per_s`, not the designed
/// 2.0 m/s, so that the ramp can find a speed above it).
#[derive(Clone, Debug, PartialEq, Serialize, JsonSchema)]
#[serde(default)]
#[schemars(rename = "RampSettings", extend("x-python-settings" = true))]
pub(crate) struct RampSettings {
    /// Ramp acceleration (m/s^2).
    #[schemars(extend("x-python-check" = "positive"))]
    pub accel_m_per_s2: f64,
    /// Top of the ramp (m/s), then held for 1 s.
    #[schemars(extend("x-python-check" = "positive"))]
    pub max_command_m_per_s: f64,
    /// Standing still before the ramp (s).
    #[schemars(extend("x-python-check" = "non_negative"))]
    pub settle_secs: f64,
    /// Sampling period of the returned series (s).
    #[schemars(extend("x-python-check" = "positive"))]
    pub sample_every_secs: f64,
    /// The shaper's speed cap (m/s); `None`: `max_command_m_per_s`.
    #[schemars(extend("x-python-check" = "positive"))]
    pub max_speed_m_per_s: Option<f64>,
    /// The shaper's acceleration cap (m/s^2).
    #[schemars(extend("x-python-check" = "positive"))]
    pub max_accel_m_per_s2: Option<f64>,
    /// The shaper's jerk cap (m/s^3).
    #[schemars(extend("x-python-check" = "positive"))]
    pub max_jerk_m_per_s3: Option<f64>,
    /// The shaper's tilt-command cap (rad).
    #[schemars(extend("x-python-check" = "positive"))]
    pub max_tilt_command_rad: Option<f64>,
    /// The shaper's tilt-rate-command cap (rad/s).
    #[schemars(extend("x-python-check" = "positive"))]
    pub max_tilt_rate_command_rad_per_s: Option<f64>,
}

impl Default for RampSettings {
    fn default() -> Self {
        Self {
            accel_m_per_s2: 0.25,
            max_command_m_per_s: 3.5,
            settle_secs: 0.5,
            sample_every_secs: 0.01,
            max_speed_m_per_s: None,
            max_accel_m_per_s2: None,
            max_jerk_m_per_s3: None,
            max_tilt_command_rad: None,
            max_tilt_rate_command_rad_per_s: None,
        }
    }
}
