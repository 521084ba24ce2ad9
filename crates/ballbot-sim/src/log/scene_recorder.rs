//! Recording a ballbot's 3D motion into a log for Foxglove's 3D panel, at bounded rates.

use nalgebra::Isometry3;

use super::{
    Channel, LogError, McapLogger,
    foxglove::{BallbotScene, FrameTransforms, SceneUpdate, WheelContact},
    topics,
};

/// Writes the transforms ([`topics::TRANSFORMS`]) and the scene with the contact-force arrows
/// ([`topics::SCENE`]) of a [`BallbotScene`], each at most once per interval of simulated
/// time, however often [`record`](Self::record) is called (e.g. at every 8 kHz physics step).
///
/// ```
/// use ballbot_sim::log::foxglove::{BallbotScene, WheelContact};
/// use ballbot_sim::log::{LoggerOptions, McapLog, McapLogger, SceneRecorder, topics};
/// use nalgebra::Isometry3;
///
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let dir = tempfile::tempdir()?;
/// let path = dir.path().join("world.mcap");
/// let mut log = McapLogger::create(&path, LoggerOptions::default())?;
/// let mut recorder = SceneRecorder::new(&mut log, BallbotScene::miapure_like())?;
/// let contacts = [WheelContact { normal_force_n: 280.0, traction_n: 0.0, slipping: false }; 3];
/// for step in 0..8000 {
///     let time_secs = f64::from(step) / 8000.0; // 1 s of an 8 kHz simulation
///     let pose = Isometry3::translation(0.2 * time_secs, 0.0, 0.1145);
///     recorder.record(&mut log, time_secs, &pose, &pose, &contacts)?;
/// }
/// log.finish()?;
/// let read = McapLog::open(&path)?;
/// assert_eq!(read.channel(topics::TRANSFORMS).map(|c| c.message_count), Some(400));
/// assert_eq!(read.channel(topics::SCENE).map(|c| c.message_count), Some(50));
/// # Ok(())
/// # }
/// ```
#[derive(Debug)]
pub struct SceneRecorder {
    robot: BallbotScene,
    transforms: Channel<FrameTransforms>,
    scene: Channel<SceneUpdate>,
    /// Simulated time between transform messages (s). Default 1/400 s.
    pub transform_interval_secs: f64,
    /// Simulated time between scene messages (s). Default 1/50 s.
    pub scene_interval_secs: f64,
    /// Length of a force arrow per newton (m/N). Default 1 mm/N.
    pub metres_per_newton: f64,
    next_transform_secs: f64,
    next_scene_secs: f64,
}

impl SceneRecorder {
    /// Registers the transform and scene channels on `log`.
    pub fn new(log: &mut McapLogger, robot: BallbotScene) -> Result<Self, LogError> {
        Ok(Self {
            transforms: log.channel::<FrameTransforms>(topics::TRANSFORMS)?,
            scene: log.channel::<SceneUpdate>(topics::SCENE)?,
            robot,
            transform_interval_secs: 1.0 / 400.0,
            scene_interval_secs: 1.0 / 50.0,
            metres_per_newton: 1e-3,
            next_transform_secs: f64::NEG_INFINITY,
            next_scene_secs: f64::NEG_INFINITY,
        })
    }

    /// The robot drawn.
    pub fn robot(&self) -> &BallbotScene {
        &self.robot
    }

    /// Records the poses (ball and body frames in the world) and the wheel contacts at a
    /// simulated time, if an interval has elapsed since the last message of each kind. The
    /// intervals are kept on a fixed grid, so the output does not depend on the step size
    /// beyond rounding to the next step.
    pub fn record(
        &mut self,
        log: &mut McapLogger,
        time_secs: f64,
        world_from_ball: &Isometry3<f64>,
        world_from_body: &Isometry3<f64>,
        contacts: &[WheelContact],
    ) -> Result<(), LogError> {
        // A small tolerance keeps a step landing on the grid up to rounding from being skipped.
        let tolerance_secs = 1e-9;
        if time_secs + tolerance_secs >= self.next_transform_secs {
            let frames = self
                .robot
                .frames(time_secs, world_from_ball, world_from_body);
            log.write(&self.transforms, time_secs, &frames)?;
            self.next_transform_secs =
                next_grid_time(time_secs, self.transform_interval_secs, tolerance_secs);
        }
        if time_secs + tolerance_secs >= self.next_scene_secs {
            let mut update = self.robot.scene(time_secs);
            update.entities.push(self.robot.contact_forces(
                time_secs,
                contacts,
                self.metres_per_newton,
            ));
            log.write(&self.scene, time_secs, &update)?;
            self.next_scene_secs =
                next_grid_time(time_secs, self.scene_interval_secs, tolerance_secs);
        }
        Ok(())
    }
}

/// The first multiple of `interval_secs` after `time_secs` (beyond the rounding tolerance).
fn next_grid_time(time_secs: f64, interval_secs: f64, tolerance_secs: f64) -> f64 {
    if interval_secs > 0.0 && interval_secs.is_finite() {
        ((time_secs + tolerance_secs) / interval_secs).floor() * interval_secs + interval_secs
    } else {
        // Non-positive interval: record every call.
        f64::NEG_INFINITY
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn grid_times_advance_by_one_interval() {
        assert!((next_grid_time(0.0, 0.02, 1e-9) - 0.02).abs() < 1e-15);
        assert!((next_grid_time(0.019_999_999_999, 0.02, 1e-9) - 0.04).abs() < 1e-15);
        assert!((next_grid_time(0.013, 0.02, 1e-9) - 0.02).abs() < 1e-15);
        assert_eq!(next_grid_time(1.0, 0.0, 1e-9), f64::NEG_INFINITY);
    }
}
