use jprom::cms::*;
fn main() {
    let t = std::time::Instant::now();
    let mut p = BladeParams::default();
    let args: Vec<String> = std::env::args().collect();
    if args.len() > 1 { p.refinement = args[1].parse().unwrap(); }
    if args.len() > 2 { p.length = args[2].parse().unwrap(); }
    if args.len() > 3 { p.thickness = args[3].parse().unwrap(); }
    let fe = BuiltinBlade::build(&p).unwrap();
    println!("dofs {} elems {} contacts {} build {:?}", fe.n_dof(), fe.n_elements, fe.contacts.len(), t.elapsed());
    println!("patch forces {:?} ratio {} patch ratio {:?}", fe.stuck_patch_forces, fe.stuck_max_friction_ratio, fe.stuck_patch_friction_ratio);
    let t = std::time::Instant::now();
    println!("free {:?}", fe.natural_frequencies_hz(4, false).unwrap());
    println!("stuck {:?} {:?}", fe.natural_frequencies_hz(4, true).unwrap(), t.elapsed());
    let t = std::time::Instant::now();
    let cb = fe.reduce(50).unwrap();
    println!("cb {:?} n_red {}", t.elapsed(), cb.cb.n_reduced());
    let f = cb.natural_frequencies_hz(true).unwrap();
    println!("cb stuck {:?}", &f[..4]);
    let f = cb.natural_frequencies_hz(false).unwrap();
    println!("cb free {:?}", &f[..4]);
}
