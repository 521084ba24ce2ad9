//! Failure detection: tilt beyond the limit, body on the floor, sustained slip, lift-off.

use super::params::FailureParams;
use super::telemetry::StepTelemetry;

/// Why a run failed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FailureKind {
    /// The body tilted beyond `max_tilt_rad`.
    Tilt {
        /// Tilt from the vertical when detected (rad).
        tilt_rad: f64,
    },
    /// A corner of the chassis reached the floor.
    BodyTouchedFloor,
    /// A wheel slipped for longer than `max_slip_duration_s`.
    SustainedSlip {
        /// Wheel index, 0-based (OW1 is 0).
        wheel: usize,
    },
    /// A wheel lost contact for longer than `max_lift_off_duration_s`.
    LiftOff {
        /// Wheel index, 0-based.
        wheel: usize,
    },
}

/// A detected failure and when it happened.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Failure {
    /// What failed.
    pub kind: FailureKind,
    /// Simulated time of detection (s).
    pub time_s: f64,
}

/// Watches the telemetry step by step and latches the first failure.
#[derive(Clone, Debug)]
pub struct FailureMonitor {
    params: FailureParams,
    /// `cos(max_tilt_rad)`: the tilt check compares the body axis' z component with it, so
    /// only a failing step pays for the arc cosine.
    cos_max_tilt: f64,
    slip_secs: [f64; 3],
    lift_off_secs: [f64; 3],
    first: Option<Failure>,
}

impl FailureMonitor {
    /// A monitor with no failure yet.
    pub fn new(params: FailureParams) -> Self {
        Self {
            params,
            cos_max_tilt: params.max_tilt_rad.min(core::f64::consts::PI).cos(),
            slip_secs: [0.0; 3],
            lift_off_secs: [0.0; 3],
            first: None,
        }
    }

    /// The first failure seen, if any.
    pub fn failure(&self) -> Option<Failure> {
        self.first
    }

    /// Clears the latched failure and the timers.
    pub fn reset(&mut self) {
        *self = Self::new(self.params);
    }

    /// Updates the timers with one step of `dt_secs`; `chassis_lowest_z_m` is the height of
    /// the chassis' lowest point above the floor. Returns the first failure (latched).
    pub fn update(
        &mut self,
        t: &StepTelemetry,
        chassis_lowest_z_m: f64,
        dt_secs: f64,
    ) -> Option<Failure> {
        if self.first.is_some() {
            return self.first;
        }
        let p = &self.params;
        let mut kind = None;
        // tilt > max_tilt  <=>  cos(tilt) < cos(max_tilt), for tilts in [0, pi].
        if body_axis_z(t) < self.cos_max_tilt {
            kind = Some(FailureKind::Tilt {
                tilt_rad: tilt_from_vertical_rad(t),
            });
        } else if chassis_lowest_z_m <= 0.0 {
            kind = Some(FailureKind::BodyTouchedFloor);
        }
        for (i, w) in t.wheels.iter().enumerate() {
            let slipping =
                w.slipping && w.slip_speed_m_per_s.abs() > p.slip_speed_threshold_m_per_s;
            self.slip_secs[i] = if slipping {
                self.slip_secs[i] + dt_secs
            } else {
                0.0
            };
            self.lift_off_secs[i] = if w.normal_force_n < p.lift_off_force_n {
                self.lift_off_secs[i] + dt_secs
            } else {
                0.0
            };
            if kind.is_none() && self.slip_secs[i] > p.max_slip_duration_s {
                kind = Some(FailureKind::SustainedSlip { wheel: i });
            }
            if kind.is_none() && self.lift_off_secs[i] > p.max_lift_off_duration_s {
                kind = Some(FailureKind::LiftOff { wheel: i });
            }
        }
        self.first = kind.map(|kind| Failure {
            kind,
            time_s: t.time_s,
        });
        self.first
    }
}

/// Angle between the body axis and the vertical (rad).
pub fn tilt_from_vertical_rad(t: &StepTelemetry) -> f64 {
    body_axis_z(t).acos()
}

/// The world z component of the body's z axis, clamped to [-1, 1] (the cosine of the tilt).
fn body_axis_z(t: &StepTelemetry) -> f64 {
    let z = t.body_orientation * nalgebra::Vector3::z();
    z.z.clamp(-1.0, 1.0)
}
