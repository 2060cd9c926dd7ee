//! Issue 13, modes: `jprom modes STUDY` lists the natural frequencies of the FE model (equal to
//! CalculiX's own to 1e-6), of its Craig-Bampton model with the contacts open and stuck (`*` on
//! the stuck modes in the band), the stuck mode the runner uses for the band, and a warning when
//! the band holds none; `jprom run` puts that warning in the summary (JSON and table).

use jprom::model::modes::NaturalMode;
use jprom_cli::modes::{band_warning, in_band};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

fn scratch(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("modes-cli").join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn block_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../jprom/tests/data/calculix/block").canonicalize().unwrap()
}

fn jprom(args: &[&str]) -> (i32, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_jprom")).args(args).output().unwrap();
    (o.status.code().unwrap_or(-1), String::from_utf8_lossy(&o.stdout).into_owned(), String::from_utf8_lossy(&o.stderr).into_owned())
}

/// A CalculiX block study (as tests/study_check.rs): radial contacts on TIP, load on LOAD,
/// outputs on OUT, the band `lo..hi` Hz, a cheap full-order sweep only.
fn block_study(deck: &Path, lo: f64, hi: f64) -> String {
    format!(
        "[model]\nkind = \"calculix\"\ndeck = \"{}\"\ncb_modes = 8\noutput_nodes = \"OUT\"\noutput_components = [\"y\"]\n\
         [[model.contacts]]\nnodes = \"TIP\"\naxis = {{ origin = [0.0, 0.0, 0.0], direction = [0.0, 0.0, 1.0], sense = \"outward\" }}\n\
         mu = 0.3\nkt1 = 1.0e4\nkt2 = 1.0e4\nkn = 2.0e4\nn0 = 10.0\n\
         [band]\nhz_start = {lo:?}\nhz_end = {hi:?}\npoints = 8\n\
         [forcing]\nlevels = [0.5]\n[[forcing.harmonic]]\nnodes = \"LOAD\"\ndirection = [0.0, 1.0, 0.0]\nmagnitude = 1.0\n\
         [solvers]\nfr = false\nnlr = false\n[output]\nplots = false\nkeep_partial = true\n",
        deck.display()
    )
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// The frequencies (Hz) CalculiX printed in its `.dat` (E I G E N V A L U E   O U T P U T).
fn ccx_frequencies(dat: &Path) -> Vec<f64> {
    let text = std::fs::read_to_string(dat).unwrap();
    let section = text.split("E I G E N V A L U E   O U T P U T").nth(1).unwrap();
    let section = section.split("P A R T I C I P A T I O N").next().unwrap();
    section
        .lines()
        .filter_map(|l| {
            let f: Vec<&str> = l.split_whitespace().collect();
            (f.len() == 5 && f[0].parse::<usize>().is_ok()).then(|| f[3].parse::<f64>().unwrap())
        })
        .collect()
}

/// The rows of a printed table: the lines after the line starting with `title` and the header
/// line, while they start with a mode number.
fn table<'a>(out: &'a str, title: &str) -> Vec<Vec<&'a str>> {
    let mut lines = out.lines().skip_while(|l| !l.starts_with(title)).skip(2);
    let mut rows = Vec::new();
    for l in lines.by_ref() {
        let f: Vec<&str> = l.split_whitespace().collect();
        if f.first().is_some_and(|x| x.parse::<usize>().is_ok()) {
            rows.push(f);
        } else {
            break;
        }
    }
    rows
}

fn num(s: &str) -> f64 {
    s.parse().unwrap_or_else(|_| panic!("not a number: {s}"))
}

#[test]
fn modes_of_a_calculix_study_match_calculix_and_mark_the_band() {
    let dir = scratch("block");
    let study = write(&dir, "study.toml", &block_study(&block_dir().join("block.inp"), 10200.0, 10700.0));
    let (code, out, err) = jprom(&["modes", study.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    // progress on stderr, as run's
    assert!(err.contains("reading the CalculiX job") && err.contains("FE natural frequencies") && err.contains("Craig-Bampton"), "{err}");

    // the FE model's frequencies are CalculiX's (7 digits printed) to 1e-6
    let ccx = ccx_frequencies(&block_dir().join("block_freq.dat"));
    assert_eq!(ccx.len(), 10);
    let fe = table(&out, "FE model:");
    assert_eq!(fe.len(), 10, "{out}");
    let fe_hz: Vec<f64> = fe.iter().map(|r| num(r[1])).collect();
    for (k, (a, b)) in fe_hz.iter().zip(&ccx).enumerate() {
        assert!((a / b - 1.0).abs() <= 1e-6, "mode {}: jprom {a} Hz, ccx {b} Hz", k + 1);
    }

    // the reduced model: free >= FE (Craig-Bampton bounds from above), stuck >= free
    let rows = table(&out, "reduced model:");
    assert_eq!(rows.len(), 10, "{out}");
    let mut marked = 0;
    for (k, r) in rows.iter().enumerate() {
        let (free, stuck) = (num(r[1]), num(r[4]));
        assert!(free >= fe_hz[k] * (1.0 - 1e-9), "mode {}: CB {free} below FE {}", k + 1, fe_hz[k]);
        assert!(stuck > free, "mode {}: stuck {stuck} not above free {free}", k + 1);
        for c in [2, 3, 5, 6] {
            assert!(num(r[c]) >= 0.0);
        }
        assert!(num(r[3]) <= 1.0 && num(r[6]) <= 1.0, "participations are shares: {r:?}");
        let star = r.len() == 8 && r[7] == "*";
        assert_eq!(star, (10200.0..=10700.0).contains(&stuck), "mode {}: {r:?}", k + 1);
        marked += star as usize;
    }
    assert!(marked >= 1, "the band holds a stuck mode: {out}");
    assert!(out.contains(&format!("stuck modes in the band: {marked}\n")), "{out}");
    // the stuck mode for the band is a marked one, and no warning
    let line = out.lines().find(|l| l.starts_with("stuck mode for the band")).unwrap();
    let hz = num(line.rsplit(": ").next().unwrap().trim_end_matches(" Hz"));
    assert!(rows.iter().any(|r| r.len() == 8 && num(r[4]) == hz), "{line}");
    assert!(!out.contains("warning"), "{out}");

    // --count, --quiet
    let (code, out, err) = jprom(&["modes", study.to_str().unwrap(), "--count", "3", "--quiet"]);
    assert_eq!(code, 0, "{err}");
    assert!(err.is_empty(), "--quiet: {err}");
    assert_eq!(table(&out, "FE model:").len(), 3);
    assert_eq!(table(&out, "reduced model:").len(), 3);
}

#[test]
fn a_band_without_a_stuck_mode_is_warned_by_modes_and_run() {
    let dir = scratch("no-stuck-mode");
    let study = write(&dir, "study.toml", &block_study(&block_dir().join("block.inp"), 11000.0, 12000.0));
    let (code, out, err) = jprom(&["modes", study.to_str().unwrap(), "--quiet"]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("stuck modes in the band: 0\n"), "{out}");
    let rows = table(&out, "reduced model:");
    assert!(rows.iter().all(|r| r.len() == 7), "no * outside the band: {out}");
    // the nearest stuck mode is named (10438.544 Hz, below the band)
    let stuck: Vec<f64> = rows.iter().map(|r| num(r[4])).collect();
    let nearest = stuck.iter().copied().min_by(|a, b| (11000.0 - a).abs().min((a - 12000.0).abs()).total_cmp(&(11000.0 - b).abs().min((b - 12000.0).abs()))).unwrap();
    let warning = out.lines().find(|l| l.starts_with("warning: ")).unwrap_or_else(|| panic!("{out}"));
    assert!(warning.contains("the band 11000 - 12000 Hz holds no stuck mode") && warning.contains(&format!("the nearest is at {nearest:.3} Hz")), "{warning}");
    assert!(warning.contains("centre the band there, e.g. hz_start = "), "{warning}");

    // run: the same warning in summary.json and the printed summary
    let out_dir = dir.join("out");
    let (code, printed, err) = jprom(&["run", study.to_str().unwrap(), "--quiet", "--out", out_dir.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out_dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(json["stuck_mode_in_band"], false);
    let warnings = json["warnings"].as_array().unwrap();
    assert_eq!(warnings.len(), 1, "{json}");
    assert_eq!(format!("warning: {}", warnings[0].as_str().unwrap()), warning);
    assert!((json["stuck_resonance_hz"].as_f64().unwrap() - nearest).abs() < 1e-3 * nearest);
    assert!(printed.contains("outside the band (!)") && printed.contains(&format!("(!) {}", warnings[0].as_str().unwrap())), "{printed}");
}

#[test]
fn band_warning_names_the_nearest_and_the_most_driven_mode_near_the_band() {
    let m = |f: f64, p: f64| NaturalMode { frequency_hz: f, modal_force: p.sqrt(), participation: p };
    let stuck = [m(100.0, 0.1), m(180.0, 0.01), m(260.0, 0.3), m(5000.0, 0.59)];
    assert!(band_warning(&stuck, (170.0, 190.0), 180.0).is_none());
    assert!(in_band(180.0, (190.0, 170.0)) && !in_band(169.9, (170.0, 190.0)));
    // nearest 180 (below), most driven within a factor 2 of the band: 260, not the 5 kHz mode
    let w = band_warning(&stuck, (200.0, 220.0), 180.0).unwrap();
    assert!(w.contains("the nearest is at 180.000 Hz") && w.contains("stuck mode nearest the band centre, 180.000 Hz"), "{w}");
    assert!(w.contains("drives the stuck mode at 260.000 Hz most") && w.contains("hz_start = 250.0, hz_end = 270.0"), "{w}");
}

#[test]
fn modes_exit_status_bad_study_2_failed_model_1_closed_pipe_0() {
    let dir = scratch("status");
    let (code, _, err) = jprom(&["modes", dir.join("missing.toml").to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    let (code, _, err) = jprom(&["modes"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("modes needs a study file"), "{err}");
    let good = write(&dir, "good.toml", &block_study(&block_dir().join("block.inp"), 10200.0, 10700.0));
    let (code, _, err) = jprom(&["modes", good.to_str().unwrap(), "--count", "0"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--count needs a positive integer"), "{err}");
    // an unknown node set: a bad study, with its key
    let bad = write(&dir, "bad.toml", &block_study(&block_dir().join("block.inp"), 10200.0, 10700.0).replace("\"TIP\"", "\"NOSUCHSET\""));
    let (code, _, err) = jprom(&["modes", bad.to_str().unwrap(), "--quiet"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("model.contacts[0].nodes"), "{err}");
    // a stiffness entry that is not a number: check passes (it reads no bodies), the model fails
    let job = dir.join("job");
    std::fs::create_dir_all(&job).unwrap();
    for ext in ["inp", "mas", "dof"] {
        std::fs::copy(block_dir().join(format!("block.{ext}")), job.join(format!("block.{ext}"))).unwrap();
    }
    let sti = std::fs::read_to_string(block_dir().join("block.sti")).unwrap();
    let mut lines: Vec<String> = sti.lines().map(String::from).collect();
    lines[10] = "1 11 x".into();
    std::fs::write(job.join("block.sti"), lines.join("\n") + "\n").unwrap();
    let broken = write(&dir, "broken.toml", &block_study(&job.join("block.inp"), 10200.0, 10700.0));
    let (code, _, err) = jprom(&["modes", broken.to_str().unwrap(), "--quiet"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("model.deck") && err.contains("block.sti"), "{err}");
    // a reader that leaves early: no panic, status 0
    let mut child = Command::new(env!("CARGO_BIN_EXE_jprom")).args(["modes", good.to_str().unwrap(), "--quiet"]).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(!err.contains("panic"), "{err}");
}
