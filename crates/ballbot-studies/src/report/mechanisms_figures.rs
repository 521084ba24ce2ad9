//! Figures of the mechanism study: maximum speed per heading and mechanism beside the paper's,
//! failure speed against `a / (mu g)`, and the contact-load ripple spectra against speed.
//!
//! The figures reuse [`TimeSeriesFigure`] with another x axis (heading, `a / (mu g)`,
//! frequency, speed): its x label says which.

use crate::report::plot::{LineStyle, PALETTE, Series, Subplot, TimeSeriesFigure};
use crate::studies::max_speed::PAPER_MAX_SPEED;
use crate::studies::mechanisms::{MechanismStudy, RippleSpectrum};
use ballbot_world::world::wheel_name;

impl MechanismStudy {
    /// Maximum speed (slow ramp) against heading, one subplot per controller, one series per
    /// world variant; the paper's values as points.
    pub fn slow_ramp_figure(&self) -> TimeSeriesFigure {
        let s = &self.settings.protocol.slow_ramp;
        let mut fig = TimeSeriesFigure::new(&format!(
            "Slow ramp ({} m/s², seed {}): maximum speed per heading and world mechanism",
            s.accel_m_per_s2, self.settings.seed
        ));
        fig.x_label = "heading (deg, 0 = towards OW1)".to_owned();
        fig.subplot_height_px = 320;
        let paper_h: Vec<f64> = PAPER_MAX_SPEED.iter().map(|p| p.heading_deg).collect();
        let paper_v: Vec<f64> = PAPER_MAX_SPEED.iter().map(|p| p.speed_m_per_s).collect();
        for &c in &self.settings.controllers {
            let mut sub = Subplot::new(&format!("{} controller: max speed (m/s)", c.as_str()))
                .with_y_range(0.0, 6.5);
            for (k, &m) in self.settings.mechanisms.iter().enumerate() {
                let (h, v): (Vec<f64>, Vec<f64>) = self
                    .settings
                    .headings_deg
                    .iter()
                    .filter_map(|&h| self.run(c, m, h).map(|r| (h, r.outcome.max_speed_m_per_s)))
                    .unzip();
                sub = sub
                    .with(Series::new(m.as_str(), &h, &v).with_color(PALETTE[k % PALETTE.len()]));
            }
            sub = sub.with(
                Series::new("paper (0 deg: upper bound)", &paper_h, &paper_v)
                    .with_style(LineStyle::Points)
                    .with_color(PALETTE[PALETTE.len() - 3]),
            );
            fig = fig.with(sub);
        }
        fig
    }

    /// Highest speed before the run ended against the ramp acceleration over `mu g`, one
    /// series per heading; runs that ended without failure are drawn as their own series
    /// (lower bounds).
    pub fn sweep_figure(&self) -> TimeSeriesFigure {
        let mut fig = TimeSeriesFigure::new(
            "Default world, corrected controller: failure speed against ramp acceleration / (μ g)",
        );
        fig.x_label = "ramp acceleration / (μ g)".to_owned();
        let mut sub = Subplot::new("max speed before failure (m/s)");
        let mut headings: Vec<f64> = self.sweep.iter().map(|p| p.outcome.heading_deg).collect();
        headings.dedup();
        for (k, &h) in headings.iter().enumerate() {
            let at = |ended: bool| -> (Vec<f64>, Vec<f64>) {
                self.sweep
                    .iter()
                    .filter(|p| {
                        (p.outcome.heading_deg - h).abs() < 1e-9
                            && (p.outcome.failure.is_some()
                                && p.outcome.supervisor_stop_secs.is_none())
                                == ended
                    })
                    .map(|p| (p.accel_over_mu_g(), p.outcome.max_speed_m_per_s))
                    .unzip()
            };
            let (x, y) = at(true);
            sub = sub.with(
                Series::new(&format!("{h:.0} deg: failed"), &x, &y)
                    .with_style(LineStyle::Points)
                    .with_color(PALETTE[k % PALETTE.len()]),
            );
            let (x, y) = at(false);
            if !x.is_empty() {
                sub = sub.with(
                    Series::new(&format!("{h:.0} deg: no failure / stop (≥)"), &x, &y)
                        .with_style(LineStyle::Points)
                        .with_color(PALETTE[(k + 3) % PALETTE.len()]),
                );
            }
        }
        fig.with(sub)
    }

    /// The first ripple heading and its cruises that did not fail; `None` without ripple runs.
    fn first_heading_cruises(&self) -> Option<(f64, Vec<&RippleSpectrum>)> {
        let h = self.ripple.first()?.heading_deg;
        let runs = self
            .ripple
            .iter()
            .filter(|r| (r.heading_deg - h).abs() < 1e-9 && r.failure.is_none())
            .collect();
        Some((h, runs))
    }

    /// The normal-force amplitude spectra of the first ripple heading, one subplot per wheel,
    /// one series per cruise speed; `None` without ripple runs.
    pub fn ripple_spectrum_figure(&self) -> Option<TimeSeriesFigure> {
        let (h, runs) = self.first_heading_cruises()?;
        let mut fig = TimeSeriesFigure::new(&format!(
            "Contact-load ripple at {h:.0} deg: normal-force amplitude spectra by cruise speed"
        ));
        fig.x_label = "frequency (Hz)".to_owned();
        for i in 0..3 {
            let mut sub = Subplot::new(&format!("{} |N| (N)", wheel_name(i)));
            for (k, r) in runs.iter().enumerate() {
                sub = sub.with(
                    Series::new(
                        &format!("{:.1} m/s", r.speed_m_per_s),
                        &r.frequencies_hz,
                        &r.wheels[i].amplitude_n,
                    )
                    .with_color(PALETTE[k % PALETTE.len()]),
                );
            }
            fig = fig.with(sub);
        }
        Some(fig)
    }

    /// The spectrum's peak and the roller-passing frequency against cruise speed, per wheel,
    /// and the amplitudes at both; `None` without ripple runs.
    pub fn ripple_peak_figure(&self) -> Option<TimeSeriesFigure> {
        let (h, runs) = self.first_heading_cruises()?;
        let mut fig = TimeSeriesFigure::new(&format!(
            "Contact-load ripple at {h:.0} deg: spectrum peak against the roller-passing frequency"
        ));
        fig.x_label = "cruise speed (m/s)".to_owned();
        let v: Vec<f64> = runs.iter().map(|r| r.speed_m_per_s).collect();
        let mut sub = Subplot::new("frequency (Hz)");
        for (i, &color) in PALETTE.iter().take(3).enumerate() {
            let peak: Vec<f64> = runs.iter().map(|r| r.wheels[i].peak_hz).collect();
            let passing: Vec<f64> = runs
                .iter()
                .map(|r| r.wheels[i].roller_passing_hz.unwrap_or(f64::NAN))
                .collect();
            sub = sub
                .with(
                    Series::new(&format!("{} spectrum peak", wheel_name(i)), &v, &peak)
                        .with_style(LineStyle::Points)
                        .with_color(color),
                )
                .with(
                    Series::new(&format!("{} N_r |ψ̇| / 2π", wheel_name(i)), &v, &passing)
                        .with_style(LineStyle::Dashed)
                        .with_color(color),
                );
        }
        let mut amp = Subplot::new("amplitude (N)");
        for (i, &color) in PALETTE.iter().take(3).enumerate() {
            let at_passing: Vec<f64> = runs
                .iter()
                .map(|r| {
                    r.wheels[i]
                        .amplitude_at_roller_passing_n
                        .unwrap_or(f64::NAN)
                })
                .collect();
            let peak: Vec<f64> = runs.iter().map(|r| r.wheels[i].peak_amplitude_n).collect();
            amp = amp
                .with(
                    Series::new(
                        &format!("{} at N_r |ψ̇| / 2π", wheel_name(i)),
                        &v,
                        &at_passing,
                    )
                    .with_color(color),
                )
                .with(
                    Series::new(&format!("{} at the peak", wheel_name(i)), &v, &peak)
                        .with_style(LineStyle::Points)
                        .with_color(color),
                );
        }
        Some(fig.with(sub).with(amp))
    }
}
