//! The real acrylic swatches of `shared/data/stitch-by-stitch-acrylic` calibrated end to end:
//! the README's shell-fit and diagnosis tables (about 4 min on 2 cores; `-- --nocapture`
//! prints them).

#![cfg(feature = "hdf5")]

use yarnhom_calib::cause::CauseId;
use yarnhom_calib::data::stitch_by_stitch::import_fabric;
use yarnhom_calib::diagnosis::diagnose;
use yarnhom_calib::diagnosis::settings::DiagnoseSettings;
use yarnhom_calib::shell::fit::{ShellFitSettings, fit_shell};
use yarnhom_calib::shell::membrane::MembraneModel;

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/stitch-by-stitch-acrylic");

#[test]
fn real_acrylic_swatches_fit_and_diagnose() {
    let (mut force, mut compression) = (Vec::new(), Vec::new());
    let (mut jammed_force, mut jammed_compression) = (Vec::new(), Vec::new());
    for pattern in ["stockinette", "garter", "rib", "seed"] {
        let files = ["x", "y"].map(|d| format!("{DATA}/acrylic-{pattern}-{d}.h5").into());
        let set = import_fabric(&files, 1).expect("imports").set;
        let fit = fit_shell(&set, &ShellFitSettings::default()).expect("fits");
        let refinement = fit.mesh_refinement_change.expect("the finer mesh has an equilibrium");
        eprintln!(
            "{pattern}: force {:.1}%, compression {:.1}%, refinement {:.1}%, {} iterations, {:.0} s",
            100.0 * fit.errors.force,
            100.0 * fit.errors.compression.expect("measured"),
            100.0 * refinement,
            fit.optimizer.iterations,
            fit.wall_time_s
        );
        assert!(refinement < 0.05, "{pattern}: the mesh resolves the swatch");
        assert_eq!(fit.unconstrained, vec!["k_ss".to_string()], "no bias tests in these files");
        force.push(fit.errors.force);
        compression.push(fit.errors.compression.expect("measured"));

        let settings = ShellFitSettings { model: MembraneModel::StvkNeoHookeanJamming, ..Default::default() };
        let jammed = fit_shell(&set, &settings).expect("fits");
        eprintln!(
            "  with jamming: force {:.1}%, compression {:.1}%, {:?}",
            100.0 * jammed.errors.force,
            100.0 * jammed.errors.compression.expect("measured"),
            jammed.material.jamming
        );
        jammed_force.push(jammed.errors.force);
        jammed_compression.push(jammed.errors.compression.expect("measured"));

        let d = diagnose(&set, &DiagnoseSettings::default()).expect("diagnoses");
        eprintln!(
            "  diagnosis: {} ({:.3} -> {:.3})",
            d.cause.id.as_str(),
            d.gain.heldout_error_before,
            d.gain.heldout_error_after
        );
        assert_ne!(
            d.cause.id,
            CauseId::None,
            "{pattern}: the base StVK misses these fabrics by far more than their noise"
        );
        let hysteresis = d.candidates.iter().find(|c| c.id == "friction-hysteresis").expect("listed");
        assert!(!hysteresis.testable, "the videos record loading only");
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    eprintln!("mean: force {:.1}%, compression {:.1}%", 100.0 * mean(&force), 100.0 * mean(&compression));
    eprintln!(
        "mean with jamming: force {:.1}%, compression {:.1}%",
        100.0 * mean(&jammed_force),
        100.0 * mean(&jammed_compression)
    );
    // Thesis Sec. 6.3.1 over 33 fabrics: 17.59% force, 16.84% compression. With (6.1) alone
    // these four meet the force figure and miss the compression one (the discrepancy the
    // diagnosis names); with the jamming it finds (`two-phase-contact`) they meet both.
    assert!(mean(&force) <= 0.1759, "force error {}", mean(&force));
    assert!(mean(&compression) > 0.1684, "(6.1) alone meets the compression figure: {}", mean(&compression));
    assert!(mean(&jammed_force) <= 0.1759, "force error with jamming {}", mean(&jammed_force));
    assert!(
        mean(&jammed_compression) <= 0.1684,
        "compression error with jamming {}",
        mean(&jammed_compression)
    );
    for (j, plain) in jammed_compression.iter().zip(&compression) {
        assert!(*j <= plain + 0.01, "the nested fit does not lose compression: {j} vs {plain}");
    }
}
