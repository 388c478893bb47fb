//! The `grid` kind: every invariant named, plan counts, merging shards, diff and HDF5 round trips.

mod common;

use yarnhom_artifacts::diff::{Tolerance, diff_grids};
use yarnhom_artifacts::{Grid, GridShard, GridTerm, MergeError};

fn problem(edit: impl FnOnce(&mut Grid)) -> String {
    let mut g = common::sample_grid(Some(3));
    edit(&mut g);
    g.validate().expect_err("must be invalid").to_string()
}

#[test]
fn the_sample_grids_are_valid_and_complete() {
    for vertices in [None, Some(3)] {
        let g = common::sample_grid(vertices);
        g.validate().expect("valid");
        // sx (3) + sa (4) + sx,sy (3 x 2) + kx,ky (3 x 2)
        assert_eq!(g.expected_samples(), 3 + 4 + 6 + 6);
        assert!(g.is_complete());
    }
    let mut g = common::sample_grid(None);
    g.samples.pop();
    assert!(!g.is_complete());
}

#[test]
fn each_broken_invariant_is_named() {
    type Edit = Box<dyn FnOnce(&mut Grid)>;
    let cases: Vec<(Edit, &str)> = vec![
        (Box::new(|g| g.terms[0].values[0][0] = f64::NAN), "terms[0].values[0][0]: not a finite number"),
        (
            Box::new(|g| g.terms[3].values[0].swap(0, 1)),
            "terms[3].values[0][1]: values must increase strictly",
        ),
        (Box::new(|g| g.terms[3].values[1] = vec![1.0, 2.0]), "terms[3].values[1]: must contain 0"),
        (
            Box::new(|g| {
                g.terms[2].values.pop();
            }),
            "terms[2].values: needs one list of values per axis",
        ),
        (Box::new(|g| g.terms[2].axes = vec![2, 0]), "terms[2].axes: must be 1 or 2 distinct axis indices"),
        (Box::new(|g| g.terms[0].axes = vec![5]), "terms[0].axes: must be 1 or 2"),
        (Box::new(|g| g.terms[0].axes = vec![0, 1, 2]), "terms[0].axes: must be 1 or 2"),
        (
            Box::new(|g| g.terms.push(GridTerm { axes: vec![1], values: vec![vec![0.0]] })),
            "terms[4]: repeats terms[1]",
        ),
        (Box::new(|g| g.shard = Some(GridShard { index: 3, count: 3 })), "shard.index: must be below"),
        (Box::new(|g| g.samples[0].term = 9), "samples[0].term: 9 is not a term index"),
        (Box::new(|g| g.samples[0].index = [0, 1]), "samples[0].index: [0, 1] is outside"),
        (Box::new(|g| g.samples[2].index = [3, 0]), "samples[2].index: [3, 0] is outside"),
        (Box::new(|g| g.samples[1].strain.sa = 0.5), "samples[1].strain: must be the axes' values"),
        (Box::new(|g| g.samples.swap(3, 4)), "samples[4]: samples must be sorted"),
        (
            Box::new(|g| {
                let s = g.samples[5].clone();
                g.samples.insert(5, s);
            }),
            "samples[6]: samples must be sorted by (term, index) without repeats",
        ),
        (
            Box::new(|g| g.samples[3].energy_density_j_m2 = Some(1.0)),
            "samples[3].energy_density_j_m2: present exactly",
        ),
        (
            Box::new(|g| g.samples[0].energy_density_j_m2 = None),
            "samples[0].energy_density_j_m2: present exactly",
        ),
        (
            Box::new(|g| g.samples[0].energy_density_j_m2 = Some(f64::INFINITY)),
            "samples[0].energy_density_j_m2[0]: not a finite number",
        ),
        (
            Box::new(|g| g.samples[3].stress = Some([0.0; 5])),
            "samples[3].stress: a failed solve reports no stress",
        ),
        (
            Box::new(|g| g.samples[0].stress = Some([f64::NAN; 5])),
            "samples[0].stress[0]: not a finite number",
        ),
        (
            Box::new(|g| g.samples[2].positions_m.as_mut().expect("geometry")[1][2] = f64::NAN),
            "samples[2].positions_m[1][2]: not a finite number",
        ),
        (
            Box::new(|g| g.samples[2].edge_twist_rad.as_mut().expect("geometry")[0] = f64::NAN),
            "samples[2].edge_twist_rad[0]: not a finite number",
        ),
        (
            Box::new(|g| g.samples[4].positions_m = None),
            "samples[4].positions_m: all samples have the geometry or none",
        ),
        (
            Box::new(|g| {
                g.samples[4].positions_m.as_mut().expect("geometry").pop();
            }),
            "samples[4].positions_m: all samples have the geometry or none, with one vertex count (3 in samples[0])",
        ),
        (
            Box::new(|g| g.samples[4].edge_twist_rad = None),
            "samples[4].edge_twist_rad: present exactly with positions_m",
        ),
    ];
    for (edit, expected) in cases {
        let message = problem(edit);
        assert!(message.contains(expected), "expected '{expected}' in '{message}'");
    }
}

#[test]
fn the_summary_names_plan_outcome_and_shard() {
    let mut g = common::sample_grid(None);
    g.shard = Some(GridShard { index: 1, count: 4 });
    let summary = g.summary();
    for expected in
        ["grid of 'rib' with 'rib'", "terms: 4 (sx; sa; sx,sy; kx,ky)", "of 19 (plan: 19, complete)"]
    {
        assert!(summary.contains(expected), "{expected} in {summary}");
    }
    assert!(summary.contains("shard 1 of 4"), "{summary}");
    assert!(summary.contains("energy density: 1.000000e-1 .. 2.320000e0 J/m²"), "{summary}");
}

/// Split a grid round-robin into `n` shards, as `--shard K/N` would sample it.
fn shards(g: &Grid, n: usize) -> Vec<Grid> {
    (0..n)
        .map(|k| Grid {
            shard: Some(GridShard { index: k as u32, count: n as u32 }),
            samples: g.samples.iter().skip(k).step_by(n).cloned().collect(),
            ..g.clone()
        })
        .collect()
}

#[test]
fn merged_shards_are_bit_identical_to_the_whole_grid() {
    let whole = common::sample_grid(Some(2));
    let mut parts = shards(&whole, 3);
    parts.reverse();
    let merged = Grid::merge(parts).expect("merge");
    assert_eq!(merged, whole);
    let bytes = |g: &Grid| yarnhom_artifacts::container::payload_of(g).expect("payload");
    assert_eq!(bytes(&merged), bytes(&whole));
    assert!(merged.is_complete());
}

#[test]
fn overlapping_shards_are_refused_naming_the_sample() {
    let whole = common::sample_grid(None);
    let mut parts = shards(&whole, 3);
    let extra = parts[2].samples[1].clone();
    parts[0].samples.push(extra);
    parts[0].samples.sort_by_key(|s| s.key());
    let (term, index) = parts[2].samples[1].key();
    let e = Grid::merge(parts).unwrap_err();
    assert_eq!(e, MergeError::Overlap { term, index, first: "shard 0".into(), second: "shard 2".into() });
    let message = e.to_string();
    assert!(
        message.contains(&format!(
            "sample (term {term}, index [{}, {}]) appears in shard 0 and shard 2",
            index[0], index[1]
        )),
        "{message}"
    );
}

#[test]
fn shards_of_other_plans_are_refused() {
    let whole = common::sample_grid(None);
    let mut parts = shards(&whole, 2);
    // -0.0 == 0.0, but the axes must be equal bit for bit.
    parts[1].terms[1].values[0][1] = 0.0;
    parts[1].samples.retain(|s| s.term != 1);
    let e = Grid::merge(parts).unwrap_err();
    assert!(matches!(e, MergeError::Mismatch { what: "axes", .. }), "{e}");
    assert!(e.to_string().contains("shard 1 differs from shard 0 in its axes"), "{e}");

    let mut parts = shards(&whole, 2);
    parts[1].model = "honey".into();
    assert!(matches!(Grid::merge(parts).unwrap_err(), MergeError::Mismatch { what: "model", .. }));
    let mut parts = shards(&whole, 2);
    parts[0].shard = Some(GridShard { index: 0, count: 3 });
    assert!(matches!(Grid::merge(parts).unwrap_err(), MergeError::Mismatch { what: "shard count", .. }));
    assert_eq!(Grid::merge(vec![]).unwrap_err(), MergeError::Empty);
    let mut parts = shards(&whole, 2);
    parts[1].samples.reverse();
    assert!(matches!(Grid::merge(parts).unwrap_err(), MergeError::Invalid { .. }));
}

const TIGHT: Tolerance = Tolerance { rtol: 1e-12, atol: 0.0 };

#[test]
fn a_grid_equals_itself() {
    let g = common::sample_grid(Some(2));
    let d = diff_grids(&g, &g, TIGHT);
    assert!(d.equal(), "{}", d.report());
    assert!(d.fields.iter().any(|f| f.field == "samples.energy_density_j_m2" && f.count == 16));
}

#[test]
fn a_changed_energy_is_found_and_its_sample_named() {
    let a = common::sample_grid(None);
    let mut b = a.clone();
    b.samples[8].energy_density_j_m2 = Some(100.0);
    let d = diff_grids(&a, &b, TIGHT);
    assert!(!d.equal());
    let energy = d.fields.iter().find(|f| f.field == "samples.energy_density_j_m2").expect("energy");
    assert_eq!((energy.outside, energy.worst_index), (1, 8));
    let report = d.report();
    assert!(report.contains(&format!("largest difference at {}", a.samples[8].describe())), "{report}");
}

#[test]
fn missing_samples_and_other_plans_are_structural() {
    let a = common::sample_grid(None);
    let mut b = a.clone();
    b.samples.remove(5);
    b.samples[0].converged = false;
    let d = diff_grids(&a, &b, TIGHT);
    assert!(
        d.structural.iter().any(|s| s.starts_with("1 samples only in the first file, e.g. sample (term 1")),
        "{:?}",
        d.structural
    );
    assert!(d.structural.iter().any(|s| s.contains("converged in one file only")), "{:?}", d.structural);
    let mut c = a.clone();
    c.terms.pop();
    let d = diff_grids(&a, &c, Tolerance { rtol: 1.0, atol: 1.0 });
    assert!(d.structural.iter().any(|s| s.starts_with("terms:")), "{:?}", d.structural);
    c = a.clone();
    c.terms[2].values[1].push(1.0);
    assert!(!diff_grids(&a, &c, Tolerance { rtol: 1.0, atol: 1.0 }).equal());
}

#[test]
fn samples_in_one_grid_only_are_counted_and_named_by_term_and_strain() {
    let a = common::sample_grid(None);
    let mut b = a.clone();
    let removed: Vec<_> = b.samples.drain(0..2).collect();
    let d = diff_grids(&b, &a, TIGHT);
    assert!(!d.equal());
    let only = d
        .structural
        .iter()
        .find(|s| s.starts_with("2 samples only in the second file, e.g. "))
        .unwrap_or_else(|| panic!("{:?}", d.structural));
    for sample in &removed {
        assert!(only.contains(&sample.describe()), "{only}");
    }
    assert!(only.contains("sx at sx=-0.1"), "the strain of the first missing sample: {only}");
    // The worst sample of a compared field is located by its strain too.
    let mut c = a.clone();
    c.samples[8].energy_density_j_m2 = Some(100.0);
    let d = diff_grids(&a, &c, TIGHT);
    let energy = d.fields.iter().find(|f| f.field == "samples.energy_density_j_m2").expect("energy");
    let at = energy.worst_at.as_deref().expect("worst sample located");
    assert!(at.starts_with(&a.samples[8].describe()) && at.contains('='), "{at}");
    assert!(d.report().contains(at), "{}", d.report());
}

#[cfg(feature = "hdf5")]
mod hdf5 {
    use yarnhom_artifacts::container::{self, Provenance};
    use yarnhom_artifacts::hdf5::{export, import};
    use yarnhom_artifacts::{AnyArtifact, Grid, GridShard};

    fn round_trip(g: Grid) {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("g.grid.h5");
        let payload = container::payload_of(&g).expect("payload");
        let header = container::header_for::<Grid>(&payload, &Provenance::default());
        export(&path, &header, &AnyArtifact::Grid(g.clone())).expect("export");
        let (back_header, back) = import(&path).expect("import");
        let AnyArtifact::Grid(back) = back else { panic!("not a grid") };
        assert_eq!(back, g);
        assert_eq!(container::payload_of(&back).expect("payload"), payload);
        assert_eq!(back_header, header);
    }

    #[test]
    fn a_grid_with_geometry_round_trips_exactly() {
        round_trip(super::common::sample_grid(Some(4)));
    }

    #[test]
    fn a_sharded_grid_without_geometry_round_trips_exactly() {
        let mut g = super::common::sample_grid(None);
        g.shard = Some(GridShard { index: 2, count: 5 });
        g.samples.retain(|s| s.term != 2);
        round_trip(g);
    }

    /// Export the sample grid, let `edit` change the file, import it and return the error.
    fn import_error_after(edit: impl FnOnce(&::hdf5::File)) -> yarnhom_artifacts::Error {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("g.grid.h5");
        let g = super::common::sample_grid(Some(2));
        let payload = container::payload_of(&g).expect("payload");
        let header = container::header_for::<Grid>(&payload, &Provenance::default());
        export(&path, &header, &AnyArtifact::Grid(g)).expect("export");
        edit(&::hdf5::File::open_rw(&path).expect("open"));
        import(&path).expect_err("the edited file must be refused")
    }

    #[test]
    fn edited_grid_files_are_refused() {
        use yarnhom_artifacts::Error;
        let write_energy = |f: &::hdf5::File, value: f64| {
            let ds = f.dataset("samples/energy_density_j_m2").expect("dataset");
            let mut e: Vec<f64> = ds.read_raw().expect("read");
            e[0] = value;
            ds.write_raw(&e).expect("write");
        };
        let e = import_error_after(|f| write_energy(f, 7.0));
        assert!(matches!(e.root(), Error::ContentHashMismatch { .. }), "{e}");
        let e = import_error_after(|f| write_energy(f, f64::NAN));
        assert!(e.to_string().contains("samples[0].energy_density_j_m2: present exactly"), "{e}");
        let e = import_error_after(|f| f.unlink("samples/edge_twist_rad").expect("unlink"));
        assert!(e.to_string().contains("missing dataset /samples/edge_twist_rad"), "{e}");
        let e = import_error_after(|f| {
            let ds = f.dataset("samples/converged").expect("dataset");
            let mut c: Vec<u8> = ds.read_raw().expect("read");
            c[1] = 2;
            ds.write_raw(&c).expect("write");
        });
        assert!(e.to_string().contains("/samples/converged[1] is 2, expected 0 or 1"), "{e}");
    }

    #[test]
    fn a_grid_without_samples_round_trips() {
        let mut g = super::common::sample_grid(None);
        g.samples.clear();
        round_trip(g);
    }
}
