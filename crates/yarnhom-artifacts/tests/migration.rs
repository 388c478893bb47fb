//! Version policy (schemas/README.md): files of an older schema version keep loading.

use yarnhom_artifacts::container::read;
use yarnhom_artifacts::{AnyArtifact, YarnModel};

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
