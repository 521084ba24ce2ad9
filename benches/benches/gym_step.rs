//! The reinforcement-learning environments (`ballbot_sim::gym`) against the bare world, in one
//! run: one agent step of `Velocity` (the core's LQR-PI underneath, 20 physics steps at 8 kHz,
//! the observation and the reward) against 20 `WorldRobot` steps, and a vector step of 8
//! environments on every core against 8 single steps one after the other.
//!
//! Measured twice: wall-clock time and, with the `_cpu` suffix, the thread's CPU time (Unix).
//! The vector step's wall time is the figure that shows the threads (its thread CPU time counts
//! the calling thread's share only).
//!
//! Run: `cargo bench -p ballbot-benches --bench gym_step -- --warm-up-time 1 --measurement-time 3`

// A bench binary on fixed, valid fixtures: failing loudly is the right behaviour.
#![allow(clippy::unwrap_used)]

mod common;
use ballbot_core::command::{Command, VelocityCommand};
use ballbot_sim::gym::{BallbotEnv, EnvConfig, Task, VecEnv, VecStep};
use ballbot_sim::rig::WorldRobot;
use ballbot_sim::world::WorldParams;
use common::bench_both;
use criterion::{Criterion, criterion_group, criterion_main};

/// A fixed command: the LQR-PI holds the robot up indefinitely, so no episode ends.
fn config() -> EnvConfig {
    let mut c = EnvConfig::new(Task::Velocity);
    c.max_episode_secs = 1.0e6;
    c
}

const COMMAND: [f64; 3] = [0.3, 0.0, 0.0];

fn gym_step(c: &mut Criterion) {
    let mut sim = WorldRobot::new(WorldParams::miapure_60kg()).unwrap();
    let cmd = Command::Velocity(VelocityCommand {
        vx_m_per_s: COMMAND[0],
        vy_m_per_s: COMMAND[1],
        yaw_rate_rad_per_s: COMMAND[2],
    });
    bench_both(c, "bare_world_20_steps_with_controller", || {
        for _ in 0..20 {
            sim.step(cmd);
        }
        sim.world().time_secs()
    });
    assert!(sim.world().failure().is_none());

    let mut env = BallbotEnv::new(config()).unwrap();
    let mut obs = vec![0.0_f32; env.observation_len()];
    let options = ballbot_sim::gym::ResetOptions {
        command: Some(COMMAND),
        ..Default::default()
    };
    env.reset(Some(0), Some(&options), &mut obs).unwrap();
    bench_both(c, "env_step_velocity", || {
        let out = env.step([0.0; 3], &mut obs).unwrap();
        assert!(!out.terminated);
        out.reward
    });

    for threads in [1, 0] {
        let n = 8;
        let mut envs = VecEnv::new(config(), n, threads).unwrap();
        let mut obs = vec![0.0_f32; n * envs.observation_len()];
        let seeds: Vec<Option<u64>> = (0..n as u64).map(Some).collect();
        envs.reset(&seeds, Some(&options), &mut obs).unwrap();
        let mut out = VecStep::default();
        let name = format!("vec_env_step_8_envs_{}_threads", envs.threads());
        bench_both(c, &name, || {
            envs.step(&[[0.0; 3]; 8], &mut out).unwrap();
            assert!(!out.terminated.iter().any(|t| *t));
            out.rewards[0]
        });
    }
}

criterion_group!(benches, gym_step);
criterion_main!(benches);
