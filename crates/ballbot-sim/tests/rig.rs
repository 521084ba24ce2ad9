//! The shipped robot loop (`ballbot_runtime::RobotLoop`) against the rapier3d world: the same
//! loop a robot binary runs arms, balances, drives, shuts down at rest, and switches the motors
//! off on an unrecoverable fault.

use ballbot_core::command::{Command, VelocityCommand};
use ballbot_core::safety::{Fault, Mode};
use ballbot_runtime::Phase;
use ballbot_sim::rig::WorldRobot;
use ballbot_sim::world::WorldParams;

fn velocity(vx_m_per_s: f64) -> Command<'static, f64> {
    Command::Velocity(VelocityCommand {
        vx_m_per_s,
        vy_m_per_s: 0.0,
        yaw_rate_rad_per_s: 0.0,
    })
}

#[test]
fn the_shipped_loop_arms_drives_and_shuts_down_at_rest_in_the_world() {
    let params = WorldParams::miapure_60kg();
    let latency_steps = (params.sensors.link_latency_secs / params.dt_secs).round() as usize;
    let mut sim = WorldRobot::new(params).unwrap();
    assert_eq!(sim.phase(), Phase::StartingUp);
    for _ in 0..=latency_steps {
        sim.step(velocity(0.5));
    }
    // Upright and still at t = 0 with no settling time: armed at the first outer task, on
    // the sample of t = 0 once the link latency has passed.
    assert_eq!((sim.phase(), sim.mode()), (Phase::Running, Mode::Balancing));
    for _ in 0..4 * 8000 {
        sim.step(velocity(0.5));
    }
    let v = sim.world().telemetry().ball_velocity_m_per_s.x;
    assert!((v - 0.5).abs() < 0.05, "cruising at {v} m/s");
    assert!(sim.robot().devices().2.enabled);

    sim.shutdown();
    let mut off_at_secs = None;
    for _ in 0..6 * 8000 {
        sim.step(velocity(0.5));
        if sim.phase() == Phase::Off {
            off_at_secs = Some(sim.world().time_secs());
            break;
        }
        assert_ne!(sim.mode(), Mode::Fault);
    }
    let off_at_secs = off_at_secs.expect("the loop disarms once at rest");
    // The operator's 0.5 m/s is overridden by the controlled stop; disarmed only at rest.
    let speed = sim.world().telemetry().ball_velocity_m_per_s.norm();
    assert!(speed < 0.05, "disarmed at {speed} m/s, t = {off_at_secs} s");
    assert!(
        off_at_secs > 4.2,
        "a stop from 0.5 m/s takes time: {off_at_secs} s"
    );
    assert!(sim.world().failure().is_none());
    // Motors off once disarmed: the world's wheels receive no torque.
    sim.step(velocity(0.5));
    assert!(!sim.robot().devices().2.enabled);
    for w in &sim.world().telemetry().wheels {
        assert_eq!(w.motor_torque_nm, 0.0);
    }
}

#[test]
fn an_unrecoverable_fault_switches_the_motors_off_in_the_world() {
    let mut sim = WorldRobot::new(WorldParams::miapure_60kg()).unwrap();
    for _ in 0..8000 {
        sim.step(Command::Stop);
    }
    assert!(sim.robot().devices().2.enabled);
    // Tip the body far beyond the supervisor's recoverable tilt.
    sim.world_mut().tilt_body([0.0, 0.6]);
    for _ in 0..40 {
        sim.step(Command::Stop);
    }
    let out = sim.last_outer().unwrap();
    assert_eq!(out.safety.mode, Mode::Fault);
    assert!(out.safety.faults.contains(Fault::TiltLimit));
    assert!(!sim.robot().devices().2.enabled, "motors must be off");
    // What the world's wheels received, not only what the driver port holds.
    for w in &sim.world().telemetry().wheels {
        assert_eq!(w.motor_torque_nm, 0.0);
    }
}

/// A wild 8 kHz encoder burst on OW1: from `from_us` for `len_us`, the drivers' encoder reads
/// a speed that jumps between +-100 rad/s every sample (the outer tick's sample stays honest).
struct WildEncoderBurst {
    from_us: u64,
    len_us: u64,
    n: u64,
}

impl ballbot_sim::rig::Injector for WildEncoderBurst {
    fn encoders(
        &mut self,
        now_us: u64,
        mut sample: ballbot_core::estimation::EncoderSample<f64>,
        outer: bool,
    ) -> Option<ballbot_core::estimation::EncoderSample<f64>> {
        if !outer && now_us >= self.from_us && now_us < self.from_us + self.len_us {
            self.n += 1;
            sample.wheel_speeds_rad_per_s[0] = if self.n.is_multiple_of(2) {
                100.0
            } else {
                -100.0
            };
        }
        Some(sample)
    }
}

#[test]
fn a_wild_encoder_burst_is_a_controlled_stop_not_a_torque_spike_in_the_world() {
    let mut sim = WorldRobot::new(WorldParams::miapure_60kg()).unwrap();
    let mut burst = WildEncoderBurst {
        from_us: 1_000_000,
        len_us: 5_000,
        n: 0,
    };
    let mut peak_nm: f64 = 0.0;
    for _ in 0..2 * 8000 {
        let tel = sim.step_injected(Command::Stop, &mut burst);
        if tel.time_secs > 0.99 {
            peak_nm = peak_nm.max(tel.wheels[0].motor_torque_nm.abs());
        }
    }
    // Without the guard's trajectory check it re-synchronised onto +-100 rad/s after 1 ms,
    // and OW1 drove at up to 34.5 N m (checked by mutation).
    assert!(peak_nm < 10.0, "OW1 peak {peak_nm} N m");
    let latched = sim.robot().controller().supervisor().latched_faults();
    assert!(latched.contains(Fault::EncoderImplausible), "{latched}");
    assert_eq!(sim.mode(), Mode::ControlledStop);
    assert!(sim.world().failure().is_none());
}
