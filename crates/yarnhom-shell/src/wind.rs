//! Air drag ("wind") as ARCSim applies it: per triangle, from the air's velocity relative to
//! the triangle's mean vertex velocity, a quadratic pressure along the normal and a linear
//! drag along the surface, lumped a third to each vertex.
//!
//! Source: ARCSim 0.2.1 as forked by ARCSim-HYLC (`PhoenixDigitalFX/ARCSim-HYLC`, the code the
//! published scenes were run with), `v0.2.1/physics.cpp` at commit
//! `00d7a899df60e142721da4cee28d631cf33eaf14`, lines 419-441 (`wind_force`,
//! `add_external_forces`; the same in the fork's first, unmodified ARCSim commit `57e4eec5`):
//! for a face with material-space (rest) area `a` (`face->a`, set by `compute_ms_data`) and
//! current unit normal `n` (`face->n`),
//!
//! `v_rel = u - (v_0 + v_1 + v_2)/3`, `v_n = n · v_rel`, `v_t = v_rel - v_n n`,
//! `f = ρ a |v_n| v_n n + d a v_t`,
//!
//! `f/3` added to each of the face's nodes, where `u` is `wind.velocity`, `ρ` `wind.density`
//! and `d` `wind.drag`. The force does not depend on the sign of `n`. ARCSim's parser
//! (`v0.2.1/conf.cpp`, `parse(Wind&, ...)`, commit `87e862f010561200b87cf9800737caa515e8453f`)
//! defaults `density` to 1, `velocity` to 0 and `drag` to 0, also when a scene has no `wind`.
//! The force goes into `fext` only, never into `Jext` (`v0.2.1/simulation.cpp`, `physics_step`,
//! commit `f1e84e6c0fb49883fdccc5f761ccfb293a62db9e`), and `implicit_update` (`physics.cpp`
//! lines 385-413) solves `(M - h² J_ext - ...) Δv = h f_ext + ...` (lines 401-402): the wind is
//! explicit, evaluated at the step's starting positions and velocities. [`crate::integrator`]
//! does the same: a constant force over the step, with no Newton matrix term.
//!
//! A flat cloth of areal density `μ` falling face-on through still air (`u = 0`) under gravity
//! `g` reaches the terminal speed where `μ g = ρ v²`, `v = sqrt(μ g / ρ)`
//! ([`Wind::terminal_speed_m_s`]): `ρ` is a pressure coefficient (`½ ρ_air C_D` of a drag law),
//! not the density of air; the published scenes set 3 to 15 kg/m³.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::mesh::ShellMesh;

/// Air drag on the cloth (ARCSim's `wind`); all zero (the default) is none.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Wind {
    /// Coefficient `ρ` of the normal pressure `ρ a |v_n| v_n` (kg/m³; ARCSim's
    /// `wind.density`).
    pub density_kg_m3: f64,
    /// Velocity `u` of the air (m/s; ARCSim's `wind.velocity`).
    pub velocity_m_s: [f64; 3],
    /// Coefficient `d` of the tangential drag `d a v_t` (kg/(m² s); ARCSim's `wind.drag`).
    pub drag_kg_m2_s: f64,
}

impl Wind {
    /// Whether the wind exerts no force whatever the cloth does (`ρ = d = 0`).
    pub fn is_none(&self) -> bool {
        self.density_kg_m3 == 0.0 && self.drag_kg_m2_s == 0.0
    }

    /// The force on a triangle of rest area `area_m2` and unit normal `normal` (zero for a
    /// degenerate triangle: only the tangential drag acts) moving at `velocity_m_s` (N).
    pub fn triangle_force_n(
        &self,
        area_m2: f64,
        normal: &Vector3<f64>,
        velocity_m_s: &Vector3<f64>,
    ) -> Vector3<f64> {
        let relative = Vector3::from(self.velocity_m_s) - velocity_m_s;
        let vn = normal.dot(&relative);
        let tangential = relative - vn * normal;
        self.density_kg_m3 * area_m2 * vn.abs() * vn * normal + self.drag_kg_m2_s * area_m2 * tangential
    }

    /// The force on each vertex of `mesh` at `positions` moving at `velocities` (N): each
    /// triangle's [`Wind::triangle_force_n`] at its mean vertex velocity, a third to each of its
    /// vertices. `rest_areas` are [`ShellMesh::rest_areas`].
    pub fn vertex_forces_n(
        &self,
        mesh: &ShellMesh,
        rest_areas: &[f64],
        positions: &[Vector3<f64>],
        velocities: &[Vector3<f64>],
    ) -> Vec<Vector3<f64>> {
        let mut forces = vec![Vector3::zeros(); positions.len()];
        for (tri, &area) in mesh.triangles.iter().zip(rest_areas) {
            let [a, b, c] = tri.map(|v| v as usize);
            let normal =
                (positions[b] - positions[a]).cross(&(positions[c] - positions[a])).try_normalize(0.0);
            let velocity = (velocities[a] + velocities[b] + velocities[c]) / 3.0;
            let force = self.triangle_force_n(area, &normal.unwrap_or_else(Vector3::zeros), &velocity) / 3.0;
            for v in [a, b, c] {
                forces[v] += force;
            }
        }
        forces
    }

    /// The terminal speed of a flat cloth of areal density `areal_density_kg_m2` falling
    /// face-on through still air under gravity `gravity_m_s2`: `sqrt(μ g / ρ)` (m/s; infinite
    /// without normal pressure).
    pub fn terminal_speed_m_s(&self, areal_density_kg_m2: f64, gravity_m_s2: f64) -> f64 {
        (areal_density_kg_m2 * gravity_m_s2 / self.density_kg_m3).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::ContactSettings;
    use crate::material::{HingeBending, ShellMaterial};
    use crate::scene::Scene;
    use crate::simulate::prepare;
    use crate::test_support::test_membrane;

    const STILL: Wind = Wind { density_kg_m3: 7.5, velocity_m_s: [0.0; 3], drag_kg_m2_s: 0.0 };

    /// A free `n x n` cloth of 20 cm, areal density 0.33 kg/m², no damping, contact or handles.
    fn free_cloth(n: usize, wind: Wind, gravity: [f64; 3]) -> (Scene, ShellMaterial) {
        let mut scene = Scene::builtin("drape").expect("builtin");
        scene.size_m = [0.2, 0.2];
        scene.vertices = [n, n];
        scene.handles.clear();
        scene.obstacles.clear();
        scene.contact = ContactSettings { self_thickness_m: 0.0, self_stiffness_n_m: 0.0, ..scene.contact };
        scene.mass_damping = 0.0;
        scene.stiffness_damping = 0.0;
        scene.gravity = gravity;
        scene.wind = wind;
        let material =
            ShellMaterial::stvk(0.33, test_membrane(), HingeBending::anisotropic(2e-6, 3e-6, 4e-6));
        (scene, material)
    }

    #[test]
    fn the_force_is_arcsims_and_ignores_the_normals_sign() {
        let wind = Wind { density_kg_m3: 2.0, velocity_m_s: [1.0, 0.0, 3.0], drag_kg_m2_s: 0.5 };
        let (n, v) = (Vector3::new(0.0, 0.0, 1.0), Vector3::new(0.0, 2.0, 1.0));
        // Relative velocity (1, -2, 2): normal part 2, tangential (1, -2, 0); so
        // ρ a |v_n| v_n = 2 x 0.1 x 4 along the normal and d a v_t = 0.05 x (1, -2, 0).
        let expected = Vector3::new(0.05, -0.1, 0.8);
        for normal in [n, -n] {
            assert!((wind.triangle_force_n(0.1, &normal, &v) - expected).norm() < 1e-15);
        }
    }

    #[test]
    fn a_cloth_at_rest_in_still_air_feels_no_drag() {
        let (scene, material) = free_cloth(4, STILL, [0.0; 3]);
        let mesh = scene.mesh();
        let positions = mesh.flat_positions();
        let forces =
            STILL.vertex_forces_n(&mesh, &mesh.rest_areas(), &positions, &vec![Vector3::zeros(); 16]);
        assert!(forces.iter().all(|f| *f == Vector3::zeros()));
        let mut sim = prepare(&scene, material).expect("scene");
        for _ in 0..10 {
            sim.step().expect("step");
        }
        assert!(sim.positions.iter().zip(&positions).all(|(p, q)| (p - q).norm() < 1e-12));
        assert!(sim.kinetic_energy() < 1e-20);
    }

    #[test]
    fn a_flat_cloth_falls_at_the_terminal_speed_of_the_wind_law() {
        // μ g = ρ v²: 0.33 x 9.81 / 7.5 = 0.432 m²/s², v = 0.657 m/s, reached within a few
        // v/g = 0.067 s; free fall would reach 9.8 m/s in the same second.
        let g = 9.81;
        let (scene, material) = free_cloth(5, STILL, [0.0, 0.0, -g]);
        let terminal = STILL.terminal_speed_m_s(0.33, g);
        let mut sim = prepare(&scene, material).expect("scene");
        while sim.time_s < 1.0 {
            sim.step().expect("step");
        }
        for v in &sim.velocities {
            assert!(v.x.abs() + v.y.abs() < 1e-9 * terminal, "the cloth stays flat: {v}");
            assert!((-v.z / terminal - 1.0).abs() < 0.01, "{} m/s against {terminal} m/s", -v.z);
        }
    }

    #[test]
    fn a_cloth_held_in_a_wind_is_pushed_along_it_and_tangential_drag_slows_sliding() {
        // Wind 1 m/s along +z on a flat cloth: a push of ρ A (1 m/s)² upwards in all.
        let wind = Wind { density_kg_m3: 1.5, velocity_m_s: [0.0, 0.0, 1.0], drag_kg_m2_s: 0.4 };
        let (scene, _) = free_cloth(4, wind, [0.0; 3]);
        let mesh = scene.mesh();
        let areas = mesh.rest_areas();
        let x = mesh.flat_positions();
        let still = vec![Vector3::zeros(); x.len()];
        let total: Vector3<f64> = wind.vertex_forces_n(&mesh, &areas, &x, &still).iter().sum();
        assert!((total - Vector3::new(0.0, 0.0, 1.5 * 0.04)).norm() < 1e-15, "{total}");
        // Sliding in its plane at 2 m/s along x: only the tangential drag, d A v, against it.
        let sliding = vec![Vector3::new(2.0, 0.0, 0.0); x.len()];
        let total: Vector3<f64> = wind.vertex_forces_n(&mesh, &areas, &x, &sliding).iter().sum();
        assert!((total - Vector3::new(-0.4 * 0.04 * 2.0, 0.0, 1.5 * 0.04)).norm() < 1e-15, "{total}");
    }
}
