//! The tile's elements and rest state, from a pattern (with rest state) and a yarn model.

use nalgebra::Vector3;
use yarnhom_artifacts::{Pattern, YarnModel};
use yarnhom_geom::segment_distance;
use yarnhom_pattern::YarnNeighbours;
use yarnhom_rod::{BendTwist, ContactLaw, RodMaterial, rod_laws};

use crate::placement::Instance;

/// Why a tile cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RveError {
    /// The pattern has no rest state (run `yarnhom rve relax` first, or import one that has).
    #[error(
        "pattern '{0}' has no rest state; relax it first (yarnhom rve relax) or import a pattern with one"
    )]
    MissingRestState(String),
    /// Model and pattern disagree on the yarn radius.
    #[error(
        "yarn model radius {model_m} m differs from the pattern's yarn radius {pattern_m} m by more than 5%"
    )]
    RadiusMismatch {
        /// Radius in the yarn model.
        model_m: f64,
        /// Radius of the pattern's yarns.
        pattern_m: f64,
    },
}

/// A stretched edge: from a tile vertex to its neighbour, possibly in another image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StretchElement {
    /// Start of the edge (in the tile).
    pub from: Instance,
    /// End of the edge.
    pub to: Instance,
    /// Rest length (m).
    pub rest_length_m: f64,
}

/// A bending-twisting element at a tile vertex.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BendElement {
    /// Previous vertex (start of the incoming edge), in its image relative to the tile vertex.
    pub prev: Instance,
    /// The vertex (in the tile).
    pub vertex: Instance,
    /// Next vertex (end of the outgoing edge).
    pub next: Instance,
    /// Stiffness and rest shape.
    pub element: BendTwist,
}

/// One yarn of the tile, as the constraints see it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct YarnInfo {
    /// Its vertices.
    pub vertices: Vec<u32>,
}

/// The tile: topology, rest state and materials. Edges are indexed by their source vertex.
#[derive(Debug, Clone)]
pub struct RveModel {
    /// Number of vertices (= edges).
    pub vertices: usize,
    /// Tile periods (m).
    pub period_m: [f64; 2],
    /// Material points `(X1, X2, h)` of the vertices: the pattern's geometry, centred on the
    /// tile's mean position.
    pub material: Vec<Vector3<f64>>,
    /// Reference directors of the edges in the material (flat) configuration.
    pub material_directors: Vec<[f64; 3]>,
    /// Twist angles of the edges' material frames in the pattern (rad): the start of the twist DOFs.
    pub material_twists: Vec<f64>,
    /// Reference twists of the bend elements in the material configuration (rad).
    pub material_reference_twists: Vec<f64>,
    /// Stretch elements, one per edge, indexed by source vertex (like every per-edge array).
    pub stretch: Vec<StretchElement>,
    /// Bend-twist elements, one per vertex.
    pub bends: Vec<BendElement>,
    /// Rod stiffness.
    pub material_law: RodMaterial,
    /// Yarn-yarn contact.
    pub contact: ContactLaw,
    /// Which edge pairs are neighbours along a yarn (no contact between them).
    pub neighbours: YarnNeighbours,
    /// Rest lengths of the edges (m), by source vertex.
    pub rest_length_m: Vec<f64>,
    /// Smallest yarn radius (m): the scale of step limits and tolerances.
    pub radius_m: f64,
    /// The yarns: vertices and closure offset.
    pub yarns: Vec<YarnInfo>,
    /// Unit tangent of the yarn at each vertex in the material configuration (the mean of its
    /// two edges' directions): the sliding direction the solver's constraints hold still.
    pub material_tangents: Vec<Vector3<f64>>,
    /// Tile images whose edges can come within contact reach of the tile's own edges: yarns
    /// reach out of their tile (loops are wider than stitches), so this may go beyond the 8
    /// neighbours.
    pub images: Vec<[i32; 2]>,
}

impl RveModel {
    /// Build the tile of `pattern` (which must carry a rest state) with the elastic-rod model
    /// `model` (Ch. 3-5: Table 4.1 parameters).
    pub fn new(pattern: &Pattern, model: &YarnModel) -> Result<Self, RveError> {
        let rest = pattern.rest.as_ref().ok_or_else(|| RveError::MissingRestState(pattern.name.clone()))?;
        let (material_law, contact) = rod_laws(model);
        let (r_lo, r_hi) = pattern.radius_range_m();
        for r in [r_lo, r_hi] {
            if (r / model.radius_m - 1.0).abs() > 0.05 {
                return Err(RveError::RadiusMismatch { model_m: model.radius_m, pattern_m: r });
            }
        }
        let n = pattern.vertex_count();
        let centre =
            pattern.positions_m.iter().fold(Vector3::zeros(), |c, p| c + Vector3::from(*p)) / n as f64;
        let material: Vec<Vector3<f64>> = pattern
            .positions_m
            .iter()
            .map(|p| Vector3::from(*p) - Vector3::new(centre.x, centre.y, 0.0))
            .collect();
        let at = |vertex: u32, image: [i32; 2]| Instance { vertex, image };
        let mut stretch =
            vec![StretchElement { from: at(0, [0, 0]), to: at(0, [0, 0]), rest_length_m: 0.0 }; n];
        let mut incoming = vec![(0u32, [0i32; 2]); n];
        let mut outgoing = vec![(0u32, [0i32; 2]); n];
        for e in pattern.edges() {
            stretch[e.from as usize] = StretchElement {
                from: at(e.from, [0, 0]),
                to: at(e.to, e.offset),
                rest_length_m: rest.edge_length_m[e.from as usize],
            };
            outgoing[e.from as usize] = (e.to, e.offset);
            incoming[e.to as usize] = (e.from, e.offset);
        }
        let bends = (0..n)
            .map(|v| {
                let (prev, o_in) = incoming[v];
                let (next, o_out) = outgoing[v];
                let rest_sum = rest.edge_length_m[prev as usize] + rest.edge_length_m[v];
                BendElement {
                    prev: at(prev, [-o_in[0], -o_in[1]]),
                    vertex: at(v as u32, [0, 0]),
                    next: at(next, o_out),
                    element: BendTwist {
                        bend_stiffness_nm2: material_law.bend_stiffness_nm2,
                        twist_stiffness_nm2: material_law.twist_stiffness_nm2,
                        rest_curvature: rest.vertex_curvature[v],
                        rest_twist_rad: rest.vertex_twist_rad[v],
                        rest_length_sum_m: rest_sum,
                    },
                }
            })
            .collect();
        let yarns = pattern.yarns.iter().map(|y| YarnInfo { vertices: y.vertices.clone() }).collect();
        let material_tangents = (0..n)
            .map(|v| {
                let s_in = &stretch[incoming[v].0 as usize];
                let s_out = &stretch[v];
                (material_edge(&material, pattern.period_m, s_in).normalize()
                    + material_edge(&material, pattern.period_m, s_out).normalize())
                .normalize()
            })
            .collect();
        let images = contact_images(&material, pattern.period_m, contact.reach_m() * 1.5);
        Ok(RveModel {
            yarns,
            material_tangents,
            images,
            vertices: n,
            period_m: pattern.period_m,
            material,
            material_directors: rest.edge_reference_director.clone(),
            material_twists: pattern.edge_twist_rad.clone(),
            material_reference_twists: rest.vertex_reference_twist_rad.clone(),
            stretch,
            bends,
            material_law,
            contact,
            neighbours: YarnNeighbours::new(pattern),
            rest_length_m: rest.edge_length_m.clone(),
            radius_m: r_lo.min(model.radius_m),
        })
    }

    /// Number of DOFs: three per vertex, one twist per edge.
    pub fn dof_count(&self) -> usize {
        4 * self.vertices
    }

    /// Index of the first position DOF of vertex `v`.
    pub fn position_dof(&self, v: u32) -> usize {
        3 * v as usize
    }

    /// Index of the twist DOF of the edge leaving vertex `v`.
    pub fn twist_dof(&self, v: u32) -> usize {
        3 * self.vertices + v as usize
    }

    /// Tile area `P1 P2` (m²): homogenized densities are per unit undeformed area (3.22).
    pub fn area_m2(&self) -> f64 {
        self.period_m[0] * self.period_m[1]
    }

    /// Whether edge `a` of the tile and edge `b` of tile image `o` (edges by source vertex) are
    /// a contact pair: not neighbours along one yarn ([`YarnNeighbours`]) and able to touch
    /// ([`Self::can_touch`]).
    pub fn contact_pair(&self, a: usize, b: usize, o: [i32; 2]) -> bool {
        !self.neighbours.are_neighbours(a as u32, b as u32, o) && self.can_touch(a, b, o)
    }

    /// Whether edge `a` of the tile and edge `b` of tile image `o` can touch: their pieces lie
    /// within contact reach plus the smaller period in the material configuration (the period
    /// is room for yarns to slide past each other). Pieces farther apart in the fabric meet
    /// only where the macro deformation brings the fabric round onto itself: bent to curvature
    /// `κ`, the tile's surface repeats after `2π/κ` of material length, so an image that far
    /// away lands on the tile itself (for the published stockinette's 15.1 mm period and its
    /// images two periods out, from `κ = 2π/(3 P_1) = 139 1/m` on). That is the same fabric seen
    /// again, not a second layer: contact across it is macro-scale self-contact (the shell's
    /// concern), and counting it in the tile gives the homogenized energy a spurious wall.
    pub fn can_touch(&self, a: usize, b: usize, o: [i32; 2]) -> bool {
        let offset =
            Vector3::new(f64::from(o[0]) * self.period_m[0], f64::from(o[1]) * self.period_m[1], 0.0);
        let segment = |e: usize, shift: Vector3<f64>| {
            let s = &self.stretch[e];
            let start = self.material[s.from.vertex as usize] + shift;
            (start, start + material_edge(&self.material, self.period_m, s))
        };
        let (a0, a1) = segment(a, Vector3::zeros());
        let (b0, b1) = segment(b, offset);
        let slack = self.period_m[0].min(self.period_m[1]);
        segment_distance(&a0, &a1, &b0, &b1).distance <= self.contact.reach_m() + slack
    }
}

/// The vector of a stretch element's edge in the material configuration.
pub fn material_edge(material: &[Vector3<f64>], period_m: [f64; 2], s: &StretchElement) -> Vector3<f64> {
    let offset = |i: Instance| {
        Vector3::new(f64::from(i.image[0]) * period_m[0], f64::from(i.image[1]) * period_m[1], 0.0)
    };
    material[s.to.vertex as usize] + offset(s.to) - material[s.from.vertex as usize] - offset(s.from)
}

/// Image offsets `o` for which some edge of the tile image `o` may come within `reach` of an
/// edge of the tile: `|o_k| P_k <= extent_k + reach` (extent of the undeformed yarns; the
/// margin covers moderate deformation).
fn contact_images(material: &[Vector3<f64>], period_m: [f64; 2], reach: f64) -> Vec<[i32; 2]> {
    let range = |k: usize| {
        let (lo, hi) =
            material.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| (a.min(p[k]), b.max(p[k])));
        ((hi - lo + reach) / period_m[k]).ceil() as i32
    };
    let (rx, ry) = (range(0), range(1));
    (-rx..=rx).flat_map(|i| (-ry..=ry).map(move |j| [i, j])).collect()
}
