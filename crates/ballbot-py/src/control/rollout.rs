//! Batch closed-loop rollouts on the nonlinear WIP, in Rust without the GIL, and the steady
//! accelerating command.

use super::controllers::{PyLqrController, PyLqrPiOuter, PyPiPdController, PySpeedPi};
use crate::arrays::{Rows, array_out, reserve, rows};
use crate::enums::step_status_code;
use crate::errors::{Kind, error};
use crate::models::PyWip;
use crate::results::Array;
use ballbot_core::rates::OUTER_LOOP_DT_SECS;
use ballbot_core::{Wip, WipState};
use ballbot_sim::planar::{PlanarError, RolloutController, RolloutSettings, rollout};
use nalgebra::Vector4;
use numpy::{AllowTypeChange, PyArray1, PyArrayDyn, PyArrayLikeDyn};
use pyo3::prelude::*;
use schemars::JsonSchema;

type Arr<'py> = PyArrayLikeDyn<'py, f64, AllowTypeChange>;

/// Runs `n_steps` controller periods from each initial state on the planar simulator's
/// scheduler (`ballbot_sim::planar::rollout`, the one planar loop); appends the flat states
/// (per trajectory `n_steps + 1` rows of 4), torques and status codes (`n_steps` each).
#[allow(clippy::too_many_arguments)]
pub(crate) fn run_rollouts(
    plant: &Wip<f64>,
    controller: &RolloutController,
    initial: &[[f64; 4]],
    commands: &[[f64; 4]],
    settings: &RolloutSettings,
    states: &mut Vec<f64>,
    torques: &mut Vec<f64>,
    statuses: &mut Vec<i8>,
) -> Result<(), PlanarError> {
    let commands: Vec<WipState<f64>> = commands.iter().map(|c| Vector4::from(*c)).collect();
    for s0 in initial {
        let run = rollout(
            *plant.params(),
            controller,
            Vector4::from(*s0),
            &commands,
            settings,
        )?;
        for s in &run.states {
            states.extend_from_slice(s.as_slice());
        }
        torques.extend_from_slice(&run.torque_nm);
        statuses.extend(run.status.iter().map(|s| step_status_code(*s)));
    }
    Ok(())
}

/// Closed-loop rollouts of `controller` on the nonlinear WIP `plant`, entirely in Rust and
/// without the GIL.
///
/// From each initial state (`(4,)`, or `(n, 4)` for a batch) the controller (a copy of it, as
/// it is now: the caller's object is not stepped) runs `n_steps` periods of `dt_secs` (default
/// 1/400 s). Its torque is held over the period while the plant advances by `substeps` RK4
/// steps. An `LqrPiOuter` needs its inner loop `inner` (a `SpeedPi`), which then runs at every
/// substep in the drive, on the joint (motor) rate its encoder measures, the ball-rate
/// reference shifted by the tilt rate of the outer sample (the paper: 400 Hz outer, 8 kHz inner,
/// `substeps=20`). The loop is the planar simulator's scheduler on the ideal WIP (no friction,
/// no actuator limit beyond the controllers' own, perfect sensors, no delay); a state that
/// becomes non-finite ends the trajectory with NaN rows of status `invalid_input`.
/// `command` is a WIP state `(4,)` held throughout, or one per period `(n_steps, 4)`.
///
/// Returns a `Rollout`: `time_secs` `(n_steps + 1,)`; `state` `(n_steps + 1, 4)` or
/// `(n, n_steps + 1, 4)`; `torque_nm` (the mean torque applied over each period) and `status`
/// (int8 codes, `StepStatus.from_code`) `(n_steps,)` or `(n, n_steps)`; and
/// `compute_secs`, the time spent in the Rust loop. Raises `ParameterError` for a bad
/// `dt_secs`/`substeps`/`inner`, `ShapeError` for bad shapes, `MemoryError` when the result
/// cannot be allocated.
#[pyfunction]
#[pyo3(signature = (
    plant, controller, initial_state, *, n_steps, dt_secs = OUTER_LOOP_DT_SECS, command = None,
    inner = None, substeps = 1,
))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn closed_loop_rollout<'py>(
    py: Python<'py>,
    plant: PyRef<'py, PyWip>,
    controller: &Bound<'py, PyAny>,
    initial_state: Arr<'py>,
    n_steps: usize,
    dt_secs: f64,
    command: Option<Arr<'py>>,
    inner: Option<PyRef<'py, PySpeedPi>>,
    substeps: usize,
) -> PyResult<Bound<'py, PyAny>> {
    if !(dt_secs.is_finite() && dt_secs > 0.0) {
        return Err(error(
            py,
            Kind::Parameter,
            "invalid parameter `dt_secs`: must be finite and > 0",
        ));
    }
    if substeps == 0 {
        return Err(error(
            py,
            Kind::Parameter,
            "invalid parameter `substeps`: must be >= 1",
        ));
    }
    let ctrl = if let Ok(c) = controller.cast::<PyLqrController>() {
        RolloutController::Lqr(c.borrow().inner)
    } else if let Ok(c) = controller.cast::<PyPiPdController>() {
        RolloutController::PiPd(c.borrow().inner)
    } else if let Ok(c) = controller.cast::<PyLqrPiOuter>() {
        let Some(inner) = &inner else {
            return Err(error(
                py,
                Kind::Parameter,
                "an LqrPiOuter controller needs its inner loop: pass `inner=SpeedPi(...)`",
            ));
        };
        RolloutController::LqrPi {
            outer: c.borrow().inner,
            inner: inner.inner,
        }
    } else {
        return Err(pyo3::exceptions::PyTypeError::new_err(
            "`controller` must be an LqrController, PiPdController or LqrPiOuter",
        ));
    };
    if inner.is_some() && !matches!(ctrl, RolloutController::LqrPi { .. }) {
        return Err(error(
            py,
            Kind::Parameter,
            "`inner` is only used with an LqrPiOuter controller",
        ));
    }
    let init: Rows<4> = rows(py, &initial_state, "initial_state")?;
    let commands = match &command {
        Some(c) => {
            let c: Rows<4> = rows(py, c, "command")?;
            if !c.single && c.rows.len() != n_steps {
                return Err(error(
                    py,
                    Kind::Shape,
                    format!(
                        "`command` must have shape (4,) or (n_steps, 4) = ({n_steps}, 4), got \
                         ({}, 4)",
                        c.rows.len()
                    ),
                ));
            }
            if c.rows.is_empty() {
                vec![[0.0; 4]]
            } else {
                c.rows
            }
        }
        None => vec![[0.0; 4]],
    };
    let n = init.rows.len();
    let too_big = || {
        pyo3::exceptions::PyMemoryError::new_err(format!(
            "a rollout of {n} trajectories x {n_steps} steps is too large"
        ))
    };
    let state_len = n
        .checked_mul(n_steps.checked_add(1).ok_or_else(too_big)?)
        .and_then(|x| x.checked_mul(4))
        .ok_or_else(too_big)?;
    let step_len = n.checked_mul(n_steps).ok_or_else(too_big)?;
    let mut states = reserve::<f64>(state_len)?;
    let mut torques = reserve::<f64>(step_len)?;
    let mut statuses = reserve::<i8>(step_len)?;
    let wip = plant.inner;
    let settings = RolloutSettings {
        dt_secs,
        n_steps,
        substeps,
    };
    let (result, compute_secs) = py.detach(|| {
        let start = std::time::Instant::now();
        let result = run_rollouts(
            &wip,
            &ctrl,
            &init.rows,
            &commands,
            &settings,
            &mut states,
            &mut torques,
            &mut statuses,
        );
        (result, start.elapsed().as_secs_f64())
    });
    result.map_err(|e| error(py, Kind::Parameter, e.to_string()))?;
    let time: Vec<f64> = (0..=n_steps).map(|k| k as f64 * dt_secs).collect();
    let (state_shape, step_shape): (Vec<usize>, Vec<usize>) = if init.single {
        (vec![n_steps + 1, 4], vec![n_steps])
    } else {
        (vec![n, n_steps + 1, 4], vec![n, n_steps])
    };
    let status: Bound<'py, PyArrayDyn<i8>> = {
        use numpy::PyArrayMethods;
        PyArray1::from_vec(py, statuses)
            .reshape(step_shape.as_slice())?
            .to_dyn()
            .clone()
    };
    let view = RolloutView {
        time_secs: PyArray1::from_vec(py, time),
        state: array_out(py, states, &state_shape)?,
        torque_nm: array_out(py, torques, &step_shape)?,
        status,
        compute_secs,
    };
    crate::results::build_objects(py, view)
}

/// Closed-loop rollouts (`closed_loop_rollout`): one trajectory or a batch.
// The arrays are made from the Rust buffers (no copy), not through `pythonize`: a rollout of
// 500 x 2000 steps is 40 MB of states.
#[derive(IntoPyObject, JsonSchema)]
#[schemars(rename = "Rollout")]
pub(crate) struct RolloutView<'py> {
    /// Time of each state (s), `(n_steps + 1,)`.
    #[schemars(with = "Array", extend("x-python-dtype" = "f8"))]
    time_secs: Bound<'py, PyArray1<f64>>,
    /// States `[theta, phi, theta_dot, phi_dot]`, `(n_steps + 1, 4)` or `(n, n_steps + 1, 4)`.
    #[schemars(with = "Array", extend("x-python-dtype" = "f8"))]
    state: Bound<'py, PyArrayDyn<f64>>,
    /// Mean torque applied over each period (N m), `(n_steps,)` or `(n, n_steps)`.
    #[schemars(with = "Array", extend("x-python-dtype" = "f8"))]
    torque_nm: Bound<'py, PyArrayDyn<f64>>,
    /// Step status codes (`StepStatus.from_code`/`decode`), shaped as `torque_nm`.
    #[schemars(with = "Array", extend("x-python-dtype" = "i1"))]
    status: Bound<'py, PyArrayDyn<i8>>,
    /// Time spent in the Rust loop (s).
    compute_secs: f64,
}

/// The steady command that accelerates the ball at `ball_accel_rad_per_s2` while rolling at
/// `ball_rate_rad_per_s` on `wip`'s nonlinear model (`theta_dot = 0`, constant `phi_ddot`):
/// `(command_state (4,), torque_nm)`, the lean and torque that hold that acceleration; `None`
/// when no lean can hold it (or for non-finite input).
#[pyfunction(name = "accelerating_command")]
pub(crate) fn py_accelerating_command<'py>(
    py: Python<'py>,
    wip: PyRef<'py, PyWip>,
    ball_rate_rad_per_s: f64,
    ball_accel_rad_per_s2: f64,
) -> Option<(Bound<'py, PyArray1<f64>>, f64)> {
    ballbot_core::control::accelerating_command(
        &wip.inner,
        ball_rate_rad_per_s,
        ball_accel_rad_per_s2,
    )
    .map(|(s, tau)| (PyArray1::from_slice(py, s.as_slice()), tau))
}
