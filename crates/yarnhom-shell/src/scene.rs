//! Scenes: a square cloth, its handles and their motions, obstacles, time stepping and contact,
//! as a JSON file (schema in the README), as a built-in (`stretch-x`, `stretch-y`, `drape`: the
//! published 30 cm stockinette tests of `../shared/data/hylc-scenes`), or read from an
//! ARCSim-HYLC scene file directly.
//!
//! Sides of the cloth: 0 is `-x`, 1 is `-y`, 2 is `+x`, 3 is `+y` (ARCSim's handlebars: the
//! stretch-X scenes hold sides 0 and 2 and move them along `∓x`).

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::contact::{ContactSettings, Obstacle};
use crate::elastic::NewtonMatrix;
use crate::integrator::{Dynamics, Handle, Motion};
use crate::linear_solver::LinearSolver;
use crate::mesh::ShellMesh;
use crate::wind::Wind;

/// A simulation scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Name.
    pub name: String,
    /// Side lengths of the rectangular cloth along x and y (m), lying flat at z = 0 centred on
    /// the origin, material x (weft) along world x.
    pub size_m: [f64; 2],
    /// Vertices along x and y.
    pub vertices: [usize; 2],
    /// End time (s).
    pub end_time_s: f64,
    /// Time between output frames (s).
    pub frame_time_s: f64,
    /// Time steps per frame.
    pub steps_per_frame: u32,
    /// Gravity (m/s²).
    pub gravity: [f64; 3],
    /// Rayleigh mass damping `α` (1/s).
    pub mass_damping: f64,
    /// Rayleigh stiffness damping `β` (s).
    pub stiffness_damping: f64,
    /// Air drag (ARCSim's `wind`, [`crate::wind`]); none when absent.
    #[serde(default)]
    pub wind: Wind,
    /// Handles.
    pub handles: Vec<HandleSpec>,
    /// Motions: keyframes `(time_s, translation_m)` referenced by handles.
    pub motions: Vec<Vec<(f64, [f64; 3])>>,
    /// Obstacles.
    pub obstacles: Vec<Obstacle>,
    /// Contact parameters.
    pub contact: ContactSettings,
    /// Newton iterations per step at most.
    pub max_newton_iterations: u32,
    /// Newton tolerance on the position update (m).
    pub tolerance_m: f64,
    /// The element matrices of the Newton matrix (`gauss-newton`, the default, or
    /// `projected`).
    #[serde(default)]
    pub newton_matrix: NewtonMatrix,
    /// How the Newton system is solved (`auto`, the default, or `cholesky`).
    #[serde(default)]
    pub linear_solver: LinearSolver,
}

/// Which vertices a handle holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum HandleSpec {
    /// A bar along a side (ARCSim's handlebar): from `inset` to `inset + length` along the side
    /// (fractions of its length), `width` deep into the cloth (fraction of the cloth's size
    /// across the side).
    Bar {
        /// Side 0 (-x), 1 (-y), 2 (+x), 3 (+y).
        side: u8,
        /// Fraction of the side held.
        length: f64,
        /// Depth held, as a fraction of the cloth across the side.
        width: f64,
        /// Start along the side, as a fraction.
        inset: f64,
        /// Index into the motions, if it moves.
        motion: Option<usize>,
    },
    /// The vertices within a sphere (ARCSim's handlesphere), or the nearest vertex if the mesh
    /// has none inside.
    Sphere {
        /// Centre (m).
        center: [f64; 3],
        /// Radius (m).
        radius: f64,
        /// Index into the motions, if it moves.
        motion: Option<usize>,
    },
}

/// Why a scene is not usable.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// Unknown built-in.
    #[error("no built-in scene '{0}' (built-ins: stretch-x, stretch-y, drape)")]
    UnknownBuiltin(String),
    /// The file does not parse.
    #[error("{0}")]
    Parse(String),
    /// A value is out of range.
    #[error("scene '{scene}': {problem}")]
    Invalid {
        /// The scene.
        scene: String,
        /// What is wrong.
        problem: String,
    },
}

/// The built-in scene names.
pub const BUILTINS: [&str; 3] = ["stretch-x", "stretch-y", "drape"];

impl Scene {
    /// A built-in: the published stockinette stretch (`stock_stretchX.json`, `stock_stretchY.json`:
    /// bars on opposite sides, 67% long, 7% deep, 16% inset, pulled 3.5 cm each over 0.4 s, 1 s
    /// in all; stiffness damping 1 ms, air drag density 10 kg/m³) and drape (`stock_drapeX.json`:
    /// held in two 1 cm spheres at x = -10 cm, y = ±10 cm, over a 3 cm sphere 4 cm below the
    /// centre, friction 0.052, 2 s; stiffness damping 2 ms, air drag density 7.5 kg/m³). As in
    /// ARCSim, no Rayleigh mass damping ([`crate::arcsim_scene`]).
    pub fn builtin(name: &str) -> Result<Self, SceneError> {
        let base = Scene {
            name: name.into(),
            size_m: [0.3, 0.3],
            vertices: [50, 50],
            end_time_s: 1.0,
            frame_time_s: 0.0167,
            steps_per_frame: 4,
            gravity: [0.0, 0.0, -9.81],
            mass_damping: 0.0,
            stiffness_damping: 1e-3,
            wind: Wind { density_kg_m3: 10.0, ..Wind::default() },
            handles: Vec::new(),
            motions: Vec::new(),
            obstacles: Vec::new(),
            contact: ContactSettings {
                thickness_m: 2e-3,
                stiffness_n_m: 1e3,
                friction: 0.052,
                self_thickness_m: 0.0,
                self_stiffness_n_m: 0.0,
            },
            max_newton_iterations: 30,
            tolerance_m: 1e-4,
            newton_matrix: NewtonMatrix::default(),
            linear_solver: LinearSolver::default(),
        };
        let bar = |side: u8, motion: usize| HandleSpec::Bar {
            side,
            length: 0.67,
            width: 0.07,
            inset: 0.16,
            motion: Some(motion),
        };
        let pull = |d: [f64; 3]| vec![(0.0, [0.0; 3]), (0.4, d)];
        match name {
            "stretch-x" => Ok(Scene {
                handles: vec![bar(0, 0), bar(2, 1)],
                motions: vec![pull([-0.035, 0.0, 0.0]), pull([0.035, 0.0, 0.0])],
                ..base
            }),
            "stretch-y" => Ok(Scene {
                handles: vec![bar(1, 0), bar(3, 1)],
                motions: vec![pull([0.0, -0.035, 0.0]), pull([0.0, 0.035, 0.0])],
                ..base
            }),
            "drape" => Ok(Scene {
                end_time_s: 2.0,
                stiffness_damping: 2e-3,
                wind: Wind { density_kg_m3: 7.5, ..Wind::default() },
                handles: [-0.1, 0.1]
                    .map(|y| HandleSpec::Sphere { center: [-0.1, y, 0.0], radius: 0.01, motion: None })
                    .to_vec(),
                obstacles: vec![Obstacle::Sphere { center: [0.0, 0.0, -0.04], radius: 0.03 }],
                contact: ContactSettings { self_thickness_m: 6e-3, self_stiffness_n_m: 10.0, ..base.contact },
                ..base
            }),
            other => Err(SceneError::UnknownBuiltin(other.into())),
        }
    }

    /// Parse a scene from its JSON text and check it.
    pub fn from_json(text: &str) -> Result<Self, SceneError> {
        let scene: Scene =
            serde_json::from_str(text).map_err(|e| SceneError::Parse(format!("scene JSON: {e}")))?;
        scene.validate()?;
        Ok(scene)
    }

    /// Check ranges.
    pub fn validate(&self) -> Result<(), SceneError> {
        let bad = |problem: String| Err(SceneError::Invalid { scene: self.name.clone(), problem });
        if !(self.size_m.iter().all(|&s| s > 0.0) && self.vertices.iter().all(|&n| n >= 2)) {
            return bad("the cloth needs positive sizes and at least 2 vertices per side".into());
        }
        if !(self.end_time_s > 0.0 && self.frame_time_s > 0.0 && self.steps_per_frame > 0) {
            return bad("end_time_s, frame_time_s and steps_per_frame must be positive".into());
        }
        let w = &self.wind;
        if !(w.density_kg_m3 >= 0.0 && w.drag_kg_m2_s >= 0.0 && w.velocity_m_s.iter().all(|v| v.is_finite()))
        {
            return bad(
                "wind: density_kg_m3 and drag_kg_m2_s must be non-negative, velocity_m_s finite".into()
            );
        }
        for (k, h) in self.handles.iter().enumerate() {
            let motion = match h {
                HandleSpec::Bar { side, motion, .. } if *side > 3 => {
                    return bad(format!("handle {k}: side {side} is not 0-3"));
                }
                HandleSpec::Bar { motion, .. } | HandleSpec::Sphere { motion, .. } => *motion,
            };
            if let Some(m) = motion.filter(|&m| m >= self.motions.len()) {
                return bad(format!(
                    "handle {k}: motion {m} does not exist ({} motions)",
                    self.motions.len()
                ));
            }
        }
        Ok(())
    }

    /// The time step (s).
    pub fn dt_s(&self) -> f64 {
        self.frame_time_s / f64::from(self.steps_per_frame)
    }

    /// The cloth mesh.
    pub fn mesh(&self) -> ShellMesh {
        ShellMesh::rectangle(self.size_m[0], self.size_m[1], self.vertices[0], self.vertices[1])
            .unwrap_or_else(|e| unreachable!("a rectangle is a valid mesh: {e}"))
    }

    /// The handles over `mesh` with their motions; errors if a handle holds no vertex.
    pub fn handles(&self, mesh: &ShellMesh) -> Result<Vec<Handle>, SceneError> {
        self.handles_at(&mesh.flat_positions())
    }

    /// The handles over vertices at rest `positions` (the cloth's rectangle of `size_m`
    /// centred on the origin) with their motions; errors if a handle holds no vertex.
    pub fn handles_at(&self, positions: &[Vector3<f64>]) -> Result<Vec<Handle>, SceneError> {
        self.handles
            .iter()
            .enumerate()
            .map(|(k, spec)| {
                let mut vertices: Vec<usize> =
                    (0..positions.len()).filter(|&v| self.holds(spec, &positions[v])).collect();
                if let (true, HandleSpec::Sphere { center, .. }) = (vertices.is_empty(), spec) {
                    // A coarse mesh may have no vertex inside a small sphere: hold the nearest.
                    let distance = |v: usize| (positions[v] - Vector3::from(*center)).norm();
                    vertices
                        .extend((0..positions.len()).min_by(|&a, &b| distance(a).total_cmp(&distance(b))));
                }
                if vertices.is_empty() {
                    return Err(SceneError::Invalid {
                        scene: self.name.clone(),
                        problem: format!("handle {k} holds no vertex"),
                    });
                }
                let motion = match spec {
                    HandleSpec::Bar { motion, .. } | HandleSpec::Sphere { motion, .. } => *motion,
                };
                let keys = motion.map(|m| self.motions[m].clone()).unwrap_or_default();
                Ok(Handle { vertices, motion: Motion { keys } })
            })
            .collect()
    }

    /// Whether the handle holds a vertex at rest position `p`.
    fn holds(&self, spec: &HandleSpec, p: &Vector3<f64>) -> bool {
        const SLACK: f64 = 1e-9;
        match *spec {
            HandleSpec::Sphere { center, radius, .. } => (p - Vector3::from(center)).norm() <= radius + SLACK,
            HandleSpec::Bar { side, length, width, inset, .. } => {
                let [wx, wy] = self.size_m;
                // along: coordinate along the side in [0, 1]; depth: distance from it in m.
                let (along, depth, across) = match side {
                    0 => ((p.y + wy / 2.0) / wy, p.x + wx / 2.0, wx),
                    1 => ((p.x + wx / 2.0) / wx, p.y + wy / 2.0, wy),
                    2 => ((p.y + wy / 2.0) / wy, wx / 2.0 - p.x, wx),
                    _ => ((p.x + wx / 2.0) / wx, wy / 2.0 - p.y, wy),
                };
                along >= inset - SLACK && along <= inset + length + SLACK && depth <= width * across + SLACK
            }
        }
    }

    /// The integrator settings.
    pub fn dynamics(&self) -> Dynamics {
        Dynamics {
            dt_s: self.dt_s(),
            gravity: self.gravity,
            mass_damping: self.mass_damping,
            stiffness_damping: self.stiffness_damping,
            wind: self.wind,
            max_newton_iterations: self.max_newton_iterations,
            tolerance_m: self.tolerance_m,
            newton_matrix: self.newton_matrix,
            linear_solver: self.linear_solver,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtins_hold_the_published_handles() {
        let scene = Scene::builtin("stretch-x").expect("builtin");
        let mesh = scene.mesh();
        let handles = scene.handles(&mesh).expect("handles");
        assert_eq!(handles.len(), 2);
        let p = mesh.flat_positions();
        for (h, sign) in handles.iter().zip([-1.0, 1.0]) {
            // Every held vertex within 7% of 30 cm of its side, within the middle 67%.
            assert!(h.vertices.iter().all(|&v| sign * p[v].x >= 0.15 - 0.021 - 1e-9));
            assert!(h.vertices.iter().all(|&v| p[v].y.abs() <= 0.3 * 0.34 + 1e-9));
            assert!((h.motion.translation(1.0).x - sign * 0.035).abs() < 1e-15);
        }
        let drape = Scene::builtin("drape").expect("builtin");
        let held = drape.handles(&drape.mesh()).expect("handles");
        assert!(held.iter().all(|h| !h.vertices.is_empty() && h.motion.keys.is_empty()));
    }

    #[test]
    fn scene_files_round_trip_and_bad_ones_are_named() {
        let scene = Scene::builtin("drape").expect("builtin");
        let text = serde_json::to_string_pretty(&scene).expect("json");
        assert_eq!(Scene::from_json(&text).expect("parses"), scene);
        let bad = text.replace("\"steps_per_frame\": 4", "\"steps_per_frame\": 0");
        assert!(Scene::from_json(&bad).expect_err("invalid").to_string().contains("steps_per_frame"));
        assert!(matches!(Scene::builtin("wave"), Err(SceneError::UnknownBuiltin(_))));
    }

    #[test]
    fn scene_files_without_wind_load_without_air_drag() {
        let mut json = serde_json::to_value(Scene::builtin("drape").expect("builtin")).expect("json");
        assert_eq!(json["wind"]["density_kg_m3"], 7.5);
        json.as_object_mut().expect("object").remove("wind");
        let old = Scene::from_json(&json.to_string()).expect("parses");
        assert_eq!(old.wind, Wind::default());
        assert!(old.wind.is_none() && old.dynamics().wind.is_none());
        json["wind"] = serde_json::json!({"drag_kg_m2_s": 0.2});
        let partial = Scene::from_json(&json.to_string()).expect("parses");
        assert_eq!(partial.wind, Wind { drag_kg_m2_s: 0.2, ..Wind::default() });
        json["wind"] = serde_json::json!({"density_kg_m3": -1.0});
        assert!(Scene::from_json(&json.to_string()).expect_err("invalid").to_string().contains("wind"));
    }
}
