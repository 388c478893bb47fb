//! The `yarnhom` binary end to end: the acceptance commands of the foundation issue.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use yarnhom_artifacts::container::{self, Provenance};
use yarnhom_artifacts::{Artifact, Pattern};

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/hylc-patterns");

fn yarnhom(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_yarnhom")).args(args).current_dir(cwd).output().expect("run yarnhom")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn ok(args: &[&str], cwd: &Path) -> String {
    let o = yarnhom(args, cwd);
    assert!(o.status.success(), "yarnhom {args:?} failed: {}", stderr(&o));
    stdout(&o)
}

/// Exit status 2 with a one-line `error: ...` naming `problem`, and no panic.
fn fails_with(args: &[&str], cwd: &Path, problem: &str) {
    let o = yarnhom(args, cwd);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "yarnhom {args:?}: {err}");
    assert!(!err.contains("panicked"), "yarnhom {args:?} panicked: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err}");
    assert_eq!(err.matches(problem).count(), 1, "yarnhom {args:?}: expected '{problem}' once in: {err}");
}

fn rib(dir: &Path) -> PathBuf {
    let out = dir.join("rib.pattern.yh");
    ok(&["pattern", "import", &format!("{DATA}/rib.pyp"), "-o", out.to_str().expect("utf8")], dir);
    out
}

#[test]
fn import_and_inspect_show_the_published_rib() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = rib(dir.path());
    let text = ok(&["inspect", out.to_str().expect("utf8")], dir.path());
    // The published header: px py radius n = 0.0174261 0.0116613 0.001001 356.
    for expected in [
        "kind: pattern v1",
        "17.4261 mm x 11.6613 mm",
        "vertices: 356",
        "yarn radius: 1.0010 mm",
        "knit fabric",
        "rest state: yes",
    ] {
        assert!(text.contains(expected), "missing '{expected}' in:\n{text}");
    }
    assert!(text.contains("input: pyp sha256:"), "provenance of the .pyp missing:\n{text}");
}

/// The RMS distance of the vertices from their mirror images, in radii, as `pattern mirror`
/// prints it ("vertices from their images: X mm RMS (R radii), ...").
fn vertex_distance_radii(text: &str) -> f64 {
    let line = text.lines().find(|l| l.contains("vertices from their images")).expect("the vertex line");
    let (_, rest) = line.split_once("mm RMS (").expect("RMS in radii");
    rest.split_once(" radii").and_then(|(r, _)| r.parse().ok()).expect("a number of radii")
}

#[test]
fn pattern_mirror_reports_the_published_stockinettes_asymmetry_and_writes_its_image() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let stock = format!("{DATA}/stock.pyp");
    let text = ok(&["pattern", "mirror", &stock, "-o", "image.pattern.yh"], d);
    for expected in ["mirror X1 -> -X1 of stock", "yarn 0 <- yarn 0, backwards"] {
        assert!(text.contains(expected), "missing '{expected}' in:\n{text}");
    }
    // Off its mirror image, but by less than a yarn radius (the published tile is nearly
    // symmetric about its wale axis).
    let radii = vertex_distance_radii(&text);
    assert!(radii > 0.0 && radii < 1.0, "{text}");
    // A mirror is an involution: the image is exactly as far from its own image, and
    // remembers where it came from.
    let again = ok(&["pattern", "mirror", "image.pattern.yh"], d);
    assert_eq!(vertex_distance_radii(&again), radii, "{again}");
    assert!(ok(&["inspect", "image.pattern.yh"], d).contains("mirrored X1 -> -X1"));
    fails_with(&["pattern", "mirror", "missing.pyp"], d, "missing.pyp");
}

#[test]
fn damaged_files_give_one_line_errors_and_exit_2() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = rib(dir.path());
    let bytes = std::fs::read(&path).expect("read");
    let write = |name: &str, b: &[u8]| {
        let p = dir.path().join(name);
        std::fs::write(&p, b).expect("write");
        p.to_str().expect("utf8").to_string()
    };
    let truncated = write("truncated.pattern.yh", &bytes[..bytes.len() - 100]);
    fails_with(&["inspect", &truncated], dir.path(), "truncated file");
    let mut flipped = bytes.clone();
    flipped[bytes.len() / 2] ^= 0x10;
    let flipped = write("flipped.pattern.yh", &flipped);
    fails_with(&["inspect", &flipped], dir.path(), "checksum mismatch");
    // A file from a future yarnhom: a correctly framed payload with a newer schema version.
    let (_, pattern) = container::read::<Pattern>(&path).expect("read");
    let payload = container::payload_of(&pattern).expect("payload");
    let mut header = container::header_for::<Pattern>(&payload, &Provenance::default());
    header.schema_version = Pattern::SCHEMA_VERSION + 1;
    let bumped = write("bumped.pattern.yh", &container::frame(&header, &payload).expect("frame"));
    fails_with(&["inspect", &bumped], dir.path(), "schema version 2 is newer than the supported version 1");
    let mut newer_container = bytes.clone();
    newer_container[8] += 1;
    let newer_container = write("container.pattern.yh", &newer_container);
    fails_with(&["inspect", &newer_container], dir.path(), "container version 2 is newer");
    let garbage = write("garbage.pattern.yh", b"\x89YHOM\r\n\x1a\x01\x00\xff\xff\xff\xff");
    fails_with(&["diff", &garbage, &truncated], dir.path(), "truncated file");
    fails_with(&["inspect", "does-not-exist.yh"], dir.path(), "does-not-exist.yh");
    let text = write("notes.txt", b"hello");
    fails_with(&["convert", &text, "--to", "json"], dir.path(), "not a yarnhom artifact");
}

#[test]
fn diff_exits_0_for_equal_and_1_for_different_patterns() {
    let dir = tempfile::tempdir().expect("tempdir");
    let a = rib(dir.path());
    let a = a.to_str().expect("utf8");
    assert_eq!(yarnhom(&["diff", a, a], dir.path()).status.code(), Some(0));
    let b = dir.path().join("stock.pattern.yh");
    ok(&["pattern", "import", &format!("{DATA}/stock.pyp"), "-o", b.to_str().expect("utf8")], dir.path());
    let o = yarnhom(&["diff", a, b.to_str().expect("utf8")], dir.path());
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stdout(&o).contains("DIFFERENT"));
    // Moving one vertex by 1 um: different at the default tolerance, equal with atol = 2 um.
    let (_, mut moved) = container::read::<Pattern>(a).expect("read");
    moved.positions_m[7][2] += 1e-6;
    let c = dir.path().join("moved.pattern.yh");
    container::write(&c, &moved, &Provenance::default()).expect("write");
    let c = c.to_str().expect("utf8");
    let o = yarnhom(&["diff", a, c], dir.path());
    assert_eq!(o.status.code(), Some(1));
    assert!(stdout(&o).contains("worst at [7]"), "{}", stdout(&o));
    assert_eq!(yarnhom(&["diff", a, c, "--atol", "2e-6"], dir.path()).status.code(), Some(0));
    fails_with(&["diff", a, c, "--rtol", "-1"], dir.path(), "tolerances must be non-negative");
}

#[test]
fn conversions_are_lossless() {
    let dir = tempfile::tempdir().expect("tempdir");
    let a = rib(dir.path());
    let a = a.to_str().expect("utf8");
    for (format, file) in [("json", "rib.pattern.json"), ("hdf5", "rib.pattern.h5"), ("pyp", "rib.pyp")] {
        let out = dir.path().join(file);
        ok(&["convert", a, "--to", format, "-o", out.to_str().expect("utf8")], dir.path());
        let back = dir.path().join(format!("back-{format}.pattern.yh"));
        ok(
            &["convert", out.to_str().expect("utf8"), "--to", "yh", "-o", back.to_str().expect("utf8")],
            dir.path(),
        );
        let o = yarnhom(&["diff", a, back.to_str().expect("utf8"), "--rtol", "0"], dir.path());
        assert_eq!(o.status.code(), Some(0), "{format}: {}", stdout(&o));
    }
    fails_with(&["convert", a, "--to", "yh", "-o", a], dir.path(), "would overwrite the input");
}

#[test]
fn every_generator_writes_a_valid_pattern() {
    let dir = tempfile::tempdir().expect("tempdir");
    let list = ok(&["pattern", "list"], dir.path());
    for name in ["stockinette", "garter", "rib", "seed", "plain", "basket", "satin"] {
        assert!(list.contains(name), "{name} not listed");
        let out = dir.path().join(format!("{name}.pattern.yh"));
        ok(&["pattern", "generate", name, "-o", out.to_str().expect("utf8")], dir.path());
        let (_, p) = container::read::<Pattern>(&out).expect("a generated pattern reads back");
        assert_eq!(p.name, name);
    }
    fails_with(&["pattern", "generate", "argyle"], dir.path(), "argyle");
    fails_with(&["pattern", "generate", "rib", "--radius-m", "-0.001"], dir.path(), "radius");
}

#[test]
fn yarn_models_and_schemas() {
    let dir = tempfile::tempdir().expect("tempdir");
    let list = ok(&["model", "list"], dir.path());
    assert_eq!(list.lines().count(), 7, "Table 4.1 has seven rows:\n{list}");
    let out = dir.path().join("rib.yarnmodel.yh");
    ok(&["model", "write", "table4.1:rib", "-o", out.to_str().expect("utf8")], dir.path());
    let text = ok(&["inspect", out.to_str().expect("utf8")], dir.path());
    assert!(text.contains("youngs_modulus_pa = 500000"), "{text}");
    fails_with(&["model", "write", "table4.1:argyle"], dir.path(), "unknown yarn model");
    let fixture = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/yarnmodel.v0.yh");
    assert!(ok(&["inspect", fixture], dir.path()).contains("read through migration to v1"));
    // `convert --to yh` upgrades an old file to the current version, keeping its content.
    let upgraded = dir.path().join("upgraded.yarnmodel.yh");
    ok(&["convert", fixture, "--to", "yh", "-o", upgraded.to_str().expect("utf8")], dir.path());
    assert!(ok(&["inspect", upgraded.to_str().expect("utf8")], dir.path()).contains("kind: yarnmodel v1\n"));
    assert_eq!(
        yarnhom(&["diff", fixture, upgraded.to_str().expect("utf8"), "--rtol", "0"], dir.path())
            .status
            .code(),
        Some(0)
    );
    for kind in yarnhom_artifacts::KINDS {
        let schema: serde_json::Value =
            serde_json::from_str(&ok(&["schema", kind], dir.path())).expect("JSON");
        let version = yarnhom_artifacts::schema_version(kind).expect("known kind");
        assert_eq!(schema["$id"], format!("yarnhom:{kind}.v{version}"));
    }
    fails_with(&["schema", "teapot"], dir.path(), "unknown artifact kind 'teapot'");
    fails_with(&["convert", out.to_str().expect("utf8"), "--to", "pyp"], dir.path(), "only patterns");
}

#[test]
fn every_command_explains_itself() {
    let dir = tempfile::tempdir().expect("tempdir");
    let commands: &[&[&str]] = &[
        &[],
        &["pattern"],
        &["pattern", "list"],
        &["pattern", "generate"],
        &["pattern", "import"],
        &["pattern", "export"],
        &["model"],
        &["model", "list"],
        &["model", "write"],
        &["inspect"],
        &["convert"],
        &["schema"],
        &["diff"],
        &["rve"],
        &["rve", "solve"],
        &["rve", "relax"],
        &["rve", "sample"],
        &["grid", "merge"],
        &["fit"],
        &["fit", "import-arcsim"],
        &["fit", "export-arcsim"],
        &["fit", "plot"],
        &["fit", "compare"],
        &["shell"],
        &["shell", "simulate"],
        &["shell", "scene"],
        &["yls"],
        &["yls", "swatch"],
        &["yls", "simulate"],
    ];
    for cmd in commands {
        let mut args = cmd.to_vec();
        args.push("--help");
        let text = ok(&args, dir.path());
        assert!(text.contains("Usage:"), "{cmd:?} --help:\n{text}");
        assert!(text.lines().next().is_some_and(|l| l.len() > 20), "{cmd:?} has no description:\n{text}");
    }
}

#[test]
fn rve_solve_reports_energy_and_stress_and_refuses_bad_input() {
    let dir = tempfile::tempdir().expect("tempdir");
    let tiny = format!("{DATA}/stocktiniest.pyp");
    let out = dir.path().join("tiny.rvesolve.yh");
    let out_s = out.to_str().expect("utf8");
    let text = ok(
        &[
            "rve",
            "solve",
            &tiny,
            "--model",
            "table4.1:stock-small",
            "--strain",
            "sx=0.2,sy=-0.05",
            "--fd-stress",
            "-o",
            out_s,
        ],
        dir.path(),
    );
    assert!(text.contains("converged after"), "{text}");
    assert!(text.contains("stress (3.23c)") && text.contains("stress (finite differences)"), "{text}");
    let (_, solved) = container::read::<yarnhom_artifacts::RveSolve>(&out).expect("rvesolve reads back");
    assert!(solved.converged && solved.energy_density_j_m2.is_some_and(|e| e > 0.0));
    let (stress, fd) = (solved.stress.expect("stress"), solved.stress_fd.expect("fd stress"));
    assert!((stress[0] - fd[0]).abs() < 1e-2 * stress[0].abs(), "dsx: {stress:?} vs {fd:?}");
    assert_eq!(solved.positions_m.len(), 13);
    assert_eq!(yarnhom(&["diff", out_s, out_s], dir.path()).status.code(), Some(0));
    fails_with(
        &["rve", "solve", &tiny, "--model", "table4.1:stock-small", "--strain", "sa=1"],
        dir.path(),
        "|sa| < 1",
    );
    fails_with(
        &["rve", "solve", &tiny, "--model", "table4.1:stock-small", "--strain", "sx=-1.5"],
        dir.path(),
        "must be > -1",
    );
    fails_with(
        &["rve", "solve", &tiny, "--model", "table4.1:stock-small", "--strain", "sq=1"],
        dir.path(),
        "unknown parameter 'sq'",
    );
    fails_with(
        &["rve", "solve", &tiny, "--model", "table4.1:stock", "--strain", "sx=0.1"],
        dir.path(),
        "differs from the pattern's yarn radius",
    );
    let generated = dir.path().join("g.pattern.yh");
    ok(&["pattern", "generate", "stockinette", "-o", generated.to_str().expect("utf8")], dir.path());
    fails_with(
        &[
            "rve",
            "solve",
            generated.to_str().expect("utf8"),
            "--model",
            "table4.1:stock",
            "--strain",
            "sx=0.1",
        ],
        dir.path(),
        "has no rest state",
    );
}

#[test]
fn rve_relax_gives_a_generated_pattern_a_rest_state_without_in_plane_stress() {
    let dir = tempfile::tempdir().expect("tempdir");
    let generated = dir.path().join("g.pattern.yh");
    let g = generated.to_str().expect("utf8");
    ok(&["pattern", "generate", "stockinette", "-o", g], dir.path());
    fails_with(
        &["rve", "relax", g, "--model", "table4.1:stock", "--keep-rest-shape"],
        dir.path(),
        "needs a pattern with a rest state",
    );
    fails_with(
        &["rve", "relax", g, "--model", "table4.1:stock", "--estimation", "1.5"],
        dir.path(),
        "strictly between 0 and 1",
    );
    let relaxed = dir.path().join("r.pattern.yh");
    let r = relaxed.to_str().expect("utf8");
    let text = ok(&["rve", "relax", g, "--model", "table4.1:stock", "-o", r], dir.path());
    assert!(text.contains("in-plane stress at zero strain"), "{text}");
    let (_, pattern) = container::read::<yarnhom_artifacts::Pattern>(&relaxed).expect("pattern reads back");
    assert!(pattern.rest.is_some(), "a relaxed pattern carries its rest state");
    // Pre-tension (Algorithm 2) shrinks the knit's periods.
    assert!(pattern.period_m[0] < 8.4e-3 && pattern.period_m[1] < 4.4e-3, "{:?}", pattern.period_m);
    let solved = dir.path().join("s.rvesolve.yh");
    let text = ok(
        &[
            "rve",
            "solve",
            r,
            "--model",
            "table4.1:stock",
            "--strain",
            "sx=0",
            "-o",
            solved.to_str().expect("utf8"),
        ],
        dir.path(),
    );
    assert!(text.contains("converged after"), "{text}");
}

#[test]
fn rve_sample_shards_merge_into_the_unsharded_grid_and_a_killed_run_resumes() {
    let dir = tempfile::tempdir().expect("tempdir");
    let tiny = format!("{DATA}/stocktiniest.pyp");
    let args = |extra: &[&str], out: &str| -> Vec<String> {
        let mut a: Vec<String> =
            ["rve", "sample", &tiny, "--model", "table4.1:stock-small", "--n1d", "5", "--n2d", "3"]
                .iter()
                .map(|s| s.to_string())
                .collect();
        a.extend(extra.iter().map(|s| s.to_string()));
        a.extend(["-o".to_string(), out.to_string()]);
        a
    };
    let run = |a: Vec<String>| ok(&a.iter().map(String::as_str).collect::<Vec<_>>(), dir.path());
    let whole = dir.path().join("whole.grid.yh");
    let text = run(args(&[], whole.to_str().expect("utf8")));
    assert!(text.contains("complete"), "{text}");
    let mut shards = Vec::new();
    for k in 0..3 {
        let shard = dir.path().join(format!("shard-{k}.grid.yh"));
        run(args(&["--shard", &format!("{k}/3")], shard.to_str().expect("utf8")));
        shards.push(shard.to_str().expect("utf8").to_string());
    }
    let merged = dir.path().join("merged.grid.yh");
    let mut merge: Vec<&str> = vec!["grid", "merge"];
    merge.extend(shards.iter().map(String::as_str));
    merge.extend(["-o", merged.to_str().expect("utf8")]);
    ok(&merge, dir.path());
    let payload = |p: &std::path::Path| {
        let (_, g) = container::read::<yarnhom_artifacts::Grid>(p).expect("grid reads back");
        container::payload_of(&g).expect("payload")
    };
    assert_eq!(payload(&merged), payload(&whole), "merged shards differ from the unsharded run");
    // Overlapping shards are refused.
    fails_with(&["grid", "merge", &shards[0], &shards[0], "-o", "x.grid.yh"], dir.path(), "appears in");
    // Kill a run once its checkpoint holds finished lines; the rerun continues from there and
    // ends with the same grid as the uninterrupted run.
    let resumed = dir.path().join("resumed.grid.yh");
    let checkpoint = dir.path().join("resumed.grid.yh.checkpoint");
    let a = args(&[], resumed.to_str().expect("utf8"));
    let mut child = Command::new(env!("CARGO_BIN_EXE_yarnhom"))
        .args(&a)
        .current_dir(dir.path())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("run yarnhom");
    let header = 200;
    while std::fs::metadata(&checkpoint).map_or(0, |m| m.len()) < 4 * header {
        if child.try_wait().expect("child").is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    child.kill().ok();
    child.wait().expect("child ends");
    assert!(checkpoint.exists(), "the run was killed before it finished");
    let o = yarnhom(&a.iter().map(String::as_str).collect::<Vec<_>>(), dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("resumed from"), "{}", stderr(&o));
    assert!(!checkpoint.exists(), "a finished run removes its checkpoint");
    assert_eq!(payload(&resumed), payload(&whole), "the resumed run differs from the uninterrupted one");
    fails_with(
        &["rve", "sample", &tiny, "--model", "table4.1:stock-small", "--shard", "3/3"],
        dir.path(),
        "0 <= K < N",
    );
}

#[test]
fn rve_sample_takes_its_1d_and_2d_ranges_from_the_command_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let tiny: &'static str = format!("{DATA}/stocktiniest.pyp").leak();
    let base = ["rve", "sample", tiny, "--model", "table4.1:stock-small", "--n1d", "3", "--n2d", "3"];
    let with = |extra: &[&'static str]| [&base[..], extra].concat();
    ok(
        &with(&["--range", "sx=-0.2:0.4", "--plane-range", "ky,sa=-40:40,-0.3:0.3", "-o", "r.grid.yh"]),
        dir.path(),
    );
    let (_, grid) = container::read::<yarnhom_artifacts::Grid>(&dir.path().join("r.grid.yh")).expect("grid");
    assert_eq!(grid.terms[0].axes, [0]);
    assert_eq!(grid.terms[0].values[0], [-0.2, 0.0, 0.4]);
    let sa_ky = grid.terms.iter().find(|t| t.axes == [1, 4]).expect("sa,ky");
    assert_eq!(sa_ky.values, [vec![-0.3, 0.0, 0.3], vec![-40.0, 0.0, 40.0]], "axes put in order");
    let sx_sa = grid.terms.iter().find(|t| t.axes == [0, 1]).expect("sx,sa");
    assert_eq!(sx_sa.values, [vec![-0.1, 0.0, 0.67], vec![-0.6, 0.0, 0.6]], "the published stockinette's");
    // The ranges a published material was sampled over, then one overridden.
    let rib: &'static str = format!("{MATERIALS}/rib1.json").leak();
    ok(&with(&["--ranges-from", rib, "--range", "kx=-50:50", "-o", "rib.grid.yh"]), dir.path());
    let (_, grid) =
        container::read::<yarnhom_artifacts::Grid>(&dir.path().join("rib.grid.yh")).expect("grid");
    let ends = |axes: &[u8], slot: usize| {
        let values = &grid.terms.iter().find(|t| t.axes == axes).expect("term").values[slot];
        [values[0], values[values.len() - 1]]
    };
    let close = |a: [f64; 2], b: [f64; 2]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9 * y.abs());
    assert!(close(ends(&[0], 0), [-0.66, 0.99]), "rib's sx: {:?}", ends(&[0], 0));
    assert_eq!(ends(&[3], 0), [-50.0, 50.0], "--range applies after --ranges-from");
    assert!(close(ends(&[1, 4], 0), [-0.48, 0.48]) && close(ends(&[1, 4], 1), [-64.0, 64.0]));
    fails_with(&with(&["--ranges-from", tiny]), dir.path(), "--ranges-from");
    fails_with(&with(&["--range", "sa=-0.5:1"]), dir.path(), "|sa| < 1");
    fails_with(&with(&["--range", "kx=10:200"]), dir.path(), "0 strictly inside");
    fails_with(&with(&["--plane-range", "kx,ky=-1:1,-1:1"]), dir.path(), "never sampled together");
    for (args, problem) in [
        (with(&["--plane-range", "sa=-0.3:0.3"]), "expected A,B=MIN:MAX,MIN:MAX"),
        (with(&["--range", "sz=-1:1"]), "unknown axis 'sz'"),
    ] {
        let o = yarnhom(&args, dir.path());
        assert_eq!(o.status.code(), Some(2), "a usage error");
        assert!(stderr(&o).contains(problem), "{}", stderr(&o));
    }
}

#[test]
fn fit_writes_a_spline_that_reproduces_its_grid_and_plots_it() {
    let dir = tempfile::tempdir().expect("tempdir");
    let grid = dir.path().join("synthetic.grid.yh");
    let provenance = Provenance {
        producer: yarnhom_artifacts::Producer { name: "test".into(), version: "0".into() },
        inputs: vec![],
    };
    container::write(&grid, &yarnhom_fit::synthetic::synthetic_grid(), &provenance).expect("grid");
    let report = ok(&["fit", "synthetic.grid.yh", "-o", "synthetic.spline.yh"], dir.path());
    assert!(report.contains("sx,kx") && report.contains("relative RMS"), "{report}");
    let inspect = ok(&["inspect", "synthetic.spline.yh"], dir.path());
    assert!(inspect.contains("spline") && inspect.contains("fitted by yarnhom"), "{inspect}");
    let o =
        yarnhom(&["fit", "plot", "synthetic.grid.yh", "synthetic.spline.yh", "-o", "figures"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let svgs = std::fs::read_dir(dir.path().join("figures")).expect("figures").count();
    assert_eq!(svgs, 14, "one figure per term of the grid");
    assert_eq!(stderr(&o).lines().filter(|l| l.ends_with(".svg")).count(), 14, "each named as written");
    fails_with(
        &["fit", "synthetic.spline.yh", "-o", "x.spline.yh"],
        dir.path(),
        "expected a 'grid' artifact but the file holds 'spline'",
    );
    let limited =
        ok(&["fit", "synthetic.grid.yh", "--limit", "kx=-100:150", "-o", "limited.spline.yh"], dir.path());
    assert!(limited.contains("samples used"), "{limited}");
    let o = yarnhom(&["fit", "synthetic.grid.yh", "--limit", "kx=10:150", "-o", "x.spline.yh"], dir.path());
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("must contain 0"), "{}", stderr(&o));
}

#[test]
fn published_materials_round_trip_and_simulate_into_a_streamed_trace() {
    let dir = tempfile::tempdir().expect("tempdir");
    let published = format!("{}/../../../shared/data/hylc-materials/satin1.json", env!("CARGO_MANIFEST_DIR"));
    ok(&["fit", "import-arcsim", &published, "-o", "satin.spline.yh"], dir.path());
    ok(&["fit", "export-arcsim", "satin.spline.yh", "-o", "satin.json"], dir.path());
    let (a, b) = (
        std::fs::read_to_string(&published).expect("published"),
        std::fs::read_to_string(dir.path().join("satin.json")).expect("ours"),
    );
    let (a, b): (serde_json::Value, serde_json::Value) =
        (serde_json::from_str(&a).expect("json"), serde_json::from_str(&b).expect("json"));
    assert_eq!(a["coeffs"], b["coeffs"], "every coefficient survives import and export");

    // Three frames of the drape on a 9 x 9 mesh, streamed to stdout, read back as a trace.
    let out = yarnhom(
        &[
            "shell",
            "simulate",
            "drape",
            "--material",
            "satin.spline.yh",
            "-o",
            "-",
            "--frames",
            "3",
            "--resolution",
            "9",
            "--obj-dir",
            "obj",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let messages: Vec<_> =
        yarnhom_trace::TraceReader::new(&out.stdout[..]).collect::<Result<_, _>>().expect("a complete trace");
    let count = |f: &dyn Fn(&yarnhom_trace::TraceMessage) -> bool| messages.iter().filter(|m| f(m)).count();
    assert_eq!(count(&|m| matches!(m, yarnhom_trace::TraceMessage::Topology(_))), 1);
    assert_eq!(count(&|m| matches!(m, yarnhom_trace::TraceMessage::Frame(_))), 4);
    assert_eq!(count(&|m| matches!(m, yarnhom_trace::TraceMessage::Scalars(_))), 4);
    assert_eq!(count(&|m| matches!(m, yarnhom_trace::TraceMessage::Solver(_))), 12, "4 steps per frame");
    let Some(yarnhom_trace::TraceMessage::Frame(last)) =
        messages.iter().rev().find(|m| matches!(m, yarnhom_trace::TraceMessage::Frame(_)))
    else {
        panic!("no frame")
    };
    assert_eq!(last.positions_m.len(), 81);
    assert!(last.positions_m.iter().any(|p| p[2] < -1e-4), "the cloth falls");
    assert_eq!(std::fs::read_dir(dir.path().join("obj")).expect("obj dir").count(), 4);

    fails_with(
        &["shell", "simulate", "wave", "--material", "satin.spline.yh", "-o", "x.mcap"],
        dir.path(),
        "neither a built-in scene",
    );
    std::fs::write(dir.path().join("bad.json"), "{\"membrane\": 1}").expect("write");
    fails_with(
        &["shell", "simulate", "drape", "--material", "bad.json", "-o", "x.mcap"],
        dir.path(),
        "not a Ch. 6 material",
    );
    let scene = ok(&["shell", "scene", "stretch-x", "-o", "scene.json"], dir.path());
    assert!(scene.contains("scene.json"));
    let simulate_scene = |extra: &[&str]| {
        let args = ["shell", "simulate", "scene.json", "--material", published.as_str(), "--frames", "1"];
        yarnhom(&[&args[..], extra].concat(), dir.path())
    };
    let out = simulate_scene(&[
        "-o",
        "s.mcap",
        "--resolution",
        "7",
        "--newton-matrix",
        "gauss-newton",
        "--linear-solver",
        "cholesky",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("0 conjugate gradient iterations"), "{}", stderr(&out));
    let trace = std::fs::read(dir.path().join("s.mcap")).expect("trace");
    let metadata = yarnhom_trace::read_metadata(&trace).expect("metadata");
    assert_eq!(metadata[0].entries["newton_matrix"], "gauss-newton");
    assert_eq!(metadata[0].entries["linear_solver"], "cholesky");
    let out = simulate_scene(&["-o", "t.mcap", "--newton-matrix", "exact"]);
    assert!(!out.status.success() && stderr(&out).contains("possible values: projected, gauss-newton"));

    // The Ch. 6 model (6.1), (6.4) from its JSON file.
    let ch6 = format!("{}/../../tools/materials/ch6-example.json", env!("CARGO_MANIFEST_DIR"));
    let report = yarnhom(
        &[
            "shell",
            "simulate",
            "stretch-x",
            "--material",
            &ch6,
            "-o",
            "c.mcap",
            "--frames",
            "2",
            "--resolution",
            "7",
        ],
        dir.path(),
    );
    assert!(report.status.success(), "{}", stderr(&report));
    assert!(stderr(&report).contains("elastic energy"), "{}", stderr(&report));
}

/// `yarnhom diff A A`: exit 0 and "equal within tolerance"; its `--json` form parses and names
/// the kind.
fn diff_with_itself(path: &str, kind: &str, dir: &Path) {
    let o = yarnhom(&["diff", path, path], dir);
    assert_eq!(o.status.code(), Some(0), "diff {path} {path}: {}{}", stdout(&o), stderr(&o));
    assert!(stdout(&o).starts_with(&format!("{kind} equal within tolerance")), "{}", stdout(&o));
    let json: serde_json::Value =
        serde_json::from_str(&ok(&["diff", path, path, "--json"], dir)).expect("diff --json is JSON");
    assert_eq!(json["kind"], kind, "{json}");
}

const MATERIALS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/hylc-materials");

#[test]
fn diff_of_every_artifact_kind_with_itself_exits_0() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let tiny = format!("{DATA}/stocktiniest.pyp");
    ok(&["pattern", "import", &format!("{DATA}/stock.pyp"), "-o", "stock.pattern.yh"], d);
    diff_with_itself("stock.pattern.yh", "pattern", d);
    ok(&["model", "write", "table4.1:stock-small", "-o", "m.yarnmodel.yh"], d);
    diff_with_itself("m.yarnmodel.yh", "yarnmodel", d);
    let model = ["--model", "table4.1:stock-small"];
    ok(&[&["rve", "solve", &tiny][..], &model, &["--strain", "sx=0.1", "-o", "s.rvesolve.yh"]].concat(), d);
    diff_with_itself("s.rvesolve.yh", "rvesolve", d);
    ok(
        &[&["rve", "sample", &tiny][..], &model, &["--n1d", "5", "--n2d", "3", "-o", "g.grid.yh"]].concat(),
        d,
    );
    diff_with_itself("g.grid.yh", "grid", d);
    ok(&["fit", "g.grid.yh", "-o", "fit.spline.yh"], d);
    diff_with_itself("fit.spline.yh", "spline", d);
    ok(&["fit", "import-arcsim", &format!("{MATERIALS}/satin1.json"), "-o", "satin.spline.yh"], d);
    diff_with_itself("satin.spline.yh", "spline", d);
    let simulate = ["shell", "simulate", "drape", "--material", "satin.spline.yh", "--resolution", "7"];
    ok(&[&simulate[..], &["--frames", "2", "-o", "t.mcap"]].concat(), d);
    diff_with_itself("t.mcap", "trace", d);

    // The same grid fitted with another quasiconvexity slope: a different material, evaluated.
    ok(&["fit", "g.grid.yh", "--min-slope", "0.05", "-o", "steep.spline.yh"], d);
    let o = yarnhom(&["diff", "fit.spline.yh", "steep.spline.yh"], d);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let report = stdout(&o);
    assert!(report.starts_with("spline DIFFERENT"), "{report}");
    let outside = report.lines().filter(|l| l.ends_with("outside tolerance")).count();
    assert!(outside > 0 && report.contains(".energy_density_j_m2"), "{report}");
}

#[test]
fn diff_of_a_spline_with_an_edited_coefficient_names_its_term() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let published = format!("{MATERIALS}/stock1.json");
    let mut spline = yarnhom_artifacts::open::open_artifact::<yarnhom_artifacts::Spline>(&published)
        .map(|o| o.value)
        .expect("published material");
    let term = spline.terms_1d.iter_mut().find(|t| t.axis == 3).expect("kx term");
    let last = term.values.len() - 1;
    term.values[last] *= 1.5;
    let json = yarnhom_artifacts::arcsim::ArcsimMaterial::from_spline(&spline).to_json().expect("json");
    std::fs::write(d.join("edited.json"), json).expect("write");
    let o = yarnhom(&["diff", &published, "edited.json"], d);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let report = stdout(&o);
    let line = |field: &str| {
        let start = format!("  {field} ");
        report.lines().find(|l| l.starts_with(&start)).unwrap_or_else(|| panic!("no {field} in {report}"))
    };
    assert!(line("kx.energy_density_j_m2").contains("worst at kx="), "{report}");
    assert!(line("kx.energy_density_j_m2").ends_with("outside tolerance"), "{report}");
    for unrelated in ["sx", "sa", "sy", "ky"] {
        assert!(!line(&format!("{unrelated}.energy_density_j_m2")).contains("outside"), "{report}");
    }
    assert!(report.contains("f_kx.values"), "the coefficient note names the term: {report}");

    let o = yarnhom(&["diff", &published, "edited.json", "--json"], d);
    assert_eq!(o.status.code(), Some(1));
    let json: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("diff --json is JSON");
    assert_eq!(json["kind"], "spline");
    let fields = json["fields"].as_array().expect("fields");
    let field = |name: &str| fields.iter().find(|f| f["field"] == name).unwrap_or_else(|| panic!("{name}"));
    let kx = field("kx.energy_density_j_m2");
    assert!(kx["outside"].as_u64().is_some_and(|n| n > 0), "{kx}");
    assert!(kx["max_abs"].as_f64().is_some_and(|x| x > 0.0), "{kx}");
    assert!(kx["worst_at"].as_str().is_some_and(|s| s.starts_with("kx=")), "{kx}");
    assert_eq!(field("sx.stress")["outside"], 0);
    for key in ["structural", "notes"] {
        assert!(json[key].is_array(), "{key} in {json}");
    }
    // A tolerance above the change makes them equal.
    assert_eq!(yarnhom(&["diff", &published, "edited.json", "--atol", "1e3"], d).status.code(), Some(0));
}

#[test]
fn diff_of_traces_names_missing_frames_and_truncation() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    ok(&["fit", "import-arcsim", &format!("{MATERIALS}/satin1.json"), "-o", "satin.spline.yh"], d);
    let simulate = ["shell", "simulate", "drape", "--material", "satin.spline.yh", "--resolution", "7"];
    ok(&[&simulate[..], &["--frames", "2", "-o", "two.mcap"]].concat(), d);
    ok(&[&simulate[..], &["--frames", "1", "-o", "one.mcap"]].concat(), d);
    let o = yarnhom(&["diff", "two.mcap", "one.mcap"], d);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let report = stdout(&o);
    assert!(report.starts_with("trace DIFFERENT"), "{report}");
    assert!(report.contains("  /mesh/frame: 2 messages matched"), "{report}");
    assert!(report.contains("only in the first trace: 1 messages, e.g. frame 2, mesh drape"), "{report}");

    let o = yarnhom(&["diff", "two.mcap", "one.mcap", "--json"], d);
    assert_eq!(o.status.code(), Some(1));
    let json: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("diff --json is JSON");
    assert_eq!(json["kind"], "trace");
    let topics = json["topics"].as_array().expect("topics");
    let frames = topics.iter().find(|t| t["topic"] == "/mesh/frame").expect("/mesh/frame");
    assert_eq!(frames["matched"], 2);
    assert_eq!(frames["only_in_first"]["count"], 1);
    assert!(
        frames["fields"].as_array().expect("fields").iter().any(|f| f["field"] == "positions_m"),
        "{frames}"
    );

    // A trace cut short is a difference, not an error; a trace detected by its content needs no
    // `.mcap` name.
    let bytes = std::fs::read(d.join("two.mcap")).expect("read");
    std::fs::write(d.join("cut"), &bytes[..bytes.len() * 2 / 3]).expect("write");
    let o = yarnhom(&["diff", "two.mcap", "cut"], d);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stdout(&o).contains("structure: the second trace is truncated or damaged"), "{}", stdout(&o));
}

#[test]
fn diff_of_a_missing_file_or_of_other_kinds_exits_2() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let pattern = rib(d);
    let pattern = pattern.to_str().expect("utf8");
    fails_with(&["diff", pattern, "does-not-exist.yh"], d, "does-not-exist.yh");
    fails_with(&["diff", "does-not-exist.mcap", pattern], d, "does-not-exist.mcap");
    ok(&["model", "write", "table4.1:stock", "-o", "m.yarnmodel.yh"], d);
    fails_with(&["diff", pattern, "m.yarnmodel.yh"], d, "cannot compare a 'pattern'");
    std::fs::write(d.join("fake.mcap"), b"not a trace").expect("write");
    fails_with(&["diff", "fake.mcap", "fake.mcap"], d, "or MCAP trace");
    ok(&["fit", "import-arcsim", &format!("{MATERIALS}/satin1.json"), "-o", "satin.spline.yh"], d);
    ok(
        &[
            "shell",
            "simulate",
            "drape",
            "--material",
            "satin.spline.yh",
            "--frames",
            "1",
            "--resolution",
            "5",
            "-o",
            "t.mcap",
        ],
        d,
    );
    fails_with(&["diff", "t.mcap", pattern], d, "cannot compare a MCAP trace (t.mcap) with a 'pattern'");
}

#[test]
fn diff_of_an_old_schema_version_with_itself_and_its_migration_exits_0() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let old = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/rvesolve.v1.yh");
    diff_with_itself(old, "rvesolve", d);
    // The migrated file, written in the current version, equals the old one.
    ok(&["convert", old, "--to", "yh", "-o", "new.rvesolve.yh"], d);
    let o = yarnhom(&["diff", old, "new.rvesolve.yh"], d);
    assert_eq!(o.status.code(), Some(0), "{}{}", stdout(&o), stderr(&o));
}

#[test]
fn rve_residual_finds_the_published_stockinette_balanced_by_the_table_4_1_contact() {
    let dir = tempfile::tempdir().expect("temp dir");
    let stock = format!("{DATA}/stock.pyp");
    let text = ok(&["rve", "residual", &stock, "--model", "table4.1:stock"], dir.path());
    let scale: f64 = text
        .lines()
        .find_map(|l| l.trim().strip_prefix("best contact scale"))
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no contact scale in: {text}"));
    assert!((scale - 1.0).abs() < 0.1, "{text}");
    let generated = dir.path().join("g.pattern.yh");
    ok(&["pattern", "generate", "stockinette", "-o", generated.to_str().expect("utf8")], dir.path());
    fails_with(
        &["rve", "residual", generated.to_str().expect("utf8"), "--model", "table4.1:stock"],
        dir.path(),
        "has no rest state",
    );
}

const FIXTURES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures");

#[test]
fn calibration_reports_of_old_versions_inspect_and_diff_through_their_migrations() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (v1, v2, yarn) = (
        format!("{FIXTURES}/diagnosis.v1.json"),
        format!("{FIXTURES}/diagnosis.v2.json"),
        format!("{FIXTURES}/yarn-fit.v1.json"),
    );
    let text = ok(&["inspect", &v1], dir.path());
    assert!(text.contains("report: yarnhom.diagnosis v1"), "inspect names the report:\n{text}");
    assert!(text.contains("cause:"), "inspect prints the diagnosis' summary:\n{text}");
    // A report equals itself; an old file is compared as its migration to the current version.
    for report in [&v1, &v2, &yarn] {
        assert_eq!(yarnhom(&["diff", report, report], dir.path()).status.code(), Some(0), "{report}");
    }
    let different = yarnhom(&["diff", &v1, &v2], dir.path());
    assert_eq!(different.status.code(), Some(1), "two diagnoses of different sets: {}", stdout(&different));
    fails_with(&["diff", &v1, &yarn], dir.path(), "cannot compare a 'yarnhom.diagnosis' report");
}
