//! Figures: a PIPTB-like time-series figure and a capability map from deterministic synthetic
//! data, written as SVG and PNG and checked (files exist, are not trivial, SVG is XML with the
//! labels, PNG decodes to the stated size).

use std::path::{Path, PathBuf};

use ballbot_sim::report::plot::{
    LegendPosition, LineStyle, PlotError, PolarFigure, PolarSeries, Rgb, Series, Subplot,
    TimeSeriesFigure,
};

/// Where figures go: `BALLBOT_PLOT_DIR` if set (to look at them), else a temporary folder.
fn output_dir() -> (Option<tempfile::TempDir>, PathBuf) {
    match std::env::var_os("BALLBOT_PLOT_DIR") {
        Some(dir) => {
            std::fs::create_dir_all(&dir).unwrap();
            (None, PathBuf::from(dir))
        }
        None => {
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().to_owned();
            (Some(dir), path)
        }
    }
}

/// Time (s), tilt (rad), ball rate (rad/s), its command (rad/s), torque (N m).
type Run = (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>);

/// A synthetic PIPTB run: accelerate 0 -> 1 m/s in 2 s, hold 2 s, brake in 1.4 s, sampled at
/// 400 Hz, with a controller-dependent lag, overshoot and torque ripple (deterministic).
fn synthetic_run(lag_secs: f64, ripple_nm: f64) -> Run {
    let radius_m = 0.1;
    let times: Vec<f64> = (0..=2400).map(|i| f64::from(i) / 400.0).collect();
    let command = |t: f64| -> f64 {
        if t < 2.0 {
            t / 2.0
        } else if t < 4.0 {
            1.0
        } else if t < 5.4 {
            let s = (t - 4.0) / 1.4;
            1.0 - s * s * (3.0 - 2.0 * s)
        } else {
            0.0
        }
    };
    let speed_command: Vec<f64> = times.iter().map(|t| command(*t) / radius_m).collect();
    let ball_rate: Vec<f64> = times
        .iter()
        .map(|t| command(t - lag_secs) / radius_m * (1.0 + 0.03 * (-(t - 4.0).powi(2) * 8.0).exp()))
        .collect();
    let tilt: Vec<f64> = times
        .iter()
        .map(|t| {
            let accel = (command(t + 0.01) - command(t - 0.01)) / 0.02;
            -0.06 * accel + 0.002 * (25.0 * t).sin() * lag_secs * 20.0
        })
        .collect();
    let torque: Vec<f64> = times
        .iter()
        .map(|t| {
            let accel = (command(t + 0.01) - command(t - 0.01)) / 0.02;
            4.0 * accel + ripple_nm * (2.0 * std::f64::consts::PI * 7.0 * t).sin()
        })
        .collect();
    (times, tilt, ball_rate, speed_command, torque)
}

fn piptb_figure() -> TimeSeriesFigure {
    let mut tilt = Subplot::new("tilt θ (rad)");
    let mut rate = Subplot::new("ball rate dφ/dt (rad/s)");
    let mut torque = Subplot::new("torque τ (N·m)");
    for (index, (name, lag_secs, ripple_nm)) in [
        ("LQR", 0.08, 0.15),
        ("PI-PD", 0.05, 0.3),
        ("LQR-PI", 0.03, 0.05),
    ]
    .into_iter()
    .enumerate()
    {
        let (times, theta, phi_dot, command, tau) = synthetic_run(lag_secs, ripple_nm);
        tilt = tilt.with(Series::new(name, &times, &theta));
        rate = rate.with(Series::new(name, &times, &phi_dot));
        if index == 2 {
            rate = rate.with(
                Series::new("command", &times, &command)
                    .with_style(LineStyle::Dashed)
                    .with_color(Rgb::BLACK),
            );
        }
        torque = torque.with(Series::new(name, &times, &tau));
    }
    TimeSeriesFigure::new("PIPTB: acceleration, cruise and optimal braking (synthetic data)")
        .with(tilt.with_legend(LegendPosition::UpperLeft))
        .with(rate)
        .with(torque)
        .shade(4.0, 5.4, "braking")
        .marker(5.1, "failure")
}

fn capability_map() -> PolarFigure {
    let heading_deg: Vec<f64> = (0..24).map(|i| f64::from(i) * 15.0).collect();
    let speed = |mu: f64| -> Vec<f64> {
        heading_deg
            .iter()
            .map(|h| {
                mu * (2.4
                    - 1.6 * (3.0 * h.to_radians()).cos().max(0.0)
                    - 0.4 * h.to_radians().cos())
            })
            .collect()
    };
    let mut figure = PolarFigure::new(
        "Capability map: maximum speed per heading",
        "max speed (m/s)",
    )
    .with(PolarSeries::new(
        "simulated, μ = 0.8",
        &heading_deg,
        &speed(0.8),
    ))
    .with(
        PolarSeries::new("simulated, μ = 0.6", &heading_deg, &speed(0.6))
            .with_style(LineStyle::Dashed),
    )
    .with(
        PolarSeries::new("paper", &[0.0, 180.0], &[0.6, 2.3])
            .with_style(LineStyle::Points)
            .with_color(Rgb::BLACK),
    );
    figure.angle_label = "heading h_z".to_owned();
    figure
}

fn check_svg(path: &Path, expected_text: &[&str]) {
    let text = std::fs::read_to_string(path).unwrap();
    assert!(
        text.len() > 10_000,
        "{} is only {} bytes",
        path.display(),
        text.len()
    );
    let document = roxmltree::Document::parse(&text).unwrap();
    assert_eq!(document.root_element().tag_name().name(), "svg");
    let texts: Vec<&str> = document
        .descendants()
        .filter(|n| n.has_tag_name("text"))
        .filter_map(|n| n.text())
        .collect();
    for expected in expected_text {
        assert!(
            texts.iter().any(|t| t.contains(expected)),
            "{} has no text {expected:?}",
            path.display()
        );
    }
    let lines = document
        .descendants()
        .filter(|n| n.has_tag_name("polyline") || n.has_tag_name("path"))
        .count();
    assert!(lines > 10, "{} has only {lines} lines", path.display());
}

/// Decodes the PNG's header (size) and checks it is not a blank canvas: many distinct bytes.
fn check_png(path: &Path, size_px: (u32, u32)) {
    let bytes = std::fs::read(path).unwrap();
    assert!(
        bytes.len() > 20_000,
        "{} is only {} bytes",
        path.display(),
        bytes.len()
    );
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    assert_eq!(&bytes[12..16], b"IHDR");
    let width = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
    let height = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
    assert_eq!((width, height), size_px);
}

#[test]
fn time_series_figure_is_written_as_svg_and_png() {
    let (_keep, dir) = output_dir();
    let figure = piptb_figure();
    let [svg, png] = figure
        .save_svg_and_png(&dir.join("piptb_synthetic"))
        .unwrap();
    check_svg(
        &svg,
        &[
            "tilt θ (rad)",
            "ball rate dφ/dt (rad/s)",
            "torque τ (N·m)",
            "time (s)",
            "LQR-PI",
            "PI-PD",
            "command",
            "braking",
            "failure",
        ],
    );
    check_png(&png, figure.size_px());
    // Deterministic: the same figure gives the same SVG.
    assert_eq!(
        figure.to_svg_string().unwrap(),
        std::fs::read_to_string(&svg).unwrap()
    );
}

#[test]
fn polar_capability_map_is_written_as_svg_and_png() {
    let (_keep, dir) = output_dir();
    let figure = capability_map();
    let [svg, png] = figure
        .save_svg_and_png(&dir.join("capability_map_synthetic"))
        .unwrap();
    check_svg(
        &svg,
        &[
            "max speed (m/s)",
            "paper",
            "simulated, μ = 0.6",
            "180°",
            "90°",
        ],
    );
    let (width, height) = (figure.size_px, figure.size_px + 40 + 36);
    check_png(&png, (width, height));
}

#[test]
fn malformed_figures_are_rejected_with_the_path() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.png");
    let uneven = TimeSeriesFigure::new("x").with(Subplot::new("y (m)").with(Series::new(
        "a",
        &[0.0, 1.0],
        &[1.0],
    )));
    let error = uneven.save(&path).unwrap_err();
    assert!(matches!(error, PlotError::InvalidFigure { .. }), "{error}");
    assert!(error.to_string().contains("bad.png"));
    assert!(!path.exists());
    let empty = TimeSeriesFigure::new("x");
    assert!(matches!(
        empty.save(&path),
        Err(PlotError::InvalidFigure { .. })
    ));
    let good = piptb_figure();
    let error = good.save(&dir.path().join("figure.pdf")).unwrap_err();
    assert!(
        matches!(error, PlotError::UnsupportedFormat { .. }),
        "{error}"
    );
    let error = good
        .save(&dir.path().join("missing/dir/figure.png"))
        .unwrap_err();
    assert!(matches!(error, PlotError::Draw { .. }), "{error}");
    let negative = PolarFigure::new("", "r (m)").with(PolarSeries::new("a", &[0.0], &[-1.0]));
    assert!(matches!(
        negative.to_svg_string(),
        Err(PlotError::InvalidFigure { .. })
    ));
}

#[test]
fn long_traces_are_thinned_for_drawing_without_losing_peaks() {
    // 10 s at 8 kHz with a single-sample spike: the SVG stays small (the thinning keeps every
    // column's extremes; see the unit test of `decimate`).
    let time_secs: Vec<f64> = (0..80_000).map(|i| f64::from(i) / 8000.0).collect();
    let values: Vec<f64> = time_secs
        .iter()
        .enumerate()
        .map(|(i, t)| (5.0 * t).sin() + if i == 40_037 { 3.0 } else { 0.0 })
        .collect();
    let figure = TimeSeriesFigure::new("")
        .with(Subplot::new("torque τ (N·m)").with(Series::new("plant", &time_secs, &values)));
    let svg = figure.to_svg_string().unwrap();
    assert!(svg.len() < 300_000, "{} bytes", svg.len());
    let document = roxmltree::Document::parse(&svg).unwrap();
    let trace = document
        .descendants()
        .filter(|n| n.has_tag_name("polyline"))
        .filter_map(|n| n.attribute("points"))
        .max_by_key(|p| p.split_whitespace().count())
        .unwrap();
    let xy: Vec<(f64, f64)> = trace
        .split_whitespace()
        .map(|p| {
            let (x, y) = p.split_once(',').unwrap();
            (x.parse().unwrap(), y.parse().unwrap())
        })
        .collect();
    let points = xy.len();
    assert!(points < 4 * 1000 + 8, "{points} points drawn");
    assert!(points > 1000, "{points} points drawn");
    // The peak survives (the name's claim, checked here and not only by `decimate`'s unit
    // test): the topmost drawn point (smallest SVG y) is the spike at t = 5.005 s, the middle
    // of the trace, within 1 % of its width. (The spike sits inside a drawing column, not at
    // its first sample, which any thinning keeps.) Losing the spike would put the top at a sine crest
    // (t = 4.08 or 5.34 s, 3.4 % or more from the middle) and the top 2.87 above the crest
    // would vanish.
    let (x_min, x_max) = xy
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let top = xy.iter().min_by(|a, b| a.1.total_cmp(&b.1)).unwrap();
    let middle = 0.5 * (x_min + x_max);
    assert!(
        (top.0 - middle).abs() < 0.01 * (x_max - x_min),
        "topmost point at x = {} but the spike is at {middle}",
        top.0
    );
}
