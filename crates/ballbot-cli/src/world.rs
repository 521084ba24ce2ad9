//! `ballbot world`: one run of the 3D world (rapier3d) with the core's controller in the loop,
//! written to an MCAP log for Foxglove (`ballbot_sim::studies::world_run`).
//!
//! The command is a velocity ramp at `--accel-m-per-s2` towards `--heading-deg` (body frame, 0
//! is towards OW1) up to `--top-speed-m-per-s`, after a 0.5 s hold; optionally a push of the
//! body. Prints the outcome (failure kind, wheel and time; highest speed; peak friction-cone
//! utilisation) and writes the log.
//!
//! ```text
//! ballbot world --heading-deg 0 --accel-m-per-s2 1.0 --top-speed-m-per-s 1.5 \
//!     --duration-secs 4 --out out/world.mcap
//! ballbot world --push-ns 40 --push-at-secs 1.0 --push-heading-deg 90 --duration-secs 3
//! ballbot world --live --duration-secs 30 --decimate 8    # watch it in Foxglove as it runs
//! ballbot world --duration-secs 60 --decimate 8000        # a 1 Hz log of a minute
//! ballbot world --duration-secs 60 --no-log               # the same run, no log
//! ballbot world --no-log --video out/world.gif            # an animated GIF of the run
//! ```
//!
//! With `--live` the run is also served over the Foxglove SDK's WebSocket server
//! (`ws://127.0.0.1:8765` by default), paced to real time unless `--as-fast-as-possible`.

use crate::video::VideoRecorder;
use anyhow::{Context, bail};
use ballbot_core::BallbotParams;
use ballbot_core::ballbot::BallbotControllerConfig;
use ballbot_sim::log::{LiveOptions, LivePace, LiveServer, LogSink, McapLogger, WorldLogOptions};
use ballbot_sim::params_file::{FileKind, ParamsFile};
pub use ballbot_sim::studies::world_run::{SETTLE_SECS, WorldOutcome};
use ballbot_sim::studies::world_run::{
    WorldRunSettings, run_logged_world, run_world, run_world_observed, run_world_with_sink,
};
use ballbot_sim::world::{StopRules, WorldParams, wheel_name};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Examples and log sizes shown after `ballbot world --help`.
pub const AFTER_HELP: &str = "\
Examples:
  ballbot world --heading-deg 0 --accel-m-per-s2 1 --top-speed-m-per-s 1.5 --duration-secs 4 \\
      --out out/world.mcap
  ballbot world --wheel-ball-friction 0.05 --accel-m-per-s2 1 --duration-secs 1.5 --out out/slip.mcap
  ballbot world --top-speed-m-per-s 0 --push-ns 40 --push-at-secs 1 --duration-secs 3

  ballbot world --live --duration-secs 30 --decimate 8
  ballbot world --duration-secs 60 --decimate 8000     # every channel at most 1 Hz
  ballbot world --duration-secs 60 --no-log            # the same run without a log
  ballbot world --no-log --duration-secs 3 --video out/world.gif   # a GIF (.mp4: ffmpeg)

Open the log in Foxglove with the layout foxglove/world-layout.json (3D scene, per-wheel
normal force, cone utilisation, slip speed). With --live, open a Foxglove WebSocket connection
to the printed address (ws://127.0.0.1:8765) and watch the run as it happens. Size: about
3.3 MB per simulated second with telemetry at every 8 kHz step, 0.81 MB with --decimate 8
(1 kHz), about 4 kB with --decimate 8000 (1 Hz).";

/// How long `--live` waits, once a client has connected, for it to subscribe before the run
/// starts.
const LIVE_SUBSCRIBE_WAIT: Duration = Duration::from_secs(5);

/// The controller configuration `ballbot world --controller` runs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ControllerChoice {
    /// The shipped default (`BallbotControllerConfig::design`), designed for the world's
    /// robot.
    Design,
    /// The paper's configuration (`BallbotControllerConfig::paper`), designed for the
    /// world's robot.
    Paper,
    /// A controller file (`ballbot params show --kind controller`), its own robot model
    /// included: a controller designed for another robot than the world's is a model
    /// mismatch, and runs as one.
    File(PathBuf),
}

impl std::str::FromStr for ControllerChoice {
    type Err = std::convert::Infallible;

    /// `design`, `paper`, or else the path of a controller file.
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        Ok(match text {
            "design" => Self::Design,
            "paper" => Self::Paper,
            path => Self::File(PathBuf::from(path)),
        })
    }
}

impl ControllerChoice {
    /// The configuration: designed for `robot`, or read and checked from the file (every
    /// error names the file and the key).
    pub fn config(
        &self,
        robot: &BallbotParams<f64>,
    ) -> anyhow::Result<BallbotControllerConfig<f64>> {
        let designed = match self {
            Self::Design => BallbotControllerConfig::design(robot),
            Self::Paper => BallbotControllerConfig::paper(robot),
            Self::File(path) => return read_controller_file(path),
        };
        designed.context(
            "cannot design the controller for this robot (--wheel-ball-friction/--com-height-m)",
        )
    }
}

/// A controller file, checked ([`ParamsFile::check`]).
pub fn read_controller_file(path: &Path) -> anyhow::Result<BallbotControllerConfig<f64>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read the controller file {}", path.display()))?;
    match ParamsFile::check(&text, FileKind::Controller)
        .with_context(|| format!("{} is not a valid controller file", path.display()))?
    {
        ParamsFile::Controller(config) => Ok(*config),
        other => bail!(
            "{} is a {} file, not a controller file",
            path.display(),
            other.kind()
        ),
    }
}

/// Arguments of `ballbot world`.
#[derive(Debug, Clone, clap::Args)]
pub struct WorldArgs {
    /// Heading of travel in the body frame (deg; 0 is towards OW1, counter-clockwise from
    /// above).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = crate::finite_f64)]
    pub heading_deg: f64,
    /// Acceleration of the commanded velocity ramp (m/s^2, > 0). Above the core's shaper cap
    /// (1.0 m/s^2) the cap is raised to it, with the tilt-command limits raised to 0.5 rad and
    /// 5 rad/s.
    #[arg(long, default_value_t = 0.5, value_parser = crate::finite_f64)]
    pub accel_m_per_s2: f64,
    /// Top commanded speed (m/s, >= 0); the ramp holds it. Above the core's shaper cap
    /// (2.0 m/s) the cap is raised to it.
    #[arg(long, default_value_t = 1.0, value_parser = crate::finite_f64)]
    pub top_speed_m_per_s: f64,
    /// Simulated time (s, > 0); the ramp starts after a 0.5 s hold.
    #[arg(long, default_value_t = 5.0, value_parser = crate::finite_f64)]
    pub duration_secs: f64,
    /// Seed of the sensor noise.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Omniwheel-ball friction coefficient mu (> 0); default the robot's (0.6). The
    /// controller is designed for the same robot.
    #[arg(long, value_parser = crate::finite_f64)]
    pub wheel_ball_friction: Option<f64>,
    /// Height of the body's centre of mass above the ball centre (m, > 0); default the
    /// robot's (0.5). The controller is designed for the same robot.
    #[arg(long, value_parser = crate::finite_f64)]
    pub com_height_m: Option<f64>,
    /// Horizontal impulse applied to the body at its centre of mass (N s, >= 0); 0: no push.
    #[arg(long, default_value_t = 0.0, value_parser = crate::finite_f64)]
    pub push_ns: f64,
    /// When the push is applied (s).
    #[arg(long, default_value_t = 2.0, value_parser = crate::finite_f64)]
    pub push_at_secs: f64,
    /// Direction of the push in the body frame (deg; 0 is towards OW1).
    #[arg(long, default_value_t = 90.0, allow_negative_numbers = true, value_parser = crate::finite_f64)]
    pub push_heading_deg: f64,
    /// Simulated time kept running after a failure, to see the fall (s, >= 0).
    #[arg(long, default_value_t = 0.25, value_parser = crate::finite_f64)]
    pub after_failure_secs: f64,
    /// The world's stop rules, which end a run early: `all` (tilt, slip, lift-off,
    /// driver-trip: as every study ran before), `none` (the run ends at its end or when the
    /// body touches the floor), or some of `tilt,slip,lift-off,driver-trip`. The events
    /// (slips, lift-offs, trips, faults, traction limits) are reported whatever the rules.
    #[arg(long, default_value = "all")]
    pub stop_on: StopRules,
    /// The controller: `design`, the shipped default (traction-aware control and
    /// balance-point estimation on), `paper`, the configuration the paper's studies pin (both
    /// off) (`BallbotControllerConfig::design` / `::paper`, designed for the world's robot),
    /// or the path of a controller file (`ballbot params show --kind controller --preset
    /// design > mine.toml`, then edit; its robot model is the controller's own).
    #[arg(long, default_value = "design", value_name = "design|paper|FILE")]
    pub controller: ControllerChoice,
    /// The traction envelope's friction safety factor (>= 1; it plans with `mu / factor`):
    /// overrides the controller's (`traction.friction_safety_factor`, 2 in `design`; used only
    /// where traction-aware control is on).
    #[arg(long, value_parser = crate::finite_f64)]
    pub traction_safety_factor: Option<f64>,
    /// Time constant of the command shaper's reference filter (s, >= 0; 0 is off). Default:
    /// the controller's own (0.3 s in `design`, off in `paper`), which removes the speed
    /// overshoot of a velocity ramp (`CommandShaperParams::reference_filter_secs`,
    /// docs/embedding.md).
    #[arg(long, value_parser = crate::finite_f64)]
    pub reference_filter_secs: Option<f64>,
    /// The MCAP log to write (its folder is created).
    #[arg(long, default_value = "out/world.mcap")]
    pub out: PathBuf,
    /// Write no log: the same run, step for step, printing only its outcome (what a log
    /// costs is the difference in speed).
    #[arg(long, conflicts_with_all = ["live", "out", "decimate", "scene_hz"])]
    pub no_log: bool,
    /// Write the telemetry every N physics steps (1: every 8 kHz step), and no other channel
    /// more often: the controller's output (400 Hz), the transforms and joint states (twice
    /// --scene-hz) and the scene (--scene-hz) keep their rates where these are slower, so
    /// `--decimate 8000` is a 1 Hz log.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    pub decimate: u32,
    /// Rate of the Foxglove scene (SceneUpdate) messages (Hz, > 0); the frame transforms are
    /// written at twice this rate.
    #[arg(long, default_value_t = 50.0, value_parser = crate::finite_f64)]
    pub scene_hz: f64,
    /// Print the outcome as JSON.
    #[arg(long)]
    pub json: bool,
    /// Also serve the run live over the Foxglove SDK's WebSocket server (Foxglove: Open
    /// connection, Foxglove WebSocket, the printed address).
    #[arg(long)]
    pub live: bool,
    /// Address the live view listens on (127.0.0.1: this machine only).
    #[arg(long, default_value = "127.0.0.1", requires = "live")]
    pub live_host: String,
    /// Port of the live view (0 picks a free one, printed).
    #[arg(long, default_value_t = 8765, requires = "live")]
    pub live_port: u16,
    /// Wait up to this long for Foxglove to connect before the run starts (s, >= 0); then up
    /// to 5 s more for it to subscribe to the run's channels.
    #[arg(long, default_value_t = 60.0, requires = "live", value_parser = crate::finite_f64)]
    pub live_wait_secs: f64,
    /// Run the live view as fast as the simulation goes instead of in real time.
    #[arg(long, requires = "live")]
    pub as_fast_as_possible: bool,
    /// Also write a video of the run (`ballbot_render`'s 3/4 view: floor grid, ball, body,
    /// omniwheels with their rollers, contact-force arrows coloured by friction-cone use,
    /// lift-off and slip marked): `.gif` an animated GIF, `.mp4` through `ffmpeg` (on PATH),
    /// `.png` one still frame at --video-from-secs.
    #[arg(long, value_name = "FILE.gif|FILE.mp4", conflicts_with = "live")]
    pub video: Option<PathBuf>,
    /// Frames per second of the video (in (0, 100]).
    #[arg(long, default_value_t = 25.0, requires = "video", value_parser = crate::finite_f64)]
    pub video_fps: f64,
    /// Simulated seconds per second of video (< 1 is slow motion: 0.25 shows a lift-off at a
    /// quarter of its speed).
    #[arg(long, default_value_t = 1.0, requires = "video", value_parser = crate::finite_f64)]
    pub video_speed: f64,
    /// Simulated time of the video's first frame (s, >= 0): the run before it is not shown.
    #[arg(long, default_value_t = 0.0, requires = "video", value_parser = crate::finite_f64)]
    pub video_from_secs: f64,
    /// Size of the video's frames (WIDTHxHEIGHT pixels).
    #[arg(long, default_value = "480x360", requires = "video", value_parser = crate::video::parse_size)]
    pub video_size: (u32, u32),
}

impl Default for WorldArgs {
    fn default() -> Self {
        Self {
            heading_deg: 0.0,
            accel_m_per_s2: 0.5,
            top_speed_m_per_s: 1.0,
            duration_secs: 5.0,
            seed: 0,
            wheel_ball_friction: None,
            com_height_m: None,
            push_ns: 0.0,
            push_at_secs: 2.0,
            push_heading_deg: 90.0,
            after_failure_secs: 0.25,
            stop_on: StopRules::all(),
            controller: ControllerChoice::Design,
            traction_safety_factor: None,
            reference_filter_secs: None,
            out: PathBuf::from("out/world.mcap"),
            no_log: false,
            decimate: 1,
            scene_hz: 50.0,
            json: false,
            live: false,
            live_host: "127.0.0.1".to_owned(),
            live_port: 8765,
            live_wait_secs: 60.0,
            as_fast_as_possible: false,
            video: None,
            video_fps: 25.0,
            video_speed: 1.0,
            video_from_secs: 0.0,
            video_size: (480, 360),
        }
    }
}

fn check(ok: bool, flag: &str, requirement: &str, value: f64) -> anyhow::Result<()> {
    if ok {
        Ok(())
    } else {
        bail!("{flag} must be {requirement}, got {value}")
    }
}

impl WorldArgs {
    /// Checks every flag; the error names the first bad one.
    pub fn validate(&self) -> anyhow::Result<()> {
        let finite = |x: f64| x.is_finite();
        check(
            finite(self.heading_deg),
            "--heading-deg",
            "finite",
            self.heading_deg,
        )?;
        check(
            finite(self.accel_m_per_s2) && self.accel_m_per_s2 > 0.0,
            "--accel-m-per-s2",
            "finite and > 0",
            self.accel_m_per_s2,
        )?;
        check(
            finite(self.top_speed_m_per_s) && self.top_speed_m_per_s >= 0.0,
            "--top-speed-m-per-s",
            "finite and >= 0",
            self.top_speed_m_per_s,
        )?;
        check(
            finite(self.duration_secs) && self.duration_secs > 0.0 && self.duration_secs <= 3600.0,
            "--duration-secs",
            "in (0, 3600]",
            self.duration_secs,
        )?;
        if let Some(mu) = self.wheel_ball_friction {
            check(
                finite(mu) && mu > 0.0,
                "--wheel-ball-friction",
                "finite and > 0",
                mu,
            )?;
        }
        if let Some(h) = self.com_height_m {
            check(finite(h) && h > 0.0, "--com-height-m", "finite and > 0", h)?;
        }
        check(
            finite(self.push_ns) && self.push_ns >= 0.0,
            "--push-ns",
            "finite and >= 0",
            self.push_ns,
        )?;
        check(
            finite(self.push_at_secs) && self.push_at_secs >= 0.0,
            "--push-at-secs",
            "finite and >= 0",
            self.push_at_secs,
        )?;
        check(
            finite(self.push_heading_deg),
            "--push-heading-deg",
            "finite",
            self.push_heading_deg,
        )?;
        check(
            finite(self.after_failure_secs) && self.after_failure_secs >= 0.0,
            "--after-failure-secs",
            "finite and >= 0",
            self.after_failure_secs,
        )?;
        if let Some(filter_secs) = self.reference_filter_secs {
            check(
                finite(filter_secs) && filter_secs >= 0.0,
                "--reference-filter-secs",
                "finite and >= 0",
                filter_secs,
            )?;
        }
        check(
            finite(self.scene_hz) && self.scene_hz > 0.0 && self.scene_hz <= 1000.0,
            "--scene-hz",
            "in (0, 1000]",
            self.scene_hz,
        )?;
        check(
            finite(self.live_wait_secs) && self.live_wait_secs >= 0.0,
            "--live-wait-secs",
            "finite and >= 0",
            self.live_wait_secs,
        )?;
        Ok(())
    }

    /// The world's parameters: MiaPURE with 60 kg, with `--seed`, `--wheel-ball-friction`, `--com-height-m`.
    pub fn world_params(&self) -> anyhow::Result<WorldParams> {
        let mut params = WorldParams::miapure_60kg();
        params.sensors.seed = self.seed;
        if let Some(mu) = self.wheel_ball_friction {
            params.robot.drivetrain.wheel_ball_friction = mu;
        }
        if let Some(h) = self.com_height_m {
            params.robot.sagittal.com_height_m = h;
            params.robot.frontal.com_height_m = h;
        }
        params
            .validate()
            .context("the robot given by --wheel-ball-friction/--com-height-m is invalid")?;
        Ok(params)
    }

    /// The controller (`--controller`) with the flags' overrides, and the command shaper's
    /// speed and acceleration caps raised to the requested ramp where it exceeds them
    /// (`CommandShaperParams::admitting_ramp`). The result is checked as a whole.
    pub fn controller_config(
        &self,
        params: &WorldParams,
    ) -> anyhow::Result<BallbotControllerConfig<f64>> {
        let mut config = self.controller.config(&params.robot)?;
        if let Some(filter_secs) = self.reference_filter_secs {
            config.shaping.reference_filter_secs = filter_secs;
        }
        if let Some(factor) = self.traction_safety_factor {
            config.traction.friction_safety_factor = factor;
        }
        config.shaping = config
            .shaping
            .admitting_ramp(self.top_speed_m_per_s, self.accel_m_per_s2);
        ballbot_core::ballbot::BallbotController::new(config).context(
            "the controller with --traction-safety-factor/--reference-filter-secs is invalid",
        )?;
        Ok(config)
    }
}

impl WorldArgs {
    /// What the log of a world stepping every `dt_secs` writes and how often: no channel
    /// faster than the telemetry.
    fn log_options(&self, dt_secs: f64) -> WorldLogOptions {
        let scene_interval_secs = 1.0 / self.scene_hz;
        WorldLogOptions {
            telemetry_every_steps: self.decimate,
            scene_interval_secs,
            transform_interval_secs: 0.5 * scene_interval_secs,
            ..WorldLogOptions::default()
        }
        .capped_at_telemetry_rate(dt_secs)
    }

    /// The command and push of the run.
    fn run_settings(&self) -> WorldRunSettings {
        WorldRunSettings {
            heading_deg: self.heading_deg,
            accel_m_per_s2: self.accel_m_per_s2,
            top_speed_m_per_s: self.top_speed_m_per_s,
            duration_secs: self.duration_secs,
            push_ns: self.push_ns,
            push_at_secs: self.push_at_secs,
            push_heading_deg: self.push_heading_deg,
            after_failure_secs: self.after_failure_secs,
            stop_rules: self.stop_on,
        }
    }
}

/// Runs the world as `args` say, writes the log (none with `--no-log`) and returns the
/// outcome (without printing). `--live` is not served here (see [`run`]).
pub fn simulate(args: &WorldArgs) -> anyhow::Result<WorldOutcome> {
    Ok(simulate_with_video(args)?.0)
}

/// [`simulate`], also writing `--video` if given: returns the outcome and the video's path and
/// frame count.
pub fn simulate_with_video(
    args: &WorldArgs,
) -> anyhow::Result<(WorldOutcome, Option<(PathBuf, u64)>)> {
    args.validate()?;
    let params = args.world_params()?;
    let config = args.controller_config(&params)?;
    if let Some(path) = &args.video {
        let mut video = VideoRecorder::create(
            path,
            &params,
            args.video_size,
            args.video_fps,
            args.video_speed,
            args.video_from_secs,
        )?;
        let log = (!args.no_log).then(|| (args.out.as_path(), args.log_options(params.dt_secs)));
        let outcome = run_world_observed(params, config, &args.run_settings(), log, &mut |t| {
            video.observe(t)
        })
        .with_context(|| format!("ballbot world --out {}", args.out.display()))?;
        return Ok((outcome, Some(video.finish()?)));
    }
    Ok((simulate_without_video(args, params, config)?, None))
}

fn simulate_without_video(
    args: &WorldArgs,
    params: WorldParams,
    config: BallbotControllerConfig<f64>,
) -> anyhow::Result<WorldOutcome> {
    if args.no_log {
        return Ok(run_world(params, config, &args.run_settings())?);
    }
    run_logged_world(
        params,
        config,
        &args.run_settings(),
        &args.out,
        args.log_options(params.dt_secs),
    )
    .with_context(|| format!("ballbot world --out {}", args.out.display()))
}

/// Runs the world as `args` say, writing the log and serving it live to Foxglove
/// (`--live`): prints the address, waits up to `--live-wait-secs` for a client, then runs
/// paced to real time (or as fast as possible).
pub fn simulate_live(args: &WorldArgs) -> anyhow::Result<WorldOutcome> {
    args.validate()?;
    let params = args.world_params()?;
    let config = args.controller_config(&params)?;
    let pace = if args.as_fast_as_possible {
        LivePace::AsFastAsPossible
    } else {
        LivePace::RealTime
    };
    let server = LiveServer::start(LiveOptions {
        host: args.live_host.clone(),
        port: args.live_port,
        pace,
        ..LiveOptions::default()
    })
    .context("ballbot world --live: cannot start the Foxglove WebSocket server")?;
    println!(
        "live view: {} (Foxglove: Open connection, Foxglove WebSocket)",
        server.url()
    );
    std::io::stdout().flush()?;
    if let Some(dir) = args.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    let options = args.log_options(params.dt_secs);
    let file = McapLogger::create(&args.out, options.logger.clone())
        .with_context(|| format!("ballbot world --out {}", args.out.display()))?;
    let sink = LogSink::file(file).with_live(server.clone());
    let run = args.run_settings();
    // Wait for a client only once the run's channels exist: a client that connects then is
    // sent every channel before its first subscription is read (one connected earlier can
    // subscribe to a channel in the instant between its advertisement and its registration
    // for that client, and be refused). A connected client subscribes once it has seen the
    // channels: wait for that too, so that it sees the run from its first step.
    let live_wait_secs = args.live_wait_secs;
    let wait_for_client = |sink: &LogSink| {
        if live_wait_secs <= 0.0 {
            return;
        }
        if sink.wait_for_client(Duration::from_secs_f64(live_wait_secs)) {
            sink.wait_for_subscriber(LIVE_SUBSCRIBE_WAIT);
        } else {
            println!("no client after {live_wait_secs} s: running anyway");
        }
    };
    let outcome = run_world_with_sink(params, config, &run, sink, options, wait_for_client)
        .with_context(|| format!("ballbot world --live --out {}", args.out.display()))?;
    server.stop();
    Ok(outcome)
}

/// Prints the events, grouped by kind and wheel: how many, the first's onset, the longest.
fn print_events(o: &WorldOutcome) {
    if o.events.is_empty() {
        println!("events: none");
        return;
    }
    let mut groups: std::collections::BTreeMap<String, (usize, f64, f64)> = Default::default();
    for e in &o.events {
        let name = serde_json::to_value(e).ok().map_or_else(String::new, |v| {
            let what = v.get("wheel").or_else(|| v.get("fault"));
            match what.and_then(|w| w.as_str()) {
                Some(w) => format!("{} {w}", e.kind.as_str()),
                None => e.kind.as_str().to_owned(),
            }
        });
        let g = groups.entry(name).or_insert((0, e.onset_secs, 0.0));
        g.0 += 1;
        g.2 = g.2.max(e.duration_secs);
    }
    println!("events ({} in all):", o.events.len());
    for (name, (n, first, longest)) in groups {
        println!(
            "  {name}: {n}, first at {first:.3} s, longest {:.1} ms",
            longest * 1e3
        );
    }
}

/// Runs `ballbot world` and prints the outcome.
pub fn run(args: &WorldArgs) -> anyhow::Result<()> {
    let (o, video) = if args.live {
        (simulate_live(args)?, None)
    } else {
        simulate_with_video(args)?
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&o)?);
        return Ok(());
    }
    match o.outcome.time_secs() {
        Some(t) => println!("outcome: {} at {t:.4} s", o.outcome.as_str()),
        None => println!("outcome: {}", o.outcome.as_str()),
    }
    println!("stop rules: {}", o.stop_rules);
    match (&o.failure, o.failure_time_secs) {
        (Some(kind), Some(time_secs)) => {
            let wheel = o.failure_wheel.map_or_else(String::new, |w| {
                format!(" of {}", wheel_name(w.saturating_sub(1)))
            });
            println!("failure: {kind}{wheel} at {time_secs:.4} s");
        }
        _ => println!("failure: none ({:.3} s simulated)", o.end_time_secs),
    }
    print_events(&o);
    println!(
        "max speed along {} deg: {:.3} m/s",
        args.heading_deg, o.max_speed_m_per_s
    );
    println!(
        "peak cone utilisation: {:.3} (OW{}); min normal force {:.1} N; max tilt {:.2} deg",
        o.peak_cone_utilisation, o.peak_cone_wheel, o.min_normal_force_n, o.max_tilt_deg
    );
    if args.no_log {
        println!("log: none (--no-log)");
    } else {
        println!("log: {} ({:.2} MB)", o.log, o.log_bytes as f64 / 1.0e6);
    }
    if let Some((path, frames)) = video {
        let bytes = std::fs::metadata(&path).map_or(0, |m| m.len());
        println!(
            "video: {} ({frames} frames, {:.2} MB)",
            path.display(),
            bytes as f64 / 1.0e6
        );
    }
    Ok(())
}
