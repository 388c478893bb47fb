//! The HDF5 layout of a `swatch` (see the [module docs](super) and `schemas/hdf5.md`).
//!
//! `N` vertices, `E` edges, `Y` yarns, `G` glue springs. The yarn model and the glue settings are
//! JSON root attributes (a handful of scalars each); the source pattern is the group `/pattern`
//! in the pattern layout.

use ::hdf5::Group;

use super::layer::{Spec, create_group, h5, write_str_attr};
use super::{DatasetSpec, read_dataset, read_pattern, read_str_attr, rows, write_dataset, write_pattern};
use crate::error::{Error, Result};
use crate::swatch::{GlueSettings, GlueSpring, Swatch, SwatchYarn};
use crate::yarnmodel::YarnModel;

const SIZE: DatasetSpec = DatasetSpec {
    path: "/size_m",
    spec: Spec {
        units: "m",
        description: "width and height of the cut rectangle [0, W] x [0, H] in the pattern's tile coordinates",
    },
};
const POSITION: DatasetSpec = DatasetSpec {
    path: "/vertices/position_m",
    spec: Spec { units: "m", description: "yarn centreline vertex positions, yarn after yarn" },
};
const SOURCE_VERTEX: DatasetSpec = DatasetSpec {
    path: "/vertices/source_vertex",
    spec: Spec {
        units: "1",
        description: "the pattern vertex (row of /pattern/positions_m) each vertex copies",
    },
};
const SOURCE_TILE: DatasetSpec = DatasetSpec {
    path: "/vertices/source_tile",
    spec: Spec {
        units: "1",
        description: "tile (i, j) of each vertex's copy: its position is the pattern vertex's plus (i P1, j P2, 0)",
    },
};
const REST_CURVATURE: DatasetSpec = DatasetSpec {
    path: "/vertices/rest_curvature",
    spec: Spec {
        units: "1",
        description: "rest material curvature (kappa1, kappa2) at each vertex, integrated; zero at open yarn ends",
    },
};
const REST_TWIST: DatasetSpec = DatasetSpec {
    path: "/vertices/rest_twist_rad",
    spec: Spec { units: "rad", description: "rest twist at each vertex; zero at open yarn ends" },
};
const REFERENCE_TWIST: DatasetSpec = DatasetSpec {
    path: "/vertices/reference_twist_rad",
    spec: Spec {
        units: "rad",
        description: "twist of the reference frame across each vertex; zero at open yarn ends",
    },
};
const EDGE_TWIST: DatasetSpec = DatasetSpec {
    path: "/edges/twist_rad",
    spec: Spec {
        units: "rad",
        description: "twist of each edge's material frame relative to its reference frame; edges yarn after yarn",
    },
};
const REST_LENGTH: DatasetSpec = DatasetSpec {
    path: "/edges/rest_length_m",
    spec: Spec { units: "m", description: "rest length of each edge" },
};
const REFERENCE_DIRECTOR: DatasetSpec = DatasetSpec {
    path: "/edges/reference_director",
    spec: Spec { units: "1", description: "first director of each edge's reference frame (unit vector)" },
};
const YARN_RADIUS: DatasetSpec =
    DatasetSpec { path: "/yarns/radius_m", spec: Spec { units: "m", description: "radius of each yarn" } };
const YARN_FIRST: DatasetSpec = DatasetSpec {
    path: "/yarns/first_vertex",
    spec: Spec { units: "1", description: "first vertex of each yarn; a yarn's vertices are contiguous" },
};
const YARN_COUNT: DatasetSpec = DatasetSpec {
    path: "/yarns/vertex_count",
    spec: Spec { units: "1", description: "number of vertices of each yarn" },
};
const YARN_CLOSED: DatasetSpec = DatasetSpec {
    path: "/yarns/closed",
    spec: Spec {
        units: "1",
        description: "1 if the yarn is a closed loop (n edges), 0 if open (n - 1 edges)",
    },
};
const YARN_SOURCE: DatasetSpec = DatasetSpec {
    path: "/yarns/source_yarn",
    spec: Spec { units: "1", description: "the pattern yarn each yarn was cut from" },
};
const GLUE_VERTICES: DatasetSpec = DatasetSpec {
    path: "/glue/vertices",
    spec: Spec {
        units: "1",
        description: "the two vertices of each glue spring; the first is the cut yarn end",
    },
};
const GLUE_REST_LENGTH: DatasetSpec = DatasetSpec {
    path: "/glue/rest_length_m",
    spec: Spec { units: "m", description: "rest length of each glue spring" },
};
const GLUE_STIFFNESS: DatasetSpec = DatasetSpec {
    path: "/glue/stiffness_n_m",
    spec: Spec { units: "N/m", description: "stiffness of each glue spring" },
};

pub(super) fn write_swatch(root: &Group, s: &Swatch) -> Result<()> {
    write_str_attr(root, "name", &s.name)?;
    write_str_attr(root, "yarnmodel", &json("the yarn model", &s.model)?)?;
    write_str_attr(root, "glue_settings", &json("the glue settings", &s.glue_settings)?)?;
    write_dataset(root, &SIZE, &[2], &s.size_m)?;
    write_vertices(root, s)?;
    write_edges(root, s)?;
    write_yarns(root, &s.yarns)?;
    write_glue(root, &s.glue)?;
    write_pattern(&create_group(root, "pattern")?, &s.pattern)
}

pub(super) fn read_swatch(root: &Group) -> Result<Swatch> {
    let size = read_dataset::<f64>(root, &SIZE, &[Some(2)])?.0;
    let (positions, shape) = read_dataset::<f64>(root, &POSITION, &[None, Some(3)])?;
    let n = Some(shape[0]);
    let (edge_twist_rad, shape) = read_dataset::<f64>(root, &EDGE_TWIST, &[None])?;
    let e = Some(shape[0]);
    let group = root.group("pattern").map_err(|err| h5("cannot open the group /pattern", err))?;
    Ok(Swatch {
        name: read_str_attr(root, "name")?,
        pattern: read_pattern(&group)?,
        model: from_json::<YarnModel>(root, "yarnmodel")?,
        size_m: [size[0], size[1]],
        positions_m: rows(positions),
        edge_twist_rad,
        source_vertex: read_dataset(root, &SOURCE_VERTEX, &[n])?.0,
        source_tile: rows(read_dataset(root, &SOURCE_TILE, &[n, Some(2)])?.0),
        yarns: read_yarns(root)?,
        rest_length_m: read_dataset(root, &REST_LENGTH, &[e])?.0,
        reference_director: rows(read_dataset(root, &REFERENCE_DIRECTOR, &[e, Some(3)])?.0),
        rest_curvature: rows(read_dataset(root, &REST_CURVATURE, &[n, Some(2)])?.0),
        rest_twist_rad: read_dataset(root, &REST_TWIST, &[n])?.0,
        reference_twist_rad: read_dataset(root, &REFERENCE_TWIST, &[n])?.0,
        glue: read_glue(root)?,
        glue_settings: from_json::<GlueSettings>(root, "glue_settings")?,
    })
}

fn write_vertices(root: &Group, s: &Swatch) -> Result<()> {
    let n = s.vertex_count();
    create_group(root, "vertices")?;
    write_dataset(root, &POSITION, &[n, 3], s.positions_m.as_flattened())?;
    write_dataset(root, &SOURCE_VERTEX, &[n], &s.source_vertex)?;
    write_dataset(root, &SOURCE_TILE, &[n, 2], s.source_tile.as_flattened())?;
    write_dataset(root, &REST_CURVATURE, &[n, 2], s.rest_curvature.as_flattened())?;
    write_dataset(root, &REST_TWIST, &[n], &s.rest_twist_rad)?;
    write_dataset(root, &REFERENCE_TWIST, &[n], &s.reference_twist_rad)
}

fn write_edges(root: &Group, s: &Swatch) -> Result<()> {
    let e = s.edge_count();
    create_group(root, "edges")?;
    write_dataset(root, &EDGE_TWIST, &[e], &s.edge_twist_rad)?;
    write_dataset(root, &REST_LENGTH, &[e], &s.rest_length_m)?;
    write_dataset(root, &REFERENCE_DIRECTOR, &[e, 3], s.reference_director.as_flattened())
}

fn write_yarns(root: &Group, yarns: &[SwatchYarn]) -> Result<()> {
    let y = yarns.len();
    create_group(root, "yarns")?;
    let column = |f: fn(&SwatchYarn) -> u32| yarns.iter().map(f).collect::<Vec<u32>>();
    let radius: Vec<f64> = yarns.iter().map(|y| y.radius_m).collect();
    let closed: Vec<u8> = yarns.iter().map(|y| u8::from(y.closed)).collect();
    write_dataset(root, &YARN_RADIUS, &[y], &radius)?;
    write_dataset(root, &YARN_FIRST, &[y], &column(|y| y.first_vertex))?;
    write_dataset(root, &YARN_COUNT, &[y], &column(|y| y.vertex_count))?;
    write_dataset(root, &YARN_CLOSED, &[y], &closed)?;
    write_dataset(root, &YARN_SOURCE, &[y], &column(|y| y.source_yarn))
}

fn read_yarns(root: &Group) -> Result<Vec<SwatchYarn>> {
    let (radius, shape) = read_dataset::<f64>(root, &YARN_RADIUS, &[None])?;
    let y = Some(shape[0]);
    let first = read_dataset::<u32>(root, &YARN_FIRST, &[y])?.0;
    let count = read_dataset::<u32>(root, &YARN_COUNT, &[y])?.0;
    let closed = read_dataset::<u8>(root, &YARN_CLOSED, &[y])?.0;
    let source = read_dataset::<u32>(root, &YARN_SOURCE, &[y])?.0;
    (0..radius.len())
        .map(|k| {
            Ok(SwatchYarn {
                radius_m: radius[k],
                first_vertex: first[k],
                vertex_count: count[k],
                closed: flag(&YARN_CLOSED, k, closed[k])?,
                source_yarn: source[k],
            })
        })
        .collect()
}

fn write_glue(root: &Group, glue: &[GlueSpring]) -> Result<()> {
    let g = glue.len();
    create_group(root, "glue")?;
    let vertices: Vec<[u32; 2]> = glue.iter().map(|s| s.vertices).collect();
    let rest: Vec<f64> = glue.iter().map(|s| s.rest_length_m).collect();
    let stiffness: Vec<f64> = glue.iter().map(|s| s.stiffness_n_m).collect();
    write_dataset(root, &GLUE_VERTICES, &[g, 2], vertices.as_flattened())?;
    write_dataset(root, &GLUE_REST_LENGTH, &[g], &rest)?;
    write_dataset(root, &GLUE_STIFFNESS, &[g], &stiffness)
}

fn read_glue(root: &Group) -> Result<Vec<GlueSpring>> {
    let (vertices, shape) = read_dataset::<u32>(root, &GLUE_VERTICES, &[None, Some(2)])?;
    let g = Some(shape[0]);
    let rest = read_dataset::<f64>(root, &GLUE_REST_LENGTH, &[g])?.0;
    let stiffness = read_dataset::<f64>(root, &GLUE_STIFFNESS, &[g])?.0;
    Ok(rows::<u32, 2>(vertices)
        .into_iter()
        .zip(rest)
        .zip(stiffness)
        .map(|((vertices, rest_length_m), stiffness_n_m)| GlueSpring {
            vertices,
            rest_length_m,
            stiffness_n_m,
        })
        .collect())
}

/// A 0/1 flag of row `k` of `dataset`.
fn flag(dataset: &DatasetSpec, k: usize, value: u8) -> Result<bool> {
    match value {
        0 => Ok(false),
        1 => Ok(true),
        other => Err(Error::Hdf5(format!("{}[{k}] is {other}, expected 0 or 1", dataset.path))),
    }
}

fn json(what: &'static str, value: &impl serde::Serialize) -> Result<String> {
    serde_json::to_string(value).map_err(|e| Error::Encode { what, message: e.to_string() })
}

/// The JSON root attribute `name` decoded (exactly: serde_json reads back every `f64` it wrote).
fn from_json<T: serde::de::DeserializeOwned>(root: &Group, name: &str) -> Result<T> {
    serde_json::from_str(&read_str_attr(root, name)?)
        .map_err(|e| Error::Hdf5(format!("root attribute '{name}' is not the expected JSON: {e}")))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use ::hdf5::File;

    use super::super::{export, import};
    use super::*;
    use crate::container::{self, Provenance};
    use crate::pattern::{Fabric, Pattern, RestState, Yarn};
    use crate::{AnyArtifact, Header};

    /// A valid swatch: one open and one closed yarn cut from a two-yarn tile, one glue spring,
    /// awkward floats.
    fn swatch(glued: bool) -> Swatch {
        let n = 3;
        let pattern = Pattern {
            name: "tile ü".into(),
            fabric: Fabric::Knit,
            period_m: [0.01, 0.01 * (1.0 + f64::EPSILON)],
            positions_m: vec![[0.0, 0.0, -0.0], [0.003, 0.001, 1e-300], [0.006, -0.001, 0.1 + 0.2 - 0.3]],
            edge_twist_rad: vec![0.1, -0.2, 0.3],
            yarns: vec![Yarn {
                radius_m: 5e-4,
                vertices: vec![0, 1, 2],
                edge_offsets: vec![[0, 0], [0, 0], [1, 0]],
            }],
            rest: Some(RestState {
                edge_length_m: vec![0.003; n],
                vertex_curvature: vec![[0.1, f64::MIN_POSITIVE / 4.0]; n],
                vertex_twist_rad: vec![0.01; n],
                edge_reference_director: vec![[0.0, 0.6, 0.8]; n],
                vertex_reference_twist_rad: vec![-0.02; n],
            }),
            origin: "hdf5 test".into(),
        };
        let v = 7;
        let ends = |k: usize| k == 0 || k == 3;
        let rest = |k: usize, x: f64| if ends(k) { 0.0 } else { x };
        Swatch {
            name: "swatch \"quoted\"".into(),
            pattern,
            model: YarnModel::table_4_1("rib").unwrap(),
            size_m: [0.03, 0.02],
            positions_m: (0..v).map(|k| [k as f64 * 0.003, (k as f64).sin() * 1e-3, 1e-4 / 3.0]).collect(),
            edge_twist_rad: (0..6).map(|k| k as f64 / 7.0).collect(),
            source_vertex: (0..v).map(|k| (k % n) as u32).collect(),
            source_tile: (0..v).map(|k| [k as i32 - 3, -1]).collect(),
            yarns: vec![
                SwatchYarn {
                    radius_m: 5e-4,
                    first_vertex: 0,
                    vertex_count: 4,
                    closed: false,
                    source_yarn: 0,
                },
                SwatchYarn {
                    radius_m: 0.1 + 0.2,
                    first_vertex: 4,
                    vertex_count: 3,
                    closed: true,
                    source_yarn: 0,
                },
            ],
            rest_length_m: (0..6).map(|k| 0.003 + k as f64 * 1e-17).collect(),
            reference_director: vec![[0.0, 0.0, 1.0]; 6],
            rest_curvature: (0..v).map(|k| [rest(k, 0.2), rest(k, -0.0)]).collect(),
            rest_twist_rad: (0..v).map(|k| rest(k, 0.05)).collect(),
            reference_twist_rad: (0..v).map(|k| rest(k, -0.07)).collect(),
            glue: if glued {
                vec![GlueSpring { vertices: [3, 5], rest_length_m: 0.9e-3, stiffness_n_m: 1234.5 }]
            } else {
                vec![]
            },
            glue_settings: GlueSettings { stiffness_n_m: glued.then_some(1234.5), ..GlueSettings::default() },
        }
    }

    fn header_of(s: &Swatch) -> Header {
        let payload = container::payload_of(s).unwrap();
        container::header_for::<Swatch>(&payload, &Provenance::default())
    }

    fn round_trip(s: Swatch) {
        s.validate().unwrap();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.h5");
        let header = header_of(&s);
        export(&path, &header, &AnyArtifact::Swatch(s.clone())).unwrap();
        let (h, back) = import(&path).unwrap();
        let AnyArtifact::Swatch(back) = back else { panic!("not a swatch") };
        assert_eq!(back, s);
        let bits = |s: &Swatch| container::payload_of(s).unwrap();
        assert_eq!(bits(&back), bits(&s), "every f64 bit for bit");
        assert_eq!(h, header);
    }

    #[test]
    fn round_trip_is_exact() {
        round_trip(swatch(true));
    }

    #[test]
    fn round_trip_without_glue_is_exact() {
        round_trip(swatch(false));
    }

    #[test]
    fn datasets_carry_units_and_the_pattern_its_layout() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.h5");
        let s = swatch(true);
        export(&path, &header_of(&s), &AnyArtifact::Swatch(s)).unwrap();
        let f = File::open(&path).unwrap();
        let units = |p: &str| {
            f.dataset(p)
                .unwrap()
                .attr("units")
                .unwrap()
                .read_scalar::<::hdf5::types::VarLenUnicode>()
                .unwrap()
        };
        assert_eq!(units("vertices/position_m").as_str(), "m");
        assert_eq!(units("glue/stiffness_n_m").as_str(), "N/m");
        assert_eq!(units("pattern/rest/edge_length_m").as_str(), "m");
        assert_eq!(f.dataset("glue/vertices").unwrap().shape(), [1, 2]);
        assert_eq!(f.dataset("edges/rest_length_m").unwrap().shape(), [6]);
        assert_eq!(f.dataset("pattern/positions_m").unwrap().shape(), [3, 3]);
    }

    /// Export a valid swatch, let `edit` change the file, import it and return the error.
    fn import_error_after(edit: impl FnOnce(&File)) -> Error {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.h5");
        let s = swatch(true);
        export(&path, &header_of(&s), &AnyArtifact::Swatch(s)).unwrap();
        {
            let f = File::open_rw(&path).unwrap();
            edit(&f);
        }
        import(&path).unwrap_err()
    }

    #[test]
    fn broken_files_are_refused_naming_the_dataset() {
        let e = import_error_after(|f| f.unlink("pattern/yarns/vertices").unwrap());
        assert!(e.to_string().contains("missing dataset /pattern/yarns/vertices"), "{e}");
        let e = import_error_after(|f| f.unlink("glue/rest_length_m").unwrap());
        assert!(e.to_string().contains("missing dataset /glue/rest_length_m"), "{e}");
        let e = import_error_after(|f| f.dataset("yarns/closed").unwrap().write_raw(&[0u8, 2]).unwrap());
        assert!(e.to_string().contains("/yarns/closed[1] is 2"), "{e}");
        let e = import_error_after(|f| f.group("pattern").unwrap().delete_attr("fabric").unwrap());
        assert!(e.to_string().contains("missing attribute 'fabric' of /pattern"), "{e}");
        // A glue spring from a vertex to itself: the file reads, the swatch is invalid.
        let e = import_error_after(|f| f.dataset("glue/vertices").unwrap().write_raw(&[3u32, 3]).unwrap());
        assert!(matches!(e.root(), Error::Invalid { kind: "swatch", .. }), "{e}");
        let e = import_error_after(|f| {
            f.dataset("vertices/position_m").unwrap().write_raw(&[0.5f64; 21]).unwrap()
        });
        assert!(matches!(e.root(), Error::ContentHashMismatch { .. }), "{e}");
    }
}
