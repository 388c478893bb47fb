//! `yarnhom measure`: import the real stitch-by-stitch data, check sets, refuse bad ones.

use std::path::Path;
use std::process::{Command, Output};

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/stitch-by-stitch-acrylic");

fn yarnhom(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_yarnhom")).args(args).current_dir(cwd).output().expect("run yarnhom")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

#[cfg(feature = "hdf5")]
#[test]
fn import_stockinette_x_then_check() {
    let dir = tempfile::tempdir().expect("tempdir");
    let input = format!("{DATA}/acrylic-stockinette-x.h5");
    let o = yarnhom(&["measure", "import-stitch-by-stitch", &input, "-o", "set"], dir.path());
    assert!(o.status.success(), "import failed: {}", text(&o.stderr));
    let report = text(&o.stderr);
    assert!(report.contains("weft video5:") && report.contains("saturated"), "{report}");
    assert!(dir.path().join("set/fabric.toml").exists() && dir.path().join("set/stretch.csv").exists());

    let o = yarnhom(&["measure", "check", "set"], dir.path());
    assert!(o.status.success(), "check failed: {}", text(&o.stderr));
    let summary = text(&o.stdout);
    for expected in ["pattern stockinette", "weft load:", "5 repeats", "bending points: 0"] {
        assert!(summary.contains(expected), "missing '{expected}' in:\n{summary}");
    }
    assert!(!summary.contains("warp"), "{summary}");
}

#[test]
fn a_bad_csv_exits_2_naming_the_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let set = dir.path().join("set");
    std::fs::create_dir(&set).expect("mkdir");
    std::fs::write(set.join("fabric.toml"), "name = \"bad\"\npattern = \"rib\"\n").expect("write");
    std::fs::write(set.join("stretch.csv"), "direction,stretch,force_n\nweft,0.1,1\nweft,0.2,nan\n")
        .expect("write");
    let o = yarnhom(&["measure", "check", "set"], dir.path());
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err}");
    assert!(err.contains("stretch.csv:3: column `force_n`"), "{err}");
}

#[cfg(feature = "hdf5")]
#[test]
fn a_fabrics_x_and_y_files_import_into_one_set_with_a_swatch_per_direction() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (x, y) = (format!("{DATA}/acrylic-rib-x.h5"), format!("{DATA}/acrylic-rib-y.h5"));
    let o =
        yarnhom(&["measure", "import-stitch-by-stitch", &x, &y, "-o", "set", "--every", "20"], dir.path());
    assert!(o.status.success(), "import failed: {}", text(&o.stderr));
    let fabric = std::fs::read_to_string(dir.path().join("set/fabric.toml")).expect("fabric.toml");
    for expected in
        ["name = \"acrylic-rib\"", "[swatch.weft]", "[swatch.warp]", "stretch_gauge_m", "compression_gauge_m"]
    {
        assert!(fabric.contains(expected), "missing '{expected}' in:\n{fabric}");
    }
    let o = yarnhom(&["measure", "check", "set"], dir.path());
    let summary = text(&o.stdout);
    assert!(summary.contains("weft load:") && summary.contains("warp load:"), "{summary}");
    assert!(summary.contains("swatch (warp):") && summary.contains("stretch read over"), "{summary}");

    let stock = format!("{DATA}/acrylic-stockinette-y.h5");
    let o = yarnhom(&["measure", "import-stitch-by-stitch", &x, &stock, "-o", "mixed"], dir.path());
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o.stderr).contains("pattern 'stockinette' differs from 'rib'"), "{}", text(&o.stderr));
    let o = yarnhom(&["measure", "import-stitch-by-stitch", &x, &x, "-o", "twice"], dir.path());
    assert!(text(&o.stderr).contains("a second file for direction 'weft'"), "{}", text(&o.stderr));
}
