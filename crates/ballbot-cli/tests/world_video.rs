//! `ballbot world --video`: a GIF of the run with a frame per 1/fps of simulated time (times
//! the playback speed), the run itself unchanged; a still PNG; `.mp4` without ffmpeg on PATH
//! is an error naming ffmpeg.

use ballbot_cli::world::{WorldArgs, simulate, simulate_with_video};
use std::process::Command;

fn short(video: Option<std::path::PathBuf>) -> WorldArgs {
    WorldArgs {
        duration_secs: 0.4,
        no_log: true,
        video,
        video_fps: 20.0,
        video_speed: 0.5,
        video_size: (160, 120),
        ..WorldArgs::default()
    }
}

#[test]
fn a_gif_has_a_frame_per_step_of_video_time_and_the_run_is_the_same() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("clip/run.gif");
    let (with, video) = simulate_with_video(&short(Some(path.clone()))).unwrap();
    let (written, frames) = video.unwrap();
    assert_eq!(written, path);
    // 20 frames/s at 0.5 simulated seconds per second of video: a frame every 0.025 s of the
    // 0.4 s run, at 0, 0.025, ..., 0.4 s.
    assert_eq!(frames, 17);
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(&bytes[..6], b"GIF89a");
    let without = simulate(&short(None)).unwrap();
    assert_eq!(
        serde_json::to_value(&with).unwrap(),
        serde_json::to_value(&without).unwrap()
    );
}

#[test]
fn a_png_is_one_still_frame() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("still.png");
    let mut args = short(Some(path.clone()));
    args.video_from_secs = 0.2;
    let (_, video) = simulate_with_video(&args).unwrap();
    assert_eq!(video.unwrap().1, 1);
    assert_eq!(&std::fs::read(&path).unwrap()[1..4], b"PNG");
    args.video_from_secs = 9.0;
    let err = simulate_with_video(&args).unwrap_err();
    assert!(format!("{err:#}").contains("ended before"), "{err:#}");
}

#[test]
fn mp4_without_ffmpeg_on_path_names_ffmpeg_and_other_extensions_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_ballbot"))
        .args(["world", "--duration-secs", "0.1", "--no-log", "--video"])
        .arg(dir.path().join("run.mp4"))
        .env("PATH", dir.path())
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("needs ffmpeg on PATH"), "{stderr}");
    let err = simulate_with_video(&short(Some(dir.path().join("run.avi")))).unwrap_err();
    assert!(format!("{err:#}").contains(".gif"), "{err:#}");
}
