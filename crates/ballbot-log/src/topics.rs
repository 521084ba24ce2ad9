//! Topic names shared by the simulators' logs and the committed Foxglove layout
//! (`foxglove/ballbot-layout.json`), so a log opens in Foxglove with every panel filled.
//!
//! | topic | schema | content |
//! | --- | --- | --- |
//! | [`TRANSFORMS`] | `foxglove.FrameTransforms` | `world -> ball`, `world -> body` ([`BallbotScene::frames`](super::foxglove::BallbotScene::frames)) |
//! | [`SCENE`] | `foxglove.SceneUpdate` | ball, body, wheels ([`BallbotScene::scene`](super::foxglove::BallbotScene::scene)) |
//! | [`JOINT_STATES`] | `foxglove.JointStates` | the omniwheels `ow1`..`ow3`: angle, speed, motor torque |
//! | [`LOG`] | `foxglove.Log` | the run's events as text, for Foxglove's Log panel |
//! | [`WORLD_TELEMETRY`] | the 3D world's per-step telemetry | `wheels[i].normal_force_n`, `wheels[i].traction_n`, `wheels[i].cone_utilisation`, `wheels[i].slip_speed_m_per_s`, `tilt_rad[0..2]`, ... |
//! | [`WORLD_CONTROLLER`] | the 3D controller's outer loop | `reference_torque_nm[0..3]`, `estimate.sagittal.tilt_rad`, `mode`, ... |
//! | [`WORLD_COMMAND`] | the 3D world's command | `speed_m_per_s`, `heading_deg`, ... |
//! | [`PLANAR_STATE`] | the planar simulator's state | `tilt_rad`, `ball_rate_rad_per_s`, ... |
//! | [`PLANAR_COMMAND`] | the planar simulator's command | `ball_rate_rad_per_s`, ... |
//! | [`PLANAR_CONTROL`] | the planar controller's output with per-term contributions | `torque_nm`, ... |
//! | [`FAULTS`] | faults and failure events | `kind`, `wheel`, `tilt_rad`, `description` |

/// Frame transforms of the 3D world (`foxglove.FrameTransforms`).
pub const TRANSFORMS: &str = "/tf";
/// Scene entities of the 3D world (`foxglove.SceneUpdate`).
pub const SCENE: &str = "/scene";
/// The omniwheel joints of the 3D world (`foxglove.JointStates`).
pub const JOINT_STATES: &str = "/joint_states";
/// The run's events as text (`foxglove.Log`).
pub const LOG: &str = "/log";
/// Per-step telemetry of the 3D world.
pub const WORLD_TELEMETRY: &str = "/world/telemetry";
/// The 3D controller's outer-loop output (references, estimates, safety mode).
pub const WORLD_CONTROLLER: &str = "/world/controller";
/// Commands given to the 3D robot.
pub const WORLD_COMMAND: &str = "/world/command";
/// State of the planar simulator.
pub const PLANAR_STATE: &str = "/planar/state";
/// Commands of the planar simulator.
pub const PLANAR_COMMAND: &str = "/planar/command";
/// Controller output of the planar simulator, with per-term contributions.
pub const PLANAR_CONTROL: &str = "/planar/control";
/// Faults and failure events of either simulator.
pub const FAULTS: &str = "/faults";

/// Every topic above.
pub const ALL: [&str; 11] = [
    TRANSFORMS,
    SCENE,
    JOINT_STATES,
    LOG,
    WORLD_TELEMETRY,
    WORLD_CONTROLLER,
    WORLD_COMMAND,
    PLANAR_STATE,
    PLANAR_COMMAND,
    PLANAR_CONTROL,
    FAULTS,
];
