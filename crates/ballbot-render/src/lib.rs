//! The ballbot scene renderer: frames of the 3D world's robot, shared by the `ballbot` CLI
//! (`ballbot world --video`) and the Python package (the Gymnasium environments'
//! `rgb_array` and `human` render modes).
//!
//! [`SceneRenderer`] draws one [`ballbot_world::world::StepTelemetry`] of a world with
//! tiny-skia: a 3/4 perspective camera ([`camera`]) that follows the ball over a floor grid
//! fixed to the world, the ball, the body, the three omniwheels with their rollers where the
//! world's parameters put them, and the contact forces coloured by friction-cone use, with
//! lift-off and slip marked ([`scene`]). [`clip`] writes frames as an animated GIF.
//!
//! Headless, no system fonts (DejaVu Sans is embedded, [`text`]).

pub mod camera;
pub mod clip;
pub mod palette;
pub mod scene;
pub mod text;

pub use camera::CameraView;
pub use clip::GifClip;
pub use scene::{DEFAULT_HEIGHT, DEFAULT_WIDTH, Frame, RenderError, SceneRenderer};
