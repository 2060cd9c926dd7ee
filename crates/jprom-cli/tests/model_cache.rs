//! `model.cache` (issue 19: the demo's Craig-Bampton model kept after the first run): a second
//! build into the same output folder reads the model instead of reducing the blade again and
//! gets the same model bit for bit; a file built for other parameters, or damaged, is rebuilt
//! and replaced; a cache that cannot be written is an error, not a silent miss; FE models
//! refuse the key.

use jprom::JpError;
use jprom_cli::run::build_model;
use jprom_cli::study::{Study, BLADE_MODEL_CACHE};
use std::path::Path;

fn study(dir: &Path, cb_modes: usize, cache: bool) -> Study {
    let text = format!(
        "[model]\nkind = \"blade\"\ncb_modes = {cb_modes}\ncache = {cache}\n[forcing]\nlevels = [0.1]\n[output]\ndir = {:?}\n",
        dir.display().to_string()
    );
    Study::from_toml_str(&text).unwrap()
}

fn same_model(a: &jprom::model::Model, b: &jprom::model::Model) -> bool {
    serde_json::to_string(a).unwrap() == serde_json::to_string(b).unwrap()
}

#[test]
fn a_second_build_reads_the_same_model_and_a_stale_or_damaged_file_is_rebuilt() {
    let dir = std::env::temp_dir().join(format!("jprom-model-cache-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let file = dir.join(BLADE_MODEL_CACHE);

    // without the key nothing is written
    let uncached = build_model(&study(&dir, 12, false)).unwrap();
    assert!(!file.exists());

    // the first build writes the file, the second reads it: the same model, bit for bit
    let first = build_model(&study(&dir, 12, true)).unwrap();
    assert!(same_model(&first, &uncached));
    let written = std::fs::read_to_string(&file).unwrap();
    assert!(written.contains("\"kind\":\"blade_model_cache\""));
    let stamp = std::fs::metadata(&file).unwrap().modified().unwrap();
    let second = build_model(&study(&dir, 12, true)).unwrap();
    assert!(same_model(&second, &first));
    assert_eq!(std::fs::metadata(&file).unwrap().modified().unwrap(), stamp, "a hit does not rewrite the file");

    // a file built for other parameters (here cb_modes) is rebuilt and replaced
    let other = build_model(&study(&dir, 14, true)).unwrap();
    assert_eq!(other.n_dof(), first.n_dof() + 2);
    assert!(std::fs::read_to_string(&file).unwrap().contains("cb_modes 14"));

    // a damaged file (cut in half) is rebuilt and replaced
    let text = std::fs::read_to_string(&file).unwrap();
    std::fs::write(&file, &text[..text.len() / 2]).unwrap();
    let rebuilt = build_model(&study(&dir, 14, true)).unwrap();
    assert!(same_model(&rebuilt, &other));
    assert_eq!(std::fs::read_to_string(&file).unwrap(), text);

    // a file whose contact coordinates do not match its model's contacts is rebuilt too
    let mut doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    doc["data"]["positions"].as_array_mut().unwrap().pop();
    std::fs::write(&file, serde_json::to_string(&doc).unwrap()).unwrap();
    let rebuilt = build_model(&study(&dir, 14, true)).unwrap();
    assert!(same_model(&rebuilt, &other));

    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_cache_that_cannot_be_written_is_an_error_and_fe_models_refuse_the_key() {
    // the output folder is a file: the cache cannot be written there
    let blocker = std::env::temp_dir().join(format!("jprom-model-cache-blocker-{}", std::process::id()));
    std::fs::write(&blocker, "not a folder").unwrap();
    match build_model(&study(&blocker.join("out"), 12, true)) {
        Err(JpError::Io { reason, .. }) => assert!(reason.contains("model.cache"), "{reason}"),
        other => panic!("expected an I/O error, got {:?}", other.map(|m| m.n_dof())),
    }
    let _ = std::fs::remove_file(&blocker);

    // the cache's name is taken by a folder: the file is written beside it, the rename fails,
    // and nothing is left beside it
    let dir = std::env::temp_dir().join(format!("jprom-model-cache-taken-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("blade_model_cache.json").join("inside")).unwrap();
    match build_model(&study(&dir, 12, true)) {
        Err(JpError::Io { reason, .. }) => assert!(reason.contains("model.cache"), "{reason}"),
        other => panic!("expected an I/O error, got {:?}", other.map(|m| m.n_dof())),
    }
    let left: Vec<String> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert_eq!(left, vec!["blade_model_cache.json".to_string()], "a temporary file was left: {left:?}");
    let _ = std::fs::remove_dir_all(&dir);

    let fe = "[model]\nkind = \"calculix\"\ndeck = \"job.inp\"\ncache = true\n[forcing]\nlevels = [0.1]\n";
    match Study::from_toml_str(fe) {
        Err(JpError::Parse { reason, .. }) => assert!(reason.contains("model.cache") && reason.contains("calculix"), "{reason}"),
        other => panic!("expected a parse error, got {other:?}"),
    }
}
