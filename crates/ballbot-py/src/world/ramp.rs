//! The maximum-speed ramp (`max_speed_ramp`) and its result.

use super::world_loop::Shaping;
use super::{finite, non_negative, params_or_default};
use crate::errors::world_error;
use crate::errors::{Kind, error};
use crate::params::{PyControllerConfig, PyWorldParams};
use crate::results::{Columns, FailureParts};
use crate::studies::settings::RampSettings;
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_sim::studies::ramp::{RampParams, RampResult, RampSample, max_speed_ramp_with_config};
use pyo3::prelude::*;
use schemars::JsonSchema;
use serde::Serialize;

/// A maximum-speed ramp in the 3D world (`max_speed_ramp`).
// The ramp's samples as columns.
#[derive(Serialize, JsonSchema)]
#[schemars(rename = "RampRun")]
pub struct RampRunView<'a> {
    /// Ramp heading in the body frame (deg; 0 towards OW1).
    heading_deg: f64,
    /// Highest ball speed along the heading before failure (m/s).
    max_speed_m_per_s: f64,
    /// The failure that ended the ramp, or `None`.
    failure: Option<FailureParts>,
    /// When the safety supervisor stopped balancing (s), or `None`.
    supervisor_stop_secs: Option<f64>,
    #[serde(flatten)]
    samples: Columns<'a, RampSample>,
}

impl<'a> From<&'a RampResult> for RampRunView<'a> {
    fn from(r: &'a RampResult) -> Self {
        Self {
            heading_deg: r.heading_deg,
            max_speed_m_per_s: r.max_speed_m_per_s,
            failure: r.failure.map(FailureParts::from),
            supervisor_stop_secs: r.supervisor_stop_secs,
            samples: Columns(&r.samples),
        }
    }
}

/// The controller (the paper's configuration unless `controller`, the shaping overrides on
/// top) and the ramp of `settings`.
fn ramp_setup(
    py: Python<'_>,
    params: &ballbot_sim::world::WorldParams,
    heading_deg: f64,
    controller: Option<PyControllerConfig>,
    settings: &RampSettings,
) -> PyResult<(BallbotControllerConfig<f64>, RampParams)> {
    let RampSettings {
        accel_m_per_s2,
        max_command_m_per_s,
        settle_secs,
        sample_every_secs,
        max_speed_m_per_s,
        max_accel_m_per_s2,
        max_jerk_m_per_s3,
        max_tilt_command_rad,
        max_tilt_rate_command_rad_per_s,
    } = *settings;
    finite(py, &[heading_deg], "heading_deg")?;
    for (value, name) in [
        (accel_m_per_s2, "accel_m_per_s2"),
        (max_command_m_per_s, "max_command_m_per_s"),
        (sample_every_secs, "sample_every_secs"),
    ] {
        if !(value.is_finite() && value > 0.0) {
            return Err(error(
                py,
                Kind::Parameter,
                format!("invalid parameter `{name}`: must be finite and > 0, got {value}"),
            ));
        }
    }
    non_negative(py, settle_secs, "settle_secs")?;
    // The study looks for the highest speed: the shaper's speed cap (2.0 m/s as designed)
    // must not end the ramp first, so by default it is the ramp's top.
    let config = Shaping {
        controller: controller.map(|c| c.inner),
        max_speed_m_per_s: max_speed_m_per_s.or(Some(max_command_m_per_s)),
        max_accel_m_per_s2,
        max_jerk_m_per_s3,
        max_tilt_command_rad,
        max_tilt_rate_command_rad_per_s,
        wheel_mapping: None,
        // The paper's configuration, as the Rust ramp study (`studies::ramp`) pins it
        // (without `controller`; with one, its own layers).
        traction_control: false,
        balance_point: false,
        imu_lean_time_constant_secs: None,
    }
    .config(py, params)?;
    let ramp = RampParams {
        accel_m_per_s2,
        max_command_m_per_s,
        settle_secs,
        sample_every_secs,
    };
    Ok((config, ramp))
}

/// The maximum-speed experiment of the paper's Sec. V in the 3D world
/// (`ballbot_sim::studies::ramp::max_speed_ramp`): the core's controller follows a
/// velocity ramp towards `heading_deg` (body frame; 0 is towards OW1) after `settle_secs`, rising
/// at `accel_m_per_s2` to `max_command_m_per_s`, until the world detects a failure or the top
/// speed has been held for 1 s. Runs in Rust without the GIL. The shaping keywords lift the
/// controller's caps as in `WorldLoop`; the speed cap `max_speed_m_per_s` defaults to the
/// ramp's top `max_command_m_per_s` (not the designed 2.0 m/s, which would end every ramp at
/// about 2.07 m/s whatever the heading), the others keep the designed caps (1.0 m/s^2,
/// 2.0 m/s^3, 0.2 rad, 1.0 rad/s).
///
/// The controller is the paper's configuration (traction-aware control and balance-point
/// estimation off), as the Rust study pins it, unless `controller` (a `ControllerConfig`) is
/// given: then that one runs, with its own layers and caps, the shaping keywords on top and the
/// speed cap still raised to `max_command_m_per_s` unless `max_speed_m_per_s` is given.
///
/// Returns a `RampRun`: `heading_deg`, `max_speed_m_per_s` (highest ball speed along the heading
/// before failure), `failure` (`Failure` or `None` if the ramp ended first),
/// `supervisor_stop_secs` (when the core's safety supervisor stopped balancing, e.g. at its
/// wheel-speed limit, or `None`), and samples every
/// `sample_every_secs`: `time_secs`, `command_m_per_s` (the ramp), `shaped_command_m_per_s` (after
/// the controller's command shaper), `speed_m_per_s`, `tilt_rad` (from the vertical),
/// `max_cone_utilisation` (n,); `normal_force_n`, `cone_utilisation` (n, 3).
#[pyfunction]
#[pyo3(signature = (
    params = None, *, heading_deg = 0.0, accel_m_per_s2 = 0.25, max_command_m_per_s = 3.5,
    settle_secs = 0.5, sample_every_secs = 0.01, max_speed_m_per_s = None, max_accel_m_per_s2 = None,
    max_jerk_m_per_s3 = None, max_tilt_command_rad = None, max_tilt_rate_command_rad_per_s = None,
    controller = None,
))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn max_speed_ramp<'py>(
    py: Python<'py>,
    params: Option<PyWorldParams>,
    heading_deg: f64,
    accel_m_per_s2: f64,
    max_command_m_per_s: f64,
    settle_secs: f64,
    sample_every_secs: f64,
    max_speed_m_per_s: Option<f64>,
    max_accel_m_per_s2: Option<f64>,
    max_jerk_m_per_s3: Option<f64>,
    max_tilt_command_rad: Option<f64>,
    max_tilt_rate_command_rad_per_s: Option<f64>,
    controller: Option<PyControllerConfig>,
) -> PyResult<Bound<'py, PyAny>> {
    let params = params_or_default(params);
    let settings = RampSettings {
        accel_m_per_s2,
        max_command_m_per_s,
        settle_secs,
        sample_every_secs,
        max_speed_m_per_s,
        max_accel_m_per_s2,
        max_jerk_m_per_s3,
        max_tilt_command_rad,
        max_tilt_rate_command_rad_per_s,
    };
    let (config, ramp) = ramp_setup(py, &params, heading_deg, controller, &settings)?;
    let result = py
        .detach(|| max_speed_ramp_with_config(params, config, heading_deg, &ramp))
        .map_err(|e| world_error(py, e))?;
    crate::results::build(py, &RampRunView::from(&result))
}
