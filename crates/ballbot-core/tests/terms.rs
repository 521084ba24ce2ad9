//! `control::Terms`: every scalar field of a controller output but its status is a term, named
//! as the field, visited in declaration order with the field's value; `TERM_NAMES` lists the
//! same names and `term` finds each. Checked against the outputs' `Debug` form, so a field
//! added to an output without becoming a term fails here.

#![allow(clippy::unwrap_used)] // test code

use ballbot_core::ballbot::SpinOuterOutput;
use ballbot_core::control::{
    LqrOutput, LqrPiOuterOutput, PiPdOutput, SpeedPiOutput, StepStatus, Terms,
};
use std::collections::BTreeSet;
use std::fmt::Debug;

/// `(field, value)` pairs of a `Debug`-printed struct with scalar fields.
fn debug_fields(out: &impl Debug) -> Vec<(String, String)> {
    let text = format!("{out:?}");
    let body = text
        .split_once(" { ")
        .unwrap()
        .1
        .strip_suffix(" }")
        .unwrap();
    body.split(", ")
        .map(|kv| {
            let (k, v) = kv.split_once(": ").unwrap();
            (k.to_owned(), v.to_owned())
        })
        .collect()
}

/// The terms of `out` agree with its fields; its values are all different, so a term bound to
/// the wrong field shows.
fn check<O: Terms<f64> + Debug>(out: &O) {
    let mut visited = Vec::new();
    out.for_each_term(|name, value| visited.push((name, value)));
    let names: Vec<&str> = visited.iter().map(|(n, _)| *n).collect();
    assert_eq!(names, O::TERM_NAMES, "{out:?}");
    let unique: BTreeSet<&str> = names.iter().copied().collect();
    assert_eq!(unique.len(), names.len(), "names repeat: {names:?}");
    let fields: Vec<(String, String)> = debug_fields(out)
        .into_iter()
        .filter(|(k, _)| k != "status")
        .collect();
    let field_names: Vec<&str> = fields.iter().map(|(k, _)| k.as_str()).collect();
    assert_eq!(names, field_names, "every scalar field is a term, in order");
    for ((name, value), (_, field_value)) in visited.iter().zip(&fields) {
        assert_eq!(&format!("{value:?}"), field_value, "term {name}");
        assert_eq!(out.term(name), Some(*value));
    }
    let values: BTreeSet<u64> = visited.iter().map(|(_, v)| v.to_bits()).collect();
    assert_eq!(values.len(), visited.len(), "test values must differ");
    assert_eq!(out.term("status"), None);
    assert_eq!(out.term("no_such_term"), None);
}

#[test]
fn lqr_output_terms_are_its_fields() {
    check(&LqrOutput {
        torque_nm: 1.0,
        tilt_term_nm: 2.0,
        tilt_rate_term_nm: 3.0,
        ball_rate_term_nm: 4.0,
        saturation_nm: 5.0,
        status: StepStatus::Saturated,
    });
}

#[test]
fn pi_pd_output_terms_are_its_fields() {
    check(&PiPdOutput {
        torque_nm: 1.0,
        reference_tilt_rad: 2.0,
        tilt_feedforward_rad: 3.0,
        speed_p_term_rad: 4.0,
        speed_i_term_rad: 5.0,
        tilt_limit_rad: 6.0,
        tilt_p_term_nm: 7.0,
        tilt_d_term_nm: 8.0,
        saturation_nm: 9.0,
        status: StepStatus::Nominal,
    });
}

#[test]
fn lqr_pi_outer_output_terms_are_its_fields() {
    check(&LqrPiOuterOutput {
        reference_torque_nm: 1.0,
        reference_ball_rate_rad_per_s: 2.0,
        reference_ball_accel_rad_per_s2: 3.0,
        reference_tilt_accel_rad_per_s2: 3.5,
        tilt_term_nm: 4.0,
        tilt_rate_term_nm: 5.0,
        ball_rate_term_nm: 6.0,
        saturation_nm: 7.0,
        anchor_correction_rad_per_s: 8.0,
        status: StepStatus::Nominal,
    });
}

#[test]
fn speed_pi_output_terms_are_its_fields() {
    check(&SpeedPiOutput {
        torque_nm: 1.0,
        feedforward_nm: 2.0,
        proportional_nm: 3.0,
        integral_nm: 4.0,
        saturation_nm: 5.0,
        speed_error_rad_per_s: 6.0,
        status: StepStatus::InvalidInput,
    });
}

#[test]
fn spin_outer_output_terms_are_its_fields() {
    check(&SpinOuterOutput {
        reference_torque_nm: 1.0,
        reference_rate_rad_per_s: 2.0,
        reference_accel_rad_per_s2: 3.0,
        status: StepStatus::Nominal,
    });
}

#[test]
fn term_names_are_known_without_an_output() {
    // What a log header needs, as the simulator and the bindings spell them today.
    assert_eq!(
        LqrOutput::<f64>::TERM_NAMES,
        [
            "torque_nm",
            "tilt_term_nm",
            "tilt_rate_term_nm",
            "ball_rate_term_nm",
            "saturation_nm"
        ]
    );
    assert_eq!(SpeedPiOutput::<f32>::TERM_NAMES.len(), 6);
    assert_eq!(PiPdOutput::<f64>::TERM_NAMES[8], "saturation_nm");
}
