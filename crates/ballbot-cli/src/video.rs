//! `ballbot world --video`: a run's frames (`ballbot_render::SceneRenderer`) as an animated
//! GIF (`.gif`, the `gif` crate), an MP4 video (`.mp4`, frames piped to `ffmpeg`, which must
//! be on PATH) or one still frame (`.png`, at `--video-from-secs`).

use anyhow::{Context, bail};
use ballbot_render::{GifClip, SceneRenderer};
use ballbot_sim::world::{StepTelemetry, WorldParams};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, Stdio};

/// Where the frames go.
enum Sink {
    Gif(GifClip<BufWriter<File>>),
    Ffmpeg {
        child: Child,
        stdin: ChildStdin,
    },
    /// One still frame, at the first frame's time.
    Png,
}

/// A video being recorded from a run's steps.
pub struct VideoRecorder {
    path: PathBuf,
    renderer: SceneRenderer,
    sink: Sink,
    /// Simulated time between frames (s): the playback speed over the frame rate.
    frame_sim_secs: f64,
    next_frame_secs: f64,
    frames: u64,
    rgb: Vec<u8>,
    error: Option<anyhow::Error>,
}

/// What `--video-size` takes: `WIDTHxHEIGHT`.
pub fn parse_size(text: &str) -> Result<(u32, u32), String> {
    let bad = || format!("expected WIDTHxHEIGHT in pixels (e.g. 480x360), got {text:?}");
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(bad)?;
    let w: u32 = w.trim().parse().map_err(|_| bad())?;
    let h: u32 = h.trim().parse().map_err(|_| bad())?;
    if !(16..=4096).contains(&w) || !(16..=4096).contains(&h) {
        return Err(format!("each side must be 16 to 4096 pixels, got {text:?}"));
    }
    Ok((w, h))
}

impl VideoRecorder {
    /// A recorder of the world `params` to `path` (`.gif` or `.mp4`), `size` pixels, shown at
    /// `fps` frames per second, `speed` simulated seconds per second of video, from the
    /// simulated time `from_secs` on.
    pub fn create(
        path: &Path,
        params: &WorldParams,
        size: (u32, u32),
        fps: f64,
        speed: f64,
        from_secs: f64,
    ) -> anyhow::Result<Self> {
        if !(from_secs.is_finite() && from_secs >= 0.0) {
            bail!("--video-from-secs must be finite and >= 0, got {from_secs}");
        }
        if !(fps.is_finite() && fps > 0.0 && fps <= 100.0) {
            bail!("--video-fps must be in (0, 100], got {fps}");
        }
        if !(speed.is_finite() && speed > 0.0) {
            bail!("--video-speed must be finite and > 0, got {speed}");
        }
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("cannot create {}", dir.display()))?;
        }
        let renderer = SceneRenderer::new(params, size.0, size.1)?;
        let sink = match extension.as_deref() {
            Some("gif") => {
                let file = File::create(path)
                    .with_context(|| format!("cannot create {}", path.display()))?;
                Sink::Gif(GifClip::new(BufWriter::new(file), size.0, size.1, fps)?)
            }
            Some("mp4") => ffmpeg(path, size, fps)?,
            Some("png") => Sink::Png,
            _ => bail!(
                "--video {}: the file must end in .gif (an animated GIF), .mp4 (through \
                 ffmpeg) or .png (one still frame at --video-from-secs)",
                path.display()
            ),
        };
        Ok(Self {
            path: path.to_owned(),
            renderer,
            sink,
            frame_sim_secs: speed / fps,
            next_frame_secs: from_secs,
            frames: 0,
            rgb: Vec::new(),
            error: None,
        })
    }

    /// Shows the recorder one step: a frame is drawn whenever a frame's simulated time has
    /// passed. The first error is kept for [`VideoRecorder::finish`].
    pub fn observe(&mut self, t: &StepTelemetry) {
        if self.error.is_some() || t.time_secs + 1e-12 < self.next_frame_secs {
            return;
        }
        self.next_frame_secs += self.frame_sim_secs;
        if let Err(e) = self.frame(t) {
            self.error = Some(e);
        }
    }

    fn frame(&mut self, t: &StepTelemetry) -> anyhow::Result<()> {
        match &mut self.sink {
            Sink::Gif(clip) => clip.push(&self.renderer.render(t))?,
            Sink::Ffmpeg { stdin, .. } => {
                self.renderer.draw(t);
                self.renderer.rgb_into(&mut self.rgb);
                stdin
                    .write_all(&self.rgb)
                    .context("ffmpeg stopped reading frames (see its message above)")?;
            }
            Sink::Png if self.frames == 0 => {
                self.renderer.draw(t);
                std::fs::write(&self.path, self.renderer.png()?)
                    .with_context(|| format!("cannot write {}", self.path.display()))?;
            }
            Sink::Png => return Ok(()),
        }
        self.frames += 1;
        Ok(())
    }

    /// Ends the video: returns its path and frame count, or the first error.
    pub fn finish(self) -> anyhow::Result<(PathBuf, u64)> {
        let path = self.path;
        let context = || format!("--video {}", path.display());
        if let Some(e) = self.error {
            return Err(e.context(context()));
        }
        match self.sink {
            Sink::Gif(clip) => {
                clip.finish()?.flush().with_context(context)?;
            }
            Sink::Png if self.frames == 0 => {
                bail!("{}: the run ended before --video-from-secs", context())
            }
            Sink::Png => {}
            Sink::Ffmpeg { mut child, stdin } => {
                drop(stdin);
                let status = child.wait().with_context(context)?;
                if !status.success() {
                    bail!("{}: ffmpeg failed ({status})", context());
                }
            }
        }
        Ok((path, self.frames))
    }
}

/// `ffmpeg` reading raw RGB frames on its standard input, writing an H.264 MP4.
fn ffmpeg(path: &Path, (w, h): (u32, u32), fps: f64) -> anyhow::Result<Sink> {
    let spawned = Command::new("ffmpeg")
        .args([
            "-y",
            "-loglevel",
            "error",
            "-f",
            "rawvideo",
            "-pix_fmt",
            "rgb24",
        ])
        .args([
            "-s",
            &format!("{w}x{h}"),
            "-r",
            &format!("{fps}"),
            "-i",
            "-",
        ])
        .args([
            "-vf",
            "pad=ceil(iw/2)*2:ceil(ih/2)*2",
            "-pix_fmt",
            "yuv420p",
        ])
        .arg(path)
        .stdin(Stdio::piped())
        .spawn();
    let mut child = match spawned {
        Ok(child) => child,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => bail!(
            "--video {}: writing .mp4 needs ffmpeg on PATH, and none was found (install \
             ffmpeg, e.g. `apt-get install ffmpeg`, or write a .gif instead)",
            path.display()
        ),
        Err(e) => return Err(e).context("cannot start ffmpeg"),
    };
    let stdin = child
        .stdin
        .take()
        .context("ffmpeg's standard input is not a pipe")?;
    Ok(Sink::Ffmpeg { child, stdin })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse() {
        assert_eq!(parse_size("480x360"), Ok((480, 360)));
        assert!(parse_size("480").is_err());
        assert!(parse_size("8x8").is_err());
    }
}
