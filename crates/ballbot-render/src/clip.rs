//! [`GifClip`]: frames written as an animated GIF that loops.
//!
//! Every frame uses one global palette: a 6 x 6 x 6 colour cube plus the scene's exact
//! colours ([`crate::palette`]), each pixel mapped to its nearest entry through a 32^3 table
//! (fast and the same for every frame). A frame stores only the rectangle that changed since
//! the previous one, with unchanged pixels transparent, which keeps clips small.

use crate::palette;
use crate::scene::Frame;
use std::io::Write;

/// The palette index that means "as in the previous frame".
const TRANSPARENT: u8 = 255;

/// Why a clip cannot be written.
#[derive(Debug, thiserror::Error)]
pub enum ClipError {
    /// The GIF encoder failed (usually the writer).
    #[error("cannot write the GIF: {0}")]
    Gif(#[from] gif::EncodingError),
    /// A frame's size differs from the clip's, or exceeds 65535 pixels a side.
    #[error("frame of {got_width} x {got_height} pixels in a clip of {width} x {height}")]
    Size {
        /// The clip's width (px).
        width: u32,
        /// The clip's height (px).
        height: u32,
        /// The frame's width (px).
        got_width: u32,
        /// The frame's height (px).
        got_height: u32,
    },
    /// The frame rate must be in (0, 100] frames per second (GIF delays are centiseconds).
    #[error("frame rate {0} must be in (0, 100] frames per second")]
    Rate(f64),
}

/// An animated GIF being written (module documentation).
pub struct GifClip<W: Write> {
    encoder: gif::Encoder<W>,
    width: u16,
    height: u16,
    palette: Vec<[u8; 3]>,
    lut: Vec<u8>,
    previous: Option<Vec<u8>>,
    frame_secs: f64,
    frames: u64,
    written_cs: u64,
}

impl<W: Write> GifClip<W> {
    /// A clip of `width` x `height` frames shown at `fps` frames per second, written to
    /// `writer`.
    pub fn new(writer: W, width: u32, height: u32, fps: f64) -> Result<Self, ClipError> {
        if !(fps > 0.0 && fps <= 100.0) {
            return Err(ClipError::Rate(fps));
        }
        let size_error = || ClipError::Size {
            width,
            height,
            got_width: width,
            got_height: height,
        };
        let w = u16::try_from(width).map_err(|_| size_error())?;
        let h = u16::try_from(height).map_err(|_| size_error())?;
        let palette = build_palette();
        let flat: Vec<u8> = palette.iter().flatten().copied().collect();
        let mut encoder = gif::Encoder::new(writer, w, h, &flat)?;
        encoder.set_repeat(gif::Repeat::Infinite)?;
        let lut = nearest_table(&palette);
        Ok(Self {
            encoder,
            width: w,
            height: h,
            palette,
            lut,
            previous: None,
            frame_secs: 1.0 / fps,
            frames: 0,
            written_cs: 0,
        })
    }

    /// The palette's colour for `rgb`.
    pub fn quantise(&self, rgb: [u8; 3]) -> [u8; 3] {
        self.palette[usize::from(self.index(rgb))]
    }

    fn index(&self, [r, g, b]: [u8; 3]) -> u8 {
        let i = (usize::from(r >> 3) << 10) | (usize::from(g >> 3) << 5) | usize::from(b >> 3);
        self.lut[i]
    }

    /// Appends `frame`.
    pub fn push(&mut self, frame: &Frame) -> Result<(), ClipError> {
        if frame.width != u32::from(self.width) || frame.height != u32::from(self.height) {
            return Err(ClipError::Size {
                width: u32::from(self.width),
                height: u32::from(self.height),
                got_width: frame.width,
                got_height: frame.height,
            });
        }
        let indices: Vec<u8> = frame
            .rgb
            .chunks_exact(3)
            .map(|p| self.index([p[0], p[1], p[2]]))
            .collect();
        self.frames += 1;
        let due_cs = (self.frames as f64 * self.frame_secs * 100.0).round() as u64;
        let delay =
            u16::try_from(due_cs.saturating_sub(self.written_cs).max(1)).unwrap_or(u16::MAX);
        self.written_cs += u64::from(delay);
        let (w, h) = (usize::from(self.width), usize::from(self.height));
        let (rect, buffer) = match &self.previous {
            None => ((0, 0, w, h), indices.clone()),
            Some(prev) => changed(prev, &indices, w, h),
        };
        let gif_frame = gif::Frame {
            delay,
            dispose: gif::DisposalMethod::Keep,
            transparent: self.previous.is_some().then_some(TRANSPARENT),
            left: rect.0 as u16,
            top: rect.1 as u16,
            width: rect.2 as u16,
            height: rect.3 as u16,
            buffer: std::borrow::Cow::Owned(buffer),
            ..gif::Frame::default()
        };
        self.encoder.write_frame(&gif_frame)?;
        self.previous = Some(indices);
        Ok(())
    }

    /// Frames written so far.
    pub fn frames(&self) -> u64 {
        self.frames
    }

    /// Ends the clip and returns the writer.
    pub fn finish(self) -> Result<W, ClipError> {
        Ok(self.encoder.into_inner()?)
    }
}

/// The rectangle `(left, top, width, height)` where `now` differs from `prev`, and its
/// indices with unchanged pixels transparent (one pixel when nothing changed).
fn changed(prev: &[u8], now: &[u8], w: usize, h: usize) -> ((usize, usize, usize, usize), Vec<u8>) {
    let (mut x0, mut y0, mut x1, mut y1) = (w, h, 0, 0);
    for y in 0..h {
        let row = y * w;
        for x in 0..w {
            if prev[row + x] != now[row + x] {
                x0 = x0.min(x);
                x1 = x1.max(x + 1);
                y0 = y0.min(y);
                y1 = y1.max(y + 1);
            }
        }
    }
    if x1 <= x0 {
        return ((0, 0, 1, 1), vec![TRANSPARENT]);
    }
    let mut out = Vec::with_capacity((x1 - x0) * (y1 - y0));
    for y in y0..y1 {
        for x in x0..x1 {
            let i = y * w + x;
            out.push(if prev[i] == now[i] {
                TRANSPARENT
            } else {
                now[i]
            });
        }
    }
    ((x0, y0, x1 - x0, y1 - y0), out)
}

/// The 6^3 cube, then the scene's colours; 255 entries (the last index is transparency).
fn build_palette() -> Vec<[u8; 3]> {
    let level = |k: u8| k * 51;
    let mut p: Vec<[u8; 3]> = Vec::with_capacity(255);
    for r in 0..6 {
        for g in 0..6 {
            for b in 0..6 {
                p.push([level(r), level(g), level(b)]);
            }
        }
    }
    let scene = [
        palette::SKY_TOP,
        palette::SKY_HORIZON,
        palette::FLOOR,
        palette::FLOOR_TILE,
        palette::GRID_LINE,
        palette::BALL_LIGHT,
        palette::BALL_DARK,
        palette::BALL_MARK,
        palette::BODY,
        palette::shade(palette::BODY, 0.8),
        palette::shade(palette::BODY, 0.7),
        palette::shade(palette::BODY, 0.9),
        palette::WHEELS[0],
        palette::WHEELS[1],
        palette::WHEELS[2],
        palette::ROLLER,
        palette::LIFT_OFF,
        palette::SLIP,
        palette::INK,
        palette::CONE_RAMP[0],
        palette::CONE_RAMP[1],
        palette::CONE_RAMP[2],
        palette::cone_colour(0.25),
        palette::cone_colour(0.75),
    ];
    p.extend(scene);
    // Greys and the ball's shades fill the rest.
    let mut k = 0u32;
    while p.len() < 255 {
        let s = f64::from(k % 17) / 16.0;
        let c = if k < 17 {
            let g = (s * 255.0).round() as u8;
            [g, g, g]
        } else {
            let (a, b) = (palette::BALL_DARK, palette::BALL_LIGHT);
            let m = |i: usize| {
                (f64::from(a[i]) + (f64::from(b[i]) - f64::from(a[i])) * s).round() as u8
            };
            [m(0), m(1), m(2)]
        };
        p.push(c);
        k += 1;
    }
    p.truncate(255);
    p
}

/// For every 5-bit RGB cell, the nearest palette entry to the cell's centre.
fn nearest_table(palette: &[[u8; 3]]) -> Vec<u8> {
    let mut lut = vec![0u8; 1 << 15];
    for (i, slot) in lut.iter_mut().enumerate() {
        let c = [(i >> 10) & 31, (i >> 5) & 31, i & 31].map(|v| (v as i32) * 8 + 4);
        let mut best = (i32::MAX, 0u8);
        for (k, p) in palette.iter().enumerate() {
            let d: i32 = (0..3).map(|j| (c[j] - i32::from(p[j])).pow(2)).sum();
            if d < best.0 {
                best = (d, k as u8);
            }
        }
        *slot = best.1;
    }
    lut
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat(width: u32, height: u32, rgb: [u8; 3]) -> Frame {
        Frame {
            width,
            height,
            rgb: rgb.repeat((width * height) as usize),
        }
    }

    #[test]
    fn a_clip_decodes_to_its_frames_with_the_right_delays() -> Result<(), Box<dyn std::error::Error>>
    {
        let mut clip = GifClip::new(Vec::new(), 8, 6, 30.0)?;
        let a = flat(8, 6, palette::FLOOR);
        let mut b = a.clone();
        b.rgb[3 * 13..3 * 14].copy_from_slice(&palette::LIFT_OFF);
        for f in [&a, &b, &b] {
            clip.push(f)?;
        }
        assert!(clip.push(&flat(4, 4, palette::FLOOR)).is_err());
        let bytes = clip.finish()?;
        let mut options = gif::DecodeOptions::new();
        options.set_color_output(gif::ColorOutput::RGBA);
        let mut decoder = options.read_info(bytes.as_slice())?;
        let mut delays = Vec::new();
        let mut last = None;
        while let Some(frame) = decoder.read_next_frame()? {
            delays.push(frame.delay);
            last = Some((
                frame.left,
                frame.top,
                frame.width,
                frame.height,
                frame.buffer.to_vec(),
            ));
        }
        // 30 fps in centiseconds: 3, 4, 3 (10 cs in 3 frames).
        assert_eq!(delays, vec![3, 4, 3]);
        // The second frame changed one pixel; the third none.
        assert_eq!(last.map(|l| (l.2, l.3)), Some((1, 1)));
        assert!(GifClip::new(Vec::new(), 8, 6, 0.0).is_err());
        Ok(())
    }

    #[test]
    fn the_scene_colours_are_kept_exactly() -> Result<(), ClipError> {
        let clip = GifClip::new(Vec::new(), 8, 6, 25.0)?;
        for c in [
            palette::LIFT_OFF,
            palette::WHEELS[0],
            palette::WHEELS[1],
            palette::WHEELS[2],
            palette::INK,
            palette::FLOOR,
        ] {
            assert_eq!(clip.quantise(c), c);
        }
        Ok(())
    }
}
