//! Properties of the [`JerkLimiter`] and the [`CommandShaper`]'s stop over the whole finite
//! range of `f32` and `f64`: exact arrival within [`JerkLimiter::steps_to_rest_bound`], the
//! limits kept, and `is_at_rest` after a stop.

extern crate std;

use super::*;
use crate::BallbotParams;
use nalgebra::RealField;
use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use std::format;

/// The seed of every property here (proptest prints the failing case; re-run with it).
const SEED: u64 = 0x6a65_726b;

/// One drawn limiter problem, in `f64` before conversion.
#[derive(Clone, Copy, Debug)]
struct Problem {
    max_value: f64,
    max_rate: f64,
    jerk: f64,
    dt: f64,
    value0: f64,
    rate0: f64,
    target: f64,
}

/// `10^e` with a random sign.
fn signed(negative: bool, exponent: f64) -> f64 {
    let m = 10f64.powf(exponent);
    if negative { -m } else { m }
}

/// A problem whose magnitudes span `[10^lo, 10^hi]` (log-uniform scale of the value and of
/// the step, subnormals included), with the ratios that set the step count (steps to cross
/// the range at the acceleration limit, steps to reach that limit at the jerk limit) kept
/// to at most a few hundred so that a run ends.
fn problem(lo: f64, hi: f64) -> impl Strategy<Value = Problem> {
    (
        (lo..hi, 0.0..1.0f64),
        (
            0.0..2.5f64,
            0.0..2.0f64,
            prop_oneof![3 => 0.0..2.5f64, 1 => Just(f64::INFINITY)],
        ),
        (any::<bool>(), 0.0..1.6f64, any::<bool>(), 0.0..1.6f64),
        (
            any::<bool>(),
            prop_oneof![3 => 0.0..1.5f64, 1 => Just(0.0)],
            prop_oneof![4 => Just(None), 1 => (lo..hi).prop_map(Some)],
        ),
    )
        .prop_map(
            move |((value_e, dt_u), (n1_e, n2_e, n3_e), (tn, tw, vn, vw), (rn, rw, wild))| {
                // The step, chosen so that jerk = value / (dt^2 n1 n2) stays finite and normal
                // (log margin of 7 decades for the ratios).
                let dt_lo = ((value_e - hi) / 2.0 + 4.0).max(lo);
                let dt_hi = ((value_e - lo) / 2.0 - 4.0).min(hi);
                let dt_e = if dt_lo < dt_hi {
                    dt_lo + dt_u * (dt_hi - dt_lo)
                } else {
                    0.0
                };
                let max_value = 10f64.powf(value_e);
                let dt = 10f64.powf(dt_e);
                let n1 = 10f64.powf(n1_e); // steps across max_value at max_rate
                let max_rate = max_value / (dt * n1);
                let n2 = 10f64.powf(n2_e - 1.0); // steps from 0 to max_rate at the jerk limit
                let jerk = if n3_e.is_finite() {
                    max_rate / (dt * n2)
                } else {
                    f64::INFINITY
                };
                let target = if tn { -tw * max_value } else { tw * max_value };
                let value0 = match wild {
                    Some(e) => signed(vn, e),
                    None if vn => -vw * max_value,
                    None => vw * max_value,
                };
                let rate0 = if rn { -rw * max_rate } else { rw * max_rate };
                Problem {
                    max_value,
                    max_rate,
                    jerk,
                    dt,
                    value0,
                    rate0,
                    target,
                }
            },
        )
}

fn to<T: RealField + Copy>(x: f64) -> T {
    nalgebra::convert(x)
}

fn back<T: RealField + Copy>(x: T) -> f64 {
    nalgebra::try_convert::<T, f64>(x).unwrap_or(f64::NAN)
}

/// Runs `p` in `T`; checks the limits every step and returns `(steps to arrival, bound)`.
fn run<T: RealField + Copy>(p: &Problem, cap: u64) -> Result<Option<(u64, u64)>, TestCaseError> {
    let limits = AxisLimits::<T> {
        max_value: to(p.max_value),
        max_rate_per_s: to(p.max_rate),
        max_jerk_per_s2: to(p.jerk),
    };
    let dt: T = to(p.dt);
    let target: T = to(p.target);
    let finite_positive = |x: T| x.is_finite() && x > T::zero();
    let valid = finite_positive(limits.max_value)
        && finite_positive(limits.max_rate_per_s)
        && finite_positive(dt)
        && limits.max_jerk_per_s2 > T::zero();
    if !valid {
        return Ok(None);
    }
    let mut limiter = JerkLimiter::<T>::at(T::zero());
    limiter.reset(to(p.value0), to(p.rate0));
    let bound = limiter.steps_to_rest_bound(target, &limits, dt);
    let Some(bound) = bound.filter(|&b| b <= cap) else {
        return Ok(None);
    };
    let eps = back(T::default_epsilon());
    let (m, a, j) = (p.max_value, p.max_rate, p.jerk);
    let dtf = back(dt);
    let j_step = back(limits.max_jerk_per_s2 * dt);
    let target_c = back(target).clamp(-back(limits.max_value), back(limits.max_value));
    let tiny = 4.0 / back(T::max_value().unwrap_or_else(|| to(f64::MAX)));
    let outside = back(limiter.rate_per_s()).abs() > back(limits.max_rate_per_s)
        || back(limiter.value()).abs() > back(limits.max_value);
    for k in 1..=bound + 2 {
        let (v0, r0) = (back(limiter.value()), back(limiter.rate_per_s()));
        let v = back(limiter.step(target, &limits, dt));
        let r = back(limiter.rate_per_s());
        let slack = |x: f64| x * (1.0 + 8.0 * eps) + tiny;
        prop_assert!(
            v.abs() <= back(limits.max_value),
            "step {k}: value {v} beyond {m}"
        );
        prop_assert!(r.abs() <= slack(a), "step {k}: rate {r} beyond {a}");
        if !(k == 1 && outside) {
            prop_assert!(
                (r - r0).abs() <= slack(j_step) + 2.0 * eps * (r.abs() + r0.abs()),
                "step {k}: rate {r0} -> {r}, jerk step {j_step} ({j})"
            );
            prop_assert!(
                (v - v0).abs() <= slack(a * dtf) + 2.0 * eps * (v.abs() + v0.abs()),
                "step {k}: value {v0} -> {v} faster than {a} x {dtf}"
            );
        }
        if v == target_c && r == 0.0 {
            // Arrived: and stays.
            let again = back(limiter.step(target, &limits, dt));
            prop_assert!(again == target_c && back(limiter.rate_per_s()) == 0.0);
            return Ok(Some((k, bound)));
        }
    }
    Err(TestCaseError::fail(format!(
        "not at {target_c} after {} steps (bound {bound}): value {}, rate {}",
        bound + 2,
        back(limiter.value()),
        back(limiter.rate_per_s())
    )))
}

fn config(cases: u32) -> ProptestConfig {
    ProptestConfig {
        rng_seed: RngSeed::Fixed(SEED),
        ..ProptestConfig::with_cases(cases)
    }
}

proptest! {
    #![proptest_config(config(2000))]

    #[test]
    fn jerk_limiter_arrives_exactly_within_its_bound_over_the_f64_range(p in problem(-320.0, 300.0)) {
        if let Some((steps, bound)) = run::<f64>(&p, 20_000)? {
            prop_assert!(steps <= bound, "{steps} > {bound}");
        }
    }

    #[test]
    fn jerk_limiter_arrives_exactly_within_its_bound_over_the_f32_range(p in problem(-44.0, 37.0)) {
        if let Some((steps, bound)) = run::<f32>(&p, 20_000)? {
            prop_assert!(steps <= bound, "{steps} > {bound}");
        }
    }
}

/// `+-10^e`, `e` uniform in `[lo, hi]` (subnormals included when `lo` is below the normal
/// range), or an exact zero now and then.
fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    prop_oneof![
        20 => (any::<bool>(), lo..hi).prop_map(|(negative, e)| signed(negative, e)),
        1 => Just(0.0),
    ]
}

/// A shaper of MiaPURE's defaults in `T`, the reference filter on (0.3 s) or off.
fn shaper<T: RealField + Copy>(filter: bool) -> CommandShaper<T> {
    let mut params = CommandShaperParams::<T>::miapure();
    if filter {
        params.reference_filter_secs = to(0.3);
    }
    let robot = BallbotParams::<T>::miapure_60kg();
    match CommandShaper::new(params, &robot) {
        Ok(s) => s,
        Err(e) => panic!("MiaPURE's shaper: {e}"),
    }
}

/// From any finite state of the three limiters and the reference filter, `Stop` brings the
/// shaper to rest (`is_at_rest`, what the controller's `stopped` reports) within the largest
/// of the limiters' [`JerkLimiter::steps_to_rest_bound`]s, plus the filter's geometric
/// decay to its 0.1 mm/s snap.
fn stop_from<T: RealField + Copy>(state: [f64; 8], filter: bool) -> Result<(), TestCaseError> {
    let mut s = shaper::<T>(filter);
    s.vx.reset(to(state[0]), to(state[1]));
    s.vy.reset(to(state[2]), to(state[3]));
    s.yaw_rate.reset(to(state[4]), to(state[5]));
    s.filtered_m_per_s = (to(state[6]), to(state[7]));
    let dt: T = to(0.0025);
    let p = *s.params();
    let bound_of =
        |l: &JerkLimiter<T>, limits: &AxisLimits<T>| l.steps_to_rest_bound(T::zero(), limits, dt);
    let limiters = [
        bound_of(&s.vx, &p.translation),
        bound_of(&s.vy, &p.translation),
        bound_of(&s.yaw_rate, &p.yaw),
    ];
    let Some(mut bound) = limiters.iter().try_fold(0u64, |m, b| b.map(|b| m.max(b))) else {
        return Err(TestCaseError::fail("no bound for MiaPURE's limits"));
    };
    if filter {
        let (fx, fy) = s.filtered_m_per_s;
        let far = back(fx)
            .abs()
            .max(back(fy).abs())
            .max(back(p.translation.max_value));
        let gain = 0.0025 / 0.3;
        bound += ((far.max(1e-4) / 1e-4).ln() / -(1.0f64 - gain).ln()).ceil() as u64 + 2;
    }
    for k in 0..=bound {
        if s.is_at_rest() {
            // And it stays there.
            s.step(&Command::Stop, dt);
            prop_assert!(s.is_at_rest());
            return Ok(());
        }
        let shaped = s.step(&Command::Stop, dt);
        prop_assert!(back(shaped.velocity.vx_m_per_s).abs() <= 2.0, "step {k}");
    }
    Err(TestCaseError::fail(format!(
        "not at rest after {bound} steps: {:?}",
        s.velocity().vx_m_per_s
    )))
}

/// An acceleration limit that records whether it was asked.
struct Recording<T> {
    limit: T,
    asked: core::cell::Cell<bool>,
}

impl<T: RealField + Copy> AccelLimit<T> for Recording<T> {
    fn accel_limit_m_per_s2(&self, _dir_x: T, _dir_y: T, _braking: bool) -> T {
        self.asked.set(true);
        self.limit
    }
}

/// A velocity command of any finite size: its direction kept, its speed clamped to the
/// translation limit, and the acceleration limit asked and kept on every step it accelerates.
fn huge_command<T: RealField + Copy>(vx: f64, vy: f64) -> Result<(), TestCaseError> {
    let (vx_t, vy_t): (T, T) = (to(vx), to(vy));
    let mut s = shaper::<T>(false);
    let limit = Recording {
        limit: to::<T>(0.8),
        asked: core::cell::Cell::new(false),
    };
    let command = Command::Velocity(VelocityCommand {
        vx_m_per_s: vx_t,
        vy_m_per_s: vy_t,
        yaw_rate_rad_per_s: T::zero(),
    });
    let dt: T = to(0.0025);
    let eps = back(T::default_epsilon());
    for k in 0..2000 {
        limit.asked.set(false);
        let (x0, y0) = (back(s.velocity().vx_m_per_s), back(s.velocity().vy_m_per_s));
        let shaped = s.step_within(&command, dt, &limit);
        let (ax, ay) = (back(shaped.acceleration.x), back(shaped.acceleration.y));
        let (x, y) = (
            back(shaped.velocity.vx_m_per_s),
            back(shaped.velocity.vy_m_per_s),
        );
        if (x, y) != (x0, y0) {
            prop_assert!(
                limit.asked.get(),
                "step {k}: moved without asking the limit ({vx:e}, {vy:e})"
            );
            prop_assert!(shaped.accel_limit_m_per_s2.is_some());
        }
        prop_assert!(
            ax.hypot(ay) <= 0.8 * (1.0 + 8.0 * eps) + 1e-30,
            "step {k}: |a| = {}",
            ax.hypot(ay)
        );
    }
    // Arrived: the command's direction, the translation limit's speed (or the command's).
    let (x, y) = (back(s.velocity().vx_m_per_s), back(s.velocity().vy_m_per_s));
    let (cx, cy) = (back(vx_t), back(vy_t));
    let speed = cx.hypot(cy).min(2.0);
    prop_assert!(
        x.hypot(y) <= 2.0 * (1.0 + 8.0 * eps),
        "|v| = {}",
        x.hypot(y)
    );
    if cx.hypot(cy) > 0.0 {
        let (ux, uy) = (cx / cx.hypot(cy), cy / cx.hypot(cy));
        prop_assert!(
            (x - ux * speed).abs() <= 1e3 * eps * 2.0 + 1e-30
                && (y - uy * speed).abs() <= 1e3 * eps * 2.0 + 1e-30,
            "({x}, {y}) for ({cx:e}, {cy:e})"
        );
    }
    Ok(())
}

proptest! {
    #![proptest_config(config(256))]

    #[test]
    fn shaper_stops_from_any_f64_state(
        state in proptest::array::uniform8(log_uniform(-320.0, 300.0)),
        filter in any::<bool>(),
    ) {
        stop_from::<f64>(state, filter)?;
    }

    #[test]
    fn shaper_stops_from_any_f32_state(
        state in proptest::array::uniform8(log_uniform(-44.0, 38.0)),
        filter in any::<bool>(),
    ) {
        stop_from::<f32>(state, filter)?;
    }

    #[test]
    fn huge_f64_velocity_commands_keep_direction_and_the_envelope(
        vx in log_uniform(-320.0, 308.0),
        vy in log_uniform(-320.0, 308.0),
    ) {
        huge_command::<f64>(vx, vy)?;
    }

    #[test]
    fn huge_f32_velocity_commands_keep_direction_and_the_envelope(
        vx in log_uniform(-44.0, 38.4),
        vy in log_uniform(-44.0, 38.4),
    ) {
        huge_command::<f32>(vx, vy)?;
    }
}
