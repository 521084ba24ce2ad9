//! The paper's controller comparison in the 3D world (`studies::controllers_3d`): LQR-PI
//! balances where the torque-only LQR and PI-PD do not, and why.

use ballbot_core::BallbotParams;
use ballbot_sim::rig::Outcome;
use ballbot_sim::studies::controllers_3d::{
    Controller3d, Controllers3dJob, Controllers3dSettings, Controllers3dStudy, Drivetrain3d,
    Task3d, run_task,
};
use ballbot_sim::studies::mechanisms::Mechanism;
use ballbot_sim::world::WorldParams;

fn study(world: WorldParams) -> Controllers3dStudy {
    Controllers3dStudy {
        settings: Controllers3dSettings::quick(),
        world,
    }
}

fn job(controller: Controller3d, task: Task3d) -> Controllers3dJob {
    Controllers3dJob {
        controller,
        task,
        drivetrain: Drivetrain3d::Default,
    }
}

/// In the default world the LQR-PI balances through the push and the velocity cycle, settles
/// at rest and tracks the cycle within 0.15 m/s RMS; the LQR with its torque open loop falls in
/// the cycle, and the PI-PD cannot even stand.
#[test]
fn lqr_pi_balances_where_the_torque_only_lqr_and_pi_pd_fall() {
    let s = study(WorldParams::miapure_60kg());
    for task in [Task3d::VelocityCycle, Task3d::Push] {
        let t = run_task(&s, &job(Controller3d::LqrPi, task), &mut |_| {}).unwrap();
        assert!(t.balanced, "{task:?}: {:?}", t.happened.outcome);
        assert!(
            matches!(t.happened.outcome, Outcome::AtRest { .. }),
            "{task:?}"
        );
        assert!(
            t.speed_rmse_m_per_s < 0.15,
            "{task:?}: {}",
            t.speed_rmse_m_per_s
        );
        assert!(
            t.peak_tilt_rad < 8f64.to_radians(),
            "{task:?}: {}",
            t.peak_tilt_rad
        );
    }
    let lqr = run_task(
        &s,
        &job(Controller3d::Lqr, Task3d::VelocityCycle),
        &mut |_| {},
    )
    .unwrap();
    assert!(!lqr.balanced, "{:?}", lqr.happened.outcome);
    let pi_pd = run_task(&s, &job(Controller3d::PiPd, Task3d::Standing), &mut |_| {}).unwrap();
    assert!(!pi_pd.balanced && pi_pd.measured_secs < 1.0, "{pi_pd:?}");
}

/// The mechanism is the world's compliance between torque and encoder, closed at 400 Hz: the
/// torque-only LQR stands in the ideal world (stiff contacts) and with the drivetrain alone,
/// and falls once the rubber coating's soft, lightly damped contact is added; the LQR-PI's
/// 8 kHz speed loop closes around it.
#[test]
fn the_torque_only_lqr_falls_through_the_rubber_coating() {
    let robot = BallbotParams::miapure_60kg();
    let stands = |m: Mechanism| {
        let s = study(m.params(robot));
        let mut j = job(Controller3d::Lqr, Task3d::Standing);
        j.drivetrain = Drivetrain3d::Rigid;
        if m == Mechanism::Drivetrain {
            j.drivetrain = Drivetrain3d::Default;
        }
        let t = run_task(&s, &j, &mut |_| {}).unwrap();
        eprintln!(
            "lqr standing, {}: {:?}, tilt RMS {:.3} deg",
            m.as_str(),
            t.happened.outcome,
            t.tilt_rms_rad.to_degrees()
        );
        t.balanced
    };
    assert!(stands(Mechanism::Ideal));
    assert!(stands(Mechanism::Drivetrain));
    assert!(!stands(Mechanism::RubberCoating));
}
