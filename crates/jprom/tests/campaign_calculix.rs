//! The campaign's models (docs/formulation.md §6.9) assembled by another FE code: each mesh
//! written as a CalculiX deck (`Mesh::calculix_deck`, C3D8), `ccx` run on it
//! (`*FREQUENCY, SOLVER=MATRIXSTORAGE`), its `.sti`/`.mas`/`.dof` read back and reduced as the
//! natively assembled model is. The two give the same band and level scale, a full-order sweep
//! through slip on each the same peak, and the ccx model at the native peak's frequency the
//! same response.
//!
//! Needs `ccx` on `PATH` (`.ci/run` installs `calculix-ccx` and sets `JPROM_REQUIRE_CCX`, so
//! there a missing `ccx` fails the test; elsewhere it is skipped with a message).

use jprom::aft::Discretisation;
use jprom::condensation::CondensedSystem;
use jprom::hbm::{solve_point, sweep, HbmOptions, SweepEnd, SweepOptions, SweepResult};
use jprom_testkit::campaign::{self, model};
use std::ops::ControlFlow;
use std::path::PathBuf;

fn ccx_on_path() -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path).map(|d| d.join("ccx")).find(|p| p.is_file())
}

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

fn peak(r: &SweepResult) -> (f64, f64) {
    r.points.iter().map(|p| (campaign::x1(p), p.omega)).fold((0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a })
}

#[test]
fn campaign_models_assembled_by_calculix_sweep_as_the_native_ones() {
    let Some(ccx) = ccx_on_path() else {
        assert!(std::env::var_os("JPROM_REQUIRE_CCX").is_none(), "JPROM_REQUIRE_CCX is set but there is no ccx on PATH");
        eprintln!("no ccx on PATH: the CalculiX campaign check is skipped");
        return;
    };
    // the campaign subset's first three models (seed 57): an end patch, node pairs, a tip line
    let models = campaign::models_with_every_site(57, 3);
    assert_eq!(models.len(), 3);
    let root = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("campaign-calculix");
    for (index, (spec, native)) in models.iter().enumerate() {
        let dir = root.join(index.to_string());
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("campaign.inp"), spec.mesh().calculix_deck()).unwrap();
        let run = std::process::Command::new(&ccx).arg("-i").arg("campaign").current_dir(&dir).output().expect("ccx runs");
        assert!(run.status.success(), "ccx failed on model {index}: {}", String::from_utf8_lossy(&run.stdout));
        let from_ccx = model::build(spec, Some(&dir)).unwrap_or_else(|e| panic!("model {index} from ccx's files: {e}"));
        assert_eq!(from_ccx.n_fe_dofs, native.n_fe_dofs, "model {index}: DoFs");
        let band = relative(from_ccx.band.0, native.band.0).max(relative(from_ccx.band.1, native.band.1));
        let scale = relative(from_ccx.level_scale, native.level_scale);
        println!("model {index}: {} ({} FE DoFs): band {band:.1e} apart, level scale {scale:.1e} apart", spec.describe(), native.n_fe_dofs);
        // what differs is the 14 digits of the deck and of ccx's matrix files; another element
        // formulation or DoF order would show at 1e-3 and above
        assert!(band < 1e-7 && scale < 1e-6, "model {index}: band {band:e}, level scale {scale:e} apart");
        // a full-order sweep through slip (level 0.02 of the stuck limit) on each
        let level = 0.02;
        let hopts = HbmOptions::default();
        let systems: Vec<CondensedSystem> = [&from_ccx, native]
            .iter()
            .map(|b| {
                let mut m = b.model.clone();
                m.excitation.dynamic_scale = b.level_scale / level;
                CondensedSystem::new(&m, Discretisation::with_nt(1, 64)).unwrap()
            })
            .collect();
        let swept: Vec<SweepResult> = systems
            .iter()
            .zip([&from_ccx, native])
            .map(|(sys, b)| sweep(sys, &SweepOptions::band(b.band.0, b.band.1), &hopts, &mut |_| ControlFlow::Continue(())).unwrap())
            .collect();
        assert!(swept.iter().all(|r| r.end == SweepEnd::ReachedEnd), "model {index}: {:?}", swept.iter().map(|r| &r.failure).collect::<Vec<_>>());
        let ((a_ccx, w_ccx), (a_native, w_native)) = (peak(&swept[0]), peak(&swept[1]));
        // the ccx model at the native peak's frequency, from its own nearest sweep point
        let near = swept[0].points.iter().min_by(|p, q| (p.omega - w_native).abs().total_cmp(&(q.omega - w_native).abs())).unwrap();
        let there = campaign::x1(&solve_point(&systems[0], w_native, Some(&near.z), &hopts).unwrap());
        println!("  level {level}: peak X1 {a_ccx:.6e} at {w_ccx:.3} rad/s (ccx), {a_native:.6e} at {w_native:.3} (native); ccx at the native peak {there:.9e}");
        assert!(relative(there, a_native) < 1e-6, "model {index}: X1 {there:e} (ccx) against {a_native:e} at {w_native} rad/s");
        assert!(relative(a_ccx, a_native) < 1e-3 && relative(w_ccx, w_native) < 1e-3, "model {index}: peaks {a_ccx:e} at {w_ccx} (ccx), {a_native:e} at {w_native}");
    }
}
