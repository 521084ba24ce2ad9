//! Figures of the reliability campaign: the fault-injection matrix as a coloured grid, the
//! Monte Carlo runs' largest recovered push against heading.

use super::plot::{GridCell, GridFigure, LineStyle, PolarFigure, PolarSeries, Rgb};
use crate::studies::robustness::{
    ControllerVariant, FaultMatrix, FaultMatrixSettings, MonteCarlo, MonteCarloRun, SafeState,
};

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

/// The Monte Carlo runs against the push heading: the largest recovered push of each bisected
/// run (points), the study's push (dashed ring), and the runs that did not stay up after it
/// (red points on the ring).
pub fn monte_carlo_figure(mc: &MonteCarlo) -> PolarFigure {
    let s = &mc.settings;
    let (mut h, mut r) = (Vec::new(), Vec::new());
    for run in &mc.all_runs {
        if let Some(limit) = run.largest_recovered_ns {
            h.push(run.mismatch.heading_deg);
            r.push(limit);
        }
    }
    let ring: Vec<f64> = (0..=72).map(|k| f64::from(k) * 5.0).collect();
    let failed: Vec<&MonteCarloRun> = mc.all_runs.iter().filter(|r| !r.stayed_up).collect();
    let mut figure = PolarFigure::new(
        &format!(
            "Monte Carlo, `{}`, ±{:.0} % mismatch: pushes stayed up after",
            s.controller.as_str(),
            s.fraction * 100.0
        ),
        "push (N·s)",
    )
    .with(
        PolarSeries::new(
            &format!("largest push stayed up after ({} bisected runs)", h.len()),
            &h,
            &r,
        )
        .with_style(LineStyle::Points)
        .open(),
    )
    .with(
        PolarSeries::new(
            &format!("the study's push, {} N·s", s.impulse_ns),
            &ring,
            &vec![s.impulse_ns; ring.len()],
        )
        .with_style(LineStyle::Dashed)
        .with_color(Rgb(120, 120, 120)),
    );
    if !failed.is_empty() {
        let fh: Vec<f64> = failed.iter().map(|r| r.mismatch.heading_deg).collect();
        figure = figure.with(
            PolarSeries::new(
                &format!(
                    "slip or lift-off at {} N·s ({} runs)",
                    s.impulse_ns,
                    failed.len()
                ),
                &fh,
                &vec![s.impulse_ns; fh.len()],
            )
            .with_style(LineStyle::Points)
            .with_color(Rgb::RED)
            .open(),
        );
    }
    figure
}
