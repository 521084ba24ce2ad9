//! Figures of the PIPTB controller comparison: one per controller and the comparison.

use crate::report::plot::{PlotError, Series, Subplot, TimeSeriesFigure};
use crate::studies::piptb::PiptbReport;
use std::path::{Path, PathBuf};

impl PiptbReport {
    /// Writes the paper-style figures into `dir`: `piptb_<controller>.{svg,png}` (tilt, speed
    /// with its command, torque; braking shaded) for trial 0 of each controller, and
    /// `piptb_comparison.{svg,png}` (speed and torque of all three).
    pub fn plot(&self, dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
        let mut written = Vec::new();
        let (t2, t3) = (
            self.settings.brake_start_secs(),
            self.settings.brake_end_secs(),
        );
        let mut speed = Subplot::new("ball speed (m/s)");
        let mut torque = Subplot::new("torque τ (N·m)");
        for c in &self.controllers {
            let Some(trial) = c.trials.first() else {
                continue;
            };
            let s = &trial.series;
            let tilt_deg: Vec<f64> = s.tilt_rad.iter().map(|x| x.to_degrees()).collect();
            let mut fig = TimeSeriesFigure::new(&format!(
                "PIPTB braking, {} (seed {}): J_P = {:.3} N²m²s",
                c.kind.label(),
                trial.seed,
                trial.j_p
            ))
            .with(Subplot::new("tilt θ (deg)").with(Series::new("θ", &s.time_secs, &tilt_deg)))
            .with(
                Subplot::new("ball speed (m/s)")
                    .with(Series::new("r φ̇", &s.time_secs, &s.speed_m_per_s))
                    .with(Series::new(
                        "r φ̇_c (command)",
                        &s.time_secs,
                        &s.command_speed_m_per_s,
                    )),
            )
            .with(
                Subplot::new("torque τ (N·m)")
                    .with(Series::new("τ delivered", &s.time_secs, &s.torque_nm))
                    .with(Series::new(
                        "transmission friction",
                        &s.time_secs,
                        &s.friction_torque_nm,
                    )),
            )
            .shade(t2, t3, "braking");
            if let (Some(f), Some(t)) = (&trial.fault, s.time_secs.last()) {
                fig = fig.marker(*t, f);
            }
            let paths = fig.save_svg_and_png(&dir.join(format!("piptb_{}", c.kind.key())))?;
            written.extend(paths);
            speed = speed.with(Series::new(c.kind.label(), &s.time_secs, &s.speed_m_per_s));
            torque = torque.with(Series::new(c.kind.label(), &s.time_secs, &s.torque_nm));
        }
        if let Some(c) = self.controllers.first().and_then(|c| c.trials.first()) {
            speed = speed.with(Series::new(
                "command",
                &c.series.time_secs,
                &c.series.command_speed_m_per_s,
            ));
        }
        let fig = TimeSeriesFigure::new("PIPTB braking: the three controllers (trial 0)")
            .with(speed)
            .with(torque)
            .shade(t2, t3, "braking");
        written.extend(fig.save_svg_and_png(&dir.join("piptb_comparison"))?);
        Ok(written)
    }
}
