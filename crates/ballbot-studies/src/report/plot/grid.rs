//! [`GridFigure`]: a table of coloured cells with a short text in each, e.g. the outcome of
//! every cell of a fault-injection matrix.

use std::path::{Path, PathBuf};

use plotters::{
    coord::Shift,
    prelude::{DrawingArea, DrawingBackend, Rectangle, Text},
    style::{Color, IntoFont, TextStyle, WHITE},
};

use super::{
    PlotError,
    render::{self, DrawResult, Figure},
    style::Rgb,
};

/// One cell: its fill colour and text.
#[derive(Debug, Clone, PartialEq)]
pub struct GridCell {
    /// Fill colour.
    pub color: Rgb,
    /// Short text drawn in the cell (a few characters).
    pub text: String,
}

/// A grid of coloured cells with row and column labels and a legend of the colours.
///
/// ```
/// use ballbot_studies::report::plot::{GridCell, GridFigure, Rgb};
/// # fn main() -> Result<(), ballbot_studies::report::plot::PlotError> {
/// let ok = GridCell { color: Rgb(150, 210, 150), text: "ok".into() };
/// let bad = GridCell { color: Rgb(230, 120, 120), text: "fell".into() };
/// let figure = GridFigure::new("faults", vec!["imu".into()], vec!["standing".into(), "braking".into()])
///     .with_row(vec![ok, bad])
///     .with_legend(Rgb(150, 210, 150), "as expected");
/// let svg = figure.to_svg_string()?;
/// assert!(svg.contains("standing") && svg.contains("fell"));
/// # Ok(())
/// # }
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct GridFigure {
    /// Title (empty for none).
    pub title: String,
    /// One label per row.
    pub row_labels: Vec<String>,
    /// One label per column.
    pub column_labels: Vec<String>,
    /// The cells, row by row.
    pub rows: Vec<Vec<GridCell>>,
    /// Colour legend: colour and meaning.
    pub legend: Vec<(Rgb, String)>,
    /// Cell size (px).
    pub cell_px: (u32, u32),
}

const ROW_LABEL_PX: u32 = 200;
const COLUMN_LABEL_PX: u32 = 60;
const LEGEND_PX: u32 = 30;

impl GridFigure {
    /// An empty grid with its title and labels; cells come with [`Self::with_row`].
    pub fn new(title: &str, row_labels: Vec<String>, column_labels: Vec<String>) -> Self {
        Self {
            title: title.to_owned(),
            row_labels,
            column_labels,
            rows: Vec::new(),
            legend: Vec::new(),
            cell_px: (74, 26),
        }
    }

    /// Adds the next row of cells.
    pub fn with_row(mut self, cells: Vec<GridCell>) -> Self {
        self.rows.push(cells);
        self
    }

    /// Adds a legend entry.
    pub fn with_legend(mut self, color: Rgb, meaning: &str) -> Self {
        self.legend.push((color, meaning.to_owned()));
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

    fn legend_rows(&self) -> u32 {
        // Three legend entries per line.
        (self.legend.len() as u32).div_ceil(3)
    }
}

impl Figure for GridFigure {
    fn size(&self) -> (u32, u32) {
        let (w, h) = self.cell_px;
        let columns = self.column_labels.len() as u32;
        let rows = self.row_labels.len() as u32;
        (
            (ROW_LABEL_PX + columns * w + 20).max(820),
            self.title_px() + COLUMN_LABEL_PX + rows * h + 20 + self.legend_rows() * LEGEND_PX,
        )
    }

    fn validate(&self, path: &Path) -> Result<(), PlotError> {
        let invalid = |reason: String| PlotError::InvalidFigure {
            path: path.to_owned(),
            reason,
        };
        if self.rows.len() != self.row_labels.len() {
            return Err(invalid(format!(
                "the grid has {} rows but {} row labels",
                self.rows.len(),
                self.row_labels.len()
            )));
        }
        if let Some(row) = self
            .rows
            .iter()
            .find(|r| r.len() != self.column_labels.len())
        {
            return Err(invalid(format!(
                "a row has {} cells but there are {} column labels",
                row.len(),
                self.column_labels.len()
            )));
        }
        if self.rows.is_empty() || self.column_labels.is_empty() {
            return Err(invalid("the grid is empty".to_owned()));
        }
        Ok(())
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        root.fill(&WHITE)?;
        let area = if self.title.is_empty() {
            root.clone()
        } else {
            root.titled(&self.title, ("sans-serif", 22).into_font())?
        };
        let (w, h) = (self.cell_px.0 as i32, self.cell_px.1 as i32);
        let x0 = ROW_LABEL_PX as i32;
        let y0 = COLUMN_LABEL_PX as i32;
        let label = TextStyle::from(("sans-serif", 13).into_font());
        let centred = label.pos(plotters::style::text_anchor::Pos::new(
            plotters::style::text_anchor::HPos::Center,
            plotters::style::text_anchor::VPos::Center,
        ));
        for (j, text) in self.column_labels.iter().enumerate() {
            // Two lines at most: "cruising" over "90°".
            for (k, line) in text.split('\n').take(2).enumerate() {
                let x = x0 + j as i32 * w + w / 2;
                let y = y0 - 36 + 18 * k as i32;
                area.draw(&Text::new(line.to_owned(), (x, y), centred.clone()))?;
            }
        }
        let grid_line = Rgb(255, 255, 255).to_plotters();
        for (i, (row, text)) in self.rows.iter().zip(&self.row_labels).enumerate() {
            let y = y0 + i as i32 * h;
            area.draw(&Text::new(text.clone(), (8, y + h / 2 - 6), label.clone()))?;
            for (j, cell) in row.iter().enumerate() {
                let x = x0 + j as i32 * w;
                area.draw(&Rectangle::new(
                    [(x, y), (x + w, y + h)],
                    cell.color.to_plotters().filled(),
                ))?;
                area.draw(&Rectangle::new(
                    [(x, y), (x + w, y + h)],
                    grid_line.stroke_width(2),
                ))?;
                area.draw(&Text::new(
                    cell.text.clone(),
                    (x + w / 2, y + h / 2),
                    centred.clone(),
                ))?;
            }
        }
        let legend_y = y0 + self.rows.len() as i32 * h + 14;
        for (k, (color, meaning)) in self.legend.iter().enumerate() {
            let x = 8 + (k % 3) as i32 * 260;
            let y = legend_y + (k / 3) as i32 * LEGEND_PX as i32;
            area.draw(&Rectangle::new(
                [(x, y), (x + 18, y + 18)],
                color.to_plotters().filled(),
            ))?;
            area.draw(&Text::new(meaning.clone(), (x + 26, y + 2), label.clone()))?;
        }
        Ok(())
    }
}
