//! The renderer draws what the world's state says: three wheels (each in its colour), a lifted wheel in the
//! lift-off colour, a floor that moves with the world and not with the camera.

use ballbot_render::palette;
use ballbot_render::{Frame, SceneRenderer};
use ballbot_world::world::{BallbotWorld, StepTelemetry, WorldParams};
use nalgebra::Vector3;

type Result<T = ()> = std::result::Result<T, Box<dyn std::error::Error>>;

/// The robot at rest on the floor, its wheels loaded.
fn resting() -> Result<(WorldParams, StepTelemetry)> {
    let params = WorldParams::miapure_60kg();
    let mut world = BallbotWorld::new(params)?;
    for _ in 0..80 {
        world.step([0.0; 3]);
    }
    Ok((params, *world.telemetry()))
}

#[test]
fn a_resting_robot_shows_three_wheels_and_nothing_lifted() -> Result {
    let (params, t) = resting()?;
    assert!(t.wheels.iter().all(|w| w.normal_force_n > 100.0));
    let mut r = SceneRenderer::new(&params, 480, 360)?;
    let frame = r.render(&t);
    assert_eq!(frame.rgb.len(), 480 * 360 * 3);
    for (i, rgb) in palette::WHEELS.iter().enumerate() {
        assert!(frame.count(*rgb) > 60, "OW{}: {}", i + 1, frame.count(*rgb));
    }
    assert_eq!(frame.count(palette::LIFT_OFF), 0);
    // The force arrows at rest are green (cone use near 0).
    assert!(frame.count(palette::cone_colour(t.wheels[0].cone_utilisation)) > 20);
    Ok(())
}

#[test]
fn a_lifted_wheel_is_painted_in_the_lift_off_colour() -> Result {
    let (params, mut t) = resting()?;
    t.wheels[1].normal_force_n = 0.0;
    t.wheels[1].cone_utilisation = 0.0;
    let mut r = SceneRenderer::new(&params, 480, 360)?;
    let frame = r.render(&t);
    assert!(
        frame.count(palette::LIFT_OFF) > 200,
        "{}",
        frame.count(palette::LIFT_OFF)
    );
    assert_eq!(frame.count(palette::WHEELS[1]), 0);
    assert!(frame.count(palette::WHEELS[0]) > 60 && frame.count(palette::WHEELS[2]) > 60);
    Ok(())
}

#[test]
fn the_floor_grid_moves_with_the_world() -> Result {
    let (params, t) = resting()?;
    let moved = |dx: f64| {
        let mut m = t;
        m.ball_position_m += Vector3::new(dx, 0.0, 0.0);
        m.body_position_m += Vector3::new(dx, 0.0, 0.0);
        m
    };
    let mut r = SceneRenderer::new(&params, 480, 360)?;
    let a = r.render(&t);
    let differing = |b: &Frame| {
        a.rgb
            .chunks(3)
            .zip(b.rgb.chunks(3))
            .filter(|(p, q)| p != q)
            .count()
    };
    // A quarter tile: the floor slides under the robot. A whole checker period (two tiles):
    // the same picture but for rounding at edges.
    let quarter = differing(&r.render(&moved(0.125)));
    let period = differing(&r.render(&moved(2.0 * ballbot_render::scene::TILE_M)));
    assert!(quarter > 10_000, "{quarter}");
    assert!(period < quarter / 10, "{period} vs {quarter}");
    Ok(())
}

#[test]
fn a_frame_is_written_as_png() -> Result {
    let (params, t) = resting()?;
    let mut r = SceneRenderer::new(&params, 64, 48)?;
    r.draw(&t);
    let png = r.png()?;
    assert_eq!(&png[1..4], b"PNG");
    assert!(SceneRenderer::new(&params, 8, 48).is_err());
    Ok(())
}

#[test]
fn the_state_before_the_first_step_shows_no_lift_off() -> Result {
    let params = WorldParams::miapure_60kg();
    let world = BallbotWorld::new(params)?;
    let t = *world.telemetry();
    assert!(t.wheels.iter().all(|w| w.normal_force_n == 0.0));
    let frame = SceneRenderer::new(&params, 480, 360)?.render(&t);
    assert_eq!(frame.count(palette::LIFT_OFF), 0);
    assert!(palette::WHEELS.iter().all(|c| frame.count(*c) > 60));
    Ok(())
}
