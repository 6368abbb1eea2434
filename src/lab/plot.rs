//! SVG plots with plotters (SVG backend, no font feature: text is written as SVG text and
//! needs no system fonts). One helper draws lines, points and error bars on linear axes.

use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// How a series is drawn.
#[derive(Clone, Debug)]
pub enum Style {
    /// A polyline.
    Line,
    /// Markers.
    Points,
    /// Markers with vertical error bars (`errors` gives ± per point).
    ErrorBars(Vec<f64>),
}

/// One series.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// The data.
    pub points: Vec<(f64, f64)>,
    /// Drawing style.
    pub style: Style,
}

impl Series {
    /// A line.
    pub fn line(label: &str, points: Vec<(f64, f64)>) -> Series {
        Series { label: label.into(), points, style: Style::Line }
    }
    /// Markers.
    pub fn points(label: &str, points: Vec<(f64, f64)>) -> Series {
        Series { label: label.into(), points, style: Style::Points }
    }
    /// Markers with error bars.
    pub fn errors(label: &str, points: Vec<(f64, f64)>, errors: Vec<f64>) -> Series {
        Series { label: label.into(), points, style: Style::ErrorBars(errors) }
    }
}

/// A chart: title, axis labels (with units), series.
#[derive(Clone, Debug)]
pub struct Chart {
    /// Title.
    pub title: String,
    /// x-axis label, with units.
    pub x_label: String,
    /// y-axis label, with units.
    pub y_label: String,
    /// The data.
    pub series: Vec<Series>,
    /// Legend in the upper left corner (default: upper right).
    pub legend_left: bool,
}

const COLOURS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) =
        values.filter(|v| v.is_finite()).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let pad = if hi > lo { 0.05 * (hi - lo) } else { 0.5 * lo.abs().max(1.0) };
    (lo - pad, hi + pad)
}

/// A chart that could not be drawn: the file, and what plotters said.
#[derive(Clone, Debug, PartialEq)]
pub struct PlotError {
    /// The SVG file.
    pub path: PathBuf,
    /// What went wrong.
    pub reason: String,
}

impl std::fmt::Display for PlotError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.path.display(), self.reason)
    }
}

impl std::error::Error for PlotError {}

/// Draws `chart` into an SVG file at `path`.
pub fn draw(chart: &Chart, path: &Path) -> Result<(), PlotError> {
    let err = |e: &dyn std::fmt::Display| PlotError { path: path.to_path_buf(), reason: e.to_string() };
    let (x0, x1) = range(chart.series.iter().flat_map(|s| s.points.iter().map(|p| p.0)));
    let (y0, y1) = range(chart.series.iter().flat_map(|s| {
        let bars: Vec<f64> = match &s.style {
            Style::ErrorBars(e) => s.points.iter().zip(e).flat_map(|(p, e)| [p.1 - e, p.1 + e]).collect(),
            _ => s.points.iter().map(|p| p.1).collect(),
        };
        bars.into_iter()
    }));
    let root = SVGBackend::new(path, (800, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut plot = ChartBuilder::on(&root)
        .caption(&chart.title, ("sans-serif", 22))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(64)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|e| err(&e))?;
    plot.configure_mesh()
        .x_desc(chart.x_label.as_str())
        .y_desc(chart.y_label.as_str())
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(|e| err(&e))?;
    for (k, s) in chart.series.iter().enumerate() {
        let colour = COLOURS[k % COLOURS.len()];
        let style = ShapeStyle::from(&colour).stroke_width(2);
        let drawn = match &s.style {
            Style::Line => plot.draw_series(LineSeries::new(s.points.iter().copied(), style)),
            Style::Points => plot.draw_series(s.points.iter().map(|&p| Circle::new(p, 4, style.filled()))),
            Style::ErrorBars(errors) => plot.draw_series(
                s.points
                    .iter()
                    .zip(errors)
                    .map(|(&(x, y), &e)| ErrorBar::new_vertical(x, y - e, y, y + e, style.filled(), 8)),
            ),
        }
        .map_err(|e| err(&e))?;
        drawn.label(s.label.as_str()).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
    }
    plot.configure_series_labels()
        .position(if chart.legend_left { SeriesLabelPosition::UpperLeft } else { SeriesLabelPosition::UpperRight })
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))?;
    Ok(())
}
