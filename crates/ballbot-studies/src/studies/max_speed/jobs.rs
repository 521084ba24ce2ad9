//! The study's distinct jobs (one slow ramp or one failing-acceleration search each): variants
//! equal to the nominal robot share the nominal robot's jobs.

use super::protocol::MaxSpeedStudySettings;
use super::variant::Variant;
use ballbot_world::world::WorldParams;

/// One job of the maximum-speed study ([`super::MaxSpeedExperiment`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MaxSpeedJob {
    /// One slow ramp ([`super::MaxSpeedProtocol::slow_ramp`]) of a robot variant.
    Slow {
        /// The robot variant.
        variant: Variant,
        /// Heading (deg).
        heading_deg: f64,
        /// Seed of the sensor noise.
        seed: u64,
    },
    /// The failing-acceleration search of a robot variant: the ramp acceleration bisected on
    /// the protocol's grid ([`super::MaxSpeedProtocol::accel_search`]).
    Search {
        /// The robot variant.
        variant: Variant,
        /// Heading (deg).
        heading_deg: f64,
        /// Seed of the sensor noise (the same for every ramp of the search).
        seed: u64,
    },
}

use MaxSpeedJob as Job;

/// Number of jobs (one slow ramp or one failing-acceleration search each) the study runs, for
/// a progress bar.
pub fn job_count(params: &WorldParams, settings: &MaxSpeedStudySettings) -> usize {
    jobs(params, settings).len()
}

pub(super) fn same(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9
}

/// The distinct jobs of the study; variants equal to the nominal robot share its jobs.
pub(super) fn jobs(params: &WorldParams, settings: &MaxSpeedStudySettings) -> Vec<Job> {
    let first_seed = settings.seeds.first().copied().unwrap_or(0);
    let mut out = Vec::new();
    // Searches first: they are the longest jobs, so the pool ends evenly.
    let search = |variant: Variant, heading_deg: f64, out: &mut Vec<Job>| {
        // One search per heading with sensor seed 0: the grid's resolution, not the noise,
        // dominates their spread.
        let job = Job::Search {
            variant: normalise(variant, params),
            heading_deg,
            seed: 0,
        };
        if !out.iter().any(|j| job_eq(j, &job)) {
            out.push(job);
        }
    };
    for &h in &settings.map_headings_deg {
        search(Variant::Nominal, h, &mut out);
    }
    for &h in &settings.sensitivity_headings_deg {
        search(Variant::Nominal, h, &mut out);
        for v in sensitivity_variants(settings) {
            search(v, h, &mut out);
        }
    }
    let slow = |variant: Variant, heading_deg: f64, seed: u64, out: &mut Vec<Job>| {
        let job = Job::Slow {
            variant: normalise(variant, params),
            heading_deg,
            seed,
        };
        if !out.iter().any(|j| job_eq(j, &job)) {
            out.push(job);
        }
    };
    for &h in &settings.trial_headings_deg {
        for &seed in &settings.seeds {
            slow(Variant::Nominal, h, seed, &mut out);
        }
    }
    for &h in &settings.map_headings_deg {
        slow(Variant::Nominal, h, first_seed, &mut out);
    }
    for &h in &settings.sensitivity_headings_deg {
        slow(Variant::Nominal, h, first_seed, &mut out);
        for v in sensitivity_variants(settings) {
            slow(v, h, first_seed, &mut out);
        }
    }
    out
}

/// The non-nominal sensitivity variants (values equal to the nominal robot's are the nominal
/// runs, not repeated).
fn sensitivity_variants(settings: &MaxSpeedStudySettings) -> Vec<Variant> {
    let mut v: Vec<Variant> = settings
        .sensitivity_wheel_ball_friction
        .iter()
        .map(|&mu| Variant::WheelBallFriction(mu))
        .collect();
    v.extend(
        settings
            .sensitivity_com_height_m
            .iter()
            .map(|&l| Variant::ComHeight(l)),
    );
    v
}

fn variant_eq(a: Variant, b: Variant) -> bool {
    match (a, b) {
        (Variant::Nominal, Variant::Nominal) => true,
        (Variant::WheelBallFriction(x), Variant::WheelBallFriction(y))
        | (Variant::ComHeight(x), Variant::ComHeight(y)) => same(x, y),
        _ => false,
    }
}

pub(super) fn job_eq(a: &Job, b: &Job) -> bool {
    match (a, b) {
        (
            Job::Slow {
                variant: va,
                heading_deg: ha,
                seed: sa,
            },
            Job::Slow {
                variant: vb,
                heading_deg: hb,
                seed: sb,
            },
        ) => variant_eq(*va, *vb) && same(*ha, *hb) && sa == sb,
        (
            Job::Search {
                variant: va,
                heading_deg: ha,
                seed: sa,
            },
            Job::Search {
                variant: vb,
                heading_deg: hb,
                seed: sb,
            },
        ) => variant_eq(*va, *vb) && same(*ha, *hb) && sa == sb,
        _ => false,
    }
}

/// Collapses a variant equal to the nominal robot into [`Variant::Nominal`], so its runs are
/// shared with the nominal ones.
pub(super) fn normalise(variant: Variant, params: &WorldParams) -> Variant {
    match variant {
        Variant::WheelBallFriction(mu) if same(mu, params.robot.drivetrain.wheel_ball_friction) => {
            Variant::Nominal
        }
        Variant::ComHeight(l)
            if same(l, params.robot.sagittal.com_height_m)
                && same(l, params.robot.frontal.com_height_m) =>
        {
            Variant::Nominal
        }
        v => v,
    }
}
