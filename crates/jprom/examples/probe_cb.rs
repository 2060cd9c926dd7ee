use jprom::fe::{BladeParams, BuiltinBlade, CbOptions};
use std::time::Instant;
fn main() {
    let r: usize = std::env::var("REF").ok().and_then(|s| s.parse().ok()).unwrap_or(8);
    let t = Instant::now();
    let fe = BuiltinBlade::build(&BladeParams { refinement: r, ..Default::default() }).unwrap();
    println!("r {r} contacts {} dofs {} build {:.2} s", fe.contacts.len(), fe.n_dof(), t.elapsed().as_secs_f64());
    let t = Instant::now();
    let cb = fe.reduce_with(CbOptions { n_modes: 50, keep_recovery: false, cutoff_hz: None }).unwrap();
    println!("CB {:.2} s n_red {}", t.elapsed().as_secs_f64(), cb.cb.n_reduced());
}
