//! The world suite ([`crate::studies::world_suite`]: 3D braking time and push recovery) as the
//! summary's JSON (`min_braking_time_3d_secs`, `push_recovery_ns`, `world_braking`,
//! `world_push`) and as comparison tables.

use crate::studies::push::{PushOutcome, PushRecovery, PushTrial};
use crate::studies::world_braking::{BrakingOutcome, BrakingRun, BrakingStudy};
use crate::studies::world_suite::{
    BRAKING_LIFT_OFF_RULE_RELAXED, PAPER_MIN_BRAKING_TIME_SECS, PUSH_RULES_RELAXED, SEED,
    WorldSuite,
};
use ballbot_world::rig::Happened;
use ballbot_world::world::{Failure, wheel_name};
use serde_json::{Map, Value, json};
use std::fmt::Write;

/// The failure's canonical JSON (`Failure`'s `Serialize`) plus its `Display` as `label`.
fn failure_json(f: &Failure) -> Value {
    let mut v = serde_json::to_value(f).unwrap_or(Value::Null);
    if let Value::Object(map) = &mut v {
        map.insert("label".to_owned(), Value::String(f.to_string()));
    }
    v
}

/// What bounded a braking run: the failure, or the most used resource.
pub fn limiting(run: &BrakingRun) -> String {
    let p = &run.peaks;
    let argmax = |v: &[f64; 3]| {
        (0..3)
            .max_by(|&a, &b| v[a].total_cmp(&v[b]))
            .unwrap_or_default()
    };
    let cone = argmax(&p.cone_utilisation);
    let act = argmax(&p.actuator_utilisation);
    let used = format!(
        "cone {} {:.2}, actuator {} {:.2}, tilt {:.1} deg",
        wheel_name(cone),
        p.cone_utilisation[cone],
        wheel_name(act),
        p.actuator_utilisation[act],
        p.tilt_rad.to_degrees()
    );
    match run.outcome {
        BrakingOutcome::Failed(f) => format!(
            "{} ({:.3} s after braking started); {used}",
            f,
            f.time_secs - run.brake_start_secs
        ),
        BrakingOutcome::NoTrajectory { status } => format!("no trajectory ({status})"),
        BrakingOutcome::NotAtRest {
            rest_speed_m_per_s, ..
        } => format!("not at rest ({rest_speed_m_per_s:.3} m/s); {used}"),
        BrakingOutcome::Stopped { .. } => used,
    }
}

/// `record` with what happened in its run: `outcome` (how it ended: fell, ended by a stop
/// rule, at rest...), `events` and `events_dropped`; a run never flown has a null outcome and
/// no events.
pub(crate) fn with_happened(mut record: Value, happened: Option<&Happened>) -> Value {
    let fields = happened.map_or_else(
        || json!({ "outcome": null, "events": [], "events_dropped": 0 }),
        |h| serde_json::to_value(h).unwrap_or(Value::Null),
    );
    if let (Value::Object(r), Value::Object(f)) = (&mut record, fields) {
        r.extend(f);
    }
    record
}

fn run_json(run: &BrakingRun) -> Value {
    let p = &run.peaks;
    let outcome = match run.outcome {
        BrakingOutcome::Stopped { rest_speed_m_per_s } => {
            json!({ "rest_speed_m_per_s": rest_speed_m_per_s })
        }
        BrakingOutcome::NoTrajectory { status } => json!({ "solve_status": status.as_str() }),
        BrakingOutcome::Failed(f) => failure_json(&f),
        BrakingOutcome::NotAtRest {
            rest_speed_m_per_s,
            rest_tilt_rad,
        } => json!({
            "rest_speed_m_per_s": rest_speed_m_per_s,
            "rest_tilt_deg": rest_tilt_rad.to_degrees(),
        }),
    };
    let record = json!({
        "duration_secs": run.duration_secs,
        "verdict": run.outcome.label(),
        "success": run.outcome.is_success(),
        "detail": outcome,
        "limiting": limiting(run),
        "plan_peak_tilt_deg": run.plan_peak_tilt_rad.map(f64::to_degrees),
        "plan_cost_n2m2s": run.plan_cost_n2m2s,
        "peak_cone_utilisation": p.cone_utilisation,
        "min_normal_force_n": p.min_normal_force_n,
        "peak_actuator_utilisation": p.actuator_utilisation,
        "peak_tilt_deg": p.tilt_rad.to_degrees(),
        "peak_speed_error_m_per_s": p.speed_error_m_per_s,
        "slip_secs": p.slip_secs,
        "brake_start_secs": run.brake_start_secs,
    });
    with_happened(record, run.happened.as_ref())
}

fn study_json(study: &BrakingStudy, planar_secs: Option<f64>) -> Value {
    json!({
        "heading_deg": study.heading_deg,
        "descent": study.descent.iter().map(run_json).collect::<Vec<_>>(),
        "bisection": study.bisection.iter().map(run_json).collect::<Vec<_>>(),
        "shortest_success_secs": study.shortest_success_secs,
        "first_failure_secs": study.first_failure_secs,
        "limit_secs": study.limit_secs,
        "limit_failure_secs": study.limit_failure_secs,
        "planar_min_braking_time_secs": planar_secs,
    })
}

fn push_json(r: &PushRecovery) -> Value {
    let trial = |t: &PushTrial| {
        let record = json!({
            "impulse_ns": t.impulse_ns,
            "verdict": t.outcome.label(),
            "failure": match t.outcome {
                PushOutcome::Failed(f) => failure_json(&f),
                _ => Value::Null,
            },
            "peak_tilt_deg": t.peak_tilt_rad.to_degrees(),
            "peak_speed_m_per_s": t.peak_speed_m_per_s,
            "rest_speed_m_per_s": t.rest_speed_m_per_s,
        });
        with_happened(record, Some(&t.happened))
    };
    json!({
        "heading_deg": r.heading_deg,
        "largest_recovered_ns": r.largest_recovered_ns,
        "smallest_failing_ns": r.smallest_failing_ns,
        "trials": r.trials.iter().map(trial).collect::<Vec<_>>(),
    })
}

fn key(heading_deg: f64) -> String {
    format!("{heading_deg:.0}")
}

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or_else(|| "-".to_owned(), |x| format!("{x:.digits$}"))
}

impl WorldSuite {
    fn planar_json(&self) -> Map<String, Value> {
        let mut planar = Map::new();
        for &(h, t) in &self.planar_min_braking_time_secs {
            planar.insert(key(h), json!(t));
        }
        planar
    }

    /// Adds `min_braking_time_3d_secs` (the shortest successful braking at 180 deg, s),
    /// `push_recovery_ns` (heading -> largest push recovered, N s), `world_braking` and
    /// `world_push` (protocols and every run) to `summary`.
    pub fn add_to_summary(&self, summary: &mut Map<String, Value>) {
        let planar = self.planar_json();
        let planar_at = |h: f64| planar.get(&key(h)).and_then(Value::as_f64);
        let mut headings = Map::new();
        for study in &self.braking {
            headings.insert(
                key(study.heading_deg),
                study_json(study, planar_at(study.heading_deg)),
            );
        }
        let ablation = self.ablation.as_ref().map_or(Value::Null, |study| {
            study_json(study, planar_at(study.heading_deg))
        });
        let b = &self.settings.braking;
        summary.insert(
            "min_braking_time_3d_secs".to_owned(),
            json!(self.paper_heading().and_then(|st| st.shortest_success_secs)),
        );
        let mut push_map = Map::new();
        for p in &self.pushes {
            push_map.insert(key(p.heading_deg), json!(p.largest_recovered_ns));
        }
        summary.insert("push_recovery_ns".to_owned(), Value::Object(push_map));
        summary.insert(
            "world_braking".to_owned(),
            json!({
                "paper_min_braking_time_secs": PAPER_MIN_BRAKING_TIME_SECS,
                "seed": SEED,
                "protocol": {
                    "cruise_speed_m_per_s": b.cruise_speed_m_per_s,
                    "approach_accel_m_per_s2": b.approach_accel_m_per_s2,
                    "approach_jerk_m_per_s3": b.approach_jerk_m_per_s3,
                    "cruise_secs": b.cruise_secs,
                    "rest_within_secs": b.rest_within_secs,
                    "rest_hold_secs": b.rest_hold_secs,
                    "rest_speed_m_per_s": b.rest_speed_m_per_s,
                    "rest_tilt_deg": b.rest_tilt_rad.to_degrees(),
                    "trajectory_tilt_limit_deg": b.trajectory_tilt_limit_rad.to_degrees(),
                    "trajectory_limits": "actuators (peak torque, torque-speed line) and traction mu N at all three omniwheels, tilt bound; tau = 0 at both ends",
                    "feedforward": b.feedforward.label(),
                },
                "headings": headings,
                "ablation_core_feedforward_180": ablation,
                "lift_off_rule_relaxed": {
                    "stop_rules": BRAKING_LIFT_OFF_RULE_RELAXED.to_string(),
                    "headings": self.braking_lift_off_rule_relaxed.iter().map(|st| (key(st.heading_deg), study_json(st, planar_at(st.heading_deg)))).collect::<Map<_, _>>(),
                },
                "planar_min_braking_time_secs": planar,
            }),
        );
        if !self.margin_sweep.is_empty()
            && let Some(Value::Object(wb)) = summary.get_mut("world_braking")
        {
            wb.insert("normal_force_margin".to_owned(), self.margin_sweep_json());
        }
        let pp = &self.settings.push;
        summary.insert(
            "world_push".to_owned(),
            json!({
                "seed": SEED,
                "protocol": {
                    "settle_secs": pp.settle_secs,
                    "observe_secs": pp.observe_secs,
                    "max_tilt_deg": pp.max_tilt_rad.to_degrees(),
                    "rest_within_secs": pp.rest_within_secs,
                    "rest_speed_m_per_s": pp.rest_speed_m_per_s,
                    "rest_tilt_deg": pp.rest_tilt_rad.to_degrees(),
                    "push_duration_secs": pp.push_duration_secs,
                },
                "headings": self.pushes.iter().map(|p| (key(p.heading_deg), push_json(p))).collect::<Map<_, _>>(),
                "impulsive": self.impulsive.iter().map(|p| (key(p.heading_deg), push_json(p))).collect::<Map<_, _>>(),
                "rules_relaxed": {
                    "stop_rules": PUSH_RULES_RELAXED.to_string(),
                    "headings": self.pushes_rules_relaxed.iter().map(|p| (key(p.heading_deg), push_json(p))).collect::<Map<_, _>>(),
                },
            }),
        );
    }

    /// The margin sweep as `world_braking.normal_force_margin`: one record per margin (0 N
    /// first, from the main studies) with, per heading, the shortest success of the descent,
    /// the bisection limit, the first failure, what failed first, and the planar minimum
    /// braking time under that margin (s).
    fn margin_sweep_json(&self) -> Value {
        let zero = (0.0, &self.braking, &self.planar_min_braking_time_secs);
        let rows = std::iter::once(zero)
            .chain(self.margin_sweep.iter().map(|e| {
                (
                    e.normal_force_margin_n,
                    &e.studies,
                    &e.planar_min_braking_time_secs,
                )
            }))
            .map(|(m, studies, planar)| {
                let planar_at = |h: f64| {
                    planar
                        .iter()
                        .find(|(ph, _)| key(*ph) == key(h))
                        .and_then(|(_, t)| *t)
                };
                let headings: Map<String, Value> = studies
                    .iter()
                    .map(|st| {
                        (
                            key(st.heading_deg),
                            json!({
                                "shortest_success_secs": st.shortest_success_secs,
                                "limit_secs": st.limit_secs,
                                "limit_failure_secs": st.limit_failure_secs,
                                "first_failure_secs": st.first_failure_secs,
                                "first_failure": st.first_failure().map(limiting),
                                "planar_min_braking_time_secs": planar_at(st.heading_deg),
                                "runs": st.descent.iter().chain(&st.bisection).map(run_json).collect::<Vec<_>>(),
                            }),
                        )
                    })
                    .collect();
                json!({ "normal_force_margin_n": m, "headings": headings })
            })
            .collect();
        Value::Array(rows)
    }

    /// The margin sweep as a plain-text table (empty without a sweep).
    fn margin_sweep_table(&self, out: &mut String) {
        if self.margin_sweep.is_empty() {
            return;
        }
        let _ = writeln!(
            out,
            "world braking with a normal-force margin in the planner (|F_i| <= mu (N_i - margin)):"
        );
        let _ = writeln!(
            out,
            "  {:>10} | {:>7} | {:>24} | {:>15} | {:>13} | what failed first",
            "margin", "heading", "shortest success (desc.)", "bisection limit", "planar min T",
        );
        let zero = (0.0, &self.braking, &self.planar_min_braking_time_secs);
        let rows = std::iter::once(zero).chain(self.margin_sweep.iter().map(|e| {
            (
                e.normal_force_margin_n,
                &e.studies,
                &e.planar_min_braking_time_secs,
            )
        }));
        for (m, studies, planar) in rows {
            for st in studies {
                let p = planar
                    .iter()
                    .find(|(h, _)| key(*h) == key(st.heading_deg))
                    .and_then(|(_, t)| *t);
                let fail = st.first_failure().map_or_else(|| "-".to_owned(), limiting);
                let _ = writeln!(
                    out,
                    "  {:>8.0} N | {:>6.0}° | {:>22} s | {:>13} s | {:>11} s | {}",
                    m,
                    st.heading_deg,
                    opt(st.shortest_success_secs, 2),
                    opt(st.limit_secs, 3),
                    opt(p, 3),
                    fail
                );
            }
        }
    }

    /// The comparison tables (braking, push recovery), as `ballbot reproduce` prints them.
    pub fn table(&self) -> String {
        let mut out = String::new();
        let shove_secs = self.settings.push.push_duration_secs;
        let _ = writeln!(
            out,
            "world braking (MiaPURE 60 kg, 1.4 m/s at heading h -> rest in T, optimal trajectories \
             under actuator, traction and 15 deg tilt limits, seed {SEED}):"
        );
        let _ = writeln!(
            out,
            "  {:>7} | {:>24} | {:>15} | {:>15} | {:>13} | what failed first",
            "heading",
            "shortest success (desc.)",
            "bisection limit",
            "first failure",
            "planar min T",
        );
        let rows = self.braking.iter().map(|st| (st, "°")).chain(
            self.braking_lift_off_rule_relaxed
                .iter()
                .map(|st| (st, "°*")),
        );
        for (st, mark) in rows {
            let fail = st.first_failure().map_or_else(|| "-".to_owned(), limiting);
            let _ = writeln!(
                out,
                "  {:>6.0}{mark:<2}| {:>22} s | {:>13} s | {:>13} s | {:>11} s | {}",
                st.heading_deg,
                opt(st.shortest_success_secs, 2),
                opt(st.limit_secs, 3),
                opt(st.first_failure_secs, 2),
                opt(self.planar_at(st.heading_deg), 3),
                fail
            );
        }
        if !self.braking_lift_off_rule_relaxed.is_empty() {
            let _ = writeln!(
                out,
                "  * with the world's lift-off stop rule off (stop rules: {BRAKING_LIFT_OFF_RULE_RELAXED})"
            );
        }
        let _ = writeln!(
            out,
            "  paper (hardware, 180°): shortest success {PAPER_MIN_BRAKING_TIME_SECS:.1} s \
             (descent from 5 s by 0.5 s)"
        );
        if let Some(a) = &self.ablation {
            let _ = writeln!(
                out,
                "  ablation, 180° with the equilibrium feedforward only (no c θ̈* term): shortest success \
                 {} s, first failure {} s",
                opt(a.shortest_success_secs, 2),
                opt(a.first_failure_secs, 2)
            );
        }
        self.margin_sweep_table(&mut out);
        let _ = writeln!(
            out,
            "push recovery (standing; impulse at the body's COM as a {shove_secs} s force pulse, and in \
             one step; recovered: tilt < 15°, at rest < 0.1 m/s within 3 s):"
        );
        let _ = writeln!(
            out,
            "  {:>9} | {:>8} | {:>19} | {:>17} | failing trial",
            "direction", "push", "largest recovered", "smallest failing"
        );
        let rows = self
            .pushes
            .iter()
            .map(|p| (p, format!("{shove_secs} s")))
            .chain(self.impulsive.iter().map(|p| (p, "1 step".to_owned())))
            .chain(
                self.pushes_rules_relaxed
                    .iter()
                    .map(|p| (p, format!("{shove_secs} s*"))),
            );
        for (p, kind) in rows {
            let how = p.smallest_failing().map_or_else(
                || "-".to_owned(),
                |t| match t.outcome {
                    PushOutcome::Failed(f) => f.to_string(),
                    o => format!(
                        "{} (peak tilt {:.1}°)",
                        o.label(),
                        t.peak_tilt_rad.to_degrees()
                    ),
                },
            );
            let _ = writeln!(
                out,
                "  {:>8.0}° | {:>8} | {:>15.1} N·s | {:>13} N·s | {}",
                p.heading_deg,
                kind,
                p.largest_recovered_ns,
                opt(p.smallest_failing_ns, 1),
                how
            );
        }
        if !self.pushes_rules_relaxed.is_empty() {
            let _ = writeln!(
                out,
                "  * with the world's slip and lift-off stop rules off (stop rules: {PUSH_RULES_RELAXED})"
            );
        }
        let _ = writeln!(
            out,
            "  paper: not measured (MiaPURE was only pushed gently to steer it, pHRI demo)"
        );
        out
    }
}
