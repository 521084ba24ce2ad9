//! Text on a frame: DejaVu Sans embedded (the Bitstream Vera licence, `assets/fonts/`), glyphs
//! rasterised by `ab_glyph` once per character and size and blended into the pixmap.

use ab_glyph::{Font, FontRef, PxScale, ScaleFont};
use std::collections::HashMap;
use tiny_skia::{Color, Paint, Pixmap, Rect, Transform};

static DEJAVU_SANS: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");

/// One rasterised glyph: coverage in a box relative to the pen on the baseline.
struct Bitmap {
    left: i32,
    top: i32,
    width: usize,
    coverage: Vec<u8>,
    advance_px: f32,
}

/// The font and the glyphs drawn so far.
pub struct Text {
    font: FontRef<'static>,
    glyphs: HashMap<(char, u16), Bitmap>,
}

/// Where a label goes relative to its anchor point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Anchor {
    /// The anchor is the label's top-left corner.
    TopLeft,
    /// The anchor is the middle of the label's left edge.
    MiddleLeft,
}

impl Text {
    /// The embedded font, or `None` if it cannot be parsed (it always can).
    pub fn new() -> Option<Self> {
        Some(Self {
            font: FontRef::try_from_slice(DEJAVU_SANS).ok()?,
            glyphs: HashMap::new(),
        })
    }

    fn glyph(&mut self, c: char, size: u16) -> &Bitmap {
        let font = &self.font;
        self.glyphs.entry((c, size)).or_insert_with(|| {
            let scale = PxScale::from(f32::from(size));
            let id = font.glyph_id(c);
            let advance_px = font.as_scaled(scale).h_advance(id);
            let glyph = id.with_scale_and_position(scale, ab_glyph::point(0.0, 0.0));
            let Some(outline) = font.outline_glyph(glyph) else {
                return Bitmap {
                    left: 0,
                    top: 0,
                    width: 0,
                    coverage: Vec::new(),
                    advance_px,
                };
            };
            let bounds = outline.px_bounds();
            let width = bounds.width() as usize;
            let height = bounds.height() as usize;
            let mut coverage = vec![0u8; width * height];
            outline.draw(|x, y, c| {
                let i = y as usize * width + x as usize;
                if let Some(v) = coverage.get_mut(i) {
                    *v = (c.clamp(0.0, 1.0) * 255.0).round() as u8;
                }
            });
            Bitmap {
                left: bounds.min.x as i32,
                top: bounds.min.y as i32,
                width,
                coverage,
                advance_px,
            }
        })
    }

    /// Width of `text` at `size` pixels (px).
    pub fn width(&mut self, text: &str, size: u16) -> f32 {
        text.chars().map(|c| self.glyph(c, size).advance_px).sum()
    }

    /// Draws `text` at `size` pixels in `rgb` at `(x, y)` as `anchor` says, on a
    /// translucent white box when `boxed`. Returns the label's right edge (px).
    #[allow(clippy::too_many_arguments)]
    pub fn draw(
        &mut self,
        pixmap: &mut Pixmap,
        text: &str,
        (x, y): (f32, f32),
        anchor: Anchor,
        size: u16,
        rgb: [u8; 3],
        boxed: bool,
    ) -> f32 {
        let ascent = 0.76 * f32::from(size);
        let height = f32::from(size) * 1.15;
        let top = match anchor {
            Anchor::TopLeft => y,
            Anchor::MiddleLeft => y - 0.5 * height,
        };
        let width = self.width(text, size);
        if boxed && let Some(rect) = Rect::from_xywh(x - 3.0, top, width + 6.0, height) {
            let mut paint = Paint::default();
            paint.set_color(Color::from_rgba8(255, 255, 255, 200));
            pixmap.fill_rect(rect, &paint, Transform::identity(), None);
        }
        let baseline = (top + 0.5 * (height - f32::from(size)) + ascent).round() as i32;
        let (w, h) = (pixmap.width() as i32, pixmap.height() as i32);
        let mut pen = x;
        for c in text.chars() {
            let pen_px = pen.round() as i32;
            let g = self.glyph(c, size);
            let data = pixmap.data_mut();
            for (row, line) in g.coverage.chunks(g.width.max(1)).enumerate() {
                let py = baseline + g.top + row as i32;
                if !(0..h).contains(&py) {
                    continue;
                }
                for (col, &cov) in line.iter().enumerate() {
                    let px = pen_px + g.left + col as i32;
                    if cov == 0 || !(0..w).contains(&px) {
                        continue;
                    }
                    let i = 4 * (py * w + px) as usize;
                    let a = u16::from(cov);
                    for k in 0..3 {
                        let dst = u16::from(data[i + k]);
                        let src = u16::from(rgb[k]);
                        data[i + k] = ((src * a + dst * (255 - a) + 127) / 255) as u8;
                    }
                }
            }
            pen += g.advance_px;
        }
        x + width
    }
}
