//! Closed-loop tests of the planar controllers on the nonlinear WIP.
//!
//! The plant is the core's nonlinear WIP integrated with `rk4_step` at 8 kHz (torque held
//! between controller updates, as a motor driver holds it); the controllers run at their own
//! rates: LQR, PI-PD and the LQR-PI outer part at 400 Hz, the LQR-PI inner speed PI at 8 kHz.
//! An optional friction torque on the relative (motor) joint stands in for the PIPTB's
//! transmission stiction (MODEL.md section 7).
#![allow(clippy::unwrap_used)]

use ballbot_core::control::{
    LqrController, LqrGains, LqrPiOuter, LqrPiOuterConfig, PiPdController, PiPdGains, SpeedCommand,
    SpeedPi, SpeedPiGains, StepStatus, accelerating_command,
};
use ballbot_core::{Wip, WipParams, WipState, rk4_step};
use nalgebra::Vector4;
use proptest::prelude::*;

const OUTER_HZ: f64 = 400.0;
const INNER_HZ: f64 = 8000.0;
/// Plant RK4 substeps per inner period: 1, the plant at 8 kHz with the torque held over each
/// inner period (as the motor driver holds it). Convergence check: 2 substeps (16 kHz) give
/// the same reported numbers to 3-4 significant digits, at twice the test time.
const PLANT_SUBSTEPS: usize = 1;
const INNER_PER_OUTER: usize = 20;
/// Bandwidth of the inner speed PI's error dynamics (rad/s).
const INNER_BANDWIDTH_RAD_PER_S: f64 = 30.0;

const TILT: usize = 0;
const TILT_RATE: usize = 2;
const BALL_RATE: usize = 3;

// ----------------------------------------------------------------------------------------
// Fixtures

/// A robot preset with the torque limit its planar controller must respect.
#[derive(Clone, Copy, Debug)]
struct Preset {
    name: &'static str,
    params: WipParams<f64>,
    /// MiaPURE: the x-plane torque capacity of three 43.2 N m actuators (MODEL.md section 6,
    /// the smaller of the two planes); PIPTB: one actuator's peak.
    max_torque_nm: f64,
}

fn presets() -> [Preset; 3] {
    [
        Preset {
            name: "miapure_60kg",
            params: WipParams::miapure_60kg(),
            max_torque_nm: 83.9,
        },
        Preset {
            name: "miapure_unloaded",
            params: WipParams::miapure_unloaded(),
            max_torque_nm: 83.9,
        },
        Preset {
            name: "piptb",
            params: WipParams::piptb(),
            max_torque_nm: 43.2,
        },
    ]
}

fn miapure() -> Preset {
    presets()[0]
}

/// LQR gains for a preset, designed by the core's synthesis (continuous LQR on the upright
/// linearisation, MODEL.md's weights Q = diag(100, 10, 1), R = 0.1).
fn lqr_gains(preset: &Preset) -> LqrGains<f64> {
    LqrGains::for_wip(&wip(preset), preset.max_torque_nm).unwrap()
}

fn wip(preset: &Preset) -> Wip<f64> {
    Wip::new(preset.params).unwrap()
}

fn inner_gains(preset: &Preset) -> SpeedPiGains<f64> {
    SpeedPiGains::for_wip_ball_rate(
        &wip(preset),
        INNER_BANDWIDTH_RAD_PER_S,
        preset.max_torque_nm,
    )
    .unwrap()
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Lqr,
    PiPd,
    LqrPi,
}

/// A controller under test, driven at the inner rate.
enum Controller {
    Lqr(LqrController<f64>),
    PiPd(PiPdController<f64>),
    LqrPi {
        outer: LqrPiOuter<f64>,
        inner: SpeedPi<f64>,
        command: SpeedCommand<f64>,
    },
}

impl Controller {
    fn new(kind: Kind, preset: &Preset) -> Self {
        match kind {
            Kind::Lqr => Self::Lqr(LqrController::new(lqr_gains(preset)).unwrap()),
            Kind::PiPd => Self::PiPd(
                PiPdController::new(
                    PiPdGains::for_wip(&wip(preset), preset.max_torque_nm).unwrap(),
                )
                .unwrap(),
            ),
            Kind::LqrPi => {
                let inner = inner_gains(preset);
                let config = LqrPiOuterConfig::new(lqr_gains(preset), &inner).unwrap();
                Self::lqr_pi(preset, inner, config)
            }
        }
    }

    fn lqr_pi(preset: &Preset, inner: SpeedPiGains<f64>, config: LqrPiOuterConfig<f64>) -> Self {
        Self::LqrPi {
            outer: LqrPiOuter::new(wip(preset), config).unwrap(),
            inner: SpeedPi::new(inner).unwrap(),
            command: SpeedCommand {
                speed_rad_per_s: 0.0,
                feedforward_torque_nm: 0.0,
            },
        }
    }

    /// The torque for the coming inner period. `outer_due` marks an outer-rate tick; the LQR
    /// and the PI-PD hold their torque between outer ticks.
    fn tick(&mut self, s: &WipState<f64>, sc: &WipState<f64>, outer_due: bool, held: f64) -> f64 {
        let dt_outer = 1.0 / OUTER_HZ;
        match self {
            Self::Lqr(c) => {
                if outer_due {
                    c.step(s, sc, dt_outer).torque_nm
                } else {
                    held
                }
            }
            Self::PiPd(c) => {
                if outer_due {
                    c.step(s, sc, dt_outer).torque_nm
                } else {
                    held
                }
            }
            Self::LqrPi {
                outer,
                inner,
                command,
            } => {
                if outer_due {
                    let o = outer.step(s, sc, dt_outer);
                    *command = SpeedCommand {
                        speed_rad_per_s: o.reference_ball_rate_rad_per_s,
                        feedforward_torque_nm: o.reference_torque_nm,
                    };
                }
                inner.step(s[BALL_RATE], command, 1.0 / INNER_HZ).torque_nm
            }
        }
    }
}

/// Friction on the relative (motor) joint, opposing `phi_dot - theta_dot`.
#[derive(Clone, Copy, Debug)]
enum Friction {
    None,
    /// Smooth Coulomb friction `torque_nm tanh(w_rel / slip_rate_rad_per_s)`.
    Coulomb {
        torque_nm: f64,
        slip_rate_rad_per_s: f64,
    },
    /// Karnopp stick-slip: within `stick_rate_rad_per_s` of zero relative rate the joint sticks
    /// (friction cancels the net torque that would make it slip, up to `stiction_nm`); outside
    /// it slides against `coulomb_nm`.
    Karnopp {
        stiction_nm: f64,
        coulomb_nm: f64,
        stick_rate_rad_per_s: f64,
    },
}

struct Plant {
    wip: Wip<f64>,
    friction: Friction,
    state: WipState<f64>,
}

impl Plant {
    /// Friction torque on the relative joint with the motor applying `torque_nm`.
    fn friction_nm(&self, s: &WipState<f64>, torque_nm: f64) -> f64 {
        match self.friction {
            Friction::None => 0.0,
            Friction::Coulomb {
                torque_nm,
                slip_rate_rad_per_s,
            } => torque_nm * ((s[BALL_RATE] - s[TILT_RATE]) / slip_rate_rad_per_s).tanh(),
            Friction::Karnopp {
                stiction_nm,
                coulomb_nm,
                stick_rate_rad_per_s,
            } => {
                let w_rel = s[BALL_RATE] - s[TILT_RATE];
                if w_rel.abs() > stick_rate_rad_per_s {
                    return coulomb_nm * w_rel.signum();
                }
                // The relative acceleration is affine in the net torque: find the friction
                // that holds it at zero, and stick if the joint can supply it.
                let rel_accel = |net: f64| {
                    let q = self.wip.accelerations(s, net);
                    q[1] - q[0]
                };
                let at_zero = rel_accel(0.0);
                let per_nm = rel_accel(1.0) - at_zero;
                let hold = torque_nm + at_zero / per_nm;
                hold.clamp(-stiction_nm, stiction_nm)
            }
        }
    }

    fn step(&mut self, torque_nm: f64, dt_secs: f64) {
        let f = |x: &WipState<f64>| {
            self.wip
                .derivative(x, torque_nm - self.friction_nm(x, torque_nm))
        };
        self.state = rk4_step(f, &self.state, dt_secs);
    }
}

#[test]
fn karnopp_friction_sticks_below_stiction_and_slips_above() {
    let preset = miapure();
    let plant = Plant {
        wip: wip(&preset),
        friction: Friction::Karnopp {
            stiction_nm: 6.0,
            coulomb_nm: 5.0,
            stick_rate_rad_per_s: 0.01,
        },
        state: Vector4::new(0.02, 0.0, 0.1, 0.1),
    };
    let rel_accel = |s: &WipState<f64>, tau: f64| {
        let d = plant.wip.derivative(s, tau - plant.friction_nm(s, tau));
        d[3] - d[2]
    };
    // Stuck (relative rate 0): a 2 N m motor torque does not make the joint slip.
    assert!(rel_accel(&plant.state, 2.0).abs() < 1e-9);
    // 20 N m exceeds the stiction: it slips.
    assert!(rel_accel(&plant.state, 20.0) > 1.0);
    // Sliding: the Coulomb level, against the motion.
    let sliding = Vector4::new(0.0, 0.0, 0.0, 1.0);
    assert_eq!(plant.friction_nm(&sliding, 0.0), 5.0);
}

/// One record per outer period.
#[derive(Clone, Copy, Debug)]
struct Sample {
    t_secs: f64,
    state: WipState<f64>,
    command: WipState<f64>,
    torque_nm: f64,
}

struct Trace {
    samples: Vec<Sample>,
    ball_radius_m: f64,
    /// When the body passed 1.2 rad (the run stops there).
    fell_at_secs: Option<f64>,
}

impl Trace {
    fn speed_error_m_per_s(&self, s: &Sample) -> f64 {
        (s.state[BALL_RATE] - s.command[BALL_RATE]) * self.ball_radius_m
    }

    fn between(&self, t0: f64, t1: f64) -> impl Iterator<Item = &Sample> {
        self.samples
            .iter()
            .filter(move |s| s.t_secs >= t0 && s.t_secs <= t1)
    }

    /// Mean speed error over `[t0, t1]` (m/s, signed).
    fn mean_speed_error(&self, t0: f64, t1: f64) -> f64 {
        let (sum, n) = self.between(t0, t1).fold((0.0, 0), |(a, n), s| {
            (a + self.speed_error_m_per_s(s), n + 1)
        });
        sum / n as f64
    }

    /// Largest |speed error| over `[t0, t1]` (m/s).
    fn max_speed_error(&self, t0: f64, t1: f64) -> f64 {
        self.between(t0, t1)
            .map(|s| self.speed_error_m_per_s(s).abs())
            .fold(0.0, f64::max)
    }

    /// Settle criterion: the time after which the robot stays within |theta| <= 0.5 deg,
    /// |theta_dot| <= 2 deg/s and |ball speed| <= 0.02 m/s (a regulation run to rest).
    /// `None` if it is outside the band at the end.
    fn settle_time_secs(&self) -> Option<f64> {
        if self.fell_at_secs.is_some() {
            return None;
        }
        let deg = std::f64::consts::PI / 180.0;
        let inside = |s: &Sample| {
            s.state[TILT].abs() <= 0.5 * deg
                && s.state[TILT_RATE].abs() <= 2.0 * deg
                && (s.state[BALL_RATE] * self.ball_radius_m).abs() <= 0.02
        };
        let last_outside = self.samples.iter().rposition(|s| !inside(s));
        match last_outside {
            None => Some(0.0),
            Some(i) if i + 1 < self.samples.len() => Some(self.samples[i + 1].t_secs),
            Some(_) => None,
        }
    }

    fn max_abs_tilt_rad(&self) -> f64 {
        self.samples
            .iter()
            .map(|s| s.state[TILT].abs())
            .fold(0.0, f64::max)
    }

    fn max_abs_torque_nm(&self) -> f64 {
        self.samples
            .iter()
            .map(|s| s.torque_nm.abs())
            .fold(0.0, f64::max)
    }
}

/// Runs `controller` on the plant for `duration_secs` from `initial`, the command state
/// given by `command(t)`.
fn simulate(
    preset: &Preset,
    controller: &mut Controller,
    friction: Friction,
    initial: WipState<f64>,
    command: impl Fn(f64) -> WipState<f64>,
    duration_secs: f64,
) -> Trace {
    let mut plant = Plant {
        wip: wip(preset),
        friction,
        state: initial,
    };
    let inner_dt = 1.0 / INNER_HZ;
    let plant_dt = inner_dt / PLANT_SUBSTEPS as f64;
    let steps = (duration_secs * INNER_HZ).round() as usize;
    let mut samples = Vec::with_capacity(steps / INNER_PER_OUTER + 1);
    let mut torque = 0.0;
    let mut sc = command(0.0);
    let mut fell_at_secs = None;
    for k in 0..steps {
        let t = k as f64 * inner_dt;
        let outer_due = k % INNER_PER_OUTER == 0;
        if outer_due {
            sc = command(t);
        }
        torque = controller.tick(&plant.state, &sc, outer_due, torque);
        assert!(torque.is_finite() && torque.abs() <= preset.max_torque_nm + 1e-9);
        if outer_due {
            samples.push(Sample {
                t_secs: t,
                state: plant.state,
                command: sc,
                torque_nm: torque,
            });
        }
        for _ in 0..PLANT_SUBSTEPS {
            plant.step(torque, plant_dt);
        }
        if plant.state[TILT].abs() > 1.2 || !plant.state[TILT].is_finite() {
            fell_at_secs = Some(t);
            break;
        }
    }
    Trace {
        samples,
        ball_radius_m: preset.params.ball_radius_m,
        fell_at_secs,
    }
}

/// A speed command: `speed_m_per_s(t)` as the ball rate, upright, no tilt rate.
fn speed_command(r: f64, speed_m_per_s: impl Fn(f64) -> f64) -> impl Fn(f64) -> WipState<f64> {
    move |t| Vector4::new(0.0, 0.0, 0.0, speed_m_per_s(t) / r)
}

/// The paper's PIPTB profile without the braking phase: 0 -> 1 m/s in 2 s, hold.
fn ramp_1m_per_s(t: f64) -> f64 {
    (t / 2.0).min(1.0)
}

// ----------------------------------------------------------------------------------------
// Recovery from a 10 deg tilt

#[test]
fn every_controller_recovers_every_preset_from_10_deg() {
    let tilt0 = 10.0_f64.to_radians();
    for preset in presets() {
        for kind in [Kind::Lqr, Kind::PiPd, Kind::LqrPi] {
            let mut c = Controller::new(kind, &preset);
            let trace = simulate(
                &preset,
                &mut c,
                Friction::None,
                Vector4::new(tilt0, 0.0, 0.0, 0.0),
                |_| Vector4::zeros(),
                8.0,
            );
            let settle = trace.settle_time_secs();
            eprintln!(
                "{:>16} {kind:?}: settle {settle:?} s, max tilt {:.2} deg, max torque {:.1} N m",
                preset.name,
                trace.max_abs_tilt_rad().to_degrees(),
                trace.max_abs_torque_nm()
            );
            let settle = settle.unwrap_or(f64::INFINITY);
            assert!(settle <= 5.0, "{} {kind:?}: settle {settle} s", preset.name);
        }
    }
}

/// Without a disturbance the speed error obeys `e_dot = -B4 tau_e` from `e = 0`, so the inner
/// PI adds (almost) nothing and the LQR-PI moves like the LQR: a check of the reference model's
/// signs and of the outer/inner timing.
#[test]
fn without_disturbance_lqr_pi_moves_like_lqr() {
    for preset in presets() {
        let run = |kind| {
            simulate(
                &preset,
                &mut Controller::new(kind, &preset),
                Friction::None,
                Vector4::new(10.0_f64.to_radians(), 0.0, 0.0, 0.0),
                |_| Vector4::zeros(),
                3.0,
            )
        };
        let (a, b) = (run(Kind::Lqr), run(Kind::LqrPi));
        let max_diff = a
            .samples
            .iter()
            .zip(&b.samples)
            .map(|(x, y)| (x.state[TILT] - y.state[TILT]).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "{:>16}: max tilt difference LQR vs LQR-PI {:.4} deg",
            preset.name,
            max_diff.to_degrees()
        );
        assert!(max_diff < 0.1_f64.to_radians(), "{}", preset.name);
    }
}

/// The same controllers in f32 (microcontroller arithmetic), on an f32 plant: designs and
/// loops work without f64.
#[test]
fn f32_controllers_recover_miapure_from_10_deg() {
    let wip = Wip::new(WipParams::<f32>::miapure_60kg()).unwrap();
    let limit = 83.9_f32;
    let lqr = LqrGains::for_wip(&wip, limit).unwrap();
    let inner = SpeedPiGains::for_wip_ball_rate(&wip, 30.0, limit).unwrap();
    let config = LqrPiOuterConfig::new(lqr, &inner).unwrap();
    for use_pi_pd in [false, true] {
        let mut outer = LqrPiOuter::new(wip, config).unwrap();
        let mut pi = SpeedPi::new(inner).unwrap();
        let mut pipd = PiPdController::new(PiPdGains::for_wip(&wip, limit).unwrap()).unwrap();
        let mut s = Vector4::new(10.0_f32.to_radians(), 0.0, 0.0, 0.0);
        let mut command = SpeedCommand {
            speed_rad_per_s: 0.0,
            feedforward_torque_nm: 0.0,
        };
        let mut torque = 0.0_f32;
        let dt_inner = 1.0 / INNER_HZ as f32;
        for k in 0..(6.0 * INNER_HZ) as usize {
            if k % INNER_PER_OUTER == 0 {
                let sc = Vector4::zeros();
                if use_pi_pd {
                    torque = pipd.step(&s, &sc, 1.0 / OUTER_HZ as f32).torque_nm;
                } else {
                    let o = outer.step(&s, &sc, 1.0 / OUTER_HZ as f32);
                    command = SpeedCommand {
                        speed_rad_per_s: o.reference_ball_rate_rad_per_s,
                        feedforward_torque_nm: o.reference_torque_nm,
                    };
                }
            }
            if !use_pi_pd {
                torque = pi.step(s[BALL_RATE], &command, dt_inner).torque_nm;
            }
            assert!(torque.is_finite() && torque.abs() <= limit);
            s = rk4_step(|x| wip.derivative(x, torque), &s, dt_inner);
        }
        let which = if use_pi_pd { "PI-PD" } else { "LQR-PI" };
        eprintln!("f32 {which}: after 6 s {s:?}");
        assert!(s[TILT].abs() < 0.5_f32.to_radians(), "{which}: {s:?}");
        assert!(s[BALL_RATE].abs() * 0.1145 < 0.02, "{which}: {s:?}");
    }
}

// ----------------------------------------------------------------------------------------
// Tracking the paper's 1 m/s ramp

#[test]
fn lqr_lqr_pi_and_pi_pd_track_the_1_m_per_s_ramp() {
    let mut results = Vec::new();
    for preset in presets() {
        for kind in [Kind::Lqr, Kind::LqrPi, Kind::PiPd] {
            let mut c = Controller::new(kind, &preset);
            let r = preset.params.ball_radius_m;
            let trace = simulate(
                &preset,
                &mut c,
                Friction::None,
                Vector4::zeros(),
                speed_command(r, ramp_1m_per_s),
                8.0,
            );
            assert_eq!(trace.fell_at_secs, None, "{} {kind:?} fell", preset.name);
            let ramp = trace.max_speed_error(0.0, 2.0);
            let lag = trace.mean_speed_error(1.5, 2.0);
            let hold = trace.max_speed_error(6.0, 8.0);
            // The same ramp with the lean that holds the acceleration in the command state.
            let w = wip(&preset);
            let consistent = move |t: f64| {
                let (v, a) = if t < 2.0 { (t / 2.0, 0.5) } else { (1.0, 0.0) };
                accelerating_command(&w, v / r, a / r).unwrap().0
            };
            let mut c2 = Controller::new(kind, &preset);
            let trace2 = simulate(
                &preset,
                &mut c2,
                Friction::None,
                Vector4::zeros(),
                consistent,
                2.5,
            );
            let ramp2 = trace2.max_speed_error(0.0, 2.0);
            let lag2 = trace2.mean_speed_error(1.5, 2.0);
            eprintln!(
                "{:>16} {kind:?}: speed error on the ramp max {ramp:.3} m/s (mean over the last \
                 0.5 s {lag:+.3}), 4 s into the hold max {hold:.4} m/s; lean command: max {ramp2:.3} mean {lag2:+.4}",
                preset.name
            );
            results.push((preset.name, kind, ramp, hold, lag, lag2));
        }
    }
    assert!(!results.is_empty());
    for (name, kind, ramp, hold, lag, lag_with_lean) in results {
        // The command state carries only the speed (theta_c = 0): the lean needed to
        // accelerate is fought by k1, so the controllers lag the ramp by a bounded amount.
        assert!(ramp < 0.5, "{name} {kind:?}: ramp error {ramp}");
        assert!(hold < 0.01, "{name} {kind:?}: hold error {hold}");
        // Commanding the lean the acceleration needs (accelerating_command) at least halves
        // the LQR's lag at the end of the ramp. (The PI-PD's speed integral already removes
        // most of its lag: reported, not checked.)
        if kind != Kind::PiPd {
            assert!(
                lag_with_lean.abs() < 0.5 * lag.abs(),
                "{name} {kind:?}: {lag_with_lean} vs {lag}"
            );
        }
    }
}

// ----------------------------------------------------------------------------------------
// The paper's central claim: stiction

/// With Coulomb friction on the drive, the LQR alone cruises with a steady speed error
/// (`tau_c / |k3|` by the steady-state balance); the LQR-PI removes it (and so does the PI-PD's
/// integral).
#[test]
fn lqr_pi_removes_the_steady_speed_error_that_friction_leaves_under_lqr() {
    let cruise = |t: f64| 0.5 * t.min(1.0);
    for preset in presets() {
        let gains = lqr_gains(&preset);
        let r = preset.params.ball_radius_m;
        // "Several N m" on the drive.
        let coulomb_nm = 5.0;
        for friction in [
            Friction::Coulomb {
                torque_nm: coulomb_nm,
                slip_rate_rad_per_s: 0.05,
            },
            Friction::Karnopp {
                stiction_nm: 1.2 * coulomb_nm,
                coulomb_nm,
                stick_rate_rad_per_s: 0.01,
            },
        ] {
            let mut errors = [0.0; 3];
            for (i, kind) in [Kind::Lqr, Kind::LqrPi, Kind::PiPd].into_iter().enumerate() {
                let mut c = Controller::new(kind, &preset);
                let trace = simulate(
                    &preset,
                    &mut c,
                    friction,
                    Vector4::zeros(),
                    speed_command(r, cruise),
                    8.0,
                );
                assert_eq!(trace.fell_at_secs, None, "{} {kind:?} fell", preset.name);
                errors[i] = trace.mean_speed_error(7.0, 8.0);
                eprintln!(
                    "{:>16} {kind:?} with {friction:?}, 0.5 m/s command: steady speed error \
                     {:+.4} m/s",
                    preset.name, errors[i]
                );
            }
            // LQR: at a steady cruise the body is upright and the net torque zero, so the
            // k3 term must supply the friction: |error| = coulomb / |k3| (times r, in m/s).
            let predicted = coulomb_nm / gains.ball_rate_nm_s_per_rad.abs() * r;
            assert!(
                (errors[0].abs() - predicted).abs() < 0.1 * predicted,
                "{}: LQR error {} vs predicted {predicted}",
                preset.name,
                errors[0]
            );
            assert!(errors[0].abs() > 0.05, "{}: {}", preset.name, errors[0]);
            // LQR-PI: removed. The PI-PD's speed integral removes it too (the paper: the
            // PI "can break the stiction"), at the price of its harder tuning.
            assert!(
                errors[1].abs() < 0.005,
                "{}: LQR-PI error {}",
                preset.name,
                errors[1]
            );
            assert!(
                errors[2].abs() < 0.005,
                "{}: PI-PD error {}",
                preset.name,
                errors[2]
            );
        }
    }
}

// ----------------------------------------------------------------------------------------
// Anti-windup

/// Long saturation: the motor driver is derated to 30 N m (thermal or supply limit) while the
/// outer loop still plans with the full 83.9 N m, the drive has 5 N m of Coulomb friction, and
/// the robot starts at 15 deg. The inner loop is saturated for about 0.2 s, six time constants
/// of its 30 rad/s error dynamics: the speed error and the integral would wind up. With the
/// anti-windup (back-calculation plus the reference anchor band) the LQR-PI's excursion stays
/// close to that of the LQR (which has no integrator to wind up); with both disabled, the
/// same run overshoots far more, which shows that this test can fail.
#[test]
fn lqr_pi_does_not_overshoot_after_a_long_saturation() {
    let base = miapure();
    let driver_limit_nm = 30.0;
    let tilt0 = 15.0_f64.to_radians();
    let friction = Friction::Coulomb {
        torque_nm: 5.0,
        slip_rate_rad_per_s: 0.05,
    };
    let derated = Preset {
        max_torque_nm: driver_limit_nm,
        ..base
    };
    let inner = SpeedPiGains {
        max_torque_nm: driver_limit_nm,
        ..inner_gains(&base)
    };
    let with = LqrPiOuterConfig::new(lqr_gains(&base), &inner).unwrap();
    let inner_without = SpeedPiGains {
        anti_windup_per_s: 0.0,
        ..inner
    };
    let without = LqrPiOuterConfig {
        max_speed_error_rad_per_s: 1e6,
        ..with
    };
    let lqr = LqrGains {
        max_torque_nm: driver_limit_nm,
        ..lqr_gains(&base)
    };
    let mut results = Vec::new();
    for (name, mut c) in [
        ("LQR", Controller::Lqr(LqrController::new(lqr).unwrap())),
        ("LQR-PI", Controller::lqr_pi(&derated, inner, with)),
        (
            "LQR-PI without anti-windup",
            Controller::lqr_pi(&derated, inner_without, without),
        ),
    ] {
        let trace = simulate(
            &derated,
            &mut c,
            friction,
            Vector4::new(tilt0, 0.0, 0.0, 0.0),
            |_| Vector4::zeros(),
            8.0,
        );
        assert_eq!(trace.fell_at_secs, None, "{name} fell");
        let r = derated.params.ball_radius_m;
        let saturated_secs = trace
            .samples
            .iter()
            .filter(|s| s.torque_nm.abs() >= driver_limit_nm - 1e-9)
            .count() as f64
            / OUTER_HZ;
        let peak_speed = trace
            .samples
            .iter()
            .map(|s| (s.state[BALL_RATE] * r).abs())
            .fold(0.0, f64::max);
        let reverse_tilt = trace
            .samples
            .iter()
            .map(|s| -s.state[TILT])
            .fold(0.0, f64::max);
        eprintln!(
            "{name}: saturated {saturated_secs:.3} s, peak ball speed {peak_speed:.3} m/s, \
             reverse tilt {:.2} deg",
            reverse_tilt.to_degrees()
        );
        results.push((saturated_secs, peak_speed, trace.settle_time_secs()));
    }
    let [
        (_, lqr_peak, _),
        (sat, pi_peak, pi_settle),
        (_, raw_peak, _),
    ] = results[..]
    else {
        unreachable!()
    };
    assert!(sat >= 0.15, "the scenario must saturate for long: {sat} s");
    assert!(
        pi_peak < 1.25 * lqr_peak,
        "LQR-PI {pi_peak} vs LQR {lqr_peak}"
    );
    assert!(pi_settle.is_some_and(|t| t < 3.0), "{pi_settle:?}");
    assert!(raw_peak > 1.5 * lqr_peak, "without anti-windup {raw_peak}");
}

/// Back-calculation, checked by its fixed point (the unit test
/// `saturation_keeps_the_integral_within_the_limit` only checks `I <= max`, which the
/// clamp alone guarantees: it passes with the anti-windup sign flipped). Held saturated at an
/// upper bound `u` below the actuator peak with a constant error `e`, the update
/// `I += ki e dt + k_aw dt (u - kp e - I)` settles at `I* = u - kp e + ki e / k_aw`, here
/// 4 - 1 + 2 = 5 N m, inside the 10 N m clamp; the request then exceeds the output by exactly
/// `ki e / k_aw` = 2 N m. A flipped or missing back-calculation term winds the integral up to
/// the clamp (10 N m) instead.
#[test]
fn back_calculation_settles_the_integral_at_its_fixed_point() {
    let gains = SpeedPiGains::<f64> {
        proportional_nm_s_per_rad: 2.0,
        integral_nm_per_rad: 20.0,
        anti_windup_per_s: 5.0,
        max_torque_nm: 10.0,
    };
    let (upper, error, dt) = (4.0, 0.5, 0.001);
    let command = SpeedCommand {
        speed_rad_per_s: error,
        feedforward_torque_nm: 0.0,
    };
    let expected = upper - gains.proportional_nm_s_per_rad * error
        + gains.integral_nm_per_rad * error / gains.anti_windup_per_s;
    assert_eq!(expected, 5.0);
    let mut pi = SpeedPi::new(gains).unwrap();
    // The integral error shrinks by (1 - k_aw dt) = 0.995 per step: 0.995^8000 ~ 4e-18.
    // (The first steps are unsaturated: the request kp e = 1 N m grows with the integral.)
    for _ in 0..8000 {
        pi.step_within(0.0, &command, dt, -10.0, upper);
    }
    let out = pi.step_within(0.0, &command, dt, -10.0, upper);
    assert_eq!((out.torque_nm, out.status), (upper, StepStatus::Saturated));
    assert!(
        (pi.integral_nm() - expected).abs() < 1e-9,
        "integral {} vs fixed point {expected}",
        pi.integral_nm()
    );
    // Without back-calculation the same run winds the integral up to the clamp.
    let mut raw = SpeedPi::new(SpeedPiGains {
        anti_windup_per_s: 0.0,
        ..gains
    })
    .unwrap();
    for _ in 0..8000 {
        raw.step_within(0.0, &command, dt, -10.0, upper);
    }
    assert_eq!(raw.integral_nm(), gains.max_torque_nm);
}

/// A speed step clips the PI-PD's reference tilt for a long time (the longer, the larger the
/// step). With conditional integration the speed overshoot stays about the same small amount
/// whatever the step; a winding-up integral would grow it with the clipped time.
#[test]
fn pi_pd_speed_steps_do_not_wind_up_the_speed_integral() {
    for preset in presets() {
        let r = preset.params.ball_radius_m;
        for v in [1.0, 3.0] {
            let mut c = Controller::new(Kind::PiPd, &preset);
            let step = move |t: f64| if t < 0.2 { 0.0 } else { v };
            let trace = simulate(
                &preset,
                &mut c,
                Friction::None,
                Vector4::zeros(),
                speed_command(r, step),
                8.0,
            );
            assert_eq!(trace.fell_at_secs, None, "{} {v} m/s fell", preset.name);
            let overshoot = trace
                .samples
                .iter()
                .map(|s| s.state[BALL_RATE] * r - v)
                .fold(f64::MIN, f64::max);
            let clipped_secs = trace
                .samples
                .iter()
                .filter(|s| (s.state[BALL_RATE] * r - v).abs() > 0.5)
                .count() as f64
                / OUTER_HZ;
            let final_error = trace.max_speed_error(7.0, 8.0);
            eprintln!(
                "{:>16} PI-PD step to {v} m/s: overshoot {overshoot:.3} m/s, {clipped_secs:.2} s \
                 more than 0.5 m/s off, final error {final_error:.4} m/s, max tilt {:.1} deg",
                preset.name,
                trace.max_abs_tilt_rad().to_degrees()
            );
            assert!(overshoot < 0.15, "{} {v}: {overshoot}", preset.name);
            assert!(final_error < 0.01, "{} {v}: {final_error}", preset.name);
        }
    }
}

// ----------------------------------------------------------------------------------------
// Robustness

#[test]
fn non_finite_measurements_give_zero_finite_torque_then_recover() {
    let preset = miapure();
    let good = Vector4::new(0.05, 0.0, 0.1, 1.0);
    let zero = Vector4::zeros();
    let dt = 1.0 / OUTER_HZ;
    let mut lqr = LqrController::new(lqr_gains(&preset)).unwrap();
    let mut pipd =
        PiPdController::new(PiPdGains::for_wip(&wip(&preset), preset.max_torque_nm).unwrap())
            .unwrap();
    let inner_g = inner_gains(&preset);
    let mut outer = LqrPiOuter::new(
        wip(&preset),
        LqrPiOuterConfig::new(lqr_gains(&preset), &inner_g).unwrap(),
    )
    .unwrap();
    let mut inner = SpeedPi::new(inner_g).unwrap();
    outer.step(&good, &zero, dt);
    pipd.step(&good, &zero, dt);
    let held_reference = outer.reference_ball_rate_rad_per_s();
    let held_integral = pipd.speed_error_integral_rad();
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        for i in 0..4 {
            let mut s = good;
            s[i] = bad;
            for (m, c) in [(&s, &zero), (&good, &s)] {
                let a = lqr.step(m, c, dt);
                assert_eq!((a.torque_nm, a.status), (0.0, StepStatus::InvalidInput));
                let b = pipd.step(m, c, dt);
                assert_eq!((b.torque_nm, b.status), (0.0, StepStatus::InvalidInput));
                let o = outer.step(m, c, dt);
                assert_eq!(
                    (o.reference_torque_nm, o.status),
                    (0.0, StepStatus::InvalidInput)
                );
                assert_eq!(Some(o.reference_ball_rate_rad_per_s), held_reference);
                // The motor driver's PI sees a finite (held) reference and the measured
                // speed; with the speed itself non-finite it gives zero torque.
                let cmd = SpeedCommand {
                    speed_rad_per_s: o.reference_ball_rate_rad_per_s,
                    feedforward_torque_nm: o.reference_torque_nm,
                };
                let e = inner.step(m[BALL_RATE], &cmd, 1.0 / INNER_HZ);
                assert!(e.torque_nm.is_finite() && e.torque_nm.abs() <= preset.max_torque_nm);
                if !m[BALL_RATE].is_finite() {
                    assert_eq!((e.torque_nm, e.status), (0.0, StepStatus::InvalidInput));
                }
            }
        }
    }
    // State held through the bad steps.
    assert_eq!(outer.reference_ball_rate_rad_per_s(), held_reference);
    assert_eq!(pipd.speed_error_integral_rad(), held_integral);
    // Valid again: a finite, positive balancing torque from each.
    assert!(lqr.step(&good, &zero, dt).torque_nm > 0.0);
    assert!(pipd.step(&good, &zero, dt).torque_nm > 0.0);
    assert!(outer.step(&good, &zero, dt).reference_torque_nm > 0.0);
}

fn any_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => -10.0..10.0f64,
        2 => proptest::num::f64::ANY,
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
        1 => Just(f64::MAX),
    ]
}

fn any_state() -> impl Strategy<Value = WipState<f64>> {
    [any_f64(), any_f64(), any_f64(), any_f64()].prop_map(Vector4::from)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// For arbitrary (including non-finite) inputs, no controller's `step` panics, and every
    /// torque it returns is finite and within its limit; rejected steps are flagged.
    #[test]
    fn step_never_panics_and_torque_is_finite_and_bounded(
        steps in proptest::collection::vec((any_state(), any_state(), any_f64(), any_f64()), 1..20)
    ) {
        let preset = miapure();
        let limit = preset.max_torque_nm;
        let mut lqr = LqrController::new(lqr_gains(&preset)).unwrap();
        let mut pipd = PiPdController::new(PiPdGains::for_wip(&wip(&preset), limit).unwrap()).unwrap();
        let inner_g = inner_gains(&preset);
        let mut outer = LqrPiOuter::new(
            wip(&preset),
            LqrPiOuterConfig::new(lqr_gains(&preset), &inner_g).unwrap(),
        ).unwrap();
        let mut inner = SpeedPi::new(inner_g).unwrap();
        for (s, sc, dt, extra) in steps {
            let a = lqr.step(&s, &sc, dt);
            prop_assert!(a.torque_nm.is_finite() && a.torque_nm.abs() <= limit);
            let b = pipd.step(&s, &sc, dt);
            prop_assert!(b.torque_nm.is_finite() && b.torque_nm.abs() <= limit);
            prop_assert!(b.reference_tilt_rad.is_finite());
            let o = outer.step(&s, &sc, dt);
            prop_assert!(o.reference_torque_nm.is_finite() && o.reference_torque_nm.abs() <= limit);
            prop_assert!(o.reference_ball_rate_rad_per_s.is_finite());
            let cmd = SpeedCommand { speed_rad_per_s: o.reference_ball_rate_rad_per_s, feedforward_torque_nm: o.reference_torque_nm };
            let i = inner.step(s[BALL_RATE], &cmd, dt);
            prop_assert!(i.torque_nm.is_finite() && i.torque_nm.abs() <= limit);
            // The same with arbitrary raw inputs to the inner PI, and arbitrary bounds.
            let raw = SpeedCommand { speed_rad_per_s: extra, feedforward_torque_nm: sc[0] };
            let j = inner.step_within(s[1], &raw, dt, -extra.abs(), sc[2]);
            prop_assert!(j.torque_nm.is_finite() && j.torque_nm.abs() <= limit);
            prop_assert!(inner.integral_nm().is_finite());
            let all_finite = s.iter().chain(sc.iter()).all(|v| v.is_finite());
            if !all_finite {
                prop_assert_eq!(a.status, StepStatus::InvalidInput);
                prop_assert_eq!(o.status, StepStatus::InvalidInput);
            }
        }
    }
}

fn any_f32() -> impl Strategy<Value = f32> {
    prop_oneof![
        4 => -10.0..10.0f32,
        2 => proptest::num::f32::ANY,
        1 => Just(f32::NAN),
        1 => Just(f32::INFINITY),
        1 => Just(f32::MAX),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// The same contract in f32, where overflow comes much sooner (`f32::MAX` is 3.4e38).
    #[test]
    fn f32_step_never_panics_and_torque_is_finite_and_bounded(
        steps in proptest::collection::vec(
            ([any_f32(), any_f32(), any_f32(), any_f32()], [any_f32(), any_f32(), any_f32(), any_f32()], any_f32()),
            1..20,
        )
    ) {
        let wip = Wip::new(WipParams::<f32>::miapure_60kg()).unwrap();
        let limit = 83.9_f32;
        let inner_g = SpeedPiGains::for_wip_ball_rate(&wip, 30.0, limit).unwrap();
        let lqr = LqrGains::for_wip(&wip, limit).unwrap();
        let mut lqr_c = LqrController::new(lqr).unwrap();
        let mut pipd = PiPdController::new(PiPdGains::for_wip(&wip, limit).unwrap()).unwrap();
        let mut outer = LqrPiOuter::new(wip, LqrPiOuterConfig::new(lqr, &inner_g).unwrap()).unwrap();
        let mut inner = SpeedPi::new(inner_g).unwrap();
        for (s, sc, dt) in steps {
            let (s, sc) = (Vector4::from(s), Vector4::from(sc));
            let a = lqr_c.step(&s, &sc, dt).torque_nm;
            let b = pipd.step(&s, &sc, dt).torque_nm;
            let o = outer.step(&s, &sc, dt);
            prop_assert!(o.reference_ball_rate_rad_per_s.is_finite());
            let cmd = SpeedCommand {
                speed_rad_per_s: o.reference_ball_rate_rad_per_s,
                feedforward_torque_nm: o.reference_torque_nm,
            };
            let i = inner.step(s[BALL_RATE], &cmd, dt).torque_nm;
            for t in [a, b, o.reference_torque_nm, i] {
                prop_assert!(t.is_finite() && t.abs() <= limit, "{t}");
            }
        }
    }
}
