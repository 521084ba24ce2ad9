//! What a world log writes and how often.

use std::path::Path;

use crate::{LogError, LoggerOptions};
use ballbot_core::rates::OUTER_LOOP_DT_SECS;

/// What a [`WorldLogger`](super::WorldLogger) writes and how often.
///
/// Rates are set on a grid of simulated time (a message at the first step at or after each
/// multiple of the interval), so they do not depend on how often `record` is called beyond
/// rounding to the next step. Sizes with the defaults, for the MiaPURE with the core's
/// controller (zstd chunks): see `docs/world-logs.md`.
#[derive(Clone, Debug, PartialEq)]
pub struct WorldLogOptions {
    /// Write the telemetry at every n-th call of `record` (1: every physics step). Default 1.
    /// Must be >= 1.
    pub telemetry_every_steps: u32,
    /// Simulated time between `foxglove.FrameTransforms` messages (s). Default 0.01 (100 Hz).
    /// Must be finite and > 0.
    pub transform_interval_secs: f64,
    /// Simulated time between `foxglove.SceneUpdate` messages (s). Default 0.02 (50 Hz).
    /// Must be finite and > 0.
    pub scene_interval_secs: f64,
    /// The controller's outer-loop period (s): one
    /// [`WorldControllerMsg`](super::WorldControllerMsg) per outer step, and commands
    /// ([`WorldLogger::record_command`](super::WorldLogger::record_command)) at most this
    /// often. Default 1/400 s, the core's outer-loop rate. Must be a whole multiple of the
    /// physics step.
    pub controller_interval_secs: f64,
    /// Write the controller's output at every n-th outer step (1: every one), and commands at
    /// most once per n outer steps. Default 1. Must be >= 1. Safety-mode changes are written
    /// on `/faults` at the outer step they happen, whatever n.
    pub controller_every_outer_steps: u32,
    /// Length of a contact-force arrow per newton (m/N). Default 5e-4 (the 344 N static load
    /// draws 0.17 m). Must be finite and > 0.
    pub metres_per_newton: f64,
    /// Chunking, flushing and compression of the file.
    pub logger: LoggerOptions,
}

impl Default for WorldLogOptions {
    fn default() -> Self {
        Self {
            telemetry_every_steps: 1,
            transform_interval_secs: 0.01,
            scene_interval_secs: 0.02,
            controller_interval_secs: OUTER_LOOP_DT_SECS,
            controller_every_outer_steps: 1,
            metres_per_newton: 5e-4,
            logger: LoggerOptions::default(),
        }
    }
}

impl WorldLogOptions {
    /// The defaults with the telemetry at 1 kHz (every 8th step at 8 kHz): about a quarter of
    /// the file size (0.81 instead of 3.3 MB per simulated second), for experiments that write
    /// many logs.
    ///
    /// ```
    /// use ballbot_log::WorldLogOptions;
    /// assert_eq!(WorldLogOptions::compact().telemetry_every_steps, 8);
    /// ```
    pub fn compact() -> Self {
        Self {
            telemetry_every_steps: 8,
            ..Self::default()
        }
    }

    /// These options with no periodic channel written more often than the telemetry, every
    /// `telemetry_every_steps` physics steps of `dt_secs`: the transforms and joint states,
    /// the scene, the controller's output and the command keep their own rates where these
    /// are slower. Telemetry at 1 kHz or faster changes nothing; at 1 Hz (every 8,000th step
    /// at 8 kHz) the log writes about one message per channel and simulated second, so it
    /// costs little between the steps it writes (`ballbot world --decimate`).
    ///
    /// ```
    /// use ballbot_log::WorldLogOptions;
    /// let dt = 1.0 / 8000.0;
    /// assert_eq!(WorldLogOptions::compact().capped_at_telemetry_rate(dt), WorldLogOptions::compact());
    /// let one_hz = WorldLogOptions { telemetry_every_steps: 8000, ..WorldLogOptions::default() }
    ///     .capped_at_telemetry_rate(dt);
    /// assert_eq!(one_hz.scene_interval_secs, 1.0);
    /// assert_eq!(one_hz.controller_every_outer_steps, 400);
    /// ```
    #[must_use]
    pub fn capped_at_telemetry_rate(mut self, dt_secs: f64) -> Self {
        let every = f64::from(self.telemetry_every_steps);
        let telemetry_interval_secs = every * dt_secs;
        self.transform_interval_secs = self.transform_interval_secs.max(telemetry_interval_secs);
        self.scene_interval_secs = self.scene_interval_secs.max(telemetry_interval_secs);
        let steps_per_outer = (self.controller_interval_secs / dt_secs).round().max(1.0);
        // At most `telemetry_every_steps` (a u32): the cast cannot truncate.
        let outer_steps = (every / steps_per_outer).ceil() as u32;
        self.controller_every_outer_steps = self.controller_every_outer_steps.max(outer_steps);
        self
    }

    /// Checks every field against the physics step `dt_secs`; `path` only names the file in
    /// the error.
    pub fn validate(&self, path: &Path, dt_secs: f64) -> Result<(), LogError> {
        let invalid = |field, requirement| LogError::InvalidOption {
            path: path.to_owned(),
            field,
            requirement,
        };
        if self.telemetry_every_steps == 0 {
            return Err(invalid("telemetry_every_steps", ">= 1"));
        }
        if self.controller_every_outer_steps == 0 {
            return Err(invalid("controller_every_outer_steps", ">= 1"));
        }
        let positive = |x: f64| x.is_finite() && x > 0.0;
        if !positive(self.transform_interval_secs) {
            return Err(invalid("transform_interval_secs", "finite and > 0"));
        }
        if !positive(self.scene_interval_secs) {
            return Err(invalid("scene_interval_secs", "finite and > 0"));
        }
        if !positive(self.metres_per_newton) {
            return Err(invalid("metres_per_newton", "finite and > 0"));
        }
        let ratio = self.controller_interval_secs / dt_secs;
        if !(ratio.is_finite() && ratio >= 1.0 && (ratio - ratio.round()).abs() < 1e-9) {
            return Err(invalid(
                "controller_interval_secs",
                "a whole multiple of the physics step dt_secs",
            ));
        }
        self.logger.validate(path)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn invalid_options_name_the_field() {
        let path = Path::new("x.mcap");
        let dt = 1.0 / 8000.0;
        let bad = WorldLogOptions {
            controller_interval_secs: 1.5 * dt,
            ..WorldLogOptions::default()
        };
        assert!(matches!(
            bad.validate(path, dt),
            Err(LogError::InvalidOption {
                field: "controller_interval_secs",
                ..
            })
        ));
        let bad = WorldLogOptions {
            telemetry_every_steps: 0,
            ..WorldLogOptions::default()
        };
        assert!(matches!(
            bad.validate(path, dt),
            Err(LogError::InvalidOption {
                field: "telemetry_every_steps",
                ..
            })
        ));
        WorldLogOptions::default().validate(path, dt).unwrap();
    }
}
