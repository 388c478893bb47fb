//! Energy, gradient and Hessian of the tile over its DOFs `g` (positions then twists).
//!
//! Every element is evaluated on world positions of vertex instances; derivatives are pulled
//! back to the tile DOFs through `x = ... + R(X) g`: `∇_g = Rᵀ ∇_x`, `H_gg' = Rᵀ H_xx' R'`.

use nalgebra::{DVector, Matrix3, Vector3};
use yarnhom_geom::segment_distance;
use yarnhom_pattern::min_distance::lower_bound;
use yarnhom_rod::{
    BendTwistDofs, BendTwistReference, EdgeFrame, contact_energy, contact_energy_only, curvature_and_twist,
    stretch_energy,
};

use crate::broadphase::{Aabb, EdgePair};
use crate::model::{BendElement, RveModel, material_edge};
use crate::placement::{Instance, Placement};

/// Energy (J), gradient and Hessian triplets `(row, column, value)` (duplicates summed).
#[derive(Debug, Clone)]
pub struct Assembled {
    /// Total energy of the tile (J).
    pub energy_j: f64,
    /// Gradient over the DOFs.
    pub gradient: DVector<f64>,
    /// Hessian triplets; empty when only the energy was asked for.
    pub hessian: Vec<(usize, usize, f64)>,
}

/// What to assemble.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Want {
    /// Energy only (line searches, stress); the gradient is left zero.
    Energy,
    /// Energy and gradient.
    EnergyGradient,
    /// Energy, gradient and Hessian.
    Derivatives,
    /// Energy, gradient and the Hessian's lower triangle (`row >= column`): all that a
    /// symmetric factorization reads ([`yarnhom_sparse::SpdSolver`]), in half the triplets.
    DerivativesLower,
}

impl Want {
    /// Whether the Hessian is wanted (whole or its lower triangle).
    fn hessian(self) -> bool {
        matches!(self, Want::Derivatives | Want::DerivativesLower)
    }
}

/// The iterate of a tile solve: DOFs and the reference frames they are measured against.
#[derive(Debug, Clone)]
pub struct RveState {
    /// DOFs: unrotated fluctuations `g = Rᵀũ` (3 per vertex), then edge twists.
    pub g: DVector<f64>,
    /// Frame of each edge (by source vertex) at its tile instance, in world coordinates.
    pub frames: Vec<EdgeFrame>,
    /// Reference twist of each bend element at the last frame update (rad).
    pub reference_twists: Vec<f64>,
}

impl RveState {
    /// The affine start (A.2.3, "initial guess"): zero fluctuation, so the tile is deformed
    /// rigidly by the macro strain; edge twists as in the pattern; reference frames co-rotated
    /// (3.26) and parallel transported onto the deformed edges.
    pub fn affine(model: &RveModel, placement: &Placement) -> Self {
        let mut g = DVector::zeros(model.dof_count());
        for (v, &theta) in model.material_twists.iter().enumerate() {
            g[model.twist_dof(v as u32)] = theta;
        }
        let frames = model
            .stretch
            .iter()
            .map(|s| {
                let v = s.from.vertex as usize;
                let r = placement.rotation(s.from);
                let flat = EdgeFrame::new(
                    material_edge(&model.material, model.period_m, s).into(),
                    model.material_directors[v],
                );
                let rotate = |a: [f64; 3]| (r * Vector3::from(a)).into();
                let corotated = EdgeFrame { tangent: rotate(flat.tangent), director: rotate(flat.director) };
                corotated.updated(world_edge(model, placement, &g, s.from, s.to).into())
            })
            .collect();
        let mut state = RveState { g, frames, reference_twists: model.material_reference_twists.clone() };
        state.reference_twists = reference_twists(model, placement, &state);
        state
    }

    /// Move the reference frames onto the current configuration (time-parallel transport) and
    /// record the reference twists there; call after every accepted step.
    pub fn update_frames(&mut self, model: &RveModel, placement: &Placement) {
        self.frames = model
            .stretch
            .iter()
            .zip(&self.frames)
            .map(|(s, f)| f.updated(world_edge(model, placement, &self.g, s.from, s.to).into()))
            .collect();
        self.reference_twists = reference_twists(model, placement, self);
    }
}

fn position_of(model: &RveModel, placement: &Placement, g: &DVector<f64>, i: Instance) -> Vector3<f64> {
    let k = model.position_dof(i.vertex);
    placement.position(i, &Vector3::new(g[k], g[k + 1], g[k + 2]))
}

fn world_edge(
    model: &RveModel,
    placement: &Placement,
    g: &DVector<f64>,
    a: Instance,
    b: Instance,
) -> Vector3<f64> {
    position_of(model, placement, g, b) - position_of(model, placement, g, a)
}

/// The frame of the edge leaving `source` in tile image `image`: the stored frame co-rotated
/// by `R(image) R(tile)ᵀ`, with `R` taken at the edge's first vertex (A.21).
fn frame_in_image(placement: &Placement, state: &RveState, source: u32, image: [i32; 2]) -> EdgeFrame {
    let f = state.frames[source as usize];
    if image == [0, 0] {
        return f;
    }
    let q: Matrix3<f64> = placement.rotation(Instance { vertex: source, image })
        * placement.rotation(Instance { vertex: source, image: [0, 0] }).transpose();
    let rotate = |a: [f64; 3]| (q * Vector3::from(a)).into();
    EdgeFrame { tangent: rotate(f.tangent), director: rotate(f.director) }
}

fn bend_reference(
    placement: &Placement,
    state: &RveState,
    b: &BendElement,
    index: usize,
) -> BendTwistReference {
    BendTwistReference {
        frames: [
            frame_in_image(placement, state, b.prev.vertex, b.prev.image),
            state.frames[b.vertex.vertex as usize],
        ],
        reference_twist_rad: state.reference_twists[index],
    }
}

fn bend_dofs(model: &RveModel, placement: &Placement, g: &DVector<f64>, b: &BendElement) -> BendTwistDofs {
    let [p, v, n] = [b.prev, b.vertex, b.next].map(|i| position_of(model, placement, g, i));
    let (t_in, t_out) = (g[model.twist_dof(b.prev.vertex)], g[model.twist_dof(b.vertex.vertex)]);
    BendTwistDofs::from_column_slice(&[p.x, p.y, p.z, v.x, v.y, v.z, n.x, n.y, n.z, t_in, t_out])
}

fn reference_twists(model: &RveModel, placement: &Placement, state: &RveState) -> Vec<f64> {
    model
        .bends
        .iter()
        .enumerate()
        .map(|(k, b)| {
            let reference = bend_reference(placement, state, b, k);
            let q = bend_dofs(model, placement, &state.g, b);
            let (_, twist) = curvature_and_twist(&reference, &std::array::from_fn(|i| q[i]));
            twist - (q[10] - q[9])
        })
        .collect()
}

/// Pull an element's derivatives back to the tile DOFs and add them in, block by block:
/// position blocks are rotated by the instances' `R` (`∇_g = Rᵀ ∇_x`, `H_gg' = Rᵀ H R'`),
/// twist entries pass through. No allocation beyond the Hessian triplets.
struct Scatter<'a> {
    model: &'a RveModel,
    placement: &'a Placement,
    out: &'a mut Assembled,
    /// Keep only the Hessian's lower triangle.
    lower: bool,
}

impl Scatter<'_> {
    /// `instances`: the element's vertices (3 local DOFs each, first; at most 4); `twists`: the
    /// source vertices of its twisted edges (1 local DOF each, after the positions); `h`: the
    /// local Hessian, column-major.
    fn add(&mut self, instances: &[Instance], twists: &[u32], g: &[f64], h: Option<&[f64]>) {
        let np = instances.len();
        let k = 3 * np + twists.len();
        let mut rotation = [Matrix3::identity(); 4];
        let mut base = [0usize; 4];
        for (i, inst) in instances.iter().enumerate() {
            rotation[i] = self.placement.rotation(*inst);
            base[i] = self.model.position_dof(inst.vertex);
            let local = rotation[i].transpose() * Vector3::new(g[3 * i], g[3 * i + 1], g[3 * i + 2]);
            for c in 0..3 {
                self.out.gradient[base[i] + c] += local[c];
            }
        }
        let twist_index = |t: usize| self.model.twist_dof(twists[t]);
        for (t, &value) in g[3 * np..].iter().enumerate() {
            self.out.gradient[twist_index(t)] += value;
        }
        let Some(h) = h else { return };
        let at = |row: usize, col: usize| h[col * k + row];
        let block = |i: usize, j: usize| Matrix3::from_fn(|r, c| at(3 * i + r, 3 * j + c));
        let lower = self.lower;
        let hessian = &mut self.out.hessian;
        let mut push = |row: usize, col: usize, value: f64| {
            if !lower || row >= col {
                hessian.push((row, col, value));
            }
        };
        for i in 0..np {
            for j in 0..np {
                if lower && base[j] > base[i] + 2 {
                    // Above the diagonal.
                    continue;
                }
                let pulled = rotation[i].transpose() * block(i, j) * rotation[j];
                for r in 0..3 {
                    for c in 0..3 {
                        push(base[i] + r, base[j] + c, pulled[(r, c)]);
                    }
                }
            }
            for t in 0..twists.len() {
                let column = rotation[i].transpose()
                    * Vector3::new(
                        at(3 * i, 3 * np + t),
                        at(3 * i + 1, 3 * np + t),
                        at(3 * i + 2, 3 * np + t),
                    );
                for r in 0..3 {
                    push(base[i] + r, twist_index(t), column[r]);
                    push(twist_index(t), base[i] + r, column[r]);
                }
            }
        }
        for t in 0..twists.len() {
            for u in 0..twists.len() {
                push(twist_index(t), twist_index(u), at(3 * np + t, 3 * np + u));
            }
        }
    }
}

/// Assemble the tile's energy (and derivatives) at DOFs `g`, measured against `state`'s frames.
pub fn assemble(
    model: &RveModel,
    placement: &Placement,
    state: &RveState,
    g: &DVector<f64>,
    want: Want,
) -> Assembled {
    let candidates = ContactCandidates::new(model, placement, g, 0.0);
    assemble_with(model, placement, state, g, want, &candidates)
}

/// [`assemble`] with the contact pairs taken from `candidates`, which must cover `g`
/// ([`ContactCandidates::cover`]): the same result, without a broad phase of its own.
pub fn assemble_with(
    model: &RveModel,
    placement: &Placement,
    state: &RveState,
    g: &DVector<f64>,
    want: Want,
    candidates: &ContactCandidates,
) -> Assembled {
    let mut out =
        Assembled { energy_j: 0.0, gradient: DVector::zeros(model.dof_count()), hessian: Vec::new() };
    let derivatives = want.hessian();
    let lower = want == Want::DerivativesLower;
    if derivatives {
        out.hessian.reserve(hessian_capacity(model, candidates.pairs.len()));
    }
    let position = |i: Instance| position_of(model, placement, g, i);
    for s in &model.stretch {
        let (e, grad, hess) =
            stretch_energy(&model.material_law.stretch, s.rest_length_m, &position(s.from), &position(s.to));
        out.energy_j += e;
        if want != Want::Energy {
            let h = derivatives.then_some(hess.as_slice());
            Scatter { model, placement, out: &mut out, lower }.add(&[s.from, s.to], &[], grad.as_slice(), h);
        }
    }
    for (k, b) in model.bends.iter().enumerate() {
        let reference = bend_reference(placement, state, b, k);
        let q = bend_dofs(model, placement, g, b);
        let twists = [b.prev.vertex, b.vertex.vertex];
        if want != Want::Energy {
            let (e, grad, hess) = b.element.energy_gradient_hessian(&reference, &q);
            out.energy_j += e;
            let h = derivatives.then_some(hess.as_slice());
            Scatter { model, placement, out: &mut out, lower }.add(
                &[b.prev, b.vertex, b.next],
                &twists,
                grad.as_slice(),
                h,
            );
        } else {
            out.energy_j += b.element.energy(&reference, &q);
        }
    }
    add_contacts(model, placement, g, want, candidates, &mut out);
    out
}

/// Hessian triplets of the stretch and bend elements and of `pairs` contacts at most.
fn hessian_capacity(model: &RveModel, pairs: usize) -> usize {
    // Stretch: 2 vertices; bend: 3 vertices and 2 twists; contact: 4 vertices.
    let dense = |dofs: usize| dofs * dofs;
    model.stretch.len() * dense(6) + model.bends.len() * dense(11) + pairs * dense(12)
}

/// The edge pairs that may come within contact reach while no vertex instance moves more than
/// an allowance from where they were found (a Verlet list): the broad phase
/// ([`crate::broadphase`]) on the edges' boxes grown by half the reach plus the allowance. Each
/// edge's box after such moves lies in its grown box, so every pair within reach then is a
/// candidate.
#[derive(Debug, Clone)]
pub struct ContactCandidates {
    /// DOFs the pairs were found at.
    g: DVector<f64>,
    /// The edges' ends there, as `[image][edge]` ([`image_segments`]).
    ends: Vec<Vec<(Vector3<f64>, Vector3<f64>)>>,
    /// Largest move of a vertex instance they allow (m).
    allowance: f64,
    /// The candidate pairs, sorted.
    pairs: Vec<EdgePair>,
    /// The image edges `(image, edge)` of the pairs, each once: `pairs[k]`'s is
    /// `image_edges[image_edge[k]]`.
    image_edges: Vec<(usize, usize)>,
    image_edge: Vec<usize>,
}

impl ContactCandidates {
    /// The candidates at DOFs `g` under `placement` for moves up to `allowance` (m).
    pub fn new(model: &RveModel, placement: &Placement, g: &DVector<f64>, allowance: f64) -> Self {
        // The relative 1e-9 keeps pairs whose quadrature points round to just within reach.
        let margin = 0.5 * model.contact.reach_m() * (1.0 + 1e-9) + allowance;
        let ends = image_segments(model, placement, g);
        let boxes: Vec<Vec<Aabb>> = ends
            .iter()
            .map(|e| e.iter().map(|(p, q)| Aabb::around_segment(p, q, margin)).collect())
            .collect();
        let pairs = crate::broadphase::edge_pairs(model, &boxes);
        let mut slot = vec![usize::MAX; model.images.len() * model.stretch.len()];
        let mut image_edges = Vec::new();
        let image_edge = pairs
            .iter()
            .map(|p| {
                let k = &mut slot[p.image * model.stretch.len() + p.b];
                if *k == usize::MAX {
                    *k = image_edges.len();
                    image_edges.push((p.image, p.b));
                }
                *k
            })
            .collect();
        ContactCandidates { g: g.clone(), ends, allowance, pairs, image_edges, image_edge }
    }

    /// Whether the candidates hold at DOFs `g` under the placement they were found in: no
    /// vertex moved more than the allowance (an instance moves by `|R Δg_v| = |Δg_v|`).
    pub fn cover(&self, model: &RveModel, g: &DVector<f64>) -> bool {
        (0..model.vertices as u32).all(|v| {
            let k = model.position_dof(v);
            let moved = Vector3::new(g[k] - self.g[k], g[k + 1] - self.g[k + 1], g[k + 2] - self.g[k + 2]);
            moved.norm() <= self.allowance
        })
    }

    /// Whether the candidates hold at DOFs `g` under another `placement` (a nearby strain): no
    /// edge end in any image moved more than the allowance.
    pub fn cover_placed(&self, model: &RveModel, placement: &Placement, g: &DVector<f64>) -> bool {
        let within = |(p, q): &(Vector3<f64>, Vector3<f64>), (p0, q0): &(Vector3<f64>, Vector3<f64>)| {
            (p - p0).norm() <= self.allowance && (q - q0).norm() <= self.allowance
        };
        image_segments(model, placement, g)
            .iter()
            .zip(&self.ends)
            .all(|(now, then)| now.iter().zip(then).all(|(a, b)| within(a, b)))
    }
}

/// Contact (Sec. 3.3) between every edge of the tile and every edge of the tile images within
/// reach ([`RveModel::images`]), each physical pair once, neighbours along a yarn excluded: the
/// pairs of `candidates` whose segments come within reach, summed in sorted order, so the
/// result is reproducible (and the same for every covering set of candidates).
fn add_contacts(
    model: &RveModel,
    placement: &Placement,
    g: &DVector<f64>,
    want: Want,
    candidates: &ContactCandidates,
    out: &mut Assembled,
) {
    let reach = model.contact.reach_m();
    let segment = |i: Instance, j: Instance, o: [i32; 2]| {
        (position_of(model, placement, g, shifted(i, o)), position_of(model, placement, g, shifted(j, o)))
    };
    let tile: Vec<_> = model.stretch.iter().map(|s| segment(s.from, s.to, [0, 0])).collect();
    let images: Vec<_> = candidates
        .image_edges
        .iter()
        .map(|&(image, b)| segment(model.stretch[b].from, model.stretch[b].to, model.images[image]))
        .collect();
    for (&EdgePair { a, image, b }, &k) in candidates.pairs.iter().zip(&candidates.image_edge) {
        let (a0, a1) = tile[a];
        let (b0, b1) = images[k];
        if lower_bound(&a0, &a1, &b0, &b1) >= reach {
            continue;
        }
        let (ends, rest) = ([&a0, &a1, &b0, &b1], (model.rest_length_m[a], model.rest_length_m[b]));
        if want == Want::Energy {
            out.energy_j += contact_energy_only(&model.contact, ends, rest.0, rest.1);
            continue;
        }
        let (e, grad, hess) = contact_energy(&model.contact, ends, rest.0, rest.1);
        if e == 0.0 && grad.amax() == 0.0 {
            continue;
        }
        out.energy_j += e;
        let h = want.hessian().then_some(hess.as_slice());
        let (sa, sb, o) = (model.stretch[a], model.stretch[b], model.images[image]);
        let instances = [sa.from, sa.to, shifted(sb.from, o), shifted(sb.to, o)];
        let lower = want == Want::DerivativesLower;
        Scatter { model, placement, out: &mut *out, lower }.add(&instances, &[], grad.as_slice(), h);
    }
}

/// The smallest centreline distance (m) between two yarn pieces of the tile and its images at
/// `state` (neighbours along a yarn excluded, as in contact), among the pairs within contact
/// reach; `None` when no pair is within reach. Touching yarns of radius `R` are `2R` apart; a
/// distance below `R` puts a centreline inside another yarn (the tile self-intersects).
pub fn min_separation(model: &RveModel, placement: &Placement, state: &RveState) -> Option<f64> {
    let candidates = ContactCandidates::new(model, placement, &state.g, 0.0);
    let position = |i: Instance, o: [i32; 2]| position_of(model, placement, &state.g, shifted(i, o));
    candidates
        .pairs
        .iter()
        .map(|&EdgePair { a, image, b }| {
            let (sa, sb, o) = (model.stretch[a], model.stretch[b], model.images[image]);
            let (a0, a1) = (position(sa.from, [0, 0]), position(sa.to, [0, 0]));
            let (b0, b1) = (position(sb.from, o), position(sb.to, o));
            segment_distance(&a0, &a1, &b0, &b1).distance
        })
        .filter(|d| *d < model.contact.reach_m())
        .min_by(f64::total_cmp)
}

/// The instance `i` moved by the tile offset `o`.
fn shifted(i: Instance, o: [i32; 2]) -> Instance {
    Instance { vertex: i.vertex, image: [i.image[0] + o[0], i.image[1] + o[1]] }
}

/// Endpoints of every edge in every contact image ([`RveModel::images`]) at DOFs `g`, as
/// `[image][edge]`.
pub fn image_segments(
    model: &RveModel,
    placement: &Placement,
    g: &DVector<f64>,
) -> Vec<Vec<(Vector3<f64>, Vector3<f64>)>> {
    let position = |i: Instance, o: [i32; 2]| position_of(model, placement, g, shifted(i, o));
    model
        .images
        .iter()
        .map(|&o| model.stretch.iter().map(|s| (position(s.from, o), position(s.to, o))).collect())
        .collect()
}

/// Energy of every bend-twist element (J), in vertex order: where a tile stores bending.
pub fn bend_energies(model: &RveModel, placement: &Placement, state: &RveState) -> Vec<f64> {
    model
        .bends
        .iter()
        .enumerate()
        .map(|(k, b)| {
            b.element
                .energy(&bend_reference(placement, state, b, k), &bend_dofs(model, placement, &state.g, b))
        })
        .collect()
}

/// Material curvature `(κ1, κ2)` and twist `m` (rad) of every bend-twist element, in vertex
/// order: the values a rest-shape reset stores (Alg. 2, Sec. 6.5.2).
pub fn bend_strains(model: &RveModel, placement: &Placement, state: &RveState) -> Vec<([f64; 2], f64)> {
    model
        .bends
        .iter()
        .enumerate()
        .map(|(k, b)| {
            let q = bend_dofs(model, placement, &state.g, b);
            curvature_and_twist(&bend_reference(placement, state, b, k), &std::array::from_fn(|i| q[i]))
        })
        .collect()
}

/// Length of every edge (m), by source vertex, at the state's DOFs.
pub fn edge_lengths(model: &RveModel, placement: &Placement, state: &RveState) -> Vec<f64> {
    model.stretch.iter().map(|s| world_edge(model, placement, &state.g, s.from, s.to).norm()).collect()
}

/// World positions of the tile's vertices at the state's DOFs.
pub fn world_positions(model: &RveModel, placement: &Placement, state: &RveState) -> Vec<[f64; 3]> {
    (0..model.vertices as u32)
        .map(|v| position_of(model, placement, &state.g, Instance { vertex: v, image: [0, 0] }).into())
        .collect()
}
