//! Helpers shared by the benches (`mod common;` in each): deterministic inputs, timing, peak
//! memory and the built-in blade model.
#![allow(dead_code)]

use jprom::fe::{BladeParams, BuiltinBlade};
use jprom::contact::ContactLaw;
use jprom::model::{Damping, Model};
use std::time::Instant;

/// Deterministic pseudo-random numbers in [-1, 1) (no dev-dependency needed in a bench).
pub struct Lcg(pub u64);
impl Lcg {
    pub fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

/// `n_contacts` 3D contacts with `nc` harmonic coefficients of displacements that mix stick,
/// slip and separation: `(laws, offsets, n_w, w)`.
pub fn aft_setup(n_contacts: usize, nc: usize) -> (Vec<ContactLaw>, Vec<usize>, usize, Vec<f64>) {
    let laws = vec![ContactLaw::Friction3D { kt1: 1.0, kt2: 0.8, kn: 1.5, mu: 0.4, n0: 1.0 }; n_contacts];
    let offsets: Vec<usize> = (0..n_contacts).map(|c| 3 * c).collect();
    let n_w = 3 * n_contacts;
    let mut rng = Lcg(12345);
    let mut w = vec![0.0; nc * n_w];
    for c in 0..n_contacts {
        let amp = 0.1 + 1.5 * (rng.next() + 1.0) / 2.0;
        for k in 0..nc {
            let decay = if k == 0 { 0.3 } else { 1.0 / ((k + 1) / 2) as f64 };
            for i in 0..3 {
                let scale = if i == 2 { 0.6 } else { amp };
                w[k * n_w + 3 * c + i] = scale * decay * rng.next();
            }
        }
    }
    (laws, offsets, n_w, w)
}

/// Seconds per call of `f`, repeating (doubling) until a batch takes more than `min_secs`.
pub fn time_per_call(mut f: impl FnMut(), min_secs: f64) -> f64 {
    f();
    let mut reps = 1;
    loop {
        let t = Instant::now();
        for _ in 0..reps {
            f();
        }
        let dt = t.elapsed().as_secs_f64();
        if dt > min_secs {
            return dt / reps as f64;
        }
        reps *= 2;
    }
}

/// Peak resident memory of this process (MB), from /proc/self/status.
pub fn vm_hwm_mb() -> f64 {
    let s = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    s.lines()
        .find(|l| l.starts_with("VmHWM:"))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|v| v.parse::<f64>().ok())
        .map(|kb| kb / 1024.0)
        .unwrap_or(f64::NAN)
}

/// The built-in blade at `refinement`, Craig-Bampton with 50 modes, damping ratio 0.002 at
/// 2165 Hz, dynamic scale `scale`.
pub fn blade_model(refinement: usize, scale: f64) -> Model {
    let fe = BuiltinBlade::build(&BladeParams { refinement, ..Default::default() }).expect("blade");
    let cb = fe.reduce(50).expect("CB");
    let omega = 2.0 * std::f64::consts::PI * 2165.0;
    let mut m = cb.to_model(Damping::from_modal_ratio(0.002, omega)).expect("model");
    m.excitation.dynamic_scale = scale;
    m
}
