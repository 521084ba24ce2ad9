//! The planar controllers (`ballbot_core::control`): the LQR, the PI-PD cascade and the
//! LQR-PI outer loop, in `f64` and instantiated in `f32`, stepped on measured and commanded
//! states and step lengths drawn from gentle to any finite or non-finite value (the `f32`
//! ones from the whole `f32` range), with a sane step every hundredth.
//!
//! Invariant ([`inv::PLANAR`]): every output finite, every torque within its limit, whatever
//! the input; and a sane input after any sequence of hostile ones gives a finite, limited
//! output (no integrator or stored reference poisoned).

use super::episode::EpisodeCounts;
use super::hostile::{chance, hostile, index, log_uniform_f32, symmetric};
use super::invariants as inv;
use ballbot_core::control::{
    LqrController, LqrGains, LqrPiOuter, LqrPiOuterConfig, PiPdController, PiPdGains, SpeedPiGains,
};
use ballbot_core::wip::WipState;
use ballbot_core::{Wip, WipParams};
use nalgebra::RealField;
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;

/// The three planar controllers of one scalar type, designed for MiaPURE's sagittal plane.
struct Planar<T: RealField + Copy> {
    lqr: LqrController<T>,
    pipd: PiPdController<T>,
    lqr_pi: LqrPiOuter<T>,
    max_torque_nm: T,
    max_ref_torque_nm: T,
}

impl<T: RealField + Copy> Planar<T> {
    fn new() -> Result<Self, ballbot_core::Error> {
        let wip = Wip::new(WipParams::<T>::miapure_60kg())?;
        // The plane's torque limit of the design (MODEL.md: 83.9 N m) and the motor PI's.
        let max_torque_nm = nalgebra::convert(83.9);
        let lqr_gains = LqrGains::for_wip(&wip, max_torque_nm)?;
        let inner = SpeedPiGains::for_wip_ball_rate(
            &wip,
            nalgebra::convert(30.0),
            nalgebra::convert(83.9),
        )?;
        let config = LqrPiOuterConfig::new(lqr_gains, &inner)?;
        Ok(Self {
            lqr: LqrController::new(lqr_gains)?,
            pipd: PiPdController::new(PiPdGains::for_wip(&wip, max_torque_nm)?)?,
            lqr_pi: LqrPiOuter::new(wip, config)?,
            max_torque_nm,
            max_ref_torque_nm: config.lqr.max_torque_nm,
        })
    }

    /// One step of each on `(measured, command, dt)`; what broke, if anything.
    fn step(&mut self, m: &WipState<T>, c: &WipState<T>, dt: T) -> Option<&'static str> {
        let limit = self.max_torque_nm * nalgebra::convert(1.0 + 1e-6);
        let ok = |t: T, lim: T| t.is_finite() && t.abs() <= lim;
        let lqr = self.lqr.step(m, c, dt);
        if !ok(lqr.torque_nm, limit) {
            return Some("LQR torque not finite or beyond its limit");
        }
        let pipd = self.pipd.step(m, c, dt);
        if !(ok(pipd.torque_nm, limit) && pipd.reference_tilt_rad.is_finite()) {
            return Some("PI-PD torque or reference tilt not finite or beyond its limit");
        }
        let o = self.lqr_pi.step(m, c, dt);
        let ref_limit = self.max_ref_torque_nm * nalgebra::convert(1.0 + 1e-6);
        if !(ok(o.reference_torque_nm, ref_limit)
            && o.reference_ball_rate_rad_per_s.is_finite()
            && o.reference_ball_accel_rad_per_s2.is_finite())
        {
            return Some(
                "LQR-PI reference torque, rate or acceleration not finite or beyond its limit",
            );
        }
        None
    }
}

/// A state of 4 values: each gentle, hostile (any `f64`, NaN, infinities) or any `f32`.
fn state(rng: &mut ChaCha8Rng) -> [f64; 4] {
    core::array::from_fn(|_| match index(rng, 3) {
        0 => symmetric(rng, 1.0),
        1 => hostile(rng),
        _ => f64::from(log_uniform_f32(rng)),
    })
}

/// Runs `steps` steps of the planar controllers in `f64` and `f32` (each counted as one outer
/// step); every hundredth is sane (upright at rest, zero command, 2.5 ms).
pub fn run_planar_episode(seed: u64, steps: u64) -> Result<EpisodeCounts, ballbot_core::Error> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut c64 = Planar::<f64>::new()?;
    let mut c32 = Planar::<f32>::new()?;
    let mut counts = EpisodeCounts::default();
    let mut was_broken = false;
    for k in 0..steps {
        let sane = k % 100 == 99;
        let (m, c, dt) = if sane {
            ([0.0; 4], [0.0; 4], 0.0025)
        } else {
            let dt = if chance(&mut rng, 0.5) {
                0.0025
            } else {
                hostile(&mut rng)
            };
            (state(&mut rng), state(&mut rng), dt)
        };
        let (m64, c64s) = (WipState::from(m), WipState::from(c));
        let broken64 = c64.step(&m64, &c64s, dt);
        let (m32, c32s) = (m64.cast::<f32>(), c64s.cast::<f32>());
        let broken32 = c32.step(&m32, &c32s, dt as f32);
        counts.outer_steps += 1;
        let broken = broken64
            .map(|w| format!("f64: {w}"))
            .or_else(|| broken32.map(|w| format!("f32: {w}")));
        if let Some(what) = &broken
            && !was_broken
        {
            let what = format!("{what} (measured {m:?}, command {c:?}, dt {dt:e}; sane: {sane})");
            counts.record(inv::PLANAR, seed, k, what);
        }
        was_broken = broken.is_some();
    }
    Ok(counts)
}
