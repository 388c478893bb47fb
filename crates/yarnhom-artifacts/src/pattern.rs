//! The `pattern` artifact: a periodic yarn tile.
//!
//! A pattern is the unit cell of a fabric: yarn centrelines inside a rectangular tile of size
//! `period_m[0] x period_m[1]` in the (X1, X2) plane, repeated periodically. Every yarn is
//! closed periodically: it leaves the tile on one side and re-enters on the opposite side, so a
//! yarn with `n` vertices has `n` edges, and edge `k` joins `vertices[k]` to `vertices[k+1 mod n]`
//! shifted by `edge_offsets[k]` whole tiles.
//!
//! Per-edge data is indexed by the edge's *source vertex* (edge `i` is the edge leaving vertex
//! `i`), per-vertex data by the vertex; so all arrays have one entry per vertex. This is the
//! "vertedge" layout of the published `.pyp` files.

use serde::{Deserialize, Serialize};

use crate::check;
use crate::error::ValidationError;

/// Knitted or woven: decides, e.g., the tension applied by the rest-state heuristic (Alg. 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Fabric {
    /// Weft- or warp-knitted: yarns form interlocked loops.
    Knit,
    /// Woven: warp and weft yarns cross over and under each other.
    Woven,
}

impl std::fmt::Display for Fabric {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Fabric::Knit => "knit",
            Fabric::Woven => "woven",
        })
    }
}

/// One periodically closed yarn.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct Yarn {
    /// Yarn radius (m).
    pub radius_m: f64,
    /// Vertex indices in order along the yarn.
    pub vertices: Vec<u32>,
    /// `edge_offsets[k]`: whole tiles (along X1, X2) that the end of edge `k` is shifted by, i.e.
    /// edge `k` runs from `x[vertices[k]]` to `x[vertices[k+1 mod n]] + offset * period`.
    pub edge_offsets: Vec<[i32; 2]>,
}

impl Yarn {
    /// The total tile shift accumulated along one pass of the yarn: where the yarn re-enters
    /// itself. `(1, 0)` for a yarn running along X1.
    pub fn closure_offset(&self) -> [i32; 2] {
        self.edge_offsets.iter().fold([0, 0], |a, o| [a[0] + o[0], a[1] + o[1]])
    }
}

/// The rest shape of the yarns (discrete elastic rods, Bergou et al. 2010).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct RestState {
    /// Rest length of the edge leaving each vertex (m).
    pub edge_length_m: Vec<f64>,
    /// Rest material curvature (kappa1, kappa2) at each vertex, Bergou's integrated
    /// (dimensionless) curvature expressed in the material frames of the two incident edges.
    pub vertex_curvature: Vec<[f64; 2]>,
    /// Rest twist at each vertex (rad).
    pub vertex_twist_rad: Vec<f64>,
    /// First director of the reference frame of the edge leaving each vertex (unit vector).
    pub edge_reference_director: Vec<[f64; 3]>,
    /// Reference twist at each vertex (rad): the twist of the reference frame across the vertex.
    pub vertex_reference_twist_rad: Vec<f64>,
}

/// A periodic yarn tile.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
pub struct Pattern {
    /// Short name, e.g. `rib` or `stockinette`.
    pub name: String,
    /// Knit or woven.
    pub fabric: Fabric,
    /// Tile periods along X1 and X2 (m).
    pub period_m: [f64; 2],
    /// Yarn centreline vertex positions in tile coordinates (m).
    pub positions_m: Vec<[f64; 3]>,
    /// Twist angle of the material frame relative to the reference frame, on the edge leaving
    /// each vertex (rad).
    pub edge_twist_rad: Vec<f64>,
    /// The yarns; together they use every vertex exactly once.
    pub yarns: Vec<Yarn>,
    /// Rest shape, when known (imported from `.pyp` or computed by `rve relax`).
    pub rest: Option<RestState>,
    /// How the pattern was made, e.g. `import of rib.pyp` or `generator stockinette {..}`.
    pub origin: String,
}

/// One edge resolved to its two vertices and its vector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Edge {
    /// Yarn index.
    pub yarn: usize,
    /// Position of the edge along its yarn.
    pub index_in_yarn: usize,
    /// Source vertex (the edge's index in per-edge arrays).
    pub from: u32,
    /// Target vertex.
    pub to: u32,
    /// Tile offset of the target.
    pub offset: [i32; 2],
}

impl Pattern {
    /// Number of vertices (= number of edges).
    pub fn vertex_count(&self) -> usize {
        self.positions_m.len()
    }

    /// Every edge, yarn by yarn.
    pub fn edges(&self) -> impl Iterator<Item = Edge> + '_ {
        self.yarns.iter().enumerate().flat_map(|(y, yarn)| {
            let n = yarn.vertices.len();
            (0..n).map(move |k| Edge {
                yarn: y,
                index_in_yarn: k,
                from: yarn.vertices[k],
                to: yarn.vertices[(k + 1) % n],
                offset: yarn.edge_offsets[k],
            })
        })
    }

    /// Position of vertex `v` shifted by `offset` tiles.
    pub fn shifted(&self, v: u32, offset: [i32; 2]) -> [f64; 3] {
        let x = self.positions_m[v as usize];
        [x[0] + f64::from(offset[0]) * self.period_m[0], x[1] + f64::from(offset[1]) * self.period_m[1], x[2]]
    }

    /// The vector of an edge, end minus start (m).
    pub fn edge_vector(&self, e: &Edge) -> [f64; 3] {
        let a = self.positions_m[e.from as usize];
        let b = self.shifted(e.to, e.offset);
        [b[0] - a[0], b[1] - a[1], b[2] - a[2]]
    }

    /// Smallest and largest yarn radius (m).
    pub fn radius_range_m(&self) -> (f64, f64) {
        self.yarns
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), y| (lo.min(y.radius_m), hi.max(y.radius_m)))
    }

    /// The `nx x ny` tiling of this pattern as one larger tile: vertices copied per tile
    /// (copy `(i, j)` holds vertices `(j nx + i) n ..`), yarns re-traced through the copies, rest
    /// state copied. Homogenized quantities of the tiling equal those of the tile.
    pub fn tiled(&self, nx: u32, ny: u32) -> Pattern {
        let (nx, ny) = (nx.max(1) as i32, ny.max(1) as i32);
        let n = self.vertex_count();
        let copy_index = |c: [i32; 2]| (c[1] * nx + c[0]) as usize;
        let mut positions = Vec::with_capacity(n * (nx * ny) as usize);
        for j in 0..ny {
            for i in 0..nx {
                positions.extend(self.positions_m.iter().map(|p| {
                    [p[0] + f64::from(i) * self.period_m[0], p[1] + f64::from(j) * self.period_m[1], p[2]]
                }));
            }
        }
        let mut next = vec![(0u32, [0i32; 2], 0usize); n];
        for e in self.edges() {
            next[e.from as usize] = (e.to, e.offset, e.yarn);
        }
        let mut seen = vec![false; positions.len()];
        let mut yarns = Vec::new();
        for start in 0..positions.len() {
            if seen[start] {
                continue;
            }
            let mut yarn = Yarn { radius_m: 0.0, vertices: vec![], edge_offsets: vec![] };
            let mut at = start;
            while !seen[at] {
                seen[at] = true;
                let (v, c) = (at % n, at / n);
                let copy = [(c as i32) % nx, (c as i32) / nx];
                let (to, offset, y) = next[v];
                let target = [copy[0] + offset[0], copy[1] + offset[1]];
                let wrapped = [target[0].rem_euclid(nx), target[1].rem_euclid(ny)];
                yarn.radius_m = self.yarns[y].radius_m;
                yarn.vertices.push(at as u32);
                yarn.edge_offsets.push([target[0].div_euclid(nx), target[1].div_euclid(ny)]);
                at = copy_index(wrapped) * n + to as usize;
            }
            yarns.push(yarn);
        }
        let copies = (nx * ny) as usize;
        let repeat = |v: &Vec<f64>| v.iter().copied().cycle().take(n * copies).collect::<Vec<f64>>();
        let rest = self.rest.as_ref().map(|r| RestState {
            edge_length_m: repeat(&r.edge_length_m),
            vertex_curvature: r.vertex_curvature.iter().copied().cycle().take(n * copies).collect(),
            vertex_twist_rad: repeat(&r.vertex_twist_rad),
            edge_reference_director: r
                .edge_reference_director
                .iter()
                .copied()
                .cycle()
                .take(n * copies)
                .collect(),
            vertex_reference_twist_rad: repeat(&r.vertex_reference_twist_rad),
        });
        Pattern {
            name: format!("{}-{nx}x{ny}", self.name),
            fabric: self.fabric,
            period_m: [self.period_m[0] * f64::from(nx), self.period_m[1] * f64::from(ny)],
            edge_twist_rad: repeat(&self.edge_twist_rad),
            positions_m: positions,
            yarns,
            rest,
            origin: format!("{nx}x{ny} tiling of {}", self.origin),
        }
    }

    /// Check every invariant of a pattern; the error names the offending field.
    pub fn validate(&self) -> Result<(), ValidationError> {
        check::positive("period_m[0]", self.period_m[0])?;
        check::positive("period_m[1]", self.period_m[1])?;
        let n = self.vertex_count();
        check::finite_rows("positions_m", &self.positions_m)?;
        check::len("edge_twist_rad", self.edge_twist_rad.len(), n, "vertices")?;
        check::finite("edge_twist_rad", &self.edge_twist_rad)?;
        if self.yarns.is_empty() {
            return Err(ValidationError::new("yarns", "a pattern needs at least one yarn"));
        }
        self.validate_yarns()?;
        self.validate_edge_lengths()?;
        if let Some(rest) = &self.rest {
            rest.validate(n)?;
        }
        Ok(())
    }

    fn validate_yarns(&self) -> Result<(), ValidationError> {
        let n = self.vertex_count();
        let mut owner: Vec<Option<usize>> = vec![None; n];
        for (y, yarn) in self.yarns.iter().enumerate() {
            let field = |f: &str| format!("yarns[{y}].{f}");
            check::positive(&field("radius_m"), yarn.radius_m)?;
            if yarn.vertices.len() < 3 {
                return Err(ValidationError::new(
                    field("vertices"),
                    format!("a closed yarn needs at least 3 vertices, got {}", yarn.vertices.len()),
                ));
            }
            check::len(
                &field("edge_offsets"),
                yarn.edge_offsets.len(),
                yarn.vertices.len(),
                "vertices in the yarn",
            )?;
            for (k, &v) in yarn.vertices.iter().enumerate() {
                let slot = owner.get_mut(v as usize).ok_or_else(|| {
                    ValidationError::new(
                        format!("yarns[{y}].vertices[{k}]"),
                        format!("dangling vertex index {v}: the pattern has {n} vertices"),
                    )
                })?;
                if let Some(other) = slot.replace(y) {
                    return Err(ValidationError::new(
                        format!("yarns[{y}].vertices[{k}]"),
                        format!("vertex {v} is already used by yarn {other}"),
                    ));
                }
            }
            for (k, o) in yarn.edge_offsets.iter().enumerate() {
                if o[0].abs() > 1 || o[1].abs() > 1 {
                    return Err(ValidationError::new(
                        format!("yarns[{y}].edge_offsets[{k}]"),
                        format!(
                            "offset {o:?} skips a whole tile; an edge may cross at most one tile boundary per axis"
                        ),
                    ));
                }
            }
            if yarn.closure_offset() == [0, 0] {
                return Err(ValidationError::new(
                    field("edge_offsets"),
                    "the offsets sum to (0, 0): the yarn closes on itself inside the tile instead of continuing periodically",
                ));
            }
        }
        if let Some(v) = owner.iter().position(Option::is_none) {
            return Err(ValidationError::new(format!("positions_m[{v}]"), "vertex belongs to no yarn"));
        }
        Ok(())
    }

    fn validate_edge_lengths(&self) -> Result<(), ValidationError> {
        let tiny = 1e-9 * self.period_m[0].max(self.period_m[1]);
        for e in self.edges() {
            let d = self.edge_vector(&e);
            let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            if len <= tiny {
                return Err(ValidationError::new(
                    format!("yarns[{}].vertices[{}]", e.yarn, e.index_in_yarn),
                    format!("zero-length edge from vertex {} to vertex {}", e.from, e.to),
                ));
            }
        }
        Ok(())
    }

    /// A one-paragraph human summary (for `yarnhom inspect`).
    pub fn summary(&self) -> String {
        let (r_lo, r_hi) = self.radius_range_m();
        let radius = if r_lo == r_hi {
            format!("{:.4} mm", r_lo * 1e3)
        } else {
            format!("{:.4}-{:.4} mm", r_lo * 1e3, r_hi * 1e3)
        };
        let z = self.positions_m.iter().map(|p| p[2]);
        let (z_lo, z_hi) = z.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), z| (a.min(z), b.max(z)));
        let closures: Vec<String> = self.yarns.iter().map(|y| format!("{:?}", y.closure_offset())).collect();
        format!(
            "pattern '{}' ({} fabric)\n  periods: {:.4} mm x {:.4} mm\n  yarns: {} (closure offsets {})\n  vertices: {} (edges: {})\n  yarn radius: {}\n  thickness (centrelines): {:.4} mm\n  rest state: {}\n  origin: {}",
            self.name,
            self.fabric,
            self.period_m[0] * 1e3,
            self.period_m[1] * 1e3,
            self.yarns.len(),
            closures.join(" "),
            self.vertex_count(),
            self.vertex_count(),
            radius,
            (z_hi - z_lo) * 1e3,
            if self.rest.is_some() { "yes" } else { "no" },
            self.origin,
        )
    }

    /// Guess knit or woven from the geometry: woven yarns advance monotonically along their
    /// run direction, knitted yarns loop back (their projection on the run direction reverses).
    pub fn infer_fabric(&self) -> Fabric {
        let run_direction: Vec<[f64; 2]> = self
            .yarns
            .iter()
            .map(|yarn| {
                let c = yarn.closure_offset();
                let d = [f64::from(c[0]) * self.period_m[0], f64::from(c[1]) * self.period_m[1]];
                let norm = d[0].hypot(d[1]);
                [d[0] / norm, d[1] / norm]
            })
            .collect();
        let loops_back = self.edges().any(|e| {
            let d = self.edge_vector(&e);
            let u = run_direction[e.yarn];
            d[0] * u[0] + d[1] * u[1] < -0.25 * self.yarns[e.yarn].radius_m
        });
        if loops_back { Fabric::Knit } else { Fabric::Woven }
    }
}

impl RestState {
    fn validate(&self, n: usize) -> Result<(), ValidationError> {
        check::len("rest.edge_length_m", self.edge_length_m.len(), n, "vertices")?;
        check::len("rest.vertex_curvature", self.vertex_curvature.len(), n, "vertices")?;
        check::len("rest.vertex_twist_rad", self.vertex_twist_rad.len(), n, "vertices")?;
        check::len("rest.edge_reference_director", self.edge_reference_director.len(), n, "vertices")?;
        check::len("rest.vertex_reference_twist_rad", self.vertex_reference_twist_rad.len(), n, "vertices")?;
        for (i, &l) in self.edge_length_m.iter().enumerate() {
            check::positive(&format!("rest.edge_length_m[{i}]"), l)?;
        }
        check::finite_rows("rest.vertex_curvature", &self.vertex_curvature)?;
        check::finite("rest.vertex_twist_rad", &self.vertex_twist_rad)?;
        check::finite_rows("rest.edge_reference_director", &self.edge_reference_director)?;
        check::finite("rest.vertex_reference_twist_rad", &self.vertex_reference_twist_rad)?;
        for (i, d) in self.edge_reference_director.iter().enumerate() {
            let norm = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            if (norm - 1.0).abs() > 1e-3 {
                return Err(ValidationError::new(
                    format!("rest.edge_reference_director[{i}]"),
                    format!("must be a unit vector, has length {norm}"),
                ));
            }
        }
        Ok(())
    }
}
