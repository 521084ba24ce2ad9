//! The contact-load ripple of a steady cruise: the amplitude spectrum of each omniwheel's
//! normal force, its peak, and the roller-passing frequency `N_r |psi_dot| / (2 pi)` it
//! should peak at.
//!
//! The robot accelerates gently to a constant speed under the core's controller, holds it, and
//! the last [`RippleProtocol::window_secs`] of every physics step's normal forces are analysed:
//! mean removed, Hann window, one FFT ([`rustfft`]). The amplitude of a sinusoid of amplitude
//! `A` reads `A` at its frequency (the window's coherent gain is divided out).

use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_core::command::{Command, VelocityCommand};
use ballbot_world::rig::WorldRobot;
use ballbot_world::world::{WorldError, WorldParams};
use rustfft::FftPlanner;
use rustfft::num_complex::Complex;

/// How a cruise is run and analysed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RippleProtocol {
    /// Acceleration of the velocity command up to the cruise speed (m/s^2). Default 0.5.
    pub accel_m_per_s2: f64,
    /// Time at the cruise speed before the analysis window opens (s). Default 1.5.
    pub settle_secs: f64,
    /// Length of the analysed window (s); the frequency resolution is its inverse. Default 1.
    pub window_secs: f64,
    /// Lowest frequency a peak may have (Hz): below it are the balance loop's own motions.
    /// Default 2.
    pub min_peak_hz: f64,
    /// Highest frequency kept in the spectrum (Hz). Default 400.
    pub max_hz: f64,
}

impl Default for RippleProtocol {
    fn default() -> Self {
        Self {
            accel_m_per_s2: 0.5,
            settle_secs: 1.5,
            window_secs: 1.0,
            min_peak_hz: 2.0,
            max_hz: 400.0,
        }
    }
}

/// One wheel's normal-force spectrum in one cruise.
#[derive(Clone, Debug, PartialEq)]
pub struct WheelRipple {
    /// Mean wheel speed magnitude in the window (rad/s).
    pub mean_speed_rad_per_s: f64,
    /// Mean normal force in the window (N).
    pub mean_normal_force_n: f64,
    /// Roller-passing frequency `N_r |psi_dot| / (2 pi)` (Hz); `None` for a continuous rim.
    pub roller_passing_hz: Option<f64>,
    /// Frequency of the largest amplitude at or above [`RippleProtocol::min_peak_hz`] (Hz).
    pub peak_hz: f64,
    /// Amplitude at the peak (N).
    pub peak_amplitude_n: f64,
    /// Amplitude at the spectrum line nearest the roller-passing frequency (N); `None` for a
    /// continuous rim.
    pub amplitude_at_roller_passing_n: Option<f64>,
    /// Amplitude spectrum (N) at [`RippleSpectrum::frequencies_hz`].
    pub amplitude_n: Vec<f64>,
}

/// The spectra of one cruise.
#[derive(Clone, Debug, PartialEq)]
pub struct RippleSpectrum {
    /// Heading of travel (deg, body frame).
    pub heading_deg: f64,
    /// Commanded cruise speed (m/s).
    pub speed_m_per_s: f64,
    /// Rollers per omniwheel `N_r` (0: continuous rim).
    pub roller_count: u32,
    /// Frequencies of the spectrum lines (Hz), from 0 in steps of `1 / window_secs`.
    pub frequencies_hz: Vec<f64>,
    /// OW1, OW2, OW3.
    pub wheels: [WheelRipple; 3],
    /// The failure, if the cruise failed before the window closed (then the spectra are
    /// empty).
    pub failure: Option<ballbot_world::world::Failure>,
}

/// Cruises at `speed_m_per_s` towards `heading_deg` in the world `params` with the controller
/// `config`, and returns the normal-force spectra of the three wheels.
pub fn cruise_spectrum(
    params: WorldParams,
    config: BallbotControllerConfig<f64>,
    roller_count: u32,
    heading_deg: f64,
    speed_m_per_s: f64,
    protocol: &RippleProtocol,
) -> Result<RippleSpectrum, WorldError> {
    let cruise = Cruise {
        roller_count,
        heading_deg,
        speed_m_per_s,
    };
    cruise_spectrum_observed(params, config, cruise, protocol, &mut |_| {})
}

/// One ripple cruise: the rollers per wheel, where it goes and how fast.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cruise {
    /// Rollers per omniwheel `N_r` (0: continuous rim).
    pub roller_count: u32,
    /// Heading of travel (deg, body frame).
    pub heading_deg: f64,
    /// Commanded cruise speed (m/s).
    pub speed_m_per_s: f64,
}

/// [`cruise_spectrum`] showing every physics step to `observe` after it is taken (a logger);
/// the run is the same with or without an observer.
pub fn cruise_spectrum_observed(
    params: WorldParams,
    config: BallbotControllerConfig<f64>,
    cruise: Cruise,
    protocol: &RippleProtocol,
    observe: &mut dyn FnMut(&WorldRobot),
) -> Result<RippleSpectrum, WorldError> {
    let Cruise {
        roller_count,
        heading_deg,
        speed_m_per_s,
    } = cruise;
    if !(protocol.accel_m_per_s2 > 0.0
        && protocol.window_secs > 0.0
        && protocol.settle_secs >= 0.0
        && protocol.max_hz > protocol.min_peak_hz
        && speed_m_per_s.is_finite())
    {
        return Err(WorldError::InvalidParameter {
            field: "ripple",
            requirement: "accel and window > 0, settle >= 0, max_hz > min_peak_hz, finite speed",
        });
    }
    let mut sim = WorldRobot::with_config(params, config)?;
    let dt = params.dt_secs;
    let (s, c) = heading_deg.to_radians().sin_cos();
    let ramp_secs = speed_m_per_s.abs() / protocol.accel_m_per_s2;
    let window_steps = (protocol.window_secs / dt).round() as usize;
    let start = ((ramp_secs + protocol.settle_secs) / dt).ceil() as usize;
    let mut normal = [const { Vec::new() }; 3];
    let mut speed = [0.0; 3];
    for k in 0..start + window_steps {
        let t = k as f64 * dt;
        let v = (t * protocol.accel_m_per_s2).min(speed_m_per_s.abs()) * speed_m_per_s.signum();
        let cmd = VelocityCommand {
            vx_m_per_s: v * c,
            vy_m_per_s: v * s,
            yaw_rate_rad_per_s: 0.0,
        };
        let tel = *sim.step(Command::Velocity(cmd));
        observe(&sim);
        if sim.world().failure().is_some() {
            break;
        }
        if k >= start {
            for (i, w) in tel.wheels.iter().enumerate() {
                normal[i].push(w.normal_force_n);
                speed[i] += w.speed_rad_per_s.abs();
            }
        }
    }
    let failure = sim.world().failure();
    let n = normal[0].len();
    let frequencies_hz: Vec<f64> = if failure.is_none() {
        (0..n / 2 + 1)
            .map(|k| k as f64 / (n as f64 * dt))
            .take_while(|&f| f <= protocol.max_hz)
            .collect()
    } else {
        Vec::new()
    };
    let wheels = std::array::from_fn(|i| {
        let mean_speed = if n > 0 { speed[i] / n as f64 } else { 0.0 };
        let passing = (roller_count > 0)
            .then(|| f64::from(roller_count) * mean_speed / std::f64::consts::TAU);
        wheel_ripple(
            &normal[i],
            &frequencies_hz,
            mean_speed,
            passing,
            protocol.min_peak_hz,
        )
    });
    Ok(RippleSpectrum {
        heading_deg,
        speed_m_per_s,
        roller_count,
        frequencies_hz,
        wheels,
        failure,
    })
}

fn wheel_ripple(
    normal_n: &[f64],
    frequencies_hz: &[f64],
    mean_speed_rad_per_s: f64,
    roller_passing_hz: Option<f64>,
    min_peak_hz: f64,
) -> WheelRipple {
    let mean = normal_n.iter().sum::<f64>() / normal_n.len().max(1) as f64;
    let amplitude_n = if frequencies_hz.is_empty() {
        Vec::new()
    } else {
        amplitude_spectrum(normal_n, mean, frequencies_hz.len())
    };
    let (peak_hz, peak_amplitude_n) = frequencies_hz
        .iter()
        .zip(&amplitude_n)
        .filter(|(f, _)| **f >= min_peak_hz)
        .fold(
            (0.0, 0.0),
            |best, (&f, &a)| if a > best.1 { (f, a) } else { best },
        );
    let amplitude_at_roller_passing_n = roller_passing_hz.and_then(|f| {
        let df = frequencies_hz.get(1)?;
        amplitude_n.get((f / df).round() as usize).copied()
    });
    WheelRipple {
        mean_speed_rad_per_s,
        mean_normal_force_n: mean,
        roller_passing_hz,
        peak_hz,
        peak_amplitude_n,
        amplitude_at_roller_passing_n,
        amplitude_n,
    }
}

/// The one-sided amplitude spectrum of `x - mean` under a Hann window, its first `lines`
/// lines: a sinusoid of amplitude `A` on a line reads `A`.
pub fn amplitude_spectrum(x: &[f64], mean: f64, lines: usize) -> Vec<f64> {
    let n = x.len();
    if n < 2 {
        return vec![0.0; lines.min(n)];
    }
    let hann = |k: usize| 0.5 - 0.5 * (std::f64::consts::TAU * k as f64 / n as f64).cos();
    let mut buf: Vec<Complex<f64>> = x
        .iter()
        .enumerate()
        .map(|(k, v)| Complex::new((v - mean) * hann(k), 0.0))
        .collect();
    FftPlanner::new().plan_fft_forward(n).process(&mut buf);
    let gain: f64 = (0..n).map(hann).sum();
    buf.iter()
        .take(lines.min(n / 2 + 1))
        .enumerate()
        .map(|(k, z)| {
            let one_sided = if k == 0 { 1.0 } else { 2.0 };
            one_sided * z.norm() / gain
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sinusoid_reads_its_amplitude_at_its_frequency() {
        // 8 kHz for 1 s: 37 Hz, amplitude 12 N, on a 300 N mean.
        let n = 8000;
        let x: Vec<f64> = (0..n)
            .map(|k| 300.0 + 12.0 * (std::f64::consts::TAU * 37.0 * k as f64 / 8000.0).sin())
            .collect();
        let a = amplitude_spectrum(&x, 300.0, 400);
        let (peak, amp) = a
            .iter()
            .enumerate()
            .fold((0, 0.0), |b, (k, &v)| if v > b.1 { (k, v) } else { b });
        assert_eq!(peak, 37);
        assert!((amp - 12.0).abs() < 1e-6, "{amp}");
        assert!(a[10] < 1e-6 && a[80] < 1e-6);
    }
}
