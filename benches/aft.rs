//! AFT throughput: residual + analytical Jacobian of all contacts (`evaluate_contacts` with
//! the Jacobian) per second, for 18, 180 and 1800 3D contacts at H = 1 (Nt = 64) and H = 3
//! (Nt = 128), states mixing stick, slip and separation; sequential vs rayon; and the
//! table-vs-FFT backend choice per contact for growing H.
//!
//! Run: `cargo bench --bench aft`.

use jprom::aft::{evaluate_contacts_with, AftBackend, AftPlan, ContactForces, Threading};
use jprom::contact::{ContactLaw, ContactState};
use std::time::Instant;

/// Deterministic pseudo-random numbers in [-1, 1) (no dev-dependency needed in a bench).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

fn setup(n_contacts: usize, nc: usize) -> (Vec<ContactLaw>, Vec<usize>, usize, Vec<f64>) {
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

fn time_per_call(mut f: impl FnMut(), min_secs: f64) -> f64 {
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

fn main() {
    println!("threads available to rayon: {}", rayon::current_num_threads());
    println!();
    println!("evaluate_contacts with Jacobian (3D contacts, mixed states)");
    println!(
        "{:>3} {:>5} {:>9} {:>14} {:>14} {:>14} {:>10} {:>22}",
        "H", "Nt", "contacts", "seq eval/s", "rayon eval/s", "us/contact seq", "speed-up", "stick/slip/sep %"
    );
    for (h, nt) in [(1usize, 64usize), (3, 128)] {
        let plan = AftPlan::new(h, nt).unwrap();
        let nc = plan.n_coeffs();
        for n_contacts in [18, 180, 1800] {
            let (laws, offsets, n_w, w) = setup(n_contacts, nc);
            let mut out = ContactForces::default();
            evaluate_contacts_with(&plan, &laws, &offsets, n_w, &w, true, true, &mut out, Threading::Sequential);
            let mut counts = [0usize; 3];
            for cy in &out.cycles {
                for s in &cy.states {
                    counts[*s as usize] += 1;
                }
            }
            let total = (counts.iter().sum::<usize>()) as f64;
            let mix = format!(
                "{:.0}/{:.0}/{:.0}",
                100.0 * counts[ContactState::Stick as usize] as f64 / total,
                100.0 * counts[ContactState::Slip as usize] as f64 / total,
                100.0 * counts[ContactState::Separated as usize] as f64 / total
            );
            let t_seq = time_per_call(
                || evaluate_contacts_with(&plan, &laws, &offsets, n_w, &w, true, false, &mut out, Threading::Sequential),
                0.3,
            );
            let t_par = time_per_call(
                || evaluate_contacts_with(&plan, &laws, &offsets, n_w, &w, true, false, &mut out, Threading::Auto),
                0.3,
            );
            println!(
                "{h:>3} {nt:>5} {n_contacts:>9} {:>14.0} {:>14.0} {:>14.2} {:>10.2} {mix:>22}",
                1.0 / t_seq,
                1.0 / t_par,
                1e6 * t_seq / n_contacts as f64,
                t_seq / t_par
            );
        }
    }

    println!();
    println!("one 3D contact with Jacobian: tables vs rustfft (us per contact), Nt = 4 (H + 1) rounded up to 2^k, min 64");
    println!("{:>3} {:>5} {:>10} {:>10} {:>8}", "H", "Nt", "tables", "fft", "Auto");
    for h in [1usize, 3, 5, 8, 12, 16, 24] {
        let nt = (4 * (h + 1)).next_power_of_two().max(64);
        let nc = 2 * h + 1;
        let (laws, offsets, n_w, w) = setup(64, nc);
        let mut res = Vec::new();
        for backend in [AftBackend::Tables, AftBackend::Fft] {
            let plan = AftPlan::with_backend(h, nt, backend).unwrap();
            let mut out = ContactForces::default();
            let t = time_per_call(
                || evaluate_contacts_with(&plan, &laws, &offsets, n_w, &w, true, false, &mut out, Threading::Sequential),
                0.2,
            );
            res.push(1e6 * t / 64.0);
        }
        let auto = if AftPlan::new(h, nt).unwrap().uses_fft() { "fft" } else { "tables" };
        println!("{h:>3} {nt:>5} {:>10.2} {:>10.2} {auto:>8}", res[0], res[1]);
    }
}
