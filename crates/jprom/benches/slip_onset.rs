//! Sweeps through slip onset on an FE model unlike the built-in blade (issue 11): the twisted
//! hex8 plate with 16 tip contacts closed by their preload alone, radial normals, reduced by
//! Craig-Bampton through the FE-model API. Full-order (condensed) sweeps over a band from 4 %
//! below the free first bending mode to 4 % above the stuck one, at three levels from near
//! stuck to gross slip, H = 1 and 3. Prints points per sweep, time per point and how each
//! sweep ended.
//!
//! Run: `cargo bench -p jprom --bench slip_onset`.
//!
//! Before the continuation fix of issue 11 (commit 46d5fd5, the same plate through the study
//! runner with its defaults) every one of these sweeps hit the 800-point cap stalled near slip
//! onset: 3.7-4.7 s per sweep at H = 1, 15-17 s at H = 3, never reaching the band's end.

use jprom::condensation::CondensedSystem;
use jprom::contact::ContactState;
use jprom::fe::{PlateFe, PlateParams};
use jprom::hbm::{sweep, HbmOptions, SweepOptions};
use jprom::jp::prediction::{static_solution, stuck_mode};
use jprom::level::stuck_limit;
use jprom::linalg::eigen::dense_generalized_eigenvalues;
use jprom::model::{ContactCoordinates, Damping};
use std::ops::ControlFlow;
use std::time::Instant;

const TWO_PI: f64 = 2.0 * std::f64::consts::PI;

fn main() {
    let params = PlateParams { n_span: 16, n_chord: 15, n_thickness: 2, kt: 0.5, kn: 20.0, n0: 1.0, ..PlateParams::default() };
    let t = Instant::now();
    let plate = PlateFe::build(&params).expect("plate");
    let (fe, spec) = plate.fe_model(12).expect("FE model");
    let probe = fe.reduce(&spec, Damping::default()).expect("reduce");
    let free = dense_generalized_eigenvalues(&probe.stiffness, &probe.mass).expect("eigen")[0].sqrt();
    let coords = ContactCoordinates::new(&probe, 1).expect("coords");
    let (w_stuck, _) = stuck_mode(&coords, (TWO_PI * 250.0, TWO_PI * 350.0)).expect("stuck mode");
    let band = (0.96 * free, 1.04 * w_stuck);
    let model = fe.reduce(&spec, Damping::from_modal_ratio(0.005, 0.5 * (band.0 + band.1))).expect("reduce");
    println!(
        "plate: {} FE DoFs, {} contacts, reduced to {} DoFs in {:.2} s; band {:.1}-{:.1} Hz",
        fe.n_dof(),
        model.contacts.len(),
        model.n_dof(),
        t.elapsed().as_secs_f64(),
        band.0 / TWO_PI,
        band.1 / TWO_PI
    );
    println!("{:>2} {:>6} {:>12} {:>7} {:>9} {:>12} {:>11}  end", "H", "level", "slip at peak", "points", "time (s)", "ms / point", "rejected");
    for harmonics in [1, 3] {
        let hopts = HbmOptions::default();
        let coords = ContactCoordinates::new(&model, harmonics).expect("coords");
        let z0 = static_solution(&coords).expect("static");
        let (w_st, _) = stuck_mode(&coords, band).expect("stuck mode");
        let limit = stuck_limit(&coords, &z0, w_st).expect("stuck limit");
        for level in [1.0, 0.1, 0.01] {
            let mut m = model.clone();
            m.excitation.dynamic_scale = limit.scale_at(level).expect("level");
            let condensed = CondensedSystem::new(&m, harmonics).expect("condensed");
            let t = Instant::now();
            let res = sweep(&condensed, &SweepOptions::band(band.0, band.1), &hopts, &mut |_| ControlFlow::Continue(())).expect("sweep");
            let secs = t.elapsed().as_secs_f64();
            let peak = res.points.iter().max_by(|a, b| a.output_amplitude(1, 0).total_cmp(&b.output_amplitude(1, 0))).expect("points");
            let samples: usize = peak.contact_cycles.iter().map(|c| c.states.len()).sum();
            let slipping: usize = peak.contact_cycles.iter().map(|c| c.states.iter().filter(|s| **s != ContactState::Stick).count()).sum();
            println!(
                "{harmonics:>2} {level:>6} {:>11.0}% {:>7} {secs:>9.2} {:>12.1} {:>11}  {}",
                100.0 * slipping as f64 / samples.max(1) as f64,
                res.points.len(),
                1e3 * secs / res.points.len() as f64,
                res.rejected_steps,
                res.end.name()
            );
        }
    }
}
