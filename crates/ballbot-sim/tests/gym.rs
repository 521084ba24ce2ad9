//! The reinforcement-learning environments: seeding, termination and truncation (stop rules,
//! falls) and the contact events, the observation against the world, sensor delay, pushes, the
//! LQR-PI underneath, and the vector env against single environments.

use ballbot_sim::gym::{
    BallbotEnv, EnvConfig, GymError, Randomization, ResetOptions, StepOutcome, Task, Termination,
    VecEnv, VecInfo, VecStep,
};
use ballbot_sim::rig::{Event, EventKind};
use ballbot_sim::world::{FailureKind, StopRules};

fn quiet(mut config: EnvConfig) -> EnvConfig {
    config.world.sensors.tilt_noise_rad = 0.0;
    config.world.sensors.gyro_noise_rad_per_s = 0.0;
    config
}

/// Observations and rewards of `steps` steps with a fixed policy `action(obs)`.
fn rollout(
    env: &mut BallbotEnv,
    seed: u64,
    steps: usize,
    action: impl Fn(&[f32]) -> [f64; 3],
) -> (Vec<Vec<f32>>, Vec<f64>, bool) {
    let mut obs = vec![0.0_f32; env.observation_len()];
    env.reset(Some(seed), None, &mut obs).unwrap();
    let (mut all, mut rewards) = (vec![obs.clone()], Vec::new());
    for _ in 0..steps {
        let out = env.step(action(&obs), &mut obs).unwrap();
        all.push(obs.clone());
        rewards.push(out.reward);
        if out.terminated || out.truncated {
            return (all, rewards, out.terminated);
        }
    }
    (all, rewards, false)
}

/// A hand-tuned tilt feedback on the wheel torques: not a good controller, a scripted policy
/// that reacts to the observation.
fn lean_back(obs: &[f32]) -> [f64; 3] {
    let (roll, pitch) = (f64::from(obs[0]), f64::from(obs[1]));
    [0.3 * pitch, -0.2 * roll, 0.1 * roll]
}

#[test]
fn a_seed_replays_an_episode_bit_for_bit_and_another_seed_differs() {
    let mut config = EnvConfig::new(Task::Balance);
    config.randomization = Randomization::recommended();
    let mut env = BallbotEnv::new(config).unwrap();
    let a = rollout(&mut env, 11, 200, lean_back);
    let b = rollout(&mut env, 11, 200, lean_back);
    let c = rollout(&mut env, 12, 200, lean_back);
    assert_eq!(a, b);
    assert_ne!(a.0[0], c.0[0]);
}

#[test]
fn without_torque_a_tilted_robot_falls_terminated_and_must_be_reset() {
    let mut env = BallbotEnv::new(quiet(EnvConfig::new(Task::Balance))).unwrap();
    let mut obs = vec![0.0_f32; env.observation_len()];
    let options = ResetOptions {
        initial_tilt_rad: Some([0.0, 0.1]),
        ..ResetOptions::default()
    };
    env.reset(Some(0), Some(&options), &mut obs).unwrap();
    let mut steps = 0;
    let out = loop {
        let out = env.step([0.0; 3], &mut obs).unwrap();
        steps += 1;
        if out.terminated || out.truncated {
            break out;
        }
    };
    assert!(out.terminated && !out.truncated);
    let failure = out.info.failure.expect("a world failure ends the episode");
    assert_eq!(failure.kind.as_str(), "tilt");
    let termination = out.info.termination.expect("terminated has a reason");
    assert_eq!(termination, Termination::StopRule(failure.kind));
    assert!(termination.is_fall(), "the tilt rule is a fall");
    // A 0.1 rad tilt of a 0.5 m pendulum takes some 0.4 s to reach 25 deg.
    assert!((100..400).contains(&steps), "fell after {steps} steps");
    assert!(
        out.reward < 0.0,
        "no alive reward for the fall: {}",
        out.reward
    );
    assert!(matches!(
        env.step([0.0; 3], &mut obs),
        Err(GymError::NeedsReset(_))
    ));
}

#[test]
fn the_observation_is_the_imu_and_lies_in_its_box() {
    let mut env = BallbotEnv::new(quiet(EnvConfig::new(Task::Balance))).unwrap();
    let mut obs = vec![0.0_f32; env.observation_len()];
    // Tilt about world x by 0.05 rad: the IMU's roll, not its pitch.
    let options = ResetOptions {
        initial_tilt_rad: Some([0.05, 0.0]),
        ..ResetOptions::default()
    };
    env.reset(Some(0), Some(&options), &mut obs).unwrap();
    assert!((obs[0] - 0.05).abs() < 1e-3, "roll {}", obs[0]);
    assert!(obs[1].abs() < 1e-3, "pitch {}", obs[1]);
    let high = env.observation_high().to_vec();
    for _ in 0..300 {
        let out = env.step([1.0, -1.0, 1.0], &mut obs).unwrap();
        for (o, h) in obs.iter().zip(&high) {
            assert!(o.abs() <= *h, "{o} outside +-{h}");
        }
        if out.terminated {
            break;
        }
    }
}

#[test]
fn a_sensor_delay_shows_the_observation_of_earlier_steps() {
    let tilt = ResetOptions {
        initial_tilt_rad: Some([0.0, 0.08]),
        ..ResetOptions::default()
    };
    let run = |delay_secs: f64| {
        let mut config = quiet(EnvConfig::new(Task::Balance));
        config.randomization.sensor_delay_secs = Some(delay_secs.into());
        let mut env = BallbotEnv::new(config).unwrap();
        let mut obs = vec![0.0_f32; env.observation_len()];
        env.reset(Some(0), Some(&tilt), &mut obs).unwrap();
        let mut pitch = vec![obs[1]];
        for _ in 0..60 {
            env.step([0.0; 3], &mut obs).unwrap();
            pitch.push(obs[1]);
        }
        pitch
    };
    let (now, late) = (run(0.0), run(0.010));
    // 10 ms is four agent steps at 400 Hz.
    assert_eq!(&late[4..], &now[..now.len() - 4]);
    assert_ne!(late, now);
}

#[test]
fn pushes_come_at_the_drawn_interval_and_move_the_body() {
    let run = |impulse_ns: f64| {
        let mut config = quiet(EnvConfig::new(Task::Velocity));
        config.randomization.push_impulse_ns = Some(impulse_ns.into());
        config.randomization.push_interval_secs = Some(0.5.into());
        let mut env = BallbotEnv::new(config).unwrap();
        let mut obs = vec![0.0_f32; env.observation_len()];
        let options = ResetOptions {
            command: Some([0.0; 3]),
            ..ResetOptions::default()
        };
        env.reset(Some(5), Some(&options), &mut obs).unwrap();
        let (mut pushed_at, mut body_x) = (Vec::new(), Vec::new());
        for k in 0..450 {
            let out = env.step([0.0; 3], &mut obs).unwrap();
            if let Some(j) = out.info.push_ns {
                assert!((j[0].hypot(j[1]) - impulse_ns).abs() < 1e-9);
                pushed_at.push(k);
            }
            body_x.push(env.telemetry().unwrap().body_position_m);
            assert!(!out.terminated, "the LQR-PI rides out 15 N s pushes");
        }
        (pushed_at, body_x)
    };
    let ((pushed_at, pushed), (_, still)) = (run(15.0), run(0.0));
    assert_eq!(pushed_at, vec![200, 400]);
    assert_eq!(
        pushed[199], still[199],
        "nothing differs before the first push"
    );
    let moved = (pushed[240] - still[240]).norm();
    assert!(moved > 0.01, "the push moved the body by {moved} m");
}

#[test]
fn the_lqr_pi_underneath_tracks_a_command_and_earns_the_alive_reward() {
    let mut config = quiet(EnvConfig::new(Task::Velocity));
    config.max_episode_secs = 6.0;
    let mut env = BallbotEnv::new(config).unwrap();
    let mut obs = vec![0.0_f32; env.observation_len()];
    let options = ResetOptions {
        command: Some([0.5, 0.0, 0.0]),
        ..ResetOptions::default()
    };
    env.reset(Some(0), Some(&options), &mut obs).unwrap();
    let mut steps = 0;
    let out = loop {
        let out = env.step([0.0; 3], &mut obs).unwrap();
        steps += 1;
        if out.terminated || out.truncated {
            break out;
        }
    };
    assert!(out.truncated && !out.terminated, "6 s: the time limit");
    assert_eq!(steps, 2400);
    let v = env.telemetry().unwrap().ball_velocity_m_per_s;
    assert!(
        (v.x - 0.5).abs() < 0.05 && v.y.abs() < 0.05,
        "ball at {v:?}"
    );
    assert!(
        out.reward > 0.9,
        "tracking earns nearly 1 per step: {}",
        out.reward
    );
    assert_eq!(&obs[9..12], &[0.5, 0.0, 0.0]);
}

#[test]
fn a_full_residual_changes_what_the_drivers_apply() {
    let mut config = quiet(EnvConfig::new(Task::Velocity));
    config.residual_fraction = 0.1;
    let fixed = ResetOptions {
        command: Some([0.0; 3]),
        ..ResetOptions::default()
    };
    let torque_after = |action: [f64; 3]| {
        let mut env = BallbotEnv::new(config).unwrap();
        let mut obs = vec![0.0_f32; env.observation_len()];
        env.reset(Some(0), Some(&fixed), &mut obs).unwrap();
        env.step(action, &mut obs).unwrap();
        env.telemetry().unwrap().wheels.map(|w| w.motor_torque_nm)
    };
    let (base, pushed) = (torque_after([0.0; 3]), torque_after([1.0, 0.0, -1.0]));
    let peak = config.world.robot.drivetrain.actuator.peak_torque_nm;
    // The controller reacts within the step too, so only the sign and the order are checked:
    // at least a quarter of the residual is left at the end of the step. (Before the
    // world modelled the drivetrain more than half was left; the motor side the encoder reads is
    // lighter than wheel and rotor together, so the inner PI sees the residual sooner.)
    assert!(
        pushed[0] - base[0] > 0.25 * 0.1 * peak,
        "{base:?} {pushed:?}"
    );
    assert!(
        pushed[2] - base[2] < -0.25 * 0.1 * peak,
        "{base:?} {pushed:?}"
    );
}

/// Regression: the loop's motor-health monitor compared the drivers' torque, residual
/// included, with the loop's own setpoint, so a residual above its tolerance (about action
/// 0.25 at the default fraction) tripped `MotorStuck` and switched the motors off within a
/// few steps. The residual is now taken off the feedback the loop reads.
#[test]
fn a_large_residual_does_not_read_as_a_stuck_motor() {
    let mut config = quiet(EnvConfig::new(Task::Velocity));
    config.max_episode_secs = 0.5;
    let mut env = BallbotEnv::new(config).unwrap();
    let mut obs = vec![0.0_f32; env.observation_len()];
    let fixed = ResetOptions {
        command: Some([0.0; 3]),
        ..ResetOptions::default()
    };
    env.reset(Some(0), Some(&fixed), &mut obs).unwrap();
    // Alternating +-0.5 on one wheel: a large residual the controller can balance against.
    for k in 0..200 {
        let a = if (k / 10) % 2 == 0 { 0.5 } else { -0.5 };
        let out = env.step([a, 0.0, 0.0], &mut obs).unwrap();
        assert!(
            !out.terminated,
            "step {k}: {:?}",
            out.info.termination.map(|t| t.as_str())
        );
        if out.truncated {
            break;
        }
    }
}

#[test]
fn bad_configuration_and_options_are_rejected_naming_the_field() {
    let mut config = EnvConfig::new(Task::Balance);
    config.control_hz = 300.0;
    let e = BallbotEnv::new(config).err().unwrap().to_string();
    assert!(e.contains("control_hz"), "{e}");
    let mut config = EnvConfig::new(Task::Balance);
    config.residual_fraction = 0.0;
    let e = BallbotEnv::new(config).err().unwrap().to_string();
    assert!(e.contains("residual_fraction"), "{e}");
    let mut env = BallbotEnv::new(EnvConfig::new(Task::Balance)).unwrap();
    let mut obs = vec![0.0_f32; env.observation_len()];
    assert!(matches!(
        env.step([0.0; 3], &mut obs),
        Err(GymError::NeedsReset(_))
    ));
    let options = ResetOptions {
        initial_tilt_rad: Some([0.0, 1.0]),
        ..ResetOptions::default()
    };
    let e = env.reset(None, Some(&options), &mut obs).unwrap_err();
    assert!(e.to_string().contains("initial_tilt_rad"), "{e}");
    env.reset(None, None, &mut obs).unwrap();
    let e = env.step([f64::NAN, 0.0, 0.0], &mut obs).unwrap_err();
    assert!(matches!(e, GymError::NonFiniteAction(_)));
    let e = env.step([0.0; 3], &mut obs[..5]).unwrap_err();
    assert!(e.to_string().contains("`obs`"), "{e}");
}

/// The vector env against single environments stepped and reset in the same order: the
/// outputs, the infos (terminations) and each environment's events of the step.
#[test]
fn the_vector_env_equals_single_envs_with_next_step_autoreset_on_any_thread_count() {
    let mut config = quiet(EnvConfig::new(Task::Balance));
    config.max_episode_secs = 0.2;
    config.randomization = Randomization::recommended();
    let n = 3;
    let seeds = [Some(7), Some(8), Some(9)];
    let actions = |k: usize| -> Vec<[f64; 3]> {
        (0..n)
            .map(|i| {
                let x = ((k * 7 + i * 3) % 11) as f64 / 5.0 - 1.0;
                [x, -x, 0.5 * x]
            })
            .collect()
    };
    let mut runs = Vec::new();
    for threads in [1, 2] {
        let mut envs = VecEnv::new(config, n, threads).unwrap();
        let mut obs = vec![0.0_f32; n * envs.observation_len()];
        envs.reset(&seeds, None, &mut obs).unwrap();
        let mut out = VecStep::default();
        let mut trace = vec![(obs.clone(), vec![], vec![], vec![], vec![], vec![])];
        let (mut resets, mut events) = (0, 0);
        for k in 0..250 {
            envs.step(&actions(k), &mut out).unwrap();
            resets += out
                .infos
                .iter()
                .filter(|i| matches!(i, VecInfo::Reset(_)))
                .count();
            let step_events: Vec<Vec<Event>> = envs
                .envs()
                .iter()
                .map(|e| e.step_events().copied().collect())
                .collect();
            events += step_events.iter().map(Vec::len).sum::<usize>();
            trace.push((
                out.obs.clone(),
                out.rewards.clone(),
                out.terminated.clone(),
                out.truncated.clone(),
                out.infos.clone(),
                step_events,
            ));
        }
        assert!(resets >= 3, "every env ended and was reset: {resets}");
        assert!(events > 0, "the full torques make contact events");
        runs.push(trace);
    }
    assert_eq!(runs[0], runs[1], "1 and 2 threads agree bit for bit");
    // Environment i alone.
    for i in 0..n {
        let mut env = BallbotEnv::new(config).unwrap();
        let len = env.observation_len();
        let mut obs = vec![0.0_f32; len];
        env.reset(seeds[i], None, &mut obs).unwrap();
        assert_eq!(&runs[0][0].0[i * len..(i + 1) * len], &obs[..]);
        let mut ended = false;
        for k in 0..250 {
            let (v_obs, v_rew, v_term, v_trunc, v_info, v_events) = &runs[0][k + 1];
            let (reward, term, trunc) = if ended {
                env.reset(None, None, &mut obs).unwrap();
                ended = false;
                assert!(matches!(v_info[i], VecInfo::Reset(_)), "env {i} step {k}");
                (0.0, false, false)
            } else {
                let o = env.step(actions(k)[i], &mut obs).unwrap();
                ended = o.terminated || o.truncated;
                assert_eq!(v_info[i], VecInfo::Step(o.info), "env {i} step {k}");
                (o.reward, o.terminated, o.truncated)
            };
            assert_eq!(&v_obs[i * len..(i + 1) * len], &obs[..], "env {i} step {k}");
            assert_eq!(
                (v_rew[i], v_term[i], v_trunc[i]),
                (reward, term, trunc),
                "env {i} step {k}"
            );
            let events: Vec<Event> = env.step_events().copied().collect();
            assert_eq!(v_events[i], events, "env {i} step {k}");
        }
    }
}

/// `steps` steps of Balance from upright (seed 0, no sensor noise) with `action` for the first
/// ten and nothing after, under `rules`: each step's outcome and events in progress.
fn lean_and_let_go(rules: StopRules, steps: usize) -> Vec<(StepOutcome, Vec<f32>, Vec<Event>)> {
    let mut config = quiet(EnvConfig::new(Task::Balance));
    config.stop_rules = rules;
    let mut env = BallbotEnv::new(config).unwrap();
    let mut obs = vec![0.0_f32; env.observation_len()];
    let upright = ResetOptions {
        initial_tilt_rad: Some([0.0, 0.0]),
        ..ResetOptions::default()
    };
    env.reset(Some(0), Some(&upright), &mut obs).unwrap();
    let mut trace = Vec::new();
    for k in 0..steps {
        let action = if k < 10 { [0.5, -0.5, 0.0] } else { [0.0; 3] };
        let out = env.step(action, &mut obs).unwrap();
        trace.push((
            out,
            obs.clone(),
            env.step_events().copied().collect::<Vec<_>>(),
        ));
        if out.terminated || out.truncated {
            break;
        }
    }
    // Each event's last report (the step it ended in, or the last) is its record in the log.
    let log = env.events().unwrap();
    assert_eq!(log.dropped(), 0);
    for e in log.events() {
        assert!(
            trace.iter().any(|(_, _, step)| step.contains(e)),
            "{e:?} is reported as it ended"
        );
    }
    trace
}

/// Half torque on OW1 and minus half on OW2 for 25 ms lift a wheel off the ball for longer than
/// the lift-off rule's 20 ms: with every rule on (as every episode ran before) the episode ends
/// there; by default it goes on, the lift-off reported, until the robot falls.
#[test]
fn a_lift_off_is_an_event_by_default_and_ends_the_episode_only_under_the_old_rules() {
    let old = lean_and_let_go(StopRules::all(), 400);
    let (last, _, _) = old.last().unwrap();
    assert!(last.terminated, "the lift-off rule ends the episode");
    let Some(Termination::StopRule(FailureKind::LiftOff { wheel })) = last.info.termination else {
        panic!("ended by {:?}", last.info.termination);
    };
    let k = old.len() - 1;
    assert!(
        k < 20,
        "the lift-off rule ends it within the push: step {k}"
    );

    let new = lean_and_let_go(EnvConfig::DEFAULT_STOP_RULES, 400);
    // The stop rules change nothing but the end: the same world up to the old end (whose
    // step stopped at the failure, some physics steps short).
    for (j, ((a, obs_a, ev_a), (b, obs_b, ev_b))) in old[..k].iter().zip(&new).enumerate() {
        assert_eq!(obs_a, obs_b, "step {j}");
        assert_eq!(a.reward, b.reward, "step {j}");
        assert_eq!(ev_a, ev_b, "step {j}");
    }
    let (at_old_end, _, events) = &new[k];
    assert!(!at_old_end.terminated && at_old_end.info.termination.is_none());
    let lift_off = events
        .iter()
        .find(|e| matches!(e.kind, EventKind::LiftOff { wheel: w, .. } if w == wheel))
        .expect("the lift-off is reported in the step the old rule ended");
    let max_secs = EnvConfig::new(Task::Balance)
        .world
        .failure
        .max_lift_off_duration_secs;
    assert!(
        lift_off.ongoing && lift_off.duration_secs > max_secs,
        "{lift_off:?}"
    );
    assert!(
        new.len() > k + 50,
        "the episode goes on: {} steps",
        new.len()
    );
    let (end, _, _) = new.last().unwrap();
    assert!(end.terminated, "the robot falls in the end");
    let termination = end.info.termination.unwrap();
    assert!(termination.is_fall(), "ended by {termination:?}");
    // The lift-off went on past the old end and is reported until it ended.
    let lasted = new[k..]
        .iter()
        .flat_map(|(_, _, e)| e)
        .filter(|e| e.onset_secs == lift_off.onset_secs && e.kind.as_str() == "lift_off")
        .map(|e| e.duration_secs)
        .fold(0.0, f64::max);
    assert!(lasted > lift_off.duration_secs, "lasted {lasted} s");
}

#[test]
fn without_stop_rules_a_falling_robot_ends_on_the_floor_after_the_tilt_rule_would_have() {
    let run = |rules: StopRules| {
        let mut config = quiet(EnvConfig::new(Task::Balance));
        config.stop_rules = rules;
        let mut env = BallbotEnv::new(config).unwrap();
        let mut obs = vec![0.0_f32; env.observation_len()];
        let tilt = ResetOptions {
            initial_tilt_rad: Some([0.0, 0.1]),
            ..ResetOptions::default()
        };
        env.reset(Some(0), Some(&tilt), &mut obs).unwrap();
        loop {
            let out = env.step([0.0; 3], &mut obs).unwrap();
            if out.terminated || out.truncated {
                return out;
            }
        }
    };
    let (by_tilt, on_floor) = (run(EnvConfig::DEFAULT_STOP_RULES), run(StopRules::none()));
    assert!(matches!(
        by_tilt.info.termination,
        Some(Termination::StopRule(FailureKind::Tilt { .. }))
    ));
    assert!(on_floor.terminated && !on_floor.truncated);
    assert_eq!(on_floor.info.termination, Some(Termination::Fell));
    assert_eq!(on_floor.info.termination.map(|t| t.as_str()), Some("fell"));
    assert!(on_floor.info.termination.is_some_and(|t| t.is_fall()));
    assert!(
        on_floor.info.time_secs > by_tilt.info.time_secs,
        "the floor at {} s, the tilt rule at {} s",
        on_floor.info.time_secs,
        by_tilt.info.time_secs
    );
}

/// The LQR-PI underneath (the shipped loop's plant) rides out a 40 N s push that lifts a wheel
/// for longer than 20 ms: the old rules ended the episode at the lift-off; by default it runs
/// to the time limit, and the lift-off and the controller's slip fault are its events.
#[test]
fn with_the_controller_underneath_a_push_past_the_lift_off_rule_is_ridden_out_and_reported() {
    let run = |rules: StopRules| {
        let mut config = quiet(EnvConfig::new(Task::Velocity));
        config.stop_rules = rules;
        // One push, 0.5 s in; the episode ends before the next.
        config.max_episode_secs = 1.0;
        config.randomization.push_impulse_ns = Some(40.0.into());
        config.randomization.push_interval_secs = Some(0.5.into());
        let mut env = BallbotEnv::new(config).unwrap();
        let mut obs = vec![0.0_f32; env.observation_len()];
        let stand = ResetOptions {
            command: Some([0.0; 3]),
            ..ResetOptions::default()
        };
        env.reset(Some(5), Some(&stand), &mut obs).unwrap();
        let (mut pushes, mut reported) = (0, Vec::new());
        let out = loop {
            let out = env.step([0.0; 3], &mut obs).unwrap();
            pushes += usize::from(out.info.push_ns.is_some());
            reported.extend(env.step_events().copied());
            if out.terminated || out.truncated {
                break out;
            }
        };
        assert_eq!(pushes, 1);
        (out, env.events().unwrap().events().to_vec(), reported)
    };
    let (old, _, _) = run(StopRules::all());
    assert!(
        matches!(
            old.info.termination,
            Some(Termination::StopRule(FailureKind::LiftOff { .. }))
        ),
        "{:?}",
        old.info.termination
    );
    let (new, events, reported) = run(EnvConfig::DEFAULT_STOP_RULES);
    assert!(new.truncated && !new.terminated, "{:?}", new.info);
    let max_secs = EnvConfig::new(Task::Velocity)
        .world
        .failure
        .max_lift_off_duration_secs;
    assert!(
        events
            .iter()
            .any(|e| matches!(e.kind, EventKind::LiftOff { .. }) && e.duration_secs > max_secs),
        "{events:?}"
    );
    assert!(
        events.iter().any(|e| e.kind.as_str() == "controller_fault"),
        "the controller's faults are events too: {events:?}"
    );
    for e in &events {
        assert!(reported.contains(e), "{e:?} reported in a step");
    }
}
