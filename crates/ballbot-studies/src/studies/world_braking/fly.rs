//! One braking run in the 3D world: the approach, the cruise, and the planned trajectory
//! flown by the core's controller to rest, with the samples and peaks the study reports.

use super::*;
use ballbot_core::command::TrajectoryLimits;
use ballbot_world::rig::{Happened, OutcomeTracker, WorldRobot};
use ballbot_world::world::failure::tilt_from_vertical_rad;
use ballbot_world::world::telemetry::StepTelemetry;

/// `samples` (period `period_secs`) linearly interpolated at `t_secs`, held after the end.
fn sample_linear(samples: &[WipState<f64>], period_secs: f64, t_secs: f64) -> WipState<f64> {
    let x = (t_secs / period_secs).max(0.0);
    let k = x.floor() as usize;
    match (samples.get(k), samples.get(k + 1)) {
        (Some(a), Some(b)) => a + (b - a) * (x - k as f64),
        (Some(a), None) => *a,
        _ => samples.last().copied().unwrap_or_else(WipState::zeros),
    }
}

/// Ball speed along the heading in the body's yaw frame, signed tilt in the plane of the
/// heading, and the ball's velocity in the yaw frame (m/s: x, y).
fn along_heading(tel: &StepTelemetry, cos_h: f64, sin_h: f64) -> (f64, f64, [f64; 2]) {
    let v_body = tel.ball_velocity_yaw_frame_m_per_s();
    let speed = v_body.x * cos_h + v_body.y * sin_h;
    // The command maps a planar tilt to the sagittal plane as cos(h) and to the frontal plane
    // as -sin(h); project back the same way.
    let tilt = cos_h * tel.tilt_rad[1] - sin_h * tel.tilt_rad[0];
    (speed, tilt, [v_body.x, v_body.y])
}

fn actuator_utilisation(world_params: &WorldParams, tel: &StepTelemetry) -> [f64; 3] {
    let actuator = world_params.robot.drivetrain.actuator;
    tel.wheels.map(|w| {
        let (lo, hi) = actuator.torque_bounds_nm(w.speed_rad_per_s);
        let bound = if w.motor_torque_nm >= 0.0 { hi } else { lo };
        if bound.abs() > 1e-12 {
            (w.motor_torque_nm / bound).abs()
        } else if w.motor_torque_nm == 0.0 {
            0.0
        } else {
            1.0
        }
    })
}

/// Runs one braking experiment: settle, jerk-limited ramp to the cruise speed along
/// `heading_deg`, cruise, then the optimal braking trajectory to rest in `duration_secs`
/// (solved here, warm-started from `warm`; `None`: from the solver's cold start, what the
/// braking study's every trial does), followed until the end of the rest window.
pub fn braking_run(
    world_params: WorldParams,
    params: &BrakingParams,
    heading_deg: f64,
    duration_secs: f64,
    warm: Option<&Trajectory>,
) -> Result<BrakingRun, BrakingError> {
    braking_run_observed(
        world_params,
        params,
        heading_deg,
        duration_secs,
        warm,
        &mut |_, _| {},
    )
}

/// [`braking_run`] calling `observe` after every physics step of the flight, as
/// [`fly_braking`] does (nothing is flown, and `observe` never called, when no trajectory is
/// found). The run is the same with or without an observer.
pub fn braking_run_observed(
    world_params: WorldParams,
    params: &BrakingParams,
    heading_deg: f64,
    duration_secs: f64,
    warm: Option<&Trajectory>,
    observe: &mut dyn FnMut(&WorldRobot, Option<&VelocityCommand<f64>>),
) -> Result<BrakingRun, BrakingError> {
    params.validate()?;
    if !(duration_secs.is_finite() && duration_secs > 0.0) {
        return Err(invalid("duration_secs", "must be finite and > 0"));
    }
    if !heading_deg.is_finite() {
        return Err(invalid("heading_deg", "must be finite"));
    }
    let plan = plan_braking(
        &world_params.robot,
        params,
        heading_deg,
        duration_secs,
        warm,
    )?;
    if !plan.is_solved() {
        let config = braking_controller_config(&world_params.robot)?;
        return Ok(BrakingRun {
            heading_deg,
            duration_secs,
            outcome: BrakingOutcome::NoTrajectory {
                status: plan.status,
            },
            brake_start_secs: brake_start_step(&world_params, params, &config) as f64
                * world_params.dt_secs,
            plan: None,
            plan_peak_tilt_rad: None,
            plan_cost_n2m2s: None,
            peaks: BrakingPeaks::default(),
            samples: Vec::new(),
            telemetry_hash: ballbot_world::world::telemetry::FNV_OFFSET_BASIS,
            happened: None,
        });
    }
    let mut run = fly_braking(world_params, params, heading_deg, &plan.trajectory, observe)?;
    run.plan_cost_n2m2s = Some(plan.cost_n2m2s);
    Ok(run)
}

/// The physics step at which braking starts: after settle, approach and cruise, rounded up to
/// an outer-loop step, so the outer loop samples the trajectory exactly at its sample times.
pub(super) fn brake_start_step(
    world_params: &WorldParams,
    params: &BrakingParams,
    config: &BallbotControllerConfig<f64>,
) -> u64 {
    let dt = world_params.dt_secs;
    let steps_per_outer = (config.outer_dt_secs / dt).round().max(1.0) as u64;
    let before_brake_secs = params.settle_secs + params.approach_secs() + params.cruise_secs;
    (before_brake_secs / dt / steps_per_outer as f64).ceil() as u64 * steps_per_outer
}

/// Flies one braking run with a given braking trajectory `plan` (its duration is the braking
/// time), calling `observe` after every physics step with the loop and, before braking, the
/// velocity command of that step (e.g. to write an MCAP log with
/// [`ballbot_log::WorldLogger`]). The run is the same with or without an observer, and
/// [`braking_run`] is this with the plan it solves, so replaying a run's
/// [`BrakingRun::plan`] reproduces it bit for bit.
pub fn fly_braking(
    world_params: WorldParams,
    params: &BrakingParams,
    heading_deg: f64,
    plan: &Trajectory,
    observe: &mut dyn FnMut(&WorldRobot, Option<&VelocityCommand<f64>>),
) -> Result<BrakingRun, BrakingError> {
    params.validate()?;
    if !heading_deg.is_finite() {
        return Err(invalid("heading_deg", "must be finite"));
    }
    let duration_secs = plan.duration_secs();
    let config = braking_controller_config(&world_params.robot)?;
    let dt = world_params.dt_secs;
    let brake_step = brake_start_step(&world_params, params, &config);
    let heading_rad = heading_deg.to_radians();
    let plane = plane_for_heading(&world_params.robot, heading_rad);
    let mut run = BrakingRun {
        heading_deg,
        duration_secs,
        outcome: BrakingOutcome::NoTrajectory {
            status: SolveStatus::Solved,
        },
        brake_start_secs: brake_step as f64 * dt,
        plan: Some(plan.clone()),
        plan_peak_tilt_rad: Some(
            plan.knot_states()
                .iter()
                .fold(0.0, |m: f64, s| m.max(s[0].abs())),
        ),
        plan_cost_n2m2s: None,
        peaks: BrakingPeaks::default(),
        samples: Vec::new(),
        telemetry_hash: ballbot_world::world::telemetry::FNV_OFFSET_BASIS,
        happened: None,
    };
    let radius = plane.ball_radius_m;
    let period = config.outer_dt_secs;
    let physical: Vec<WipState<f64>> = plan.sample(period).into_iter().map(|(_, s, _)| s).collect();
    let mut states = physical.clone();
    if params.feedforward == TrajectoryFeedforward::Core {
        // The core shifts the commanded tilt theta_c by c(theta_c) theta_ddot* / k1
        // (theta_ddot*: slope of the tilt rate on the interval starting at the sample); the
        // sample's tilt theta_c solves theta_c + c(theta_c) theta_ddot* / k1 = theta* (a few
        // fixed-point steps: the shift is a contraction, |dc/dtheta theta_ddot* / k1| << 1).
        let (lqr, robot_plane) = if heading_rad.cos().abs() >= heading_rad.sin().abs() {
            (config.sagittal.lqr, config.robot.sagittal)
        } else {
            (config.frontal.lqr, config.robot.frontal)
        };
        let mrl = robot_plane.body_mass_kg * robot_plane.ball_radius_m * robot_plane.com_height_m;
        let coupling = |tilt: f64| mrl * tilt.cos() - robot_plane.wheel_inertia_kg_m2;
        let k1 = lqr.tilt_nm_per_rad;
        if k1.is_finite() && k1 != 0.0 {
            for (k, s) in states.iter_mut().enumerate() {
                let next = physical.get(k + 1).unwrap_or(&physical[k]);
                let tilt_accel = (next[2] - physical[k][2]) / period;
                let planned = physical[k][0];
                for _ in 0..4 {
                    s[0] = planned - coupling(s[0]) * tilt_accel / k1;
                }
            }
        }
    }
    // The protocol flies the plan as it is, also where the controller's trajectory limits
    // would refuse it (a short braking time whose speed-up passes the shaper's speed clamp; the
    // `Core` ablation, whose shifted tilts are not the integral of its tilt rates): such a plan
    // is built against limits that only ask for the outer period, and the shaper's clamps apply
    // as they always did. A robot binary accepts trajectories with
    // `BallbotController::accept_trajectory` instead.
    let robot_error = |e| BrakingError::World(WorldError::Robot(e));
    let limits = config.trajectory_limits().map_err(robot_error)?;
    let command_trajectory = match CommandTrajectory::new(&states, period, heading_rad, &limits) {
        Ok(t) => t,
        Err(_) => CommandTrajectory::new(&states, period, heading_rad, &protocol_limits(&limits))
            .map_err(robot_error)?,
    };

    let mut sim = WorldRobot::with_config(world_params, config)?;
    sim.world_mut().set_stop_rules(params.stop_rules);
    let mut judge = OutcomeTracker::default();
    let (sin_h, cos_h) = heading_rad.sin_cos();
    let ramp_limits = AxisLimits {
        max_value: params.cruise_speed_m_per_s,
        max_rate_per_s: params.approach_accel_m_per_s2,
        max_jerk_per_s2: params.approach_jerk_m_per_s3,
    };
    let mut ramp = JerkLimiter::at(0.0);
    let settle_steps = (params.settle_secs / dt).round() as u64;
    let rest_from_step =
        brake_step + ((duration_secs + params.rest_within_secs) / dt).round() as u64;
    let end_step = rest_from_step + (params.rest_hold_secs / dt).round() as u64;
    let every = (params.sample_every_secs / dt).round().max(1.0) as u64;
    let after_failure_steps = (AFTER_FAILURE_SECS / dt).round() as u64;
    let plan_steps = (duration_secs / dt).round() as u64;
    let mut failed_at: Option<u64> = None;
    let mut peaks = BrakingPeaks {
        min_normal_force_n: [f64::INFINITY; 3],
        ..BrakingPeaks::default()
    };
    let slip_threshold = world_params.failure.slip_speed_threshold_m_per_s;
    let (mut rest_speed, mut rest_tilt) = (0.0_f64, 0.0_f64);
    run.samples
        .reserve((end_step / every + 1).min(1 << 20) as usize);
    for k in 0..end_step {
        let (command, command_speed, command_tilt) = if k < brake_step {
            let v = if k >= settle_steps {
                ramp.step(params.cruise_speed_m_per_s, &ramp_limits, dt)
            } else {
                0.0
            };
            let cmd = VelocityCommand {
                vx_m_per_s: v * cos_h,
                vy_m_per_s: v * sin_h,
                yaw_rate_rad_per_s: 0.0,
            };
            (Command::Velocity(cmd), v, 0.0)
        } else {
            let t = (k - brake_step) as f64 * dt;
            let s = sample_linear(&physical, period, t);
            let cmd = Command::Trajectory {
                trajectory: command_trajectory,
                time_secs: t,
            };
            (cmd, s[3] * radius, s[0])
        };
        let tel = *sim.step(command);
        match command {
            Command::Velocity(v) => observe(&sim, Some(&v)),
            _ => observe(&sim, None),
        }
        tel.hash_into(&mut run.telemetry_hash);
        let (speed, tilt, v_yaw) = along_heading(&tel, cos_h, sin_h);
        let braking = k >= brake_step;
        if failed_at.is_none() {
            // The plan ends at rest: past its end the command is to stand.
            let planned = if k >= brake_step + plan_steps {
                0.0
            } else {
                command_speed
            };
            judge.update(&sim, v_yaw, [planned * cos_h, planned * sin_h]);
        }
        let utilisation = if braking || k % every == 0 {
            actuator_utilisation(&world_params, &tel)
        } else {
            [0.0; 3]
        };
        let failed = failed_at.is_some();
        if braking && !failed {
            let p = &mut peaks;
            for (i, w) in tel.wheels.iter().enumerate() {
                p.cone_utilisation[i] = p.cone_utilisation[i].max(w.cone_utilisation);
                p.min_normal_force_n[i] = p.min_normal_force_n[i].min(w.normal_force_n);
                p.actuator_utilisation[i] = p.actuator_utilisation[i].max(utilisation[i]);
            }
            if tel
                .wheels
                .iter()
                .any(|w| w.slipping && w.slip_speed_m_per_s.abs() > slip_threshold)
            {
                p.slip_secs += dt;
            }
            p.tilt_rad = p.tilt_rad.max(tilt_from_vertical_rad(&tel));
            p.speed_error_m_per_s = p.speed_error_m_per_s.max((command_speed - speed).abs());
        }
        if k % every == 0 {
            run.samples.push(BrakingSample {
                time_secs: tel.time_secs,
                command_m_per_s: command_speed,
                speed_m_per_s: speed,
                command_tilt_rad: command_tilt,
                tilt_rad: tilt,
                cone_utilisation: tel.wheels.map(|w| w.cone_utilisation),
                normal_force_n: tel.wheels.map(|w| w.normal_force_n),
                actuator_utilisation: utilisation,
            });
        }
        if k >= rest_from_step && !failed {
            let v = &tel.ball_velocity_m_per_s;
            rest_speed = rest_speed.max(v.x.hypot(v.y));
            rest_tilt = rest_tilt.max(tilt_from_vertical_rad(&tel));
        }
        match (failed_at, sim.world().failure()) {
            (None, Some(failure)) => {
                run.outcome = BrakingOutcome::Failed(failure);
                failed_at = Some(k);
            }
            (Some(at), _) if k >= at + after_failure_steps => break,
            _ => {}
        }
    }
    if !matches!(run.outcome, BrakingOutcome::Failed(_)) {
        run.outcome =
            if rest_speed <= params.rest_speed_m_per_s && rest_tilt <= params.rest_tilt_rad {
                BrakingOutcome::Stopped {
                    rest_speed_m_per_s: rest_speed,
                }
            } else {
                BrakingOutcome::NotAtRest {
                    rest_speed_m_per_s: rest_speed,
                    rest_tilt_rad: rest_tilt,
                }
            };
    }
    // Never braked (failed before): no normal-force extreme to report.
    for n in &mut peaks.min_normal_force_n {
        if !n.is_finite() {
            *n = 0.0;
        }
    }
    run.peaks = peaks;
    run.happened = Some(Happened::of(&sim, &judge));
    Ok(run)
}

/// Limits that ask only for the controller's sample period (see [`fly_braking`]).
fn protocol_limits(controller: &TrajectoryLimits<f64>) -> TrajectoryLimits<f64> {
    TrajectoryLimits {
        min_sample_period_secs: controller.min_sample_period_secs,
        max_tilt_rad: f64::MAX,
        max_tilt_rate_rad_per_s: f64::MAX,
        max_ball_rate_rad_per_s: f64::MAX,
        max_ball_accel_rad_per_s2: f64::MAX,
        max_torque_nm: f64::MAX,
        tilt_inertia_kg_m2: f64::MIN_POSITIVE,
        ball_inertia_kg_m2: f64::MIN_POSITIVE,
        lean_per_tilt_accel_s2: f64::MIN_POSITIVE,
        lean_per_ball_accel_s2: f64::MIN_POSITIVE,
    }
}
