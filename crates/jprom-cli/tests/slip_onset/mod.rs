//! Shared by the slip-onset tests (issue 11): two models unlike the built-in blade's usual
//! setup, with contacts closed by their preload alone, and the check that FO, FR and NLR sweeps
//! cross a band from stick to gross slip.
//!
//! - The twisted plate ([`jprom::fe::PlateFe`]): a solid hex mesh clamped at the root, 16 tip
//!   nodes against a casing with radial normals, closed by `n0`, forced at the leading edge,
//!   exported as Matrix Market `M`, `K` with a DoF map and read back through a study file.
//! - The built-in blade with its pre-twist load replaced by the preload `n0` it produced.

#![allow(dead_code)]

use jprom_cli::run::build_model;
use jprom_cli::study::Study;
use jprom::fe::{BladeParams, BuiltinBlade, PlateFe, PlateParams};
use jprom::condensation::CondensedSystem;
use jprom::contact::ContactLaw;
use jprom::rom::error_metric::{actual_error, linearised_error};
use jprom::hbm::{solve_point, sweep, HbmOptions, PointSolution, SweepEnd, SweepOptions, SweepResult};
use jprom::io::dof_map::{DofMap, NodeDofs};
use jprom::io::matrix_market::write_matrix_market;
use jprom::jp::prediction::{static_solution, stuck_mode};
use jprom::jp::PredictionOptions;
use jprom::level::{stuck_limit, StuckLimit};
use jprom::model::{ContactCoordinates, Damping, Model};
use jprom::rom::{adaptive_sweep, AdaptiveOptions, FrRom, NlrRom, ReducedModel, RomKind};
use std::fmt::Write;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

pub const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

pub fn scratch(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("slip-onset-tests").join(name)
}

/// The plate of the tests: coarse enough for the test suite.
pub fn plate_params() -> PlateParams {
    PlateParams { n_span: 16, n_chord: 15, n_thickness: 2, kt: 0.5, kn: 20.0, n0: 1.0, ..PlateParams::default() }
}

/// Writes the plate as `M.mtx`, `K.mtx`, `nodes.json` and a study placing one contact per tip
/// node (each its own radial normal), the load and the outputs; returns the study path.
pub fn export_plate(fe: &PlateFe, dir: &Path, band_hz: (f64, f64), harmonics: usize) -> PathBuf {
    let _ = std::fs::remove_dir_all(dir);
    std::fs::create_dir_all(dir).unwrap();
    write_matrix_market(&dir.join("M.mtx"), &fe.mass, false).unwrap();
    write_matrix_market(&dir.join("K.mtx"), &fe.stiffness, false).unwrap();
    let id = |node: usize| 7000 + node as i64;
    let mut nodes: Vec<NodeDofs> = fe.contacts.iter().map(|c| NodeDofs { id: id(c.node), coords: fe.coords[c.node], dofs: c.dofs }).collect();
    for nd in [fe.load_node, fe.tip_node] {
        nodes.push(NodeDofs { id: id(nd), coords: fe.coords[nd], dofs: [3 * nd, 3 * nd + 1, 3 * nd + 2] });
    }
    DofMap::new(fe.n_dof(), nodes).unwrap().save(&dir.join("nodes.json")).unwrap();
    let ContactLaw::Friction3D { kt1, kt2, kn, mu, n0 } = fe.params.contact_law() else { panic!("3D law") };
    let v = |x: [f64; 3]| format!("[{:?}, {:?}, {:?}]", x[0], x[1], x[2]);
    let mut s = String::new();
    writeln!(s, "[model]\nkind = \"matrix_market\"\nmass = \"M.mtx\"\nstiffness = \"K.mtx\"\ndof_map = \"nodes.json\"").unwrap();
    writeln!(s, "cb_modes = 12\ndamping_ratio = 0.005\noutput_nodes = [{}, {}]\noutput_components = [\"y\"]", id(fe.load_node), id(fe.tip_node)).unwrap();
    for c in &fe.contacts {
        writeln!(s, "[[model.contacts]]\nnodes = [{}]\nnormal = {}\ntangent = {}", id(c.node), v(c.frame[2]), v(c.frame[0])).unwrap();
        writeln!(s, "mu = {mu:?}\nkt1 = {kt1:?}\nkt2 = {kt2:?}\nkn = {kn:?}\nn0 = {n0:?}").unwrap();
    }
    writeln!(s, "[band]\nhz_start = {:?}\nhz_end = {:?}\npoints = 100\n[hbm]\nharmonics = {harmonics}\nnt = 64", band_hz.0, band_hz.1).unwrap();
    writeln!(s, "[forcing]\nlevels = [1.0]\n[[forcing.harmonic]]\nnodes = [{}]\ndirection = [0.0, 1.0, 0.0]\nmagnitude = {:?}", id(fe.load_node), fe.params.force).unwrap();
    let path = dir.join("study.toml");
    std::fs::write(&path, s).unwrap();
    path
}

/// The plate model read back through the Matrix Market study path, and its band (rad/s):
/// from 4 % below the free first bending mode to 4 % above the stuck one.
pub fn plate_model(harmonics: usize, tag: &str) -> (Model, (f64, f64)) {
    let fe = PlateFe::build(&plate_params()).unwrap();
    // a first pass with any band gives the CB model's free and stuck frequencies
    let path = export_plate(&fe, &scratch(tag), (100.0, 200.0), harmonics);
    let model = build_model(&Study::from_file(&path).unwrap()).unwrap();
    let coords = ContactCoordinates::new(&model, harmonics).unwrap();
    let (w_stuck, _) = stuck_mode(&coords, (TWO_PI * 250.0, TWO_PI * 350.0)).unwrap();
    let free = jprom::linalg::eigen::dense_generalized_eigenvalues(&model.stiffness, &model.mass).unwrap()[0].sqrt();
    let band = (0.96 * free, 1.04 * w_stuck);
    let path = export_plate(&fe, &scratch(tag), (band.0 / TWO_PI, band.1 / TWO_PI), harmonics);
    (build_model(&Study::from_file(&path).unwrap()).unwrap(), band)
}

/// The built-in blade (Craig-Bampton, 50 modes) with the pre-twist replaced by the normal
/// preload it produced at each contact in the linear stuck state, so `f_E^0 = 0`.
pub fn preloaded_blade() -> (Model, (f64, f64)) {
    let fe = BuiltinBlade::build(&BladeParams::default()).unwrap();
    let cb = fe.reduce(50).unwrap();
    let band = (TWO_PI * 2140.0, TWO_PI * 2190.0);
    let mut model = cb.to_model(Damping::from_modal_ratio(0.002, 0.5 * (band.0 + band.1))).unwrap();
    let coords = ContactCoordinates::new(&model, 1).unwrap();
    let z0 = static_solution(&coords).unwrap();
    for (c, &off) in model.contacts.iter_mut().zip(&coords.offsets) {
        if let ContactLaw::Friction3D { kn, ref mut n0, .. } = c.law {
            *n0 = kn * z0[off + 2];
            assert!(*n0 > 0.0, "the pre-twist presses every contact");
        }
    }
    model.excitation.static_force.iter_mut().for_each(|f| *f = 0.0);
    model.validate().unwrap();
    (model, band)
}

/// The stuck limit of a model at dynamic scale 1 in its band.
pub fn limit_of(model: &Model, band: (f64, f64), harmonics: usize) -> StuckLimit {
    let mut m = model.clone();
    m.excitation.dynamic_scale = 1.0;
    let coords = ContactCoordinates::new(&m, harmonics).unwrap();
    let z0 = static_solution(&coords).unwrap();
    let (w_st, _) = stuck_mode(&coords, band).unwrap();
    stuck_limit(&coords, &z0, w_st).unwrap()
}

/// The output whose first harmonic is compared: the load node's `y` on the plate (its only
/// output component is `y`, output 0), the tip's flap (`y`) on the blade (output 25: node 9 of
/// 9, component 1).
pub fn output_of(model: &Model) -> usize {
    if model.output_dofs.len() == 27 {
        25
    } else {
        0
    }
}

thread_local!(static OUTPUT: std::cell::Cell<usize> = const { std::cell::Cell::new(0) });

/// Amplitude of the first harmonic at the compared output (see [`output_of`]).
pub fn x1(p: &PointSolution) -> f64 {
    p.output_amplitude(1, OUTPUT.with(|o| o.get()))
}

/// Sets the compared output for this thread.
pub fn compare_output(model: &Model) {
    OUTPUT.with(|o| o.set(output_of(model)));
}

pub fn peak(points: &[PointSolution]) -> &PointSolution {
    points.iter().max_by(|a, b| x1(a).total_cmp(&x1(b))).unwrap()
}

/// What one level gave: per solver (FO, FR, NLR) the sweep's end and size, the ROMs' X1 error
/// at the FO peak, and the worst `e_1 / e*_1` over the ROM points.
#[derive(Debug, Default)]
pub struct LevelReport {
    pub level: f64,
    pub slip_fraction: f64,
    pub fo_points: usize,
    pub fo_seconds: f64,
    pub rom: Vec<RomReport>,
}

#[derive(Debug)]
pub struct RomReport {
    pub kind: RomKind,
    pub end: SweepEnd,
    pub points: usize,
    pub sizes: Vec<usize>,
    pub x1_error: f64,
    /// Points with `e_1 > 1e-6`, and among them the ones with `e*_1 < e_1`.
    pub compared: usize,
    pub not_conservative: Vec<(f64, f64, f64)>,
    pub max_e1: f64,
    /// Worst error the self-correcting sweep judged its basis by.
    pub worst_error: f64,
}

/// The full-order solution at `omega` on the branch of `fo`: from the sweep point nearest in
/// frequency among those on the same side of every fold (a fresh solve from there).
pub fn full_order_at(condensed: &CondensedSystem, fo: &SweepResult, omega: f64, reference_x1: f64, hopts: &HbmOptions) -> Option<PointSolution> {
    // candidates ordered by frequency distance, ties broken by amplitude closeness
    let mut idx: Vec<usize> = (0..fo.points.len()).collect();
    idx.sort_by(|&a, &b| {
        let da = (fo.points[a].omega - omega).abs() + 1e-3 * (x1(&fo.points[a]) - reference_x1).abs();
        let db = (fo.points[b].omega - omega).abs() + 1e-3 * (x1(&fo.points[b]) - reference_x1).abs();
        da.total_cmp(&db)
    });
    idx.iter().take(3).find_map(|&i| solve_point(condensed, omega, Some(&fo.points[i].z), hopts).ok())
}

/// Sweeps FO (condensed), FR and NLR (self-correcting) at `level` and compares them.
pub fn run_level(model: &Model, limit: &StuckLimit, band: (f64, f64), harmonics: usize, level: f64) -> LevelReport {
    compare_output(model);
    let mut model = model.clone();
    model.excitation.dynamic_scale = limit.scale_at(level).unwrap();
    let hopts = HbmOptions::default();
    let condensed = CondensedSystem::new(&model, harmonics).unwrap();
    let sopts = SweepOptions::band(band.0, band.1);
    let t = std::time::Instant::now();
    let fo = sweep(&condensed, &sopts, &hopts, &mut |_| ControlFlow::Continue(())).unwrap();
    let fo_seconds = t.elapsed().as_secs_f64();
    assert_eq!(fo.end, SweepEnd::ReachedEnd, "level {level}: FO sweep ended early: {:?}", fo.failure);
    let p = peak(&fo.points);
    let samples: usize = p.contact_cycles.iter().map(|c| c.states.len()).sum();
    let slipping: usize = p.contact_cycles.iter().map(|c| c.states.iter().filter(|s| **s != jprom::contact::ContactState::Stick).count()).sum();
    let coords = ContactCoordinates::new(&model, harmonics).unwrap();
    let mut report = LevelReport { level, slip_fraction: slipping as f64 / samples as f64, fo_points: fo.points.len(), fo_seconds, rom: Vec::new() };
    for kind in [RomKind::Fr, RomKind::Nlr] {
        let pred = PredictionOptions::new(band);
        let a = adaptive_sweep(&model, harmonics, &pred, &sopts, &hopts, &AdaptiveOptions { kind, ..AdaptiveOptions::default() }).unwrap();
        let rom: Box<dyn ReducedModel> = match kind {
            RomKind::Fr => Box::new(FrRom::new(&coords, &a.basis).unwrap()),
            RomKind::Nlr => Box::new(NlrRom::new(&condensed, &a.basis).unwrap()),
        };
        // X1 at the FO peak frequency, the ROM solved there from its nearest point
        let guess = a.sweep.points.iter().min_by(|u, v| (u.omega - p.omega).abs().total_cmp(&(v.omega - p.omega).abs())).unwrap();
        let r = solve_point(rom.as_ref(), p.omega, Some(&guess.z), &hopts).unwrap();
        let x1_error = (x1(&r) - x1(p)).abs() / x1(p);
        // e* against e at every reduced point, e from a full-order point at the same frequency
        let mut compared = 0;
        let mut not_conservative = Vec::new();
        let mut max_e1 = 0.0f64;
        for (q, e_star) in a.sweep.points.iter().zip(&a.predicted_errors) {
            let Some(f) = full_order_at(&condensed, &fo, q.omega, x1(q), &hopts) else { panic!("level {level}: no full-order point at {}", q.omega) };
            let e = actual_error(rom.as_ref(), q.omega, &q.z, &f).unwrap();
            max_e1 = max_e1.max(e[1]);
            if e[1] > 1e-6 {
                compared += 1;
                if e_star[1] < e[1] {
                    let lin = linearised_error(rom.as_ref(), &condensed, q.omega, &q.z).map(|v| v[1]).unwrap_or(f64::NAN);
                    not_conservative.push((q.omega, e_star[1], e[1]));
                    let _ = lin;
                }
            }
        }
        report.rom.push(RomReport {
            kind,
            end: a.sweep.end,
            points: a.sweep.points.len(),
            sizes: rom.layout().sizes.clone(),
            x1_error,
            compared,
            not_conservative,
            max_e1,
            worst_error: a.worst_error,
        });
    }
    report
}

pub fn print(report: &LevelReport) {
    println!(
        "level {:.0e}: slip {:.0} % of contact samples at the FO peak, FO {} points {:.2} s",
        report.level,
        100.0 * report.slip_fraction,
        report.fo_points,
        report.fo_seconds
    );
    for r in &report.rom {
        println!(
            "  {:?}: end {:?}, {} points, sizes {:?}, X1 error {:.2e}, worst judged {:.2e}, max e_1 {:.2e}, e* < e at {} of {} points {:?}",
            r.kind,
            r.end,
            r.points,
            r.sizes,
            r.x1_error,
            r.worst_error,
            r.max_e1,
            r.not_conservative.len(),
            r.compared,
            r.not_conservative.iter().take(3).collect::<Vec<_>>()
        );
    }
}
