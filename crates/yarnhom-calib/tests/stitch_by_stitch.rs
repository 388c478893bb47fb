//! The stitch-by-stitch importer on the real acrylic files.

#![cfg(feature = "hdf5")]

use std::path::PathBuf;

use yarnhom_calib::data::set::{Direction, MeasurementSet, Phase, StretchPoint};
use yarnhom_calib::data::stitch_by_stitch::{SATURATION_FORCE_N, import};

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/stitch-by-stitch-acrylic/");

const FILES: [&str; 8] = [
    "acrylic-garter-x",
    "acrylic-garter-y",
    "acrylic-rib-x",
    "acrylic-rib-y",
    "acrylic-seed-x",
    "acrylic-seed-y",
    "acrylic-stockinette-x",
    "acrylic-stockinette-y",
];

fn file(name: &str) -> PathBuf {
    PathBuf::from(format!("{DATA}{name}.h5"))
}

/// Load points of video 1.
fn video1_load(name: &str) -> Vec<StretchPoint> {
    let imported = import(&file(name), 1).expect("import");
    imported.set.stretch.into_iter().filter(|p| p.repeat == Some(1) && p.phase == Phase::Load).collect()
}

/// Smallest and largest (stretch, compression) over the load points nearest in force to
/// `force_n` (every point at the smallest |force - force_n|).
///
/// The data notes' figures are single frames: the gauge reads to 0.01 N and dithers by up to
/// 1 N from frame to frame, so several frames (for rib X at 2 N, frames from stretch 0.75 to
/// 1.08, where the swatch unfolds at almost constant force) tie for nearest. A figure is
/// reproduced when it lies in the range of the tied frames, widened by `tolerance`.
fn nearest_in_force(points: &[StretchPoint], force_n: f64) -> [(f64, f64); 2] {
    let error = |p: &StretchPoint| (p.force_n - force_n).abs();
    let best = points.iter().map(error).fold(f64::INFINITY, f64::min);
    let tied: Vec<&StretchPoint> = points.iter().filter(|p| error(p) <= best + 1e-9).collect();
    let span = |values: Vec<f64>| {
        (
            values.iter().copied().fold(f64::INFINITY, f64::min),
            values.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        )
    };
    [
        span(tied.iter().map(|p| p.stretch).collect()),
        span(tied.iter().map(|p| p.compression.expect("compression")).collect()),
    ]
}

/// `expected` lies in `range` widened by 3 % of `expected` plus `absolute`.
fn within(range: (f64, f64), expected: f64, absolute: f64) -> bool {
    let slack = 0.03 * expected.abs() + absolute;
    range.0 - slack <= expected && expected <= range.1 + slack
}

#[test]
fn sanity_figures_of_the_notes_are_reproduced() {
    // (file, force N, stretch, contraction) from NOTES.md, video 1.
    let figures = [
        ("acrylic-stockinette-x", 2.0, 0.075, 0.003),
        ("acrylic-stockinette-x", 10.0, 0.32, 0.13),
        ("acrylic-stockinette-y", 2.0, 0.024, 0.014),
        ("acrylic-stockinette-y", 10.0, 0.12, 0.05),
        ("acrylic-rib-x", 2.0, 1.08, 0.13),
        ("acrylic-rib-x", 10.0, 1.70, 0.31),
        ("acrylic-rib-y", 2.0, 0.078, -0.01),
        ("acrylic-rib-y", 10.0, 0.39, 0.05),
    ];
    for (name, force_n, stretch, contraction) in figures {
        let [s, c] = nearest_in_force(&video1_load(name), force_n);
        // The notes round to two significant digits: 0.005 absolute on small contractions.
        assert!(within(s, stretch, 0.001), "{name} at {force_n} N: stretch {s:?}, notes {stretch}");
        assert!(
            within(c, contraction, 0.005),
            "{name} at {force_n} N: contraction {c:?}, notes {contraction}"
        );
    }
}

#[test]
fn single_frame_figures_of_stockinette_match_closely() {
    // Where one frame is nearest, it is the notes' frame: equal within 3 % plus half a unit of
    // the notes' last digit (they round to two significant digits).
    for (name, force_n, stretch) in
        [("acrylic-stockinette-x", 10.0, 0.32), ("acrylic-stockinette-y", 10.0, 0.12)]
    {
        let [s, _] = nearest_in_force(&video1_load(name), force_n);
        assert!((s.1 - s.0) < 1e-12, "{name}: several frames tie");
        assert!((s.0 - stretch).abs() <= 0.03 * stretch + 0.005, "{name}: {} vs {stretch}", s.0);
    }
}

#[test]
fn every_file_imports_and_round_trips() {
    for name in FILES {
        let imported = import(&file(name), 1).expect("import");
        let set = &imported.set;
        let direction = if name.ends_with("-x") { Direction::Weft } else { Direction::Warp };
        assert!(set.stretch.iter().all(|p| p.direction == direction), "{name}");
        assert!(set.stretch.iter().all(|p| p.force_n < SATURATION_FORCE_N), "{name}");
        assert_eq!(imported.videos.len(), 5, "{name}");
        for video in &imported.videos {
            let kept = video.load + video.unload;
            assert_eq!(kept + video.dropped_saturated + video.dropped_nan, video.frames, "{name}");
            assert!(video.load > 1000, "{name}: video{} has {} load points", video.repeat, video.load);
        }
        assert!(name.contains(&set.fabric.pattern), "{name}: pattern {}", set.fabric.pattern);
        let swatch = &set.fabric.swatch;
        assert!((0.03..0.12).contains(&swatch.length_m) && (0.03..0.16).contains(&swatch.width_m), "{name}");
        let (stretch_gauge, compression_gauge) =
            (swatch.stretch_gauge_m.expect("pins"), swatch.compression_gauge_m.expect("pins"));
        assert!(
            stretch_gauge > 0.5 * swatch.length_m && stretch_gauge < swatch.length_m,
            "{name}: {stretch_gauge}"
        );
        assert!(compression_gauge > 0.3 * swatch.width_m && compression_gauge <= swatch.width_m, "{name}");
        let dir = tempfile::tempdir().expect("tempdir");
        set.write(dir.path()).expect("write");
        assert_eq!(&MeasurementSet::read(dir.path()).expect("read back"), set, "{name}");
    }
}

#[test]
fn saturated_readings_are_dropped_and_counted() {
    let imported = import(&file("acrylic-stockinette-y"), 1).expect("import");
    let dropped: usize = imported.videos.iter().map(|v| v.dropped_saturated).sum();
    // Every stockinette-y video reaches the gauge's ceiling (see the module docs).
    assert!(imported.videos.iter().all(|v| v.dropped_saturated > 0));
    assert!(dropped > 100, "{dropped}");
    assert!(imported.report().contains("saturated"));
}

#[test]
fn thinning_keeps_every_nth_point_per_phase() {
    let all = import(&file("acrylic-stockinette-y"), 1).expect("import");
    let thinned = import(&file("acrylic-stockinette-y"), 10).expect("import");
    for (a, t) in all.videos.iter().zip(&thinned.videos) {
        assert_eq!(t.load, a.load.div_ceil(10));
        assert_eq!(t.unload, a.unload.div_ceil(10));
        assert_eq!(t.load + t.unload + t.dropped_thinning, a.load + a.unload);
    }
}

#[test]
fn stretch_starts_at_zero_and_unload_follows_the_peak() {
    let imported = import(&file("acrylic-stockinette-x"), 1).expect("import");
    for repeat in 1..=5 {
        let points: Vec<&StretchPoint> =
            imported.set.stretch.iter().filter(|p| p.repeat == Some(repeat)).collect();
        assert_eq!(points[0].stretch, 0.0);
        assert_eq!(points[0].compression, Some(0.0));
        let peak = points.iter().filter(|p| p.phase == Phase::Load).map(|p| p.stretch).fold(0.0, f64::max);
        assert!(points.iter().filter(|p| p.phase == Phase::Unload).all(|p| p.stretch <= peak));
    }
}
