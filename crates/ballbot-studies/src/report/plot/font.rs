//! The font used for text in figures, embedded so PNGs render the same on every machine.
//!
//! plotters' `ab_glyph` text backend draws glyphs from fonts registered in memory, without
//! system fonts or fontconfig. The font is DejaVu Sans 2.37 (from Debian's `fonts-dejavu-core`,
//! Bitstream Vera licence; see `assets/fonts/LICENSE-DejaVu.txt`), which covers Greek letters
//! and the usual mathematical signs used in axis labels (θ, φ, τ, ω, °, ², ·).

use std::sync::OnceLock;

use plotters::style::FontStyle;

static DEJAVU_SANS: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");

/// Registers the embedded font under every family name plotters may ask for, once per
/// process. Returns whether the font is available.
pub(crate) fn ensure_registered() -> bool {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    *REGISTERED.get_or_init(|| {
        ["sans-serif", "serif", "monospace"].iter().all(|family| {
            [
                FontStyle::Normal,
                FontStyle::Bold,
                FontStyle::Italic,
                FontStyle::Oblique,
            ]
            .into_iter()
            .all(|style| plotters::style::register_font(family, style, DEJAVU_SANS).is_ok())
        })
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    #[test]
    fn embedded_font_parses_and_registers() {
        assert!(super::ensure_registered());
    }
}
