//! Version policy (schemas/README.md): files of an older schema version keep loading.

use yarnhom_artifacts::container::read;
use yarnhom_artifacts::{AnyArtifact, RveSolve, YarnModel};

const FIXTURE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/yarnmodel.v0.yh");

#[test]
fn a_v0_yarn_model_loads_as_the_current_version() {
    let (header, model) = read::<YarnModel>(FIXTURE).expect("v0 fixture loads");
    assert_eq!(header.schema_version, 0, "the fixture must stay a v0 file");
    // The v0 row holds the Table 4.1 rib parameters, so the migration must land exactly on them.
    assert_eq!(Some(model), YarnModel::table_4_1("rib"));
}

#[test]
fn a_v0_yarn_model_loads_through_the_kind_dispatch() {
    let (_, any) = AnyArtifact::read(FIXTURE).expect("v0 fixture loads");
    assert!(matches!(any, AnyArtifact::YarnModel(_)));
}

const RVESOLVE_V1: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/rvesolve.v1.yh");

#[test]
fn a_v1_tile_solve_loads_without_the_equilibrium_stress() {
    // Version 1 (written by `yarnhom rve solve` before schema version 2) had only the
    // finite-difference stress; the migration keeps every field and adds no stress it never had.
    let (header, solve) = read::<RveSolve>(RVESOLVE_V1).expect("v1 fixture loads");
    assert_eq!(header.schema_version, 1, "the fixture must stay a v1 file");
    assert!(solve.converged && solve.energy_density_j_m2.is_some());
    assert_eq!(solve.stress, None, "v1 files carry no (3.23c) stress");
    let fd = solve.stress_fd.expect("the v1 fixture was written with its finite-difference stress");
    assert!(fd.iter().all(|x| x.is_finite()) && fd[0] > 0.0, "stretching along X1 needs a positive dsx");
    assert_eq!(solve.positions_m.len(), solve.edge_twist_rad.len());
}
