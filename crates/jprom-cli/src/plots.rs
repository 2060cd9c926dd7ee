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
    /// A fixed look (a solver's: [`Series::solver`]); overrides the fields above.
    pub style: Option<Style>,
    /// Drawn after the others (the full-order reference goes on top).
    pub on_top: bool,
}

/// How a line is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dash {
    Solid,
    Dashed,
    None,
}

/// A marker's shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Marker {
    None,
    Circle,
    Square,
    Triangle,
}

/// A series' look: colour, line, width and marker.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Style {
    pub color: RGBColor,
    pub dash: Dash,
    pub width: u32,
    pub marker: Marker,
    /// Markers on at most this many points (a sweep has hundreds); 0: on every point.
    pub max_markers: usize,
}

/// The colour of each solver, the same in every plot: FO black, FR red, NLR blue.
pub const FO_COLOR: RGBColor = RGBColor(0, 0, 0);
pub const FR_COLOR: RGBColor = RGBColor(214, 39, 40);
pub const NLR_COLOR: RGBColor = RGBColor(31, 119, 180);

/// The solver a label names (`FO...`, `FR...`, `NLR...`), if any.
pub fn solver_of(label: &str) -> Option<&'static str> {
    ["NLR", "FR", "FO"].into_iter().find(|s| label.starts_with(s))
}

/// A solver's colour ([`FO_COLOR`], [`FR_COLOR`], [`NLR_COLOR`]); grey for anything else.
pub fn solver_color(solver: &str) -> RGBColor {
    match solver_of(solver) {
        Some("FO") => FO_COLOR,
        Some("FR") => FR_COLOR,
        Some("NLR") => NLR_COLOR,
        _ => RGBColor(110, 110, 110),
    }
}

impl Series {
    pub fn line(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Series { label: label.into(), points, markers: false, line_and_markers: false, color: None, style: None, on_top: false }
    }
    pub fn markers(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Series { label: label.into(), points, markers: true, line_and_markers: false, color: None, style: None, on_top: false }
    }
    /// A line through square markers.
    pub fn line_and_markers(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Series { label: label.into(), points, markers: false, line_and_markers: true, color: None, style: None, on_top: false }
    }
    /// A solver's curve in its own look, the same in every plot (`label` starts with `FO`,
    /// `FR` or `NLR`): FO a thin solid black line with circles, drawn on top; FR a wide red
    /// dashed line with squares; NLR a wider blue solid line with triangles, underneath. Where
    /// the three coincide all three stay visible. `line = false`: markers only.
    pub fn solver(label: impl Into<String>, points: Vec<(f64, f64)>, line: bool) -> Self {
        let label = label.into();
        let solver = solver_of(&label);
        let (dash, width, marker) = match solver {
            Some("FO") => (Dash::Solid, 2, Marker::Circle),
            Some("FR") => (Dash::Dashed, 3, Marker::Square),
            Some("NLR") => (Dash::Solid, 6, Marker::Triangle),
            _ => (Dash::Solid, 2, Marker::Circle),
        };
        let color = solver_color(&label);
        let color = if solver == Some("NLR") && line { RGBColor(140, 185, 220) } else { color };
        let style = Style { color, dash: if line { dash } else { Dash::None }, width, marker, max_markers: if line { 12 } else { 0 } };
        Series { label, points, markers: !line, line_and_markers: false, color: None, style: Some(style), on_top: solver == Some("FO") }
    }
    /// A ROM pass' linearised-error checks (`label` starts with the solver's name): circles
    /// in the solver's full colour, no line, drawn on top of the sweeps' curves.
    pub fn checks(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        let label = label.into();
        let style = Style { color: solver_color(&label), dash: Dash::None, width: 2, marker: Marker::Circle, max_markers: 0 };
        Series { label, points, markers: true, line_and_markers: false, color: None, style: Some(style), on_top: true }
    }
    /// The same series in a fixed look.
    pub fn styled(mut self, style: Style) -> Self {
        self.style = Some(style);
        self
    }
    /// The look it is drawn with: its [`Style`], or one from its kind and palette colour `i`.
    pub fn look(&self, i: usize) -> Style {
        if let Some(st) = self.style {
            return st;
        }
        let color = PALETTE[self.color.unwrap_or(i) % PALETTE.len()];
        if self.line_and_markers {
            Style { color, dash: Dash::Solid, width: 2, marker: Marker::Square, max_markers: 0 }
        } else if self.markers {
            Style { color, dash: Dash::None, width: 2, marker: Marker::Circle, max_markers: 0 }
        } else {
            Style { color, dash: Dash::Solid, width: 2, marker: Marker::None, max_markers: 0 }
        }
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

/// Colours of the excitation levels on a chart of several levels (none a solver's colour).
pub const LEVEL_PALETTE: [RGBColor; 6] =
    [RGBColor(44, 160, 44), RGBColor(255, 127, 14), RGBColor(148, 103, 189), RGBColor(140, 86, 75), RGBColor(227, 119, 194), RGBColor(23, 190, 207)];

/// A solver's curve at the `level`-th excitation level on a chart of several levels: the
/// level's colour ([`LEVEL_PALETTE`]), the solver's line and marker (FO solid, on top; FR
/// dashed with squares; NLR triangles without a line).
pub fn level_series(label: impl Into<String>, level: usize, points: Vec<(f64, f64)>) -> Series {
    let label = label.into();
    let solver = solver_of(&label);
    let color = LEVEL_PALETTE[level % LEVEL_PALETTE.len()];
    let (dash, width, marker, max_markers) = match solver {
        Some("FR") => (Dash::Dashed, 2, Marker::Square, 12),
        Some("NLR") => (Dash::None, 2, Marker::Triangle, 24),
        _ => (Dash::Solid, 2, Marker::None, 0),
    };
    Series { label, points, markers: false, line_and_markers: false, color: None, style: Some(Style { color, dash, width, marker, max_markers }), on_top: solver == Some("FO") }
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
        // whole decades, with room so that a point on a decade is not drawn on the frame
        // (a little beyond them, so that the decades themselves are inside and labelled)
        let (l, h) = ((lo.log10() - 0.05).floor(), (hi.log10() + 0.05).ceil());
        (0.98 * 10f64.powf(l), 1.02 * 10f64.powf(if h > l { h } else { l + 1.0 }))
    } else {
        let pad = if hi > lo { 0.05 * (hi - lo) } else { lo.abs().max(1.0) * 0.05 };
        (lo - pad, hi + pad)
    }
}

/// Tick label: on log axes the decades (`1e-5`), and on an axis of at most two decades also
/// `2e-5` and `5e-5`; other ticks are left unlabelled, so no label repeats. On linear axes one
/// notation for the whole axis `(lo, hi)`: plain numbers when its largest magnitude is in
/// `[1e-3, 1e5)`, else scientific (`0.001` and `5.0e-4` never share an axis), with as many
/// digits as the axis' span needs for neighbouring ticks to differ (a static term that varies
/// in its fifth digit: `-2.00012e-5`, `-2.00014e-5`).
fn tick(v: f64, log: bool, decades: f64, (lo, hi): (f64, f64)) -> String {
    if !log {
        let a = v.abs();
        let span = hi - lo;
        let step = (span / 10.0).abs();
        let largest = lo.abs().max(hi.abs());
        if largest != 0.0 && !(1e-3..1e5).contains(&largest) {
            if a == 0.0 || a < 1e-9 * largest {
                return "0".into();
            }
            let digits = if step > 0.0 && step.is_finite() { ((a / step).log10().ceil().max(1.0) as usize).min(12) } else { 1 };
            return format!("{v:.digits$e}");
        }
        let decimals = if step > 0.0 && step < 1.0 { ((-step.log10()).ceil() as i32 + 1).clamp(6, 15) } else { 6 };
        let scale = 10f64.powi(decimals);
        return format!("{}", (v * scale).round() / scale);
    }
    let e = v.log10().floor();
    let mantissa = v / 10f64.powf(e);
    for m in [1.0, 2.0, 5.0, 10.0] {
        if (mantissa / m - 1.0).abs() < 1e-6 && (m == 1.0 || m == 10.0 || decades <= 2.5) {
            let (m, e) = if m == 10.0 { (1.0, e + 1.0) } else { (m, e) };
            return format!("{m}e{}", e as i32);
        }
    }
    String::new()
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

/// Width of the legend panel right of the chart (the legend never covers data).
const LEGEND_W: u32 = 250;

fn draw_plot(svg: &mut String, path: &Path, spec: &PlotSpec, series: &[Series]) -> Result<()> {
    let root = SVGBackend::with_string(svg, (760 + LEGEND_W, 520)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| plot_err(path, e))?;
    let title_area = root.titled(spec.title, ("sans-serif", 18)).map_err(|e| plot_err(path, e))?;
    let (chart_area, legend_area) = title_area.split_horizontally(760);
    let all = || series.iter().flat_map(|s| s.points.iter());
    let (mut x0, mut x1) = range(all().map(|p| p.0), spec.log_x);
    let (mut y0, mut y1) = range(all().map(|p| p.1), spec.log_y);
    if spec.diagonal {
        let lo = x0.min(y0);
        let hi = x1.max(y1);
        (x0, x1, y0, y1) = (lo, hi, lo, hi);
    }
    // drawing order: everything, then the series on top (the full order); legend in given order
    let mut order: Vec<usize> = (0..series.len()).filter(|&i| !series[i].on_top).collect();
    order.extend((0..series.len()).filter(|&i| series[i].on_top));
    let mut builder = ChartBuilder::on(&chart_area);
    builder.margin(12).x_label_area_size(45).y_label_area_size(80);
    macro_rules! draw {
        ($chart:expr) => {{
            let mut chart = $chart.map_err(|e| plot_err(path, e))?;
            chart
                .configure_mesh()
                .x_desc(spec.x_label)
                .y_desc(spec.y_label)
                .x_label_formatter(&|v: &f64| tick(*v, spec.log_x, (x1 / x0).log10(), (x0, x1)))
                .y_label_formatter(&|v: &f64| tick(*v, spec.log_y, (y1 / y0).log10(), (y0, y1)))
                .light_line_style(WHITE.mix(0.0))
                .bold_line_style(BLACK.mix(0.12))
                .draw()
                .map_err(|e| plot_err(path, e))?;
            if spec.diagonal {
                chart.draw_series(LineSeries::new(vec![(x0, x0), (x1, x1)], BLACK.mix(0.4).stroke_width(1))).map_err(|e| plot_err(path, e))?;
            }
            let visible = |s: &Series| -> Vec<(f64, f64)> {
                s.points.iter().copied().filter(|p| p.0.is_finite() && p.1.is_finite() && (!spec.log_x || p.0 > 0.0) && (!spec.log_y || p.1 > 0.0)).collect()
            };
            // the lines first, then the markers over every line (so that no series' markers
            // hide under another's line), each pass in drawing order
            for &i in &order {
                let st = series[i].look(i);
                let pts = visible(&series[i]);
                let line = ShapeStyle { color: st.color.to_rgba(), filled: false, stroke_width: st.width };
                match st.dash {
                    Dash::Solid => {
                        chart.draw_series(LineSeries::new(pts.clone(), line)).map_err(|e| plot_err(path, e))?;
                    }
                    Dash::Dashed => {
                        chart.draw_series(DashedLineSeries::new(pts.clone(), 10, 6, line)).map_err(|e| plot_err(path, e))?;
                    }
                    Dash::None => {}
                }
            }
            for &i in &order {
                let st = series[i].look(i);
                let pts = visible(&series[i]);
                // markers on at most max_markers points, offset per series so they do not coincide
                let every = if st.max_markers == 0 || pts.len() <= st.max_markers { 1 } else { pts.len().div_ceil(st.max_markers) };
                let shift = if every > 1 { (i * every / 3) % every } else { 0 };
                let marks: Vec<(f64, f64)> = pts.iter().copied().skip(shift).step_by(every).collect();
                let fill = st.color.filled();
                match st.marker {
                    Marker::None => {}
                    Marker::Circle => {
                        chart.draw_series(marks.iter().map(|&p| Circle::new(p, 4, fill))).map_err(|e| plot_err(path, e))?;
                    }
                    Marker::Square => {
                        chart.draw_series(marks.iter().map(|&p| EmptyElement::at(p) + Rectangle::new([(-4, -4), (4, 4)], fill))).map_err(|e| plot_err(path, e))?;
                    }
                    Marker::Triangle => {
                        chart.draw_series(marks.iter().map(|&p| TriangleMarker::new(p, 6, fill))).map_err(|e| plot_err(path, e))?;
                    }
                }
            }
        }};
    }
    match (spec.log_x, spec.log_y) {
        (false, false) => draw!(builder.build_cartesian_2d(x0..x1, y0..y1)),
        (false, true) => draw!(builder.build_cartesian_2d(x0..x1, (y0..y1).log_scale())),
        (true, false) => draw!(builder.build_cartesian_2d((x0..x1).log_scale(), y0..y1)),
        (true, true) => draw!(builder.build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())),
    }
    draw_legend(&legend_area, path, spec, series)?;
    root.present().map_err(|e| plot_err(path, e))?;
    Ok(())
}

/// The legend, in its own panel right of the chart: per series its line, marker and label
/// (then the diagonal's), top to bottom in the order given.
fn draw_legend<DB: DrawingBackend>(area: &DrawingArea<DB, plotters::coord::Shift>, path: &Path, spec: &PlotSpec, series: &[Series]) -> Result<()> {
    let font = ("sans-serif", 13).into_font().color(&BLACK);
    let mut y = 40i32;
    let mut entries: Vec<(Style, String)> = series.iter().enumerate().map(|(i, s)| (s.look(i), s.label.clone())).collect();
    if spec.diagonal {
        entries.push((Style { color: RGBColor(150, 150, 150), dash: Dash::Solid, width: 1, marker: Marker::None, max_markers: 0 }, "predicted = actual".into()));
    }
    for (st, label) in entries {
        let line = ShapeStyle { color: st.color.to_rgba(), filled: false, stroke_width: st.width };
        match st.dash {
            Dash::Solid => area.draw(&PathElement::new(vec![(8, y), (40, y)], line)).map_err(|e| plot_err(path, e))?,
            Dash::Dashed => area.draw(&PathElement::new(vec![(8, y), (18, y)], line)).and_then(|_| area.draw(&PathElement::new(vec![(26, y), (40, y)], line))).map_err(|e| plot_err(path, e))?,
            Dash::None => {}
        }
        let fill = st.color.filled();
        match st.marker {
            Marker::None => {}
            Marker::Circle => area.draw(&Circle::new((24, y), 4, fill)).map_err(|e| plot_err(path, e))?,
            Marker::Square => area.draw(&Rectangle::new([(20, y - 4), (28, y + 4)], fill)).map_err(|e| plot_err(path, e))?,
            Marker::Triangle => area.draw(&TriangleMarker::new((24, y), 6, fill)).map_err(|e| plot_err(path, e))?,
        }
        // long labels are wrapped at ", " to fit the panel
        let mut lines: Vec<String> = vec![String::new()];
        for (k, piece) in label.split(", ").enumerate() {
            let last = lines.last_mut().expect("a line");
            if k > 0 && last.len() + piece.len() + 2 > 28 {
                last.push(',');
                lines.push(format!("  {piece}"));
            } else {
                if k > 0 {
                    last.push_str(", ");
                }
                last.push_str(piece);
            }
        }
        for l in lines {
            area.draw(&Text::new(l, (48, y - 7), font.clone())).map_err(|e| plot_err(path, e))?;
            y += 17;
        }
        y += 6;
    }
    Ok(())
}

/// The contact nodes on their surfaces, each coloured by the energy it dissipates per cycle
/// (the paper's Fig. 4a). `positions` and `frames` (rows `t1, t2, n`) are the nodes', `energies`
/// their energies, all in the same (study) order; each node is labelled with its number in that
/// order (the x axis of the energy-per-node plot) where there is room. Nodes whose normals agree
/// (within 10 degrees) form a surface, drawn in its own panel in its tangent plane (`t1` of its
/// first node and `n x t1`); with more than four such surfaces (normals that turn, as round a
/// disc) every node goes into one panel, in the plane of the two coordinate axes along which
/// the nodes spread most. A node that dissipates nothing (stuck, or open) is an empty circle.
///
/// # Errors
/// [`JpError::InvalidValue`] if the counts differ or there is no node; [`JpError::Io`] if the
/// file cannot be written.
pub fn write_energy_map(path: &Path, title: &str, positions: &[[f64; 3]], frames: &[[[f64; 3]; 3]], energies: &[f64], energy_label: &str) -> Result<()> {
    let n = positions.len();
    if n == 0 || frames.len() != n || energies.len() != n {
        return Err(JpError::invalid("energy map", format!("{n} positions, {} frames and {} energies", frames.len(), energies.len())));
    }
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let cross = |a: [f64; 3], b: [f64; 3]| [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    // surfaces: nodes grouped by normal
    let mut groups: Vec<([f64; 3], [f64; 3], Vec<usize>)> = Vec::new();
    for (i, f) in frames.iter().enumerate() {
        match groups.iter_mut().find(|g| dot(g.0, f[2]) > 0.985) {
            Some(g) => g.2.push(i),
            None => groups.push((f[2], f[0], vec![i])),
        }
    }
    let panels: Vec<(String, String, Vec<usize>, Vec<(f64, f64)>)> = if groups.len() <= 4 {
        groups
            .iter()
            .enumerate()
            .map(|(k, (nrm, t1, idx))| {
                let v = cross(*nrm, *t1);
                let pts = idx.iter().map(|&i| (dot(positions[i], *t1), dot(positions[i], v))).collect();
                (format!("surface {} (normal {:.2} {:.2} {:.2}): along t1", k + 1, nrm[0], nrm[1], nrm[2]), "along n x t1".to_string(), idx.clone(), pts)
            })
            .collect()
    } else {
        let spread = |d: usize| {
            let (lo, hi) = positions.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p[d]), hi.max(p[d])));
            hi - lo
        };
        let mut axes = [0usize, 1, 2];
        axes.sort_by(|&a, &b| spread(b).total_cmp(&spread(a)));
        let (ax, ay) = (axes[0].min(axes[1]), axes[0].max(axes[1]));
        let names = ["x", "y", "z"];
        vec![(names[ax].to_string(), names[ay].to_string(), (0..n).collect(), positions.iter().map(|p| (p[ax], p[ay])).collect())]
    };
    let e_max = energies.iter().copied().filter(|e| e.is_finite()).fold(0.0f64, f64::max);
    // pale (nothing) to dark red (the largest energy)
    let shade = |e: f64| {
        let t = if e_max > 0.0 { (e / e_max).clamp(0.0, 1.0) } else { 0.0 };
        let lerp = |a: f64, b: f64| (a + (b - a) * t).round() as u8;
        RGBColor(lerp(255.0, 140.0), lerp(235.0, 0.0), lerp(200.0, 0.0))
    };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (760 + LEGEND_W, 520)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| plot_err(path, e))?;
        let title_area = root.titled(title, ("sans-serif", 18)).map_err(|e| plot_err(path, e))?;
        let (charts_area, bar_area) = title_area.split_horizontally(760);
        let areas = charts_area.split_evenly((1, panels.len()));
        let label_font = ("sans-serif", 10).into_font().color(&BLACK);
        for ((x_desc, y_desc, idx, pts), area) in panels.iter().zip(&areas) {
            // equal scales on both axes, so the surface keeps its shape
            let (x0, x1) = range(pts.iter().map(|p| p.0), false);
            let (y0, y1) = range(pts.iter().map(|p| p.1), false);
            let half = 0.5 * (x1 - x0).max(y1 - y0);
            let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
            let mut chart = ChartBuilder::on(area)
                .margin(12)
                .x_label_area_size(45)
                .y_label_area_size(60)
                .build_cartesian_2d(cx - half..cx + half, cy - half..cy + half)
                .map_err(|e| plot_err(path, e))?;
            chart
                .configure_mesh()
                .x_desc(x_desc.as_str())
                .y_desc(y_desc.as_str())
                .x_labels(5)
                .y_labels(5)
                .x_label_formatter(&|v: &f64| tick(*v, false, 0.0, (cx - half, cx + half)))
                .y_label_formatter(&|v: &f64| tick(*v, false, 0.0, (cy - half, cy + half)))
                .light_line_style(WHITE.mix(0.0))
                .bold_line_style(BLACK.mix(0.12))
                .draw()
                .map_err(|e| plot_err(path, e))?;
            let many = idx.len() > 40;
            let r = if many { 4 } else { 8 };
            for (&i, &p) in idx.iter().zip(pts) {
                let e = energies[i];
                if e > 0.0 {
                    chart.draw_series(std::iter::once(Circle::new(p, r, shade(e).filled()))).map_err(|e| plot_err(path, e))?;
                }
                chart.draw_series(std::iter::once(Circle::new(p, r, BLACK.stroke_width(1)))).map_err(|e| plot_err(path, e))?;
                if !many {
                    chart.draw_series(std::iter::once(EmptyElement::at(p) + Text::new(format!("{}", i + 1), (10, -4), label_font.clone()))).map_err(|e| plot_err(path, e))?;
                }
            }
        }
        // the colour bar: energy from 0 (bottom) to the largest (top)
        let font = ("sans-serif", 13).into_font().color(&BLACK);
        bar_area.draw(&Text::new(energy_label.to_string(), (10, 30), font.clone())).map_err(|e| plot_err(path, e))?;
        let (top, bottom) = (60i32, 420i32);
        for k in 0..(bottom - top) {
            let e = e_max * (1.0 - k as f64 / (bottom - top) as f64);
            bar_area.draw(&Rectangle::new([(20, top + k), (50, top + k + 1)], shade(e).filled())).map_err(|e| plot_err(path, e))?;
        }
        bar_area.draw(&Rectangle::new([(20, top), (50, bottom)], BLACK.stroke_width(1))).map_err(|e| plot_err(path, e))?;
        bar_area.draw(&Text::new(format!("{e_max:.3e}"), (58, top - 6), font.clone())).map_err(|e| plot_err(path, e))?;
        bar_area.draw(&Text::new("0 (stuck or open:".to_string(), (58, bottom - 6), font.clone())).map_err(|e| plot_err(path, e))?;
        bar_area.draw(&Text::new("empty circle)".to_string(), (58, bottom + 10), font)).map_err(|e| plot_err(path, e))?;
        root.present().map_err(|e| plot_err(path, e))?;
    }
    jprom::io::write_file(path, |w| w.write_all(svg.as_bytes()))
}

#[cfg(test)]
mod tests {
    use super::tick;

    /// One notation per linear axis: the FRF of the demo's partial-slip level (0 to 3.5e-3 mm)
    /// was labelled `0.001 ... 5.0e-4 ... 0`.
    #[test]
    fn linear_ticks_share_one_notation_per_axis() {
        let axis = (-1.7e-4, 3.6e-3);
        let labels: Vec<String> = [0.0, 5e-4, 1e-3, 2.5e-3].iter().map(|&v| tick(v, false, 0.0, axis)).collect();
        assert_eq!(labels, ["0", "0.0005", "0.001", "0.0025"]);
        let small = (-2e-5, 4.2e-4);
        let labels: Vec<String> = [0.0, 1e-4, 4e-4].iter().map(|&v| tick(v, false, 0.0, small)).collect();
        assert!(labels[0] == "0" && labels[1..].iter().all(|l| l.contains('e')), "{labels:?}");
        // neighbouring ticks of an axis spanning its fifth digit differ
        let narrow = (-2.00016e-5, -2.00010e-5);
        assert_ne!(tick(-2.00012e-5, false, 0.0, narrow), tick(-2.00014e-5, false, 0.0, narrow));
    }

    #[test]
    fn log_ticks_label_decades_only_beyond_two_decades() {
        assert_eq!(tick(1e-3, true, 4.0, (1e-5, 1e-1)), "1e-3");
        assert_eq!(tick(5e-3, true, 4.0, (1e-5, 1e-1)), "");
        assert_eq!(tick(5e-3, true, 2.0, (1e-3, 1e-1)), "5e-3");
    }
}
