//! Figures of the maximum-speed study: the capability map as polar plots and the Fig.
//! "acc"-like time series of one ramp.

use crate::report::plot::{LineStyle, PolarFigure, PolarSeries, Series, Subplot, TimeSeriesFigure};
use crate::studies::max_speed::{
    MaxSpeedStudy, PAPER_MAX_SPEED, quasi_static_failing_accel_m_per_s2,
};
use crate::studies::ramp::{RampResult, RampSample};
use ballbot_world::world::wheel_name;

impl MaxSpeedStudy {
    /// Polar plots of the capability map: maximum speed (slow ramp) and failing acceleration
    /// against heading, the paper's points marked. Censored values are drawn at their lower
    /// bound.
    pub fn capability_figures(&self) -> [PolarFigure; 2] {
        let h: Vec<f64> = self.map.iter().map(|m| m.heading_deg).collect();
        let speed: Vec<f64> = self.map.iter().map(|m| m.slow.max_speed_m_per_s).collect();
        let accel: Vec<f64> = self
            .map
            .iter()
            .map(|m| m.failing.largest_surviving_m_per_s2.unwrap_or(0.0))
            .collect();
        let closed = self.map.len() > 2;
        let line = |s: PolarSeries| if closed { s } else { s.open() };
        let paper_h: Vec<f64> = PAPER_MAX_SPEED.iter().map(|p| p.heading_deg).collect();
        let paper_v: Vec<f64> = PAPER_MAX_SPEED.iter().map(|p| p.speed_m_per_s).collect();
        let speed_fig = PolarFigure::new(
            "MiaPURE maximum speed (slow ramp) per heading",
            "max speed (m/s)",
        )
        .with(line(PolarSeries::new(
            "simulated (≥ where censored)",
            &h,
            &speed,
        )))
        .with(
            PolarSeries::new("paper (0 deg: upper bound)", &paper_h, &paper_v)
                .with_style(LineStyle::Points),
        );
        let accel_fig = PolarFigure::new(
            "MiaPURE largest surviving ramp acceleration per heading",
            "acceleration (m/s²)",
        )
        .with(line(PolarSeries::new("simulated", &h, &accel)))
        .with(line(
            PolarSeries::new(
                "quasi-static contact model (core)",
                &h,
                &h.iter()
                    .map(|&d| {
                        quasi_static_failing_accel_m_per_s2(&self.params.robot, d)
                            .unwrap_or(f64::NAN)
                    })
                    .collect::<Vec<_>>(),
            )
            .with_style(LineStyle::Dashed),
        ));
        let top = self.settings.protocol.fast_top_m_per_s;
        let (cruise_h, cruise_a): (Vec<f64>, Vec<f64>) = self
            .map
            .iter()
            .filter(|m| m.failing.failed_during_ramp(top) == Some(false))
            .map(|m| {
                (
                    m.heading_deg,
                    m.failing.largest_surviving_m_per_s2.unwrap_or(0.0),
                )
            })
            .unzip();
        let accel_fig = if cruise_h.is_empty() {
            accel_fig
        } else {
            accel_fig.with(
                PolarSeries::new(
                    "next step failed at cruise, not accelerating",
                    &cruise_h,
                    &cruise_a,
                )
                .with_style(LineStyle::Points),
            )
        };
        [speed_fig, accel_fig]
    }
}

/// The Fig. "acc"-like figure of one ramp: command and ball speed, tilt, the three normal
/// forces and cone utilisations against time, the failure instant as a vertical line.
pub fn acc_figure(run: &RampResult, title: &str) -> TimeSeriesFigure {
    let s = &run.samples;
    let t: Vec<f64> = s.iter().map(|x| x.time_secs).collect();
    let col = |f: &dyn Fn(&RampSample) -> f64| -> Vec<f64> { s.iter().map(f).collect() };
    let mut normal = Subplot::new("normal force N (N)");
    let mut cone = Subplot::new("cone use |F|/(μN)");
    for i in 0..3 {
        let label = wheel_name(i);
        normal = normal.with(Series::new(label, &t, &col(&|x| x.normal_force_n[i])));
        cone = cone.with(Series::new(label, &t, &col(&|x| x.cone_utilisation[i])));
    }
    let mut fig = TimeSeriesFigure::new(title)
        .with(
            Subplot::new("speed (m/s)")
                .with(
                    Series::new("ramp command", &t, &col(&|x| x.command_m_per_s))
                        .with_style(LineStyle::Dashed),
                )
                .with(
                    Series::new("shaped command", &t, &col(&|x| x.shaped_command_m_per_s))
                        .with_style(LineStyle::Dashed),
                )
                .with(Series::new("ball", &t, &col(&|x| x.speed_m_per_s))),
        )
        .with(Subplot::new("tilt (deg)").with(Series::new(
            "tilt",
            &t,
            &col(&|x| x.tilt_rad.to_degrees()),
        )))
        .with(normal)
        .with(cone);
    if let Some(f) = run.failure {
        fig = fig.marker(f.time_secs, &format!("failure: {f}"));
    }
    fig
}
