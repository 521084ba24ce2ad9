//! Colours and line styles shared by the figures.

use plotters::style::RGBColor;

/// An sRGB colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Rgb(pub u8, pub u8, pub u8);

impl Rgb {
    /// Black.
    pub const BLACK: Self = Self(0, 0, 0);
    /// The failure-marker red.
    pub const RED: Self = Self(200, 0, 0);
    /// The shading grey of time intervals.
    pub const LIGHT_GREY: Self = Self(225, 225, 225);

    pub(crate) fn to_plotters(self) -> RGBColor {
        RGBColor(self.0, self.1, self.2)
    }
}

/// The colour cycle given to series without an explicit colour: ten distinct colours that
/// stay distinguishable in print (the "tab10" palette of matplotlib).
pub const PALETTE: [Rgb; 10] = [
    Rgb(31, 119, 180),
    Rgb(255, 127, 14),
    Rgb(44, 160, 44),
    Rgb(214, 39, 40),
    Rgb(148, 103, 189),
    Rgb(140, 86, 75),
    Rgb(227, 119, 194),
    Rgb(127, 127, 127),
    Rgb(188, 189, 34),
    Rgb(23, 190, 207),
];

/// How a series' line is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LineStyle {
    /// A continuous line (measured or simulated values).
    #[default]
    Solid,
    /// A dashed line (commands and references).
    Dashed,
    /// Markers at the data points, no line.
    Points,
}

/// Where a legend box sits inside its plotting area.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LegendPosition {
    /// Top right corner.
    #[default]
    UpperRight,
    /// Top left corner.
    UpperLeft,
    /// Bottom right corner.
    LowerRight,
    /// Bottom left corner.
    LowerLeft,
}

impl LegendPosition {
    pub(crate) fn to_plotters(self) -> plotters::chart::SeriesLabelPosition {
        use plotters::chart::SeriesLabelPosition as P;
        match self {
            Self::UpperRight => P::UpperRight,
            Self::UpperLeft => P::UpperLeft,
            Self::LowerRight => P::LowerRight,
            Self::LowerLeft => P::LowerLeft,
        }
    }
}
