//! The SVG writer produces a well-formed picture holding the series, labels and the diagonal.

use jprom_cli::plots::{write_plot, Legend, PlotSpec, Series};

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
