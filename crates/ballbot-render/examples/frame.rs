//! Renders the resting robot to a PNG and measures the renderer's frames per second.
//!
//! ```text
//! cargo run --release -p ballbot-render --example frame -- out/frame.png [lift]
//! ```

use ballbot_render::{DEFAULT_HEIGHT, DEFAULT_WIDTH, SceneRenderer};
use ballbot_world::world::{BallbotWorld, WorldParams};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let out = args.next().unwrap_or_else(|| "out/frame.png".to_owned());
    let lift = args.next().is_some_and(|a| a == "lift");
    let params = WorldParams::miapure_60kg();
    let mut world = BallbotWorld::new(params)?;
    for _ in 0..80 {
        world.step([0.0; 3]);
    }
    let mut t = *world.telemetry();
    if lift {
        t.wheels[1].normal_force_n = 0.0;
        t.wheels[0].cone_utilisation = 0.8;
        t.wheels[2].cone_utilisation = 1.2;
        t.wheels[2].slipping = true;
    }
    let mut renderer = SceneRenderer::new(&params, DEFAULT_WIDTH, DEFAULT_HEIGHT)?;
    if let Ok(d) = std::env::var("VIEW_DISTANCE") {
        renderer.set_view(ballbot_render::CameraView {
            distance_m: d.parse()?,
            ..Default::default()
        });
    }
    renderer.draw(&t);
    if let Some(dir) = std::path::Path::new(&out).parent() {
        std::fs::create_dir_all(dir)?;
    }
    std::fs::write(&out, renderer.png()?)?;
    let n = 300;
    let start = Instant::now();
    let mut rgb = Vec::new();
    for k in 0..n {
        t.ball_position_m.x += 0.003;
        t.body_position_m.x += 0.003;
        t.wheels[0].angle_rad = 0.01 * f64::from(k);
        renderer.draw(&t);
        renderer.rgb_into(&mut rgb);
    }
    let secs = start.elapsed().as_secs_f64();
    println!(
        "{out}: {DEFAULT_WIDTH}x{DEFAULT_HEIGHT}, {:.0} frames/s ({n} frames with RGB read-out in {secs:.2} s)",
        f64::from(n) / secs
    );
    Ok(())
}
