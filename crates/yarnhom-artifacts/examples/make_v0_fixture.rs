//! Writes `fixtures/yarnmodel.v0.yh` and `schemas/yarnmodel.v0.schema.json`: a `yarnmodel` in the schema version 0 layout (a flat
//! Table 4.1 row), framed as version 0. The file is committed; `tests/migration.rs` checks that it
//! keeps loading through the migration. Run once from the repository root:
//! `cargo run -p yarnhom-artifacts --example make_v0_fixture`.

use yarnhom_artifacts::container::{Header, Producer, content_hash, frame, payload_of};
use yarnhom_artifacts::yarnmodel::YarnModelV0;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let v0 = YarnModelV0 {
        name: "table4.1:rib".into(),
        e: 5e5,
        g: 2e5,
        gamma: 0.001,
        k_contact: 6e1,
        rho: 6e1,
        radius: 1e-3,
    };
    let payload = payload_of(&v0)?;
    let header = Header {
        kind: "yarnmodel".into(),
        schema_version: 0,
        producer: Producer { name: "yarnhom (v0 layout)".into(), version: "0.0.0".into() },
        created_utc: "2026-11-22T00:00:00Z".into(),
        inputs: vec![],
        content_hash: content_hash(&payload),
        payload_bytes: payload.len() as u64,
    };
    let path = "fixtures/yarnmodel.v0.yh";
    std::fs::write(path, frame(&header, &payload)?)?;
    println!("wrote {path}");
    let schema = serde_json::to_string_pretty(&schemars::schema_for!(YarnModelV0))? + "\n";
    std::fs::write("schemas/yarnmodel.v0.schema.json", schema)?;
    println!("wrote schemas/yarnmodel.v0.schema.json");
    Ok(())
}
