//! The HDF5 layout of a `grid` (see the [module docs](super) and `schemas/hdf5.md`).

use ::hdf5::Group;
use ::hdf5::types::VarLenUnicode;

use super::layer::{Spec, create_group, varlen, write_str_attr, write_u32_attr};
use super::{DatasetSpec, has_attr, read_dataset, read_str_attr, read_u32_attr, rows, write_dataset};
use crate::Artifact;
use crate::error::{Error, Result, ValidationError};
use crate::grid::{Grid, GridSample, GridShard, GridTerm, strain_from_values, strain_values};

const TERM_LENGTHS: DatasetSpec = DatasetSpec {
    path: "/terms/lengths",
    spec: Spec {
        units: "1",
        description: "number of sampled values of each term's axes; the second is 0 for a 1D term",
    },
};
const TERM_VALUES: DatasetSpec = DatasetSpec {
    path: "/terms/values",
    spec: Spec {
        units: "1 (sx, sa, sy) or 1/m (kx, ky)",
        description: "the sampled values of every term's axes, term by term, axis by axis (split by /terms/lengths)",
    },
};
const TERM_AXES: DatasetSpec = DatasetSpec {
    path: "/terms/axes",
    spec: Spec {
        units: "1",
        description: "axis indices (0 sx, 1 sa, 2 sy, 3 kx, 4 ky) of each term; the second is -1 for a 1D term",
    },
};
const TERM: DatasetSpec = DatasetSpec {
    path: "/samples/term",
    spec: Spec { units: "1", description: "term of each sample (row of /terms/axes)" },
};
const INDEX: DatasetSpec = DatasetSpec {
    path: "/samples/index",
    spec: Spec {
        units: "1",
        description: "indices into the values of the term's axes; the second is 0 for a 1D term",
    },
};
const STRAIN: DatasetSpec = DatasetSpec {
    path: "/samples/strain",
    spec: Spec { units: "1, 1, 1, 1/m, 1/m", description: "imposed strain, columns sx, sa, sy, kx, ky" },
};
const CONVERGED: DatasetSpec = DatasetSpec {
    path: "/samples/converged",
    spec: Spec { units: "1", description: "1 if the equilibrium was found, else 0" },
};
const STOP_REASON: DatasetSpec = DatasetSpec {
    path: "/samples/stop_reason",
    spec: Spec { units: "1", description: "why the solver stopped" },
};
const ENERGY: DatasetSpec = DatasetSpec {
    path: "/samples/energy_density_j_m2",
    spec: Spec { units: "J/m^2", description: "homogenized energy density (3.22); NaN where not converged" },
};
const STRESS: DatasetSpec = DatasetSpec {
    path: "/samples/stress",
    spec: Spec {
        units: "J/m^2, J/m^2, J/m^2, J/m, J/m",
        description: "homogenized stress (3.23c), derivatives by sx, sa, sy, kx, ky; NaN rows where absent",
    },
};
const ITERATIONS: DatasetSpec =
    DatasetSpec { path: "/samples/iterations", spec: Spec { units: "1", description: "Newton iterations" } };
const POSITIONS: DatasetSpec = DatasetSpec {
    path: "/samples/positions_m",
    spec: Spec { units: "m", description: "equilibrium yarn centreline vertices of each sample's tile" },
};
const TWISTS: DatasetSpec = DatasetSpec {
    path: "/samples/edge_twist_rad",
    spec: Spec { units: "rad", description: "equilibrium edge twists of each sample, by source vertex" },
};

pub(super) fn write_grid(root: &Group, g: &Grid) -> Result<()> {
    write_str_attr(root, "pattern", &g.pattern)?;
    write_str_attr(root, "model", &g.model)?;
    if let Some(s) = g.shard {
        write_u32_attr(root, "shard_index", s.index)?;
        write_u32_attr(root, "shard_count", s.count)?;
    }
    create_group(root, "terms")?;
    let terms: Vec<[i32; 2]> = g.terms.iter().map(term_row).collect();
    write_dataset(root, &TERM_AXES, &[terms.len(), 2], terms.as_flattened())?;
    let lengths: Vec<[u32; 2]> = g.terms.iter().map(term_lengths).collect();
    write_dataset(root, &TERM_LENGTHS, &[lengths.len(), 2], lengths.as_flattened())?;
    let values: Vec<f64> = g.terms.iter().flat_map(|t| t.values.iter().flatten().copied()).collect();
    write_dataset(root, &TERM_VALUES, &[values.len()], &values)?;
    create_group(root, "samples")?;
    Columns::of(&g.samples)?.write(root)
}

pub(super) fn read_grid(root: &Group) -> Result<Grid> {
    let rows_of_axes = rows::<i32, 2>(read_dataset(root, &TERM_AXES, &[None, Some(2)])?.0);
    let n = rows_of_axes.len();
    let lengths = rows::<u32, 2>(read_dataset(root, &TERM_LENGTHS, &[Some(n), Some(2)])?.0);
    let mut values = read_dataset::<f64>(root, &TERM_VALUES, &[None])?.0.into_iter();
    let mut terms = Vec::with_capacity(n);
    for (t, (row, lengths)) in rows_of_axes.into_iter().zip(lengths).enumerate() {
        let mut term = term_of_row(t, row)?;
        term.values = lengths[..term.axes.len()]
            .iter()
            .map(|&len| values.by_ref().take(len as usize).collect())
            .collect();
        terms.push(term);
    }
    if values.next().is_some() {
        return Err(Error::Hdf5(format!(
            "{} holds more values than {} counts",
            TERM_VALUES.path, TERM_LENGTHS.path
        )));
    }
    let columns = Columns::read(root)?;
    Ok(Grid {
        pattern: read_str_attr(root, "pattern")?,
        model: read_str_attr(root, "model")?,
        terms,
        shard: read_shard(root)?,
        samples: (0..columns.term.len()).map(|k| columns.sample(k)).collect::<Result<_>>()?,
    })
}

/// A term as a row of `/terms/axes`: its axis indices, -1 for the missing second of a 1D term.
fn term_row(term: &GridTerm) -> [i32; 2] {
    let axis = |k: usize| term.axes.get(k).map_or(-1, |&a| i32::from(a));
    [axis(0), axis(1)]
}

/// How many values each of a term's axes has, 0 for the missing second of a 1D term.
fn term_lengths(term: &GridTerm) -> [u32; 2] {
    let len = |k: usize| term.values.get(k).map_or(0, |v| v.len() as u32);
    [len(0), len(1)]
}

/// A term's axes from its row of `/terms/axes` (its values are read separately).
fn term_of_row(t: usize, row: [i32; 2]) -> Result<GridTerm> {
    let axis = |a: i32| {
        u8::try_from(a).map_err(|_| Error::Invalid {
            kind: Grid::KIND,
            problem: ValidationError::new(
                format!("{}[{t}]", TERM_AXES.path),
                format!("{a} is not an axis index (0 to 4, or -1 for the second of a 1D term)"),
            ),
        })
    };
    let axes = match row {
        [a, -1] => vec![axis(a)?],
        [a, b] => vec![axis(a)?, axis(b)?],
    };
    Ok(GridTerm { axes, values: Vec::new() })
}

fn read_shard(root: &Group) -> Result<Option<GridShard>> {
    match (has_attr(root, "shard_index")?, has_attr(root, "shard_count")?) {
        (false, false) => Ok(None),
        (true, true) => Ok(Some(GridShard {
            index: read_u32_attr(root, "shard_index")?,
            count: read_u32_attr(root, "shard_count")?,
        })),
        _ => Err(Error::Hdf5(
            "root attributes 'shard_index' and 'shard_count' come together; one is missing".into(),
        )),
    }
}

/// The samples as the columns of `/samples`, geometry flattened (`V` vertices per sample).
struct Columns {
    term: Vec<u32>,
    index: Vec<[u32; 2]>,
    strain: Vec<[f64; 5]>,
    converged: Vec<u8>,
    stop_reason: Vec<VarLenUnicode>,
    energy: Vec<f64>,
    stress: Vec<[f64; 5]>,
    iterations: Vec<u32>,
    /// `V`, the positions `[n, V, 3]` and the twists `[n, V]`, when the samples have geometry.
    geometry: Option<(usize, Vec<f64>, Vec<f64>)>,
}

impl Columns {
    fn of(samples: &[GridSample]) -> Result<Self> {
        let geometry = samples.first().and_then(|s| s.positions_m.as_ref()).map(|first| {
            let positions = samples.iter().flat_map(|s| s.positions_m.iter().flatten().flatten());
            let twists = samples.iter().flat_map(|s| s.edge_twist_rad.iter().flatten());
            (first.len(), positions.copied().collect(), twists.copied().collect())
        });
        let stop_reason = samples.iter().map(|s| varlen("stop_reason", &s.stop_reason));
        Ok(Columns {
            term: samples.iter().map(|s| s.term).collect(),
            index: samples.iter().map(|s| s.index).collect(),
            strain: samples.iter().map(|s| strain_values(&s.strain)).collect(),
            converged: samples.iter().map(|s| u8::from(s.converged)).collect(),
            stop_reason: stop_reason.collect::<Result<_>>()?,
            energy: samples.iter().map(|s| s.energy_density_j_m2.unwrap_or(f64::NAN)).collect(),
            stress: samples.iter().map(|s| s.stress.unwrap_or([f64::NAN; 5])).collect(),
            iterations: samples.iter().map(|s| s.iterations).collect(),
            geometry,
        })
    }

    fn write(&self, root: &Group) -> Result<()> {
        let n = self.term.len();
        write_dataset(root, &TERM, &[n], &self.term)?;
        write_dataset(root, &INDEX, &[n, 2], self.index.as_flattened())?;
        write_dataset(root, &STRAIN, &[n, 5], self.strain.as_flattened())?;
        write_dataset(root, &CONVERGED, &[n], &self.converged)?;
        write_dataset(root, &STOP_REASON, &[n], &self.stop_reason)?;
        write_dataset(root, &ENERGY, &[n], &self.energy)?;
        write_dataset(root, &STRESS, &[n, 5], self.stress.as_flattened())?;
        write_dataset(root, &ITERATIONS, &[n], &self.iterations)?;
        if let Some((v, positions, twists)) = &self.geometry {
            write_dataset(root, &POSITIONS, &[n, *v, 3], positions)?;
            write_dataset(root, &TWISTS, &[n, *v], twists)?;
        }
        Ok(())
    }

    fn read(root: &Group) -> Result<Self> {
        let (term, shape) = read_dataset::<u32>(root, &TERM, &[None])?;
        let n = Some(shape[0]);
        let geometry = if root.link_exists("samples/positions_m") {
            let (positions, shape) = read_dataset(root, &POSITIONS, &[n, None, Some(3)])?;
            let twists = read_dataset(root, &TWISTS, &[n, Some(shape[1])])?.0;
            Some((shape[1], positions, twists))
        } else {
            None
        };
        Ok(Columns {
            term,
            index: rows(read_dataset(root, &INDEX, &[n, Some(2)])?.0),
            strain: rows(read_dataset(root, &STRAIN, &[n, Some(5)])?.0),
            converged: read_dataset(root, &CONVERGED, &[n])?.0,
            stop_reason: read_dataset(root, &STOP_REASON, &[n])?.0,
            energy: read_dataset(root, &ENERGY, &[n])?.0,
            stress: rows(read_dataset(root, &STRESS, &[n, Some(5)])?.0),
            iterations: read_dataset(root, &ITERATIONS, &[n])?.0,
            geometry,
        })
    }

    /// Sample `k`: NaN energies and all-NaN stress rows are absent values.
    fn sample(&self, k: usize) -> Result<GridSample> {
        let converged = match self.converged[k] {
            0 => false,
            1 => true,
            other => return Err(Error::Hdf5(format!("{}[{k}] is {other}, expected 0 or 1", CONVERGED.path))),
        };
        let (energy, stress) = (self.energy[k], self.stress[k]);
        let geometry = self.geometry.as_ref().map(|(v, positions, twists)| {
            let rows3 = rows::<f64, 3>(positions[k * v * 3..(k + 1) * v * 3].to_vec());
            (rows3, twists[k * v..(k + 1) * v].to_vec())
        });
        let (positions_m, edge_twist_rad) = geometry.unzip();
        Ok(GridSample {
            term: self.term[k],
            index: self.index[k],
            strain: strain_from_values(self.strain[k]),
            converged,
            stop_reason: self.stop_reason[k].as_str().into(),
            energy_density_j_m2: (!energy.is_nan()).then_some(energy),
            stress: (!stress.iter().all(|x| x.is_nan())).then_some(stress),
            iterations: self.iterations[k],
            positions_m,
            edge_twist_rad,
        })
    }
}
