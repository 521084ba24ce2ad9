//! Figures for papers and reports, written as SVG and PNG with plotters (cargo feature
//! `plot`). Plain drawing: it imports nothing else of the crate; the reports build figures.
//!
//! - [`TimeSeriesFigure`]: stacked [`Subplot`]s sharing the time axis, several [`Series`] per
//!   subplot with a legend, shaded time intervals (e.g. the braking phase) and vertical marker
//!   lines (e.g. the failure instant).
//! - [`PolarFigure`]: a value against heading, e.g. the maximum speed per heading.
//! - [`GridFigure`]: a table of coloured cells, e.g. a fault-injection matrix.
//!
//! Text is drawn with an embedded font (DejaVu Sans), so PNGs need no system fonts and look
//! the same on every machine. Figures are plain data: build them, then
//! [`save`](TimeSeriesFigure::save) to a `.svg` or `.png` path, or write both with
//! `save_svg_and_png`. Put units in axis labels: `ball speed (m/s)`, `torque τ (N·m)`.

mod error;
mod font;
mod grid;
mod polar;
mod render;
mod style;
mod timeseries;

pub use error::PlotError;
pub use grid::{GridCell, GridFigure};
pub use polar::{PolarFigure, PolarSeries};
pub use style::{LegendPosition, LineStyle, PALETTE, Rgb};
pub use timeseries::{Series, Subplot, TimeInterval, TimeMarker, TimeSeriesFigure};
