//! The `grid` artifact: homogenized energies of one pattern and yarn model sampled over a plan
//! (thesis Sec. 4.1.1, App. A.3.1).
//!
//! A plan gives the terms of the energy decomposition (4.2) to sample, each with the sampled
//! values of its strain axes (`sx, sa, sy, kx, ky`). A 1D term is sampled at every value of its
//! axis, a 2D term on the grid of its two axes' values, the other strain parameters being zero
//! (App. A.3.1 uses 150 samples per 1D term and 50 x 50 per 2D term, so a term carries its own
//! values). Large plans are sampled
//! in shards (`--shard K/N`), each a partial grid, and joined with [`Grid::merge`].

use serde::{Deserialize, Serialize};

use crate::check;
use crate::error::ValidationError;
use crate::rvesolve::StrainSample;

/// The strain axes in the order of [`GridTerm::axes`]' indices and of the fields of
/// [`StrainSample`].
pub const AXIS_NAMES: [&str; 5] = ["sx", "sa", "sy", "kx", "ky"];

/// Sampled homogenized energies of one pattern with one yarn model over a sampling plan. It
/// stores no wall times, so a run in shards merges into exactly the grid of a run in one piece.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct Grid {
    /// Pattern name.
    pub pattern: String,
    /// Yarn model name.
    pub model: String,
    /// The 1D and 2D terms of the energy decomposition (4.2) sampled, each at most once.
    pub terms: Vec<GridTerm>,
    /// Which part of the plan this is, for a partial grid written by `--shard K/N`; absent for
    /// a whole (or merged) grid.
    pub shard: Option<GridShard>,
    /// The samples, sorted by `(term, index)`, each at most once.
    pub samples: Vec<GridSample>,
}

/// One term of the energy decomposition (4.2): the axes it depends on and their sampled values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct GridTerm {
    /// One axis index, or two distinct ones ascending, into [`AXIS_NAMES`]: `[0]` is `f_sx`,
    /// `[0, 2]` is `f_{sx,sy}`.
    pub axes: Vec<u8>,
    /// The sampled values of each of the term's axes (in the order of `axes`), each sorted
    /// strictly ascending and containing 0, the rest state (dimensionless for `sx, sa, sy`; 1/m
    /// for the curvatures `kx, ky`).
    pub values: Vec<Vec<f64>>,
}

/// The part of a sampling plan a partial grid holds (`--shard index/count`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct GridShard {
    /// This shard, `0 <= index < count`.
    pub index: u32,
    /// Number of shards the plan was split into.
    pub count: u32,
}

/// One sampled tile solve of a grid. A solve that did not converge carries no energy or stress.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct GridSample {
    /// Index into [`Grid::terms`].
    pub term: u32,
    /// Indices into the values of the term's axes (the second is 0 for a 1D term).
    pub index: [u32; 2],
    /// The strain imposed: the term's axes at their indexed values, the other parameters 0.
    pub strain: StrainSample,
    /// Whether the equilibrium was found (A.33).
    pub converged: bool,
    /// Why the solver stopped (`converged`, `iteration_limit`, `line_search_failed`,
    /// `factorization_failed`).
    pub stop_reason: String,
    /// Homogenized energy density (3.22) (J/m²); present exactly when converged.
    pub energy_density_j_m2: Option<f64>,
    /// Homogenized stress `dΨ/d(sx, sa, sy, kx, ky)` (3.23c) (J/m² per unit strain; J/m per unit
    /// curvature); absent when not converged or not computed.
    pub stress: Option<[f64; 5]>,
    /// Newton iterations.
    pub iterations: u32,
    /// Equilibrium yarn centreline vertices of the tile (m); all samples of a grid have them
    /// or none.
    pub positions_m: Option<Vec<[f64; 3]>>,
    /// Equilibrium edge twists (rad), by source vertex; present exactly with `positions_m`.
    pub edge_twist_rad: Option<Vec<f64>>,
}

/// Why shards cannot be merged into one grid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MergeError {
    /// No grid was given.
    #[error("nothing to merge: no grids given")]
    Empty,
    /// A part breaks an invariant of its kind.
    #[error("{part} is invalid: {problem}")]
    Invalid {
        /// The part (`shard K` or `part P`).
        part: String,
        /// What is wrong.
        problem: ValidationError,
    },
    /// A part was sampled with another plan (pattern, model, axes, terms or shard count).
    #[error("{part} differs from {first} in its {what}: only shards of one sampling plan merge")]
    Mismatch {
        /// The differing part.
        part: String,
        /// The first part.
        first: String,
        /// What differs.
        what: &'static str,
    },
    /// Two parts hold the same sample.
    #[error("sample (term {term}, index [{}, {}]) appears in {first} and {second}", index[0], index[1])]
    Overlap {
        /// The sample's term.
        term: u32,
        /// The sample's index.
        index: [u32; 2],
        /// The first part holding it.
        first: String,
        /// The second part holding it.
        second: String,
    },
}

/// The strain parameters as an array, in the order of [`AXIS_NAMES`].
pub fn strain_values(s: &StrainSample) -> [f64; 5] {
    [s.sx, s.sa, s.sy, s.kx, s.ky]
}

/// The strain of an array in the order of [`AXIS_NAMES`].
pub fn strain_from_values(v: [f64; 5]) -> StrainSample {
    StrainSample { sx: v[0], sa: v[1], sy: v[2], kx: v[3], ky: v[4] }
}

/// A term's values: one list per axis, finite, strictly ascending, containing 0.
fn validate_values(field: &str, term: &GridTerm) -> Result<(), ValidationError> {
    if term.values.len() != term.axes.len() {
        return Err(ValidationError::new(
            field,
            format!("needs one list of values per axis ({}), got {}", term.axes.len(), term.values.len()),
        ));
    }
    for (k, values) in term.values.iter().enumerate() {
        let field = format!("{field}[{k}]");
        check::finite(&field, values)?;
        if let Some(i) = values.windows(2).position(|w| w[0] >= w[1]) {
            return Err(ValidationError::new(
                format!("{field}[{}]", i + 1),
                format!("values must increase strictly, but {} follows {}", values[i + 1], values[i]),
            ));
        }
        if !values.contains(&0.0) {
            return Err(ValidationError::new(field, "must contain 0 (the rest state)"));
        }
    }
    Ok(())
}

impl GridTerm {
    /// The term's name: its axes' names joined by commas, e.g. `sx,sy`.
    pub fn name(&self) -> String {
        let name = |&a: &u8| AXIS_NAMES.get(a as usize).copied().unwrap_or("?");
        self.axes.iter().map(name).collect::<Vec<_>>().join(",")
    }
}

impl GridSample {
    /// The sort key of a sample within its grid.
    pub fn key(&self) -> (u32, [u32; 2]) {
        (self.term, self.index)
    }

    /// The sample named for messages: `sample (term t, index [i, j])`.
    pub fn describe(&self) -> String {
        format!("sample (term {}, index [{}, {}])", self.term, self.index[0], self.index[1])
    }
}

impl Grid {
    /// The strain of the sample of term `term` at `index`: the term's axes at their indexed
    /// values, the other parameters 0. `None` when the term or an index is out of range, or
    /// the second index of a 1D term is not 0.
    pub fn strain_at(&self, term: usize, index: [u32; 2]) -> Option<StrainSample> {
        let term = self.terms.get(term)?;
        if term.axes.len() == 1 && index[1] != 0 {
            return None;
        }
        let mut values = [0.0; 5];
        for ((&axis, axis_values), &i) in term.axes.iter().zip(&term.values).zip(&index) {
            *values.get_mut(axis as usize)? = *axis_values.get(i as usize)?;
        }
        Some(strain_from_values(values))
    }

    /// Number of samples of the whole plan: over the terms, the product of their axes' lengths.
    pub fn expected_samples(&self) -> usize {
        self.terms.iter().map(|t| t.values.iter().map(Vec::len).product::<usize>()).sum()
    }

    /// Whether every sample of the plan is present (for a valid grid).
    pub fn is_complete(&self) -> bool {
        self.samples.len() == self.expected_samples()
    }

    /// Check the invariants: a valid plan, sorted unique samples at the plan's strains, and no
    /// numbers from failed solves.
    pub fn validate(&self) -> Result<(), ValidationError> {
        self.validate_terms()?;
        if let Some(s) = self.shard.filter(|s| s.index >= s.count) {
            return Err(ValidationError::new(
                "shard.index",
                format!("must be below shard.count ({}), got {}", s.count, s.index),
            ));
        }
        for (k, sample) in self.samples.iter().enumerate() {
            self.validate_sample(k, sample)?;
        }
        self.validate_order()?;
        self.validate_geometry()
    }

    fn validate_terms(&self) -> Result<(), ValidationError> {
        for (t, term) in self.terms.iter().enumerate() {
            let valid = match term.axes.as_slice() {
                [a] => *a < 5,
                [a, b] => a < b && *b < 5,
                _ => false,
            };
            if !valid {
                return Err(ValidationError::new(
                    format!("terms[{t}].axes"),
                    format!("must be 1 or 2 distinct axis indices below 5, ascending; got {:?}", term.axes),
                ));
            }
            validate_values(&format!("terms[{t}].values"), term)?;
            if let Some(first) = self.terms[..t].iter().position(|x| x.axes == term.axes) {
                return Err(ValidationError::new(format!("terms[{t}]"), format!("repeats terms[{first}]")));
            }
        }
        Ok(())
    }

    fn validate_sample(&self, k: usize, s: &GridSample) -> Result<(), ValidationError> {
        let field = |name: &str| format!("samples[{k}].{name}");
        let Some(term) = self.terms.get(s.term as usize) else {
            return Err(ValidationError::new(
                field("term"),
                format!("{} is not a term index (there are {} terms)", s.term, self.terms.len()),
            ));
        };
        let Some(strain) = self.strain_at(s.term as usize, s.index) else {
            return Err(ValidationError::new(
                field("index"),
                format!(
                    "{:?} is outside the values of term {} ({}); a 1D term's second index is 0",
                    s.index,
                    s.term,
                    term.name()
                ),
            ));
        };
        if strain != s.strain {
            return Err(ValidationError::new(
                field("strain"),
                format!("must be the axes' values at the index, {strain:?}, got {:?}", s.strain),
            ));
        }
        self.validate_outcome(k, s)
    }

    fn validate_outcome(&self, k: usize, s: &GridSample) -> Result<(), ValidationError> {
        let field = |name: &str| format!("samples[{k}].{name}");
        if s.converged != s.energy_density_j_m2.is_some() {
            return Err(ValidationError::new(
                field("energy_density_j_m2"),
                "present exactly when the solve converged (a failed solve reports no number)",
            ));
        }
        check::finite(&field("energy_density_j_m2"), &s.energy_density_j_m2)?;
        match &s.stress {
            Some(_) if !s.converged => {
                return Err(ValidationError::new(field("stress"), "a failed solve reports no stress"));
            }
            Some(stress) => check::finite(&field("stress"), stress)?,
            None => {}
        }
        if let Some(positions) = &s.positions_m {
            check::finite_rows(&field("positions_m"), positions)?;
        }
        if let Some(twists) = &s.edge_twist_rad {
            check::finite(&field("edge_twist_rad"), twists)?;
        }
        Ok(())
    }

    fn validate_order(&self) -> Result<(), ValidationError> {
        match self.samples.windows(2).position(|w| w[0].key() >= w[1].key()) {
            Some(k) => Err(ValidationError::new(
                format!("samples[{}]", k + 1),
                format!(
                    "samples must be sorted by (term, index) without repeats, but {} follows {}",
                    self.samples[k + 1].describe(),
                    self.samples[k].describe()
                ),
            )),
            None => Ok(()),
        }
    }

    /// Geometry is present for all samples or none, with one vertex count and a twist per vertex.
    fn validate_geometry(&self) -> Result<(), ValidationError> {
        let Some(first) = self.samples.first() else { return Ok(()) };
        let vertices = first.positions_m.as_ref().map(Vec::len);
        for (k, s) in self.samples.iter().enumerate() {
            if s.positions_m.as_ref().map(Vec::len) != vertices {
                return Err(ValidationError::new(
                    format!("samples[{k}].positions_m"),
                    format!(
                        "all samples have the geometry or none, with one vertex count ({} in samples[0])",
                        vertices.map_or("absent".into(), |n| n.to_string())
                    ),
                ));
            }
            if s.edge_twist_rad.as_ref().map(Vec::len) != vertices {
                return Err(ValidationError::new(
                    format!("samples[{k}].edge_twist_rad"),
                    "present exactly with positions_m, one twist per vertex",
                ));
            }
        }
        Ok(())
    }

    /// A human summary.
    pub fn summary(&self) -> String {
        let terms: Vec<String> = self.terms.iter().map(GridTerm::name).collect();
        let converged = self.samples.iter().filter(|s| s.converged).count();
        let mut out = format!(
            "grid of '{}' with '{}'\n  terms: {} ({})\n  samples: {converged} converged of {} (plan: {}, {})",
            self.pattern,
            self.model,
            self.terms.len(),
            terms.join("; "),
            self.samples.len(),
            self.expected_samples(),
            if self.is_complete() { "complete" } else { "incomplete" },
        );
        if let Some(s) = self.shard {
            out.push_str(&format!("\n  shard {} of {}", s.index, s.count));
        }
        out.push_str(&format!("\n  energy density: {}", self.energy_range()));
        out
    }

    fn energy_range(&self) -> String {
        let energies = self.samples.iter().filter_map(|s| s.energy_density_j_m2);
        let range = energies.fold(None, |r: Option<(f64, f64)>, e| match r {
            Some((lo, hi)) => Some((lo.min(e), hi.max(e))),
            None => Some((e, e)),
        });
        match range {
            Some((lo, hi)) => format!("{lo:.6e} .. {hi:.6e} J/m²"),
            None => "none (no converged sample)".into(),
        }
    }

    /// The part named for messages: `shard K` when it is one, else `part P` (its position).
    fn label(&self, position: usize) -> String {
        match self.shard {
            Some(s) => format!("shard {}", s.index),
            None => format!("part {position}"),
        }
    }

    /// What of the sampling plan differs between two grids, if anything. Axis values compare
    /// bit for bit.
    fn plan_difference(&self, other: &Grid) -> Option<&'static str> {
        let bits = |g: &Grid| -> Vec<Vec<Vec<u64>>> {
            g.terms
                .iter()
                .map(|t| t.values.iter().map(|v| v.iter().map(|x| x.to_bits()).collect()).collect())
                .collect()
        };
        let axes = |g: &Grid| -> Vec<Vec<u8>> { g.terms.iter().map(|t| t.axes.clone()).collect() };
        let count = |g: &Grid| g.shard.map(|s| s.count);
        if self.pattern != other.pattern {
            Some("pattern")
        } else if self.model != other.model {
            Some("model")
        } else if axes(self) != axes(other) {
            Some("terms")
        } else if bits(self) != bits(other) {
            Some("axes")
        } else if count(self).zip(count(other)).is_some_and(|(a, b)| a != b) {
            Some("shard count")
        } else {
            None
        }
    }

    /// Merge partial grids of one plan (shards) into one grid: the parts must be valid, share
    /// pattern, model, axes (bit for bit), terms and shard count, and hold disjoint samples.
    /// The result has no shard and its samples sorted, so it is identical to a grid sampled
    /// in one piece.
    pub fn merge(parts: Vec<Grid>) -> Result<Grid, MergeError> {
        let first = parts.first().ok_or(MergeError::Empty)?;
        let labels: Vec<String> = parts.iter().enumerate().map(|(p, g)| g.label(p)).collect();
        for (p, part) in parts.iter().enumerate() {
            part.validate().map_err(|problem| MergeError::Invalid { part: labels[p].clone(), problem })?;
            if let Some(what) = first.plan_difference(part) {
                return Err(MergeError::Mismatch { part: labels[p].clone(), first: labels[0].clone(), what });
            }
        }
        let mut merged = Grid {
            pattern: first.pattern.clone(),
            model: first.model.clone(),
            terms: first.terms.clone(),
            shard: None,
            samples: Vec::new(),
        };
        let mut tagged: Vec<(usize, GridSample)> = parts
            .into_iter()
            .enumerate()
            .flat_map(|(p, g)| g.samples.into_iter().map(move |s| (p, s)))
            .collect();
        tagged.sort_by_key(|(_, s)| s.key());
        if let Some(w) = tagged.windows(2).find(|w| w[0].1.key() == w[1].1.key()) {
            let (term, index) = w[0].1.key();
            return Err(MergeError::Overlap {
                term,
                index,
                first: labels[w[0].0].clone(),
                second: labels[w[1].0].clone(),
            });
        }
        merged.samples = tagged.into_iter().map(|(_, s)| s).collect();
        Ok(merged)
    }
}
