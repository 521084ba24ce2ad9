//! The 3D-world parts of `ballbot reproduce`: MiaPURE's maximum speed per heading (paper
//! Sec. V) as a study ([`crate::world::max_speed`]).
//!
//! Summary keys: `max_speed_by_heading` (heading in deg as text -> mean slow-ramp maximum speed
//! in m/s) and `max_speed_study` (protocol, trials with failures and censoring, failing
//! acceleration by heading, the 15 deg map, sensitivity to mu and COM height, the paper's
//! values). Figures: `max_speed_polar`, `failing_accel_polar`, `acc_h{0,90,180}` (slow ramp,
//! first seed) and `acc_fail_h{0,90,180}` (the ramp at the smallest failing acceleration).
//! Logs: `logs/max_speed_h{0,90,180}.mcap`, the first trial per heading with
//! [`WorldLogger`] (telemetry at 1 kHz, 100 Hz with `--quick`; Foxglove scene; open with
//! `foxglove/world-layout.json`).

use super::reproduce::progress_bar;
use crate::log::{WorldLogOptions, WorldLogger};
use crate::world::WorldParams;
use crate::world::experiments::{RampResult, max_speed_ramp_observed};
use crate::world::max_speed::{self, MaxSpeedProtocol, MaxSpeedStudySettings, acc_figure};
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
    for h in &study.trials {
        let Some(first) = h.trials.first() else {
            continue;
        };
        let path = out
            .join("logs")
            .join(format!("max_speed_h{:.0}.mcap", h.heading_deg));
        let every = if quick { 80 } else { 8 };
        let logged = log_slow_ramp(
            params,
            &settings.protocol,
            h.heading_deg,
            first.seed,
            &path,
            every,
        )?;
        anyhow::ensure!(
            logged == h.first_run,
            "the logged run at {} deg differs from the study's trial with the same seed",
            h.heading_deg
        );
    }
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

/// Runs one slow-ramp trial again (it is deterministic in its seed) and writes it to `path`
/// with [`WorldLogger`]: telemetry every `telemetry_every_steps`-th physics step, the
/// controller, the command, the scene and the failure event.
fn log_slow_ramp(
    params: WorldParams,
    protocol: &MaxSpeedProtocol,
    heading_deg: f64,
    seed: u64,
    path: &Path,
    telemetry_every_steps: u32,
) -> anyhow::Result<RampResult> {
    let mut p = params;
    p.sensors.seed = seed;
    let config = max_speed::controller(&p, protocol)?;
    let options = WorldLogOptions {
        telemetry_every_steps,
        ..WorldLogOptions::default()
    };
    let mut log = WorldLogger::with_options(path, &p, options)
        .with_context(|| format!("cannot create {}", path.display()))?;
    let mut error = None;
    let run = max_speed_ramp_observed(
        p,
        config,
        heading_deg,
        &protocol.slow_ramp,
        &mut |sim, cmd| {
            if error.is_some() {
                return;
            }
            let time_s = sim.world().time_s();
            if let Err(e) = log
                .record_core(sim)
                .and_then(|()| log.record_command(time_s, cmd))
            {
                error = Some(e);
            }
        },
    )?;
    if let Some(e) = error {
        return Err(e).with_context(|| format!("cannot write {}", path.display()));
    }
    log.finish()
        .with_context(|| format!("cannot finish {}", path.display()))?;
    Ok(run)
}
