//! The scene as a whole: its public description ([`Scene`]) and the system built from it, with
//! the layout of the DOFs `q = (x_0 .. x_{N-1}, θ_0 .. θ_{E-1})`: all yarns' vertex positions
//! (yarn after yarn), then all their edge twists.

use nalgebra::{DVector, Vector3};
use yarnhom_rod::{ContactLaw, Rod};

use super::contact::{CandidateList, ContactTopology};
use super::damping::{Damping, yarn_windows};
use super::handles::Handle;
use yarnhom_artifacts::GlueSpring;

use super::input::{InputError, YarnInput, non_negative, positive};
use super::obstacles::Obstacle;
use super::wind::YarnWind;

/// How yarns repel each other.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ContactModel {
    /// No yarn-yarn contact (yarns pass through each other).
    Off,
    /// Kaldor et al. (2008) ([`ContactLaw::Kaldor`]) with this stiffness (N/m) and the largest
    /// yarn radius of the scene.
    Kaldor {
        /// `k_contact` (N/m).
        stiffness_n_m: f64,
    },
    /// Any law of `yarnhom-rod`.
    Law(ContactLaw),
}

/// Settings of the Newton solve of every step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverOptions {
    /// Newton iterations per step at most.
    pub max_newton_iterations: usize,
    /// Convergence: the Newton step (the gradient scaled by the inverse Hessian) moves no free
    /// vertex more than `tolerance` yarn radii and no twist more than `tolerance` rad; where the
    /// Hessian needed a shift, the gradient scaled by the inertia and twist stiffness instead
    /// (`|∇_v Φ| h² / m_v` and `|∂Φ/∂θ_e| / k_e`, the step of those alone).
    pub tolerance: f64,
    /// Margin of the broad phase beyond the contact law's reach, in yarn radii: pairs are
    /// candidates within `reach + margin`, and no Newton step moves a vertex further than
    /// `margin / 2`.
    pub broad_phase_margin_radii: f64,
    /// Halvings of the step in one line search at most.
    pub max_line_search_cuts: usize,
}

impl Default for SolverOptions {
    fn default() -> Self {
        SolverOptions {
            max_newton_iterations: 100,
            tolerance: 1e-6,
            broad_phase_margin_radii: 2.0,
            max_line_search_cuts: 40,
        }
    }
}

/// Everything a simulation starts from.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// The yarns, their vertices numbered yarn after yarn (global vertex indices).
    pub yarns: Vec<YarnInput>,
    /// Springs between vertices (global indices: the yarns' vertices one after the other), of
    /// energy `k (|x_a - x_b| - L)² / 2`: they hold the cut yarn ends of a swatch together.
    pub glue: Vec<GlueSpring>,
    /// Yarn-yarn contact.
    pub contact: ContactModel,
    /// Gravitational acceleration (m/s²).
    pub gravity_m_s2: [f64; 3],
    /// Rigid obstacles.
    pub obstacles: Vec<Obstacle>,
    /// Vertices moved by prescribed translations.
    pub handles: Vec<Handle>,
    /// Damping of non-rigid motion, if any.
    pub damping: Option<Damping>,
    /// Air drag, if any.
    pub wind: Option<YarnWind>,
    /// Newton solver settings.
    pub solver: SolverOptions,
}

impl Scene {
    /// The yarns with nothing else: no glue, contact, gravity, obstacles, handles or damping.
    pub fn new(yarns: Vec<YarnInput>) -> Scene {
        Scene {
            yarns,
            glue: vec![],
            contact: ContactModel::Off,
            gravity_m_s2: [0.0; 3],
            obstacles: vec![],
            handles: vec![],
            damping: None,
            wind: None,
            solver: SolverOptions::default(),
        }
    }
}

/// Weight of the proximal term that fixes the twists' gauge, relative to the stiffness
/// `max(β, α₁, α₂) / L̄` of each edge (see [`System::twist_anchor`]).
const TWIST_GAUGE: f64 = 1e-9;

/// The scene, validated and laid out over the DOFs.
pub(crate) struct System {
    /// One rod per yarn (their reference frames move with the accepted steps).
    pub rods: Vec<Rod>,
    /// First global vertex of every yarn, and the number of vertices at the end.
    pub vertex_offsets: Vec<usize>,
    /// First global edge of every yarn, and the number of edges at the end.
    pub edge_offsets: Vec<usize>,
    /// Every segment: its two global vertices and its rest length (m).
    pub segments: Vec<(usize, usize, f64)>,
    /// Air drag, if any.
    pub wind: Option<YarnWind>,
    /// Lumped mass of every vertex (kg): linear density times half the adjacent rest lengths.
    pub masses_kg: Vec<f64>,
    /// Radius of every vertex's yarn (m).
    pub vertex_radius_m: Vec<f64>,
    /// The largest yarn radius (m): the unit of distances in reports and tolerances.
    pub radius_m: f64,
    /// Per edge, the stiffness scale `k_e = max(β, α₁, α₂) / L̄_e` of its twist (N m/rad).
    pub twist_scale_nm: Vec<f64>,
    /// Per edge, the weight `w_e` of the proximal term `w_e (θ_e - θ_e,n)² / 2` of a step:
    /// `10⁻⁹ k_e`. Twists have no inertia; with isotropic bending the energy is invariant under
    /// turning all twists of a yarn together, and this term (a billionth of the twist
    /// stiffness) picks that gauge, so the Hessian stays regular.
    pub twist_anchor: Vec<f64>,
    pub glue: Vec<GlueSpring>,
    pub obstacles: Vec<Obstacle>,
    pub contact: Option<ContactLaw>,
    pub topology: ContactTopology,
    pub gravity: Vector3<f64>,
    pub handles: Vec<Handle>,
    /// Per held vertex: the vertex, its handle and its initial position.
    pub held: Vec<(usize, usize, Vector3<f64>)>,
    /// Reduced (solve) index of every DOF, `None` for held positions.
    pub free_index: Vec<Option<usize>>,
    /// Number of free DOFs.
    pub free_count: usize,
    /// The damping and its windows (global vertex lists).
    pub damping: Option<(Damping, Vec<Vec<usize>>)>,
    pub options: SolverOptions,
}

impl System {
    /// Validate `scene` and lay it out.
    pub(crate) fn new(scene: &Scene) -> Result<System, InputError> {
        for (y, yarn) in scene.yarns.iter().enumerate() {
            yarn.validate(y)?;
        }
        let mut vertex_offsets = vec![0];
        let mut edge_offsets = vec![0];
        for yarn in &scene.yarns {
            vertex_offsets.push(vertex_offsets[vertex_offsets.len() - 1] + yarn.vertex_count());
            edge_offsets.push(edge_offsets[edge_offsets.len() - 1] + yarn.edge_count());
        }
        let vertices = vertex_offsets[scene.yarns.len()];
        let mut masses_kg = vec![0.0; vertices];
        let mut vertex_radius_m = vec![0.0; vertices];
        let mut twist_scale_nm = vec![];
        let mut segments = vec![];
        for (y, yarn) in scene.yarns.iter().enumerate() {
            let first = vertex_offsets[y];
            let n = yarn.vertex_count();
            for (e, &rest) in yarn.rest_length_m.iter().enumerate() {
                segments.push((first + e, first + (e + 1) % n, rest));
                for v in [e, (e + 1) % n] {
                    masses_kg[first + v] += 0.5 * rest * yarn.linear_density_kg_m;
                }
                let m = yarn.material;
                let stiffness =
                    m.twist_stiffness_nm2.max(m.bend_stiffness_nm2[0]).max(m.bend_stiffness_nm2[1]);
                twist_scale_nm.push(stiffness / rest);
            }
            vertex_radius_m[first..first + n].fill(yarn.radius_m);
        }
        let radius_m = scene.yarns.iter().map(|y| y.radius_m).fold(0.0, f64::max);
        validate_glue(&scene.glue, vertices)?;
        validate_obstacles(&scene.obstacles)?;
        let held = held_vertices(scene, vertices)?;
        let contact = contact_law(scene.contact, radius_m)?;
        validate_options(&scene.solver)?;
        if let Some(w) = &scene.wind {
            validate_wind(w)?;
        }
        if !scene.gravity_m_s2.iter().all(|g| g.is_finite()) {
            return Err(InputError::Parameter { what: "gravity".into(), range: "finite", value: f64::NAN });
        }
        let damping = match scene.damping {
            Some(d) => {
                d.validate()?;
                let windows = scene
                    .yarns
                    .iter()
                    .enumerate()
                    .flat_map(|(y, yarn)| {
                        yarn_windows(vertex_offsets[y], yarn.vertex_count(), yarn.closed, d.window_vertices)
                    })
                    .collect();
                Some((d, windows))
            }
            None => None,
        };
        let dofs = 3 * vertices + edge_offsets[scene.yarns.len()];
        let mut is_held = vec![false; dofs];
        for &(v, _, _) in &held {
            is_held[3 * v..3 * v + 3].fill(true);
        }
        let mut free_count = 0;
        let free_index = is_held
            .iter()
            .map(|&h| {
                (!h).then(|| {
                    free_count += 1;
                    free_count - 1
                })
            })
            .collect();
        let yarn_layout: Vec<(usize, usize, bool, &[f64])> = scene
            .yarns
            .iter()
            .enumerate()
            .map(|(y, yarn)| {
                (vertex_offsets[y], yarn.vertex_count(), yarn.closed, yarn.rest_length_m.as_slice())
            })
            .collect();
        let glued: Vec<(usize, usize)> =
            scene.glue.iter().map(|g| (g.vertices[0] as usize, g.vertices[1] as usize)).collect();
        Ok(System {
            rods: scene.yarns.iter().map(YarnInput::rod).collect(),
            vertex_offsets,
            edge_offsets,
            segments,
            wind: scene.wind,
            masses_kg,
            vertex_radius_m,
            radius_m,
            twist_anchor: twist_scale_nm.iter().map(|k| TWIST_GAUGE * k).collect(),
            twist_scale_nm,
            glue: scene.glue.clone(),
            obstacles: scene.obstacles.clone(),
            contact,
            topology: ContactTopology::new(&yarn_layout, &glued),
            gravity: Vector3::from(scene.gravity_m_s2),
            handles: scene.handles.clone(),
            held,
            free_index,
            free_count,
            damping,
            options: scene.solver,
        })
    }

    /// Number of vertices.
    pub(crate) fn vertex_count(&self) -> usize {
        self.vertex_offsets[self.vertex_offsets.len() - 1]
    }

    /// Number of DOFs.
    pub(crate) fn dof_count(&self) -> usize {
        3 * self.vertex_count() + self.edge_offsets[self.edge_offsets.len() - 1]
    }

    /// The global DOF of every local DOF of yarn `y`'s rod (positions, then twists).
    pub(crate) fn rod_dofs(&self, y: usize) -> Vec<usize> {
        let (v0, v1) = (self.vertex_offsets[y], self.vertex_offsets[y + 1]);
        let (e0, e1) = (self.edge_offsets[y], self.edge_offsets[y + 1]);
        let twists = 3 * self.vertex_count();
        (3 * v0..3 * v1).chain(twists + e0..twists + e1).collect()
    }

    /// The DOFs of yarn `y`'s rod, taken from the global `q`.
    pub(crate) fn rod_q(&self, y: usize, q: &DVector<f64>) -> DVector<f64> {
        DVector::from_iterator(self.rod_dofs(y).len(), self.rod_dofs(y).into_iter().map(|i| q[i]))
    }

    /// Position of vertex `v`.
    pub(crate) fn position(q: &DVector<f64>, v: usize) -> Vector3<f64> {
        Vector3::new(q[3 * v], q[3 * v + 1], q[3 * v + 2])
    }

    /// The broad-phase radius `reach + margin` and the margin (m), without contact `None`.
    pub(crate) fn broad_phase_m(&self) -> Option<(f64, f64)> {
        self.contact.map(|law| (law.reach_m() + self.margin_m(), self.margin_m()))
    }

    /// The candidate contact pairs at `q` ([`CandidateList`]).
    pub(crate) fn candidate_list(&self, q: &DVector<f64>) -> CandidateList {
        CandidateList::new(&self.topology, &q.as_slice()[..3 * self.vertex_count()], self.broad_phase_m())
    }

    /// The broad-phase margin (m).
    pub(crate) fn margin_m(&self) -> f64 {
        self.options.broad_phase_margin_radii * self.radius_m
    }

    /// The DOFs of the initial state, from the yarns.
    pub(crate) fn initial_q(&self, scene: &Scene) -> DVector<f64> {
        let positions = scene.yarns.iter().flat_map(|y| y.positions_m.iter().flatten().copied());
        let twists = scene.yarns.iter().flat_map(|y| y.edge_twist_rad.iter().copied());
        DVector::from_iterator(self.dof_count(), positions.chain(twists))
    }

    /// Move the rods' reference frames to `q` (after an accepted step).
    pub(crate) fn update_references(&mut self, q: &DVector<f64>) {
        let local: Vec<DVector<f64>> = (0..self.rods.len()).map(|y| self.rod_q(y, q)).collect();
        for (rod, q) in self.rods.iter_mut().zip(&local) {
            rod.update_references(q);
        }
    }
}

/// Wind: finite velocity, non-negative coefficients and area.
fn validate_wind(w: &YarnWind) -> Result<(), InputError> {
    if !w.velocity_m_s.iter().all(|u| u.is_finite()) {
        return Err(InputError::Parameter { what: "wind velocity".into(), range: "finite", value: f64::NAN });
    }
    non_negative("wind density", w.density_kg_m3)?;
    non_negative("wind drag", w.drag_kg_m2_s)?;
    non_negative("wind area per yarn length", w.area_per_length_m)
}

/// Glue springs: vertices in range, stiffness and rest length finite and non-negative.
fn validate_glue(glue: &[GlueSpring], vertices: usize) -> Result<(), InputError> {
    for (i, g) in glue.iter().enumerate() {
        if let Some(vertex) = g.vertices.map(|v| v as usize).into_iter().find(|&v| v >= vertices) {
            return Err(InputError::VertexOutOfRange { what: format!("glue spring {i}"), vertex, vertices });
        }
        non_negative(&format!("stiffness of glue spring {i}"), g.stiffness_n_m)?;
        non_negative(&format!("rest length of glue spring {i}"), g.rest_length_m)?;
    }
    Ok(())
}

/// Obstacles: finite shapes, positive activation distance, non-negative stiffness.
fn validate_obstacles(obstacles: &[Obstacle]) -> Result<(), InputError> {
    use super::obstacles::ObstacleShape;
    for (i, o) in obstacles.iter().enumerate() {
        positive(&format!("activation distance of obstacle {i}"), o.activation_distance_m)?;
        non_negative(&format!("stiffness of obstacle {i}"), o.stiffness_n_m)?;
        let (numbers, size) = match o.shape {
            ObstacleShape::Plane { point_m, normal } => {
                (point_m.into_iter().chain(normal).collect::<Vec<_>>(), Vector3::from(normal).norm())
            }
            ObstacleShape::Sphere { centre_m, radius_m } => (centre_m.to_vec(), radius_m),
            ObstacleShape::Box { min_m, max_m } => {
                let thinnest = (0..3).map(|k| max_m[k] - min_m[k]).fold(f64::INFINITY, f64::min);
                (min_m.into_iter().chain(max_m).collect(), thinnest)
            }
        };
        if !numbers.iter().all(|x| x.is_finite()) {
            return Err(InputError::Parameter {
                what: format!("obstacle {i}"),
                range: "finite",
                value: f64::NAN,
            });
        }
        positive(&format!("size of obstacle {i} (normal length, radius or box side)"), size)?;
    }
    Ok(())
}

/// The held vertices `(vertex, handle, initial position)` in handle order, after checking the
/// handles.
fn held_vertices(scene: &Scene, vertices: usize) -> Result<Vec<(usize, usize, Vector3<f64>)>, InputError> {
    let positions: Vec<[f64; 3]> = scene.yarns.iter().flat_map(|y| y.positions_m.iter().copied()).collect();
    let mut seen = vec![false; vertices];
    let mut held = vec![];
    for (h, handle) in scene.handles.iter().enumerate() {
        handle.validate(h, vertices)?;
        for &v in &handle.vertices {
            if std::mem::replace(&mut seen[v], true) {
                return Err(InputError::VertexInTwoHandles { vertex: v });
            }
            held.push((v, h, Vector3::from(positions[v])));
        }
    }
    Ok(held)
}

/// The contact law of `model`, checked.
fn contact_law(model: ContactModel, radius_m: f64) -> Result<Option<ContactLaw>, InputError> {
    match model {
        ContactModel::Off => Ok(None),
        ContactModel::Kaldor { stiffness_n_m } => {
            non_negative("contact stiffness", stiffness_n_m)?;
            Ok(Some(ContactLaw::Kaldor { stiffness: stiffness_n_m, radius_m }))
        }
        ContactModel::Law(law) => {
            positive("contact reach", law.reach_m())?;
            Ok(Some(law))
        }
    }
}

/// Solver options in range.
fn validate_options(options: &SolverOptions) -> Result<(), InputError> {
    positive("solver tolerance", options.tolerance)?;
    positive("broad-phase margin", options.broad_phase_margin_radii)?;
    if options.max_newton_iterations == 0 {
        return Err(InputError::Parameter {
            what: "Newton iterations".into(),
            range: "at least 1",
            value: 0.0,
        });
    }
    Ok(())
}
