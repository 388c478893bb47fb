//! Air drag on yarns: ARCSim's wind law, which the published scenes set (`"wind"`, applied per
//! cloth triangle as `ρ a |v_n| v_n n + d a v_t` against the air's relative velocity, module
//! `wind` of `yarnhom-shell`), carried to yarn segments.
//!
//! Our reading for yarns: the cloth's area is shared among the yarn segments in proportion to
//! their rest lengths (`a_e = L̄_e A / Σ L̄`, [`YarnWind::area_per_length_m`]), the normal
//! pressure acts on the relative velocity's part normal to the segment and the tangential drag
//! on its part along it. A flat swatch moving across its plane feels exactly the shell's drag;
//! moving within its plane, its segments across the motion feel a pressure the shell's faces do
//! not. Like ARCSim, the force is explicit: evaluated at a step's start, held over the step.

use nalgebra::{DVector, Vector3};

use super::system::System;

/// The air around the yarns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct YarnWind {
    /// Coefficient `ρ` of the normal pressure `ρ a |v_n| v_n` (kg/m³, ARCSim's `wind.density`).
    pub density_kg_m3: f64,
    /// Velocity of the air (m/s).
    pub velocity_m_s: [f64; 3],
    /// Coefficient `d` of the drag `d a v_t` along the yarn (kg/(m² s), ARCSim's `wind.drag`).
    pub drag_kg_m2_s: f64,
    /// Cloth area per unit rest length of yarn (m): the swatch's area over its yarns' length.
    pub area_per_length_m: f64,
}

/// The wind's force on every vertex (N) at positions and velocities `q_n`, `v_n`: per segment
/// `ρ a |w| w + d a (u·t) t` for the relative velocity `u` of the air, its part `w` normal to
/// the segment of unit tangent `t`, half to each end.
pub(crate) fn wind_forces(
    system: &System,
    wind: &YarnWind,
    q_n: &DVector<f64>,
    v_n: &DVector<f64>,
) -> Vec<Vector3<f64>> {
    let mut forces = vec![Vector3::zeros(); system.vertex_count()];
    let air = Vector3::from(wind.velocity_m_s);
    for &(a, b, rest_m) in &system.segments {
        let t = (System::position(q_n, b) - System::position(q_n, a)).normalize();
        let velocity = (System::position(v_n, a) + System::position(v_n, b)) / 2.0;
        let relative = air - velocity;
        let along = t * relative.dot(&t);
        let normal = relative - along;
        let area = rest_m * wind.area_per_length_m;
        let force = normal * (wind.density_kg_m3 * area * normal.norm()) + along * (wind.drag_kg_m2_s * area);
        forces[a] += force / 2.0;
        forces[b] += force / 2.0;
    }
    forces
}
