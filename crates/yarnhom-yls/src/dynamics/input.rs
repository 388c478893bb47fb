//! What a simulation starts from: the yarns (state and rest shape, independent of any artifact
//! format), the glue springs between them, and the input errors.

use yarnhom_rod::{RestShape, Rod, RodMaterial};

/// One yarn: an open or closed discrete elastic rod (Bergou et al. 2010) with its state and
/// rest shape. Per-vertex rest data (`rest_curvature`, `rest_twist_rad`,
/// `reference_twist_rad`) are read at the bend vertices only (all vertices of a closed yarn,
/// all but the two ends of an open one).
#[derive(Debug, Clone, PartialEq)]
pub struct YarnInput {
    /// Centreline vertices (m).
    pub positions_m: Vec<[f64; 3]>,
    /// Twist angle of every edge's material frame from its reference frame (rad).
    pub edge_twist_rad: Vec<f64>,
    /// Whether the last vertex is joined to the first by an edge.
    pub closed: bool,
    /// Yarn radius (m): obstacle gaps are measured from the yarn's surface.
    pub radius_m: f64,
    /// Rest length of every edge (m).
    pub rest_length_m: Vec<f64>,
    /// First reference director of every edge at `positions_m`.
    pub reference_director: Vec<[f64; 3]>,
    /// Rest material curvature `κ̄` per vertex.
    pub rest_curvature: Vec<[f64; 2]>,
    /// Rest twist `m̄` per vertex (rad).
    pub rest_twist_rad: Vec<f64>,
    /// Reference twist per vertex at `positions_m` (rad).
    pub reference_twist_rad: Vec<f64>,
    /// Stiffness as a rod.
    pub material: RodMaterial,
    /// Mass per unit rest length (kg/m).
    pub linear_density_kg_m: f64,
}

impl YarnInput {
    /// A yarn at rest in `positions_m`, untwisted, with reference directors parallel transported
    /// from `director_hint` ([`RestShape::of`]).
    pub fn at_rest(
        positions_m: Vec<[f64; 3]>,
        closed: bool,
        radius_m: f64,
        material: RodMaterial,
        linear_density_kg_m: f64,
        director_hint: [f64; 3],
    ) -> YarnInput {
        let rest = RestShape::of(&positions_m, closed, director_hint);
        let n = positions_m.len();
        let per_vertex = |values: &[f64]| {
            let mut all = vec![0.0; n];
            for (v, &x) in Rod::bend_vertex_range(n, closed).zip(values) {
                all[v] = x;
            }
            all
        };
        let mut rest_curvature = vec![[0.0; 2]; n];
        for (v, &k) in Rod::bend_vertex_range(n, closed).zip(&rest.rest_curvature) {
            rest_curvature[v] = k;
        }
        YarnInput {
            edge_twist_rad: vec![0.0; rest.rest_lengths_m.len()],
            closed,
            radius_m,
            rest_twist_rad: per_vertex(&rest.rest_twist_rad),
            reference_twist_rad: per_vertex(&rest.reference_twist_rad),
            rest_curvature,
            rest_length_m: rest.rest_lengths_m,
            reference_director: rest.reference_directors,
            material,
            linear_density_kg_m,
            positions_m,
        }
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions_m.len()
    }

    /// Number of edges.
    pub fn edge_count(&self) -> usize {
        if self.closed { self.vertex_count() } else { self.vertex_count().saturating_sub(1) }
    }

    /// The rod of this yarn (its rest data at the bend vertices).
    pub(crate) fn rod(&self) -> Rod {
        let bends = Rod::bend_vertex_range(self.vertex_count(), self.closed);
        let rest = RestShape {
            rest_lengths_m: self.rest_length_m.clone(),
            reference_directors: self.reference_director.clone(),
            rest_curvature: self.rest_curvature[bends.clone()].to_vec(),
            rest_twist_rad: self.rest_twist_rad[bends.clone()].to_vec(),
            reference_twist_rad: self.reference_twist_rad[bends].to_vec(),
        };
        Rod::with_rest_shape(&self.positions_m, self.closed, self.material, rest)
    }

    /// Check list lengths, finiteness and signs.
    pub(crate) fn validate(&self, yarn: usize) -> Result<(), InputError> {
        let bad = |what: String| Err(InputError::Yarn { yarn, what });
        let (n, m) = (self.vertex_count(), self.edge_count());
        if n < 2 || (self.closed && n < 3) {
            return bad(format!(
                "{n} vertices are too few for an {} yarn",
                if self.closed { "closed" } else { "open" }
            ));
        }
        let lengths = [
            ("edge_twist_rad", self.edge_twist_rad.len(), m),
            ("rest_length_m", self.rest_length_m.len(), m),
            ("reference_director", self.reference_director.len(), m),
            ("rest_curvature", self.rest_curvature.len(), n),
            ("rest_twist_rad", self.rest_twist_rad.len(), n),
            ("reference_twist_rad", self.reference_twist_rad.len(), n),
        ];
        for (name, got, want) in lengths {
            if got != want {
                return bad(format!("{name} has {got} entries, the yarn needs {want}"));
            }
        }
        let finite = self.positions_m.iter().flatten().all(|x| x.is_finite())
            && self.reference_director.iter().flatten().all(|x| x.is_finite())
            && self.rest_curvature.iter().flatten().all(|x| x.is_finite())
            && [&self.edge_twist_rad, &self.rest_length_m, &self.rest_twist_rad, &self.reference_twist_rad]
                .iter()
                .all(|v| v.iter().all(|x| x.is_finite()));
        if !finite {
            return bad("non-finite positions, twists or rest data".into());
        }
        let positive = [
            ("radius_m", self.radius_m),
            ("linear_density_kg_m", self.linear_density_kg_m),
            ("smallest rest length", self.rest_length_m.iter().copied().fold(f64::INFINITY, f64::min)),
        ];
        for (name, value) in positive {
            if !(value > 0.0 && value.is_finite()) {
                return bad(format!("{name} must be positive and finite, got {value}"));
            }
        }
        for e in 0..m {
            let (a, b) = (self.positions_m[e], self.positions_m[(e + 1) % n]);
            if a == b {
                return bad(format!("edge {e} has zero length"));
            }
        }
        Ok(())
    }
}

/// Why a scene cannot be simulated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum InputError {
    /// A yarn's lists disagree, or its data are not finite or out of range.
    #[error("yarn {yarn}: {what}")]
    Yarn {
        /// Index of the yarn.
        yarn: usize,
        /// What is wrong.
        what: String,
    },
    /// A glue spring or handle names a vertex the scene does not have.
    #[error("{what} names vertex {vertex}, but the scene has {vertices} vertices")]
    VertexOutOfRange {
        /// Which item names it.
        what: String,
        /// The vertex named.
        vertex: usize,
        /// Number of vertices of the scene.
        vertices: usize,
    },
    /// Two handles (or one handle twice) name the same vertex.
    #[error("vertex {vertex} is in more than one handle")]
    VertexInTwoHandles {
        /// The vertex.
        vertex: usize,
    },
    /// A handle's keyframes are unusable.
    #[error("handle {handle}: {what}")]
    Keyframes {
        /// Index of the handle.
        handle: usize,
        /// What is wrong.
        what: String,
    },
    /// A parameter is not finite or out of its range.
    #[error("{what} must be {range}, got {value}")]
    Parameter {
        /// Which parameter.
        what: String,
        /// Its admissible range, in words.
        range: &'static str,
        /// The value given.
        value: f64,
    },
    /// A vertex starts at or inside an obstacle's barrier (its surface gap not positive).
    #[error("vertex {vertex} starts {gap_m} m from obstacle {obstacle}: its surface must clear the obstacle")]
    InsideObstacle {
        /// The vertex (global index).
        vertex: usize,
        /// Index of the obstacle.
        obstacle: usize,
        /// Distance from the yarn's surface to the obstacle (m).
        gap_m: f64,
    },
    /// Two edges in contact range start with crossing (or touching) centrelines.
    #[error("edges {a} and {b} start with centrelines {distance_m} m apart: they must not touch")]
    EdgesTouch {
        /// First edge (global index).
        a: usize,
        /// Second edge (global index).
        b: usize,
        /// Their centreline distance (m).
        distance_m: f64,
    },
    /// A list given to the simulation has the wrong length.
    #[error("{what} has {got} entries, expected {expected}")]
    Length {
        /// Which list.
        what: &'static str,
        /// Its length.
        got: usize,
        /// The length expected.
        expected: usize,
    },
}

/// Check that `value` is finite and positive.
pub(crate) fn positive(what: &str, value: f64) -> Result<(), InputError> {
    if value > 0.0 && value.is_finite() {
        Ok(())
    } else {
        Err(InputError::Parameter { what: what.into(), range: "positive and finite", value })
    }
}

/// Check that `value` is finite and not negative.
pub(crate) fn non_negative(what: &str, value: f64) -> Result<(), InputError> {
    if value >= 0.0 && value.is_finite() {
        Ok(())
    } else {
        Err(InputError::Parameter { what: what.into(), range: "non-negative and finite", value })
    }
}
