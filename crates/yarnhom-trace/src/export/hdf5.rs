//! The HDF5 export (see the [module docs](super) for the layout).

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use ::hdf5::types::{TypeDescriptor, VarLenUnicode};
use ::hdf5::{Dataset, Extent, File, Group, H5Type};
use serde::Serialize;
use yarnhom_artifacts::AtomicFile;
use yarnhom_artifacts::hdf5::layer::{
    Spec, create_group, describe, open_or_create_group, varlen, write_str_attr,
};

use super::geometry::{
    boundary_triangles, check_indices, check_tet_topology, check_vertex_count, check_yarn_frame, link_name,
};
use super::{ExportError, ExportStats};
use crate::error::Truncation;
use crate::{
    MeshFrame, MeshTopology, RveSample, Scalars, SolverIteration, SolverStep, TetFrame, TetTopology,
    TraceMessage, YarnFrame,
};

/// The `format` of the manifest.
const FORMAT: &str = "yarnhom.trace.hdf5";
/// The `format_version` of the manifest: the version of the layout.
const FORMAT_VERSION: u32 = 1;
/// Target size of a chunk of a per-frame dataset.
const CHUNK_BYTES: usize = 64 * 1024;
/// Most rows (frames) in a chunk, so that short streams do not allocate large chunks.
const MAX_CHUNK_ROWS: usize = 1024;

/// An HDF5 library error while doing `context`.
pub(super) fn h5_error(context: String, error: ::hdf5::Error) -> ExportError {
    ExportError::Hdf5 { context, error }
}

/// Writes a trace into an HDF5 file, one message at a time.
pub(super) struct Hdf5Writer {
    // Fields are dropped in order: the datasets are closed before the file, and the file before
    // an abandoned temporary file is deleted.
    streams: Streams,
    catalog: Catalog,
    file: File,
    temp: AtomicFile,
}

/// The streams met so far, each with its open datasets.
#[derive(Default)]
struct Streams {
    meshes: HashMap<String, MeshStream>,
    tets: HashMap<String, TetStream>,
    yarns: HashMap<String, YarnStream>,
    metrics: Option<Metrics>,
    solver: Option<Table>,
    iterations: Option<Table>,
    rve: Option<RveSamples>,
}

impl Hdf5Writer {
    /// Starts an export to `path`: an empty HDF5 file is created next to it.
    pub(super) fn create(path: &Path) -> Result<Self, ExportError> {
        let temp = AtomicFile::create(path)
            .map_err(|error| ExportError::Write { path: path.to_path_buf(), error })?;
        let file = File::with_options()
            .with_fcpl(|fcpl| fcpl.obj_track_times(false))
            .create(temp.temp_path())
            .map_err(|e| {
                h5_error(
                    format!("cannot create {} (to become {})", temp.temp_path().display(), path.display()),
                    e,
                )
            })?;
        Ok(Self { streams: Streams::default(), catalog: Catalog::default(), file, temp })
    }

    /// Exports one message.
    pub(super) fn write(
        &mut self,
        message: TraceMessage,
        stats: &mut ExportStats,
    ) -> Result<(), ExportError> {
        match message {
            TraceMessage::Topology(topology) => self.add_mesh(topology),
            TraceMessage::TetTopology(topology) => self.add_tet_mesh(topology),
            TraceMessage::Frame(frame) => self.write_mesh_frame(&frame, stats),
            TraceMessage::TetFrame(frame) => self.write_tet_frame(&frame, stats),
            TraceMessage::Yarns(frame) => self.write_yarn_frame(&frame, stats),
            TraceMessage::Scalars(scalars) => self.write_metrics(&scalars, stats),
            TraceMessage::Solver(step) => self.write_solver_step(&step, stats),
            TraceMessage::SolverIteration(iteration) => self.write_solver_iteration(&iteration, stats),
            TraceMessage::RveSample(sample) => self.write_rve_sample(&sample, stats),
            other => {
                stats.skip(&other);
                Ok(())
            }
        }
    }

    /// Writes the RVE term names, the root attributes and the manifest, then closes the file
    /// and moves it into place.
    pub(super) fn finish(self, input_name: &str, stats: &mut ExportStats) -> Result<(), ExportError> {
        let Self { streams, mut catalog, file, mut temp } = self;
        if let Some(rve) = &streams.rve {
            rve.write_term_names(&mut catalog)?;
        }
        drop(streams);
        write_str_attr(&file, "yarnhom_trace_version", env!("CARGO_PKG_VERSION"))?;
        write_str_attr(&file, "input", input_name)?;
        let manifest = Manifest {
            format: FORMAT,
            format_version: FORMAT_VERSION,
            yarnhom_trace_version: env!("CARGO_PKG_VERSION"),
            input: input_name,
            trace_metadata: &stats.trace_metadata,
            truncation: stats.truncation,
            skipped_messages: &stats.skipped,
            datasets: catalog.entries_with_shapes(&file)?,
        };
        write_manifest(&file, &manifest)?;
        file.close().map_err(|e| h5_error(format!("cannot close {}", temp.temp_path().display()), e))?;
        let destination = temp.destination().to_path_buf();
        temp.commit().map_err(|error| ExportError::Write { path: destination, error })?;
        stats.files_written += 1;
        Ok(())
    }

    fn add_mesh(&mut self, topology: MeshTopology) -> Result<(), ExportError> {
        let stream = format!("mesh {:?}", topology.name);
        if let Some(known) = self.streams.meshes.get(&topology.name) {
            return same_topology(&stream, known.topology == topology);
        }
        let vertex_count = topology.rest_positions_m.len();
        check_indices(&topology.triangles, vertex_count, "triangle")
            .map_err(|p| ExportError::topology(&stream, p))?;
        let group = self.stream_group("mesh", &topology.name)?;
        let catalog = &mut self.catalog;
        let triangles = topology.triangles.as_flattened();
        catalog.fixed(&group, "triangles", &[topology.triangles.len(), 3], triangles, &TRIANGLES)?;
        let rest = topology.rest_positions_m.as_flattened();
        catalog.fixed(&group, "rest_positions_m", &[vertex_count, 3], rest, &REST_POSITIONS)?;
        let frames = FrameColumns::create(catalog, &group, vertex_count)?;
        self.streams.meshes.insert(topology.name.clone(), MeshStream { topology, frames });
        Ok(())
    }

    fn add_tet_mesh(&mut self, topology: TetTopology) -> Result<(), ExportError> {
        let stream = format!("tet mesh {:?}", topology.name);
        if let Some(known) = self.streams.tets.get(&topology.name) {
            return same_topology(&stream, known.topology == topology);
        }
        check_tet_topology(&topology).map_err(|p| ExportError::topology(&stream, p))?;
        let (vertex_count, tet_count) = (topology.rest_positions_m.len(), topology.tets.len());
        let group = self.stream_group("tet", &topology.name)?;
        let catalog = &mut self.catalog;
        catalog.fixed(&group, "tets", &[tet_count, 4], topology.tets.as_flattened(), &TETS)?;
        let boundary = boundary_triangles(&topology.tets, &topology.rest_positions_m);
        catalog.fixed(&group, "triangles", &[boundary.len(), 3], boundary.as_flattened(), &BOUNDARY)?;
        let rest = topology.rest_positions_m.as_flattened();
        catalog.fixed(&group, "rest_positions_m", &[vertex_count, 3], rest, &REST_POSITIONS)?;
        for (name, values) in &topology.element_values {
            let spec = Spec {
                units: units_of(name),
                description: "per-tetrahedron value, in the unit its name implies",
            };
            let link = format!("element/{}", link_name(name));
            catalog.fixed(&group, &link, &[tet_count], values, &spec)?;
        }
        let frames = FrameColumns::create(catalog, &group, vertex_count)?;
        self.streams.tets.insert(topology.name.clone(), TetStream { topology, frames });
        Ok(())
    }

    fn write_mesh_frame(&mut self, frame: &MeshFrame, stats: &mut ExportStats) -> Result<(), ExportError> {
        let mesh = format!("mesh {:?}", frame.mesh);
        let Some(stream) = self.streams.meshes.get_mut(&frame.mesh) else {
            return Err(ExportError::MissingTopology { mesh, frame: frame.frame });
        };
        stream.frames.push(&mesh, frame.frame, frame.time_s, &frame.positions_m)?;
        stats.count_frame(&format!("/mesh/{}", frame.mesh));
        Ok(())
    }

    fn write_tet_frame(&mut self, frame: &TetFrame, stats: &mut ExportStats) -> Result<(), ExportError> {
        let mesh = format!("tet mesh {:?}", frame.mesh);
        let Some(stream) = self.streams.tets.get_mut(&frame.mesh) else {
            return Err(ExportError::MissingTopology { mesh, frame: frame.frame });
        };
        stream.frames.push(&mesh, frame.frame, frame.time_s, &frame.positions_m)?;
        stats.count_frame(&format!("/tet/{}", frame.mesh));
        Ok(())
    }

    fn write_yarn_frame(&mut self, frame: &YarnFrame, stats: &mut ExportStats) -> Result<(), ExportError> {
        let name = format!("yarns {:?}", frame.yarns);
        check_yarn_frame(frame).map_err(|p| ExportError::frame(&name, frame.frame, p))?;
        if !self.streams.yarns.contains_key(&frame.yarns) {
            let group = self.stream_group("yarns", &frame.yarns)?;
            let stream = YarnStream::create(&mut self.catalog, &group, frame)?;
            self.streams.yarns.insert(frame.yarns.clone(), stream);
        }
        if let Some(stream) = self.streams.yarns.get_mut(&frame.yarns) {
            stream.push(&name, frame)?;
        }
        stats.count_frame(&format!("/yarns/{}", frame.yarns));
        Ok(())
    }

    fn write_metrics(&mut self, scalars: &Scalars, stats: &mut ExportStats) -> Result<(), ExportError> {
        let metrics = match self.streams.metrics.take() {
            Some(metrics) => metrics,
            None => Metrics::create(&mut self.catalog, &self.file)?,
        };
        let metrics = self.streams.metrics.insert(metrics);
        metrics.push(&mut self.catalog, scalars)?;
        stats.count_frame("/metrics");
        Ok(())
    }

    fn write_solver_step(&mut self, step: &SolverStep, stats: &mut ExportStats) -> Result<(), ExportError> {
        let table = match self.streams.solver.take() {
            Some(table) => table,
            None => Table::create(&mut self.catalog, &self.file, "solver", &SOLVER_COLUMNS)?,
        };
        let table = self.streams.solver.insert(table);
        table.push(&[
            Cell::U64(step.frame),
            Cell::F64(step.time_s),
            Cell::U32(step.newton_iterations),
            Cell::F64(step.residual),
            Cell::U32(step.line_search_steps),
            Cell::U8(u8::from(step.converged)),
            Cell::F64(step.wall_time_s),
        ])?;
        stats.count_frame("/solver");
        Ok(())
    }

    fn write_solver_iteration(
        &mut self,
        iteration: &SolverIteration,
        stats: &mut ExportStats,
    ) -> Result<(), ExportError> {
        let table = match self.streams.iterations.take() {
            Some(table) => table,
            None => Table::create(&mut self.catalog, &self.file, "solver_iteration", &ITERATION_COLUMNS)?,
        };
        let table = self.streams.iterations.insert(table);
        table.push(&[
            Cell::U64(iteration.frame),
            Cell::F64(iteration.time_s),
            Cell::U32(iteration.iteration),
            Cell::F64(iteration.energy_j),
            Cell::F64(iteration.residual),
            Cell::F64(iteration.step_length),
        ])?;
        stats.count_frame("/solver_iteration");
        Ok(())
    }

    fn write_rve_sample(&mut self, sample: &RveSample, stats: &mut ExportStats) -> Result<(), ExportError> {
        let rve = match self.streams.rve.take() {
            Some(rve) => rve,
            None => RveSamples::create(&mut self.catalog, &self.file)?,
        };
        let rve = self.streams.rve.insert(rve);
        rve.push(sample)?;
        stats.count_frame("/rve_sample");
        Ok(())
    }

    /// Creates `/<kind>/<name>` (`/` in the name becomes `_`) with the attribute `name`.
    fn stream_group(&self, kind: &str, name: &str) -> Result<Group, ExportError> {
        let parent = open_or_create_group(&self.file, kind)?;
        let group = create_group(&parent, &link_name(name))?;
        write_str_attr(&group, "name", name)?;
        Ok(group)
    }
}

/// Accepts a repeated topology only if it is the same as the first.
fn same_topology(stream: &str, same: bool) -> Result<(), ExportError> {
    if same {
        Ok(())
    } else {
        let problem = "a second topology of this mesh differs from the first: the HDF5 layout has one topology per mesh \
                       (give the meshes different names)";
        Err(ExportError::topology(stream, problem.to_owned()))
    }
}

// ---------------------------------------------------------------------------------------------
// Streams

/// A triangle mesh: its topology (to compare with a repeated one) and per-frame datasets.
struct MeshStream {
    topology: MeshTopology,
    frames: FrameColumns,
}

/// A tet mesh: its topology (to compare with a repeated one) and per-frame datasets.
struct TetStream {
    topology: TetTopology,
    frames: FrameColumns,
}

/// `positions_m [F, V, 3]`, `frame [F]` and `time_s [F]` of a stream of fixed vertex count.
struct FrameColumns {
    vertex_count: usize,
    positions: Column,
    frame: Column,
    time: Column,
}

impl FrameColumns {
    fn create(catalog: &mut Catalog, group: &Group, vertex_count: usize) -> Result<Self, ExportError> {
        Ok(Self {
            vertex_count,
            positions: catalog.growing::<f64>(group, "positions_m", &[vertex_count, 3], &POSITIONS)?,
            frame: catalog.growing::<u64>(group, "frame", &[], &FRAME)?,
            time: catalog.growing::<f64>(group, "time_s", &[], &TIME)?,
        })
    }

    /// Appends one frame of `stream`, whose vertex count must be the stream's.
    fn push(
        &mut self,
        stream: &str,
        frame: u64,
        time_s: f64,
        positions: &[[f64; 3]],
    ) -> Result<(), ExportError> {
        check_vertex_count(positions, self.vertex_count).map_err(|p| ExportError::frame(stream, frame, p))?;
        self.positions.push_rows(positions)?;
        self.frame.push_value(frame)?;
        self.time.push_value(time_s)
    }
}

/// A yarn set: the yarn ranges of its first frame, which every frame must repeat, and its
/// per-frame datasets.
struct YarnStream {
    yarn_ranges: Vec<[u32; 2]>,
    frames: FrameColumns,
    twists: Column,
    radii: Column,
}

impl YarnStream {
    /// The datasets of a yarn set, shaped after its first frame.
    fn create(catalog: &mut Catalog, group: &Group, first: &YarnFrame) -> Result<Self, ExportError> {
        let n = first.positions_m.len();
        let ranges = first.yarn_ranges.as_flattened();
        catalog.fixed(group, "yarn_ranges", &[first.yarn_ranges.len(), 2], ranges, &YARN_RANGES)?;
        Ok(Self {
            yarn_ranges: first.yarn_ranges.clone(),
            frames: FrameColumns::create(catalog, group, n)?,
            twists: catalog.growing::<f64>(group, "edge_twist_rad", &[n], &TWISTS)?,
            radii: catalog.growing::<f64>(group, "radii_m", &[n], &RADII)?,
        })
    }

    /// Appends one frame; its vertex count and yarn ranges must be the first frame's.
    fn push(&mut self, stream: &str, frame: &YarnFrame) -> Result<(), ExportError> {
        if frame.yarn_ranges != self.yarn_ranges {
            let problem = format!(
                "the yarn ranges differ from the first frame's ({} yarns {:?}...): the HDF5 layout needs fixed shapes",
                self.yarn_ranges.len(),
                self.yarn_ranges.first()
            );
            return Err(ExportError::frame(stream, frame.frame, problem));
        }
        self.frames.push(stream, frame.frame, frame.time_s, &frame.positions_m)?;
        if frame.edge_twist_rad.is_empty() {
            self.twists.push_row(&vec![f64::NAN; frame.positions_m.len()])?;
        } else {
            self.twists.push_row(&frame.edge_twist_rad)?;
        }
        self.radii.push_row(&frame.radii_m)
    }
}

/// `/metrics`: one row per message, one column per value name ever seen.
struct Metrics {
    group: Group,
    frame: Column,
    time: Column,
    values: BTreeMap<String, Column>,
}

impl Metrics {
    fn create(catalog: &mut Catalog, file: &File) -> Result<Self, ExportError> {
        let group = create_group(file, "metrics")?;
        Ok(Self {
            frame: catalog.growing::<u64>(&group, "frame", &[], &FRAME)?,
            time: catalog.growing::<f64>(&group, "time_s", &[], &TIME)?,
            group,
            values: BTreeMap::new(),
        })
    }

    /// Appends one message: NaN for known values it lacks; a new value gets a column whose
    /// earlier rows are NaN.
    fn push(&mut self, catalog: &mut Catalog, scalars: &Scalars) -> Result<(), ExportError> {
        let rows = self.frame.rows();
        for name in scalars.values.keys() {
            if !self.values.contains_key(name) {
                let column = self.add_value(catalog, name, scalars.frame, rows)?;
                self.values.insert(name.clone(), column);
            }
        }
        self.frame.push_value(scalars.frame)?;
        self.time.push_value(scalars.time_s)?;
        for (name, column) in &mut self.values {
            column.push_value(scalars.values.get(name).copied().unwrap_or(f64::NAN))?;
        }
        Ok(())
    }

    /// A new value column, back-filled with `rows` NaNs.
    fn add_value(
        &self,
        catalog: &mut Catalog,
        name: &str,
        frame: u64,
        rows: usize,
    ) -> Result<Column, ExportError> {
        let link = link_name(name);
        if link == "frame" || link == "time_s" {
            let problem = format!("a metric named {name:?} collides with /metrics/{link}");
            return Err(ExportError::frame("metrics", frame, problem));
        }
        let spec = Spec {
            units: units_of(name),
            description: "metric value of each message; NaN where a message lacks it",
        };
        let mut column = catalog.growing::<f64>(&self.group, &link, &[], &spec)?;
        column.push_nan_values(rows)?;
        Ok(column)
    }
}

/// `/rve_sample`: the table of samples and the names of their terms.
struct RveSamples {
    group: Group,
    table: Table,
    term_names: Vec<String>,
}

impl RveSamples {
    fn create(catalog: &mut Catalog, file: &File) -> Result<Self, ExportError> {
        let table = Table::create(catalog, file, "rve_sample", &RVE_COLUMNS)?;
        let group = open_or_create_group(file, "rve_sample")?;
        Ok(Self { group, table, term_names: Vec::new() })
    }

    fn push(&mut self, sample: &RveSample) -> Result<(), ExportError> {
        let term = match self.term_names.iter().position(|name| *name == sample.term) {
            Some(index) => index,
            None => {
                self.term_names.push(sample.term.clone());
                self.term_names.len() - 1
            }
        };
        let term = u32::try_from(term).unwrap_or(u32::MAX);
        let stress = sample.stress.unwrap_or([f64::NAN; 5]);
        self.table.push(&[
            Cell::U64(sample.frame),
            Cell::F64(sample.time_s),
            Cell::U32(term),
            Cell::U32Row(&sample.grid_index),
            Cell::F64Row(&sample.strain),
            Cell::U8(u8::from(sample.converged)),
            Cell::F64(sample.energy_density_j_m2.unwrap_or(f64::NAN)),
            Cell::F64Row(&stress),
            Cell::U32(sample.iterations),
        ])
    }

    /// `/rve_sample/term_names`, once every sample is written.
    fn write_term_names(&self, catalog: &mut Catalog) -> Result<(), ExportError> {
        let names = self
            .term_names
            .iter()
            .map(|name| varlen("an RVE term name", name))
            .collect::<Result<Vec<_>, _>>()?;
        catalog.fixed(&self.group, "term_names", &[names.len()], &names, &TERM_NAMES)
    }
}

// ---------------------------------------------------------------------------------------------
// Tables of scalar columns

/// The element type and row shape of a table column.
#[derive(Clone, Copy)]
enum Kind {
    F64,
    U64,
    U32,
    U8,
    /// A row of this many `f64` per message.
    F64Row(usize),
    /// A row of this many `u32` per message.
    U32Row(usize),
}

/// A column of a table: its dataset name, kind, units and description.
struct ColumnSpec {
    name: &'static str,
    kind: Kind,
    spec: Spec,
}

/// One value of a table row, matching its column's [`Kind`].
enum Cell<'a> {
    F64(f64),
    U64(u64),
    U32(u32),
    U8(u8),
    F64Row(&'a [f64]),
    U32Row(&'a [u32]),
}

/// A group of columns with one row per message (`/solver`, `/solver_iteration`, `/rve_sample`).
struct Table {
    columns: Vec<Column>,
}

impl Table {
    fn create(
        catalog: &mut Catalog,
        file: &File,
        name: &str,
        specs: &[ColumnSpec],
    ) -> Result<Self, ExportError> {
        let group = open_or_create_group(file, name)?;
        let columns = specs
            .iter()
            .map(|column| match column.kind {
                Kind::F64 => catalog.growing::<f64>(&group, column.name, &[], &column.spec),
                Kind::U64 => catalog.growing::<u64>(&group, column.name, &[], &column.spec),
                Kind::U32 => catalog.growing::<u32>(&group, column.name, &[], &column.spec),
                Kind::U8 => catalog.growing::<u8>(&group, column.name, &[], &column.spec),
                Kind::F64Row(n) => catalog.growing::<f64>(&group, column.name, &[n], &column.spec),
                Kind::U32Row(n) => catalog.growing::<u32>(&group, column.name, &[n], &column.spec),
            })
            .collect::<Result<_, _>>()?;
        Ok(Self { columns })
    }

    /// Appends one row, one cell per column in the order of the specs.
    fn push(&mut self, cells: &[Cell<'_>]) -> Result<(), ExportError> {
        for (column, cell) in self.columns.iter_mut().zip(cells) {
            match *cell {
                Cell::F64(value) => column.push_value(value)?,
                Cell::U64(value) => column.push_value(value)?,
                Cell::U32(value) => column.push_value(value)?,
                Cell::U8(value) => column.push_value(value)?,
                Cell::F64Row(row) => column.push_row(row)?,
                Cell::U32Row(row) => column.push_row(row)?,
            }
        }
        Ok(())
    }
}

// ---------------------------------------------------------------------------------------------
// Datasets

const POSITIONS: Spec =
    Spec { units: "m", description: "vertex positions of each frame, in the vertex order of the topology" };
const FRAME: Spec = Spec { units: "1", description: "frame number of each row, on its producer's clock" };
const TIME: Spec = Spec { units: "s", description: "simulated time of each row" };
const TRIANGLES: Spec = Spec {
    units: "1",
    description: "triangles as 0-based vertex indices, counter-clockwise seen from the front face",
};
const BOUNDARY: Spec = Spec {
    units: "1",
    description: "boundary triangles (faces of one tetrahedron only) as 0-based vertex indices, counter-clockwise seen from outside",
};
const REST_POSITIONS: Spec = Spec { units: "m", description: "rest (material) position of each vertex" };
const TETS: Spec =
    Spec { units: "1", description: "tetrahedra as 0-based vertex indices, positively oriented at rest" };
const TWISTS: Spec = Spec {
    units: "rad",
    description: "twist of the edge leaving each vertex towards the next vertex of its yarn; NaN rows for frames without twists",
};
const RADII: Spec = Spec { units: "m", description: "yarn radius at each vertex" };
const YARN_RANGES: Spec = Spec {
    units: "1",
    description: "the yarns as [first vertex, vertex count] ranges of the vertices, the same in every frame",
};
const TERM_NAMES: Spec = Spec {
    units: "",
    description: "plan term names, in order of first appearance; /rve_sample/term indexes them",
};

/// A table column's spec, in one line.
const fn column(
    name: &'static str,
    kind: Kind,
    units: &'static str,
    description: &'static str,
) -> ColumnSpec {
    ColumnSpec { name, kind, spec: Spec { units, description } }
}

const SOLVER_COLUMNS: [ColumnSpec; 7] = [
    column("frame", Kind::U64, "1", "output frame number the step belongs to"),
    column("time_s", Kind::F64, "s", "simulated time at the end of the step"),
    column("newton_iterations", Kind::U32, "1", "Newton iterations taken"),
    column("residual", Kind::F64, "1", "final residual, in the solver's own norm"),
    column(
        "line_search_steps",
        Kind::U32,
        "1",
        "line-search backtracking steps, summed over the Newton iterations",
    ),
    column("converged", Kind::U8, "1", "1 if the solver met its convergence criterion, else 0"),
    column("wall_time_s", Kind::F64, "s", "wall-clock time spent on the step"),
];

const ITERATION_COLUMNS: [ColumnSpec; 6] = [
    column(
        "frame",
        Kind::U64,
        "1",
        "index of the state on its producer's clock (for a static solve, the iteration)",
    ),
    column("time_s", Kind::F64, "s", "simulated time (0 for static solves)"),
    column("iteration", Kind::U32, "1", "iteration number within the solve, from 0"),
    column("energy_j", Kind::F64, "J", "total energy at the start of the iteration"),
    column(
        "residual",
        Kind::F64,
        "1",
        "convergence measure at the start of the iteration, in the solver's own norm",
    ),
    column(
        "step_length",
        Kind::F64,
        "1",
        "fraction of the Newton step taken (0 if the iteration ended the solve)",
    ),
];

const RVE_COLUMNS: [ColumnSpec; 9] = [
    column("frame", Kind::U64, "1", "sample number, in the order written"),
    column("time_s", Kind::F64, "s", "simulated time (always 0)"),
    column("term", Kind::U32, "1", "plan term of each sample, as an index into /rve_sample/term_names"),
    column(
        "grid_index",
        Kind::U32Row(2),
        "1",
        "index of the sample in its term's axes (the second is 0 for 1D terms)",
    ),
    column("strain", Kind::F64Row(5), "1, 1, 1, 1/m, 1/m", "imposed strain, columns sx, sa, sy, kx, ky"),
    column("converged", Kind::U8, "1", "1 if the equilibrium was found, else 0"),
    column(
        "energy_density_j_m2",
        Kind::F64,
        "J/m^2",
        "homogenized energy density (3.22); NaN where not converged",
    ),
    column(
        "stress",
        Kind::F64Row(5),
        "J/m^2, J/m^2, J/m^2, J/m, J/m",
        "homogenized stress (3.23c), derivatives by sx, sa, sy, kx, ky; NaN rows where absent",
    ),
    column("iterations", Kind::U32, "1", "Newton iterations taken"),
];

/// The unit a value's name implies by its suffix (`elastic_energy_j`: J), or `SI`.
fn units_of(name: &str) -> &'static str {
    const SUFFIXES: [(&str, &str); 12] = [
        ("_j_m2", "J/m^2"),
        ("_j_m", "J/m"),
        ("_n_m", "N/m"),
        ("_kg_m2", "kg/m^2"),
        ("_m2", "m^2"),
        ("_rad", "rad"),
        ("_kg", "kg"),
        ("_pa", "Pa"),
        ("_j", "J"),
        ("_n", "N"),
        ("_m", "m"),
        ("_s", "s"),
    ];
    SUFFIXES.iter().find(|(suffix, _)| name.ends_with(suffix)).map_or("SI", |(_, units)| units)
}

/// The datasets written so far, for the manifest.
#[derive(Default)]
pub(super) struct Catalog {
    entries: Vec<DatasetEntry>,
}

/// One dataset in the manifest.
#[derive(Serialize)]
struct DatasetEntry {
    path: String,
    shape: Vec<usize>,
    dtype: String,
    units: &'static str,
    description: &'static str,
}

impl Catalog {
    /// Writes a dataset of fixed shape in one go.
    pub(super) fn fixed<T: H5Type>(
        &mut self,
        group: &Group,
        name: &str,
        shape: &[usize],
        data: &[T],
        spec: &Spec,
    ) -> Result<(), ExportError> {
        let path = format!("{}/{name}", group.name());
        let dataset = group
            .new_dataset::<T>()
            .shape(shape)
            .create(name)
            .map_err(|e| h5_error(format!("cannot create {path}"), e))?;
        if !data.is_empty() {
            dataset.write_raw(data).map_err(|e| h5_error(format!("cannot write {path}"), e))?;
        }
        self.register::<T>(&dataset, path, spec)
    }

    /// Creates an empty dataset of rows of shape `row_shape`, chunked and unlimited along its
    /// first dimension.
    pub(super) fn growing<T: H5Type>(
        &mut self,
        group: &Group,
        name: &str,
        row_shape: &[usize],
        spec: &Spec,
    ) -> Result<Column, ExportError> {
        let path = format!("{}/{name}", group.name());
        let row_bytes = row_shape.iter().product::<usize>().max(1) * T::type_descriptor().size();
        let chunk_rows = (CHUNK_BYTES / row_bytes).clamp(1, MAX_CHUNK_ROWS);
        let extents: Vec<Extent> =
            std::iter::once(Extent::from(0..)).chain(row_shape.iter().map(|&n| Extent::from(n))).collect();
        let chunk: Vec<usize> = std::iter::once(chunk_rows).chain(row_shape.iter().copied()).collect();
        let dataset = group
            .new_dataset::<T>()
            .chunk(chunk)
            .shape(extents)
            .create(name)
            .map_err(|e| h5_error(format!("cannot create {path}"), e))?;
        self.register::<T>(&dataset, path.clone(), spec)?;
        let shape = std::iter::once(0).chain(row_shape.iter().copied()).collect();
        Ok(Column { dataset, path, shape })
    }

    /// Writes the `units` and `description` attributes and lists the dataset.
    fn register<T: H5Type>(
        &mut self,
        dataset: &Dataset,
        path: String,
        spec: &Spec,
    ) -> Result<(), ExportError> {
        describe(dataset, spec)?;
        let dtype = match T::type_descriptor() {
            TypeDescriptor::VarLenUnicode => "string".to_owned(),
            other => other.to_string(),
        };
        self.entries.push(DatasetEntry {
            path,
            shape: Vec::new(),
            dtype,
            units: spec.units,
            description: spec.description,
        });
        Ok(())
    }

    /// The entries with their final shapes, read from the file, and the manifest's own last.
    fn entries_with_shapes(mut self, file: &File) -> Result<Vec<DatasetEntry>, ExportError> {
        for entry in &mut self.entries {
            let dataset =
                file.dataset(&entry.path).map_err(|e| h5_error(format!("cannot open {}", entry.path), e))?;
            entry.shape = dataset.shape();
        }
        self.entries.push(manifest_entry());
        Ok(self.entries)
    }
}

/// A dataset growing by one row per message along its first dimension.
pub(super) struct Column {
    dataset: Dataset,
    path: String,
    /// The current shape: rows, then the row shape.
    shape: Vec<usize>,
}

impl Column {
    /// Rows written so far.
    fn rows(&self) -> usize {
        self.shape[0]
    }

    /// Adds `count` rows; returns the index of the first.
    fn grow(&mut self, count: usize) -> Result<usize, ExportError> {
        let first = self.shape[0];
        self.shape[0] += count;
        self.dataset
            .resize(self.shape.as_slice())
            .map_err(|e| h5_error(format!("cannot extend {}", self.path), e))?;
        Ok(first)
    }

    /// Appends a value to a dataset of shape `[F]`.
    fn push_value<T: H5Type>(&mut self, value: T) -> Result<(), ExportError> {
        let row = self.grow(1)?;
        let written = self.dataset.write_slice(std::slice::from_ref(&value), row..row + 1);
        written.map_err(|e| h5_error(format!("cannot write row {row} of {}", self.path), e))
    }

    /// Appends `count` NaNs to a dataset of shape `[F]`.
    fn push_nan_values(&mut self, count: usize) -> Result<(), ExportError> {
        let first = self.grow(count)?;
        let written = self.dataset.write_slice(vec![f64::NAN; count].as_slice(), first..first + count);
        written.map_err(|e| h5_error(format!("cannot write rows {first}.. of {}", self.path), e))
    }

    /// Appends a row to a dataset of shape `[F, n]`.
    fn push_row<T: H5Type>(&mut self, row: &[T]) -> Result<(), ExportError> {
        let index = self.grow(1)?;
        let written = self.dataset.write_slice(row, (index, ..));
        written.map_err(|e| h5_error(format!("cannot write row {index} of {}", self.path), e))
    }

    /// Appends rows of `N` values as one row of a dataset of shape `[F, n, N]`.
    pub(super) fn push_rows<T: H5Type, const N: usize>(
        &mut self,
        rows: &[[T; N]],
    ) -> Result<(), ExportError> {
        let index = self.grow(1)?;
        let written = self.dataset.write_slice::<&[[T; N]], T, _, _>(rows, (index, .., ..));
        written.map_err(|e| h5_error(format!("cannot write row {index} of {}", self.path), e))
    }
}

// ---------------------------------------------------------------------------------------------
// Manifest

/// The JSON stored in `/manifest`.
#[derive(Serialize)]
struct Manifest<'a> {
    format: &'static str,
    format_version: u32,
    yarnhom_trace_version: &'static str,
    input: &'a str,
    trace_metadata: &'a [BTreeMap<String, String>],
    truncation: Option<Truncation>,
    skipped_messages: &'a BTreeMap<String, u64>,
    datasets: Vec<DatasetEntry>,
}

const MANIFEST: Spec = Spec {
    units: "",
    description: "JSON: format, provenance (input, trace metadata, truncation, skipped messages) and every dataset with its path, shape, dtype, units and description",
};

/// The manifest's entry for itself.
fn manifest_entry() -> DatasetEntry {
    DatasetEntry {
        path: "/manifest".into(),
        shape: Vec::new(),
        dtype: "string".into(),
        units: MANIFEST.units,
        description: MANIFEST.description,
    }
}

/// Writes `/manifest`, a scalar string.
fn write_manifest(file: &File, manifest: &Manifest<'_>) -> Result<(), ExportError> {
    let json = serde_json::to_string(manifest)
        .map_err(|e| h5_error("cannot encode the manifest".into(), e.to_string().into()))?;
    let text = varlen("the manifest", &json)?;
    let dataset = file
        .new_dataset::<VarLenUnicode>()
        .shape(())
        .create("manifest")
        .map_err(|e| h5_error("cannot create /manifest".into(), e))?;
    dataset.write_scalar(&text).map_err(|e| h5_error("cannot write /manifest".into(), e))?;
    Ok(describe(&dataset, &MANIFEST)?)
}
