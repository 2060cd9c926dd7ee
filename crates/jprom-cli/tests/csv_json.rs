//! Issue 19: the sweep CSVs hold every harmonic `x0..xH` of every output with units in their
//! headers, and summary.json each sweep's end reason, the basis time and the units. Run on the
//! twisted plate (Matrix Market study, two outputs) at H = 3.

mod slip_onset;

#[test]
fn csv_has_every_harmonic_of_every_output_and_the_summary_its_end_reasons() {
    let fe = jprom::fe::PlateFe::build(&slip_onset::plate_params()).unwrap();
    let dir = slip_onset::scratch("csv-json");
    let path = slip_onset::export_plate(&fe, &dir, (307.7, 345.4), 3);
    let study = std::fs::read_to_string(&path).unwrap().replace("points = 100", "points = 30").replace("levels = [1.0]", "levels = [0.1]")
        + "[solvers]\nfull_order = true\nfr = false\nnlr = true\n[output]\ndir = \"out\"\nplots = false\n";
    std::fs::write(&path, study).unwrap();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_jprom")).arg("run").arg(&path).arg("--quiet").output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}\n{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    let table = String::from_utf8_lossy(&o.stdout);
    assert!(table.contains("basis s"), "{table}");

    let mut expected: Vec<String> = vec!["freq_hz".into()];
    for j in 0..2 {
        expected.extend((0..=3).map(|h| format!("x{h}_out{j}_lu")));
    }
    expected.extend((0..=3).map(|h| format!("e_star_{h}")));
    for name in ["judged_e1", "iterations", "residual", "stick_samples", "slip_samples", "separated_samples", "dissipated_energy_flu", "events_after", "sweep_end"] {
        expected.push(name.into());
    }
    let summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("out/summary.json")).unwrap()).unwrap();
    assert_eq!(summary["length_unit"], "lu");
    assert_eq!(summary["energy_unit"], "flu");
    let mut slipping_rows = 0;
    for (file, solver) in [("alpha_ST_x1e-1_fo.csv", "FO (condensed)"), ("alpha_ST_x1e-1_nlr.csv", "NLR")] {
        let text = std::fs::read_to_string(dir.join("out").join(file)).unwrap();
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        assert_eq!(header, expected, "{file}");
        let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
        assert!(rows.len() > 10 && rows.iter().all(|r| r.len() == header.len()), "{file}");
        let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
        let num = |r: &Vec<&str>, name: &str| r[col(name)].parse::<f64>().unwrap();
        // e* only for the reduced model, for every harmonic
        for h in 0..=3 {
            assert_eq!(rows.iter().all(|r| !r[col(&format!("e_star_{h}"))].is_empty()), solver == "NLR", "{file} e_star_{h}");
        }
        // a slipping contact makes odd higher harmonics: x3 is a real column, not padding
        for r in rows.iter().filter(|r| num(r, "slip_samples") > 0.0) {
            slipping_rows += 1;
            assert!(num(r, "x3_out0_lu") > 0.0 && num(r, "x3_out1_lu") > 0.0, "{file}: slip but no third harmonic: {r:?}");
        }
        // the judged error only for the reduced model; its verdict agrees with it, and a
        // reduced sweep that is not trusted reports no peak
        assert_eq!(rows.iter().all(|r| !r[col("judged_e1")].is_empty()), solver == "NLR", "{file} judged_e1");
        let row = summary["rows"].as_array().unwrap().iter().find(|r| r["solver"] == solver).unwrap();
        let mut peak_reported = true;
        if solver == "NLR" {
            let within = rows.iter().all(|r| r[col("judged_e1")].parse::<f64>().is_ok_and(|e| e <= 0.05));
            let trusted = row["trusted"].as_bool().expect("a reduced row has a verdict");
            assert!(!trusted || within, "{file}: trusted with a judged error above the threshold");
            assert_eq!(trusted, row["trust_reason"].is_null(), "{row}");
            if !trusted {
                assert!(row["peak_x1"].is_null() && row["peak_hz"].is_null(), "an untrusted row reports a peak: {row}");
                peak_reported = false;
            }
        } else {
            assert!(row["trusted"].is_null(), "{row}");
        }
        // the summary's peak is the CSV's largest x1 at the first output, with its x0
        let peak = rows.iter().max_by(|a, b| num(a, "x1_out0_lu").total_cmp(&num(b, "x1_out0_lu"))).unwrap();
        let rel = |a: f64, b: f64| (a - b).abs() / b.abs().max(1e-300);
        if peak_reported {
            assert!(rel(num(peak, "x1_out0_lu"), row["peak_x1"].as_f64().unwrap()) < 1e-8, "{file}");
            assert!(rel(num(peak, "x0_out0_lu"), row["peak_x0"].as_f64().unwrap()) < 1e-8 || row["peak_x0"].as_f64().unwrap().abs() < 1e-12, "{file}");
        }
        assert_eq!(row["end"], "reached_end");
        assert_eq!(row["end_reason"], "reached the band's end");
        assert!(rows.iter().all(|r| r[col("sweep_end")] == "reached_end"));
        // each event of the summary is marked on the CSV row before it, and nothing else is
        let events = row["events"].as_array().expect("events in the summary");
        let marked: Vec<usize> = rows.iter().enumerate().filter(|(_, r)| !r[col("events_after")].is_empty()).map(|(i, _)| i).collect();
        let mut after: Vec<usize> = events.iter().map(|e| e["after_point"].as_u64().unwrap() as usize).collect();
        after.dedup();
        assert_eq!(marked, after, "{file}: events {events:?}");
        for e in events {
            let r = &rows[e["after_point"].as_u64().unwrap() as usize];
            assert!(r[col("events_after")].split('+').any(|k| k == e["kind"]), "{file}: {e} against {r:?}");
        }
        assert!(row["gaps"].as_array().is_some_and(|g| g.is_empty()) && rows.iter().all(|r| !r[col("events_after")].contains("gap")), "{file}: gaps");
        let (basis, total) = (row["basis_seconds"].as_f64().unwrap(), row["sweep_seconds"].as_f64().unwrap());
        if solver == "NLR" {
            assert!(basis > 0.0 && basis < total, "basis {basis} s of {total} s");
        } else {
            assert_eq!(basis, 0.0);
        }
    }
    assert!(slipping_rows > 0, "the level slips nowhere: the x3 check checked nothing");
}

/// A band below the resonance: the peak is the band's upper edge, every row says so, and the
/// ROM's "errors at resonance" say they were taken at the edge.
#[test]
fn a_peak_on_the_band_edge_is_warned_and_the_errors_say_where_they_were_taken() {
    let fe = jprom::fe::PlateFe::build(&slip_onset::plate_params()).unwrap();
    let dir = slip_onset::scratch("csv-json-edge");
    let path = slip_onset::export_plate(&fe, &dir, (300.0, 320.0), 1);
    let study = std::fs::read_to_string(&path).unwrap().replace("points = 100", "points = 20").replace("levels = [1.0]", "levels = [0.1]")
        + "[solvers]\nfull_order = true\nfr = false\nnlr = true\n[output]\ndir = \"out\"\nplots = false\n";
    std::fs::write(&path, study).unwrap();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_jprom")).arg("run").arg(&path).arg("--quiet").output().unwrap();
    let table = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{table}\n{}", String::from_utf8_lossy(&o.stderr));
    let summary: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("out/summary.json")).unwrap()).unwrap();
    for row in summary["rows"].as_array().unwrap() {
        let w: Vec<&str> = row["warnings"].as_array().unwrap().iter().map(|w| w.as_str().unwrap()).collect();
        assert!((row["peak_hz"].as_f64().unwrap() - 320.0).abs() < 1e-6, "{row}");
        assert!(w.iter().any(|w| w.contains("the peak is on the band edge (320.000 Hz)")), "{} {w:?}", row["solver"]);
        if row["solver"] == "NLR" {
            assert!(w.iter().any(|w| w.contains("errors \"at resonance\" are taken there")), "{w:?}");
        }
    }
    assert!(table.contains("errors \"at resonance\" are taken there"), "{table}");
}
