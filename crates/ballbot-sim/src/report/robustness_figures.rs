//! Figures of the reliability campaign: the fault-injection matrix as a coloured grid.

use super::plot::{GridCell, GridFigure, Rgb};
use crate::studies::robustness::{ControllerVariant, FaultMatrix, FaultMatrixSettings, SafeState};

const AS_EXPECTED: Rgb = Rgb(150, 210, 150);
const SAFE_OTHER: Rgb = Rgb(250, 220, 120);
const DRIFTING: Rgb = Rgb(245, 170, 100);
const UNSAFE: Rgb = Rgb(230, 110, 110);
const NOT_EXERCISED: Rgb = Rgb(215, 215, 215);

/// The matrix of `controller`: a row per fault class, a column per condition and heading,
/// coloured by outcome (green: the expected safe state; yellow: another safe state; orange:
/// drifting off the command; red: fell undetected or unsafe; grey: the fault never acted),
/// with the cell's [`mark`](crate::studies::robustness::CellResult::mark) and the time to
/// detect.
pub fn fault_matrix_figure(
    matrix: &FaultMatrix,
    settings: &FaultMatrixSettings,
    controller: ControllerVariant,
) -> GridFigure {
    let columns = settings
        .conditions
        .iter()
        .flat_map(|c| {
            settings
                .headings_deg
                .iter()
                .map(move |h| format!("{}\n{h:.0}°", c.as_str()))
        })
        .collect();
    let rows = settings
        .classes
        .iter()
        .map(|c| format!("{} ({})", c.as_str(), short(c.expected())))
        .collect();
    let mut figure = GridFigure::new(
        &format!(
            "Fault injection, controller `{}` (expected state in brackets)",
            controller.as_str()
        ),
        rows,
        columns,
    );
    for &class in &settings.classes {
        let cells = matrix
            .row(controller, class)
            .into_iter()
            .map(|cell| {
                let color = if !cell.exercised {
                    NOT_EXERCISED
                } else if cell.as_expected {
                    AS_EXPECTED
                } else if cell.observed == SafeState::Drifting {
                    DRIFTING
                } else if cell.observed.is_safe() {
                    SAFE_OTHER
                } else {
                    UNSAFE
                };
                let text = match cell.time_to_detect_ms {
                    Some(ms) if cell.observed.is_safe() => {
                        format!("{} {ms:.0}ms", cell.mark())
                    }
                    _ => cell.mark().to_owned(),
                };
                GridCell { color, text }
            })
            .collect();
        figure = figure.with_row(cells);
    }
    figure
        .with_legend(AS_EXPECTED, "expected safe state")
        .with_legend(SAFE_OTHER, "another safe state")
        .with_legend(DRIFTING, "drifting off the command")
        .with_legend(UNSAFE, "fell / unsafe")
        .with_legend(NOT_EXERCISED, "fault never acted")
}

fn short(state: SafeState) -> &'static str {
    match state {
        SafeState::KeepsBalancing => "keep",
        SafeState::ControlledStop => "stop",
        SafeState::ProtectiveStop => "off",
        SafeState::Drifting => "drift",
        SafeState::Unsafe => "unsafe",
    }
}
