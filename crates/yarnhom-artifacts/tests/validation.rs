//! Every invariant of a pattern and a yarn model is checked, and the error names the field.
//! Also: malformed `.pyp` input is reported with its line.

use yarnhom_artifacts::pyp::{parse_pyp, write_pyp};
use yarnhom_artifacts::{Error, Fabric, Pattern, RestState, Yarn, YarnMechanics, YarnModel};

/// A valid tile: one yarn of four vertices along X1 with a rest state.
fn square() -> Pattern {
    let positions_m = vec![[0.0, 0.0, 0.0], [0.25, 0.1, 0.05], [0.5, 0.0, 0.0], [0.75, -0.1, -0.05]];
    Pattern {
        name: "square".into(),
        fabric: Fabric::Woven,
        period_m: [1.0, 1.0],
        edge_twist_rad: vec![0.0; 4],
        yarns: vec![Yarn {
            radius_m: 0.01,
            vertices: vec![0, 1, 2, 3],
            edge_offsets: vec![[0, 0], [0, 0], [0, 0], [1, 0]],
        }],
        rest: Some(RestState {
            edge_length_m: vec![0.27; 4],
            vertex_curvature: vec![[0.0, 0.1]; 4],
            vertex_twist_rad: vec![0.0; 4],
            edge_reference_director: vec![[0.0, 0.0, 1.0]; 4],
            vertex_reference_twist_rad: vec![0.0; 4],
        }),
        positions_m,
        origin: "test".into(),
    }
}

fn problem(edit: impl FnOnce(&mut Pattern)) -> String {
    let mut p = square();
    edit(&mut p);
    p.validate().expect_err("must be invalid").to_string()
}

#[test]
fn the_reference_tile_is_valid() {
    square().validate().expect("valid");
}

#[test]
fn each_broken_invariant_is_named() {
    type Edit = Box<dyn FnOnce(&mut Pattern)>;
    let cases: Vec<(Edit, &str)> = vec![
        (Box::new(|p| p.period_m[1] = 0.0), "period_m[1]"),
        (Box::new(|p| p.positions_m[2][1] = f64::INFINITY), "positions_m[2][1]: not a finite number"),
        (Box::new(|p| p.edge_twist_rad.push(0.0)), "edge_twist_rad: has 5 entries but there are 4 vertices"),
        (Box::new(|p| p.yarns[0].radius_m = 0.0), "yarns[0].radius_m: must be a finite number > 0"),
        (Box::new(|p| p.yarns[0].vertices[3] = 9), "dangling vertex index 9"),
        (Box::new(|p| p.yarns[0].vertices[3] = 1), "vertex 1 is already used by yarn 0"),
        (Box::new(|p| p.yarns.clear()), "at least one yarn"),
        (
            Box::new(|p| {
                p.yarns[0].vertices.pop();
                p.yarns[0].edge_offsets.pop();
                p.yarns[0].edge_offsets[2] = [1, 0];
            }),
            "positions_m[3]: vertex belongs to no yarn",
        ),
        (
            Box::new(|p| {
                p.yarns[0].edge_offsets.pop();
            }),
            "edge_offsets: has 3 entries",
        ),
        (Box::new(|p| p.yarns[0].edge_offsets[3] = [0, 0]), "sum to (0, 0)"),
        (Box::new(|p| p.yarns[0].edge_offsets[3] = [2, 0]), "skips a whole tile"),
        (Box::new(|p| p.positions_m[1] = p.positions_m[0]), "zero-length edge from vertex 0 to vertex 1"),
        (Box::new(|p| p.rest.as_mut().expect("rest").edge_length_m[2] = -1.0), "rest.edge_length_m[2]"),
        (
            Box::new(|p| p.rest.as_mut().expect("rest").edge_reference_director[1] = [0.0, 0.0, 2.0]),
            "must be a unit vector",
        ),
        (
            Box::new(|p| {
                p.rest.as_mut().expect("rest").vertex_curvature.pop();
            }),
            "rest.vertex_curvature: has 3 entries",
        ),
        (
            Box::new(|p| p.rest.as_mut().expect("rest").vertex_twist_rad[0] = f64::NAN),
            "rest.vertex_twist_rad[0]",
        ),
    ];
    for (edit, expected) in cases {
        let message = problem(edit);
        assert!(message.contains(expected), "expected '{expected}' in '{message}'");
    }
}

#[test]
fn yarn_model_parameters_must_be_physical() {
    let mut m = YarnModel::table_4_1("stock").expect("row");
    m.validate().expect("Table 4.1 is valid");
    m.density_kg_m3 = -1.0;
    assert!(m.validate().expect_err("negative density").to_string().contains("density_kg_m3"));
    let biphasic = |r1: f64, r2: f64, k1: f64, k2: f64| YarnModel {
        name: "b".into(),
        radius_m: 1e-3,
        density_kg_m3: 100.0,
        mechanics: YarnMechanics::Biphasic {
            k_s1_n: k1,
            k_s2_n: k2,
            eps_bar: 0.1,
            k_b_nm2: 1e-9,
            r1_m: r1,
            k_c1_n_m: 1.0,
            r2_m: r2,
            k_c2_n_m: 1e3,
        },
    };
    biphasic(1e-3, 2.5e-4, 1.0, 10.0).validate().expect("valid Ch. 6 model");
    assert!(biphasic(1e-3, 2e-3, 1.0, 10.0).validate().is_err(), "inner radius beyond outer");
    assert!(biphasic(1e-3, 2.5e-4, 20.0, 10.0).validate().is_err(), "low stiffness above high");
}

fn pyp_error(text: &str) -> String {
    match parse_pyp(text, "bad", None) {
        Err(e @ Error::Format { .. }) => e.to_string(),
        Err(e @ Error::Invalid { .. }) => e.to_string(),
        other => panic!("expected a format or validation error, got {other:?}"),
    }
}

#[test]
fn malformed_pyp_is_reported_with_its_line() {
    let good = write_pyp(&square()).expect("export");
    assert_eq!(
        parse_pyp(&good, "square", Some(Fabric::Woven)).expect("reimport").positions_m,
        square().positions_m
    );
    let lines: Vec<&str> = good.lines().collect();
    let with_line = |n: usize, replacement: &str| {
        let mut l = lines.clone();
        l[n] = replacement;
        l.join("\n")
    };
    // Line numbers are 1-based: lines[4] is line 5, the first *Q row.
    assert!(pyp_error(&with_line(4, "0 0 x 0")).contains("line 5: 'x' is not a finite number"));
    assert!(pyp_error(&with_line(4, "0 0 nan 0")).contains("line 5: 'nan' is not a finite number"));
    assert!(pyp_error(&with_line(4, "0 0 0")).contains("line 5: section *Q needs 4 columns, found 3"));
    assert!(pyp_error(&with_line(1, "1 1 0.01 3")).contains("section *Q has 4 rows, expected 3"));
    let e_row = lines.iter().position(|l| l.starts_with("*E")).expect("*E") + 1;
    assert!(pyp_error(&with_line(e_row, "0 7 0 0")).contains("v1 7 is out of range 0..4"));
    assert!(pyp_error(&with_line(e_row, "0 1.5 0 0")).contains("v1 must be an integer"));
    assert!(pyp_error(&with_line(e_row + 1, "0 2 0 0")).contains("vertex 0 already has an outgoing edge"));
    let without_rl: String = good.replace("*RL # rest lengths", "*XX # renamed");
    assert!(pyp_error(&without_rl).contains("rest state is incomplete: missing *RL"));
    assert!(pyp_error("1 2 3\n*pattern\n").contains("line 1: data before the first *section header"));
    assert!(pyp_error("*Q\n").contains("missing section *pattern"));
    let doubled = format!("{good}\n*Q\n0 0 0 0\n");
    assert!(pyp_error(&doubled).contains("section *Q appears twice"));
    // Geometry that parses but breaks an invariant is a validation error naming the field.
    assert!(pyp_error(&with_line(1, "1 1 -0.01 4")).contains("radius_m"));
}

#[test]
fn a_tiling_is_a_valid_pattern_with_the_same_geometry_per_tile() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/data/hylc-patterns/stock.pyp"
    ))
    .expect("published stock");
    let p = parse_pyp(&text, "stock", None).expect("imports");
    for (nx, ny) in [(2, 1), (1, 2), (3, 2)] {
        let t = p.tiled(nx, ny);
        t.validate().unwrap_or_else(|e| panic!("{nx}x{ny}: {e}"));
        let copies = (nx * ny) as usize;
        assert_eq!(t.vertex_count(), copies * p.vertex_count());
        assert_eq!(t.period_m, [p.period_m[0] * f64::from(nx), p.period_m[1] * f64::from(ny)]);
        // Same multiset of edge vectors, each repeated once per copy.
        let vectors = |q: &Pattern| {
            let mut v: Vec<[i64; 3]> =
                q.edges().map(|e| q.edge_vector(&e).map(|c| (c * 1e9).round() as i64)).collect();
            v.sort();
            v
        };
        let mut expected: Vec<[i64; 3]> =
            vectors(&p).into_iter().flat_map(|v| std::iter::repeat_n(v, copies)).collect();
        expected.sort();
        assert_eq!(vectors(&t), expected, "{nx}x{ny}");
        assert_eq!(t.rest.as_ref().expect("rest").edge_length_m.len(), t.vertex_count());
    }
}
