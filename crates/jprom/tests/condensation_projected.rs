//! The projected condensation of the NLR model (docs/formulation.md §7, §9) against the dense one: for
//! random contact-row bases, `P^T H_h P` and `P^T g_h` of [`CondensedSystem`] equal
//! [`ProjectedCondensation::linear_part`] at several frequencies and harmonics, with a model
//! that has linear DoFs (a chain with two node-to-ground contacts and a node pair).

use jprom_testkit::chain as jp_support;

use faer::Mat;
use jp_support::*;
use jprom::hbm::HarmonicSystem;
use jprom::condensation::CondensedSystem;
use rand::{rngs::StdRng, Rng, SeedableRng};

fn rel(a: &Mat<f64>, b: &Mat<f64>) -> f64 {
    (a - b).norm_l2() / b.norm_l2().max(f64::MIN_POSITIVE)
}

fn relv(a: &[f64], b: &[f64]) -> f64 {
    let d: f64 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt();
    d / b.iter().map(|y| y * y).sum::<f64>().sqrt().max(f64::MIN_POSITIVE)
}

#[test]
fn projected_linear_part_equals_the_projection_of_the_condensed_one() {
    for harmonics in [1usize, 3] {
        let model = chain_model(&ChainOptions { n_nodes: 10, ..Default::default() });
        let cond = CondensedSystem::new(&model, harmonics).unwrap();
        let nw = cond.coordinates().n_w;
        assert!(cond.coordinates().n_dof > nw, "the model needs linear DoFs");
        let mut rng = StdRng::seed_from_u64(11 + harmonics as u64);
        let bases: Vec<Mat<f64>> = (0..=harmonics).map(|h| Mat::from_fn(nw, 2 + h, |_, _| rng.gen_range(-1.0..1.0))).collect();
        let proj = cond.project(&bases).unwrap();
        for omega in [0.3, 1.1, 2.7] {
            let full = cond.linear_part(omega).unwrap();
            let lin = proj.linear_part(omega).unwrap();
            let p0 = &bases[0];
            assert!(rel(&lin.d0.to_dense(), &(p0.transpose() * &full.d0.to_dense() * p0)) < 1e-12);
            let f0: Vec<f64> = (0..p0.ncols()).map(|j| (0..nw).map(|i| p0[(i, j)] * full.f0[i]).sum()).collect();
            assert!(relv(&lin.f0, &f0) < 1e-12);
            for h in 1..=harmonics {
                let p = &bases[h];
                let (re, im) = (p.transpose() * &full.dh_re[h - 1].to_dense() * p, p.transpose() * &full.dh_im[h - 1].to_dense() * p);
                assert!(rel(&lin.dh_re[h - 1].to_dense(), &re) < 1e-10, "H {harmonics} h {h} omega {omega}: re {:.2e}", rel(&lin.dh_re[h - 1].to_dense(), &re));
                assert!(rel(&lin.dh_im[h - 1].to_dense(), &im) < 1e-10, "H {harmonics} h {h} omega {omega}: im {:.2e}", rel(&lin.dh_im[h - 1].to_dense(), &im));
                for (got, want) in [(&lin.fh_cos[h - 1], &full.fh_cos[h - 1]), (&lin.fh_sin[h - 1], &full.fh_sin[h - 1])] {
                    let pw: Vec<f64> = (0..p.ncols()).map(|j| (0..nw).map(|i| p[(i, j)] * want[i]).sum()).collect();
                    if pw.iter().any(|x| *x != 0.0) {
                        assert!(relv(got, &pw) < 1e-10, "H {harmonics} h {h} omega {omega}: force {:.2e}", relv(got, &pw));
                    }
                }
            }
        }
        assert!(cond.project(&bases[..harmonics]).is_err());
    }
}
