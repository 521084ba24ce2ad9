//! The multi-rate scheduler: timing, delay, determinism, agreement with a direct loop.

use ballbot_core::wip::{BALL_RATE, TILT, TILT_RATE};
use ballbot_core::{PlanarRobotParams, Wip, WipState, rk4_step};
use ballbot_sim::planar::{
    DriveSetpoint, FaultKind, Observer, OuterMeasurement, OuterTick, PlanarCommand,
    PlanarController, PlanarSim, PlantStep, SensorParams, SimConfig, TransmissionFriction,
};
use nalgebra::Vector4;

/// State feedback on the reduced state that balances the PIPTB (gains by hand, checked by the
/// tests that use it).
pub struct Balance;

pub const BALANCE_GAINS: [f64; 3] = [60.0, 8.0, 0.3];

impl PlanarController for Balance {
    fn name(&self) -> &str {
        "balance"
    }
    fn outer_step(&mut self, m: &OuterMeasurement, c: &PlanarCommand, _dt: f64) -> DriveSetpoint {
        let [k1, k2, k3] = BALANCE_GAINS;
        DriveSetpoint {
            torque_nm: k1 * (m.tilt_rad - c.tilt_rad)
                + k2 * (m.tilt_rate_rad_per_s - c.tilt_rate_rad_per_s)
                + k3 * (m.ball_rate_rad_per_s - c.ball_rate_rad_per_s),
            joint_rate_rad_per_s: None,
        }
    }
    fn terms(&self, out: &mut Vec<(&'static str, f64)>) {
        out.push(("k1", BALANCE_GAINS[0]));
    }
    fn reset(&mut self) {}
}

fn cruise(t: f64) -> PlanarCommand {
    PlanarCommand {
        ball_rate_rad_per_s: (t * 5.0).min(10.0),
        ..PlanarCommand::default()
    }
}

#[derive(Default)]
struct Trace {
    states: Vec<WipState<f64>>,
    applied: Vec<f64>,
    measured: Vec<OuterMeasurement>,
    ticks: usize,
    terms: Vec<(&'static str, f64)>,
}

impl Observer for Trace {
    fn plant_step(&mut self, _t: f64, _dt: f64, s: &WipState<f64>, step: &PlantStep) {
        self.states.push(*s);
        self.applied.push(step.applied_torque_nm);
    }
    fn outer_tick(&mut self, tick: &OuterTick<'_>) {
        self.ticks += 1;
        self.measured.push(tick.measured);
        self.terms = tick.terms.to_vec();
    }
}

fn sim(
    friction: TransmissionFriction,
    sensors: SensorParams,
    config: SimConfig,
    seed: u64,
) -> PlanarSim {
    PlanarSim::new(PlanarRobotParams::piptb(), friction, sensors, config, seed).unwrap()
}

#[test]
fn ideal_sim_without_delay_equals_a_direct_loop_over_the_core_model() {
    let config = SimConfig {
        computation_delay: false,
        ..SimConfig::default()
    };
    let mut s = sim(
        TransmissionFriction::none(),
        SensorParams::ideal(),
        config,
        0,
    );
    let s0 = Vector4::new(0.03, 0.0, 0.0, 0.0);
    s.reset(s0);
    let mut trace = Trace::default();
    let out = s.run(&mut Balance, &cruise, 2.0, &mut trace);
    assert!(out.fault.is_none());
    assert_eq!(out.plant_steps, 16_000);
    assert_eq!(trace.ticks, 800);
    assert_eq!(trace.terms, [("k1", BALANCE_GAINS[0])]);

    // The same controller written out by hand: torque held for 20 plant steps.
    let robot = PlanarRobotParams::piptb();
    let wip = Wip::new(robot.plane).unwrap();
    let dt = 1.0 / 8000.0;
    let mut x = s0;
    let mut tau = 0.0;
    let [k1, k2, k3] = BALANCE_GAINS;
    for k in 0..16_000 {
        if k % 20 == 0 {
            let c = cruise(k as f64 * dt);
            tau = k1 * x[TILT] + k2 * x[TILT_RATE] + k3 * (x[BALL_RATE] - c.ball_rate_rad_per_s);
        }
        let applied = robot
            .actuator
            .clamp_torque_nm(tau, x[BALL_RATE] - x[TILT_RATE]);
        x = rk4_step(|y| wip.derivative(y, applied), &x, dt);
    }
    let err = (s.plant().state() - x).amax();
    assert!(err < 1e-12, "sim and direct loop differ by {err}");
    // Balanced and following the ramp forwards.
    assert!(
        x[TILT].abs() < 0.05 && x[BALL_RATE] > 3.0,
        "end state {x:?}"
    );
}

/// Outer loop that asks for 1 N m from t = 10 ms on.
struct StepAt10ms;
impl PlanarController for StepAt10ms {
    fn name(&self) -> &str {
        "step"
    }
    fn outer_step(&mut self, m: &OuterMeasurement, _c: &PlanarCommand, _dt: f64) -> DriveSetpoint {
        DriveSetpoint {
            torque_nm: if m.time_secs >= 0.01 - 1e-12 {
                1.0
            } else {
                0.0
            },
            joint_rate_rad_per_s: None,
        }
    }
    fn reset(&mut self) {}
}

fn first_torque_time(config: SimConfig) -> f64 {
    let mut s = sim(
        TransmissionFriction::none(),
        SensorParams::ideal(),
        config,
        0,
    );
    let mut trace = Trace::default();
    s.run(
        &mut StepAt10ms,
        &|_t: f64| PlanarCommand::default(),
        0.05,
        &mut trace,
    );
    let k = trace.applied.iter().position(|&t| t == 1.0).unwrap();
    k as f64 / config.plant_rate_hz
}

#[test]
fn computation_delay_is_one_period_of_each_loop() {
    let no_delay = SimConfig {
        computation_delay: false,
        ..SimConfig::default()
    };
    assert!((first_torque_time(no_delay) - 0.01).abs() < 1e-9);
    let delayed = first_torque_time(SimConfig::default());
    let expected = 0.01 + 1.0 / 400.0 + 1.0 / 8000.0;
    assert!((delayed - expected).abs() < 1e-9, "{delayed} vs {expected}");
    // A slower drive loop: the drive's own period adds up.
    let slow_drive = SimConfig {
        drive_rate_hz: 2000.0,
        ..SimConfig::default()
    };
    let expected = 0.01 + 1.0 / 400.0 + 1.0 / 2000.0;
    assert!((first_torque_time(slow_drive) - expected).abs() < 1e-9);
}

fn noisy_run(seed: u64) -> Trace {
    let mut s = sim(
        TransmissionFriction::piptb(),
        SensorParams::piptb(),
        SimConfig::default(),
        seed,
    );
    s.reset(Vector4::new(0.02, 0.0, 0.0, 0.0));
    let mut trace = Trace::default();
    let out = s.run(&mut Balance, &cruise, 1.0, &mut trace);
    assert!(out.fault.is_none(), "{:?}", out.fault);
    trace
}

fn bits(trace: &Trace) -> Vec<u64> {
    trace
        .states
        .iter()
        .flat_map(|s| s.iter().map(|x| x.to_bits()).collect::<Vec<_>>())
        .chain(trace.applied.iter().map(|x| x.to_bits()))
        .collect()
}

#[test]
fn same_seed_is_bit_identical_and_another_seed_changes_the_noise() {
    let a = noisy_run(42);
    let b = noisy_run(42);
    let c = noisy_run(43);
    assert_eq!(bits(&a), bits(&b));
    assert_ne!(bits(&a), bits(&c));
    assert_ne!(a.measured[5].tilt_rad, c.measured[5].tilt_rad);
}

#[test]
fn measurements_carry_bias_and_quantisation() {
    let trace = noisy_run(1);
    let sensors = SensorParams::piptb();
    let n = trace.measured.len();
    let mean_err: f64 = trace
        .measured
        .iter()
        .zip(trace.states.iter().step_by(20))
        .map(|(m, s)| m.tilt_rad - s[TILT])
        .sum::<f64>()
        / n as f64;
    assert!(
        (mean_err - sensors.tilt_bias_rad).abs() < 4.0 * sensors.tilt_noise_rad / (n as f64).sqrt()
    );
    // Quantisation (the name's second half, not checked before): the encoder part of the
    // measured ball angle, `phi - theta_imu`, is a whole number of counts at the wheel,
    // 2 pi / (16384 counts x gear ratio). Rounding of the sum with theta_imu leaves a
    // fraction of about 1e-16 / 5e-5 rad; an unquantised angle sits anywhere in [0, 1).
    let gear_ratio: f64 = PlanarRobotParams::piptb().actuator.gear_ratio;
    let count_rad =
        std::f64::consts::TAU / (f64::from(sensors.encoder_counts_per_rev) * gear_ratio);
    let mut moved = false;
    for m in &trace.measured {
        let counts = (m.ball_angle_rad - m.tilt_rad) / count_rad;
        assert!(
            (counts - counts.round()).abs() < 1e-6,
            "{counts} counts at t = {}",
            m.time_secs
        );
        moved |= counts.round().abs() > 10.0;
    }
    assert!(
        moved,
        "the encoder must have turned for this check to mean anything"
    );
}

#[test]
fn falling_over_stops_the_run_with_a_fault() {
    struct Off;
    impl PlanarController for Off {
        fn name(&self) -> &str {
            "off"
        }
        fn outer_step(&mut self, _: &OuterMeasurement, _: &PlanarCommand, _: f64) -> DriveSetpoint {
            DriveSetpoint::default()
        }
        fn reset(&mut self) {}
    }
    let mut s = sim(
        TransmissionFriction::none(),
        SensorParams::ideal(),
        SimConfig::default(),
        0,
    );
    s.reset(Vector4::new(0.01, 0.0, 0.0, 0.0));
    let out = s.run(&mut Off, &|_t: f64| PlanarCommand::default(), 5.0, &mut ());
    let fault = out.fault.unwrap();
    assert!(matches!(fault.kind, FaultKind::Fell { tilt_rad } if tilt_rad > 0.6));
    assert!(out.end_time_secs < 2.0);
}

#[test]
fn rates_that_do_not_divide_are_rejected_naming_the_key() {
    let config = SimConfig {
        outer_rate_hz: 300.0,
        ..SimConfig::default()
    };
    let err = PlanarSim::new(
        PlanarRobotParams::piptb(),
        TransmissionFriction::none(),
        SensorParams::ideal(),
        config,
        0,
    )
    .unwrap_err();
    assert!(err.to_string().contains("sim.outer_rate_hz"), "{err}");
}
