//! One table of the project's headline figures (issue 6): AFT throughput, blade build and
//! Craig-Bampton time, full-order (condensed) time per point, JP basis build time and FR/NLR
//! time per point and accuracy on the default blade at H = 1. Quick versions of
//! `benches/{aft,cms,hbm,jp}.rs`; `cargo bench --bench summary` prints a markdown table
//! (about a minute on two cores).

mod common;

use common::{aft_setup, time_per_call, vm_hwm_mb};
use jprom::aft::{evaluate_contacts_with, AftPlan, ContactForces, Threading};
use jprom::level::stuck_limit_scale;
use jprom::fe::{BladeParams, BuiltinBlade};
use jprom::condensation::CondensedSystem;
use jprom::rom::error_metric::predicted_error;
use jprom::hbm::{solve_point, sweep, HarmonicSystem, HbmOptions, PointSolution, SweepOptions, SweepResult};
use jprom::jp::prediction::static_solution;
use jprom::jp::{predict_basis, stuck_mode, PredictionOptions};
use jprom::model::{ContactCoordinates, Damping};
use jprom::rom::{FrRom, NlrRom};
use std::ops::ControlFlow;
use std::time::Instant;

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

struct Table(Vec<[String; 4]>);

impl Table {
    fn row(&mut self, figure: impl Into<String>, value: String, unit: &str, how: impl Into<String>) {
        let r = [figure.into(), value, unit.to_string(), how.into()];
        eprintln!("  {} = {} {}", r[0], r[1], r[2]);
        self.0.push(r);
    }
    fn print(&self) {
        println!("| figure | value | unit | how measured |");
        println!("|---|---:|---|---|");
        for r in &self.0 {
            println!("| {} | {} | {} | {} |", r[0], r[1], r[2], r[3]);
        }
    }
}

/// Three significant digits, scientific outside [0.01, 1e5).
fn sig(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    if x.abs() >= 1e5 || x.abs() < 1e-2 {
        return format!("{x:.2e}");
    }
    let decimals = (2 - x.abs().log10().floor() as i32).max(0) as usize;
    format!("{x:.decimals$}")
}

fn peak(points: &[PointSolution]) -> &PointSolution {
    points.iter().max_by(|a, b| a.output_amplitude(1, 0).total_cmp(&b.output_amplitude(1, 0))).expect("a point")
}

fn timed_sweep(system: &dyn HarmonicSystem, sopts: &SweepOptions, hopts: &HbmOptions) -> (SweepResult, f64) {
    let t = Instant::now();
    let res = sweep(system, sopts, hopts, &mut |_| ControlFlow::Continue(())).expect("sweep");
    (res, t.elapsed().as_secs_f64())
}

fn main() {
    let mut table = Table(Vec::new());
    eprintln!("rayon threads: {}", rayon::current_num_threads());

    // AFT: residual + analytical Jacobian of all contacts, sequential (one core)
    for (h, nt) in [(1usize, 64usize), (3, 128)] {
        let plan = AftPlan::new(h, nt).expect("plan");
        for n_contacts in [18usize, 180] {
            let (laws, offsets, n_w, w) = aft_setup(n_contacts, plan.n_coeffs());
            let mut out = ContactForces::default();
            let t = time_per_call(|| evaluate_contacts_with(&plan, &laws, &offsets, n_w, &w, true, false, &mut out, Threading::Sequential), 0.25);
            table.row(
                format!("AFT evaluations/s, {n_contacts} contacts, H = {h}"),
                sig(1.0 / t),
                "1/s",
                format!("all {n_contacts} 3D contacts' forces + analytical Jacobian, Nt = {nt}, mixed stick/slip/separation, one thread (benches/aft.rs has rayon)"),
            );
        }
    }

    // the default blade: FE build and Craig-Bampton
    let t = Instant::now();
    let fe = BuiltinBlade::build(&BladeParams::default()).expect("blade");
    let t_build = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let cb = fe.reduce(50).expect("CB");
    let t_cb = t.elapsed().as_secs_f64();
    table.row("blade FE build", sig(t_build), "s", format!("BuiltinBlade::build, default ({} DoFs, {} contact nodes)", fe.n_dof(), fe.contacts.len()));
    table.row("blade Craig-Bampton", sig(t_cb), "s", format!("50 fixed-interface modes, {} boundary DoFs -> {} reduced DoFs", fe.boundary_dofs().len(), cb.cb.n_reduced()));

    // H = 1 sweeps over the demo band at alpha_ST / 10, as `jprom demo` does
    let band = (TWO_PI * 2140.0, TWO_PI * 2190.0);
    let mut model = cb.to_model(Damping::from_modal_ratio(0.002, 0.5 * (band.0 + band.1))).expect("model");
    let hopts = HbmOptions::default();
    let coords = ContactCoordinates::new(&model, 1).expect("coords");
    let (omega_st, _) = stuck_mode(&coords, band).expect("stuck mode");
    let s_st = stuck_limit_scale(&coords, &static_solution(&coords).expect("static"), omega_st).expect("alpha_ST");
    model.excitation.dynamic_scale = s_st / 0.1;
    let coords = ContactCoordinates::new(&model, 1).expect("coords");
    let points = 60usize;
    let sopts = SweepOptions { max_step: 1.0 / points as f64, initial_step: 0.5 / points as f64, max_points: 4 * points, ..SweepOptions::band(band.0, band.1) };
    let how = "default blade, H = 1, Nt = 64, alpha = alpha_ST / 10, 2140-2190 Hz, demo arclength steps";

    let t = Instant::now();
    let condensed = CondensedSystem::new(&model, jprom::hbm::Discretisation::with_nt(1, 64)).expect("condensed");
    let t_cond = t.elapsed().as_secs_f64();
    let (fo, t_fo) = timed_sweep(&condensed, &sopts, &hopts);
    let fo_peak = peak(&fo.points).clone();
    table.row("FO (condensed) time per point", sig(1e3 * t_fo / fo.points.len() as f64), "ms", format!("{how}: {} points in {:.2} s ({} unknowns); condensation set-up {:.3} s", fo.points.len(), t_fo, condensed.layout().total(), t_cond));

    let mut popts = PredictionOptions::new(band);
    popts.gamma = 1e3;
    popts.n_samples = 100;
    let t = Instant::now();
    let (basis, report) = predict_basis(&coords, &popts).expect("basis");
    let t_basis = t.elapsed().as_secs_f64();
    table.row("JP basis build (prediction)", sig(t_basis), "s", format!("predict_basis: stuck mode, 100 log-spaced samples, {} contact-state patterns, gamma 1e3 -> sizes {:?}", report.n_patterns, basis.sizes));

    let fr = FrRom::new(&coords, &basis).expect("FR");
    let nlr = NlrRom::new(&condensed, &basis).expect("NLR");
    for (name, rom) in [("FR", &fr as &dyn HarmonicSystem), ("NLR", &nlr as &dyn HarmonicSystem)] {
        let (res, t_rom) = timed_sweep(rom, &sopts, &hopts);
        table.row(format!("{name} time per point"), sig(1e3 * t_rom / res.points.len() as f64), "ms", format!("{how}: {} points in {:.2} s, basis above (no corrections)", res.points.len(), t_rom));
        let guess = res.points.iter().min_by(|a, b| (a.omega - fo_peak.omega).abs().total_cmp(&(b.omega - fo_peak.omega).abs())).map(|q| q.z.clone());
        let r = solve_point(rom, fo_peak.omega, guess.as_deref(), &hopts).expect("ROM at the FO peak");
        let err = (r.output_amplitude(1, 0) - fo_peak.output_amplitude(1, 0)).abs() / fo_peak.output_amplitude(1, 0);
        let rom_ref: &dyn jprom::rom::ReducedModel = if name == "FR" { &fr } else { &nlr };
        let e_star = predicted_error(rom_ref, r.omega, &r.z).expect("e*")[1];
        table.row(format!("{name} relative error of the X1 amplitude at the FO resonance"), sig(err), "-", format!("relative to FO at {:.2} Hz; predicted e*_1 = {}", fo_peak.omega / TWO_PI, sig(e_star)));
    }
    table.row("peak memory", sig(vm_hwm_mb()), "MB", "VmHWM of this process (the blade build and CB dominate)");
    table.print();
}
