//! AFT throughput: residual + analytical Jacobian of all contacts (`evaluate_contacts` with
//! the Jacobian) per second, for 18, 180 and 1800 3D contacts at H = 1 (Nt = 64) and H = 3
//! (Nt = 128), states mixing stick, slip and separation; sequential vs rayon; and the
//! table-vs-FFT backend choice per contact for growing H.
//!
//! Run: `cargo bench --bench aft`.

use jprom::aft::{evaluate_contacts_with, AftBackend, AftPlan, ContactForces, Threading};
use jprom::contact::ContactState;
mod common;

use common::{aft_setup as setup, time_per_call};

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
