//! The `swatch` artifact: a finite piece of fabric at the yarn level (thesis Sec. 4.3.1).
//!
//! A swatch is a periodic [`Pattern`] with a rest state tiled over a rectangle and cut at its
//! border (`yarnhom-yls` builds one with `cut_swatch`). Its yarns are discrete elastic rods,
//! open (cut at the border) or closed, stored in global arrays:
//!
//! - vertices: the vertices of yarn `k` are the contiguous range
//!   `first_vertex .. first_vertex + vertex_count`, yarn after yarn, covering every vertex once;
//! - edges: an open yarn of `n` vertices has `n - 1` edges, a closed one `n` (the last joins its
//!   last vertex to its first); edges are numbered contiguously yarn after yarn, in the order of
//!   the vertices (see [`Swatch::edges`]);
//! - rest state: per edge a rest length and a reference director, per vertex a rest curvature,
//!   rest twist and reference twist. Vertex quantities couple the two edges meeting at a vertex,
//!   so they exist at the interior vertices of an open yarn only: its two end vertices hold
//!   zeros.
//!
//! Cut yarn ends would unravel; the thesis "effectively glue\[s\] the yarns together with springs
//! that are pre-stretched in the thickness direction". The [`GlueSpring`]s are those springs,
//! and [`GlueSettings`] records how they were made.

use serde::{Deserialize, Serialize};

use crate::check;
use crate::error::ValidationError;
use crate::pattern::Pattern;
use crate::yarnmodel::YarnModel;

/// A yarn-level swatch: yarns cut from a tiled pattern, their rest state and the glue springs
/// that hold the cut ends. SI units throughout.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct Swatch {
    /// Short name, e.g. `stock-60.2x31.7mm`.
    pub name: String,
    /// The whole periodic tile the swatch was cut from, with its rest state.
    pub pattern: Pattern,
    /// The yarn model the swatch is simulated with.
    pub model: YarnModel,
    /// Width and height of the cut rectangle `[0, W] x [0, H]` (m), in the pattern's tile
    /// coordinates (tile `(0, 0)` at the origin).
    pub size_m: [f64; 2],
    /// Yarn centreline vertex positions (m), yarn after yarn.
    pub positions_m: Vec<[f64; 3]>,
    /// Twist angle of each edge's material frame relative to its reference frame (rad).
    pub edge_twist_rad: Vec<f64>,
    /// The pattern vertex each vertex is a copy of (index into `pattern.positions_m`).
    pub source_vertex: Vec<u32>,
    /// The tile `(i, j)` each vertex's copy lies in: its position is the pattern vertex's
    /// shifted by `(i P1, j P2, 0)` (whole tiles, dimensionless).
    pub source_tile: Vec<[i32; 2]>,
    /// The yarns, in the order of their vertex ranges.
    pub yarns: Vec<SwatchYarn>,
    /// Rest length of each edge (m).
    pub rest_length_m: Vec<f64>,
    /// First director of each edge's reference frame (unit vector, perpendicular to the edge).
    pub reference_director: Vec<[f64; 3]>,
    /// Rest material curvature (kappa1, kappa2) at each vertex, integrated (dimensionless), as in
    /// [`crate::RestState::vertex_curvature`]; zero at the ends of open yarns.
    pub rest_curvature: Vec<[f64; 2]>,
    /// Rest twist at each vertex (rad); zero at the ends of open yarns.
    pub rest_twist_rad: Vec<f64>,
    /// Reference twist at each vertex, the twist of the reference frame across the vertex (rad);
    /// zero at the ends of open yarns.
    pub reference_twist_rad: Vec<f64>,
    /// The springs that glue the cut yarn ends to their neighbours.
    pub glue: Vec<GlueSpring>,
    /// How the glue springs were made.
    pub glue_settings: GlueSettings,
}

/// One yarn of a swatch: a contiguous range of vertices.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct SwatchYarn {
    /// Yarn radius (m).
    pub radius_m: f64,
    /// Index of the yarn's first vertex.
    pub first_vertex: u32,
    /// Number of vertices, at least 3.
    pub vertex_count: u32,
    /// Whether the yarn is a closed loop (its last vertex joined to its first).
    pub closed: bool,
    /// The pattern yarn it was cut from (index into `pattern.yarns`).
    pub source_yarn: u32,
}

/// A spring between two vertices holding a cut yarn end in place.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct GlueSpring {
    /// The two vertices it joins (distinct; the first is the cut yarn end).
    pub vertices: [u32; 2],
    /// Rest length (m), shorter than the vertices' distance by the pre-stretch.
    pub rest_length_m: f64,
    /// Stiffness (N/m).
    pub stiffness_n_m: f64,
}

/// How the glue springs of a swatch are made (our reading of the thesis' one sentence, Sec.
/// 4.3.1; the builder in `yarnhom-yls` states the rule): each cut end is joined to its nearest
/// vertex on another yarn (or far along its own) within reach, by a spring shorter than that
/// distance.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct GlueSettings {
    /// Reach, in sums of the two yarn radii: a vertex is a partner when its centreline distance
    /// to the end is below `reach_radii * (r_a + r_b)`. Default 1.5.
    pub reach_radii: f64,
    /// Fraction by which a spring's rest length is shorter than the distance it spans,
    /// `0 <= pre_stretch < 1`: the spring pulls the crossing together through the thickness.
    /// Default 0.1.
    pub pre_stretch: f64,
    /// Spring stiffness (N/m); absent: the yarn's stretch stiffness divided by the distance the
    /// spring spans (the default).
    pub stiffness_n_m: Option<f64>,
}

impl Default for GlueSettings {
    fn default() -> Self {
        GlueSettings { reach_radii: 1.5, pre_stretch: 0.1, stiffness_n_m: None }
    }
}

impl GlueSettings {
    /// Check the settings: a positive reach, `0 <= pre_stretch < 1`, a positive stiffness if
    /// given. `field` prefixes the error's field path.
    pub fn validate(&self, field: &str) -> Result<(), ValidationError> {
        check::positive(&format!("{field}.reach_radii"), self.reach_radii)?;
        check::non_negative(&format!("{field}.pre_stretch"), self.pre_stretch)?;
        if self.pre_stretch >= 1.0 {
            return Err(ValidationError::new(
                format!("{field}.pre_stretch"),
                format!("must be below 1 (a spring of zero rest length), got {}", self.pre_stretch),
            ));
        }
        if let Some(k) = self.stiffness_n_m {
            check::positive(&format!("{field}.stiffness_n_m"), k)?;
        }
        Ok(())
    }
}

impl SwatchYarn {
    /// Number of edges: `n - 1` for an open yarn of `n` vertices, `n` for a closed one.
    pub fn edge_count(&self) -> usize {
        let n = self.vertex_count as usize;
        if self.closed { n } else { n.saturating_sub(1) }
    }

    /// The yarn's vertex indices.
    pub fn vertices(&self) -> std::ops::Range<usize> {
        let first = self.first_vertex as usize;
        first..first + self.vertex_count as usize
    }
}

impl Swatch {
    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions_m.len()
    }

    /// Number of edges, summed over the yarns.
    pub fn edge_count(&self) -> usize {
        self.yarns.iter().map(SwatchYarn::edge_count).sum()
    }

    /// Every edge as its two vertices, in edge order: yarn after yarn, edge `i` of a yarn
    /// joining its vertices `i` and `i + 1` (and, for a closed yarn, the last to the first).
    pub fn edges(&self) -> impl Iterator<Item = [u32; 2]> + '_ {
        self.yarns.iter().flat_map(|y| {
            let (first, n) = (y.first_vertex, y.vertex_count);
            (0..y.edge_count() as u32).map(move |i| [first + i, first + (i + 1) % n])
        })
    }

    /// The swatch's size in tiles of its pattern (fractional where the cut falls mid-tile).
    pub fn size_tiles(&self) -> [f64; 2] {
        [self.size_m[0] / self.pattern.period_m[0], self.size_m[1] / self.pattern.period_m[1]]
    }

    /// Check every invariant; the error names the offending field.
    pub fn validate(&self) -> Result<(), ValidationError> {
        self.validate_sources()?;
        check::positive("size_m[0]", self.size_m[0])?;
        check::positive("size_m[1]", self.size_m[1])?;
        self.validate_yarns()?;
        self.validate_vertex_arrays()?;
        self.validate_edge_arrays()?;
        self.validate_open_ends()?;
        self.validate_glue()
    }

    /// The pattern (with its rest state), the model and the glue settings.
    fn validate_sources(&self) -> Result<(), ValidationError> {
        let prefixed = |prefix: &str, e: ValidationError| {
            ValidationError::new(format!("{prefix}.{}", e.field), e.problem)
        };
        self.pattern.validate().map_err(|e| prefixed("pattern", e))?;
        if self.pattern.rest.is_none() {
            return Err(ValidationError::new(
                "pattern.rest",
                "the source pattern of a swatch needs its rest state",
            ));
        }
        self.model.validate().map_err(|e| prefixed("model", e))?;
        self.glue_settings.validate("glue_settings")
    }

    /// Yarn ranges contiguous and covering every vertex, at least 3 vertices, positive radii,
    /// source yarns that exist.
    fn validate_yarns(&self) -> Result<(), ValidationError> {
        if self.yarns.is_empty() {
            return Err(ValidationError::new("yarns", "a swatch needs at least one yarn"));
        }
        let mut next = 0usize;
        for (k, y) in self.yarns.iter().enumerate() {
            let field = |f: &str| format!("yarns[{k}].{f}");
            check::positive(&field("radius_m"), y.radius_m)?;
            if y.vertex_count < 3 {
                return Err(ValidationError::new(
                    field("vertex_count"),
                    format!("a yarn needs at least 3 vertices, got {}", y.vertex_count),
                ));
            }
            if y.first_vertex as usize != next {
                return Err(ValidationError::new(
                    field("first_vertex"),
                    format!(
                        "is {} but the previous yarns end at vertex {next}: yarn ranges must be contiguous and not overlap",
                        y.first_vertex
                    ),
                ));
            }
            next += y.vertex_count as usize;
            if y.source_yarn as usize >= self.pattern.yarns.len() {
                return Err(ValidationError::new(
                    field("source_yarn"),
                    format!(
                        "pattern yarn {} does not exist: the pattern has {}",
                        y.source_yarn,
                        self.pattern.yarns.len()
                    ),
                ));
            }
        }
        if next != self.vertex_count() {
            return Err(ValidationError::new(
                "yarns",
                format!("the yarns cover {next} vertices but there are {}", self.vertex_count()),
            ));
        }
        Ok(())
    }

    fn validate_vertex_arrays(&self) -> Result<(), ValidationError> {
        let n = self.vertex_count();
        check::finite_rows("positions_m", &self.positions_m)?;
        check::len("source_vertex", self.source_vertex.len(), n, "vertices")?;
        check::len("source_tile", self.source_tile.len(), n, "vertices")?;
        check::len("rest_curvature", self.rest_curvature.len(), n, "vertices")?;
        check::len("rest_twist_rad", self.rest_twist_rad.len(), n, "vertices")?;
        check::len("reference_twist_rad", self.reference_twist_rad.len(), n, "vertices")?;
        check::finite_rows("rest_curvature", &self.rest_curvature)?;
        check::finite("rest_twist_rad", &self.rest_twist_rad)?;
        check::finite("reference_twist_rad", &self.reference_twist_rad)?;
        let pattern_vertices = self.pattern.vertex_count();
        match self.source_vertex.iter().position(|&v| v as usize >= pattern_vertices) {
            Some(i) => Err(ValidationError::new(
                format!("source_vertex[{i}]"),
                format!(
                    "pattern vertex {} does not exist: the pattern has {pattern_vertices}",
                    self.source_vertex[i]
                ),
            )),
            None => Ok(()),
        }
    }

    fn validate_edge_arrays(&self) -> Result<(), ValidationError> {
        let e = self.edge_count();
        check::len("edge_twist_rad", self.edge_twist_rad.len(), e, "edges")?;
        check::len("rest_length_m", self.rest_length_m.len(), e, "edges")?;
        check::len("reference_director", self.reference_director.len(), e, "edges")?;
        check::finite("edge_twist_rad", &self.edge_twist_rad)?;
        for (i, &l) in self.rest_length_m.iter().enumerate() {
            check::positive(&format!("rest_length_m[{i}]"), l)?;
        }
        check::finite_rows("reference_director", &self.reference_director)?;
        for (i, d) in self.reference_director.iter().enumerate() {
            let norm = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            if (norm - 1.0).abs() > 1e-3 {
                return Err(ValidationError::new(
                    format!("reference_director[{i}]"),
                    format!("must be a unit vector, has length {norm}"),
                ));
            }
        }
        Ok(())
    }

    /// The end vertices of open yarns carry no curvature, twist or reference twist.
    fn validate_open_ends(&self) -> Result<(), ValidationError> {
        let ends = self.yarns.iter().filter(|y| !y.closed).flat_map(|y| {
            let r = y.vertices();
            [r.start, r.end - 1]
        });
        for v in ends {
            let values = [
                ("rest_curvature", self.rest_curvature[v][0].abs() + self.rest_curvature[v][1].abs()),
                ("rest_twist_rad", self.rest_twist_rad[v].abs()),
                ("reference_twist_rad", self.reference_twist_rad[v].abs()),
            ];
            if let Some((field, value)) = values.iter().find(|(_, value)| *value != 0.0) {
                return Err(ValidationError::new(
                    format!("{field}[{v}]"),
                    format!("vertex {v} ends an open yarn, so it must hold zeros, found magnitude {value}"),
                ));
            }
        }
        Ok(())
    }

    fn validate_glue(&self) -> Result<(), ValidationError> {
        let n = self.vertex_count();
        for (i, g) in self.glue.iter().enumerate() {
            let field = |f: &str| format!("glue[{i}].{f}");
            if let Some(&v) = g.vertices.iter().find(|&&v| v as usize >= n) {
                return Err(ValidationError::new(
                    field("vertices"),
                    format!("dangling vertex index {v}: the swatch has {n} vertices"),
                ));
            }
            if g.vertices[0] == g.vertices[1] {
                return Err(ValidationError::new(
                    field("vertices"),
                    format!("joins vertex {} to itself", g.vertices[0]),
                ));
            }
            check::positive(&field("rest_length_m"), g.rest_length_m)?;
            check::positive(&field("stiffness_n_m"), g.stiffness_n_m)?;
        }
        Ok(())
    }

    /// A one-line human summary (for `yarnhom inspect`).
    pub fn summary(&self) -> String {
        let tiles = self.size_tiles();
        let open = self.yarns.iter().filter(|y| !y.closed).count();
        format!(
            "swatch '{}': {} yarns ({open} open), {} vertices, {} edges, {} glue springs, {:.2} mm x {:.2} mm ({:.2} x {:.2} tiles of pattern '{}')",
            self.name,
            self.yarns.len(),
            self.vertex_count(),
            self.edge_count(),
            self.glue.len(),
            self.size_m[0] * 1e3,
            self.size_m[1] * 1e3,
            tiles[0],
            tiles[1],
            self.pattern.name,
        )
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;
    use crate::pattern::{Fabric, RestState, Yarn};
    use crate::{Artifact, Provenance, container};

    /// A one-yarn pattern along X1 with a rest state: 4 vertices on a wavy line.
    fn pattern() -> Pattern {
        let n = 4;
        let positions_m: Vec<[f64; 3]> =
            (0..n).map(|i| [0.0025 * i as f64, 0.0, if i % 2 == 0 { 5e-4 } else { -5e-4 }]).collect();
        Pattern {
            name: "wave".into(),
            fabric: Fabric::Woven,
            period_m: [0.01, 0.004],
            positions_m,
            edge_twist_rad: vec![0.1; n],
            yarns: vec![Yarn {
                radius_m: 5e-4,
                vertices: vec![0, 1, 2, 3],
                edge_offsets: vec![[0, 0], [0, 0], [0, 0], [1, 0]],
            }],
            rest: Some(RestState {
                edge_length_m: vec![0.0027; n],
                vertex_curvature: vec![[0.2, -0.1]; n],
                vertex_twist_rad: vec![0.01; n],
                edge_reference_director: vec![[0.0, 1.0, 0.0]; n],
                vertex_reference_twist_rad: vec![0.02; n],
            }),
            origin: "test".into(),
        }
    }

    /// Two open yarns of 5 and 4 vertices and one closed yarn of 3, with one glue spring.
    fn swatch() -> Swatch {
        let counts = [(5u32, false), (4, false), (3, true)];
        let mut yarns = Vec::new();
        let mut first = 0;
        for (n, closed) in counts {
            yarns.push(SwatchYarn {
                radius_m: 5e-4,
                first_vertex: first,
                vertex_count: n,
                closed,
                source_yarn: 0,
            });
            first += n;
        }
        let n = first as usize;
        let e = 4 + 3 + 3;
        let ends = [0usize, 4, 5, 8];
        let at_end = |v: usize, x: f64| if ends.contains(&v) { 0.0 } else { x };
        Swatch {
            name: "test swatch".into(),
            pattern: pattern(),
            model: YarnModel::table_4_1("stock").unwrap(),
            size_m: [0.02, 0.008],
            positions_m: (0..n).map(|i| [0.0025 * i as f64, 0.001 * (i % 3) as f64, 0.0]).collect(),
            edge_twist_rad: vec![0.1; e],
            source_vertex: (0..n).map(|i| (i % 4) as u32).collect(),
            source_tile: vec![[0, 1]; n],
            yarns,
            rest_length_m: vec![0.0027; e],
            reference_director: vec![[0.0, 0.0, 1.0]; e],
            rest_curvature: (0..n).map(|v| [at_end(v, 0.2), at_end(v, -0.1)]).collect(),
            rest_twist_rad: (0..n).map(|v| at_end(v, 0.01)).collect(),
            reference_twist_rad: (0..n).map(|v| at_end(v, 0.02)).collect(),
            glue: vec![GlueSpring { vertices: [0, 5], rest_length_m: 0.001, stiffness_n_m: 100.0 }],
            glue_settings: GlueSettings::default(),
        }
    }

    #[test]
    fn the_test_swatch_is_valid_and_counts_edges_per_yarn_kind() {
        let s = swatch();
        s.validate().unwrap();
        assert_eq!(s.edge_count(), 10);
        let edges: Vec<[u32; 2]> = s.edges().collect();
        assert_eq!(edges.len(), 10);
        assert_eq!(edges[3], [3, 4]);
        assert_eq!(edges[4], [5, 6]);
        // The closed yarn's last edge returns to its first vertex.
        assert_eq!(&edges[7..], &[[9, 10], [10, 11], [11, 9]]);
        assert_eq!(s.size_tiles(), [2.0, 2.0]);
    }

    #[test]
    fn summary_is_one_line_with_the_counts() {
        let text = swatch().summary();
        assert!(!text.contains('\n'), "{text}");
        for part in
            ["3 yarns (2 open)", "12 vertices", "10 edges", "1 glue springs", "20.00 mm x 8.00 mm", "'wave'"]
        {
            assert!(text.contains(part), "{part} missing from {text}");
        }
    }

    /// Every corruption and the field its error must name.
    #[test]
    fn validate_rejects_each_corruption() {
        type Edit = fn(&mut Swatch);
        let cases: &[(&str, Edit, &str)] = &[
            (
                "short positions",
                |s| {
                    s.positions_m.pop();
                },
                "yarns",
            ),
            (
                "short source_vertex",
                |s| {
                    s.source_vertex.pop();
                },
                "source_vertex",
            ),
            (
                "short source_tile",
                |s| {
                    s.source_tile.pop();
                },
                "source_tile",
            ),
            (
                "short rest_curvature",
                |s| {
                    s.rest_curvature.pop();
                },
                "rest_curvature",
            ),
            (
                "short rest_twist",
                |s| {
                    s.rest_twist_rad.pop();
                },
                "rest_twist_rad",
            ),
            (
                "short reference_twist",
                |s| {
                    s.reference_twist_rad.pop();
                },
                "reference_twist_rad",
            ),
            (
                "short edge_twist",
                |s| {
                    s.edge_twist_rad.pop();
                },
                "edge_twist_rad",
            ),
            ("long rest_length", |s| s.rest_length_m.push(0.001), "rest_length_m"),
            (
                "short director",
                |s| {
                    s.reference_director.pop();
                },
                "reference_director",
            ),
            ("NaN position", |s| s.positions_m[3][1] = f64::NAN, "positions_m[3][1]"),
            ("inf edge twist", |s| s.edge_twist_rad[2] = f64::INFINITY, "edge_twist_rad[2]"),
            ("NaN curvature", |s| s.rest_curvature[2][0] = f64::NAN, "rest_curvature[2][0]"),
            ("NaN rest twist", |s| s.rest_twist_rad[2] = f64::NAN, "rest_twist_rad[2]"),
            ("NaN reference twist", |s| s.reference_twist_rad[2] = f64::NAN, "reference_twist_rad[2]"),
            ("NaN director", |s| s.reference_director[1][2] = f64::NAN, "reference_director[1][2]"),
            ("non-unit director", |s| s.reference_director[1] = [0.0, 0.0, 2.0], "reference_director[1]"),
            ("zero rest length", |s| s.rest_length_m[4] = 0.0, "rest_length_m[4]"),
            ("negative rest length", |s| s.rest_length_m[4] = -1e-3, "rest_length_m[4]"),
            ("zero radius", |s| s.yarns[1].radius_m = 0.0, "yarns[1].radius_m"),
            ("NaN radius", |s| s.yarns[1].radius_m = f64::NAN, "yarns[1].radius_m"),
            ("two-vertex yarn", |s| s.yarns[2].vertex_count = 2, "yarns[2].vertex_count"),
            ("overlapping yarns", |s| s.yarns[1].first_vertex = 4, "yarns[1].first_vertex"),
            ("gap between yarns", |s| s.yarns[1].first_vertex = 6, "yarns[1].first_vertex"),
            ("yarns past the vertices", |s| s.yarns[2].vertex_count = 4, "yarns"),
            ("no yarns", |s| s.yarns.clear(), "yarns"),
            ("unknown source yarn", |s| s.yarns[0].source_yarn = 1, "yarns[0].source_yarn"),
            ("unknown source vertex", |s| s.source_vertex[7] = 4, "source_vertex[7]"),
            ("curvature at an open end", |s| s.rest_curvature[4] = [0.0, 1e-9], "rest_curvature[4]"),
            ("twist at an open end", |s| s.rest_twist_rad[5] = 0.3, "rest_twist_rad[5]"),
            ("reference twist at an open end", |s| s.reference_twist_rad[0] = -0.1, "reference_twist_rad[0]"),
            ("glue to itself", |s| s.glue[0].vertices = [3, 3], "glue[0].vertices"),
            ("glue out of range", |s| s.glue[0].vertices = [3, 12], "glue[0].vertices"),
            ("glue of zero rest length", |s| s.glue[0].rest_length_m = 0.0, "glue[0].rest_length_m"),
            ("glue of NaN stiffness", |s| s.glue[0].stiffness_n_m = f64::NAN, "glue[0].stiffness_n_m"),
            ("negative size", |s| s.size_m[1] = -0.01, "size_m[1]"),
            ("infinite size", |s| s.size_m[0] = f64::INFINITY, "size_m[0]"),
            ("pre-stretch of 1", |s| s.glue_settings.pre_stretch = 1.0, "glue_settings.pre_stretch"),
            ("zero reach", |s| s.glue_settings.reach_radii = 0.0, "glue_settings.reach_radii"),
            (
                "zero glue stiffness",
                |s| s.glue_settings.stiffness_n_m = Some(0.0),
                "glue_settings.stiffness_n_m",
            ),
            ("pattern without rest", |s| s.pattern.rest = None, "pattern.rest"),
            ("invalid pattern", |s| s.pattern.period_m[0] = 0.0, "pattern.period_m[0]"),
            ("invalid model", |s| s.model.radius_m = -1.0, "model.radius_m"),
        ];
        for (what, edit, field) in cases {
            let mut s = swatch();
            edit(&mut s);
            let e = s.validate().expect_err(what);
            assert_eq!(&e.field, field, "{what}: {e}");
        }
    }

    #[test]
    fn a_closed_yarn_may_hold_rest_values_at_every_vertex() {
        let mut s = swatch();
        // Vertex 9 starts the closed yarn: not an end.
        s.rest_twist_rad[9] = 0.3;
        s.validate().unwrap();
    }

    #[test]
    fn round_trips_through_the_container_and_json() {
        let s = swatch();
        let bytes = container::encode(&s, &Provenance::default()).unwrap();
        let (header, back): (_, Swatch) = container::decode(&bytes).unwrap();
        assert_eq!((header.kind.as_str(), header.schema_version), (Swatch::KIND, 1));
        assert_eq!(back, s);
        let json = serde_json::to_string(&s).unwrap();
        assert_eq!(serde_json::from_str::<Swatch>(&json).unwrap(), s);
    }

    #[test]
    fn an_invalid_swatch_is_not_written() {
        let mut s = swatch();
        s.glue[0].vertices = [1, 1];
        let e = container::encode(&s, &Provenance::default()).unwrap_err();
        assert!(e.to_string().contains("glue[0].vertices"), "{e}");
    }

    #[test]
    fn diff_names_the_largest_position_difference_and_structural_changes() {
        use crate::diff::{Tolerance, diff_swatches};
        let tol = Tolerance { rtol: 0.0, atol: 1e-9 };
        let a = swatch();
        assert!(diff_swatches(&a, &a, tol).equal());
        let mut b = a.clone();
        b.positions_m[7][2] += 3e-6;
        b.model.density_kg_m3 *= 2.0;
        let d = diff_swatches(&a, &b, tol);
        assert!(!d.equal(), "{}", d.report());
        let moved = d.fields.iter().find(|f| f.field == "positions_m").unwrap();
        assert_eq!((moved.worst_index, moved.outside), (7, 1));
        assert!((moved.max_abs - 3e-6).abs() < 1e-15);
        let density = d.fields.iter().find(|f| f.field == "model.density_kg_m3").unwrap();
        assert_eq!(density.outside, 1);
        b.glue.clear();
        assert!(diff_swatches(&a, &b, tol).structural.iter().any(|s| s.contains("glue springs: 1 vs 0")));
    }
}
