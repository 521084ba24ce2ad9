//! The 3D controller comparison ([`crate::studies::controllers_3d`]) as the summary's
//! `controllers_3d` and as a table: the report function of a [`Study`]. It renders; it runs
//! nothing.

use crate::studies::controllers_3d::{
    Controller3d, Controllers3dJob, Controllers3dStudy, Controllers3dTrial, Drivetrain3d, Task3d,
};
use crate::studies::driver::{JobRecord, Study};
use serde_json::{Map, Value, json};
use std::fmt::Write;

fn trial_json(t: &Controllers3dTrial) -> Value {
    let record = json!({
        "balanced": t.balanced,
        "tilt_rms_rad": t.tilt_rms_rad,
        "speed_rmse_m_per_s": t.speed_rmse_m_per_s,
        "torque_jitter_nm": t.torque_jitter_nm,
        "peak_tilt_rad": t.peak_tilt_rad,
        "measured_secs": t.measured_secs,
    });
    super::world_suite::with_happened(record, Some(&t.happened))
}

/// The record of `job`, if it ran.
fn trial_of<'a>(
    jobs: &[Controllers3dJob],
    records: &'a [JobRecord<Controllers3dTrial>],
    controller: Controller3d,
    task: Task3d,
    drivetrain: Drivetrain3d,
) -> Option<&'a Controllers3dTrial> {
    records.iter().find_map(|r| {
        let job = jobs.get(r.index)?;
        (job.controller == controller && job.task == task && job.drivetrain == drivetrain)
            .then(|| r.trials.first().map(|(_, t)| t))
            .flatten()
    })
}

/// `controllers_3d`: the protocol and, per controller (`lqr`, `pi_pd`, `lqr_pi`) and task
/// (`standing`, `velocity_cycle`, `push`), whether it balanced, the tilt RMS (rad), the speed
/// RMS error (m/s), the torque jitter (N m), the peak tilt, the measured time and what happened:
/// the default world's at `controllers_3d.<controller>.<task>`, the same world with a rigid
/// drivetrain (when run) at `controllers_3d.rigid_drivetrain.<controller>.<task>`. Each record
/// stands once.
pub fn summary_json(
    study: &Controllers3dStudy,
    records: &[JobRecord<Controllers3dTrial>],
) -> Value {
    let jobs = study.jobs();
    let controllers = |drivetrain: Drivetrain3d| {
        let mut out = Map::new();
        for controller in Controller3d::ALL {
            let mut tasks = Map::new();
            for task in Task3d::ALL {
                if let Some(t) = trial_of(&jobs, records, controller, task, drivetrain) {
                    tasks.insert(task.as_str().to_owned(), trial_json(t));
                }
            }
            out.insert(controller.as_str().to_owned(), Value::Object(tasks));
        }
        out
    };
    let mut out = Map::new();
    out.insert("protocol".to_owned(), json!(study.settings));
    out.insert(
        "stop_rules".to_owned(),
        json!(ballbot_world::world::StopRules::contact_rules_off().to_string()),
    );
    for &drivetrain in &study.settings.drivetrains {
        match drivetrain {
            Drivetrain3d::Default => out.extend(controllers(drivetrain)),
            Drivetrain3d::Rigid => {
                out.insert(
                    "rigid_drivetrain".to_owned(),
                    Value::Object(controllers(drivetrain)),
                );
            }
        }
    }
    Value::Object(out)
}

/// The table `ballbot reproduce` prints: one row per drivetrain, controller and task.
pub fn table(study: &Controllers3dStudy, records: &[JobRecord<Controllers3dTrial>]) -> String {
    let jobs = study.jobs();
    let mut out = String::new();
    let _ = writeln!(
        out,
        "the paper's controllers in the 3D world (MiaPURE 60 kg, seed {}; each controller's own \
         gains; LQR and PI-PD with the torque open loop, as the paper ran them):",
        study.settings.seed
    );
    let _ = writeln!(
        out,
        "  {:>10} | {:>7} | {:>15} | {:>8} | {:>9} | {:>11} | {:>9} | how it ended",
        "drivetrain", "control", "task", "balanced", "tilt RMS", "speed RMSE", "jitter"
    );
    for &drivetrain in &study.settings.drivetrains {
        for controller in Controller3d::ALL {
            for task in Task3d::ALL {
                let Some(t) = trial_of(&jobs, records, controller, task, drivetrain) else {
                    continue;
                };
                let _ = writeln!(
                    out,
                    "  {:>10} | {:>7} | {:>15} | {:>8} | {:>5.2} deg | {:>6.3} m/s | {:>5.2} N m | {} ({:.2} s measured)",
                    drivetrain.as_str(),
                    controller.as_str(),
                    task.as_str(),
                    if t.balanced { "yes" } else { "no" },
                    t.tilt_rms_rad.to_degrees(),
                    t.speed_rmse_m_per_s,
                    t.torque_jitter_nm,
                    t.happened.outcome.as_str(),
                    t.measured_secs
                );
            }
        }
    }
    out
}
