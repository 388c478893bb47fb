//! The stitch-by-stitch importer on the real acrylic files.

#![cfg(feature = "hdf5")]

use std::path::{Path, PathBuf};

use hdf5::types::VarLenUnicode;
use yarnhom_calib::data::set::{Direction, MeasurementSet, PatternSource, Phase, StretchPoint};
use yarnhom_calib::data::stitch_by_stitch::{
    Import, SATURATION_FORCE_N, StretchGauge, import, import_fabric,
};

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
            let dropped = video.dropped_saturated + video.dropped_glitches + video.dropped_nan;
            assert_eq!(kept + dropped, video.frames, "{name}");
            assert_eq!(video.gauge, Some(StretchGauge::Pins), "{name}: 7 tracked points");
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

#[test]
fn gauge_glitches_are_dropped_and_counted() {
    // Per video, the readings the glitch rule drops (the counts of the module docs).
    let expected = [
        ("acrylic-garter-x", [1, 0, 0, 0, 0]),
        ("acrylic-garter-y", [1, 0, 1, 0, 0]),
        ("acrylic-rib-x", [0, 2, 2, 1, 1]),
        ("acrylic-rib-y", [1, 0, 0, 0, 0]),
        ("acrylic-seed-x", [0, 2, 2, 2, 0]),
        ("acrylic-seed-y", [0, 0, 0, 0, 0]),
        ("acrylic-stockinette-x", [0, 0, 0, 3, 2]),
        ("acrylic-stockinette-y", [0, 0, 0, 0, 0]),
    ];
    let mut total = 0;
    for (name, counts) in expected {
        let imported = import(&file(name), 1).expect("import");
        let glitches: Vec<usize> = imported.videos.iter().map(|v| v.dropped_glitches).collect();
        assert_eq!(glitches, counts, "{name}");
        total += glitches.iter().sum::<usize>();
        let report = imported.report();
        let total_line = report.lines().last().expect("a total line");
        let sum = counts.iter().sum::<usize>();
        assert!(
            total_line.starts_with("total: ") && total_line.contains(&format!(" {sum} glitches")),
            "{name}"
        );
    }
    assert_eq!(total, 21);
    // Garter y video 3, frame 166: 7.98 N at 7.7 % stretch among readings of 0.97 to 1.04 N.
    let garter = import(&file("acrylic-garter-y"), 1).expect("import");
    assert!(
        !garter.set.stretch.iter().any(|p| p.repeat == Some(3) && p.stretch < 0.1 && p.force_n > 5.0),
        "the spike is dropped"
    );
}

/// Write `data` as the f64 dataset `name` of `shape` in `file`.
fn write_dataset(file: &hdf5::File, name: &str, shape: &[usize], data: &[f64]) {
    let dataset = file.new_dataset::<f64>().shape(shape).create(name).expect("create");
    dataset.write_raw(data).expect("write");
}

/// Copy the stitch-by-stitch file `source` to `target`, keeping the rows `rows(N)` (in that
/// order) of each `/videoN/traj` and everything else as it is.
fn write_copy(source: &Path, target: &Path, rows: impl Fn(u32) -> &'static [usize]) {
    let from = hdf5::File::open(source).expect("open");
    let to = hdf5::File::create(target).expect("create");
    let description: VarLenUnicode = from.attr("description").expect("attr").read_scalar().expect("read");
    let attribute = to.new_attr::<VarLenUnicode>().create("description").expect("attr");
    attribute.write_scalar(&description).expect("write");
    let read = |name: &str| {
        let dataset = from.dataset(name).expect("dataset");
        (dataset.read_raw::<f64>().expect("read"), dataset.shape())
    };
    let copy = |name: &str| {
        let (data, shape) = read(name);
        write_dataset(&to, name, &shape, &data);
    };
    copy("clampSize");
    copy("fabricSize");
    for repeat in 1..=5 {
        let group = format!("video{repeat}");
        to.create_group(&group).expect("group");
        copy(&format!("{group}/forces"));
        copy(&format!("{group}/frames"));
        let (data, shape) = read(&format!("{group}/traj"));
        let n = shape[2];
        let rows = rows(repeat);
        let kept: Vec<f64> =
            rows.iter().flat_map(|&r| data[r * 2 * n..(r + 1) * 2 * n].iter().copied()).collect();
        write_dataset(&to, &format!("{group}/traj"), &[rows.len(), 2, n], &kept);
    }
}

/// Rows right pin, left pin, bottom clamp and top clamp of the 7-row files.
const FOUR_OF_SEVEN: [usize; 4] = [0, 1, 5, 6];

/// Rows of the 7-row files as they are.
const SEVEN: [usize; 7] = [0, 1, 2, 3, 4, 5, 6];

#[test]
fn four_point_files_read_the_stretch_between_the_clamps() {
    let source = file("acrylic-rib-x");
    let dir = tempfile::tempdir().expect("tempdir");
    let derived = dir.path().join("acrylic-rib-x.h5");
    write_copy(&source, &derived, |_| &FOUR_OF_SEVEN);
    let seven = import(&source, 1).expect("import");
    let four = import(&derived, 1).expect("import");

    // The clamp-distance stretch and the left/right pin compression, per video and frame, from
    // the 7-row file's clamp and pin rows.
    let h5 = hdf5::File::open(&source).expect("open");
    for (repeat, report) in (1..=5).zip(&four.videos) {
        let traj = h5.dataset(&format!("video{repeat}/traj")).expect("traj");
        let (data, n) = (traj.read_raw::<f64>().expect("read"), traj.shape()[2]);
        let distance = |a: usize, b: usize, i: usize| {
            let at = |row: usize, axis: usize| data[(row * 2 + axis) * n + i];
            (at(a, 0) - at(b, 0)).hypot(at(a, 1) - at(b, 1))
        };
        let stretch: Vec<f64> = (0..n).map(|i| distance(6, 5, i) / distance(6, 5, 0) - 1.0).collect();
        let compression: Vec<f64> = (0..n).map(|i| 1.0 - distance(1, 0, i) / distance(1, 0, 0)).collect();
        let forces: Vec<f64> =
            h5.dataset(&format!("video{repeat}/forces")).expect("forces").read_raw().expect("read");
        let points = |imported: &Import| -> Vec<StretchPoint> {
            imported.set.stretch.iter().filter(|p| p.repeat == Some(repeat)).cloned().collect()
        };
        let (four_points, seven_points) = (points(&four), points(&seven));
        // The same frames are kept: saturation and glitches are read off the forces alone.
        assert_eq!(four_points.len(), seven_points.len(), "video{repeat}");
        assert!(
            four_points.iter().zip(&seven_points).any(|(p, q)| (p.stretch - q.stretch).abs() > 0.01),
            "video{repeat}: the clamps stretch differently from the pins"
        );
        let mut frame = 0;
        for (p, q) in four_points.iter().zip(&seven_points) {
            assert_eq!((p.force_n, p.compression), (q.force_n, q.compression), "video{repeat}");
            // Points are in frame order: find this one's frame by its force and compression.
            while forces[frame] != p.force_n
                || (compression[frame] - p.compression.expect("measured")).abs() > 1e-12
            {
                frame += 1;
            }
            assert!((p.stretch - stretch[frame]).abs() < 1e-12, "video{repeat}, frame {frame}");
            frame += 1;
        }
        assert_eq!(report.gauge, Some(StretchGauge::Clamps));
        let seven_report = &seven.videos[repeat as usize - 1];
        assert_eq!(report.dropped_glitches, seven_report.dropped_glitches, "video{repeat}");
        assert_eq!(report.dropped_saturated, seven_report.dropped_saturated, "video{repeat}");
    }
    let (swatch, pins) = (&four.set.fabric.swatch, &seven.set.fabric.swatch);
    assert_eq!(swatch.stretch_gauge_m, Some(swatch.length_m), "the clamp distance is the gauge");
    assert_eq!((swatch.length_m, swatch.width_m), (pins.length_m, pins.width_m));
    assert_eq!(swatch.compression_gauge_m, pins.compression_gauge_m);
    assert!(four.report().contains("stretch from the clamps") && !four.report().contains("pins"));
    assert!(seven.report().contains("stretch from the top/bottom pins"));
}

#[test]
fn a_file_mixing_gauges_is_refused() {
    let dir = tempfile::tempdir().expect("tempdir");
    let derived = dir.path().join("acrylic-stockinette-y.h5");
    write_copy(
        &file("acrylic-stockinette-y"),
        &derived,
        |repeat| if repeat == 1 { &SEVEN } else { &FOUR_OF_SEVEN },
    );
    let message = import(&derived, 1).expect_err("refused").to_string();
    assert!(message.contains("acrylic-stockinette-y.h5"), "{message}");
    assert!(
        message.contains("video2 reads the stretch between the clamps, video1 between the top/bottom pins"),
        "{message}"
    );
}

#[test]
fn the_acrylic_sets_carry_the_authors_stitches() {
    // The authors' configs (`code/fabric_simulations/<pattern>config.dat`, mm): stitch length,
    // yarn radius, core radius.
    let configs = [
        ("garter", 10.55, 0.54, 0.255),
        ("rib", 16.10, 1.18, 0.41),
        ("seed", 15.67, 1.20, 0.285),
        ("stockinette", 11.28, 0.74, 0.325),
    ];
    let dir = tempfile::tempdir().expect("tempdir");
    for (pattern, length, radius, core) in configs {
        let paths = [file(&format!("acrylic-{pattern}-x")), file(&format!("acrylic-{pattern}-y"))];
        let imported = import_fabric(&paths, 50).expect("import");
        let stitch = imported.set.fabric.stitch.expect("a stitch");
        let mm = |v: f64| v * 1e3;
        assert!((mm(stitch.length_m) - length).abs() < 1e-9, "{pattern}: {stitch:?}");
        assert!((mm(stitch.yarn_radius_m) - radius).abs() < 1e-9, "{pattern}: {stitch:?}");
        assert!((mm(stitch.core_radius_m.expect("core")) - core).abs() < 1e-9, "{pattern}: {stitch:?}");
        assert_eq!((stitch.courses_per_m, stitch.wales_per_m), (None, None));
        let report = imported.report();
        let first = report.lines().next().expect("lines");
        assert!(
            first.starts_with("stitch: from the authors' yarn-level simulations (sabetta/stitch-by-stitch"),
            "{first}"
        );
        assert!(report.lines().last().expect("lines").starts_with("total: "));
        // Written to fabric.toml and read back exactly.
        let set_dir = dir.path().join(pattern);
        imported.set.write(&set_dir).expect("write");
        assert_eq!(MeasurementSet::read(&set_dir).expect("read").fabric.stitch, Some(stitch));
        // A single file gets it too.
        assert_eq!(import(&paths[0], 50).expect("import").set.fabric.stitch, Some(stitch));
        // The set's tile is generated for it: the stitch's yarn radius and length per stitch.
        let PatternSource::Generator(generator) =
            imported.set.fabric.pattern_source(&set_dir).expect("a generator")
        else {
            panic!("{pattern}: a generator")
        };
        let tile = generator.generate().expect("generates");
        assert!(tile.yarns.iter().all(|y| y.radius_m == stitch.yarn_radius_m), "{pattern}");
        let per_stitch = yarnhom_pattern::length_per_stitch_m(&tile).expect("a generated knit");
        assert!((per_stitch / stitch.length_m - 1.0).abs() < 0.01, "{pattern}: {per_stitch}");
    }
}

#[test]
fn files_of_other_yarns_get_no_stitch() {
    let dir = tempfile::tempdir().expect("tempdir");
    let renamed = dir.path().join("cotton-rib-x.h5");
    std::fs::copy(file("acrylic-rib-x"), &renamed).expect("copy");
    let imported = import(&renamed, 50).expect("import");
    assert_eq!(imported.set.fabric.stitch, None);
    assert!(!imported.report().contains("stitch:"));
}
