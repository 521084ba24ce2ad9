//! `World`, the 3D ballbot driven by wheel torques, and `world_class!`, the methods it shares
//! with `WorldLoop`.

use super::live::PyLiveView;
use super::telemetry::{PyFailure, PyMeasurement, PyStepTelemetry, vec_out};
use super::trace::{RunOptions, TorqueInput, Trace, finish_log, finish_run, logger, run_steps};
use super::{Arr, finite, non_negative, params_or_default, step_rows, vec3};
use crate::errors::world_error;
use crate::log::log_error;
use crate::params::PyWorldParams;
use ballbot_sim::world::BallbotWorld;
use nalgebra::Vector3;
use numpy::PyArray1;
use pyo3::prelude::*;
use std::path::PathBuf;

/// The world methods both `World` and `WorldLoop` have: what `BallbotWorld` offers besides
/// `step`. `$world` and `$world_mut` are expressions on `self` giving the world.
macro_rules! world_class {
    (
        $(#[$meta:meta])*
        $py_ty:ident($name:literal) {
            inner: $inner:ty,
            world: |$this:ident| $world:expr,
            world_mut: |$this_mut:ident| $world_mut:expr,
        }
        methods { $($extra:item)* }
    ) => {
        $(#[$meta])*
        #[pyclass(name = $name, module = "ballbot")]
        pub struct $py_ty {
            inner: $inner,
        }

        impl $py_ty {
            fn world(&self) -> &BallbotWorld {
                let $this = self;
                $world
            }

            fn world_mut(&mut self) -> &mut BallbotWorld {
                let $this_mut = self;
                $world_mut
            }
        }

        #[pymethods]
        impl $py_ty {
            /// The parameters the world was built with.
            #[getter]
            fn params(&self) -> PyWorldParams {
                PyWorldParams { inner: *self.world().params() }
            }

            /// Simulated time (s).
            #[getter]
            fn time_secs(&self) -> f64 {
                self.world().time_secs()
            }

            /// The record of the last step (before the first step: the initial poses).
            #[getter]
            fn telemetry(&self) -> PyStepTelemetry {
                PyStepTelemetry { inner: *self.world().telemetry() }
            }

            /// The first failure detected, or `None` (the simulation keeps running after it).
            #[getter]
            fn failure(&self) -> Option<PyFailure> {
                self.world().failure().map(PyFailure::from)
            }

            /// Samples the sensors (IMU, encoders) at the current state; draws from the
            /// seeded noise generator.
            fn measure(&mut self) -> PyMeasurement {
                PyMeasurement { inner: self.world_mut().measure() }
            }

            /// The encoders' wheel speed estimate (rad/s), as the motor drivers read it.
            fn encoder_speeds_rad_per_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
                PyArray1::from_slice(py, &self.world().encoder_speeds_rad_per_s())
            }

            /// Applies an impulse `impulse_ns` (N s, 3 numbers, world frame) at the body's
            /// centre of mass, e.g. a push.
            fn push_body(&mut self, py: Python<'_>, impulse_ns: &Bound<'_, PyAny>) -> PyResult<()> {
                let j = vec3(py, impulse_ns, "impulse_ns")?;
                self.world_mut().push_body(Vector3::from(j));
                Ok(())
            }

            /// Sets the body's centre-of-mass velocity (m/s) and angular velocity (rad/s,
            /// world frame).
            #[pyo3(signature = (linear_m_per_s, angular_rad_per_s = None))]
            fn set_body_velocity(
                &mut self,
                py: Python<'_>,
                linear_m_per_s: &Bound<'_, PyAny>,
                angular_rad_per_s: Option<&Bound<'_, PyAny>>,
            ) -> PyResult<()> {
                let v = vec3(py, linear_m_per_s, "linear_m_per_s")?;
                let w = match angular_rad_per_s {
                    Some(w) => vec3(py, w, "angular_rad_per_s")?,
                    None => [0.0; 3],
                };
                self.world_mut().set_body_velocity(Vector3::from(v), Vector3::from(w));
                Ok(())
            }

            /// Sets the ball's linear (m/s) and angular (rad/s) velocity.
            #[pyo3(signature = (linear_m_per_s, angular_rad_per_s = None))]
            fn set_ball_velocity(
                &mut self,
                py: Python<'_>,
                linear_m_per_s: &Bound<'_, PyAny>,
                angular_rad_per_s: Option<&Bound<'_, PyAny>>,
            ) -> PyResult<()> {
                let v = vec3(py, linear_m_per_s, "linear_m_per_s")?;
                let w = match angular_rad_per_s {
                    Some(w) => vec3(py, w, "angular_rad_per_s")?,
                    None => [0.0; 3],
                };
                self.world_mut().set_ball_velocity(Vector3::from(v), Vector3::from(w));
                Ok(())
            }

            /// Rotates the body about the ball centre by `tilt_rad = (theta_x, theta_y)`
            /// (about world x, then y), keeping the contacts' penetration.
            fn tilt_body(&mut self, py: Python<'_>, tilt_rad: (f64, f64)) -> PyResult<()> {
                finite(py, &[tilt_rad.0, tilt_rad.1], "tilt_rad")?;
                self.world_mut().tilt_body([tilt_rad.0, tilt_rad.1]);
                Ok(())
            }

            /// Moves the whole robot (ball and body) by `offset_m` (3 numbers), e.g. into
            /// the air.
            fn translate_robot(&mut self, py: Python<'_>, offset_m: &Bound<'_, PyAny>) -> PyResult<()> {
                let d = vec3(py, offset_m, "offset_m")?;
                self.world_mut().translate_robot(Vector3::from(d));
                Ok(())
            }

            /// Sets gravity along -z (m/s^2, finite and >= 0); 0 gives free flight. `params` follows.
            fn set_gravity_m_per_s2(&mut self, py: Python<'_>, gravity_m_per_s2: f64) -> PyResult<()> {
                finite(py, &[gravity_m_per_s2], "gravity_m_per_s2")?;
                self.world_mut()
                    .set_gravity_m_per_s2(gravity_m_per_s2)
                    .map_err(|e| world_error(py, e))
            }

            /// Sets the ball-floor friction coefficient (>= 0; 0 is a frictionless floor).
            fn set_floor_friction(&mut self, py: Python<'_>, friction: f64) -> PyResult<()> {
                non_negative(py, friction, "friction")?;
                self.world_mut()
                    .set_floor_friction(friction)
                    .map_err(|e| world_error(py, e))
            }

            /// Sets the omniwheel-ball static friction coefficient `mu` (>= 0); the kinetic
            /// one follows with the configured ratio.
            fn set_wheel_ball_friction(&mut self, py: Python<'_>, friction: f64) -> PyResult<()> {
                non_negative(py, friction, "friction")?;
                self.world_mut()
                    .set_wheel_ball_friction(friction)
                    .map_err(|e| world_error(py, e))
            }

            /// Test rig: clamps the ball in place (`True`) or releases it.
            fn set_ball_fixed(&mut self, fixed: bool) {
                self.world_mut().set_ball_fixed(fixed);
            }

            /// Test rig: clamps the body in place (`True`) or releases it.
            fn set_body_fixed(&mut self, fixed: bool) {
                self.world_mut().set_body_fixed(fixed);
            }

            /// Total kinetic energy of ball, body and wheels (J).
            fn kinetic_energy_j(&self) -> f64 {
                self.world().kinetic_energy_j()
            }

            /// Gravitational potential energy of ball and body above the floor (J).
            fn potential_energy_j(&self) -> f64 {
                self.world().potential_energy_j()
            }

            /// Elastic energy stored in the three omniwheel contacts' normal springs (J).
            fn contact_energy_j(&self) -> f64 {
                self.world().contact_energy_j()
            }

            /// Total linear momentum of ball and body (N s), shape (3,).
            fn linear_momentum_ns<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
                vec_out(py, &self.world().linear_momentum_ns())
            }

            /// Total angular momentum of ball, body and wheel spins about the world origin
            /// (N m s), shape (3,).
            fn angular_momentum_nms<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
                vec_out(py, &self.world().angular_momentum_nms())
            }

            /// Height of the chassis' lowest corner above the floor (m).
            fn chassis_clearance_m(&self) -> f64 {
                self.world().chassis_clearance_m()
            }

            $($extra)*
        }
    };
}

pub(crate) use world_class;

world_class! {
    /// The simulated 3D ballbot (`ballbot_sim::world::BallbotWorld`) driven directly by wheel
    /// torques: rapier3d integrates ball and body, the omniwheel contacts carry compliant
    /// normal forces and friction-cone-bounded traction along their rolling directions.
    ///
    /// Frames: world z up, floor at z = 0; the body frame's x points towards OW1.
    ///
    /// A world is stepped by one thread at a time (a call while another thread's `run` holds
    /// it raises `RuntimeError`); run several worlds to use several cores.
    PyWorld("World") {
        inner: BallbotWorld,
        world: |this| &this.inner,
        world_mut: |this| &mut this.inner,
    }
    methods {
        /// The world with the robot at rest, upright, the ball on the floor at the origin and
        /// the contacts pre-loaded (default parameters: `WorldParams.preset("miapure_60kg")`).
        #[new]
        #[pyo3(signature = (params = None))]
        fn py_new(py: Python<'_>, params: Option<PyWorldParams>) -> PyResult<Self> {
            let inner = BallbotWorld::new(params_or_default(params)).map_err(|e| world_error(py, e))?;
            Ok(Self { inner })
        }

        /// One physics step of `params.dt_secs` with the wheel torque commands `torque_nm`
        /// (3 numbers, N m at the wheels; each clamped to the actuator's torque-speed limit).
        fn step(&mut self, py: Python<'_>, torque_nm: &Bound<'_, PyAny>) -> PyResult<PyStepTelemetry> {
            let tau = vec3(py, torque_nm, "torque_nm")?;
            Ok(PyStepTelemetry { inner: *self.inner.step(tau) })
        }

        /// Runs `n_steps` physics steps in Rust without the GIL. `torque_nm`: wheel torques
        /// (N m), shape (3,) held for every step or (n_steps, 3), default zeros. Records every
        /// `record_every`-th step (the first one included); `stop_on_failure` ends the run at
        /// the step that detects a failure (recorded too). Returns a `WorldRun` of numpy arrays, one
        /// row per recorded step: `time_secs` (n,), `torque_nm` (n, 3) (the commands),
        /// per wheel (n, 3) `normal_force_n`, `traction_n`, `traction_demand_n`,
        /// `cone_utilisation`, `slip_speed_m_per_s`, `slipping` (bool), `motor_torque_nm`,
        /// `wheel_speed_rad_per_s`, `wheel_angle_rad`; `ball_position_m`,
        /// `ball_velocity_m_per_s`, `ball_angular_velocity_rad_per_s`, `body_position_m`,
        /// `body_rate_rad_per_s` (n, 3); `body_orientation` (n, 4) `(x, y, z, w)`; `tilt_rad`
        /// (n, 2); `tilt_from_vertical_rad`, `yaw_rad`, `floor_force_n` (n,); and `steps`
        /// (steps run), `failure` (`Failure` or `None`), `log_path`. With `log_path` every step
        /// is also written to that MCAP file (`ballbot_sim::log::WorldLogger`: telemetry,
        /// the Foxglove 3D scene and transforms, failure events; `log_compact` writes the
        /// telemetry at 1 kHz instead of every step), readable with `McapLog`. With `live` (a
        /// `LiveView`) the same channels are served to Foxglove while the run goes, paced as
        /// the view says.
        #[pyo3(signature = (
            n_steps, torque_nm = None, *, record_every = 1, stop_on_failure = false,
            log_path = None, log_compact = false, live = None,
        ))]
        #[allow(clippy::too_many_arguments)]
        fn run<'py>(
            &mut self,
            py: Python<'py>,
            n_steps: i64,
            torque_nm: Option<Arr<'py>>,
            record_every: i64,
            stop_on_failure: bool,
            log_path: Option<PathBuf>,
            log_compact: bool,
            live: Option<PyRef<'py, PyLiveView>>,
        ) -> PyResult<Bound<'py, PyAny>> {
            let options = RunOptions::new(py, n_steps, record_every, stop_on_failure)?;
            let inputs = step_rows(py, torque_nm, options.n_steps(), "torque_nm")?;
            let trace = Trace::<TorqueInput>::with_capacity(options.records())?;
            let mut log = logger(
                py,
                log_path.as_deref(),
                live.as_deref(),
                self.inner.params(),
                log_compact,
            )?;
            let world = &mut self.inner;
            let result = py.detach(|| {
                run_steps(options, &inputs, trace, |tau| {
                    let telemetry = *world.step(tau);
                    if let Some(log) = log.as_mut() {
                        log.record(world, None)?;
                    }
                    Ok((telemetry, world.failure().is_some()))
                })
            });
            let (trace, steps) = result.map_err(|e| log_error(py, e))?;
            finish_log(py, log)?;
            finish_run(py, trace, steps, self.inner.failure(), log_path.as_deref())
        }
    }
}
