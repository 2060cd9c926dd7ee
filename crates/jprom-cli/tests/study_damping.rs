//! Damping in study files (`[model.damping]`, docs/formulation.md §1): every form reaches the
//! reduced model exactly as the library API builds it (an FE damping matrix from Matrix Market,
//! Rayleigh, modal ratios, a loss factor), the short form `damping_ratio` is the default, and
//! bad values are named with their key and line.

use jprom::fe::FeModel;
use jprom::io::calculix::read_model;
use jprom::io::matrix_market::write_matrix_market;
use jprom::linalg::{sparse_from_triplets, sparse_triplets};
use jprom::model::Damping;
use jprom_cli::run::build_model;
use jprom_cli::study::Study;
use std::path::{Path, PathBuf};

fn scratch(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("study-damping").join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn block_deck() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../jprom/tests/data/calculix/block/block.inp").canonicalize().unwrap()
}

fn block_study(damping: &str) -> String {
    format!(
        "[model]\nkind = \"calculix\"\ndeck = \"{}\"\ncb_modes = 8\noutput_nodes = \"OUT\"\noutput_components = [\"y\"]\n{damping}\
         [[model.contacts]]\nnodes = \"TIP\"\nnormal = [1.0, 0.0, 0.0]\nmu = 0.3\nkt1 = 1.0e4\nkt2 = 1.0e4\nkn = 2.0e4\nn0 = 10.0\n\
         [band]\nhz_start = 10200.0\nhz_end = 10700.0\npoints = 8\n\
         [forcing]\nlevels = [0.5]\n[[forcing.harmonic]]\nnodes = \"LOAD\"\ndirection = [0.0, 1.0, 0.0]\nmagnitude = 1.0\n",
        block_deck().display()
    )
}

fn study_at(dir: &Path, text: &str) -> jprom::error::Result<Study> {
    let p = dir.join("study.toml");
    std::fs::write(&p, text).unwrap();
    Study::from_file(&p)
}

#[test]
fn every_damping_form_of_a_study_reaches_the_reduced_model() {
    let dir = scratch("forms");
    let ccx = read_model(&block_deck()).unwrap();
    let fe = FeModel::from_calculix(&ccx).unwrap();
    // an FE damping matrix: 30 M + 1e-7 K, written as the user's C.mtx
    let mut t: Vec<(usize, usize, f64)> = sparse_triplets(&fe.mass).into_iter().map(|(i, j, v)| (i, j, 30.0 * v)).collect();
    t.extend(sparse_triplets(&fe.stiffness).into_iter().map(|(i, j, v)| (i, j, 1e-7 * v)));
    let c = sparse_from_triplets(fe.n_dof(), fe.n_dof(), t).unwrap();
    write_matrix_market(&dir.join("C.mtx"), &c, true).unwrap();
    let table = "[model.damping]\nalpha = 5.0\nbeta = 2e-8\nmodal_ratios = [0.01, 0.02]\nmodal_others = 0.004\nloss_factor = 0.012\nmatrix = \"C.mtx\"\n";
    let study = study_at(&dir, &block_study(table)).unwrap();
    let model = build_model(&study).unwrap();

    // the same through the library: the FE C reduced with the model, modal damping added to it
    let plain = build_model(&study_at(&dir, &block_study("[model.damping]\n")).unwrap()).unwrap();
    assert_eq!(plain.damping, Damping::default(), "a table without forms is undamped");
    assert!(plain.added_damping.is_none() && plain.loss_factor == 0.0);
    let mut with_c = fe.clone();
    with_c.set_damping(jprom::io::matrix_market::read_symmetric_matrix_market(&dir.join("C.mtx")).unwrap()).unwrap();
    let mut spec = jprom::fe::Reduction { cb_modes: 8, ..Default::default() };
    // the study's reduction: same contacts, loads, outputs (taken from the undamped build)
    let reduced_c = {
        let mut expect = plain.clone();
        // the reduced FE C of the same boundary: reduce with C through the core and take it
        let tip = ccx.node_set("TIP").unwrap();
        spec.contacts = tip.iter().map(|&node| jprom::fe::NodalContact { node, frame: jprom::fe::contact_frame([1.0, 0.0, 0.0], None).unwrap(), law: plain.contacts[0].law.clone() }).collect();
        spec.harmonic_forces = vec![jprom::fe::NodalForce { node: ccx.node_set("LOAD").unwrap()[0], force: [0.0, 1.0, 0.0] }];
        spec.outputs = ccx.node_set("OUT").unwrap().iter().map(|&o| (o, 1)).collect();
        let m = with_c.reduce(&spec, Damping::default()).unwrap();
        assert_eq!(m.stiffness, plain.stiffness, "same reduction as the study's");
        expect.added_damping = m.added_damping;
        expect
    };
    let mut expect = reduced_c;
    let fe_c = expect.added_damping.take().unwrap();
    expect.set_modal_damping(&[0.01, 0.02], 0.004).unwrap();
    *expect.added_damping.as_mut().unwrap() += &fe_c;
    expect.damping = Damping { mass_coeff: 5.0, stiffness_coeff: 2e-8 };
    expect.loss_factor = 0.012;
    assert_eq!(model.damping, expect.damping);
    assert_eq!(model.loss_factor, expect.loss_factor);
    let (a, b) = (model.added_damping.as_ref().unwrap(), expect.added_damping.as_ref().unwrap());
    let d = (a - b).norm_max() / b.norm_max();
    assert!(d < 1e-12, "added damping differs by {d:e}");

    // the short form and the default: stiffness-proportional at the band centre
    let centre = std::f64::consts::TAU * 0.5 * (10200.0 + 10700.0);
    let short = build_model(&study_at(&dir, &block_study("damping_ratio = 0.003\n")).unwrap()).unwrap();
    assert_eq!(short.damping, Damping::from_modal_ratio(0.003, centre));
    let default = build_model(&study_at(&dir, &block_study("")).unwrap()).unwrap();
    assert_eq!(default.damping, Damping::from_modal_ratio(0.002, centre));
}

#[test]
fn bad_damping_keys_are_named_with_their_line() {
    let dir = scratch("bad");
    let cases = [
        ("damping_ratio = 0.003\n[model.damping]\nalpha = 1.0\n", "damping_ratio"),
        ("[model.damping]\nmodal_ratios = [0.01, -0.02]\n", "model.damping.modal_ratios[1]"),
        ("[model.damping]\nloss_factor = -1.0\n", "model.damping.loss_factor"),
        ("[model.damping]\nzeta = 0.01\n", "zeta"),
        ("damping_ratio = -0.1\n", "model.damping_ratio"),
    ];
    for (table, key) in cases {
        let text = block_study(table);
        let e = study_at(&dir, &text).unwrap_err().to_string();
        assert!(e.contains(key), "{table}: {e}");
        let line = text.lines().position(|l| l.contains(key.rsplit('.').next().unwrap().split('[').next().unwrap())).unwrap() + 1;
        assert!(e.contains(&format!("line {line}")), "{table}: expected line {line}: {e}");
    }
    // a damping matrix on the built-in blade, and a missing matrix file (found by run)
    let e = Study::from_toml_str("[model]\nkind = \"blade\"\n[model.damping]\nmatrix = \"C.mtx\"\n").unwrap_err().to_string();
    assert!(e.contains("model.damping.matrix"), "{e}");
    let study = study_at(&dir, &block_study("[model.damping]\nmatrix = \"missing.mtx\"\n")).unwrap();
    let e = build_model(&study).unwrap_err().to_string();
    assert!(e.contains("model.damping.matrix") && e.contains("missing.mtx"), "{e}");
}

/// `model.cb_cutoff_hz`: the study's reduction keeps the fixed-interface modes up to it (the
/// library's cut-off, checked in crates/jprom/tests/fe_model.rs), `cb_modes` a cap; refused for
/// the blade and when not positive, with key and line.
#[test]
fn a_cutoff_frequency_in_a_study_caps_the_fixed_interface_modes() {
    let dir = scratch("cutoff");
    let with = |extra: &str| block_study("").replace("cb_modes = 8\n", &format!("cb_modes = 40\n{extra}"));
    let all = build_model(&study_at(&dir, &with("")).unwrap()).unwrap();
    let cut = build_model(&study_at(&dir, &with("cb_cutoff_hz = 30000.0\n")).unwrap()).unwrap();
    let n_boundary = all.n_dof() - 40;
    assert!(cut.n_dof() > n_boundary && cut.n_dof() < all.n_dof(), "{} of {}", cut.n_dof(), all.n_dof());
    let top = jprom::model::modes::natural_modes(&cut, jprom::model::modes::Boundary::Free).unwrap();
    assert!(top[0].frequency_hz < 30000.0);
    let text = with("cb_cutoff_hz = -1.0\n");
    let e = study_at(&dir, &text).unwrap_err().to_string();
    let line = text.lines().position(|l| l.starts_with("cb_cutoff_hz")).unwrap() + 1;
    assert!(e.contains("model.cb_cutoff_hz") && e.contains(&format!("line {line}")), "{e}");
    let e = Study::from_toml_str("[model]\nkind = \"blade\"\ncb_cutoff_hz = 1000.0\n").unwrap_err().to_string();
    assert!(e.contains("cb_cutoff_hz") && e.contains("line 3"), "{e}");
}
