//! Time-series figures: stacked subplots sharing the time axis.

use std::path::{Path, PathBuf};

use plotters::{
    coord::Shift,
    prelude::{
        ChartBuilder, Circle, DashedLineSeries, DrawingArea, DrawingBackend, IntoFont, LineSeries,
        PathElement, Rectangle, WHITE,
    },
    style::{Color, ShapeStyle, TextStyle},
};

use ballbot_log::McapLog;

use super::{
    PlotError,
    render::{self, DrawResult, Figure},
    style::{LegendPosition, LineStyle, PALETTE, Rgb},
};

/// One line of a subplot: values against time.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend entry, e.g. `LQR-PI` or `command`.
    pub label: String,
    /// Sample times (s).
    pub time_secs: Vec<f64>,
    /// Values, as many as `time_secs`. Non-finite values leave a gap in the line.
    pub values: Vec<f64>,
    /// Line style.
    pub style: LineStyle,
    /// Colour; `None` takes the next colour of [`PALETTE`] within the subplot.
    pub color: Option<Rgb>,
}

impl Series {
    /// A solid line.
    pub fn new(label: &str, time_secs: &[f64], values: &[f64]) -> Self {
        Self {
            label: label.to_owned(),
            time_secs: time_secs.to_vec(),
            values: values.to_vec(),
            style: LineStyle::Solid,
            color: None,
        }
    }

    /// A solid line of one numeric field of an MCAP log, named by its Foxglove message path
    /// (see [`McapLog::field`](ballbot_log::McapLog::field)), against log time.
    ///
    /// ```
    /// use ballbot_log::{LoggerOptions, McapLog, McapLogger};
    /// use ballbot_studies::report::plot::{Series, Subplot, TimeSeriesFigure};
    ///
    /// #[derive(serde::Serialize, schemars::JsonSchema)]
    /// struct State {
    ///     tilt_rad: f64,
    /// }
    ///
    /// # fn main() -> Result<(), Box<dyn std::error::Error>> {
    /// let dir = tempfile::tempdir()?;
    /// let path = dir.path().join("run.mcap");
    /// let mut log = McapLogger::create(&path, LoggerOptions::default())?;
    /// let state = log.channel::<State>("/planar/state")?;
    /// for i in 0..400 {
    ///     let time_secs = f64::from(i) / 400.0;
    ///     log.write(&state, time_secs, &State { tilt_rad: 0.01 * time_secs.sin() })?;
    /// }
    /// log.finish()?;
    ///
    /// let log = McapLog::open(&path)?;
    /// let tilt = Series::from_log(&log, "tilt", "/planar/state.tilt_rad")?;
    /// assert_eq!(tilt.values.len(), 400);
    /// TimeSeriesFigure::new("tilt")
    ///     .with(Subplot::new("tilt θ (rad)").with(tilt))
    ///     .save(&dir.path().join("tilt.svg"))?;
    /// # Ok(())
    /// # }
    /// ```
    pub fn from_log(
        log: &McapLog,
        label: &str,
        message_path: &str,
    ) -> Result<Self, ballbot_log::LogError> {
        let (time_secs, values) = log.field(message_path)?;
        Ok(Self {
            label: label.to_owned(),
            time_secs,
            values,
            style: LineStyle::Solid,
            color: None,
        })
    }

    /// The same series with another line style.
    pub fn with_style(mut self, style: LineStyle) -> Self {
        self.style = style;
        self
    }

    /// The same series with a fixed colour.
    pub fn with_color(mut self, color: Rgb) -> Self {
        self.color = Some(color);
        self
    }
}

/// One panel of a [`TimeSeriesFigure`]: several series against the shared time axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Subplot {
    /// Y axis label with its unit, e.g. `tilt θ (rad)`.
    pub y_label: String,
    /// The lines, drawn in order, each with a legend entry.
    pub series: Vec<Series>,
    /// Fixed y range (min, max); `None` fits the data with a 5 % margin.
    pub y_range: Option<(f64, f64)>,
    /// Where the legend sits. Default upper right.
    pub legend: LegendPosition,
}

impl Subplot {
    /// An empty panel with a y axis label (put the unit in it).
    pub fn new(y_label: &str) -> Self {
        Self {
            y_label: y_label.to_owned(),
            series: Vec::new(),
            y_range: None,
            legend: LegendPosition::UpperRight,
        }
    }

    /// Adds a series.
    pub fn with(mut self, series: Series) -> Self {
        self.series.push(series);
        self
    }

    /// Moves the legend (e.g. away from the data).
    pub fn with_legend(mut self, position: LegendPosition) -> Self {
        self.legend = position;
        self
    }

    /// Fixes the y range.
    pub fn with_y_range(mut self, min: f64, max: f64) -> Self {
        self.y_range = Some((min, max));
        self
    }
}

/// A shaded time interval across all subplots (e.g. the braking phase), with a legend entry.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeInterval {
    /// Start (s).
    pub start_secs: f64,
    /// End (s).
    pub end_secs: f64,
    /// Legend entry, e.g. `braking`.
    pub label: String,
}

/// A vertical line across all subplots (e.g. the failure instant), with a legend entry.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeMarker {
    /// Time of the line (s).
    pub time_secs: f64,
    /// Legend entry, e.g. `failure`.
    pub label: String,
}

/// A figure of stacked subplots sharing the time axis, like a paper's experiment figure.
///
/// ```
/// use ballbot_studies::report::plot::{LineStyle, Series, Subplot, TimeSeriesFigure};
///
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// let time_secs: Vec<f64> = (0..=540).map(|i| f64::from(i) * 0.01).collect();
/// let speed: Vec<f64> = time_secs.iter().map(|t| (t / 2.0).min(1.0)).collect();
/// let tilt: Vec<f64> = time_secs.iter().map(|t| 0.02 * (3.0 * t).sin()).collect();
/// let figure = TimeSeriesFigure::new("PIPTB speed profile")
///     .with(Subplot::new("tilt θ (rad)").with(Series::new("LQR-PI", &time_secs, &tilt)))
///     .with(
///         Subplot::new("ball speed (m/s)")
///             .with(Series::new("LQR-PI", &time_secs, &speed))
///             .with(Series::new("command", &time_secs, &speed).with_style(LineStyle::Dashed)),
///     )
///     .shade(4.0, 5.4, "braking")
///     .marker(5.2, "failure");
/// let dir = tempfile::tempdir()?;
/// let written = figure.save_svg_and_png(&dir.path().join("piptb"))?;
/// assert!(written.iter().all(|path| path.exists()));
/// # Ok(())
/// # }
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct TimeSeriesFigure {
    /// Title above the first subplot (empty for none).
    pub title: String,
    /// Label of the shared time axis. Default `time (s)`.
    pub x_label: String,
    /// The panels, top to bottom.
    pub subplots: Vec<Subplot>,
    /// Shaded intervals.
    pub intervals: Vec<TimeInterval>,
    /// Vertical marker lines.
    pub markers: Vec<TimeMarker>,
    /// Fixed time range (start, end) in seconds; `None` spans the data.
    pub time_range_secs: Option<(f64, f64)>,
    /// Image width (px; SVG user units). Default 1000.
    pub width_px: u32,
    /// Height of each subplot (px). Default 260.
    pub subplot_height_px: u32,
}

impl TimeSeriesFigure {
    /// An empty figure with a title.
    pub fn new(title: &str) -> Self {
        Self {
            title: title.to_owned(),
            x_label: "time (s)".to_owned(),
            subplots: Vec::new(),
            intervals: Vec::new(),
            markers: Vec::new(),
            time_range_secs: None,
            width_px: 1000,
            subplot_height_px: 260,
        }
    }

    /// Adds a subplot below the others.
    pub fn with(mut self, subplot: Subplot) -> Self {
        self.subplots.push(subplot);
        self
    }

    /// Shades `[start_secs, end_secs]` in every subplot.
    pub fn shade(mut self, start_secs: f64, end_secs: f64, label: &str) -> Self {
        self.intervals.push(TimeInterval {
            start_secs,
            end_secs,
            label: label.to_owned(),
        });
        self
    }

    /// Draws a vertical line at `time_secs` in every subplot.
    pub fn marker(mut self, time_secs: f64, label: &str) -> Self {
        self.markers.push(TimeMarker {
            time_secs,
            label: label.to_owned(),
        });
        self
    }

    /// Image size in pixels (width, height).
    pub fn size_px(&self) -> (u32, u32) {
        self.pixel_size()
    }

    fn pixel_size(&self) -> (u32, u32) {
        let title_px = if self.title.is_empty() { 0 } else { 40 };
        let rows = u32::try_from(self.subplots.len()).unwrap_or(u32::MAX);
        let height = self.subplot_height_px.saturating_mul(rows);
        (self.width_px, height.saturating_add(title_px + 40))
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

    fn check(&self, path: &Path) -> Result<(), PlotError> {
        let invalid = |reason: String| PlotError::InvalidFigure {
            path: path.to_owned(),
            reason,
        };
        if self.subplots.is_empty() {
            return Err(invalid("the figure has no subplot".to_owned()));
        }
        for subplot in &self.subplots {
            for series in &subplot.series {
                if series.time_secs.len() != series.values.len() {
                    return Err(invalid(format!(
                        "series `{}` of subplot `{}` has {} times but {} values",
                        series.label,
                        subplot.y_label,
                        series.time_secs.len(),
                        series.values.len()
                    )));
                }
            }
            if let Some((min, max)) = subplot.y_range
                && !(min.is_finite() && max.is_finite() && min < max)
            {
                return Err(invalid(format!(
                    "y range of subplot `{}` must be finite with min < max",
                    subplot.y_label
                )));
            }
        }
        if self.time_range().is_none() {
            return Err(invalid(
                "no finite time range: the figure has no finite data".to_owned(),
            ));
        }
        if self.width_px < 200 || self.subplot_height_px < 100 {
            return Err(invalid(
                "the figure must be at least 200 px wide and 100 px per subplot".to_owned(),
            ));
        }
        Ok(())
    }

    fn time_range(&self) -> Option<(f64, f64)> {
        if let Some((start, end)) = self.time_range_secs {
            return (start.is_finite() && end.is_finite() && start < end).then_some((start, end));
        }
        let times = self
            .subplots
            .iter()
            .flat_map(|s| &s.series)
            .flat_map(|s| s.time_secs.iter().copied())
            .chain(
                self.intervals
                    .iter()
                    .flat_map(|i| [i.start_secs, i.end_secs]),
            )
            .chain(self.markers.iter().map(|m| m.time_secs));
        render::padded_range(times, 0.0)
    }

    fn draw_figure<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        root.fill(&WHITE)?;
        let (start_secs, end_secs) = self.time_range().unwrap_or((0.0, 1.0));
        let area = if self.title.is_empty() {
            root.clone()
        } else {
            root.titled(&self.title, ("sans-serif", 24).into_font())?
        };
        let (panels, bottom) = area.split_vertically(area.dim_in_pixel().1.saturating_sub(40));
        let rows = panels.split_evenly((self.subplots.len(), 1));
        let last = self.subplots.len() - 1;
        for (index, (subplot, panel)) in self.subplots.iter().zip(rows.iter()).enumerate() {
            self.draw_subplot(
                subplot,
                panel,
                (start_secs, end_secs),
                index == 0,
                index == last,
            )?;
        }
        // The shared time-axis label, centred under the plotting area.
        let label_style = TextStyle::from(("sans-serif", 18).into_font());
        let (width, _) = bottom.dim_in_pixel();
        let x = i32::try_from(width / 2).unwrap_or(0) + 40;
        bottom.draw_text(
            &self.x_label,
            &label_style.pos(plotters::style::text_anchor::Pos::new(
                plotters::style::text_anchor::HPos::Center,
                plotters::style::text_anchor::VPos::Top,
            )),
            (x, 6),
        )?;
        Ok(())
    }

    fn draw_subplot<DB: DrawingBackend>(
        &self,
        subplot: &Subplot,
        panel: &DrawingArea<DB, Shift>,
        (start_secs, end_secs): (f64, f64),
        first: bool,
        last: bool,
    ) -> DrawResult<DB> {
        let (y_min, y_max) = subplot.y_range.unwrap_or_else(|| {
            let values = subplot.series.iter().flat_map(|s| {
                s.time_secs
                    .iter()
                    .zip(&s.values)
                    .filter(move |(t, _)| **t >= start_secs && **t <= end_secs)
                    .map(|(_, v)| *v)
            });
            render::padded_range(values, 0.05).unwrap_or((-1.0, 1.0))
        });
        let mut chart = ChartBuilder::on(panel)
            .margin_top(if first { 8 } else { 4 })
            .margin_bottom(4)
            .margin_left(8)
            .margin_right(24)
            .x_label_area_size(if last { 28 } else { 8 })
            .y_label_area_size(80)
            .build_cartesian_2d(start_secs..end_secs, y_min..y_max)?;
        let hide = |_: &f64| String::new();
        let show = |v: &f64| render::tick_label(*v);
        let mut mesh = chart.configure_mesh();
        mesh.y_desc(subplot.y_label.as_str())
            .axis_desc_style(("sans-serif", 17))
            .label_style(("sans-serif", 14))
            .max_light_lines(1)
            .light_line_style(Rgb(244, 244, 244).to_plotters())
            .bold_line_style(Rgb(210, 210, 210).to_plotters())
            .y_label_formatter(&show)
            .x_labels(12)
            .y_labels(6);
        if last {
            mesh.x_label_formatter(&show);
        } else {
            mesh.x_label_formatter(&hide);
        }
        mesh.draw()?;

        // Shading under everything, each interval once in the legend of the first subplot.
        for interval in &self.intervals {
            let fill = Rgb::LIGHT_GREY.to_plotters().mix(0.8).filled();
            let drawn = chart.draw_series(std::iter::once(Rectangle::new(
                [(interval.start_secs, y_min), (interval.end_secs, y_max)],
                fill,
            )))?;
            if first {
                drawn
                    .label(interval.label.as_str())
                    .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 20, y + 6)], fill));
            }
        }
        for marker in &self.markers {
            let style = Rgb::RED.to_plotters().stroke_width(2);
            let line = [(marker.time_secs, y_min), (marker.time_secs, y_max)];
            let drawn = chart.draw_series(DashedLineSeries::new(line, 8, 5, style))?;
            if first {
                drawn
                    .label(marker.label.as_str())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
            }
        }
        for (index, series) in subplot.series.iter().enumerate() {
            let color = series
                .color
                .unwrap_or(PALETTE[index % PALETTE.len()])
                .to_plotters();
            let style: ShapeStyle = color.stroke_width(2);
            let mut labelled = false;
            for segment in render::finite_segments(&series.time_secs, &series.values) {
                let segment = render::decimate(&segment, (start_secs, end_secs), self.width_px);
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
                        .draw_series(segment.iter().map(|p| Circle::new(*p, 3, color.filled())))?,
                };
                if !labelled {
                    labelled = true;
                    render::add_legend(drawn, &series.label, series.style, style);
                }
            }
        }
        let has_legend = !subplot.series.is_empty()
            || (first && !(self.intervals.is_empty() && self.markers.is_empty()));
        if !has_legend {
            return Ok(());
        }
        chart
            .configure_series_labels()
            .position(subplot.legend.to_plotters())
            .label_font(("sans-serif", 14))
            .background_style(WHITE.mix(0.85))
            .border_style(Rgb(160, 160, 160).to_plotters())
            .draw()?;
        Ok(())
    }
}

impl Figure for TimeSeriesFigure {
    fn size(&self) -> (u32, u32) {
        self.pixel_size()
    }

    fn validate(&self, path: &Path) -> Result<(), PlotError> {
        self.check(path)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        self.draw_figure(root)
    }
}
