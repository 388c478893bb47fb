//! Homogenized energy density and stress of a tile at one macro strain (3.22-3.23).

use nalgebra::Vector3;
use yarnhom_geom::{MacroStrain, StrainError};

use crate::assembly::RveState;
use crate::model::RveModel;
use crate::placement::Placement;
use crate::solve::{SolveOptions, SolveReport, solve};

/// Central-difference steps for the stress: strain (dimensionless) and curvature (in units of
/// one over the tile's mean period, so that the step bends the tile by a similar amount).
const STRAIN_STEP: f64 = 1e-3;

/// The placement of the tile under `strain`.
pub fn placement(model: &RveModel, strain: &MacroStrain) -> Placement {
    let material: Vec<Vector3<f64>> = model.material.clone();
    Placement::new(material, model.period_m, strain)
}

/// Solve the tile at `strain`, from the affine start or warm-started from `start`.
pub fn solve_at(
    model: &RveModel,
    strain: &MacroStrain,
    start: Option<&RveState>,
    options: &SolveOptions,
) -> (SolveReport, RveState) {
    let placement = placement(model, strain);
    let mut state = match start {
        Some(s) => {
            let mut s = s.clone();
            s.update_frames(model, &placement);
            s
        }
        None => RveState::affine(model, &placement),
    };
    let report = solve(model, &placement, &mut state, options);
    (report, state)
}

/// `dΨ/d(sx, sa, sy, kx, ky)` at `strain` by central differences of solves warm-started from the
/// equilibrium `state` (the check route of Sec. 3.2.2; the thesis used it for bending stress in
/// Ch. 6). `None` if any of the ten solves fails to converge.
pub fn stress_by_finite_differences(
    model: &RveModel,
    strain: &MacroStrain,
    state: &RveState,
) -> Option<[f64; 5]> {
    let curvature_step = STRAIN_STEP * 2.0 / (model.period_m[0] + model.period_m[1]);
    let base = [strain.s.sx, strain.s.sa, strain.s.sy, strain.kx, strain.ky];
    let options = SolveOptions::warm_started();
    let mut stress = [0.0; 5];
    for (k, slot) in stress.iter_mut().enumerate() {
        let h = if k < 3 { STRAIN_STEP } else { curvature_step };
        let mut energies = [0.0; 2];
        for (side, sign) in [1.0, -1.0].into_iter().enumerate() {
            let mut s = base;
            s[k] += sign * h;
            let shifted = shifted_strain(s).ok()?;
            let (report, _) = solve_at(model, &shifted, Some(state), &options);
            energies[side] = if report.converged { report.energy_density_j_m2 } else { return None };
        }
        *slot = (energies[0] - energies[1]) / (2.0 * h);
    }
    Some(stress)
}

fn shifted_strain(s: [f64; 5]) -> Result<MacroStrain, StrainError> {
    MacroStrain::new(s[0], s[1], s[2], s[3], s[4])
}
