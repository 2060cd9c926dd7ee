//! The SVG writer produces a well-formed picture holding the series, labels and the diagonal.

use jprom_cli::plots::{level_series, write_energy_map, write_plot, Legend, PlotSpec, Series, LEVEL_PALETTE};

#[test]
fn svg_holds_title_axes_legend_and_every_point() {
    let dir = std::env::temp_dir().join(format!("jprom-plot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("err.svg");
    let pts: Vec<(f64, f64)> = (1..=7).map(|i| (10f64.powi(-i), 2.0 * 10f64.powi(-i))).collect();
    let spec = PlotSpec { title: "Predicted vs actual e1", x_label: "actual", y_label: "predicted", log_x: true, log_y: true, diagonal: true, legend: Legend::LowerRight };
    write_plot(&path, &spec, &[Series::markers("alpha_ST/10", pts.clone())]).unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    assert!(svg.starts_with("<svg"));
    assert!(svg.trim_end().ends_with("</svg>"));
    for text in ["Predicted vs actual e1", "actual", "predicted", "alpha_ST/10", "predicted = actual"] {
        assert!(svg.contains(text), "missing '{text}'");
    }
    // one marker per point, plus one in the legend
    assert_eq!(svg.matches("<circle").count(), pts.len() + 1);
    // a point with a non-positive value cannot go on a log axis and is left out, not drawn at -inf
    let path2 = dir.join("frf.svg");
    let spec2 = PlotSpec { title: "FRF", x_label: "f [Hz]", y_label: "X1 [mm]", log_x: false, log_y: true, diagonal: false, legend: Legend::UpperRight };
    write_plot(&path2, &spec2, &[Series::markers("FO", vec![(1.0, 1.0), (2.0, 0.0), (3.0, 2.0)])]).unwrap();
    let svg2 = std::fs::read_to_string(&path2).unwrap();
    assert_eq!(svg2.matches("<circle").count(), 2 + 1);
    assert!(!svg2.contains("NaN") && !svg2.contains("inf"));
}

/// The texts of an SVG (`<text ...>` contents), with their `x`.
fn texts(svg: &str) -> Vec<(f64, String)> {
    svg.split("<text").skip(1).map(|t| {
        let x = t.split("x=\"").nth(1).unwrap().split('"').next().unwrap().parse().unwrap();
        let body = t.split_once('>').unwrap().1.split("</text>").next().unwrap().trim().to_string();
        (x, body)
    }).collect()
}

/// `(stroke, stroke-width)` of each `<polyline>`, in document (drawing) order.
fn polylines(svg: &str) -> Vec<(String, String)> {
    let attr = |t: &str, a: &str| t.split(&format!("{a}=\"")).nth(1).unwrap().split('"').next().unwrap().to_string();
    svg.split("<polyline").skip(1).map(|t| (attr(t, "stroke"), attr(t, "stroke-width"))).collect()
}

fn write(name: &str, spec: &PlotSpec, series: &[Series]) -> String {
    let dir = std::env::temp_dir().join(format!("jprom-plot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    write_plot(&path, spec, series).unwrap();
    std::fs::read_to_string(&path).unwrap()
}

/// An FRF as the runner draws it: one look per solver (FO black, FR red dashed, NLR blue),
/// FO drawn last (on top), markers on at most 12 points, the legend right of the chart in the
/// given order with the basis sizes and gamma, the title and axis labels.
#[test]
fn frf_svg_has_three_solver_series_fo_on_top_and_the_legend_outside() {
    let curve = |scale: f64| (0..200).map(|i| (2140.0 + 0.25 * i as f64, scale * (1.0 + (i as f64 / 30.0).sin()))).collect::<Vec<_>>();
    let series = [
        Series::solver("FO (condensed)", curve(1.0), true),
        Series::solver("FR, n_h = [38, 18], gamma = 1e3", curve(1.001), true),
        Series::solver("NLR, n_h = [38, 9], gamma = 1e3", curve(0.999), true),
    ];
    let spec = PlotSpec { title: "First harmonic, alpha = alpha_ST x 1e-1, H = 3", x_label: "frequency [Hz]", y_label: "|X1| [mm]", log_x: false, log_y: false, diagonal: false, legend: Legend::UpperRight };
    let svg = write("solvers_frf.svg", &spec, &series);
    let t = texts(&svg);
    for want in ["First harmonic, alpha = alpha_ST x 1e-1, H = 3", "frequency [Hz]", "|X1| [mm]"] {
        assert!(t.iter().any(|(_, s)| s == want), "no text '{want}'");
    }
    // the legend: right of the 760-pixel chart, one entry per series, in order, sizes and gamma kept
    let legend: String = t.iter().filter(|(x, _)| *x >= 760.0).map(|(_, s)| s.as_str()).collect::<Vec<_>>().join(" ");
    let (fo, fr, nlr) = (legend.find("FO (condensed)").unwrap(), legend.find("FR, n_h = [38, 18],").unwrap(), legend.find("NLR, n_h = [38, 9],").unwrap());
    assert!(fo < fr && fr < nlr, "{legend}");
    assert_eq!(legend.matches("gamma = 1e3").count(), 2, "{legend}");
    // the lines: FO black 2 px, FR red 3 px (dashed: many pieces), NLR light blue 6 px; each once
    // in the chart and once in the legend
    let lines = polylines(&svg);
    let count = |c: &str, w: &str| lines.iter().filter(|l| l.0 == c && l.1 == w).count();
    assert_eq!(count("#000000", "2"), 2, "FO");
    assert_eq!(count("#8CB9DC", "6"), 2, "NLR");
    assert!(count("#D62728", "3") > 10, "FR is dashed");
    // FO is drawn after the other solvers' lines (on top): its chart line comes after NLR's and
    // after the last piece of FR's dashed line (the legend's two pieces are the last ones)
    let at = |c: &str, w: &str| lines.iter().enumerate().filter(|(_, l)| l.0 == c && l.1 == w).map(|(i, _)| i).collect::<Vec<_>>();
    let (fo_at, fr_at, nlr_at) = (at("#000000", "2"), at("#D62728", "3"), at("#8CB9DC", "6"));
    assert!(fo_at[0] > nlr_at[0] && fo_at[0] > fr_at[fr_at.len() - 3], "FO not on top: FO {fo_at:?}, NLR {nlr_at:?}");
    // markers: FO circles on 12 points (+1 in the legend), FR squares, NLR triangles
    assert_eq!(svg.matches("<circle").count(), 12 + 1);
    assert!(svg.matches("<polygon").count() >= 12, "NLR triangles");
}

/// Log axes: decades labelled, the one at the bottom too, no label repeated; a point on a
/// decade (error vs level with the levels 0.05 and 0.1) lies inside the chart, not on its frame.
#[test]
fn log_axes_label_decades_once_and_keep_edge_points_inside() {
    let series = [
        Series::solver("FR", vec![(0.05, 2.1e-4), (0.1, 3.7e-5)], true),
        Series::solver("NLR", vec![(0.05, 2.0e-4), (0.1, 3.5e-5)], true),
    ];
    let spec = PlotSpec { title: "Error of |X1| vs level, H = 1", x_label: "alpha / alpha_ST", y_label: "relative error of X1", log_x: true, log_y: true, diagonal: false, legend: Legend::UpperRight };
    let svg = write("solvers_level.svg", &spec, &series);
    let ticks: Vec<String> = texts(&svg).into_iter().filter(|(x, _)| *x < 760.0).map(|(_, s)| s).filter(|s| s.contains('e') && s.len() < 8).collect();
    for want in ["1e-2", "1e-1", "1e0", "1e-5", "1e-4", "1e-3"] {
        assert!(ticks.iter().any(|t| t == want), "no tick '{want}' in {ticks:?}");
    }
    let mut unique = ticks.clone();
    unique.sort();
    unique.dedup();
    assert_eq!(unique.len(), ticks.len(), "repeated tick labels: {ticks:?}");
    // the markers (FR squares as rects, NLR triangles) of the points at 0.1 are inside the chart
    let xs: Vec<f64> = svg.split("<polygon").skip(1).flat_map(|p| {
        let pts = p.split("points=\"").nth(1).unwrap().split('"').next().unwrap().to_string();
        pts.split(' ').filter_map(|xy| xy.split(',').next().and_then(|x| x.parse::<f64>().ok())).collect::<Vec<_>>()
    }).filter(|x| *x < 760.0).collect();
    assert!(!xs.is_empty());
    assert!(xs.iter().all(|&x| x > 92.0 + 1.0 && x < 748.0 - 1.0), "a marker on the frame: {xs:?}");
}

/// Linear axes over a narrow range far from zero (the static term X0 varies in its fifth
/// digit): every tick label differs from its neighbours, and the values are readable.
#[test]
fn narrow_linear_axes_label_ticks_with_enough_digits() {
    let x0: Vec<(f64, f64)> = (0..50).map(|i| (2140.0 + i as f64, -2.0e-5 - 1.5e-9 * ((i as f64) * 0.2).sin())).collect();
    let series = [Series::solver("FO (condensed)", x0, true)];
    let spec = PlotSpec { title: "Static term", x_label: "frequency [Hz]", y_label: "X0 [mm]", log_x: false, log_y: false, diagonal: false, legend: Legend::UpperRight };
    let svg = write("narrow_linear.svg", &spec, &series);
    let ticks: Vec<String> = texts(&svg).into_iter().filter(|(x, _)| *x < 760.0).map(|(_, s)| s).filter(|s| s.starts_with("-2.0")).collect();
    assert!(ticks.len() >= 3, "too few y ticks: {ticks:?}");
    let mut unique = ticks.clone();
    unique.sort();
    unique.dedup();
    assert_eq!(unique.len(), ticks.len(), "repeated tick labels: {ticks:?}");
    assert!(ticks.iter().all(|t| t.parse::<f64>().is_ok_and(|v| (-2.0002e-5..-1.9998e-5).contains(&v))), "{ticks:?}");
}

/// Every level on one chart: one colour per level (none a solver's), the solver by its line and
/// marker (FO a solid line without markers, drawn last; FR dashed with squares; NLR triangles
/// without a line), one legend entry per solver and level.
#[test]
fn levels_chart_colours_levels_and_keeps_each_solvers_look() {
    let curve = |peak: f64| (0..100).map(|i| { let f = 1600.0 + 6.0 * i as f64; (f, 1.0 / (1e-2 + ((f - peak) / 50.0).powi(2))) }).collect::<Vec<_>>();
    let mut series = Vec::new();
    for (k, (level, peak)) in [("5.0e-1", 2165.0), ("3.3e-4", 1672.0)].into_iter().enumerate() {
        for solver in ["FO (condensed)", "FR", "NLR"] {
            series.push(level_series(format!("{solver}, alpha_ST x {level}"), k, curve(peak)));
        }
    }
    let spec = PlotSpec { title: "First harmonic per unit forcing at every level", x_label: "frequency [Hz]", y_label: "|X1| / s", log_x: false, log_y: true, diagonal: false, legend: Legend::UpperRight };
    let svg = write("levels.svg", &spec, &series);
    let labels: Vec<String> = texts(&svg).into_iter().map(|t| t.1).collect();
    for level in ["5.0e-1", "3.3e-4"] {
        for solver in ["FO (condensed),", "FR, alpha_ST x", "NLR, alpha_ST x"] {
            assert!(labels.iter().any(|l| l.starts_with(solver) && (l.contains(level) || solver.starts_with("FO"))), "legend entry {solver} {level}: {labels:?}");
        }
    }
    let hex = |c: plotters::style::RGBColor| format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2);
    let lines = polylines(&svg);
    // two FO lines and two FR lines in the chart, plus one legend line each: FO drawn last
    let colours: Vec<String> = lines.iter().filter(|l| l.1 == "2").map(|l| l.0.clone()).collect();
    for k in 0..2 {
        assert!(colours.iter().any(|c| c.eq_ignore_ascii_case(&hex(LEVEL_PALETTE[k]))), "level {k} colour in {colours:?}");
    }
    assert!(!colours.iter().any(|c| c.eq_ignore_ascii_case("#000000")), "no solver black among the curves: {colours:?}");
    // NLR: triangles, no line of its own (2 levels x 24 markers at most, plus 2 in the legend)
    let triangles = svg.matches("<polygon").count();
    assert!(triangles >= 2 * 12 + 2 && triangles <= 2 * 25 + 2, "{triangles} triangles");
}

/// The energy map: one panel per contact surface (nodes grouped by normal) in its tangent
/// plane, a circle per node (filled where it dissipates), the node numbers, the colour bar with
/// the largest energy; bad sizes are refused.
#[test]
fn energy_map_draws_each_surface_with_its_nodes_and_the_colour_bar() {
    let dir = std::env::temp_dir().join(format!("jprom-plot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("map.svg");
    // two 2 x 2 patches facing -x and +x, as the blade's shroud contacts
    let mut positions = Vec::new();
    let mut frames = Vec::new();
    for (sx, nx) in [(-6.0, -1.0), (6.0, 1.0)] {
        for (y, z) in [(17.0, 105.0), (20.0, 105.0), (17.0, 109.0), (20.0, 109.0)] {
            positions.push([sx, y, z]);
            frames.push([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [nx, 0.0, 0.0]]);
        }
    }
    let energies = [0.0, 1.0, 2.0, 3.0, 4.0, 0.0, 0.5, 4.5];
    write_energy_map(&path, "FO energy on the contact nodes", &positions, &frames, &energies, "energy per cycle [mj]").unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    let labels: Vec<String> = texts(&svg).into_iter().map(|t| t.1).collect();
    for want in ["FO energy on the contact nodes", "energy per cycle [mj]", "4.500e0"] {
        assert!(labels.iter().any(|l| l == want), "missing '{want}' in {labels:?}");
    }
    assert_eq!(labels.iter().filter(|l| l.starts_with("surface ")).count(), 2, "one panel per surface: {labels:?}");
    for node in 1..=8 {
        assert!(labels.iter().any(|l| *l == node.to_string()), "node {node} unlabelled");
    }
    // a filled disc for each of the 6 dissipating nodes, an outline for all 8
    assert_eq!(svg.matches("<circle").count(), 6 + 8);
    assert!(write_energy_map(&path, "t", &positions[..3], &frames, &energies, "e").is_err());
    assert!(write_energy_map(&path, "t", &[], &[], &[], "e").is_err());
}
