//! SVG plots like the method's figures: forced responses of FO vs ROM, error vs basis size,
//! predicted vs actual error (log-log with the 45-degree line), dissipated energy per contact.
//! Drawn with `plotters`' SVG backend, which needs no fonts on the machine.

use jprom::error::{JpError, Result};
use plotters::prelude::*;
use std::path::Path;

/// One series of a plot.
#[derive(Clone, Debug)]
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    /// Draw markers (circles) instead of a line.
    pub markers: bool,
    /// Draw a line with small square markers (overrides `markers`).
    pub line_and_markers: bool,
    /// Palette index; default: the series' position.
    pub color: Option<usize>,
}

impl Series {
    pub fn line(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Series { label: label.into(), points, markers: false, line_and_markers: false, color: None }
    }
    pub fn markers(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Series { label: label.into(), points, markers: true, line_and_markers: false, color: None }
    }
    /// A line through square markers.
    pub fn line_and_markers(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Series { label: label.into(), points, markers: false, line_and_markers: true, color: None }
    }
    /// The same series in palette colour `i`.
    pub fn color(mut self, i: usize) -> Self {
        self.color = Some(i);
        self
    }
}

/// Where the legend goes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Legend {
    #[default]
    UpperRight,
    UpperLeft,
    LowerLeft,
    LowerRight,
    MiddleRight,
}

/// Axes, titles and scales of a plot.
#[derive(Clone, Debug)]
pub struct PlotSpec<'a> {
    pub title: &'a str,
    pub x_label: &'a str,
    pub y_label: &'a str,
    pub log_x: bool,
    pub log_y: bool,
    /// Draw the line `y = x` (for predicted vs actual error).
    pub diagonal: bool,
    /// Legend position.
    pub legend: Legend,
}

const PALETTE: [RGBColor; 6] = [
    RGBColor(0, 0, 0),
    RGBColor(214, 39, 40),
    RGBColor(31, 119, 180),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
];

fn plot_err(path: &Path, e: impl std::fmt::Display) -> JpError {
    JpError::Io { path: path.display().to_string(), reason: format!("plot: {e}") }
}

fn range(vals: impl Iterator<Item = f64>, log: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in vals.filter(|v| v.is_finite() && (!log || *v > 0.0)) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return if log { (1e-3, 1.0) } else { (0.0, 1.0) };
    }
    if log {
        let (l, h) = (lo.log10().floor(), hi.log10().ceil());
        (10f64.powf(l), 10f64.powf(if h > l { h } else { l + 1.0 }))
    } else {
        let pad = if hi > lo { 0.05 * (hi - lo) } else { lo.abs().max(1.0) * 0.05 };
        (lo - pad, hi + pad)
    }
}

/// Tick label: short scientific notation on log axes (`1e-5`, `2e-3`), plain otherwise.
fn tick(v: f64, log: bool) -> String {
    if !log {
        let a = v.abs();
        return if a != 0.0 && (a >= 1e5 || a < 1e-3) { format!("{v:.1e}") } else { format!("{}", (v * 1e6).round() / 1e6) };
    }
    let e = v.log10().round();
    if (v / 10f64.powf(e) - 1.0).abs() < 1e-6 {
        format!("1e{}", e as i32)
    } else {
        format!("{v:.0e}")
    }
}

/// Writes an SVG line/marker plot of `series` to `path`.
///
/// # Errors
/// [`JpError::Io`] if the file cannot be written.
pub fn write_plot(path: &Path, spec: &PlotSpec, series: &[Series]) -> Result<()> {
    // drawn into memory, then written through `io::write_file`, which reports every write
    // error (plotters' own file output drops the error of its last flush)
    let mut svg = String::new();
    draw_plot(&mut svg, path, spec, series)?;
    jprom::io::write_file(path, |w| w.write_all(svg.as_bytes()))
}

fn draw_plot(svg: &mut String, path: &Path, spec: &PlotSpec, series: &[Series]) -> Result<()> {
    let root = SVGBackend::with_string(svg, (760, 520)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| plot_err(path, e))?;
    let all = || series.iter().flat_map(|s| s.points.iter());
    let (mut x0, mut x1) = range(all().map(|p| p.0), spec.log_x);
    let (mut y0, mut y1) = range(all().map(|p| p.1), spec.log_y);
    if spec.diagonal {
        let lo = x0.min(y0);
        let hi = x1.max(y1);
        (x0, x1, y0, y1) = (lo, hi, lo, hi);
    }
    let mut builder = ChartBuilder::on(&root);
    builder.caption(spec.title, ("sans-serif", 18)).margin(12).x_label_area_size(45).y_label_area_size(75);
    macro_rules! draw {
        ($chart:expr) => {{
            let mut chart = $chart.map_err(|e| plot_err(path, e))?;
            chart
                .configure_mesh()
                .x_desc(spec.x_label)
                .y_desc(spec.y_label)
                .x_label_formatter(&|v: &f64| tick(*v, spec.log_x))
                .y_label_formatter(&|v: &f64| tick(*v, spec.log_y))
                .draw()
                .map_err(|e| plot_err(path, e))?;
            if spec.diagonal {
                chart
                    .draw_series(LineSeries::new(vec![(x0, x0), (x1, x1)], BLACK.mix(0.4).stroke_width(1)))
                    .map_err(|e| plot_err(path, e))?
                    .label("predicted = actual")
                    .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], BLACK.mix(0.4)));
            }
            for (i, s) in series.iter().enumerate() {
                let color = PALETTE[s.color.unwrap_or(i) % PALETTE.len()];
                let pts: Vec<(f64, f64)> = s
                    .points
                    .iter()
                    .copied()
                    .filter(|p| p.0.is_finite() && p.1.is_finite() && (!spec.log_x || p.0 > 0.0) && (!spec.log_y || p.1 > 0.0))
                    .collect();
                if s.line_and_markers {
                    chart
                        .draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))
                        .map_err(|e| plot_err(path, e))?
                        .label(s.label.as_str())
                        .legend(move |(x, y)| {
                            EmptyElement::at((x, y))
                                + PathElement::new(vec![(0, 0), (18, 0)], color.stroke_width(2))
                                + Rectangle::new([(6, -3), (12, 3)], color.filled())
                        });
                    chart
                        .draw_series(pts.iter().map(|&p| EmptyElement::at(p) + Rectangle::new([(-3, -3), (3, 3)], color.filled())))
                        .map_err(|e| plot_err(path, e))?;
                } else if s.markers {
                    chart
                        .draw_series(pts.iter().map(|&p| Circle::new(p, 4, color.filled())))
                        .map_err(|e| plot_err(path, e))?
                        .label(s.label.as_str())
                        .legend(move |(x, y)| Circle::new((x + 9, y), 4, color.filled()));
                } else {
                    chart
                        .draw_series(LineSeries::new(pts, color.stroke_width(2)))
                        .map_err(|e| plot_err(path, e))?
                        .label(s.label.as_str())
                        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(2)));
                }
            }
            chart
                .configure_series_labels()
                .position(match spec.legend {
                    Legend::UpperRight => SeriesLabelPosition::UpperRight,
                    Legend::UpperLeft => SeriesLabelPosition::UpperLeft,
                    Legend::LowerLeft => SeriesLabelPosition::LowerLeft,
                    Legend::LowerRight => SeriesLabelPosition::LowerRight,
                    Legend::MiddleRight => SeriesLabelPosition::MiddleRight,
                })
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .draw()
                .map_err(|e| plot_err(path, e))?;
        }};
    }
    match (spec.log_x, spec.log_y) {
        (false, false) => draw!(builder.build_cartesian_2d(x0..x1, y0..y1)),
        (false, true) => draw!(builder.build_cartesian_2d(x0..x1, (y0..y1).log_scale())),
        (true, false) => draw!(builder.build_cartesian_2d((x0..x1).log_scale(), y0..y1)),
        (true, true) => draw!(builder.build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())),
    }
    root.present().map_err(|e| plot_err(path, e))?;
    Ok(())
}
