//! HDF5 export and import of the artifact kinds that hold arrays (feature `hdf5`).
//!
//! `yarnhom convert --to hdf5` writes an artifact as an HDF5 file that any HDF5 reader (h5py,
//! MATLAB, HDFView, ...) can open; [`import`] reads such a file back into the exact artifact. Only
//! kinds made of arrays have a layout, today `pattern`, `grid` and `swatch`; a `yarnmodel` (a
//! handful of scalars) is refused with [`Error::Unrepresentable`]: use JSON for it.
//!
//! # Layout of a `pattern` (schema version 1)
//!
//! `n` is the number of vertices (= edges), `Y` the number of yarns. All numbers are stored in
//! native little-endian HDF5 types, `f64` values bit for bit.
//!
//! Root attributes (scalar; strings are variable-length UTF-8):
//!
//! | attribute | type | meaning |
//! |---|---|---|
//! | `yarnhom_kind` | string | `pattern`: marks the file as a yarnhom export |
//! | `schema_version` | u32 | schema version of the kind (1) |
//! | `content_hash` | string | `sha256:<hex>` of the pattern's msgpack payload, as in a `.yh` file |
//! | `producer_name`, `producer_version` | string | the program that made the artifact |
//! | `created_utc` | string | creation time, RFC 3339 UTC |
//! | `inputs` | string | JSON list of `{"kind", "content_hash", "path"}` the artifact was made from |
//! | `name` | string | pattern name |
//! | `fabric` | string | `knit` or `woven` |
//! | `origin` | string | how the pattern was made |
//!
//! Datasets (each with string attributes `units` and `description`):
//!
//! | dataset | type, shape | units | meaning |
//! |---|---|---|---|
//! | `/period_m` | f64 `[2]` | m | tile periods along X1, X2 |
//! | `/positions_m` | f64 `[n, 3]` | m | vertex positions |
//! | `/edge_twist_rad` | f64 `[n]` | rad | twist of the edge leaving each vertex |
//! | `/yarns/radius_m` | f64 `[Y]` | m | yarn radii |
//! | `/yarns/vertex_start` | u64 `[Y+1]` | 1 | CSR row pointer: yarn `y` owns rows `vertex_start[y] .. vertex_start[y+1]` of the next two |
//! | `/yarns/vertices` | u32 `[n]` | 1 | vertex indices (rows of `/positions_m`) along each yarn |
//! | `/yarns/edge_offsets` | i32 `[n, 2]` | 1 | whole tiles the end of each yarn edge is shifted by |
//! | `/rest/edge_length_m` | f64 `[n]` | m | rest length of the edge leaving each vertex |
//! | `/rest/vertex_curvature` | f64 `[n, 2]` | 1 | rest material curvature (kappa1, kappa2) |
//! | `/rest/vertex_twist_rad` | f64 `[n]` | rad | rest twist at each vertex |
//! | `/rest/edge_reference_director` | f64 `[n, 3]` | 1 | reference director d1 of each edge |
//! | `/rest/vertex_reference_twist_rad` | f64 `[n]` | rad | reference twist at each vertex |
//!
//! The group `/rest` exists exactly when the pattern has a rest state. Per-edge rows are indexed
//! by the edge's source vertex, as in [`Pattern`]; `edge_offsets` rows follow `/yarns/vertices`.
//!
//! # Layout of a `grid` (schema version 1)
//!
//! `n` samples, `T` terms, `V` vertices per sample (with geometry). Root attributes: those of a
//! pattern from `yarnhom_kind` (`grid`) to `inputs`, then `pattern` and `model` (strings), and
//! `shard_index`, `shard_count` (u32) for a partial grid only. Datasets (with `units` and
//! `description`):
//!
//! | dataset | type, shape | units | meaning |
//! |---|---|---|---|
//! | `/axes/sx`, `/axes/sa`, `/axes/sy`, `/axes/kx`, `/axes/ky` | f64 `[len]` | 1 (1/m for kx, ky) | sampled values of each strain axis |
//! | `/terms/axes` | i32 `[T, 2]` | 1 | axis indices of each term; the second is -1 for a 1D term |
//! | `/samples/term` | u32 `[n]` | 1 | term of each sample |
//! | `/samples/index` | u32 `[n, 2]` | 1 | indices into the term's axes' values (second 0 for 1D) |
//! | `/samples/strain` | f64 `[n, 5]` | 1, 1/m | strain, columns sx, sa, sy, kx, ky |
//! | `/samples/converged` | u8 `[n]` | 1 | 1 if converged, else 0 |
//! | `/samples/stop_reason` | string `[n]` | 1 | variable-length UTF-8, why the solver stopped |
//! | `/samples/energy_density_j_m2` | f64 `[n]` | J/m² | energy density (3.22), NaN where not converged |
//! | `/samples/stress` | f64 `[n, 5]` | J/m², J/m | stress (3.23c), NaN rows where absent |
//! | `/samples/iterations` | u32 `[n]` | 1 | Newton iterations |
//! | `/samples/seconds` | f64 `[n]` | s | wall time |
//! | `/samples/positions_m` | f64 `[n, V, 3]` | m | equilibrium vertices (optional) |
//! | `/samples/edge_twist_rad` | f64 `[n, V]` | rad | equilibrium edge twists (with positions) |
//!
//! # Layout of a `swatch` (schema version 1)
//!
//! `N` vertices, `E` edges, `Y` yarns, `G` glue springs. Root attributes: those of a pattern from
//! `yarnhom_kind` (`swatch`) to `inputs`, then `name`, `yarnmodel` (the yarn model's payload as
//! JSON) and `glue_settings` (JSON: `reach_radii`, `pre_stretch`, `stiffness_n_m` or null).
//! Datasets (with `units` and `description`):
//!
//! | dataset | type, shape | units | meaning |
//! |---|---|---|---|
//! | `/size_m` | f64 `[2]` | m | width and height of the cut rectangle |
//! | `/vertices/position_m` | f64 `[N, 3]` | m | vertex positions, yarn after yarn |
//! | `/vertices/source_vertex` | u32 `[N]` | 1 | pattern vertex each vertex copies |
//! | `/vertices/source_tile` | i32 `[N, 2]` | 1 | tile `(i, j)` of the copy |
//! | `/vertices/rest_curvature` | f64 `[N, 2]` | 1 | rest material curvature; zero at open ends |
//! | `/vertices/rest_twist_rad` | f64 `[N]` | rad | rest twist; zero at open ends |
//! | `/vertices/reference_twist_rad` | f64 `[N]` | rad | reference twist; zero at open ends |
//! | `/edges/twist_rad` | f64 `[E]` | rad | material frame angle relative to the reference frame |
//! | `/edges/rest_length_m` | f64 `[E]` | m | rest length |
//! | `/edges/reference_director` | f64 `[E, 3]` | 1 | reference director d1 (unit) |
//! | `/yarns/radius_m` | f64 `[Y]` | m | yarn radius |
//! | `/yarns/first_vertex`, `/yarns/vertex_count` | u32 `[Y]` | 1 | each yarn's contiguous vertex range |
//! | `/yarns/closed` | u8 `[Y]` | 1 | 1 for a closed yarn (`n` edges), 0 for an open one (`n - 1`) |
//! | `/yarns/source_yarn` | u32 `[Y]` | 1 | pattern yarn it was cut from |
//! | `/glue/vertices` | u32 `[G, 2]` | 1 | the vertices each glue spring joins (cut end first) |
//! | `/glue/rest_length_m` | f64 `[G]` | m | glue spring rest length |
//! | `/glue/stiffness_n_m` | f64 `[G]` | N/m | glue spring stiffness |
//! | `/pattern/...` | | | the source pattern in the pattern layout above, its attributes `name`, `fabric`, `origin` on the group `/pattern` |
//!
//! # Choices
//!
//! - No chunking and no compression: a pattern is one periodic tile, a few hundred vertices in
//!   the published patterns (about 100 bytes per vertex in all), so deflate would save a few kB
//!   at best (the f64 mantissas barely compress) while chunk indexes cost about as much. The
//!   contiguous layout also needs no filter in the reader.
//! - `kind`, `schema_version` and `content_hash` describe the artifact as written (a migrated
//!   artifact gets the hash of its current payload); producer, creation time and inputs are the
//!   header's. [`import`] recomputes the content hash of what it read and refuses a file whose
//!   data no longer matches it ([`Error::ContentHashMismatch`]): edit the `.yh` artifact instead,
//!   or re-export.
//! - Objects are written without HDF5 modification times, so the same artifact and header give
//!   the same bytes (reproducible builds, like `SOURCE_DATE_EPOCH` for `.yh` files).
//! - The file is written to a temporary file in the destination folder, synced, then renamed:
//!   a reader never sees a half-written file.

use std::path::Path;

use ::hdf5::types::{TypeDescriptor, VarLenAscii, VarLenUnicode};
use ::hdf5::{Dataset, File, Group, H5Type, Location};

use crate::container::{self, Header, InputRef, Producer};
use crate::error::{Error, Result, ValidationError};
use crate::grid::Grid;
use crate::pattern::{Fabric, Pattern, RestState, Yarn};
use crate::swatch::Swatch;
use crate::{AnyArtifact, Artifact, AtomicFile};

mod grid;
pub mod layer;
mod swatch;

use layer::{Spec, create_group, describe, h5, write_str_attr, write_u32_attr};

const FORMAT: &str = "hdf5";

/// Root attribute marking a yarnhom export and naming its kind.
pub const KIND_ATTR: &str = "yarnhom_kind";

/// A dataset of the layout: its path and the `units` and `description` attributes it carries.
struct DatasetSpec {
    path: &'static str,
    spec: Spec,
}

const PERIOD: DatasetSpec =
    DatasetSpec { path: "/period_m", spec: Spec { units: "m", description: "tile periods along X1 and X2" } };
const POSITIONS: DatasetSpec = DatasetSpec {
    path: "/positions_m",
    spec: Spec {
        units: "m",
        description: "yarn centreline vertex positions in tile coordinates, one row per vertex",
    },
};
const EDGE_TWIST: DatasetSpec = DatasetSpec {
    path: "/edge_twist_rad",
    spec: Spec {
        units: "rad",
        description: "twist of the material frame relative to the reference frame on the edge leaving each vertex",
    },
};
const YARN_RADIUS: DatasetSpec =
    DatasetSpec { path: "/yarns/radius_m", spec: Spec { units: "m", description: "radius of each yarn" } };
const YARN_START: DatasetSpec = DatasetSpec {
    path: "/yarns/vertex_start",
    spec: Spec {
        units: "1",
        description: "CSR row pointer: yarn y owns rows vertex_start[y]..vertex_start[y+1] of /yarns/vertices and /yarns/edge_offsets",
    },
};
const YARN_VERTICES: DatasetSpec = DatasetSpec {
    path: "/yarns/vertices",
    spec: Spec {
        units: "1",
        description: "vertex indices (rows of /positions_m) in order along each yarn; each yarn is closed periodically",
    },
};
const YARN_OFFSETS: DatasetSpec = DatasetSpec {
    path: "/yarns/edge_offsets",
    spec: Spec {
        units: "1",
        description: "whole tiles (along X1, X2) the end of each yarn edge is shifted by; the edge of row k joins vertices[k] to the next vertex of its yarn (cyclically)",
    },
};
const REST_LENGTH: DatasetSpec = DatasetSpec {
    path: "/rest/edge_length_m",
    spec: Spec { units: "m", description: "rest length of the edge leaving each vertex" },
};
const REST_CURVATURE: DatasetSpec = DatasetSpec {
    path: "/rest/vertex_curvature",
    spec: Spec {
        units: "1",
        description: "rest material curvature (kappa1, kappa2) at each vertex, integrated (dimensionless)",
    },
};
const REST_TWIST: DatasetSpec = DatasetSpec {
    path: "/rest/vertex_twist_rad",
    spec: Spec { units: "rad", description: "rest twist at each vertex" },
};
const REST_DIRECTOR: DatasetSpec = DatasetSpec {
    path: "/rest/edge_reference_director",
    spec: Spec {
        units: "1",
        description: "first director of the reference frame of the edge leaving each vertex (unit vector)",
    },
};
const REST_REF_TWIST: DatasetSpec = DatasetSpec {
    path: "/rest/vertex_reference_twist_rad",
    spec: Spec { units: "rad", description: "reference twist at each vertex" },
};

/// Write an artifact to an HDF5 file at `path`, atomically (see the [module docs](self) for the
/// layout). `header` supplies the producer, creation time and inputs; the kind, schema version
/// and content hash are those of `artifact`. Kinds without arrays are
/// [`Error::Unrepresentable`]. Errors name the file.
pub fn export(path: &Path, header: &Header, artifact: &AnyArtifact) -> Result<()> {
    match artifact {
        AnyArtifact::Pattern(p) => export_as(path, header, p, write_pattern),
        AnyArtifact::Grid(g) => export_as(path, header, g, grid::write_grid),
        AnyArtifact::Swatch(s) => export_as(path, header, s, swatch::write_swatch),
        AnyArtifact::YarnModel(_) => Err(Error::Unrepresentable {
            format: FORMAT,
            message: "a yarnmodel holds no arrays, so it has no HDF5 layout; use `--to json`".into(),
        }),
        AnyArtifact::Spline(_) => Err(Error::Unrepresentable {
            format: FORMAT,
            message: "a spline material is small and nested; use `--to json` or `fit export-arcsim`".into(),
        }),
        AnyArtifact::RveSolve(_) => Err(Error::Unrepresentable {
            format: FORMAT,
            message: "rvesolve has no HDF5 layout yet (grids of solves will); use `--to json`".into(),
        }),
    }
    .map_err(|e| e.at(path))
}

/// Read an HDF5 file written by [`export`] back into its header and artifact. The artifact is
/// validated and its content hash checked against the file's. Errors name the file and the
/// offending dataset or attribute.
pub fn import(path: &Path) -> Result<(Header, AnyArtifact)> {
    import_any(path).map_err(|e| e.at(path))
}

// ---------------------------------------------------------------------------------------------
// Export

/// Validate `artifact`, then write it atomically: the root attributes every export carries,
/// then the kind's own attributes and datasets by `write`.
fn export_as<T: Artifact>(
    path: &Path,
    header: &Header,
    artifact: &T,
    write: fn(&Group, &T) -> Result<()>,
) -> Result<()> {
    artifact.validate().map_err(|problem| Error::Invalid { kind: T::KIND, problem })?;
    let content_hash = container::content_hash(&container::payload_of(artifact)?);
    let inputs = serde_json::to_string(&header.inputs)
        .map_err(|e| Error::Encode { what: "inputs", message: e.to_string() })?;

    let mut target = AtomicFile::create(path)?;
    let file = File::with_options()
        .with_fcpl(|fcpl| fcpl.obj_track_times(false))
        .create(target.temp_path())
        .map_err(|e| h5("cannot create the HDF5 file", e))?;
    write_header::<T>(&file, header, &content_hash, &inputs)?;
    write(&file, artifact)?;
    file.close().map_err(|e| h5("cannot close the HDF5 file", e))?;
    Ok(target.commit()?)
}

/// The root attributes of every export: kind, schema version, content hash, provenance.
fn write_header<T: Artifact>(root: &Group, header: &Header, content_hash: &str, inputs: &str) -> Result<()> {
    write_str_attr(root, KIND_ATTR, T::KIND)?;
    write_u32_attr(root, "schema_version", T::SCHEMA_VERSION)?;
    write_str_attr(root, "content_hash", content_hash)?;
    write_str_attr(root, "producer_name", &header.producer.name)?;
    write_str_attr(root, "producer_version", &header.producer.version)?;
    write_str_attr(root, "created_utc", &header.created_utc)?;
    write_str_attr(root, "inputs", inputs)
}

fn write_pattern(root: &Group, p: &Pattern) -> Result<()> {
    write_str_attr(root, "name", &p.name)?;
    write_str_attr(root, "fabric", &p.fabric.to_string())?;
    write_str_attr(root, "origin", &p.origin)?;

    let n = p.vertex_count();
    write_dataset(root, &PERIOD, &[2], &p.period_m)?;
    write_dataset(root, &POSITIONS, &[n, 3], p.positions_m.as_flattened())?;
    write_dataset(root, &EDGE_TWIST, &[n], &p.edge_twist_rad)?;

    create_group(root, "yarns")?;
    let radius: Vec<f64> = p.yarns.iter().map(|y| y.radius_m).collect();
    let mut start = Vec::with_capacity(p.yarns.len() + 1);
    start.push(0u64);
    let mut vertices = Vec::with_capacity(n);
    let mut offsets = Vec::with_capacity(n);
    for yarn in &p.yarns {
        vertices.extend_from_slice(&yarn.vertices);
        offsets.extend_from_slice(&yarn.edge_offsets);
        start.push(vertices.len() as u64);
    }
    let m = vertices.len();
    write_dataset(root, &YARN_RADIUS, &[radius.len()], &radius)?;
    write_dataset(root, &YARN_START, &[start.len()], &start)?;
    write_dataset(root, &YARN_VERTICES, &[m], &vertices)?;
    write_dataset(root, &YARN_OFFSETS, &[m, 2], offsets.as_flattened())?;

    if let Some(rest) = &p.rest {
        create_group(root, "rest")?;
        write_dataset(root, &REST_LENGTH, &[n], &rest.edge_length_m)?;
        write_dataset(root, &REST_CURVATURE, &[n, 2], rest.vertex_curvature.as_flattened())?;
        write_dataset(root, &REST_TWIST, &[n], &rest.vertex_twist_rad)?;
        write_dataset(root, &REST_DIRECTOR, &[n, 3], rest.edge_reference_director.as_flattened())?;
        write_dataset(root, &REST_REF_TWIST, &[n], &rest.vertex_reference_twist_rad)?;
    }
    Ok(())
}

/// Write a dataset at `dataset.path` below `root` (the file's root, or a group such as a
/// swatch's `/pattern`).
fn write_dataset<T: H5Type>(root: &Group, dataset: &DatasetSpec, shape: &[usize], data: &[T]) -> Result<()> {
    let path = located(root, dataset.path);
    let ds = root
        .new_dataset_builder()
        .obj_track_times(false)
        .empty::<T>()
        .shape(shape)
        .create(relative(dataset.path))
        .map_err(|e| h5(format_args!("cannot create dataset {path}"), e))?;
    ds.write_raw(data).map_err(|e| h5(format_args!("cannot write dataset {path}"), e))?;
    describe(&ds, &dataset.spec)
}

/// A layout path (`/a/b`) relative to the group it is written in (`a/b`).
fn relative(path: &str) -> &str {
    path.trim_start_matches('/')
}

/// The path a layout path has in the file when written below `group`: `/a/b` below the root,
/// `/pattern/a/b` below `/pattern`.
fn located(group: &Group, path: &str) -> String {
    format!("{}{path}", group.name().trim_end_matches('/'))
}

// ---------------------------------------------------------------------------------------------
// Import

fn import_any(path: &Path) -> Result<(Header, AnyArtifact)> {
    // An absent file is an i/o error, not an HDF5 one.
    std::fs::metadata(path)?;
    let file = File::open(path)
        .map_err(|e| Error::Hdf5(format!("not an HDF5 file, or not readable as one ({e})")))?;
    if !has_attr(&file, KIND_ATTR)? {
        return Err(Error::Hdf5(format!(
            "not a yarnhom HDF5 export: the root group has no '{KIND_ATTR}' attribute"
        )));
    }
    let kind = read_str_attr(&file, KIND_ATTR)?;
    match kind.as_str() {
        k if k == Pattern::KIND => {
            let (header, pattern) = read_as(&file, read_pattern)?;
            Ok((header, AnyArtifact::Pattern(pattern)))
        }
        k if k == Grid::KIND => {
            let (header, grid) = read_as(&file, grid::read_grid)?;
            Ok((header, AnyArtifact::Grid(grid)))
        }
        k if k == Swatch::KIND => {
            let (header, swatch) = read_as(&file, swatch::read_swatch)?;
            Ok((header, AnyArtifact::Swatch(swatch)))
        }
        k if crate::KINDS.contains(&k) => Err(Error::Hdf5(format!(
            "root attribute '{KIND_ATTR}' names kind '{k}', which has no HDF5 layout"
        ))),
        _ => Err(Error::UnknownKind(kind)),
    }
}

/// Read an export of kind `T`: check the schema version, read the provenance, the artifact (by
/// `read`), validate it and check its content hash.
fn read_as<T: Artifact>(root: &Group, read: fn(&Group) -> Result<T>) -> Result<(Header, T)> {
    let schema_version = read_u32_attr(root, "schema_version")?;
    match schema_version.cmp(&T::SCHEMA_VERSION) {
        std::cmp::Ordering::Greater => {
            return Err(Error::NewerSchema {
                kind: T::KIND.into(),
                found: schema_version,
                supported: T::SCHEMA_VERSION,
            });
        }
        std::cmp::Ordering::Less => {
            return Err(Error::NoMigration {
                kind: T::KIND.into(),
                found: schema_version,
                supported: T::SCHEMA_VERSION,
            });
        }
        std::cmp::Ordering::Equal => {}
    }
    let stored_hash = read_str_attr(root, "content_hash")?;
    let producer = Producer {
        name: read_str_attr(root, "producer_name")?,
        version: read_str_attr(root, "producer_version")?,
    };
    let created_utc = read_str_attr(root, "created_utc")?;
    let inputs: Vec<InputRef> = serde_json::from_str(&read_str_attr(root, "inputs")?)
        .map_err(|e| Error::Hdf5(format!("root attribute 'inputs' is not a JSON list of inputs: {e}")))?;
    let artifact = read(root)?;
    artifact.validate().map_err(|problem| Error::Invalid { kind: T::KIND, problem })?;
    let payload = container::payload_of(&artifact)?;
    let computed = container::content_hash(&payload);
    if computed != stored_hash {
        return Err(Error::ContentHashMismatch { stored: stored_hash, computed });
    }
    let header = Header {
        kind: T::KIND.into(),
        schema_version,
        producer,
        created_utc,
        inputs,
        content_hash: stored_hash,
        payload_bytes: payload.len() as u64,
    };
    Ok((header, artifact))
}

fn read_pattern(root: &Group) -> Result<Pattern> {
    let name = read_str_attr(root, "name")?;
    let fabric = match read_str_attr(root, "fabric")?.as_str() {
        "knit" => Fabric::Knit,
        "woven" => Fabric::Woven,
        other => {
            return Err(Error::Hdf5(format!(
                "{} must be 'knit' or 'woven', found '{other}'",
                attr_label(root, "fabric")
            )));
        }
    };
    let origin = read_str_attr(root, "origin")?;

    let (positions, shape) = read_dataset::<f64>(root, &POSITIONS, &[None, Some(3)])?;
    let n = shape[0];
    let period = read_dataset::<f64>(root, &PERIOD, &[Some(2)])?.0;
    let edge_twist_rad = read_dataset::<f64>(root, &EDGE_TWIST, &[Some(n)])?.0;

    let (radius, shape) = read_dataset::<f64>(root, &YARN_RADIUS, &[None])?;
    let y = shape[0];
    let start = read_dataset::<u64>(root, &YARN_START, &[Some(y + 1)])?.0;
    let vertices = read_dataset::<u32>(root, &YARN_VERTICES, &[Some(n)])?.0;
    let offsets = rows::<i32, 2>(read_dataset(root, &YARN_OFFSETS, &[Some(n), Some(2)])?.0);
    let ranges = csr_ranges(&start, n)?;
    let yarns = radius
        .iter()
        .zip(ranges)
        .map(|(&radius_m, r)| Yarn {
            radius_m,
            vertices: vertices[r.clone()].to_vec(),
            edge_offsets: offsets[r].to_vec(),
        })
        .collect();

    let rest = if root.link_exists("rest") {
        Some(RestState {
            edge_length_m: read_dataset(root, &REST_LENGTH, &[Some(n)])?.0,
            vertex_curvature: rows(read_dataset(root, &REST_CURVATURE, &[Some(n), Some(2)])?.0),
            vertex_twist_rad: read_dataset(root, &REST_TWIST, &[Some(n)])?.0,
            edge_reference_director: rows(read_dataset(root, &REST_DIRECTOR, &[Some(n), Some(3)])?.0),
            vertex_reference_twist_rad: read_dataset(root, &REST_REF_TWIST, &[Some(n)])?.0,
        })
    } else {
        None
    };

    Ok(Pattern {
        name,
        fabric,
        period_m: [period[0], period[1]],
        positions_m: rows(positions),
        edge_twist_rad,
        yarns,
        rest,
        origin,
    })
}

/// The row ranges of a CSR row pointer over `n` rows, checked.
fn csr_ranges(start: &[u64], n: usize) -> Result<Vec<std::ops::Range<usize>>> {
    let bad = |problem: String| Error::Invalid {
        kind: Pattern::KIND,
        problem: ValidationError::new(YARN_START.path, problem),
    };
    let (Some(&first), Some(&last)) = (start.first(), start.last()) else {
        return Err(bad("is empty; it needs one entry more than there are yarns".into()));
    };
    if first != 0 {
        return Err(bad(format!("must start at 0, starts at {first}")));
    }
    if last != n as u64 {
        return Err(bad(format!(
            "must end at the number of rows of {} ({n}), ends at {last}",
            YARN_VERTICES.path
        )));
    }
    start
        .windows(2)
        .enumerate()
        .map(|(y, w)| {
            if w[0] > w[1] {
                Err(bad(format!(
                    "must not decrease, but entry {} ({}) > entry {} ({})",
                    y,
                    w[0],
                    y + 1,
                    w[1]
                )))
            } else {
                // Both are <= n, a usize, so they fit.
                Ok(w[0] as usize..w[1] as usize)
            }
        })
        .collect()
}

/// Group a flat row-major array into rows of `N` (the length is a multiple of `N`).
fn rows<T: Copy, const N: usize>(flat: Vec<T>) -> Vec<[T; N]> {
    flat.chunks_exact(N).map(|c| std::array::from_fn(|i| c[i])).collect()
}

/// Does the layout path `path` (`/a/b`) name a link below `root`? Checks each level, as HDF5
/// refuses to look below a missing group.
fn exists(root: &Group, path: &str) -> bool {
    let mut prefix = String::new();
    relative(path).split('/').all(|part| {
        if !prefix.is_empty() {
            prefix.push('/');
        }
        prefix.push_str(part);
        root.link_exists(&prefix)
    })
}

/// Read a whole dataset of element type `T`, checking its dtype and its shape (`None`: any
/// extent). Returns the row-major data and the shape.
fn read_dataset<T: H5Type>(
    root: &Group,
    spec: &DatasetSpec,
    expected: &[Option<usize>],
) -> Result<(Vec<T>, Vec<usize>)> {
    let path = located(root, spec.path);
    if !exists(root, spec.path) {
        return Err(Error::Hdf5(format!("missing dataset {path}")));
    }
    let ds: Dataset = root
        .dataset(relative(spec.path))
        .map_err(|e| h5(format_args!("{path} is not a readable dataset"), e))?;
    let found = ds
        .dtype()
        .and_then(|t| t.to_descriptor())
        .map_err(|e| h5(format_args!("dataset {path}: unreadable dtype"), e))?;
    let want = T::type_descriptor();
    if found != want {
        return Err(Error::Hdf5(format!("dataset {path} has dtype {found}, expected {want}")));
    }
    let shape = ds.get_shape().map_err(|e| h5(format_args!("dataset {path}: unreadable shape"), e))?;
    let fits =
        shape.len() == expected.len() && shape.iter().zip(expected).all(|(&s, e)| e.is_none_or(|e| e == s));
    if !fits {
        let want: Vec<String> =
            expected.iter().map(|e| e.map_or("any".to_string(), |e| e.to_string())).collect();
        return Err(Error::Hdf5(format!(
            "dataset {path} has shape {shape:?}, expected [{}]",
            want.join(", ")
        )));
    }
    let data = ds.read_raw::<T>().map_err(|e| h5(format_args!("cannot read dataset {path}"), e))?;
    if data.len() != shape.iter().product::<usize>() {
        return Err(Error::Hdf5(format!("dataset {path}: read {} values for shape {shape:?}", data.len())));
    }
    Ok((data, shape))
}

fn has_attr(loc: &Location, name: &str) -> Result<bool> {
    let names =
        loc.attr_names().map_err(|e| h5(format_args!("cannot list the attributes of {}", loc.name()), e))?;
    Ok(names.iter().any(|a| a == name))
}

/// An attribute as errors name it: `root attribute 'x'`, or `attribute 'x' of /pattern` below
/// the root.
fn attr_label(loc: &Location, name: &str) -> String {
    match loc.name().as_str() {
        "/" => format!("root attribute '{name}'"),
        group => format!("attribute '{name}' of {group}"),
    }
}

fn open_attr(loc: &Location, name: &str) -> Result<::hdf5::Attribute> {
    let label = attr_label(loc, name);
    if !has_attr(loc, name)? {
        return Err(Error::Hdf5(format!("missing {label}")));
    }
    loc.attr(name).map_err(|e| h5(format_args!("cannot open {label}"), e))
}

fn read_str_attr(loc: &Location, name: &str) -> Result<String> {
    let attr = open_attr(loc, name)?;
    let label = attr_label(loc, name);
    let err = |e| h5(format_args!("cannot read {label}"), e);
    match attr.dtype().and_then(|t| t.to_descriptor()).map_err(err)? {
        TypeDescriptor::VarLenUnicode => {
            attr.read_scalar::<VarLenUnicode>().map(|s| s.as_str().to_owned()).map_err(err)
        }
        TypeDescriptor::VarLenAscii => {
            attr.read_scalar::<VarLenAscii>().map(|s| s.as_str().to_owned()).map_err(err)
        }
        other => Err(Error::Hdf5(format!("{label} has type {other}, expected a variable-length string"))),
    }
}

fn read_u32_attr(loc: &Location, name: &str) -> Result<u32> {
    let attr = open_attr(loc, name)?;
    let label = attr_label(loc, name);
    let err = |e| h5(format_args!("cannot read {label}"), e);
    match attr.dtype().and_then(|t| t.to_descriptor()).map_err(err)? {
        TypeDescriptor::Integer(_) | TypeDescriptor::Unsigned(_) => {
            let v = attr.read_scalar::<i64>().map_err(err)?;
            u32::try_from(v)
                .map_err(|_| Error::Hdf5(format!("{label} is {v}, expected an unsigned 32-bit integer")))
        }
        other => Err(Error::Hdf5(format!("{label} has type {other}, expected an integer"))),
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;
    use crate::YarnModel;

    /// Two yarns with interleaved vertices, awkward floats (-0.0, subnormal, 0.1 + 0.2).
    fn pattern(with_rest: bool) -> Pattern {
        let p = 0.01;
        // Yarn 0 along X1 uses vertices 0, 2, 4, 6; yarn 1 along X2 uses 1, 3, 5.
        let positions_m = vec![
            [0.0, 0.002, -0.0],
            [0.005, 0.0, 0.001],
            [0.0025, 0.002, 0.1 + 0.2 - 0.3],
            [0.005, 0.1 / 3.0 * 0.1, -0.001],
            [0.005, 0.002, f64::MIN_POSITIVE / 4.0],
            [0.005, 0.007, 0.0005],
            [0.0075, 0.002, 1e-300],
        ];
        let n = positions_m.len();
        let rest = with_rest.then(|| RestState {
            edge_length_m: (0..n).map(|i| 0.0025 + i as f64 * 1e-17).collect(),
            vertex_curvature: (0..n).map(|i| [i as f64 * 0.1, -0.0]).collect(),
            vertex_twist_rad: (0..n).map(|i| (i as f64).sin()).collect(),
            edge_reference_director: (0..n)
                .map(|i| {
                    let a = i as f64 * 0.7;
                    [a.cos(), a.sin(), 0.0]
                })
                .collect(),
            vertex_reference_twist_rad: (0..n).map(|i| -(i as f64) / 7.0).collect(),
        });
        Pattern {
            name: "two-yarn test ü".into(),
            fabric: Fabric::Woven,
            period_m: [p, p * (1.0 + f64::EPSILON)],
            positions_m,
            edge_twist_rad: (0..n).map(|i| i as f64 / 3.0 - 1.0).collect(),
            yarns: vec![
                Yarn {
                    radius_m: 0.0005,
                    vertices: vec![0, 2, 4, 6],
                    edge_offsets: vec![[0, 0], [0, 0], [0, 0], [1, 0]],
                },
                Yarn {
                    radius_m: 0.1 + 0.2,
                    vertices: vec![1, 3, 5],
                    edge_offsets: vec![[0, 0], [0, 0], [0, 1]],
                },
            ],
            rest,
            origin: "hand-made for hdf5 tests".into(),
        }
    }

    fn header_of(p: &Pattern) -> Header {
        let payload = container::payload_of(p).unwrap();
        let provenance = container::Provenance {
            producer: Producer { name: "yarnhom test".into(), version: "9.9.9".into() },
            inputs: vec![InputRef {
                kind: "pyp".into(),
                content_hash: container::content_hash(b"abc"),
                path: "dir/with \"quotes\"/x.pyp".into(),
            }],
        };
        container::header_for::<Pattern>(&payload, &provenance)
    }

    fn bits(p: &Pattern) -> Vec<u64> {
        let mut out: Vec<f64> = p.period_m.to_vec();
        out.extend(p.positions_m.iter().flatten());
        out.extend(&p.edge_twist_rad);
        out.extend(p.yarns.iter().map(|y| y.radius_m));
        if let Some(r) = &p.rest {
            out.extend(&r.edge_length_m);
            out.extend(r.vertex_curvature.iter().flatten());
            out.extend(&r.vertex_twist_rad);
            out.extend(r.edge_reference_director.iter().flatten());
            out.extend(&r.vertex_reference_twist_rad);
        }
        out.into_iter().map(f64::to_bits).collect()
    }

    fn round_trip(with_rest: bool) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.h5");
        let p = pattern(with_rest);
        p.validate().unwrap();
        let header = header_of(&p);
        export(&path, &header, &AnyArtifact::Pattern(p.clone())).unwrap();
        let (h, back) = import(&path).unwrap();
        let AnyArtifact::Pattern(back) = back else { panic!("not a pattern") };
        assert_eq!(back, p);
        assert_eq!(bits(&back), bits(&p));
        assert_eq!(h, header);
        assert_eq!(back.rest.is_some(), with_rest);
        // Only the exported file is left: no temporary file.
        let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 1);
    }

    #[test]
    fn round_trip_with_rest_is_exact() {
        round_trip(true);
    }

    #[test]
    fn round_trip_without_rest_is_exact() {
        round_trip(false);
    }

    #[test]
    fn export_is_reproducible_and_replaces_atomically() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.h5"), dir.path().join("b.h5"));
        let p = pattern(true);
        let header = header_of(&p);
        let artifact = AnyArtifact::Pattern(p);
        export(&a, &header, &artifact).unwrap();
        std::fs::write(&b, b"old content").unwrap();
        export(&b, &header, &artifact).unwrap();
        assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    }

    #[test]
    fn yarnmodel_is_unrepresentable() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.h5");
        let model = YarnModel::table_4_1("rib").unwrap();
        let payload = container::payload_of(&model).unwrap();
        let header = container::header_for::<YarnModel>(&payload, &Default::default());
        let e = export(&path, &header, &AnyArtifact::YarnModel(model)).unwrap_err();
        match e.root() {
            Error::Unrepresentable { format, message } => {
                assert_eq!(*format, "hdf5");
                assert!(message.contains("--to json"), "{message}");
            }
            other => panic!("unexpected error {other}"),
        }
        assert!(std::fs::read_dir(dir.path()).unwrap().next().is_none());
    }

    #[test]
    fn invalid_pattern_is_not_exported() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.h5");
        let mut p = pattern(false);
        let header = header_of(&p);
        p.yarns[0].radius_m = -1.0;
        let e = export(&path, &header, &AnyArtifact::Pattern(p)).unwrap_err();
        assert!(matches!(e.root(), Error::Invalid { .. }), "{e}");
        assert!(std::fs::read_dir(dir.path()).unwrap().next().is_none());
    }

    #[test]
    fn foreign_hdf5_file_is_refused_clearly() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("foreign.h5");
        {
            let f = File::create(&path).unwrap();
            f.new_dataset_builder().with_data(&[1.0f64, 2.0, 3.0]).create("temperature").unwrap();
        }
        let e = import(&path).unwrap_err();
        let message = e.to_string();
        assert!(matches!(e.root(), Error::Hdf5(_)), "{message}");
        assert!(message.contains("not a yarnhom HDF5 export"), "{message}");
        assert!(message.contains("foreign.h5"), "{message}");
    }

    #[test]
    fn non_hdf5_and_missing_files_are_errors() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("text.h5");
        std::fs::write(&path, "*pattern\n1 2 3 4\n").unwrap();
        let e = import(&path).unwrap_err();
        assert!(matches!(e.root(), Error::Hdf5(_)), "{e}");
        assert!(e.to_string().contains("not an HDF5 file"), "{e}");
        std::fs::write(&path, b"").unwrap();
        assert!(import(&path).is_err());
        let e = import(&dir.path().join("absent.h5")).unwrap_err();
        assert!(matches!(e.root(), Error::Io(_)), "{e}");
    }

    /// Export a valid pattern, let `edit` change the file, import it and return the error.
    fn import_error_after(edit: impl FnOnce(&File)) -> Error {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.h5");
        let p = pattern(true);
        export(&path, &header_of(&p), &AnyArtifact::Pattern(p)).unwrap();
        {
            let f = File::open_rw(&path).unwrap();
            edit(&f);
        }
        import(&path).unwrap_err()
    }

    #[test]
    fn missing_dataset_is_named() {
        let e = import_error_after(|f| f.unlink("yarns/vertices").unwrap());
        assert!(e.to_string().contains("missing dataset /yarns/vertices"), "{e}");
        let e = import_error_after(|f| f.unlink("rest/vertex_twist_rad").unwrap());
        assert!(e.to_string().contains("missing dataset /rest/vertex_twist_rad"), "{e}");
        let e = import_error_after(|f| f.unlink("yarns").unwrap());
        assert!(e.to_string().contains("missing dataset /yarns/"), "{e}");
    }

    #[test]
    fn wrong_dtype_is_named() {
        let e = import_error_after(|f| {
            f.unlink("yarns/vertices").unwrap();
            f.new_dataset_builder().with_data(&[0.0f64; 7]).create("yarns/vertices").unwrap();
        });
        let message = e.to_string();
        assert!(message.contains("/yarns/vertices"), "{message}");
        assert!(message.contains("dtype float64, expected uint32"), "{message}");
    }

    #[test]
    fn wrong_shape_is_named() {
        let e = import_error_after(|f| {
            f.unlink("edge_twist_rad").unwrap();
            f.new_dataset_builder().with_data(&[0.0f64; 6]).create("edge_twist_rad").unwrap();
        });
        let message = e.to_string();
        assert!(message.contains("dataset /edge_twist_rad has shape [6], expected [7]"), "{message}");
        let e = import_error_after(|f| {
            f.unlink("positions_m").unwrap();
            f.new_dataset_builder().with_data(&[0.0f64; 14]).create("positions_m").unwrap();
        });
        assert!(e.to_string().contains("/positions_m has shape [14]"), "{e}");
    }

    #[test]
    fn broken_csr_and_invariants_are_refused() {
        let e = import_error_after(|f| {
            f.dataset("yarns/vertex_start").unwrap().write_raw(&[0u64, 5, 4]).unwrap();
        });
        assert!(matches!(e.root(), Error::Invalid { .. }), "{e}");
        assert!(e.to_string().contains("/yarns/vertex_start"), "{e}");
        // A duplicated vertex: the CSR is fine, the pattern is not.
        let e = import_error_after(|f| {
            f.dataset("yarns/vertices").unwrap().write_raw(&[0u32, 2, 4, 6, 1, 3, 3]).unwrap();
        });
        assert!(matches!(e.root(), Error::Invalid { .. }), "{e}");
    }

    #[test]
    fn modified_data_fails_the_content_hash() {
        let e = import_error_after(|f| {
            f.dataset("edge_twist_rad").unwrap().write_raw(&[0.5f64; 7]).unwrap();
        });
        assert!(matches!(e.root(), Error::ContentHashMismatch { .. }), "{e}");
    }

    #[test]
    fn bad_root_attributes_are_named() {
        let e = import_error_after(|f| f.delete_attr("created_utc").unwrap());
        assert!(e.to_string().contains("missing root attribute 'created_utc'"), "{e}");
        let e = import_error_after(|f| {
            f.attr("schema_version").unwrap().write_scalar(&2u32).unwrap();
        });
        assert!(matches!(e.root(), Error::NewerSchema { found: 2, .. }), "{e}");
        let e = import_error_after(|f| {
            let v: VarLenUnicode = "fleece".parse().unwrap();
            f.attr("yarnhom_kind").unwrap().write_scalar(&v).unwrap();
        });
        assert!(matches!(e.root(), Error::UnknownKind(k) if k == "fleece"), "{e}");
        let e = import_error_after(|f| {
            let v: VarLenUnicode = "felt".parse().unwrap();
            f.attr("fabric").unwrap().write_scalar(&v).unwrap();
        });
        assert!(e.to_string().contains("'fabric'"), "{e}");
    }
}
