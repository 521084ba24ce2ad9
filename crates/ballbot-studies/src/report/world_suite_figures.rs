//! Figures of the world suite: a braking run (speed, tilt, cone utilisation around the onset)
//! and the push recovery (tilt after the largest recovered and the smallest failing push).

use crate::report::plot::{LegendPosition, LineStyle, Series, Subplot, TimeSeriesFigure};
use crate::studies::push::PushRecovery;
use crate::studies::world_braking::{BrakingOutcome, BrakingRun, BrakingSample};
use ballbot_world::world::wheel_name;

/// The braking run's figure: the last second before braking (0.25 s before a failure) to the
/// end, time from the braking onset.
pub fn braking_figure(run: &BrakingRun, title: &str) -> TimeSeriesFigure {
    let failure = match run.outcome {
        BrakingOutcome::Failed(f) => Some(f),
        _ => None,
    };
    // A failure comes within tens of ms of the onset: zoom in on it.
    let from = run.brake_start_secs - if failure.is_some() { 0.25 } else { 1.0 };
    let samples: Vec<_> = run.samples.iter().filter(|s| s.time_secs >= from).collect();
    let t: Vec<f64> = samples
        .iter()
        .map(|s| s.time_secs - run.brake_start_secs)
        .collect();
    let col =
        |f: &dyn Fn(&BrakingSample) -> f64| -> Vec<f64> { samples.iter().map(|s| f(s)).collect() };
    let mut cone =
        Subplot::new("cone utilisation |F|/(μN)").with_legend(LegendPosition::UpperRight);
    for i in 0..3 {
        cone = cone.with(Series::new(
            wheel_name(i),
            &t,
            &col(&|s| s.cone_utilisation[i]),
        ));
    }
    let fig = TimeSeriesFigure::new(title)
        .with(
            Subplot::new("speed along heading (m/s)")
                .with(
                    Series::new("command", &t, &col(&|s| s.command_m_per_s))
                        .with_style(LineStyle::Dashed),
                )
                .with(Series::new("ball", &t, &col(&|s| s.speed_m_per_s)))
                .with_legend(LegendPosition::UpperRight),
        )
        .with(
            Subplot::new("tilt in plane of travel (deg)")
                .with(
                    Series::new("command", &t, &col(&|s| s.command_tilt_rad.to_degrees()))
                        .with_style(LineStyle::Dashed),
                )
                .with(Series::new("body", &t, &col(&|s| s.tilt_rad.to_degrees())))
                .with_legend(LegendPosition::UpperRight),
        )
        .with(cone);
    let end = t
        .last()
        .copied()
        .unwrap_or(run.duration_secs)
        .min(run.duration_secs);
    let fig = fig.shade(0.0, end, "braking");
    match failure {
        Some(f) => fig.marker(f.time_secs - run.brake_start_secs, &f.kind.to_string()),
        None => fig,
    }
}

/// The push-recovery figure: per direction, the tilt after the largest recovered and the
/// smallest failing push.
pub fn push_figure(push: &[&PushRecovery]) -> TimeSeriesFigure {
    let mut fig = TimeSeriesFigure::new(
        "MiaPURE push recovery (3D world): tilt after a push at the body's COM",
    );
    for r in push {
        let mut sub = Subplot::new(&format!("tilt (deg), push {:.0}°", r.heading_deg))
            .with_legend(LegendPosition::UpperRight);
        let trials = [
            (r.largest_recovered(), "recovered"),
            (r.smallest_failing(), "not recovered"),
        ];
        for (trial, what) in trials {
            if let Some(tr) = trial {
                let t: Vec<f64> = tr.samples.iter().map(|s| s.time_secs).collect();
                let v: Vec<f64> = tr.samples.iter().map(|s| s.tilt_rad.to_degrees()).collect();
                sub = sub.with(Series::new(
                    &format!("{:.1} N·s {what}", tr.impulse_ns),
                    &t,
                    &v,
                ));
            }
        }
        let limit = 15.0;
        sub = sub.with(
            Series::new("15° bound", &[-1.0, 4.0], &[limit, limit]).with_style(LineStyle::Dashed),
        );
        fig = fig.with(sub);
    }
    fig.marker(0.0, "push")
}
