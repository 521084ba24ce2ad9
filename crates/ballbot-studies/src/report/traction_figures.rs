//! Figures of the traction study: the envelope against the world's failing accelerations
//! (polar), and one limited ramp (time series).

use crate::report::plot::{LineStyle, PolarFigure, PolarSeries, Series, Subplot, TimeSeriesFigure};
use crate::studies::traction::{RunRecord, TractionSample, TractionStudy};
use ballbot_core::traction::{TractionEnvelope, TractionParams};

impl TractionStudy {
    /// The controller's envelope (recommended margins, and the plain quasi-static limit)
    /// every 5 deg, against the world's largest surviving ramp acceleration with traction
    /// control off and the largest acceleration reached with it on, per heading (m/s^2).
    /// Censored searches are drawn at their lower bound.
    pub fn envelope_figure(&self) -> PolarFigure {
        let recommended = TractionParams::recommended(&self.robot);
        let exact = TractionParams {
            friction_safety_factor: 1.0,
            ..recommended
        };
        let dense: Vec<f64> = (0..=72).map(|k| f64::from(k) * 5.0).collect();
        let along = |p: &TractionParams<f64>| -> Vec<f64> {
            TractionEnvelope::new(&self.robot, p).map_or(vec![f64::NAN; dense.len()], |e| {
                dense
                    .iter()
                    .map(|d| {
                        let h = d.to_radians();
                        e.friction_limit_m_per_s2(h.cos(), h.sin())
                    })
                    .collect()
            })
        };
        let h: Vec<f64> = self.headings.iter().map(|r| r.heading_deg).collect();
        let closed = h.len() > 2;
        let line = |s: PolarSeries| if closed { s } else { s.open() };
        let off: Vec<f64> = self
            .headings
            .iter()
            .map(|r| r.off.largest_surviving_m_per_s2.unwrap_or(0.0))
            .collect();
        let on: Vec<f64> = self
            .headings
            .iter()
            .map(|r| r.on_top.max_accel_m_per_s2)
            .collect();
        PolarFigure::new(
            "MiaPURE acceleration per heading: traction envelope and the 3D world",
            "acceleration (m/s²)",
        )
        .with(
            PolarSeries::new(
                "quasi-static contact limit (μ = 0.6)",
                &dense,
                &along(&exact),
            )
            .with_style(LineStyle::Dashed),
        )
        .with(PolarSeries::new(
            "controller's envelope (μ/2, N ≥ 86 N)",
            &dense,
            &along(&recommended),
        ))
        .with(line(PolarSeries::new(
            "world, traction control off: largest surviving ramp",
            &h,
            &off,
        )))
        .with(
            PolarSeries::new(
                "world, traction control on: reached (request 3 m/s²)",
                &h,
                &on,
            )
            .with_style(LineStyle::Points),
        )
    }

    /// One limited ramp (traction control on, the first heading, request at the search's top):
    /// commanded, shaped and ball speed; the shaped command's acceleration, the envelope's limit
    /// and the ball's measured acceleration; the world's cone use; estimated and true slip.
    pub fn limited_ramp_figure(&self) -> Option<TimeSeriesFigure> {
        let first = self.headings.first()?;
        Some(ramp_figure(
            &first.on_top,
            &format!(
                "Traction-aware ramp towards {:.0} deg (request {} m/s²), default world",
                first.heading_deg, self.settings.protocol.accel_bracket_m_per_s2[1]
            ),
        ))
    }
}

fn ramp_figure(run: &RunRecord, title: &str) -> TimeSeriesFigure {
    let s = &run.samples;
    let t: Vec<f64> = s.iter().map(|x| x.time_secs).collect();
    let col = |f: &dyn Fn(&TractionSample) -> f64| -> Vec<f64> { s.iter().map(f).collect() };
    // Accelerations as 0.1 s central differences of the sampled speeds.
    let diff = |v: &[f64]| -> Vec<f64> {
        (0..v.len())
            .map(|i| {
                let (a, b) = (i.saturating_sub(5), (i + 5).min(v.len() - 1));
                if b > a {
                    (v[b] - v[a]) / (t[b] - t[a])
                } else {
                    f64::NAN
                }
            })
            .collect()
    };
    let shaped = col(&|x| x.shaped_m_per_s);
    let ball = col(&|x| x.speed_m_per_s);
    let mut fig = TimeSeriesFigure::new(title)
        .with(
            Subplot::new("speed (m/s)")
                .with(
                    Series::new("ramp command", &t, &col(&|x| x.command_m_per_s))
                        .with_style(LineStyle::Dashed),
                )
                .with(Series::new("shaped command", &t, &shaped).with_style(LineStyle::Dashed))
                .with(Series::new("ball", &t, &ball)),
        )
        .with(
            Subplot::new("acceleration (m/s²)")
                .with(
                    Series::new(
                        "envelope limit",
                        &t,
                        &col(&|x| x.accel_limit_m_per_s2.unwrap_or(f64::NAN)),
                    )
                    .with_style(LineStyle::Dashed),
                )
                .with(Series::new("shaped command", &t, &diff(&shaped)))
                .with(Series::new("ball", &t, &diff(&ball))),
        )
        .with(
            Subplot::new("cone use |F|/(μN), max of 3").with(Series::new(
                "world",
                &t,
                &col(&|x| x.max_cone_utilisation),
            )),
        )
        .with(
            Subplot::new("slip speed (m/s), max of 3")
                .with(Series::new(
                    "controller's estimate",
                    &t,
                    &col(&|x| x.max_slip_estimate_m_per_s),
                ))
                .with(Series::new("world", &t, &col(&|x| x.max_slip_m_per_s))),
        );
    if let Some(f) = run.failure {
        fig = fig.marker(f.time_secs, &format!("failure: {f}"));
    }
    fig
}
