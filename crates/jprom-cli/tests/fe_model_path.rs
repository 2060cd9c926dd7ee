//! The study runner's Matrix Market path is the core's FE-model API: the twisted plate exported
//! as Matrix Market files and read through a study gives the same reduced model (matrices bit
//! for bit, contact frames to round-off) as the plate given to [`jprom::fe::FeModel`] directly.

mod slip_onset;

use jprom::fe::{PlateFe, PlateFe as Plate};
use jprom::model::Damping;
use jprom_cli::run::build_model;
use jprom_cli::study::Study;
use slip_onset::{export_plate, plate_params, scratch, TWO_PI};

#[test]
fn study_path_and_fe_model_api_give_the_same_model() {
    let plate = PlateFe::build(&plate_params()).unwrap();
    let band_hz = (150.0, 350.0);
    let path = export_plate(&plate, &scratch("fe-model-path"), band_hz, 1);
    let from_study = build_model(&Study::from_file(&path).unwrap()).unwrap();
    let (fe, spec) = plate.fe_model(12).unwrap();
    let damping = Damping::from_modal_ratio(0.005, TWO_PI * 0.5 * (band_hz.0 + band_hz.1));
    let direct = fe.reduce(&spec, damping).unwrap();
    assert_eq!(direct.n_dof(), from_study.n_dof());
    assert_eq!(direct.stiffness, from_study.stiffness);
    assert_eq!(direct.mass, from_study.mass);
    assert_eq!(direct.damping, from_study.damping);
    // the study builds each frame again from its normal and tangent (orthonormalised): equal
    // to round-off
    assert_eq!(direct.contacts.len(), from_study.contacts.len());
    for (a, b) in direct.contacts.iter().zip(&from_study.contacts) {
        assert_eq!((&a.dofs_a, &a.dofs_b, &a.law), (&b.dofs_a, &b.dofs_b, &b.law));
        for (ra, rb) in a.frame.iter().zip(&b.frame) {
            for (x, y) in ra.iter().zip(rb) {
                assert!((x - y).abs() < 1e-14, "frames {:?} vs {:?}", a.frame, b.frame);
            }
        }
    }
    assert_eq!(direct.output_dofs, from_study.output_dofs);
    assert_eq!(direct.excitation, from_study.excitation);
    assert_eq!(Plate::node_id(plate.load_node), spec.harmonic_forces[0].node);
}
