//! Semantic differences between two artifacts of the same kind (`yarnhom diff`).
//!
//! Numbers are compared element-wise with `|a - b| <= atol + rtol * |b|` (numpy's `allclose`);
//! structure (kind, yarn topology, array sizes, model family) must match exactly. A [`Diff`]
//! lists every compared field with its largest and RMS difference, so a report says *where*
//! two files differ, not only *whether*.

use std::collections::HashMap;

use serde::Serialize;

use crate::AnyArtifact;
use crate::grid::{Grid, GridSample, GridTerm};
use crate::pattern::Pattern;
use crate::rvesolve::RveSolve;
use crate::spline::Spline;
use crate::swatch::Swatch;
use crate::yarnmodel::YarnModel;

/// Tolerances of a comparison.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Tolerance {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance (in the field's SI unit).
    pub atol: f64,
}

impl Tolerance {
    /// Whether `a` is within the tolerance of `b`: `|a - b| <= atol + rtol * |b|`.
    pub fn close(&self, a: f64, b: f64) -> bool {
        (a - b).abs() <= self.atol + self.rtol * b.abs()
    }
}

/// The comparison of one numeric field.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FieldDiff {
    /// Field path, e.g. `positions_m`.
    pub field: String,
    /// Number of compared values.
    pub count: usize,
    /// Largest absolute difference.
    pub max_abs: f64,
    /// Root mean square of the differences.
    pub rms: f64,
    /// Index of the value (row) with the largest difference.
    pub worst_index: usize,
    /// Where the largest difference is, in the field's own terms (e.g. the strain
    /// `sx=0.312 sy=-0.050`, or `frame 3, mesh cloth, positions_m[12][2]`), when known.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub worst_at: Option<String>,
    /// Values outside the tolerance.
    pub outside: usize,
}

/// Builds a [`FieldDiff`] from rows of values compared one at a time, so that a comparison
/// can be streamed. A row's difference is the Euclidean norm of its element differences; a row
/// is outside tolerance if any element is (or if the rows' lengths differ).
#[derive(Debug, Clone)]
pub struct FieldDiffBuilder {
    diff: FieldDiff,
    sum_sq: f64,
}

impl FieldDiffBuilder {
    /// An empty comparison of `field`.
    pub fn new(field: impl Into<String>) -> Self {
        let diff = FieldDiff {
            field: field.into(),
            count: 0,
            max_abs: 0.0,
            rms: 0.0,
            worst_index: 0,
            worst_at: None,
            outside: 0,
        };
        FieldDiffBuilder { diff, sum_sq: 0.0 }
    }

    /// Compare the next row; returns whether it is the row with the largest difference so far
    /// (the first row, or a larger or NaN difference), so that the caller can say where it is
    /// with [`locate_worst`](Self::locate_worst) without describing every row.
    pub fn push(&mut self, a: &[f64], b: &[f64], tol: Tolerance) -> bool {
        let sq: f64 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum();
        let norm = sq.sqrt();
        let index = self.diff.count;
        self.diff.count += 1;
        self.sum_sq += sq;
        if a.len() != b.len() || !a.iter().zip(b).all(|(&x, &y)| tol.close(x, y)) {
            self.diff.outside += 1;
        }
        let worst = index == 0 || norm > self.diff.max_abs || norm.is_nan();
        if worst {
            self.diff.max_abs = norm;
            self.diff.worst_index = index;
            self.diff.worst_at = None;
        }
        worst
    }

    /// Set where the largest difference is: its index (replacing the row number) and a
    /// description.
    pub fn locate_worst(&mut self, index: usize, at: impl Into<String>) {
        self.diff.worst_index = index;
        self.diff.worst_at = Some(at.into());
    }

    /// The comparison so far.
    pub fn finish(mut self) -> FieldDiff {
        let n = self.diff.count;
        self.diff.rms = if n == 0 { 0.0 } else { (self.sum_sq / n as f64).sqrt() };
        self.diff
    }
}

impl FieldDiff {
    /// The field as one line of a human report: name, count, largest and RMS difference,
    /// where the largest is, and how many values are outside the tolerance.
    pub fn report_line(&self) -> String {
        let at = match &self.worst_at {
            Some(at) => at.clone(),
            None => format!("[{}]", self.worst_index),
        };
        let outside =
            if self.outside > 0 { format!("  {} outside tolerance", self.outside) } else { String::new() };
        format!(
            "{:<32} n={:<6} max|d|={:.3e} rms={:.3e} worst at {at}{outside}",
            self.field, self.count, self.max_abs, self.rms
        )
    }
}

/// The difference between two artifacts.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Diff {
    /// Kind compared.
    pub kind: String,
    /// Structural differences (each makes the artifacts different, whatever the tolerance).
    pub structural: Vec<String>,
    /// Numeric fields compared.
    pub fields: Vec<FieldDiff>,
    /// Differences that do not count (names, origins).
    pub notes: Vec<String>,
}

impl Diff {
    /// Whether the two artifacts are equal within the tolerance.
    pub fn equal(&self) -> bool {
        self.structural.is_empty() && self.fields.iter().all(|f| f.outside == 0)
    }

    /// A human report, one line per finding.
    pub fn report(&self) -> String {
        let mut lines = vec![format!(
            "{} {}",
            self.kind,
            if self.equal() { "equal within tolerance" } else { "DIFFERENT" }
        )];
        lines.extend(self.structural.iter().map(|s| format!("  structure: {s}")));
        for f in &self.fields {
            lines.push(format!("  {}", f.report_line()));
        }
        lines.extend(self.notes.iter().map(|s| format!("  note: {s}")));
        lines.join("\n")
    }

    /// An empty comparison of two artifacts of `kind`.
    pub fn new(kind: &str) -> Self {
        Diff { kind: kind.into(), structural: vec![], fields: vec![], notes: vec![] }
    }

    /// Take in the findings of a nested comparison, its fields and findings prefixed.
    fn merge(&mut self, prefix: &str, nested: Diff) {
        self.structural.extend(nested.structural.into_iter().map(|s| format!("{prefix}{s}")));
        self.notes.extend(nested.notes.into_iter().map(|s| format!("{prefix}{s}")));
        self.fields.extend(
            nested.fields.into_iter().map(|f| FieldDiff { field: format!("{prefix}{}", f.field), ..f }),
        );
    }

    /// Compare rows of numbers; a row's difference is the Euclidean norm of its element
    /// differences, and a row is outside tolerance if any element is.
    fn rows<const N: usize>(&mut self, field: &str, a: &[[f64; N]], b: &[[f64; N]], tol: Tolerance) {
        if a.len() != b.len() {
            self.structural.push(format!("{field}: {} vs {} entries", a.len(), b.len()));
            return;
        }
        let mut builder = FieldDiffBuilder::new(field);
        for (ra, rb) in a.iter().zip(b) {
            builder.push(ra, rb, tol);
        }
        self.fields.push(builder.finish());
    }

    fn values(&mut self, field: &str, a: &[f64], b: &[f64], tol: Tolerance) {
        let wrap = |v: &[f64]| v.iter().map(|&x| [x]).collect::<Vec<[f64; 1]>>();
        self.rows(field, &wrap(a), &wrap(b), tol);
    }

    /// Compare rows of matched grid samples; `worst_index` becomes the row of the worst sample in
    /// the first grid's `samples`, and a field outside tolerance gets a note naming that sample.
    fn sample_rows<const N: usize>(
        &mut self,
        field: &str,
        matched: &[(&GridSample, [[f64; N]; 2])],
        first: &Grid,
        tol: Tolerance,
    ) {
        let (a, b): (Vec<_>, Vec<_>) = matched.iter().map(|(_, [x, y])| (*x, *y)).unzip();
        self.rows(field, &a, &b, tol);
        let Some(f) = self.fields.last_mut() else { return };
        let Some((worst, _)) = matched.get(f.worst_index) else { return };
        f.worst_index = first.samples.iter().position(|s| s.key() == worst.key()).unwrap_or(f.worst_index);
        f.worst_at = Some(describe_sample(first, worst));
        if f.outside > 0 {
            let note = format!("{field}: largest difference at {}", worst.describe());
            self.notes.push(note);
        }
    }
}

/// A strain for reports: the named axes (indices into [`AXIS_NAMES`](crate::grid::AXIS_NAMES))
/// with their values, e.g. `sx=0.312 sy=-0.05`.
pub fn describe_strain(values: &[f64; 5], axes: &[usize]) -> String {
    let number = |x: f64| {
        if x == 0.0 {
            "0".to_string()
        } else if x.abs() >= 0.01 {
            let text = format!("{x:.4}");
            text.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            format!("{x:.3e}")
        }
    };
    let name = |axis: usize| crate::grid::AXIS_NAMES.get(axis).copied().unwrap_or("?");
    let parts: Vec<String> = axes
        .iter()
        .filter_map(|&axis| Some(format!("{}={}", name(axis), number(*values.get(axis)?))))
        .collect();
    parts.join(" ")
}

/// A grid sample with its term's name and strain, e.g.
/// `sample (term 3, index [1, 2]) sx,sy at sx=0.1 sy=-0.05`.
fn describe_sample(grid: &Grid, sample: &GridSample) -> String {
    let Some(term) = grid.terms.get(sample.term as usize) else { return sample.describe() };
    let Some(strain) = grid.strain_at(sample.term as usize, sample.index) else { return sample.describe() };
    let axes: Vec<usize> = term.axes.iter().map(|&a| a as usize).collect();
    let values = crate::grid::strain_values(&strain);
    format!("{} {} at {}", sample.describe(), term.name(), describe_strain(&values, &axes))
}

/// Compare two artifacts.
pub fn diff(a: &AnyArtifact, b: &AnyArtifact, tol: Tolerance) -> Diff {
    match (a, b) {
        (AnyArtifact::Pattern(a), AnyArtifact::Pattern(b)) => diff_patterns(a, b, tol),
        (AnyArtifact::YarnModel(a), AnyArtifact::YarnModel(b)) => diff_yarn_models(a, b, tol),
        (AnyArtifact::RveSolve(a), AnyArtifact::RveSolve(b)) => diff_rve_solves(a, b, tol),
        (AnyArtifact::Grid(a), AnyArtifact::Grid(b)) => diff_grids(a, b, tol),
        (AnyArtifact::Spline(a), AnyArtifact::Spline(b)) => diff_splines(a, b, tol),
        (AnyArtifact::Swatch(a), AnyArtifact::Swatch(b)) => diff_swatches(a, b, tol),
        _ => {
            let mut d = Diff::new(a.kind());
            d.structural.push(format!("kinds differ: {} vs {}", a.kind(), b.kind()));
            d
        }
    }
}

/// Fields that differ from run to run and are not compared: wall-clock timings.
pub const UNCOMPARED_FIELDS: &[&str] = &["wall_time_s"];

/// Compare two JSON documents of `kind` (calibration reports): the same keys, array lengths,
/// strings, booleans and nulls exactly; numbers within the tolerance, grouped by their path with
/// array indices left out (`directions[].errors.force`), one field per group. The fields of
/// [`UNCOMPARED_FIELDS`] are skipped (with a note).
pub fn diff_documents(kind: &str, a: &serde_json::Value, b: &serde_json::Value, tol: Tolerance) -> Diff {
    let mut walk = DocumentWalk { tol, diff: Diff::new(kind), groups: Vec::new(), skipped: false };
    walk.compare("", a, b);
    let DocumentWalk { mut diff, groups, skipped, .. } = walk;
    diff.fields.extend(groups.into_iter().map(|(_, builder)| builder.finish()));
    if skipped {
        diff.notes.push(format!("not compared: {}", UNCOMPARED_FIELDS.join(", ")));
    }
    diff
}

/// The state of [`diff_documents`]: the differences so far, one numeric field per path.
struct DocumentWalk {
    tol: Tolerance,
    diff: Diff,
    groups: Vec<(String, FieldDiffBuilder)>,
    skipped: bool,
}

impl DocumentWalk {
    /// Compares the values at `path`.
    fn compare(&mut self, path: &str, a: &serde_json::Value, b: &serde_json::Value) {
        use serde_json::Value;
        match (a, b) {
            (Value::Object(x), Value::Object(y)) => {
                let keys: std::collections::BTreeSet<&String> = x.keys().chain(y.keys()).collect();
                for key in keys {
                    let field = if path.is_empty() { key.clone() } else { format!("{path}.{key}") };
                    match (x.get(key), y.get(key)) {
                        _ if UNCOMPARED_FIELDS.contains(&key.as_str()) => self.skipped = true,
                        (Some(u), Some(v)) => self.compare(&field, u, v),
                        _ => self.diff.structural.push(format!("{field}: present in one document only")),
                    }
                }
            }
            (Value::Array(x), Value::Array(y)) if x.len() == y.len() => {
                let field = format!("{path}[]");
                x.iter().zip(y).for_each(|(u, v)| self.compare(&field, u, v));
            }
            (Value::Array(x), Value::Array(y)) => {
                self.diff.structural.push(format!("{path}: {} vs {} entries", x.len(), y.len()));
            }
            (Value::Number(x), Value::Number(y)) => {
                let (u, v, tol) = (x.as_f64().unwrap_or(f64::NAN), y.as_f64().unwrap_or(f64::NAN), self.tol);
                self.number(path).push(&[u], &[v], tol);
            }
            _ if a == b => {}
            _ => self.diff.structural.push(format!("{path}: {a} vs {b}")),
        }
    }

    /// The numeric field of `path`, started on first use.
    fn number(&mut self, path: &str) -> &mut FieldDiffBuilder {
        let slot = match self.groups.iter().position(|(name, _)| name == path) {
            Some(k) => k,
            None => {
                self.groups.push((path.to_string(), FieldDiffBuilder::new(path)));
                self.groups.len() - 1
            }
        };
        &mut self.groups[slot].1
    }
}

/// Compare two patterns: topology exactly, then periods, vertices, twists, radii, rest state.
pub fn diff_patterns(a: &Pattern, b: &Pattern, tol: Tolerance) -> Diff {
    let mut d = Diff::new("pattern");
    if a.name != b.name {
        d.notes.push(format!("names differ: '{}' vs '{}'", a.name, b.name));
    }
    if a.fabric != b.fabric {
        d.structural.push(format!("fabric: {} vs {}", a.fabric, b.fabric));
    }
    let topology = |p: &Pattern| -> Vec<(Vec<u32>, Vec<[i32; 2]>)> {
        p.yarns.iter().map(|y| (y.vertices.clone(), y.edge_offsets.clone())).collect()
    };
    if a.yarns.len() != b.yarns.len() {
        d.structural.push(format!("yarn count: {} vs {}", a.yarns.len(), b.yarns.len()));
    } else if topology(a) != topology(b) {
        d.structural.push("yarn connectivity (vertex order or edge offsets) differs".into());
    }
    d.values("period_m", &a.period_m, &b.period_m, tol);
    d.rows("positions_m", &a.positions_m, &b.positions_m, tol);
    d.values("edge_twist_rad", &a.edge_twist_rad, &b.edge_twist_rad, tol);
    if a.yarns.len() == b.yarns.len() {
        let radii = |p: &Pattern| p.yarns.iter().map(|y| y.radius_m).collect::<Vec<_>>();
        d.values("yarns.radius_m", &radii(a), &radii(b), tol);
    }
    match (&a.rest, &b.rest) {
        (Some(ra), Some(rb)) => {
            d.values("rest.edge_length_m", &ra.edge_length_m, &rb.edge_length_m, tol);
            d.rows("rest.vertex_curvature", &ra.vertex_curvature, &rb.vertex_curvature, tol);
            d.values("rest.vertex_twist_rad", &ra.vertex_twist_rad, &rb.vertex_twist_rad, tol);
            d.rows(
                "rest.edge_reference_director",
                &ra.edge_reference_director,
                &rb.edge_reference_director,
                tol,
            );
            d.values(
                "rest.vertex_reference_twist_rad",
                &ra.vertex_reference_twist_rad,
                &rb.vertex_reference_twist_rad,
                tol,
            );
        }
        (None, None) => {}
        (x, _) => d.structural.push(format!(
            "rest state present only in the {} file",
            if x.is_some() { "first" } else { "second" }
        )),
    }
    d
}

/// Compare two swatches: yarn ranges, sources and glue pairs exactly, then size, vertices,
/// twists, radii, rest state and glue springs; the source pattern and the yarn model as
/// [`diff_patterns`] and [`diff_yarn_models`] do, their fields prefixed `pattern.` and `model.`.
pub fn diff_swatches(a: &Swatch, b: &Swatch, tol: Tolerance) -> Diff {
    let mut d = Diff::new("swatch");
    if a.name != b.name {
        d.notes.push(format!("names differ: '{}' vs '{}'", a.name, b.name));
    }
    let topology = |s: &Swatch| -> Vec<(u32, u32, bool, u32)> {
        s.yarns.iter().map(|y| (y.first_vertex, y.vertex_count, y.closed, y.source_yarn)).collect()
    };
    if a.yarns.len() != b.yarns.len() {
        d.structural.push(format!("yarn count: {} vs {}", a.yarns.len(), b.yarns.len()));
    } else if topology(a) != topology(b) {
        d.structural.push("yarn ranges (first vertex, vertex count, closed, source yarn) differ".into());
    }
    if a.source_vertex != b.source_vertex || a.source_tile != b.source_tile {
        d.structural.push("source vertices or tiles differ".into());
    }
    let pairs = |s: &Swatch| s.glue.iter().map(|g| g.vertices).collect::<Vec<_>>();
    if pairs(a) != pairs(b) {
        d.structural.push(format!(
            "glue springs: {} vs {}, or joining other vertices",
            a.glue.len(),
            b.glue.len()
        ));
    }
    if a.glue_settings != b.glue_settings {
        d.notes.push(format!("glue settings differ: {:?} vs {:?}", a.glue_settings, b.glue_settings));
    }
    d.values("size_m", &a.size_m, &b.size_m, tol);
    d.rows("positions_m", &a.positions_m, &b.positions_m, tol);
    d.values("edge_twist_rad", &a.edge_twist_rad, &b.edge_twist_rad, tol);
    if a.yarns.len() == b.yarns.len() {
        let radii = |s: &Swatch| s.yarns.iter().map(|y| y.radius_m).collect::<Vec<_>>();
        d.values("yarns.radius_m", &radii(a), &radii(b), tol);
    }
    d.values("rest_length_m", &a.rest_length_m, &b.rest_length_m, tol);
    d.rows("reference_director", &a.reference_director, &b.reference_director, tol);
    d.rows("rest_curvature", &a.rest_curvature, &b.rest_curvature, tol);
    d.values("rest_twist_rad", &a.rest_twist_rad, &b.rest_twist_rad, tol);
    d.values("reference_twist_rad", &a.reference_twist_rad, &b.reference_twist_rad, tol);
    if a.glue.len() == b.glue.len() {
        let glue = |s: &Swatch| s.glue.iter().map(|g| [g.rest_length_m, g.stiffness_n_m]).collect::<Vec<_>>();
        d.rows("glue (rest_length_m, stiffness_n_m)", &glue(a), &glue(b), tol);
    }
    d.merge("pattern.", diff_patterns(&a.pattern, &b.pattern, tol));
    d.merge("model.", diff_yarn_models(&a.model, &b.model, tol));
    d
}

/// Compare two yarn models parameter by parameter.
pub fn diff_yarn_models(a: &YarnModel, b: &YarnModel, tol: Tolerance) -> Diff {
    let mut d = Diff::new("yarnmodel");
    if a.name != b.name {
        d.notes.push(format!("names differ: '{}' vs '{}'", a.name, b.name));
    }
    let (pa, pb) = (a.parameters(), b.parameters());
    let names = |p: &[(&'static str, f64)]| p.iter().map(|x| x.0).collect::<Vec<_>>();
    if names(&pa) != names(&pb) {
        d.structural.push("model families differ".into());
        return d;
    }
    for ((name, x), (_, y)) in pa.iter().zip(&pb) {
        d.values(name, &[*x], &[*y], tol);
    }
    d
}

/// Compare two spline materials coefficient by coefficient: scalars, then each term present in
/// both with the same knots. Terms only in one, or with other knots, are structural differences
/// (comparing the energies they evaluate to needs the evaluator, `yarnhom-fit`).
pub fn diff_splines(a: &Spline, b: &Spline, tol: Tolerance) -> Diff {
    let mut d = Diff::new("spline");
    if a.name != b.name {
        d.notes.push(format!("names differ: '{}' vs '{}'", a.name, b.name));
    }
    d.values("areal_density_kg_m2", &[a.areal_density_kg_m2], &[b.areal_density_kg_m2], tol);
    d.values("strain_scale", &a.strain_scale, &b.strain_scale, tol);
    d.values("rest_energy_density_j_m2", &[a.rest_energy_density_j_m2], &[b.rest_energy_density_j_m2], tol);
    for ta in &a.terms_1d {
        let name = crate::grid::AXIS_NAMES.get(ta.axis as usize).copied().unwrap_or("?");
        match b.terms_1d.iter().find(|tb| tb.axis == ta.axis) {
            Some(tb) if tb.knots == ta.knots => {
                d.values(&format!("f_{name}.values"), &ta.values, &tb.values, tol);
                d.values(&format!("f_{name}.slopes"), &ta.slopes, &tb.slopes, tol);
            }
            Some(_) => d.structural.push(format!("f_{name}: knots differ")),
            None => d.structural.push(format!("f_{name}: only in the first")),
        }
    }
    for ta in &a.terms_2d {
        let name = ta.name();
        match b.terms_2d.iter().find(|tb| tb.axes == ta.axes) {
            Some(tb) if tb.u_knots == ta.u_knots && tb.v_knots == ta.v_knots => {
                for (field, x, y) in [
                    ("values", &ta.values, &tb.values),
                    ("du", &ta.du, &tb.du),
                    ("dv", &ta.dv, &tb.dv),
                    ("duv", &ta.duv, &tb.duv),
                ] {
                    d.values(&format!("f_{{{name}}}.{field}"), x, y, tol);
                }
            }
            Some(_) => d.structural.push(format!("f_{{{name}}}: knots differ")),
            None => d.structural.push(format!("f_{{{name}}}: only in the first")),
        }
    }
    let only_second_1d =
        b.terms_1d.iter().filter(|tb| !a.terms_1d.iter().any(|ta| ta.axis == tb.axis)).count();
    let only_second_2d =
        b.terms_2d.iter().filter(|tb| !a.terms_2d.iter().any(|ta| ta.axes == tb.axes)).count();
    if only_second_1d + only_second_2d > 0 {
        d.structural.push(format!("{} terms only in the second", only_second_1d + only_second_2d));
    }
    d
}

/// Compare two tile solves: strain, outcome, energy, stress and equilibrium geometry.
pub fn diff_rve_solves(a: &RveSolve, b: &RveSolve, tol: Tolerance) -> Diff {
    let mut d = Diff::new("rvesolve");
    for (what, x, y) in [("pattern", &a.pattern, &b.pattern), ("model", &a.model, &b.model)] {
        if x != y {
            d.notes.push(format!("{what}s differ: '{x}' vs '{y}'"));
        }
    }
    if a.converged != b.converged {
        d.structural.push(format!("converged: {} vs {}", a.converged, b.converged));
    }
    let strain = |s: &RveSolve| [s.strain.sx, s.strain.sa, s.strain.sy, s.strain.kx, s.strain.ky];
    d.values("strain", &strain(a), &strain(b), tol);
    if let (Some(x), Some(y)) = (a.energy_density_j_m2, b.energy_density_j_m2) {
        d.values("energy_density_j_m2", &[x], &[y], tol);
    }
    for (name, x, y) in [("stress", a.stress, b.stress), ("stress_fd", a.stress_fd, b.stress_fd)] {
        match (x, y) {
            (Some(x), Some(y)) => d.values(name, &x, &y, tol),
            (None, None) => {}
            _ => d.structural.push(format!("{name} present in only one file")),
        }
    }
    d.rows("positions_m", &a.positions_m, &b.positions_m, tol);
    d.values("edge_twist_rad", &a.edge_twist_rad, &b.edge_twist_rad, tol);
    d
}

/// Compare two grids: the sampling plan exactly, then the outcome, energy and stress of the
/// samples both hold, matched by `(term, index)`. A sample field's `worst_index` is the row in
/// the first grid's `samples`; samples in only one grid are structural differences.
pub fn diff_grids(a: &Grid, b: &Grid, tol: Tolerance) -> Diff {
    let mut d = Diff::new("grid");
    for (what, x, y) in [("pattern", &a.pattern, &b.pattern), ("model", &a.model, &b.model)] {
        if x != y {
            d.notes.push(format!("{what}s differ: '{x}' vs '{y}'"));
        }
    }
    if a.shard != b.shard {
        d.notes.push(format!("shards differ: {:?} vs {:?}", a.shard, b.shard));
    }
    if a.terms != b.terms {
        let names = |g: &Grid| {
            let sizes =
                |t: &GridTerm| t.values.iter().map(|v| v.len().to_string()).collect::<Vec<_>>().join("x");
            g.terms.iter().map(|t| format!("{} ({})", t.name(), sizes(t))).collect::<Vec<_>>().join("; ")
        };
        d.structural.push(format!("terms: [{}] vs [{}]", names(a), names(b)));
        return d;
    }
    let pairs = matched_samples(a, b, &mut d);
    let energies: Vec<_> = pairs
        .iter()
        .filter_map(|(x, y)| Some((*x, [[x.energy_density_j_m2?], [y.energy_density_j_m2?]])))
        .collect();
    d.sample_rows("samples.energy_density_j_m2", &energies, a, tol);
    let stresses: Vec<_> = pairs.iter().filter_map(|(x, y)| Some((*x, [x.stress?, y.stress?]))).collect();
    d.sample_rows("samples.stress", &stresses, a, tol);
    d
}

/// The samples both grids hold, matched by `(term, index)`; samples in one grid only, and
/// matched samples whose outcome or stress presence differ, are recorded as structural.
fn matched_samples<'a>(a: &'a Grid, b: &'a Grid, d: &mut Diff) -> Vec<(&'a GridSample, &'a GridSample)> {
    let in_b: HashMap<_, _> = b.samples.iter().map(|s| (s.key(), s)).collect();
    let pairs: Vec<_> = a.samples.iter().filter_map(|s| Some((s, *in_b.get(&s.key())?))).collect();
    let in_a: HashMap<_, _> = a.samples.iter().map(|s| (s.key(), s)).collect();
    let only_a: Vec<_> = a.samples.iter().filter(|s| !in_b.contains_key(&s.key())).collect();
    let only_b: Vec<_> = b.samples.iter().filter(|s| !in_a.contains_key(&s.key())).collect();
    let outcome: Vec<_> = pairs.iter().filter(|(x, y)| x.converged != y.converged).map(|p| p.0).collect();
    let stress: Vec<_> =
        pairs.iter().filter(|(x, y)| x.stress.is_some() != y.stress.is_some()).map(|p| p.0).collect();
    for (what, samples, grid) in [
        ("only in the first file", only_a, a),
        ("only in the second file", only_b, b),
        ("converged in one file only", outcome, a),
        ("with a stress in one file only", stress, a),
    ] {
        if !samples.is_empty() {
            let examples: Vec<String> = samples.iter().take(3).map(|s| describe_sample(grid, s)).collect();
            d.structural.push(format!("{} samples {what}, e.g. {}", samples.len(), examples.join("; ")));
        }
    }
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn documents_differ_in_numbers_beyond_tolerance_and_in_structure_but_not_in_timings() {
        let tol = Tolerance { rtol: 1e-9, atol: 0.0 };
        let a = serde_json::json!({"format": "yarnhom.x", "errors": [{"force": 0.1}, {"force": 0.2}], "wall_time_s": 3.0});
        let same = serde_json::json!({"format": "yarnhom.x", "errors": [{"force": 0.1}, {"force": 0.2}], "wall_time_s": 9.0});
        let d = diff_documents("x", &a, &same, tol);
        assert!(d.equal(), "{}", d.report());
        assert_eq!(d.fields.len(), 1);
        assert_eq!((d.fields[0].field.as_str(), d.fields[0].count), ("errors[].force", 2));
        assert_eq!(d.notes, ["not compared: wall_time_s"]);

        let moved =
            serde_json::json!({"format": "yarnhom.x", "errors": [{"force": 0.1}, {"force": 0.2000001}]});
        let d = diff_documents("x", &a, &moved, tol);
        assert!(!d.equal());
        assert_eq!(d.fields[0].outside, 1);
        assert!(diff_documents("x", &a, &moved, Tolerance { rtol: 1e-5, atol: 0.0 }).equal());

        let renamed = serde_json::json!({"format": "yarnhom.y", "errors": [{"force": 0.1}]});
        let d = diff_documents("x", &a, &renamed, tol);
        assert_eq!(d.structural.len(), 2, "{:?}", d.structural);
    }
}
