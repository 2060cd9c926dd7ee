//! JP timing and accuracy table: full-order (FO) vs FR vs NLR sweeps over the band of the first
//! stuck mode, for H = 1 and H = 3, with a predicted basis (stuck mode as generating shape).
//! Until the built-in blade (crate::fe) is on main this runs on a 3D spring-mass chain with
//! node-to-ground and node-pair friction contacts (tests/jp_support); `cargo bench --bench jp`.

use jprom_testkit::chain as jp_support;

use jp_support::*;
use jprom::condensation::CondensedSystem;
use jprom::rom::error_metric::{output_error, predicted_error};
use jprom::hbm::{solve_point, sweep, FullSystem, HbmOptions, SweepOptions};
use jprom::jp::{predict_basis, PredictionOptions};
use jprom::model::ContactCoordinates;
use jprom::rom::{FrRom, NlrRom, ReducedModel};
use std::ops::ControlFlow;
use std::time::Instant;

fn main() {
    let opts = ChainOptions { n_nodes: 40, n_ground: 12, pair: true, ..Default::default() };
    let mut model = chain_model(&opts);
    model.excitation.dynamic_scale = 0.05;
    let (freqs, _) = linear_modes(&stuck_stiffness_physical(&model), &model.mass);
    let band = (0.97 * freqs[0], 1.02 * freqs[0]);
    println!("model: {} DoFs, {} contacts, first stuck mode {:.4} rad/s", model.n_dof(), model.contacts.len(), freqs[0]);
    println!("{:>2} {:>8} {:>10} {:>9} {:>8} {:>10} {:>10} {:>10} {:>10} {:>10}", "H", "gamma", "sizes", "build s", "model", "sweep s", "points", "X1 err", "X0 err", "max e*_1");
    for h in [1usize, 3] {
        let hopts = HbmOptions::default();
        let sopts = SweepOptions { max_step: 0.01, initial_step: 0.005, ..SweepOptions::band(band.0, band.1) };
        let coords = ContactCoordinates::new(&model, h).unwrap();
        let full = FullSystem::new(&model, h).unwrap();
        let t = Instant::now();
        let fo = sweep(&full, &sopts, &hopts, &mut |_| ControlFlow::Continue(())).unwrap();
        let t_fo = t.elapsed().as_secs_f64();
        let peak = fo.points.iter().max_by(|a, b| a.output_amplitude(1, 2).total_cmp(&b.output_amplitude(1, 2))).unwrap();
        println!("{h:>2} {:>8} {:>10} {:>9} {:>8} {t_fo:>10.3} {:>10} {:>10} {:>10} {:>10}", "-", "-", "-", "FO", fo.points.len(), "-", "-", "-");
        for gamma in [1e2, 1e3, 1e4] {
            let mut popts = PredictionOptions::new(band);
            popts.gamma = gamma;
            let t = Instant::now();
            let (basis, _) = predict_basis(&coords, &popts).unwrap();
            let t_build = t.elapsed().as_secs_f64();
            let fr = FrRom::new(&coords, &basis).unwrap();
            let condensed = CondensedSystem::new(&model, h).unwrap();
            let nlr = NlrRom::new(&condensed, &basis).unwrap();
            for (name, rom) in [("FR", &fr as &dyn ReducedModel), ("NLR", &nlr as &dyn ReducedModel)] {
                let t = Instant::now();
                let res = sweep(rom, &sopts, &hopts, &mut |_| ControlFlow::Continue(()));
                let t_sw = t.elapsed().as_secs_f64();
                let (npts, worst) = match &res {
                    Ok(r) => (
                        r.points.len(),
                        r.points.iter().map(|p| predicted_error(rom, p.omega, &p.z).map(|e| e[1]).unwrap_or(f64::NAN)).fold(0.0, f64::max),
                    ),
                    Err(_) => (0, f64::NAN),
                };
                let (e1, e0) = match solve_point(rom, peak.omega, None, &hopts) {
                    Ok(s) => (output_error(&s.outputs, &peak.outputs, peak.n_outputs, 1), output_error(&s.outputs, &peak.outputs, peak.n_outputs, 0)),
                    Err(_) => (f64::NAN, f64::NAN),
                };
                println!(
                    "{h:>2} {gamma:>8.0e} {:>10} {t_build:>9.3} {name:>8} {t_sw:>10.3} {npts:>10} {e1:>10.2e} {e0:>10.2e} {worst:>10.2e}",
                    format!("{:?}", rom.layout().sizes)
                );
            }
        }
    }
}
