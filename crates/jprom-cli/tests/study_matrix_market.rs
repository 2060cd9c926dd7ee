//! `model.kind = "matrix_market"` studies (issue 6): a coarse built-in blade is exported as
//! Matrix Market `M`, `K` plus a node/DoF map, and a study places contacts, loads and outputs on
//! its node ids. The runner's model must equal the blade's own Craig-Bampton model, its ROMs must
//! follow the full order, and bad studies must be errors naming the key.

use jprom_cli::run::{build_model, run_study};
use jprom::level::stuck_limit_scale;
use jprom_cli::study::Study;
use jprom::fe::{BladeFe, BladeParams, BuiltinBlade};
use jprom::contact::ContactLaw;
use jprom::io::dof_map::{DofMap, NodeDofs};
use jprom::io::matrix_market::write_matrix_market;
use jprom::jp::prediction::static_solution;
use jprom::jp::{predict_basis, stuck_mode, PredictionOptions};
use jprom::model::{ContactCoordinates, Damping};
use std::fmt::Write;
use std::path::{Path, PathBuf};

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;
const CB_MODES: usize = 20;

/// A coarse blade (a few hundred DoFs) with the default contact patches and loads.
fn coarse_blade() -> BladeFe {
    BuiltinBlade::build(&BladeParams { n_span: 9, n_chord: 2, n_thickness: 1, n_shroud_gap: 1, ..Default::default() }).unwrap()
}

fn node_id(node: usize) -> i64 {
    1000 + node as i64
}

fn list(v: impl IntoIterator<Item = String>) -> String {
    format!("[{}]", v.into_iter().collect::<Vec<_>>().join(", "))
}

fn vec3(v: [f64; 3]) -> String {
    list(v.iter().map(|x| format!("{x:?}")))
}

/// Writes `M.mtx`, `K.mtx`, `nodes.json` and `study.toml` (with `extra` appended) into `dir`;
/// returns the study path and the band (Hz).
fn export(fe: &BladeFe, dir: &Path, extra: &str) -> (PathBuf, (f64, f64)) {
    let _ = std::fs::remove_dir_all(dir);
    std::fs::create_dir_all(dir).unwrap();
    write_matrix_market(&dir.join("M.mtx"), &fe.mass, false).unwrap();
    write_matrix_market(&dir.join("K.mtx"), &fe.stiffness, false).unwrap();
    let mut nodes: Vec<NodeDofs> = fe.contacts.iter().map(|c| NodeDofs { id: node_id(c.node), coords: fe.coords[c.node], dofs: c.dofs }).collect();
    for (k, &nd) in fe.output_nodes.iter().enumerate() {
        let d = &fe.output_dofs[3 * k..3 * k + 3];
        nodes.push(NodeDofs { id: node_id(nd), coords: fe.coords[nd], dofs: [d[0], d[1], d[2]] });
    }
    DofMap::new(fe.n_dof(), nodes).unwrap().save(&dir.join("nodes.json")).unwrap();

    let f1 = fe.reduce(CB_MODES).unwrap().natural_frequencies_hz(true).unwrap()[0];
    let band = (0.985 * f1, 1.012 * f1);
    let ContactLaw::Friction3D { kt1, kt2, kn, mu, n0 } = fe.contact_law else { panic!("3D law") };
    let mut s = String::new();
    writeln!(s, "[model]\nkind = \"matrix_market\"\nmass = \"M.mtx\"\nstiffness = \"K.mtx\"\ndof_map = \"nodes.json\"").unwrap();
    writeln!(s, "cb_modes = {CB_MODES}\ndamping_ratio = 0.002").unwrap();
    writeln!(s, "output_nodes = {}", list(fe.output_nodes.iter().map(|&n| node_id(n).to_string()))).unwrap();
    let mut loads = String::new();
    for patch in 0..2 {
        let cs: Vec<_> = fe.contacts.iter().filter(|c| c.patch == patch).collect();
        let frame = cs[0].frame;
        let ids = list(cs.iter().map(|c| node_id(c.node).to_string()));
        writeln!(s, "[[model.contacts]]\nnodes = {ids}\nnormal = {}\ntangent = {}", vec3(frame[2]), vec3(frame[0])).unwrap();
        writeln!(s, "mu = {mu:?}\nkt1 = {kt1:?}\nkt2 = {kt2:?}\nkn = {kn:?}\nn0 = {n0:?}").unwrap();
        // the blade's static load: equal forces along the patch normal
        let d = cs[0].dofs;
        let f: f64 = (0..3).map(|a| fe.static_force[d[a]] * frame[2][a]).sum();
        for c in &cs {
            let g: f64 = (0..3).map(|a| fe.static_force[c.dofs[a]] * frame[2][a]).sum();
            assert!((g - f).abs() <= 1e-12 * f.abs(), "blade static load not uniform on patch {patch}");
        }
        writeln!(loads, "[[forcing.static]]\nnodes = {ids}\ndirection = {}\nmagnitude = {f:?}", vec3(frame[2])).unwrap();
    }
    let fy = fe.harmonic_force[fe.output_dofs[1]];
    writeln!(loads, "[[forcing.harmonic]]\nnodes = {}\ndirection = [0.0, 1.0, 0.0]\nmagnitude = {fy:?}", list(fe.output_nodes.iter().map(|&n| node_id(n).to_string()))).unwrap();
    writeln!(s, "[band]\nhz_start = {:?}\nhz_end = {:?}\npoints = 30\n[hbm]\nharmonics = 1\nnt = 64", band.0, band.1).unwrap();
    writeln!(s, "[forcing]\nlevels = [0.1]\n{loads}").unwrap();
    s.push_str(extra);
    let path = dir.join("study.toml");
    std::fs::write(&path, s).unwrap();
    (path, band)
}

fn scratch(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("mm-study-tests").join(name)
}

fn max_abs_diff(a: &faer::Mat<f64>, b: &faer::Mat<f64>) -> (f64, f64) {
    assert_eq!((a.nrows(), a.ncols()), (b.nrows(), b.ncols()));
    let mut d = 0.0f64;
    let mut m = 0.0f64;
    for j in 0..a.ncols() {
        for i in 0..a.nrows() {
            d = d.max((a[(i, j)] - b[(i, j)]).abs());
            m = m.max(b[(i, j)].abs());
        }
    }
    (d, m)
}

#[test]
fn matrix_market_model_equals_the_blade_craig_bampton_model() {
    let fe = coarse_blade();
    let (path, band) = export(&fe, &scratch("same"), "");
    let study = Study::from_file(&path).unwrap();
    let model = build_model(&study).unwrap();
    let centre = TWO_PI * 0.5 * (band.0 + band.1);
    let reference = fe.reduce(CB_MODES).unwrap().to_model(Damping::from_modal_ratio(0.002, centre)).unwrap();
    for (what, a, b) in [("mass", &model.mass, &reference.mass), ("stiffness", &model.stiffness, &reference.stiffness)] {
        let (d, m) = max_abs_diff(a, b);
        assert!(d <= 1e-9 * m, "{what}: max difference {d:e} (max entry {m:e})");
    }
    assert_eq!(model.damping, reference.damping);
    assert_eq!(model.output_dofs, reference.output_dofs);
    assert_eq!(model.contacts.len(), reference.contacts.len());
    for (a, b) in model.contacts.iter().zip(&reference.contacts) {
        assert_eq!(a.dofs_a, b.dofs_a);
        assert_eq!(a.law, b.law);
        for q in 0..3 {
            for r in 0..3 {
                assert!((a.frame[q][r] - b.frame[q][r]).abs() < 1e-14, "frame {:?} vs {:?}", a.frame, b.frame);
            }
        }
    }
    let close = |a: &[f64], b: &[f64]| a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-12 * (1.0 + y.abs()));
    assert!(close(&model.excitation.static_force, &reference.excitation.static_force));
    assert!(close(&model.excitation.harmonics[0].cos, &reference.excitation.harmonics[0].cos));
}

#[test]
fn matrix_market_study_runs_and_the_roms_follow_the_full_order() {
    let fe = coarse_blade();
    let extra = "[basis]\ngamma = 1000.0\nsamples = 40\nmax_corrections = 1\ngamma_study = [100.0, 10000.0]\n[output]\ndir = \"out\"\n";
    let (path, _) = export(&fe, &scratch("run"), extra);
    let study = Study::from_file(&path).unwrap();
    // output.dir is relative to the study file
    let out = scratch("run").join("out");
    assert_eq!(study.output.dir, out);
    let summary = run_study(&study, &study.output.dir, false).unwrap();
    assert_eq!(summary.contacts, 18);
    let alpha_st = summary.alpha_st.expect("the blade has a static load");
    assert!(alpha_st.is_finite() && alpha_st > 0.0);
    for f in ["alpha_ST_x1e-1_fo.csv", "alpha_ST_x1e-1_fr.csv", "alpha_ST_x1e-1_nlr.csv", "summary.json", "basis_study.csv", "error_vs_basis_size_alpha_ST_x1e-1.svg", "frf_alpha_ST_x1e-1.svg"] {
        assert!(out.join(f).exists(), "missing {f}");
    }
    let fo = summary.rows.iter().find(|r| r.solver.starts_with("FO")).unwrap();
    assert!(fo.points >= 10, "FO sweep has {} points", fo.points);
    for name in ["FR", "NLR"] {
        let r = summary.rows.iter().find(|r| r.solver == name).unwrap();
        let (e1, e0) = (r.error_x1.unwrap(), r.error_x0.unwrap());
        // X0's error is the largest over the 27 outputs relative to the largest full-order
        // |X0| (measured 0.17 for both ROMs: the static flap displacement of the tip at partial
        // slip, a small component, is where the JP basis' static part is least accurate; at the
        // first output alone it is within 3 %)
        assert!(e1 < 0.03 && e0 < 0.3, "{name}: X1 error {e1:e}, X0 error {e0:e}");
        assert!(r.predicted_e1.unwrap() < 0.1, "{name}: e* {:?}", r.predicted_e1);
        assert!(r.peak_x1 > 0.0 && (r.peak_hz - fo.peak_hz).abs() < 0.01 * fo.peak_hz);
    }
    // error vs basis size: the larger basis is at least as big and (here) more accurate
    assert_eq!(summary.basis_study.len(), 4);
    for name in ["FR", "NLR"] {
        let rows: Vec<_> = summary.basis_study.iter().filter(|r| r.solver == name).collect();
        assert!(rows[0].sizes[1] <= rows[1].sizes[1], "{name}: sizes {:?} {:?}", rows[0].sizes, rows[1].sizes);
        let e = rows[1].error_x1.unwrap();
        assert!(e < 0.03, "{name}: gamma 1e4 X1 error {e:e}");
    }
}

#[test]
fn reconditioning_a_basis_equals_predicting_it_with_the_smaller_gamma() {
    let fe = coarse_blade();
    let (path, band) = export(&fe, &scratch("recondition"), "");
    let study = Study::from_file(&path).unwrap();
    let mut model = build_model(&study).unwrap();
    // the runner's level alpha_ST / 10 (micro-slip: several contact-state patterns)
    let band = (TWO_PI * band.0, TWO_PI * band.1);
    let coords = ContactCoordinates::new(&model, 1).unwrap();
    let static_z = static_solution(&coords).unwrap();
    let s_st = stuck_limit_scale(&coords, &static_z, stuck_mode(&coords, band).unwrap().0).unwrap();
    model.excitation.dynamic_scale = 10.0 * s_st;
    let coords = ContactCoordinates::new(&model, 1).unwrap();
    let mut popts = PredictionOptions::new(band);
    popts.n_samples = 30;
    popts.gamma = 1e4;
    let (big, _) = predict_basis(&coords, &popts).unwrap();
    popts.gamma = 1e2;
    let (small, _) = predict_basis(&coords, &popts).unwrap();
    let r = big.reconditioned(1e2).unwrap();
    assert_eq!(r.sizes, small.sizes);
    assert!(r.sizes[1] < big.sizes[1], "sizes {:?} (gamma 1e2) vs {:?} (1e4)", r.sizes, big.sizes);
    for (a, b) in r.phi.iter().zip(&small.phi) {
        let (d, _) = max_abs_diff(a, b);
        assert!(d < 1e-10, "bases differ by {d:e}");
    }
    assert!(big.reconditioned(1e5).is_err());
}

fn error_of(path: &Path) -> String {
    match Study::from_file(path).and_then(|s| build_model(&s)) {
        Ok(_) => panic!("expected an error for {}", path.display()),
        Err(e) => e.to_string(),
    }
}

#[test]
fn bad_matrix_market_studies_name_the_key() {
    let fe = coarse_blade();
    let dir = scratch("bad");
    let (path, _) = export(&fe, &dir, "");
    let good = std::fs::read_to_string(&path).unwrap();
    let case = |name: &str, text: String| -> String {
        let p = dir.join(format!("{name}.toml"));
        std::fs::write(&p, text).unwrap();
        error_of(&p)
    };
    // a missing file
    let e = case("missing", good.replace("mass = \"M.mtx\"", "mass = \"nope.mtx\""));
    assert!(e.contains("model.mass") && e.contains("nope.mtx"), "{e}");
    let e = case("missing_map", good.replace("dof_map = \"nodes.json\"", "dof_map = \"nope.json\""));
    assert!(e.contains("model.dof_map"), "{e}");
    // an unknown node id in a contact set, a load and the outputs
    let first = node_id(fe.contacts[0].node).to_string();
    let e = case("unknown_contact_node", good.replacen(&format!("nodes = [{first},"), "nodes = [999999,", 1));
    assert!(e.contains("model.contacts[0].nodes") && e.contains("999999"), "{e}");
    let out0 = node_id(fe.output_nodes[0]).to_string();
    let e = case("unknown_output", good.replacen(&format!("output_nodes = [{out0},"), "output_nodes = [424242,", 1));
    assert!(e.contains("model.output_nodes") && e.contains("424242"), "{e}");
    let e = case("unknown_load_node", good.replace("[[forcing.harmonic]]\nnodes = [", "[[forcing.harmonic]]\nnodes = [31337, "));
    assert!(e.contains("forcing.harmonic[0].nodes") && e.contains("31337"), "{e}");
    // a bad normal, a tangent parallel to the normal
    let second_normal = good.match_indices("normal = ").nth(1).unwrap().0;
    let mut t = good.clone();
    let end = second_normal + t[second_normal..].find('\n').unwrap();
    t.replace_range(second_normal..end, "normal = [0.0, 0.0, 0.0]");
    let e = case("zero_normal", t);
    assert!(e.contains("model.contacts[1].normal"), "{e}");
    let e = case("parallel_tangent", good.replacen("tangent = [0.0, 1.0, 0.0]", "tangent = [-2.0, 0.0, 0.0]", 1));
    assert!(e.contains("model.contacts[0].tangent") && e.contains("parallel"), "{e}");
    // unknown keys and bad values inside the new tables
    let e = case("unknown_key", good.replacen("mu = ", "friction = 0.3\nmu = ", 1));
    assert!(e.contains("friction") && e.contains("unknown field"), "{e}");
    let e = case("bad_direction", good.replace("direction = [0.0, 1.0, 0.0]", "direction = [0.0, \"up\", 0.0]"));
    assert!(e.contains("forcing.harmonic[0].direction"), "{e}");
    let e = case("bad_axis", good.replace("output_nodes = [", "output_components = [\"w\"]\noutput_nodes = ["));
    assert!(e.contains("model.output_components[0]") && e.contains("line"), "{e}");
    let e = case("bad_type", good.replace("cb_modes = 20", "cb_modes = \"many\""));
    assert!(e.contains("model.cb_modes") && e.contains("line 6"), "{e}");
    let e = case("blade_key", good.replace("cb_modes = 20", "cb_modes = 20\nrefinement = 2"));
    assert!(e.contains("model.refinement") && e.contains("matrix_market"), "{e}");
    let e = case("no_mass", good.replace("mass = \"M.mtx\"\n", ""));
    assert!(e.contains("model.mass") && e.contains("required"), "{e}");
    let e = case("negative_kn", good.replacen("kn = ", "kn = -1.0\n# ", 1));
    assert!(e.contains("model.contacts[0].kn") && e.contains("-1"), "{e}");
    let e = case("no_harmonic", good.replace("[[forcing.harmonic]]", "[[forcing.static]]"));
    assert!(e.contains("forcing.harmonic"), "{e}");
    // nodal loads belong to matrix_market models only
    let e = Study::from_toml_str("[model]\nkind = \"blade\"\n[[forcing.static]]\nnodes = [1]\ndirection = [1.0, 0.0, 0.0]\nmagnitude = 1.0\n").unwrap_err().to_string();
    assert!(e.contains("forcing.static"), "{e}");
    // the CLI's check validates the file (and finds the relative paths)
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_jprom")).args(["check", path.to_str().unwrap()]).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// Parameter cases on an FE model: a case's `mu` and `kn` replace every contact set's (its
/// `kt1`, `kt2`, `n0` kept), `static_scale` multiplies the `[[forcing.static]]` loads, and the
/// reduced matrices are the base case's (one Craig-Bampton reduction).
#[test]
fn matrix_market_cases_override_every_contact_set() {
    let fe = coarse_blade();
    let cases = "[[cases]]\nname = \"base\"\n[[cases]]\nname = \"m\"\nmu = 0.25\nkn = 3.0e4\nstatic_scale = 1.5\ndamping_ratio = 0.003\n";
    let (path, _) = export(&fe, &scratch("cases"), cases);
    let study = Study::from_file(&path).unwrap();
    let models = jprom_cli::run::build_case_models(&study, &study.case_list(), jprom_cli::progress::Progress::Quiet).unwrap();
    let plain = build_model(&Study { cases: Vec::new(), ..study.clone() }).unwrap();
    assert_eq!(serde_json::to_string(&models[0]).unwrap(), serde_json::to_string(&plain).unwrap(), "the base case is the study without cases");
    let (base, m) = (&models[0], &models[1]);
    assert_eq!(max_abs_diff(&m.stiffness, &base.stiffness).0, 0.0);
    assert_eq!(max_abs_diff(&m.mass, &base.mass).0, 0.0);
    assert_eq!(m.contacts.len(), base.contacts.len());
    for (a, b) in m.contacts.iter().zip(&base.contacts) {
        let (ContactLaw::Friction3D { kt1, kt2, kn, mu, n0 }, ContactLaw::Friction3D { kt1: kt1b, kt2: kt2b, n0: n0b, .. }) = (&a.law, &b.law) else { panic!("3D laws") };
        assert_eq!((*mu, *kn), (0.25, 3.0e4));
        assert_eq!((kt1, kt2, n0), (kt1b, kt2b, n0b));
    }
    let scaled: Vec<f64> = base.excitation.static_force.iter().map(|f| 1.5 * f).collect();
    assert_eq!(m.excitation.static_force, scaled);
    assert!(m.damping.stiffness_coeff > 1.4 * base.damping.stiffness_coeff, "damping_ratio 0.003 vs 0.002: {:?} vs {:?}", m.damping, base.damping);
}
