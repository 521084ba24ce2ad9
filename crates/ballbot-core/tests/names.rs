//! One canonical string form per status (`Mode`, `StepStatus`, `RiccatiStatus`, `Fault`,
//! `FaultSet`): `as_str`, `Display`, `FromStr` and serde agree, names are unique snake_case,
//! and every value survives the round trip.

#![allow(clippy::unwrap_used)] // test code

use ballbot_core::ParseNameError;
use ballbot_core::ballbot::WheelMapping;
use ballbot_core::control::StepStatus;
use ballbot_core::lqr::RiccatiStatus;
use ballbot_core::safety::{Fault, FaultSet, Mode};
use core::fmt::Display;
use core::str::FromStr;
use proptest::prelude::*;
use std::collections::BTreeSet;

/// Every value of `all` has a unique snake_case name that `Display` writes and `FromStr` reads
/// back; a name in another case or with a typo is rejected with `what`.
fn check_names<T, const N: usize>(all: [T; N], as_str: fn(&T) -> &'static str, what: &str)
where
    T: Copy + PartialEq + core::fmt::Debug + Display + FromStr<Err = ParseNameError>,
{
    let names: BTreeSet<&str> = all.iter().map(as_str).collect();
    assert_eq!(names.len(), N, "{what}: names are not unique: {names:?}");
    for v in all {
        let name = as_str(&v);
        assert!(
            !name.is_empty()
                && name
                    .chars()
                    .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_'),
            "{what}: {name:?} is not snake_case"
        );
        assert_eq!(v.to_string(), name);
        assert_eq!(name.parse::<T>(), Ok(v));
        let upper = name.to_ascii_uppercase();
        assert_eq!(upper.parse::<T>().unwrap_err().what(), what);
        assert!(format!("{name}_").parse::<T>().is_err());
    }
    assert!("".parse::<T>().is_err());
}

#[test]
fn every_mode_has_one_name_that_round_trips() {
    check_names(Mode::ALL, Mode::as_str, "mode");
    assert_eq!(Mode::ControlledStop.as_str(), "controlled_stop");
}

#[test]
fn every_wheel_mapping_has_one_name_that_round_trips() {
    check_names(WheelMapping::ALL, WheelMapping::as_str, "wheel mapping");
    assert_eq!(WheelMapping::RollingBall.as_str(), "rolling_ball");
}

#[test]
fn every_step_status_has_one_name_that_round_trips() {
    check_names(StepStatus::ALL, StepStatus::as_str, "step status");
    assert_eq!(StepStatus::Saturated.as_str(), "saturated");
}

#[test]
fn every_step_status_has_one_code_that_round_trips() {
    for (i, status) in StepStatus::ALL.into_iter().enumerate() {
        assert_eq!(usize::from(status.code()), i);
        assert_eq!(StepStatus::from_code(status.code()), Some(status));
    }
    assert_eq!(StepStatus::from_code(StepStatus::ALL.len() as u8), None);
    assert_eq!(StepStatus::from_code(u8::MAX), None);
}

#[test]
fn every_riccati_status_has_one_name_that_round_trips() {
    check_names(RiccatiStatus::ALL, RiccatiStatus::as_str, "Riccati status");
    assert_eq!(RiccatiStatus::NotStabilizable.as_str(), "not_stabilizable");
}

#[test]
fn every_fault_has_one_name_that_round_trips() {
    check_names(Fault::ALL, Fault::as_str, "fault");
    assert_eq!(Fault::CommandLinkLost.as_str(), "command_link_lost");
    assert_eq!(Fault::CommandLinkLost.to_string(), "command_link_lost");
}

#[test]
fn fault_set_strings_list_names_in_code_order() {
    assert_eq!(FaultSet::empty().to_string(), "");
    assert_eq!("".parse(), Ok(FaultSet::empty()));
    let mut set = FaultSet::empty();
    set.insert(Fault::CommandLinkLost);
    set.insert(Fault::ImuStale);
    assert_eq!(set.to_string(), "imu_stale,command_link_lost");
    assert_eq!("command_link_lost,imu_stale,imu_stale".parse(), Ok(set));
    assert_eq!(
        "imu_stale,,command_link_lost".parse::<FaultSet>(),
        Err(ParseNameError::new("fault"))
    );
    assert!("imu_stale, command_link_lost".parse::<FaultSet>().is_err());
}

/// A fault set from its bits (the low 20 bits are the faults).
fn set_of(bits: u32) -> FaultSet {
    let mut set = FaultSet::empty();
    for f in Fault::ALL {
        if bits & (1 << f.code()) != 0 {
            set.insert(f);
        }
    }
    set
}

proptest! {
    #[test]
    fn every_fault_set_round_trips_through_its_string(bits in 0u32..(1 << 20)) {
        let set = set_of(bits);
        prop_assert_eq!(set.bits(), bits);
        prop_assert_eq!(set.to_string().parse::<FaultSet>(), Ok(set));
    }

    #[test]
    fn a_string_that_is_no_name_is_rejected(s in "[a-z_]{0,24}") {
        let known = Fault::ALL.iter().any(|f| f.as_str() == s);
        prop_assert_eq!(s.parse::<Fault>().is_ok(), known);
        let known = Mode::ALL.iter().any(|m| m.as_str() == s);
        prop_assert_eq!(s.parse::<Mode>().is_ok(), known);
    }
}

#[cfg(feature = "serde")]
mod serde_form {
    use super::*;

    #[test]
    fn statuses_serialize_as_their_names() {
        for m in Mode::ALL {
            let json = serde_json::to_string(&m).unwrap();
            assert_eq!(json, format!("\"{}\"", m.as_str()));
            assert_eq!(serde_json::from_str::<Mode>(&json).unwrap(), m);
        }
        for s in StepStatus::ALL {
            let json = serde_json::to_string(&s).unwrap();
            assert_eq!(json, format!("\"{}\"", s.as_str()));
            assert_eq!(serde_json::from_str::<StepStatus>(&json).unwrap(), s);
        }
        for r in RiccatiStatus::ALL {
            let json = serde_json::to_string(&r).unwrap();
            assert_eq!(json, format!("\"{}\"", r.as_str()));
            assert_eq!(serde_json::from_str::<RiccatiStatus>(&json).unwrap(), r);
        }
        for f in Fault::ALL {
            let json = serde_json::to_string(&f).unwrap();
            assert_eq!(json, format!("\"{}\"", f.as_str()));
            assert_eq!(serde_json::from_str::<Fault>(&json).unwrap(), f);
        }
        for w in WheelMapping::ALL {
            let json = serde_json::to_string(&w).unwrap();
            assert_eq!(json, format!("\"{}\"", w.as_str()));
            assert_eq!(serde_json::from_str::<WheelMapping>(&json).unwrap(), w);
        }
        assert!(serde_json::from_str::<Mode>("\"Balancing\"").is_err());
        assert!(serde_json::from_str::<Fault>("7").is_err());
    }

    proptest! {
        #[test]
        fn fault_sets_serialize_as_sequences_of_names(bits in 0u32..(1 << 20)) {
            let set = set_of(bits);
            let json = serde_json::to_string(&set).unwrap();
            let names: Vec<&str> = set.iter().map(|f| f.as_str()).collect();
            prop_assert_eq!(&json, &serde_json::to_string(&names).unwrap());
            prop_assert_eq!(serde_json::from_str::<FaultSet>(&json).unwrap(), set);
        }
    }
}
