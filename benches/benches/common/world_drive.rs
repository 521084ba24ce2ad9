//! The world-step benchmark's scenario, shared by the criterion bench (`benches/world_step.rs`)
//! and the instruction-count harness (`examples/icount_world.rs`): the MiaPURE world with the
//! core's 3D controller in the loop (outer loop 400 Hz, motor PIs 8 kHz, seeded sensor noise),
//! balancing while it drives a fixed cycle of velocity commands, so the measured steps include
//! accelerating, cruising, turning and slowing down, not a robot at rest.

use ballbot_core::command::{Command, VelocityCommand};
use ballbot_sim::rig::WorldRobot;
use ballbot_sim::world::{StepTelemetry, WorldError, WorldParams};

/// Physics steps (8 kHz) run before measuring: 1 s, the robot armed and accelerating.
pub const WARM_UP_STEPS: u64 = 8000;

/// Physics steps each command of [`DRIVE_CYCLE`] is held (2 s at 8 kHz).
pub const STEPS_PER_COMMAND: u64 = 16_000;

/// The drive: body-frame velocity commands `(vx m/s, vy m/s, yaw rate rad/s)`, each held for
/// [`STEPS_PER_COMMAND`] steps, then repeated.
/// (A stop separates the first two commands: in the default world, whose contacts have roller
/// gaps, axle losses and the soft rubber coating, the direct reversal from (0.8, -0.3) to
/// (-0.6, 0.5) made OW1 slip for over 0.1 s under the core's default command shaping; see
/// docs/mechanisms.md.)
pub const DRIVE_CYCLE: [(f64, f64, f64); 5] = [
    (0.8, -0.3, 0.2),
    (0.0, 0.0, 0.0),
    (0.6, 0.5, -0.3),
    (1.2, 0.0, 0.0),
    (0.0, 0.0, 0.5),
];

/// The world driven through [`DRIVE_CYCLE`]; rebuilt (and counted) if the robot ever fails.
pub struct WorldDrive {
    params: WorldParams,
    sim: WorldRobot,
    step_index: u64,
    /// How often the world had to be rebuilt after a failure (0 in a healthy run).
    pub restarts: u64,
}

impl WorldDrive {
    /// A fresh MiaPURE world (today's defaults), warmed up for [`WARM_UP_STEPS`].
    pub fn new() -> Result<Self, WorldError> {
        Self::with_params(WorldParams::miapure_60kg())
    }

    /// A fresh world with `params`, warmed up for [`WARM_UP_STEPS`].
    pub fn with_params(params: WorldParams) -> Result<Self, WorldError> {
        let mut drive = Self {
            params,
            sim: WorldRobot::new(params)?,
            step_index: 0,
            restarts: 0,
        };
        for _ in 0..WARM_UP_STEPS {
            drive.step()?;
        }
        Ok(drive)
    }

    /// One physics step with the command of the current drive phase.
    pub fn step(&mut self) -> Result<&StepTelemetry, WorldError> {
        if self.sim.world().failure().is_some() {
            self.sim = WorldRobot::new(self.params)?;
            self.restarts += 1;
        }
        let phase = (self.step_index / STEPS_PER_COMMAND) as usize % DRIVE_CYCLE.len();
        let (vx, vy, yaw_rate) = DRIVE_CYCLE[phase];
        self.step_index += 1;
        Ok(self.sim.step(Command::Velocity(VelocityCommand {
            vx_m_per_s: vx,
            vy_m_per_s: vy,
            yaw_rate_rad_per_s: yaw_rate,
        })))
    }

    /// The simulation.
    pub fn sim(&self) -> &WorldRobot {
        &self.sim
    }
}
