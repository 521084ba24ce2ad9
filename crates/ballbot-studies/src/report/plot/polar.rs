//! Polar figures: a value against heading, e.g. the maximum speed per heading ("capability
//! map").

use std::path::{Path, PathBuf};

use plotters::{
    coord::Shift,
    prelude::{
        ChartBuilder, Circle, DashedLineSeries, DrawingArea, DrawingBackend, IntoFont, LineSeries,
        Text, WHITE,
    },
    style::{
        Color, ShapeStyle, TextStyle,
        text_anchor::{HPos, Pos, VPos},
    },
};

use super::{
    PlotError,
    render::{self, DrawResult, Figure},
    style::{LegendPosition, LineStyle, PALETTE, Rgb},
};

/// One curve of a [`PolarFigure`]: radius against heading.
#[derive(Debug, Clone, PartialEq)]
pub struct PolarSeries {
    /// Legend entry, e.g. `simulated (mu = 0.6)` or `paper`.
    pub label: String,
    /// Headings (deg), measured counter-clockwise from the right-hand (east) direction.
    pub heading_deg: Vec<f64>,
    /// Radii in the unit of the radial axis, as many as `heading_deg`. Non-finite values leave
    /// a gap.
    pub radius: Vec<f64>,
    /// Line style; solid and dashed lines also mark the data points.
    pub style: LineStyle,
    /// Whether the line returns from the last point to the first (a full sweep).
    pub closed: bool,
    /// Colour; `None` takes the next colour of [`PALETTE`].
    pub color: Option<Rgb>,
}

impl PolarSeries {
    /// A closed solid curve through the points.
    pub fn new(label: &str, heading_deg: &[f64], radius: &[f64]) -> Self {
        Self {
            label: label.to_owned(),
            heading_deg: heading_deg.to_vec(),
            radius: radius.to_vec(),
            style: LineStyle::Solid,
            closed: true,
            color: None,
        }
    }

    /// The same series with another line style.
    pub fn with_style(mut self, style: LineStyle) -> Self {
        self.style = style;
        self
    }

    /// The same series as an open curve (first and last point not joined).
    pub fn open(mut self) -> Self {
        self.closed = false;
        self
    }

    /// The same series with a fixed colour.
    pub fn with_color(mut self, color: Rgb) -> Self {
        self.color = Some(color);
        self
    }
}

/// A polar plot: radius (e.g. maximum speed) against heading, with rings, spokes and a legend.
///
/// Heading 0 points right and headings grow counter-clockwise, as angles in the robot's x-y
/// plane seen from above.
///
/// ```
/// use ballbot_studies::report::plot::{LineStyle, PolarFigure, PolarSeries};
///
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let heading_deg: Vec<f64> = (0..24).map(|i| f64::from(i) * 15.0).collect();
/// let speed: Vec<f64> = heading_deg
///     .iter()
///     .map(|h| 1.45 - 0.85 * h.to_radians().cos())
///     .collect();
/// let figure = PolarFigure::new("Capability map", "max speed (m/s)")
///     .with(PolarSeries::new("simulated", &heading_deg, &speed))
///     .with(
///         PolarSeries::new("paper", &[0.0, 180.0], &[0.6, 2.3])
///             .with_style(LineStyle::Points),
///     );
/// let svg = figure.to_svg_string()?;
/// assert!(svg.contains("max speed (m/s)"));
/// # Ok(())
/// # }
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct PolarFigure {
    /// Title (empty for none).
    pub title: String,
    /// The radial quantity with its unit, e.g. `max speed (m/s)`.
    pub radial_label: String,
    /// The angular quantity, e.g. `heading h_z`.
    pub angle_label: String,
    /// The curves.
    pub series: Vec<PolarSeries>,
    /// Outer ring radius; `None` fits the data.
    pub radial_max: Option<f64>,
    /// Spacing of the heading spokes (deg). Default 30.
    pub spoke_step_deg: f64,
    /// Width (and height of the polar area) in pixels. Default 760.
    pub size_px: u32,
    /// Where the legend sits. Default upper right.
    pub legend: LegendPosition,
}

impl PolarFigure {
    /// An empty polar figure with a title and the radial quantity's label (with its unit).
    pub fn new(title: &str, radial_label: &str) -> Self {
        Self {
            title: title.to_owned(),
            radial_label: radial_label.to_owned(),
            angle_label: "heading".to_owned(),
            series: Vec::new(),
            radial_max: None,
            spoke_step_deg: 30.0,
            size_px: 760,
            legend: LegendPosition::UpperRight,
        }
    }

    /// Adds a curve.
    pub fn with(mut self, series: PolarSeries) -> Self {
        self.series.push(series);
        self
    }

    /// Writes the figure as SVG or PNG, chosen by the file extension.
    pub fn save(&self, path: &Path) -> Result<(), PlotError> {
        render::save(self, path)
    }

    /// Writes `<base>.svg` and `<base>.png` and returns their paths.
    pub fn save_svg_and_png(&self, base: &Path) -> Result<[PathBuf; 2], PlotError> {
        render::save_svg_and_png(self, base)
    }

    /// The figure as an SVG document.
    pub fn to_svg_string(&self) -> Result<String, PlotError> {
        render::svg_string(self)
    }

    fn title_px(&self) -> u32 {
        if self.title.is_empty() { 0 } else { 40 }
    }

    /// The outer ring radius and the ring spacing.
    fn rings(&self) -> (f64, f64) {
        let data_max = self
            .series
            .iter()
            .flat_map(|s| s.radius.iter().copied())
            .filter(|r| r.is_finite())
            .fold(0.0_f64, f64::max);
        let wanted = self.radial_max.unwrap_or(data_max);
        let wanted = if wanted > 0.0 { wanted } else { 1.0 };
        let step = nice_step(wanted / 4.0);
        ((wanted / step).ceil() * step, step)
    }
}

/// The smallest of 1, 2, 2.5, 5 times a power of ten that is at least `raw`.
fn nice_step(raw: f64) -> f64 {
    let power = 10_f64.powf(raw.log10().floor());
    [1.0, 2.0, 2.5, 5.0, 10.0]
        .into_iter()
        .map(|m| m * power)
        .find(|step| *step >= raw * (1.0 - 1e-12))
        .unwrap_or(10.0 * power)
}

fn polar_point(heading_deg: f64, radius: f64) -> (f64, f64) {
    let angle = heading_deg.to_radians();
    (radius * angle.cos(), radius * angle.sin())
}

impl Figure for PolarFigure {
    fn size(&self) -> (u32, u32) {
        (self.size_px, self.size_px + self.title_px() + 36)
    }

    fn validate(&self, path: &Path) -> Result<(), PlotError> {
        let invalid = |reason: String| PlotError::InvalidFigure {
            path: path.to_owned(),
            reason,
        };
        if self.series.is_empty() {
            return Err(invalid("the polar figure has no series".to_owned()));
        }
        for series in &self.series {
            if series.heading_deg.len() != series.radius.len() {
                return Err(invalid(format!(
                    "series `{}` has {} headings but {} radii",
                    series.label,
                    series.heading_deg.len(),
                    series.radius.len()
                )));
            }
            if series.radius.iter().any(|r| *r < 0.0) {
                return Err(invalid(format!(
                    "series `{}` has a negative radius",
                    series.label
                )));
            }
        }
        if let Some(max) = self.radial_max
            && !(max.is_finite() && max > 0.0)
        {
            return Err(invalid("radial_max must be finite and > 0".to_owned()));
        }
        if !(self.spoke_step_deg.is_finite() && self.spoke_step_deg >= 5.0) {
            return Err(invalid("spoke_step_deg must be at least 5".to_owned()));
        }
        if self.size_px < 300 {
            return Err(invalid(
                "the polar figure must be at least 300 px wide".to_owned(),
            ));
        }
        Ok(())
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        root.fill(&WHITE)?;
        let area = if self.title.is_empty() {
            root.clone()
        } else {
            root.titled(&self.title, ("sans-serif", 24).into_font())?
        };
        let (plot_area, caption_area) = area.split_vertically(self.size_px);
        let (outer, step) = self.rings();
        let extent = outer * 1.22;
        let mut chart = ChartBuilder::on(&plot_area)
            .margin(10)
            .build_cartesian_2d(-extent..extent, -extent..extent)?;

        let grid = Rgb(215, 215, 215).to_plotters();
        let ring_count = (outer / step).round() as usize;
        for ring in 1..=ring_count {
            let radius = step * ring as f64;
            let circle = (0..=360).map(|d| polar_point(f64::from(d), radius));
            let style = if ring == ring_count {
                Rgb(120, 120, 120).to_plotters().stroke_width(1)
            } else {
                grid.stroke_width(1)
            };
            chart.draw_series(LineSeries::new(circle, style))?;
        }
        let spokes = (360.0 / self.spoke_step_deg).floor() as usize;
        let label_style = TextStyle::from(("sans-serif", 15).into_font())
            .pos(Pos::new(HPos::Center, VPos::Center));
        for spoke in 0..spokes {
            let heading_deg = self.spoke_step_deg * spoke as f64;
            chart.draw_series(LineSeries::new(
                [(0.0, 0.0), polar_point(heading_deg, outer)],
                grid.stroke_width(1),
            ))?;
            chart.draw_series(std::iter::once(Text::new(
                format!("{}°", render::tick_label(heading_deg)),
                polar_point(heading_deg, outer * 1.1),
                label_style.clone(),
            )))?;
        }
        // Ring values along a ray between two spokes.
        let ring_label_deg = 0.5 * self.spoke_step_deg;
        let ring_color = Rgb(90, 90, 90).to_plotters();
        let ring_style = TextStyle::from(("sans-serif", 13).into_font())
            .color(&ring_color)
            .pos(Pos::new(HPos::Left, VPos::Bottom));
        for ring in 1..=ring_count {
            let radius = step * ring as f64;
            chart.draw_series(std::iter::once(Text::new(
                render::tick_label(radius),
                polar_point(ring_label_deg, radius),
                ring_style.clone(),
            )))?;
        }

        for (index, series) in self.series.iter().enumerate() {
            let color = series
                .color
                .unwrap_or(PALETTE[index % PALETTE.len()])
                .to_plotters();
            let style: ShapeStyle = color.stroke_width(2);
            let points: Vec<(f64, f64)> = series
                .heading_deg
                .iter()
                .zip(&series.radius)
                .map(|(h, r)| {
                    if h.is_finite() && r.is_finite() {
                        polar_point(*h, *r)
                    } else {
                        (f64::NAN, f64::NAN)
                    }
                })
                .collect();
            let (mut xs, mut ys): (Vec<f64>, Vec<f64>) = points.iter().copied().unzip();
            if series.closed && points.first().is_some_and(|p| p.0.is_finite()) {
                xs.push(points[0].0);
                ys.push(points[0].1);
            }
            let mut labelled = false;
            for segment in render::finite_segments(&xs, &ys) {
                let drawn = match series.style {
                    LineStyle::Solid => {
                        chart.draw_series(LineSeries::new(segment.iter().copied(), style))?
                    }
                    LineStyle::Dashed => chart.draw_series(DashedLineSeries::new(
                        segment.iter().copied(),
                        10,
                        6,
                        style,
                    ))?,
                    LineStyle::Points => chart
                        .draw_series(segment.iter().map(|p| Circle::new(*p, 6, color.filled())))?,
                };
                if !labelled {
                    labelled = true;
                    render::add_legend(drawn, &series.label, series.style, style);
                }
                if series.style != LineStyle::Points {
                    chart
                        .draw_series(segment.iter().map(|p| Circle::new(*p, 3, color.filled())))?;
                }
            }
        }
        chart
            .configure_series_labels()
            .position(self.legend.to_plotters())
            .label_font(("sans-serif", 15))
            .background_style(WHITE.mix(0.9))
            .border_style(Rgb(160, 160, 160).to_plotters())
            .draw()?;
        let (width, _) = caption_area.dim_in_pixel();
        caption_area.draw_text(
            &format!(
                "radius: {}    angle: {} (deg, counter-clockwise from the right)",
                self.radial_label, self.angle_label
            ),
            &TextStyle::from(("sans-serif", 16).into_font()).pos(Pos::new(HPos::Center, VPos::Top)),
            (i32::try_from(width / 2).unwrap_or(0), 4),
        )?;
        Ok(())
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn nice_steps_are_round() {
        assert_eq!(nice_step(0.6), 1.0);
        assert_eq!(nice_step(0.575), 1.0);
        assert_eq!(nice_step(0.45), 0.5);
        assert_eq!(nice_step(0.2), 0.2);
        assert_eq!(nice_step(2.2), 2.5);
        assert_eq!(nice_step(30.0), 50.0);
    }

    #[test]
    fn rings_cover_the_data() {
        let figure = PolarFigure::new("", "speed (m/s)").with(PolarSeries::new(
            "a",
            &[0.0, 180.0],
            &[0.6, 2.3],
        ));
        let (outer, step) = figure.rings();
        assert!(outer >= 2.3 && outer < 2.3 + step);
        assert!(polar_point(90.0, 2.0).0.abs() < 1e-12);
    }
}
