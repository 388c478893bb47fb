//! Message types, their topics, schemas and versions.

use std::collections::BTreeMap;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize, de::DeserializeOwned};

/// Topic names.
pub mod topics {
    /// Topic of [`MeshTopology`](crate::MeshTopology) messages.
    pub const MESH_TOPOLOGY: &str = "/mesh/topology";
    /// Topic of [`MeshFrame`](crate::MeshFrame) messages.
    pub const MESH_FRAME: &str = "/mesh/frame";
    /// Topic of [`YarnFrame`](crate::YarnFrame) messages.
    pub const YARN_FRAME: &str = "/yarn/frame";
    /// Topic of [`YarnNodes`](crate::YarnNodes) messages.
    pub const YARN_NODES: &str = "/yarn/nodes";
    /// Topic of [`TetTopology`](crate::TetTopology) messages.
    pub const TET_TOPOLOGY: &str = "/tet/topology";
    /// Topic of [`TetFrame`](crate::TetFrame) messages.
    pub const TET_FRAME: &str = "/tet/frame";
    /// Topic of [`Scalars`](crate::Scalars) messages.
    pub const METRICS: &str = "/metrics";
    /// Topic of [`SolverStep`](crate::SolverStep) messages.
    pub const SOLVER: &str = "/solver";
    /// Topic of [`SolverIteration`](crate::SolverIteration) messages.
    pub const SOLVER_ITERATION: &str = "/solver/iteration";
    /// Topic of [`RveSample`](crate::RveSample) messages.
    pub const RVE_SAMPLE: &str = "/rve/sample";
}

/// MCAP message encoding of every yarnhom channel (MessagePack maps with named fields).
pub const MESSAGE_ENCODING: &str = "msgpack";

/// MCAP schema encoding of every yarnhom schema.
pub const SCHEMA_ENCODING: &str = "jsonschema";

/// Channel-metadata key holding the topic's layout version ([`Topic::VERSION`]) as a decimal
/// string.
pub const TOPIC_VERSION_KEY: &str = "yarnhom_topic_version";

/// The rest state of a triangle mesh. Written once per mesh on `/mesh/topology`, before any
/// frame of that mesh.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct MeshTopology {
    /// Triangles as 0-based indices into the vertex arrays, counter-clockwise seen from the
    /// front face.
    pub triangles: Vec<[u32; 3]>,
    /// Rest (material) position of each vertex, in metres.
    pub rest_positions_m: Vec<[f64; 3]>,
    /// Human-readable mesh name.
    pub name: String,
}

/// Deformed vertex positions of the mesh at one output frame. Written on `/mesh/frame`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct MeshFrame {
    /// The mesh these positions belong to: the `name` of its [`MeshTopology`].
    pub mesh: String,
    /// Output frame number, counting from 0.
    pub frame: u64,
    /// Simulated time, in seconds.
    pub time_s: f64,
    /// World position of each vertex, in metres, in the vertex order of the topology.
    pub positions_m: Vec<[f64; 3]>,
}

/// The yarn centrelines at one frame: every yarn of a yarn-level state (a periodic tile, a
/// swatch). Written on `/yarn/frame`; self-contained (no topology message), since yarn-level
/// states are small and yarns may change between frames.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct YarnFrame {
    /// Name of the yarn set (e.g. the pattern's name); frames of one set share it.
    pub yarns: String,
    /// Index of the state on its producer's clock, counting from 0: the output frame of a
    /// dynamic simulation, the Newton iteration of a static solve.
    pub frame: u64,
    /// Simulated time, in seconds (0 for static solves).
    pub time_s: f64,
    /// Centreline vertex positions, in metres, yarn after yarn.
    pub positions_m: Vec<[f64; 3]>,
    /// Twist of the edge leaving each vertex towards the next vertex of its yarn, in radians
    /// (the last vertex of an open yarn has an unused 0); empty if the producer has no twists.
    pub edge_twist_rad: Vec<f64>,
    /// Yarn radius at each vertex, in metres.
    pub radii_m: Vec<f64>,
    /// The yarns as `[first vertex, vertex count]` ranges of `positions_m`, in order.
    pub yarn_ranges: Vec<[u32; 2]>,
}

/// The nodes of a yarn set as a learned simulator sees them (MeshGraphNets' `mesh_pos`,
/// `node_type` and graph edges): its rest positions, which vertices are driven, and its
/// segments. Written on `/yarn/nodes` once per yarn set, before the set's first
/// [`YarnFrame`]; its vertices are those of the frames, in the same order.
///
/// Node types are MeshGraphNets' `NodeType` codes ([`YarnNodes::NORMAL`],
/// [`YarnNodes::HANDLE`]), so that a training set exported from a trace
/// (`yarnhom trace export --format training`) means what MeshGraphNets loaders expect. Obstacle
/// geometry is not a yarn node: it has no vertex in the frames, and the code `OBSTACLE` (1) is
/// not used.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct YarnNodes {
    /// Name of the yarn set, as in its [`YarnFrame`]s.
    pub yarns: String,
    /// Rest position of each vertex, in metres, in the vertex order of the frames (yarn after
    /// yarn).
    pub rest_positions_m: Vec<[f64; 3]>,
    /// Node type of each vertex, a MeshGraphNets `NodeType` code: 0 (`NORMAL`) for a free
    /// vertex, 3 (`HANDLE`) for a vertex whose motion is prescribed (pinned, clamped or moved by
    /// a handle). Other codes are not written by yarnhom (obstacles are not yarn nodes).
    pub node_type: Vec<u8>,
    /// The yarn segments, as pairs of 0-based vertex indices (for open yarns the consecutive
    /// vertices of each yarn range, see [`YarnNodes::chain_edges`]; a closed yarn adds the
    /// segment from its last vertex back to its first).
    pub edges: Vec<[u32; 2]>,
}

impl YarnNodes {
    /// MeshGraphNets' `NodeType.NORMAL`: a free vertex, moved by the simulation.
    pub const NORMAL: u8 = 0;
    /// MeshGraphNets' `NodeType.HANDLE`: a vertex whose motion is prescribed.
    pub const HANDLE: u8 = 3;
    /// MeshGraphNets' `NodeType.SIZE`: every code is below it (the width of a one-hot node
    /// type).
    pub const CODES: u8 = 9;

    /// The segments of open yarns given as `[first vertex, vertex count]` ranges (as in
    /// [`YarnFrame::yarn_ranges`]): each vertex with the next one of its yarn, yarn after yarn.
    pub fn chain_edges(yarn_ranges: &[[u32; 2]]) -> Vec<[u32; 2]> {
        yarn_ranges
            .iter()
            .flat_map(|&[first, count]| {
                (1..count).map(move |k| [first.saturating_add(k - 1), first.saturating_add(k)])
            })
            .collect()
    }
}

/// The rest state of a tetrahedral mesh with per-element values (e.g. the fitted `gamma` of
/// volumetric homogenization). Written once per mesh on `/tet/topology`, before its frames.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct TetTopology {
    /// Human-readable mesh name.
    pub name: String,
    /// Tetrahedra as 0-based vertex indices, positively oriented at rest.
    pub tets: Vec<[u32; 4]>,
    /// Rest position of each vertex, in metres.
    pub rest_positions_m: Vec<[f64; 3]>,
    /// Per-element values by name (one value per tetrahedron), each in the SI unit its name
    /// implies.
    pub element_values: BTreeMap<String, Vec<f64>>,
}

/// Deformed vertex positions of a tetrahedral mesh at one frame. Written on `/tet/frame`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct TetFrame {
    /// The mesh these positions belong to: the `name` of its [`TetTopology`].
    pub mesh: String,
    /// Output frame number, counting from 0.
    pub frame: u64,
    /// Simulated time, in seconds.
    pub time_s: f64,
    /// World position of each vertex, in metres, in the vertex order of the topology.
    pub positions_m: Vec<[f64; 3]>,
}

/// One iteration of a nonlinear solver (a Newton iteration of a tile solve). Written on
/// `/solver/iteration`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct SolverIteration {
    /// Index of the state on its producer's clock (for a static solve: the iteration itself,
    /// matching the `frame` of the geometry written with it).
    pub frame: u64,
    /// Simulated time, in seconds (0 for static solves).
    pub time_s: f64,
    /// Iteration number within the solve, counting from 0.
    pub iteration: u32,
    /// Total energy at the start of the iteration, in joules.
    pub energy_j: f64,
    /// Convergence measure at the start of the iteration, in the solver's own norm (for tile
    /// solves: the projected gradient relative to the affine start's, A.33).
    pub residual: f64,
    /// Fraction of the Newton step taken (0 if the iteration ended the solve).
    pub step_length: f64,
}

/// One sample of a homogenized energy sweep (thesis App. A.3.1). Written on `/rve/sample` as
/// each sample is solved.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct RveSample {
    /// Sample number in the order the samples were written, counting from 0.
    pub frame: u64,
    /// Simulated time: always 0 (samples are static solves).
    pub time_s: f64,
    /// Name of the plan term (`sx`, `sx,sa`, ...).
    pub term: String,
    /// Index of the sample in its term's axes (the second is 0 for 1D terms).
    pub grid_index: [u32; 2],
    /// Imposed strain `(sx, sa, sy, kx, ky)`: stretches and shear cosine dimensionless,
    /// curvatures in 1/m.
    pub strain: [f64; 5],
    /// Whether the equilibrium was found.
    pub converged: bool,
    /// Homogenized energy density (3.22), in J/m²; absent when not converged.
    pub energy_density_j_m2: Option<f64>,
    /// Homogenized stress dΨ/d(sx, sa, sy, kx, ky) (3.23c): J/m² per unit strain, J/m per unit
    /// curvature; absent when not converged or not computed.
    pub stress: Option<[f64; 5]>,
    /// Newton iterations taken.
    pub iterations: u32,
}

/// Named scalar metrics at one frame (energies, constraint errors, ...). Written on `/metrics`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct Scalars {
    /// Output frame number the values belong to.
    pub frame: u64,
    /// Simulated time, in seconds.
    pub time_s: f64,
    /// Values by name, each in the SI unit its name implies (energies in J, forces in N,
    /// lengths in m); a unit suffix in the name (`kinetic_energy_j`) is recommended.
    pub values: BTreeMap<String, f64>,
}

/// Statistics of one solver step. Written on `/solver`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
pub struct SolverStep {
    /// Output frame number the step belongs to.
    pub frame: u64,
    /// Simulated time at the end of the step, in seconds.
    pub time_s: f64,
    /// Newton iterations taken.
    pub newton_iterations: u32,
    /// Final residual, in the solver's own norm.
    pub residual: f64,
    /// Line-search backtracking steps taken, summed over the Newton iterations.
    pub line_search_steps: u32,
    /// Whether the solver met its convergence criterion.
    pub converged: bool,
    /// Wall-clock time spent on the step, in seconds.
    pub wall_time_s: f64,
}

/// Schema name and JSON Schema of every topic's message type, in the order of the topic table
/// (committed under `schemas/trace/<schema name>.schema.json`).
pub fn topic_schemas() -> Vec<(&'static str, &'static str, schemars::Schema)> {
    fn entry<T: Topic>() -> (&'static str, &'static str, schemars::Schema) {
        (T::TOPIC, T::SCHEMA_NAME, T::root_schema())
    }
    vec![
        entry::<MeshTopology>(),
        entry::<MeshFrame>(),
        entry::<YarnNodes>(),
        entry::<YarnFrame>(),
        entry::<TetTopology>(),
        entry::<TetFrame>(),
        entry::<Scalars>(),
        entry::<SolverStep>(),
        entry::<SolverIteration>(),
        entry::<RveSample>(),
    ]
}

pub(crate) mod sealed {
    /// Seals [`Topic`](super::Topic) and carries the header fields the writer needs.
    pub trait Sealed {
        /// Simulated time of the message, if it has one.
        fn time_s(&self) -> Option<f64>;
        /// Frame number of the message, if it has one.
        fn frame(&self) -> Option<u64>;
    }
}

/// A message type with its fixed topic, schema name and layout version.
///
/// Implemented only by the message types of this crate (the trait is sealed), so the set of
/// topics and their versions is defined in one place.
pub trait Topic: Serialize + DeserializeOwned + JsonSchema + sealed::Sealed {
    /// MCAP topic name.
    const TOPIC: &'static str;
    /// Schema name stored in the MCAP schema record (`yarnhom.<Type>.v<VERSION>`).
    const SCHEMA_NAME: &'static str;
    /// Layout version, stored in channel metadata under [`TOPIC_VERSION_KEY`].
    const VERSION: u32;

    /// The JSON Schema of this message type, as generated by [`schemars::schema_for!`].
    fn root_schema() -> schemars::Schema {
        schemars::schema_for!(Self)
    }
}

macro_rules! topic {
    ($ty:ty, $topic:expr, $schema:literal, $version:literal) => {
        impl Topic for $ty {
            const TOPIC: &'static str = $topic;
            const SCHEMA_NAME: &'static str = $schema;
            const VERSION: u32 = $version;
        }
    };
}

topic!(MeshTopology, topics::MESH_TOPOLOGY, "yarnhom.MeshTopology.v1", 1);
topic!(MeshFrame, topics::MESH_FRAME, "yarnhom.MeshFrame.v1", 1);
topic!(YarnNodes, topics::YARN_NODES, "yarnhom.YarnNodes.v1", 1);
topic!(YarnFrame, topics::YARN_FRAME, "yarnhom.YarnFrame.v1", 1);
topic!(TetTopology, topics::TET_TOPOLOGY, "yarnhom.TetTopology.v1", 1);
topic!(TetFrame, topics::TET_FRAME, "yarnhom.TetFrame.v1", 1);
topic!(Scalars, topics::METRICS, "yarnhom.Scalars.v1", 1);
topic!(SolverStep, topics::SOLVER, "yarnhom.SolverStep.v1", 1);
topic!(SolverIteration, topics::SOLVER_ITERATION, "yarnhom.SolverIteration.v1", 1);
topic!(RveSample, topics::RVE_SAMPLE, "yarnhom.RveSample.v1", 1);

macro_rules! untimed {
    ($($ty:ty),*) => {$(
        impl sealed::Sealed for $ty {
            fn time_s(&self) -> Option<f64> {
                None
            }
            fn frame(&self) -> Option<u64> {
                None
            }
        }
    )*};
}

untimed!(MeshTopology, YarnNodes, TetTopology);

macro_rules! timed {
    ($($ty:ty),*) => {$(
        impl sealed::Sealed for $ty {
            fn time_s(&self) -> Option<f64> {
                Some(self.time_s)
            }
            fn frame(&self) -> Option<u64> {
                Some(self.frame)
            }
        }
    )*};
}

timed!(MeshFrame, YarnFrame, TetFrame, Scalars, SolverStep, SolverIteration, RveSample);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_topic_is_listed_once() {
        let listed = topic_schemas();
        let mut topics: Vec<&str> = listed.iter().map(|(topic, _, _)| *topic).collect();
        topics.sort_unstable();
        topics.dedup();
        assert_eq!(topics.len(), listed.len());
        assert_eq!(listed.len(), 10);
    }

    fn check<T: Topic>() {
        assert!(T::TOPIC.starts_with('/'));
        assert!(T::SCHEMA_NAME.starts_with("yarnhom."));
        assert!(T::SCHEMA_NAME.ends_with(&format!(".v{}", T::VERSION)));
        let schema = T::root_schema();
        assert_eq!(schema.get("type"), Some(&serde_json::json!("object")));
    }

    #[test]
    fn topic_constants_are_consistent() {
        check::<MeshTopology>();
        check::<MeshFrame>();
        check::<YarnNodes>();
        check::<YarnFrame>();
        check::<TetTopology>();
        check::<TetFrame>();
        check::<Scalars>();
        check::<SolverStep>();
        check::<SolverIteration>();
        check::<RveSample>();
    }

    #[test]
    fn chain_edges_join_consecutive_vertices_of_each_yarn() {
        assert_eq!(YarnNodes::chain_edges(&[[0, 3], [3, 1], [4, 2]]), [[0, 1], [1, 2], [4, 5]]);
        assert!(YarnNodes::chain_edges(&[[0, 0]]).is_empty());
    }

    #[test]
    fn field_docs_reach_the_schema() {
        let schema = serde_json::to_value(MeshFrame::root_schema()).expect("schema json");
        let description = &schema["properties"]["positions_m"]["description"];
        assert!(description.as_str().is_some_and(|d| d.contains("metres")), "{schema:#}");
    }
}
