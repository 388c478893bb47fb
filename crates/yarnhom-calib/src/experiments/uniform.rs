//! Uniform uniaxial tests of a shell material (thesis Sec. 6.3.1, (6.3)): the swatch stretched
//! by `s` along the unit direction `u`, free across it, so its compression `c` along `v ⊥ u`
//! minimizes the energy density; then the stretch stress `σ_s = ∂Ψ/∂s`. These are the uniform
//! targets `{s, c, σ_s}` handed to the yarn-level fit, and the cheap screening model of the
//! shell fit.

use nalgebra::Vector2;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use yarnhom_shell::StvkNeoHookean;
use yarnhom_shell::material::membrane_jet;

use crate::data::set::Direction;

/// The angle of a test direction from the weft (material x), in radians.
pub fn direction_angle(direction: Direction) -> f64 {
    match direction {
        Direction::Weft => 0.0,
        Direction::Bias => std::f64::consts::FRAC_PI_4,
        Direction::Warp => std::f64::consts::FRAC_PI_2,
    }
}

/// The pull direction `u` in material coordinates.
pub fn pull_axis(direction: Direction) -> Vector2<f64> {
    let angle = direction_angle(direction);
    Vector2::new(angle.cos(), angle.sin())
}

/// One uniform uniaxial state.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct UniaxialPoint {
    /// Stretch `s` along the pull.
    pub stretch: f64,
    /// Compression `c` across it, minimizing the energy (6.3).
    pub compression: f64,
    /// Stretch stress `σ_s = uᵀ (∂Ψ/∂F) u` (N/m: force per unit rest width).
    pub stress_n_m: f64,
}

/// The first fundamental form `I = Fᵀ F` of `F = (1 + s) u uᵀ + (1 - c) v vᵀ`, as
/// `(I11, I12, I22)`.
pub(crate) fn first_form(u: Vector2<f64>, stretch: f64, compression: f64) -> [f64; 3] {
    let (a, b) = ((1.0 + stretch).powi(2), (1.0 - compression).powi(2));
    let v = Vector2::new(-u.y, u.x);
    [a * u.x * u.x + b * v.x * v.x, a * u.x * u.y + b * v.x * v.y, a * u.y * u.y + b * v.y * v.y]
}

/// `∂Ψ/∂λ` along `w` where the form depends on `λ` as `λ² w wᵀ`: `2 λ ∇Ψ · (w1², w1 w2, w2²)`.
fn directional_stress(gradient: &[f64], w: Vector2<f64>, lambda: f64) -> f64 {
    2.0 * lambda * (gradient[0] * w.x * w.x + gradient[1] * w.x * w.y + gradient[2] * w.y * w.y)
}

/// (6.3): the compression minimizing the energy at stretch `s` along `direction`, and the stretch
/// stress there. The transverse stretch `1 - c` is searched in `(0, 2]` by golden sections on the
/// energy, then polished by Newton steps on `∂Ψ/∂c = 0`.
pub fn uniaxial(material: &StvkNeoHookean, direction: Direction, stretch: f64) -> UniaxialPoint {
    let u = pull_axis(direction);
    let v = Vector2::new(-u.y, u.x);
    let energy = |lambda: f64| membrane_jet(material, first_form(u, stretch, 1.0 - lambda)).value;
    let (mut lo, mut hi) = (1e-4, 2.0);
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..80 {
        let (a, b) = (hi - ratio * (hi - lo), lo + ratio * (hi - lo));
        if energy(a) <= energy(b) {
            hi = b;
        } else {
            lo = a;
        }
    }
    let mut lambda = 0.5 * (lo + hi);
    for _ in 0..3 {
        let jet = membrane_jet(material, first_form(u, stretch, 1.0 - lambda));
        let g = directional_stress(jet.gradient.as_slice(), v, lambda);
        let gg = jet.gradient;
        let d = [v.x * v.x, v.x * v.y, v.y * v.y];
        let dform: Vec<f64> = d.iter().map(|w| 2.0 * lambda * w).collect();
        let mut curvature = 2.0 * (gg[0] * d[0] + gg[1] * d[1] + gg[2] * d[2]);
        for i in 0..3 {
            for j in 0..3 {
                curvature += dform[i] * jet.hessian[(i, j)] * dform[j];
            }
        }
        if curvature <= 0.0 || !curvature.is_finite() {
            break;
        }
        let next = lambda - g / curvature;
        if !(next > 0.0 && (next - lambda).abs() < 0.1 * lambda) {
            break;
        }
        lambda = next;
    }
    let jet = membrane_jet(material, first_form(u, stretch, 1.0 - lambda));
    UniaxialPoint {
        stretch,
        compression: 1.0 - lambda,
        stress_n_m: directional_stress(jet.gradient.as_slice(), u, 1.0 + stretch),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::knit_membrane as material;

    #[test]
    fn the_compression_leaves_no_transverse_stress_and_the_stress_is_the_energy_slope() {
        for direction in Direction::ALL {
            for s in [0.05, 0.2, 0.5] {
                let p = uniaxial(&material(), direction, s);
                let u = pull_axis(direction);
                let v = Vector2::new(-u.y, u.x);
                let jet = membrane_jet(&material(), first_form(u, s, p.compression));
                let transverse = directional_stress(jet.gradient.as_slice(), v, 1.0 - p.compression);
                assert!(transverse.abs() < 1e-9 * p.stress_n_m.abs(), "{direction} {s}: {transverse}");
                // σ_s = dΨ/ds at the optimal c (envelope theorem: c's change does not count).
                let h = 1e-6;
                let e = |s: f64| membrane_jet(&material(), first_form(u, s, p.compression)).value;
                let fd = (e(s + h) - e(s - h)) / (2.0 * h);
                assert!(
                    (p.stress_n_m - fd).abs() < 1e-6 * fd.abs(),
                    "{direction} {s}: {} vs {fd}",
                    p.stress_n_m
                );
            }
        }
    }

    #[test]
    fn isotropic_linear_limit_gives_the_plane_stress_poisson_ratio() {
        // Small strain: StVK with k_xx = k_yy = k, k_xy = ν k is plane stress with Poisson ratio ν,
        // so c ≈ ν s and σ ≈ (1 - ν²) k s, the same along every direction when k_ss = (1 - ν) k / 2.
        let (k, nu) = (100.0, 0.3);
        let m = StvkNeoHookean {
            k_xx: k,
            k_xy: nu * k,
            k_yy: k,
            k_ss: 0.5 * (1.0 - nu) * k,
            k_n1: 0.0,
            k_n2: 0.0,
            stiffening: None,
            jamming: None,
        };
        for direction in Direction::ALL {
            let p = uniaxial(&m, direction, 1e-5);
            assert!((p.compression / 1e-5 - nu).abs() < 1e-3, "{direction}: {}", p.compression / 1e-5);
            assert!((p.stress_n_m / 1e-5 - (1.0 - nu * nu) * k).abs() < 0.01 * k, "{direction}");
        }
    }
}
