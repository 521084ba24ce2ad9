//! Output plumbing shared by the figures: backends by file extension, ranges, ticks, legends.

use std::path::Path;

use plotters::{
    chart::SeriesAnno,
    coord::Shift,
    prelude::{
        BitMapBackend, Circle, DrawingArea, DrawingAreaErrorKind, DrawingBackend, EmptyElement,
        IntoDrawingArea, PathElement, SVGBackend,
    },
    style::ShapeStyle,
};

use super::{PlotError, font, style::LineStyle};

/// The result of drawing on a backend.
pub(crate) type DrawResult<DB> =
    Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

/// A figure that can be drawn on any plotters backend.
pub(crate) trait Figure {
    /// Image size (px).
    fn size(&self) -> (u32, u32);
    /// Checks the figure before drawing; `path` names the output in errors.
    fn validate(&self, path: &Path) -> Result<(), PlotError>;
    /// Draws the whole figure.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB>;
}

fn backend_error(path: &Path, message: impl ToString) -> PlotError {
    PlotError::Draw {
        path: path.to_owned(),
        message: message.to_string(),
    }
}

fn prepare(figure: &impl Figure, path: &Path) -> Result<(), PlotError> {
    figure.validate(path)?;
    if font::ensure_registered() {
        Ok(())
    } else {
        Err(backend_error(path, "the embedded font could not be loaded"))
    }
}

/// Writes a figure to `path` as SVG or PNG, by extension.
pub(crate) fn save(figure: &impl Figure, path: &Path) -> Result<(), PlotError> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    prepare(figure, path)?;
    let error = |e: DrawingAreaErrorKind<_>| backend_error(path, e);
    match extension.as_deref() {
        Some("svg") => {
            let root = SVGBackend::new(path, figure.size()).into_drawing_area();
            figure.draw(&root).map_err(|e| backend_error(path, e))?;
            root.present().map_err(|e| backend_error(path, e))
        }
        Some("png") => {
            let root = BitMapBackend::new(path, figure.size()).into_drawing_area();
            figure.draw(&root).map_err(error)?;
            root.present().map_err(|e| backend_error(path, e))
        }
        _ => Err(PlotError::UnsupportedFormat {
            path: path.to_owned(),
        }),
    }
}

/// Writes `<base>.svg` and `<base>.png` and returns their paths.
pub(crate) fn save_svg_and_png(
    figure: &impl Figure,
    base: &Path,
) -> Result<[std::path::PathBuf; 2], PlotError> {
    let svg = base.with_extension("svg");
    let png = base.with_extension("png");
    save(figure, &svg)?;
    save(figure, &png)?;
    Ok([svg, png])
}

/// Draws a figure into an SVG document in memory.
pub(crate) fn svg_string(figure: &impl Figure) -> Result<String, PlotError> {
    let path = Path::new("<svg string>");
    prepare(figure, path)?;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, figure.size()).into_drawing_area();
        figure.draw(&root).map_err(|e| backend_error(path, e))?;
        root.present().map_err(|e| backend_error(path, e))?;
    }
    Ok(svg)
}

/// The range of the finite values, widened by `margin` of its span on each side (or to a
/// sensible width if all values are equal). `None` if there is no finite value.
pub(crate) fn padded_range(values: impl Iterator<Item = f64>, margin: f64) -> Option<(f64, f64)> {
    let (min, max) = values.filter(|v| v.is_finite()).fold(
        None,
        |range: Option<(f64, f64)>, v| match range {
            None => Some((v, v)),
            Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
        },
    )?;
    let span = max - min;
    if span <= 1e-12 * max.abs().max(1.0) {
        let pad = (0.1 * max.abs()).max(0.1);
        Some((min - pad, max + pad))
    } else {
        Some((min - margin * span, max + margin * span))
    }
}

/// A tick label: at most three decimals without trailing zeros, scientific for very large or
/// very small magnitudes.
pub(crate) fn tick_label(value: f64) -> String {
    let magnitude = value.abs();
    if magnitude >= 1e5 || (magnitude > 0.0 && magnitude < 1e-3) {
        return format!("{value:.1e}");
    }
    let text = format!("{value:.3}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" {
        "0".to_owned()
    } else {
        text.to_owned()
    }
}

/// Splits a series into runs of consecutive points whose coordinates are both finite.
pub(crate) fn finite_segments(xs: &[f64], ys: &[f64]) -> Vec<Vec<(f64, f64)>> {
    let mut segments = Vec::new();
    let mut current = Vec::new();
    for (&x, &y) in xs.iter().zip(ys) {
        if x.is_finite() && y.is_finite() {
            current.push((x, y));
        } else if !current.is_empty() {
            segments.push(std::mem::take(&mut current));
        }
    }
    if !current.is_empty() {
        segments.push(current);
    }
    segments
}

/// Thins a line of points sorted by x for drawing `columns` pixel columns wide over
/// `x_range`: when it has more than four points per column, each column keeps its first,
/// lowest, highest and last point, in x order. The drawn envelope (every peak, every step) is
/// unchanged while an 8 kHz trace shrinks to a few thousand points; shorter lines, and lines
/// that are not sorted by x, are returned whole.
pub(crate) fn decimate(
    points: &[(f64, f64)],
    x_range: (f64, f64),
    columns: u32,
) -> Vec<(f64, f64)> {
    let columns = columns.max(1) as usize;
    let (start, end) = x_range;
    let sorted = points.windows(2).all(|w| w[0].0 <= w[1].0);
    let range_is_valid = end > start;
    if points.len() <= 4 * columns || !sorted || !range_is_valid {
        return points.to_vec();
    }
    let column_of = |x: f64| -> usize {
        let fraction = ((x - start) / (end - start)).clamp(0.0, 1.0);
        // In [0, columns]: fits in usize.
        (fraction * columns as f64) as usize
    };
    let mut kept = Vec::with_capacity(4 * columns + 4);
    let mut index = 0;
    while index < points.len() {
        let column = column_of(points[index].0);
        let mut last = index;
        let (mut low, mut high) = (index, index);
        while last + 1 < points.len() && column_of(points[last + 1].0) == column {
            last += 1;
            if points[last].1 < points[low].1 {
                low = last;
            }
            if points[last].1 > points[high].1 {
                high = last;
            }
        }
        let mut picks = [index, low, high, last];
        picks.sort_unstable();
        let mut previous = None;
        for pick in picks {
            if previous != Some(pick) {
                kept.push(points[pick]);
                previous = Some(pick);
            }
        }
        index = last + 1;
    }
    kept
}

/// Labels a drawn series and gives it a legend sample: a short line, a dashed line, or a dot.
pub(crate) fn add_legend<'a, DB: DrawingBackend + 'a>(
    anno: &mut SeriesAnno<'a, DB>,
    label: &str,
    line: LineStyle,
    style: ShapeStyle,
) {
    let anno = anno.label(label);
    match line {
        LineStyle::Solid => {
            anno.legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
        }
        LineStyle::Dashed => {
            anno.legend(move |(x, y)| {
                EmptyElement::at((x, y))
                    + PathElement::new(vec![(0, 0), (7, 0)], style)
                    + PathElement::new(vec![(13, 0), (20, 0)], style)
            });
        }
        LineStyle::Points => {
            anno.legend(move |(x, y)| Circle::new((x + 10, y), 4, style.filled()));
        }
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn ranges_skip_non_finite_values_and_widen_flat_data() {
        let range = padded_range([1.0, f64::NAN, 3.0].into_iter(), 0.05);
        assert_eq!(range, Some((0.9, 3.1)));
        assert_eq!(
            padded_range([0.0, 0.0].into_iter(), 0.05),
            Some((-0.1, 0.1))
        );
        assert_eq!(padded_range([f64::NAN].into_iter(), 0.05), None);
    }

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(tick_label(0.30000000000000004), "0.3");
        assert_eq!(tick_label(2.0), "2");
        assert_eq!(tick_label(-0.0), "0");
        assert_eq!(tick_label(-1.25), "-1.25");
        assert_eq!(tick_label(8.2e5), "8.2e5");
    }

    #[test]
    fn decimation_keeps_the_envelope_and_bounds_the_point_count() {
        let points: Vec<(f64, f64)> = (0..80_000)
            .map(|i| {
                let t = f64::from(i) / 8000.0;
                (t, (40.0 * t).sin() + if i == 12_345 { 5.0 } else { 0.0 })
            })
            .collect();
        let kept = decimate(&points, (0.0, 10.0), 1000);
        assert!(kept.len() <= 4 * 1001, "{}", kept.len());
        assert!(kept.windows(2).all(|w| w[0].0 <= w[1].0));
        let max = |p: &[(f64, f64)]| p.iter().map(|q| q.1).fold(f64::MIN, f64::max);
        let min = |p: &[(f64, f64)]| p.iter().map(|q| q.1).fold(f64::MAX, f64::min);
        assert_eq!(max(&kept), max(&points));
        assert_eq!(min(&kept), min(&points));
        assert_eq!(kept.first(), points.first());
        assert_eq!(kept.last(), points.last());
        // Short lines are untouched.
        assert_eq!(
            decimate(&points[..100], (0.0, 10.0), 1000),
            points[..100].to_vec()
        );
    }

    #[test]
    fn segments_break_at_gaps() {
        let xs = [0.0, 1.0, 2.0, 3.0, 4.0];
        let ys = [1.0, f64::NAN, 2.0, 3.0, f64::INFINITY];
        assert_eq!(
            finite_segments(&xs, &ys),
            vec![vec![(0.0, 1.0)], vec![(2.0, 2.0), (3.0, 3.0)]]
        );
    }
}
