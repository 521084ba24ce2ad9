//! The 3D-world parts of `ballbot reproduce`: MiaPURE's maximum speed per heading (paper
//! Sec. V) as a study ([`crate::world::max_speed`]).
//!
//! Summary keys: `max_speed_by_heading` (heading in deg as text -> mean slow-ramp maximum speed
//! in m/s) and `max_speed_study` (protocol, trials with failures and censoring, failing
//! acceleration by heading, the 15 deg map, sensitivity to mu and COM height, the paper's
//! values). Figures: `max_speed_polar`, `failing_accel_polar`, `acc_h{0,90,180}` (slow ramp,
//! first seed) and `acc_fail_h{0,90,180}` (the ramp at the smallest failing acceleration).

use super::reproduce::progress_bar;
use crate::world::WorldParams;
use crate::world::max_speed::{self, MaxSpeedStudySettings, acc_figure};
use anyhow::Context;
use serde_json::{Map, Value};
use std::path::Path;

/// Runs the maximum-speed study (quick: [`MaxSpeedStudySettings::quick`], else
/// [`MaxSpeedStudySettings::paper`]) on MiaPURE with 60 kg, prints its table, writes its
/// figures into `out` unless `no_plots`, and adds its keys to `summary`.
pub fn max_speed(
    out: &Path,
    no_plots: bool,
    quick: bool,
    summary: &mut Map<String, Value>,
) -> anyhow::Result<()> {
    let params = WorldParams::miapure_60kg();
    let settings = if quick {
        MaxSpeedStudySettings::quick()
    } else {
        MaxSpeedStudySettings::paper()
    };
    let bar = progress_bar(max_speed::job_count(&params, &settings) as u64, "maxspeed");
    let study = max_speed::run_study(params, &settings, &|what| {
        bar.set_message(what.to_owned());
        bar.inc(1);
    })
    .context("maximum-speed study")?;
    bar.finish_and_clear();
    println!("{}", study.table());
    if !no_plots {
        let [speed, accel] = study.capability_figures();
        speed.save_svg_and_png(&out.join("max_speed_polar"))?;
        accel.save_svg_and_png(&out.join("failing_accel_polar"))?;
        for h in &study.trials {
            let deg = format!("{:.0}", h.heading_deg);
            acc_figure(
                &h.first_run,
                &format!(
                    "MiaPURE slow ramp {} m/s² at h_z = {deg}° (seed {})",
                    settings.protocol.slow_ramp.accel_m_per_s2,
                    h.trials.first().map_or(0, |t| t.seed)
                ),
            )
            .save_svg_and_png(&out.join(format!("acc_h{deg}")))?;
            if let Some(f) = study.failing_at(h.heading_deg)
                && let (Some(run), Some(a)) = (&f.failing_run, f.smallest_failing_m_per_s2)
            {
                acc_figure(
                    run,
                    &format!("MiaPURE ramp {a:.2} m/s² (smallest failing) at h_z = {deg}°"),
                )
                .save_svg_and_png(&out.join(format!("acc_fail_h{deg}")))?;
            }
        }
    }
    summary.insert(
        "max_speed_by_heading".to_owned(),
        study.max_speed_by_heading_json(),
    );
    summary.insert("max_speed_study".to_owned(), study.detail_json());
    Ok(())
}
