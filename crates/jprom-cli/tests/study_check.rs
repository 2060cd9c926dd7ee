//! Issue 13, study ergonomics: `jprom check` opens every file a study names and every node id
//! and node set (without reading the matrices), each error with its key and the line in the
//! study file; CalculiX models with node sets; per-node normals and cylindrical frames; FE
//! contact laws without defaults (the defaults `check` applies are printed); progress on
//! stderr; no panic when the reader of standard output leaves.

use jprom::io::calculix::read_mesh;
use jprom_cli::run::build_model;
use jprom_cli::study::Study;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

fn scratch(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("study-check").join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn block_deck() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../jprom/tests/data/calculix/block/block.inp").canonicalize().unwrap()
}

fn jprom(args: &[&str]) -> (i32, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_jprom")).args(args).output().unwrap();
    (o.status.code().unwrap_or(-1), String::from_utf8_lossy(&o.stdout).into_owned(), String::from_utf8_lossy(&o.stderr).into_owned())
}

const LAW: &str = "mu = 0.3\nkt1 = 1.0e4\nkt2 = 1.0e4\nkn = 2.0e4\nn0 = 10.0\n";

/// A CalculiX block study: radial contacts on the TIP set about the z axis, load on LOAD,
/// outputs on OUT. `{contacts}` replaces the contact table.
fn block_study(contacts: &str) -> String {
    format!(
        "[model]\nkind = \"calculix\"\ndeck = \"{}\"\ncb_modes = 8\noutput_nodes = \"OUT\"\noutput_components = [\"y\"]\n\
         {contacts}\
         [band]\nhz_start = 10200.0\nhz_end = 10700.0\npoints = 8\n\
         [forcing]\nlevels = [0.5]\n[[forcing.harmonic]]\nnodes = \"LOAD\"\ndirection = [0.0, 1.0, 0.0]\nmagnitude = 1.0\n\
         [solvers]\nfr = false\nnlr = false\n[output]\nplots = false\nkeep_partial = true\n",
        block_deck().display()
    )
}

fn radial_contacts() -> String {
    format!("[[model.contacts]]\nnodes = \"tip\"\naxis = {{ origin = [0.0, 0.0, 0.0], direction = [0.0, 0.0, 2.0], sense = \"outward\" }}\n{LAW}")
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn a_calculix_study_with_node_sets_and_cylindrical_frames_checks_and_builds() {
    let dir = scratch("block");
    let study = write(&dir, "study.toml", &block_study(&radial_contacts()));
    let (code, out, err) = jprom(&["check", study.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("valid") && out.contains("model.deck") && out.contains("15 contact nodes placed"), "{out}");
    let s = Study::from_file(&study).unwrap();
    let model = build_model(&s).unwrap();
    let mesh = read_mesh(&block_deck()).unwrap();
    let tip = mesh.node_set("TIP").unwrap();
    assert_eq!(model.contacts.len(), tip.len());
    for (c, id) in model.contacts.iter().zip(tip) {
        let p = mesh.coords[id];
        let r = (p[0] * p[0] + p[1] * p[1]).sqrt();
        let n = [p[0] / r, p[1] / r, 0.0];
        for a in 0..3 {
            assert!((c.frame[2][a] - n[a]).abs() < 1e-14, "node {id}: normal {:?}, radial {n:?}", c.frame[2]);
        }
        assert!((c.frame[0][2] - 1.0).abs() < 1e-14, "t1 along the axis: {:?}", c.frame[0]);
    }
    // inward flips the normal
    let inward = write(&dir, "inward.toml", &block_study(&radial_contacts().replace("outward", "inward")));
    let m2 = build_model(&Study::from_file(&inward).unwrap()).unwrap();
    assert!((m2.contacts[0].frame[2][0] + model.contacts[0].frame[2][0]).abs() < 1e-14);
}

#[test]
fn per_node_normals_are_used_in_order_and_counted() {
    let dir = scratch("normals");
    let contacts = format!("[[model.contacts]]\nnodes = [17, 34]\nnormals = [[1.0, 0.0, 0.0], [0.0, 0.0, -3.0]]\ntangent = [0.0, 1.0, 0.0]\n{LAW}");
    let study = write(&dir, "study.toml", &block_study(&contacts));
    let model = build_model(&Study::from_file(&study).unwrap()).unwrap();
    assert_eq!(model.contacts[0].frame[2], [1.0, 0.0, 0.0]);
    assert_eq!(model.contacts[1].frame[2], [0.0, 0.0, -1.0]);
    assert_eq!(model.contacts[1].frame[0], [0.0, 1.0, 0.0]);
    let bad = write(&dir, "bad.toml", &block_study(&contacts.replace("normals = [[1.0, 0.0, 0.0], ", "normals = [")));
    let (code, _, err) = jprom(&["check", bad.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(err.contains("model.contacts[0].normals") && err.contains("1 normals for 2 nodes") && err.contains("at line 9"), "{err}");
    let both = write(&dir, "both.toml", &block_study(&contacts.replace("tangent", "normal = [1.0, 0.0, 0.0]\ntangent")));
    let (_, _, err) = jprom(&["check", both.to_str().unwrap()]);
    assert!(err.contains("model.contacts[0]") && err.contains("give one frame, not normal and normals"), "{err}");
}

/// `jprom check` on `text`: its status and stderr.
fn check_error(dir: &Path, name: &str, text: &str) -> (i32, String) {
    let p = write(dir, name, text);
    let (code, _, err) = jprom(&["check", p.to_str().unwrap()]);
    (code, err)
}

#[test]
fn check_names_the_key_and_line_of_missing_files_unknown_nodes_bad_sets_and_values() {
    let dir = scratch("errors");
    let good = block_study(&radial_contacts());
    let line_of = |text: &str, needle: &str| text.lines().position(|l| l.starts_with(needle)).unwrap() + 1;
    // a missing file
    let t = good.replace(&block_deck().display().to_string(), "nope/job.inp");
    let (code, err) = check_error(&dir, "missing.toml", &t);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("key 'model.deck'") && err.contains("nope/job") && err.contains(&format!("at line {}", line_of(&t, "deck"))), "{err}");
    // an unknown node id
    let t = good.replace("nodes = \"LOAD\"", "nodes = [255, 999999]");
    let (code, err) = check_error(&dir, "unknown.toml", &t);
    assert_eq!(code, 2, "{err}");
    let l = t.lines().position(|l| l.contains("999999")).unwrap() + 1;
    assert!(err.contains("key 'forcing.harmonic[0].nodes'") && err.contains("999999") && err.contains(&format!("at line {l}")), "{err}");
    // a bad node set name: the message lists the deck's sets
    let t = good.replace("nodes = \"tip\"", "nodes = \"TIPS\"");
    let (code, err) = check_error(&dir, "set.toml", &t);
    assert_eq!(code, 2, "{err}");
    let l = line_of(&t, "nodes = \"TIPS\"");
    assert!(err.contains("key 'model.contacts[0].nodes'") && err.contains("node set 'TIPS': the CalculiX job") && err.contains("defines no such set (its node sets: ") && err.contains("ROOT, TIP)") && err.contains(&format!("at line {l}")), "{err}");
    // a node set with a node without DoFs (the clamped root)
    let t = good.replace("nodes = \"tip\"", "nodes = \"ROOT\"");
    let (_, err) = check_error(&dir, "root.toml", &t);
    assert!(err.contains("model.contacts[0].nodes") && err.contains("node 1 (of node set \"ROOT\") has no active DoF"), "{err}");
    // value errors: a negative stiffness, a law key missing (no default for FE models), a
    // key of another kind (an error of the whole table: its own line, not 'line 0')
    let t = good.replace("kn = 2.0e4", "kn = -2.0e4");
    let (_, err) = check_error(&dir, "kn.toml", &t);
    assert!(err.contains("key 'model.contacts[0].kn'") && err.contains(&format!("at line {}", line_of(&t, "kn ="))), "{err}");
    let t = good.replace("kt2 = 1.0e4\n", "");
    let (_, err) = check_error(&dir, "kt2.toml", &t);
    assert!(err.contains("key 'model.contacts[0].kt2'") && err.contains("no default") && err.contains(&format!("at line {}", line_of(&t, "[[model.contacts]]"))), "{err}");
    let t = good.replace("cb_modes = 8\n", "cb_modes = 8\nmass = \"M.mtx\"\n");
    let (_, err) = check_error(&dir, "kind.toml", &t);
    assert!(err.contains("model.mass") && err.contains(&format!("at line {}", line_of(&t, "mass ="))) && !err.contains("line 0"), "{err}");
    // a node on the axis has no radial direction
    let t = good.replace("origin = [0.0, 0.0, 0.0]", "origin = [100.0, 0.0, 0.0]");
    let (_, err) = check_error(&dir, "axis.toml", &t);
    assert!(err.contains("model.contacts[0].axis") && err.contains("on the axis"), "{err}");
}

/// A Matrix Market study of `n` nodes (3 DoFs each) whose matrix files are written by
/// `matrix(path, n_dof)`; outputs on every node (a long study to print).
fn mm_study(dir: &Path, n_nodes: usize, matrix: &dyn Fn(&Path, usize)) -> PathBuf {
    let n = 3 * n_nodes;
    matrix(&dir.join("K.mtx"), n);
    matrix(&dir.join("M.mtx"), n);
    let nodes: Vec<String> = (0..n_nodes).map(|i| format!("{{\"id\": {}, \"coords\": [{i}, 1, 0], \"dofs\": [{}, {}, {}]}}", i + 1, 3 * i, 3 * i + 1, 3 * i + 2)).collect();
    std::fs::write(dir.join("nodes.json"), format!("{{\"format\": \"jprom-dof-map\", \"version\": 1, \"n_dof\": {n}, \"nodes\": [{}]}}", nodes.join(",\n"))).unwrap();
    let ids: Vec<String> = (1..=n_nodes).map(|i| i.to_string()).collect();
    write(
        dir,
        "study.toml",
        &format!(
            "[model]\nkind = \"matrix_market\"\nmass = \"M.mtx\"\nstiffness = \"K.mtx\"\ndof_map = \"nodes.json\"\ncb_modes = 2\noutput_nodes = [{}]\n\
             [[model.contacts]]\nnodes = [1]\nnormal = [0.0, 0.0, 1.0]\n{LAW}\
             [forcing]\nlevels = [0.1]\n[[forcing.harmonic]]\nnodes = [1]\ndirection = [1.0, 0.0, 0.0]\nmagnitude = 1.0\n",
            ids.join(", ")
        ),
    )
}

/// A valid header and size line, then `body`.
fn header_then(body: &'static str) -> impl Fn(&Path, usize) {
    move |p: &Path, n: usize| std::fs::write(p, format!("%%MatrixMarket matrix coordinate real symmetric\n{n} {n} {n}\n{body}")).unwrap()
}

#[test]
fn check_reads_headers_not_matrix_bodies_and_run_reads_them() {
    let dir = scratch("garbage");
    let study = mm_study(&dir, 2, &header_then("1 1 1.0\n2 2 x\n3 3 1.0\n4 4 1.0\n5 5 1.0\n6 6 1.0\n"));
    let (code, out, err) = jprom(&["check", study.to_str().unwrap()]);
    assert_eq!(code, 0, "check does not read the entries: {err}");
    assert!(out.contains("6 x 6, 6 entries (symmetric)") && out.contains("header read"), "{out}");
    let (code, _, err) = jprom(&["run", study.to_str().unwrap(), "--quiet", "--out", dir.join("out").to_str().unwrap()]);
    assert_eq!(code, 1, "run reads them: {err}");
    assert!(err.contains("model.stiffness") && err.contains("K.mtx") && err.contains("line 4") && err.contains("'x' is not a number"), "{err}");
    // a DoF map that is not JSON says which file and what a DoF map is
    std::fs::copy(dir.join("K.mtx"), dir.join("nodes.json")).unwrap();
    let (code, _, err) = jprom(&["check", study.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(err.contains("key 'model.dof_map'") && err.contains("nodes.json") && err.contains("not JSON") && err.contains("a DoF map is a JSON object"), "{err}");
}

#[test]
fn check_of_a_100_mb_model_takes_under_a_second() {
    let dir = scratch("large");
    // two 50 MB files: a valid header, then the same entry line again and again
    let big = |p: &Path, n: usize| {
        let mut f = std::io::BufWriter::new(std::fs::File::create(p).unwrap());
        let line = b"1 1  4.5299145299145e+05\n";
        let count = 50_000_000 / line.len();
        write!(f, "%%MatrixMarket matrix coordinate real symmetric\n{n} {n} {count}\n").unwrap();
        for _ in 0..count {
            f.write_all(line).unwrap();
        }
        f.flush().unwrap();
    };
    let study = mm_study(&dir, 20_000, &big);
    let bytes = std::fs::metadata(dir.join("K.mtx")).unwrap().len() + std::fs::metadata(dir.join("M.mtx")).unwrap().len();
    let t = Instant::now();
    let (code, out, err) = jprom(&["check", study.to_str().unwrap()]);
    let secs = t.elapsed().as_secs_f64();
    println!("jprom check of a {:.0} MB model (60,000 DoFs, 20,000 nodes in the map): {secs:.3} s", bytes as f64 / 1e6);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("valid"));
    assert!(secs < 1.0, "check took {secs:.3} s");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn check_prints_the_defaults_it_applied_and_fe_laws_have_none() {
    let dir = scratch("defaults");
    let blade = write(&dir, "blade.toml", "[model]\nkind = \"blade\"\n[model.contact]\nmu = 0.3\n");
    let (code, out, err) = jprom(&["check", blade.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let defaults = out.split("defaults applied").nth(1).unwrap().split("the study in full").next().unwrap();
    assert!(defaults.contains("model.contact.kt1 = 20126") && defaults.contains("band.points = 200"), "{defaults}");
    assert!(!defaults.contains("model.contact.mu"), "mu is given: {defaults}");
    let fe = write(&dir, "fe.toml", &block_study(&radial_contacts()));
    let (_, out, _) = jprom(&["check", fe.to_str().unwrap()]);
    let defaults = out.split("defaults applied").nth(1).unwrap().split("the study in full").next().unwrap();
    assert!(!defaults.contains("mu") && !defaults.contains("kn") && defaults.contains("hbm.nt = 64"), "{defaults}");
}

/// Runs `args` with standard output closed before the program writes: no panic, the status
/// of a normal exit, and nothing on stderr but progress.
fn with_stdout_closed(args: &[&str]) -> (i32, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_jprom")).args(args).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    (o.status.code().unwrap_or(-1), String::from_utf8_lossy(&o.stderr).into_owned())
}

#[test]
fn a_closed_standard_output_ends_check_and_run_quietly() {
    let dir = scratch("pipe");
    // a study whose printout is far beyond a pipe's buffer, so the write meets the closed pipe
    let study = mm_study(&dir, 20_000, &header_then(""));
    let (code, err) = with_stdout_closed(&["check", study.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(err.is_empty(), "{err}");
    // a run: its summary goes to the closed pipe; progress lines go to stderr (not a terminal)
    let block = write(&dir, "block.toml", &block_study(&radial_contacts()));
    let out = dir.join("out");
    let (code, err) = with_stdout_closed(&["run", block.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("panicked") && !err.contains("Broken pipe"), "{err}");
    for step in ["jprom: reading the CalculiX job", "jprom: Craig-Bampton: 720 DoFs", "done in", "jprom: FO sweep"] {
        assert!(err.contains(step), "no '{step}' in the progress:\n{err}");
    }
    assert!(out.join("summary.json").exists());
    let (code, err) = with_stdout_closed(&["run", block.to_str().unwrap(), "--quiet", "--out", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(err.is_empty(), "--quiet: {err}");
}
