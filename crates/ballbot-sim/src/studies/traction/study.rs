//! The whole traction study on the shared job runner (see the [module](super) docs).

use super::probe::RunRecord;
use super::runs::{
    Control, FrictionPatch, PatchCrossing, cross_patch, ramp, rider_lean, stop_from_cruise,
};
use crate::studies::max_speed::{FailingAccel, MaxSpeedProtocol, failing_acceleration};
use crate::studies::runner::run_jobs;
use crate::world::{WorldError, WorldParams};
use ballbot_core::BallbotParams;
use ballbot_core::command::LeanToDriveParams;
use ballbot_core::traction::{TractionEnvelope, TractionParams};

/// What the study runs.
#[derive(Clone, Debug, PartialEq)]
pub struct TractionStudySettings {
    /// The failing-acceleration protocol and the shaper caps every `on`/`off` run uses
    /// ([`MaxSpeedProtocol::default`]: ramps to 3 m/s, search in [0.5, 3] m/s^2 on a
    /// 0.05 m/s^2 grid, caps 8 m/s and 20 m/s^2).
    pub protocol: MaxSpeedProtocol,
    /// Headings of the failing-acceleration comparison (deg). Default 0 to 345 every 15.
    pub headings_deg: Vec<f64>,
    /// Seed of the sensor noise of every run. Default 1.
    pub seed: u64,
    /// More seeds for the traction-on ramps at the search's top request (`failed_on` if any
    /// fails). Default 2, 3; none in the quick variant.
    pub extra_on_seeds: Vec<u64>,
    /// Headings of the stop from 1.4 m/s (deg). Default 0, 90, 180.
    pub stop_headings_deg: Vec<f64>,
    /// Controllers of the stop. Default on, off, shipped.
    pub stop_controls: Vec<Control>,
    /// Patch variants. Default floor and wet.
    pub patch_variants: Vec<PatchVariant>,
    /// Controllers of the patch crossings and the rider runs. Default on, off.
    pub controls: Vec<Control>,
    /// Directions the rider leans (deg). Default 0 (back, towards OW1) and 180 (forward).
    pub rider_headings_deg: Vec<f64>,
    /// The rider's lean-to-drive settings. Default a sporty rider: the rider defaults with
    /// 2 m/s (the paper's design target) and 2 m/s^2 (an acceleration the strong direction
    /// carries: the 3D world's failing acceleration away from OW1 is above 3 m/s^2).
    pub rider: LeanToDriveParams<f64>,
    /// The rider's lean (rad). Default 0.3 (17 deg, far beyond the 3 deg deadband: full speed).
    pub rider_lean_rad: f64,
    /// Worker threads; 0 uses every available core. Default 0.
    pub threads: usize,
}

impl TractionStudySettings {
    /// The full study.
    pub fn paper() -> Self {
        Self {
            protocol: MaxSpeedProtocol::default(),
            headings_deg: (0..24).map(|k| f64::from(k) * 15.0).collect(),
            seed: 1,
            extra_on_seeds: vec![2, 3],
            stop_headings_deg: vec![0.0, 90.0, 180.0],
            stop_controls: vec![Control::TractionOn, Control::TractionOff, Control::Shipped],
            patch_variants: PatchVariant::ALL.to_vec(),
            controls: vec![Control::TractionOn, Control::TractionOff],
            rider_headings_deg: vec![0.0, 180.0],
            rider: LeanToDriveParams {
                max_speed_m_per_s: 2.0,
                max_accel_m_per_s2: 2.0,
                ..LeanToDriveParams::rider()
            },
            rider_lean_rad: 0.3,
            threads: 0,
        }
    }

    /// The CI smoke variant: 0 and 180 deg on a 0.25 m/s^2 search grid, the stop with
    /// traction control on at 0 and 180 deg, the wet patch and the rider leaning back, on and
    /// off.
    pub fn quick() -> Self {
        let paper = Self::paper();
        Self {
            protocol: MaxSpeedProtocol {
                accel_resolution_m_per_s2: 0.25,
                ..paper.protocol
            },
            headings_deg: vec![0.0, 180.0],
            extra_on_seeds: Vec::new(),
            stop_headings_deg: vec![0.0, 180.0],
            stop_controls: vec![Control::TractionOn],
            patch_variants: vec![PatchVariant::Wet],
            rider_headings_deg: vec![0.0],
            ..paper
        }
    }
}

/// Which friction patch, and how it is crossed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PatchVariant {
    /// The floor at mu 0.3 (the case), crossed cruising at 1.4 m/s.
    Floor,
    /// A wet patch (the floor at mu 0.3 and the wheel-ball friction at 0.3 while the ball is
    /// on it: the water wets the ball), crossed cruising at 1.4 m/s.
    WetCruise,
    /// The wet patch crossed while the ball still accelerates towards 2 m/s at the envelope's
    /// acceleration towards OW1 (1.30 m/s^2, planned for mu 0.6) and passes 1.4 m/s: more than
    /// the wet contacts carry, and the wheels slip.
    Wet,
}

impl PatchVariant {
    /// All three.
    pub const ALL: [Self; 3] = [Self::Floor, Self::WetCruise, Self::Wet];

    /// The name in JSON and tables.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Floor => "floor_mu_0.3",
            Self::WetCruise => "wet_mu_0.3_cruise",
            Self::Wet => "wet_mu_0.3",
        }
    }

    fn patch(self) -> FrictionPatch {
        FrictionPatch {
            length_m: 0.5,
            floor_friction: 0.3,
            wheel_ball_friction: (self != Self::Floor).then_some(0.3),
        }
    }

    fn cruising(self) -> bool {
        self != Self::Wet
    }
}

/// One heading of the failing-acceleration comparison.
#[derive(Clone, Debug, PartialEq)]
pub struct HeadingResult {
    /// Heading (deg).
    pub heading_deg: f64,
    /// Traction control off: the failing-acceleration search.
    pub off: FailingAccel,
    /// On: the ramp at the search's top request.
    pub on_top: RunRecord,
    /// On: the same ramp with [`TractionStudySettings::extra_on_seeds`] (without samples), in
    /// their order.
    pub on_top_other_seeds: Vec<RunRecord>,
    /// On: the ramp at the acceleration that failed off (if one did).
    pub on_at_off_failing: Option<RunRecord>,
    /// The controller's envelope at this heading (m/s^2; friction and lift-off, recommended
    /// margins).
    pub envelope_m_per_s2: f64,
    /// The plain quasi-static limit (safety factor 1) (m/s^2).
    pub quasi_static_m_per_s2: f64,
}

/// A stop from 1.4 m/s.
#[derive(Clone, Debug, PartialEq)]
pub struct StopResult {
    /// Heading of travel (deg).
    pub heading_deg: f64,
    /// Controller.
    pub control: Control,
    /// The run (without its samples).
    pub record: RunRecord,
    /// Time from the stop command to below 0.05 m/s (s), if reached.
    pub stop_secs: Option<f64>,
}

/// A patch crossing.
#[derive(Clone, Debug, PartialEq)]
pub struct PatchResult {
    /// Which patch.
    pub variant: PatchVariant,
    /// Controller.
    pub control: Control,
    /// The run.
    pub record: RunRecord,
    /// When the ball was on the patch.
    pub on_patch: Option<PatchCrossing>,
}

impl PatchResult {
    /// Whether the body stayed within the world's fall limit `fall_tilt_rad` through the
    /// crossing (a slip failure of the world does not end the run).
    pub fn stayed_up(&self, fall_tilt_rad: f64) -> bool {
        self.record.max_tilt_rad <= fall_tilt_rad
    }

    /// Time from the world's first wheel slip to the monitor's first flag (ms), when both
    /// happened.
    pub fn detection_latency_ms(&self) -> Option<f64> {
        let r = &self.record;
        Some((r.first_detection_secs? - r.first_world_slip_secs?) * 1e3)
    }
}

/// A rider's lean.
#[derive(Clone, Debug, PartialEq)]
pub struct RiderResult {
    /// Direction of the lean (deg).
    pub heading_deg: f64,
    /// Controller.
    pub control: Control,
    /// The run (without its samples).
    pub record: RunRecord,
}

/// The study's results.
#[derive(Clone, Debug, PartialEq)]
pub struct TractionStudy {
    /// The settings it ran with.
    pub settings: TractionStudySettings,
    /// The robot.
    pub robot: BallbotParams<f64>,
    /// Per heading.
    pub headings: Vec<HeadingResult>,
    /// Stops.
    pub stops: Vec<StopResult>,
    /// Patch crossings.
    pub patches: Vec<PatchResult>,
    /// Rider runs.
    pub riders: Vec<RiderResult>,
}

#[derive(Clone, Copy, Debug)]
enum Job {
    Failing(f64),
    RampOn(f64, f64, u64),
    Stop(f64, Control),
    Patch(PatchVariant, Control),
    Rider(f64, Control),
}

enum Outcome {
    Failing(Box<FailingAccel>),
    Run(Box<RunRecord>, Option<PatchCrossing>, Option<f64>),
}

/// Runs (jobs) of the study's first phase; the second adds one ramp per heading that failed
/// off.
pub fn job_count(settings: &TractionStudySettings) -> usize {
    phase_one(settings).len() + settings.headings_deg.len()
}

fn phase_one(s: &TractionStudySettings) -> Vec<Job> {
    let top = s.protocol.accel_bracket_m_per_s2[1];
    let mut jobs: Vec<Job> = s.headings_deg.iter().map(|&h| Job::Failing(h)).collect();
    for &seed in std::iter::once(&s.seed).chain(&s.extra_on_seeds) {
        jobs.extend(s.headings_deg.iter().map(|&h| Job::RampOn(h, top, seed)));
    }
    for &h in &s.stop_headings_deg {
        jobs.extend(s.stop_controls.iter().map(|&c| Job::Stop(h, c)));
    }
    for &v in &s.patch_variants {
        jobs.extend(s.controls.iter().map(|&c| Job::Patch(v, c)));
    }
    for &h in &s.rider_headings_deg {
        jobs.extend(s.controls.iter().map(|&c| Job::Rider(h, c)));
    }
    jobs
}

fn run_job(
    params: WorldParams,
    s: &TractionStudySettings,
    job: Job,
) -> Result<Outcome, WorldError> {
    let caps = &s.protocol.shaper;
    let top_speed = s.protocol.fast_top_m_per_s;
    let run = |r: RunRecord| Outcome::Run(Box::new(r), None, None);
    Ok(match job {
        Job::Failing(h) => Outcome::Failing(Box::new(failing_acceleration(
            params,
            &s.protocol,
            h,
            s.seed,
        )?)),
        Job::RampOn(h, a, seed) => {
            let config = Control::TractionOn.config(&params, caps)?;
            let mut p = params;
            p.sensors.seed = seed;
            run(ramp(p, config, h, a, top_speed)?)
        }
        Job::Stop(h, c) => {
            let config = c.config(&params, caps)?;
            let (r, stop) = stop_from_cruise(params, config, h, 1.4, 4.0, 0.05, 6.0)?;
            Outcome::Run(Box::new(r), None, stop)
        }
        Job::Patch(v, c) => {
            let config = c.config(&params, caps)?;
            // Cruising: the shipped acceleration, then 1 s at 1.4 m/s before the patch.
            // Accelerating: at the envelope's acceleration towards OW1 for both controllers
            // (on, the envelope holds any request to it; off, the ramp asks for exactly it).
            let (accel, lead, top) = if v.cruising() {
                (1.0, 1.0, 1.4)
            } else {
                let envelope = TractionEnvelope::new(
                    &params.robot,
                    &TractionParams::recommended(&params.robot),
                )?;
                (envelope.friction_limit_m_per_s2(1.0, 0.0), 0.0, 2.0)
            };
            let (r, window) =
                cross_patch(params, config, 0.0, accel, top, 1.4, lead, &v.patch(), 1.0)?;
            Outcome::Run(Box::new(r), window, None)
        }
        Job::Rider(h, c) => {
            let config = c.config(&params, caps)?;
            run(rider_lean(
                params,
                config,
                s.rider,
                h,
                s.rider_lean_rad,
                3.0,
                3.0,
            )?)
        }
    })
}

/// Runs the study on the default world of `robot`; `progress(what)` after each run.
pub fn run_study(
    robot: BallbotParams<f64>,
    settings: &TractionStudySettings,
    progress: &(dyn Fn(&str) + Sync),
) -> Result<TractionStudy, WorldError> {
    settings.protocol.validate()?;
    let mut params = WorldParams::with_robot(robot);
    params.sensors.seed = settings.seed;
    let jobs = phase_one(settings);
    let done = |i: usize| progress(&format!("traction run {}", i + 1));
    let outcomes = run_jobs(
        &jobs,
        settings.threads,
        |&j| run_job(params, settings, j),
        &done,
    )?;
    let recommended = TractionParams::recommended(&robot);
    let planned = TractionEnvelope::new(&robot, &recommended)?;
    let exact = TractionEnvelope::new(
        &robot,
        &TractionParams {
            friction_safety_factor: 1.0,
            ..recommended
        },
    )?;
    let (mut failing, mut ramps_on, mut ramps_other) = (Vec::new(), Vec::new(), Vec::new());
    let (mut stops, mut patches, mut riders) = (Vec::new(), Vec::new(), Vec::new());
    for (job, outcome) in jobs.iter().zip(outcomes) {
        match (*job, outcome) {
            (Job::Failing(_), Outcome::Failing(f)) => failing.push(*f),
            (Job::RampOn(_, _, seed), Outcome::Run(r, ..)) if seed == settings.seed => {
                ramps_on.push(*r);
            }
            (Job::RampOn(..), Outcome::Run(r, ..)) => ramps_other.push(without_samples(*r)),
            (Job::Stop(h, control), Outcome::Run(r, _, stop_secs)) => stops.push(StopResult {
                heading_deg: h,
                control,
                record: without_samples(*r),
                stop_secs,
            }),
            (Job::Patch(variant, control), Outcome::Run(r, window, _)) => {
                patches.push(PatchResult {
                    variant,
                    control,
                    record: *r,
                    on_patch: window,
                });
            }
            (Job::Rider(h, control), Outcome::Run(r, ..)) => riders.push(RiderResult {
                heading_deg: h,
                control,
                record: without_samples(*r),
            }),
            _ => unreachable!("each job returns its own kind of outcome"),
        }
    }
    // Phase two: traction control on at exactly the ramp that failed off.
    let second: Vec<(f64, f64)> = failing
        .iter()
        .filter_map(|f| Some((f.heading_deg, f.smallest_failing_m_per_s2?)))
        .collect();
    let caps = &settings.protocol.shaper;
    let top_speed = settings.protocol.fast_top_m_per_s;
    let second_runs = run_jobs(
        &second,
        settings.threads,
        |&(h, a)| {
            ramp(
                params,
                Control::TractionOn.config(&params, caps)?,
                h,
                a,
                top_speed,
            )
        },
        &|i| progress(&format!("traction run {}", jobs.len() + i + 1)),
    )?;
    let n = settings.headings_deg.len();
    let headings = failing
        .into_iter()
        .zip(ramps_on)
        .enumerate()
        .map(|(i, (off, on_top))| {
            // The extra seeds' runs are in seed-major order.
            let on_top_other_seeds = (0..settings.extra_on_seeds.len())
                .filter_map(|k| ramps_other.get(k * n + i).cloned())
                .collect();
            let h = off.heading_deg.to_radians();
            let (dx, dy) = (h.cos(), h.sin());
            let on_at_off_failing = second
                .iter()
                .position(|&(hd, _)| hd == off.heading_deg)
                .map(|i| without_samples(second_runs[i].clone()));
            HeadingResult {
                heading_deg: off.heading_deg,
                on_at_off_failing,
                envelope_m_per_s2: planned.friction_limit_m_per_s2(dx, dy),
                quasi_static_m_per_s2: exact.friction_limit_m_per_s2(dx, dy),
                off,
                on_top,
                on_top_other_seeds,
            }
        })
        .collect();
    Ok(TractionStudy {
        settings: settings.clone(),
        robot,
        headings,
        stops,
        patches,
        riders,
    })
}

impl TractionStudy {
    /// The world's fall limit: tilt from the vertical (rad).
    pub fn fall_tilt_rad(&self) -> f64 {
        WorldParams::with_robot(self.robot).failure.max_tilt_rad
    }
}

fn without_samples(mut r: RunRecord) -> RunRecord {
    r.samples = Vec::new();
    r
}
