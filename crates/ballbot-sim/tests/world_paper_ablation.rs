//! The paper's controller as an ablation in the 3D world
//! (`BallbotControllerConfig::with_paper_ablation`: the upright wheel mapping of MODEL.md
//! section 4 and no jerk limit): on the maximum-speed study's slow ramp it loses its heading at
//! about 2.9 m/s whatever the heading, as the world's controller did before the yaw fix
//! (docs/world-reproduce.md, "Yaw at speed").

use ballbot_core::BallbotParams;
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_sim::studies::max_speed::MaxSpeedProtocol;
use ballbot_sim::studies::ramp::max_speed_ramp_observed;
use ballbot_sim::world::WorldParams;

/// The slow ramp of the maximum-speed study (0.25 m/s^2, shaper caps lifted as
/// `studies::max_speed::controller` does) with the paper ablation at `heading_deg`, sensor seed
/// 1, the ramp's top lowered to 3.6 m/s (it fails well before; the run ends 1 s after the top).
/// Returns the maximum speed (m/s), whether it lost its balance (the world's failure, or the
/// supervisor's stop that comes first since the tilt limit looks at the tilt from the
/// vertical), and the largest |yaw| (deg) before that.
fn paper_slow_ramp(heading_deg: f64) -> (f64, bool, f64) {
    let mut params = WorldParams::ideal(BallbotParams::miapure_60kg());
    params.sensors.seed = 1;
    let protocol = MaxSpeedProtocol::default();
    let mut config = BallbotControllerConfig::with_paper_ablation(&params.robot).unwrap();
    protocol.shaper.apply(&mut config);
    let mut ramp = protocol.slow_ramp;
    ramp.max_command_m_per_s = 3.6;
    let mut max_yaw_deg: f64 = 0.0;
    let run = max_speed_ramp_observed(params, config, heading_deg, &ramp, &mut |sim, _| {
        let (_, _, yaw) = sim.world().telemetry().body_orientation.euler_angles();
        max_yaw_deg = max_yaw_deg.max(yaw.to_degrees().abs());
    })
    .unwrap();
    println!(
        "{heading_deg} deg: failure {:?}, supervisor stop {:?}",
        run.failure, run.supervisor_stop_secs
    );
    let failed_balancing = run.failure.is_some() || run.supervisor_stop_secs.is_some();
    (run.max_speed_m_per_s, failed_balancing, max_yaw_deg)
}

#[test]
fn paper_ablation_loses_its_heading_at_the_same_speed_in_every_direction() {
    // Release measurements (seeds 1, 2, 3; docs/drafts/load-transfer.md): 0 deg 3.04, 2.97,
    // 2.91; 90 deg 2.84, 2.87, 2.82; 180 deg 2.98, 3.10, 2.88 m/s, every run a sustained slip
    // after the yaw diverged (the designed controller reaches 5.85 / 5.09 / 5.85 m/s, the
    // wheels' speed limit). The band [2.6, 3.3] m/s holds all nine runs with 0.2 m/s to spare;
    // the spread over headings of one seed (0.19 m/s here, 0.28 over all nine runs) must stay
    // below 0.4 m/s: the failure speed does not depend on the direction, unlike a traction
    // limit (the failing accelerations differ by a factor 1.8 between 0 and 180 deg).
    let mut speeds = Vec::new();
    for heading_deg in [0.0, 90.0, 180.0] {
        let (speed, failed, max_yaw_deg) = paper_slow_ramp(heading_deg);
        println!(
            "{heading_deg} deg: {speed:.3} m/s, failed {failed}, max |yaw| {max_yaw_deg:.1} deg"
        );
        assert!(failed, "{heading_deg} deg: no failure up to {speed} m/s");
        assert!(
            (2.6..=3.3).contains(&speed),
            "{heading_deg} deg: failed at {speed} m/s"
        );
        // The failure is the heading's: the yaw ran away before the wheels slipped.
        assert!(
            max_yaw_deg > 20.0,
            "{heading_deg} deg: yaw only {max_yaw_deg} deg"
        );
        speeds.push(speed);
    }
    let spread = speeds.iter().copied().fold(f64::MIN, f64::max)
        - speeds.iter().copied().fold(f64::MAX, f64::min);
    assert!(spread < 0.4, "{speeds:?}");
}
