//! The stretch track of a diagnosis: the targets of the stretch tests split into fitted and
//! held-out ones, the base membrane and the nested stretch-track extensions fitted by simulating
//! the clamped swatches ([`crate::shell::membrane`]), their residuals and the noise level.

use yarnhom_geom::stats::root_mean_square;
use yarnhom_shell::{Stiffening, StvkNeoHookean};

use super::report::{ModelResult, Prediction};
use super::settings::DiagnoseSettings;
use crate::cause::CauseId;
use crate::data::set::{MeasurementSet, Phase};
use crate::data::targets::{Target, TargetPlan, targets};
use crate::experiments::swatch::SimulatedReading;
use crate::optimize::akaike::criterion;
use crate::optimize::lm::LmSettings;
use crate::shell::membrane::{
    DirectionData, Problem, ShellFitError, Terms, fit_membrane, forces_and_compressions, starting_material,
};

/// The stretch targets of a diagnosis and the problems they make: `n` loading targets per
/// direction (and as many unloading ones where the set has enough unloading readings), the even
/// ones of each direction fitted, the odd ones held out.
pub(super) struct Phases {
    pub load_targets: Vec<Target>,
    pub unload_targets: Option<Vec<Target>>,
    pub load: Problem,
    pub unload: Option<Problem>,
}

impl Phases {
    /// The targets of `set` and their split.
    pub fn of_set(set: &MeasurementSet, settings: &DiagnoseSettings) -> Result<Self, ShellFitError> {
        let plan = TargetPlan {
            per_direction: settings.targets_per_direction,
            force_cap_n: settings.force_cap_n,
            phase: Phase::Load,
        };
        let load_targets = targets(set, &plan)?;
        let even = |k: usize| k.is_multiple_of(2);
        let unload_targets = targets(set, &TargetPlan { phase: Phase::Unload, ..plan }).ok();
        let load = Problem::new(DirectionData::group(set, &load_targets, even), settings.spacing_m);
        let unload = unload_targets
            .as_ref()
            .map(|t| Problem::new(DirectionData::group(set, t, even), settings.spacing_m));
        Ok(Self { load_targets, unload_targets, load, unload })
    }

    /// Why the unloading cannot be tested, if it cannot.
    pub fn unload_note(&self) -> Option<&'static str> {
        self.unload_targets.is_none().then_some("too few unloading readings to test")
    }

    /// Whether each loading target is fitted (else held out), in target order.
    pub fn load_fitted(&self) -> Vec<bool> {
        self.load.data.iter().flat_map(|d| d.fitted.iter().copied()).collect()
    }
}

/// The base of the stretch track: plain anisotropic StVK from its starting material.
pub(super) fn fit_base(phases: &Phases, lm: &LmSettings) -> Result<Fitted, ShellFitError> {
    let terms = Terms::default();
    fit_model(phases, terms, starting_material(&phases.load.data, terms), lm)
}

/// The stretch-track candidate `id` fitted nested from the base's fit (`None` without an
/// equilibrium, or for friction without unloading targets to fit).
pub(super) fn fit_candidate(id: CauseId, phases: &Phases, base: &Fitted, lm: &LmSettings) -> Option<Fitted> {
    match id {
        CauseId::AreaPreservation | CauseId::BiphasicStretch | CauseId::TwoPhaseContact => {
            let terms = Terms {
                area: id == CauseId::AreaPreservation,
                stiffening: id == CauseId::BiphasicStretch,
                jamming: id == CauseId::TwoPhaseContact,
            };
            // Nested: start at the base's fit with the new terms a thousandth of their
            // usual starting size, so the extension starts where the base ended.
            let seed = starting_material(&phases.load.data, terms);
            let start = StvkNeoHookean {
                k_n1: 1e-3 * seed.k_n1,
                k_n2: 1e-3 * seed.k_n2,
                stiffening: seed.stiffening.map(Stiffening::faint),
                jamming: seed.jamming.map(Stiffening::faint),
                ..base.material
            };
            fit_model(phases, terms, start, lm).ok()
        }
        CauseId::FrictionHysteresis => hysteresis_factor(phases, &base.unload).map(|factor| Fitted {
            material: base.material,
            unload_factor: factor,
            parameter_count: base.parameter_count + 1,
            load: base.load.clone(),
            unload: base.unload.clone(),
        }),
        _ => None,
    }
}

/// Residuals of a model's predictions: `(fitted, held out)`, pooled over both phases.
fn residuals(
    phases: &Phases,
    load: &[Vec<SimulatedReading>],
    unload: &[Vec<SimulatedReading>],
    unload_factor: f64,
) -> (Vec<f64>, Vec<f64>) {
    let mut fitted = Vec::new();
    let mut heldout = Vec::new();
    let mut add = |problem: &Problem, readings: &[Vec<SimulatedReading>], factor: f64| {
        for (d, r) in problem.data.iter().zip(readings) {
            let (f, c) = forces_and_compressions(r);
            let f: Vec<f64> = f.iter().map(|x| x * factor).collect();
            fitted.extend(d.residuals(&f, &c, true));
            heldout.extend(d.residuals(&f, &c, false));
        }
    };
    add(&phases.load, load, 1.0);
    if let Some(u) = &phases.unload {
        add(u, unload, unload_factor);
    }
    (fitted, heldout)
}

/// A fitted model: its material, unloading factor and predictions.
pub(super) struct Fitted {
    pub material: StvkNeoHookean,
    pub unload_factor: f64,
    pub parameter_count: usize,
    pub load: Vec<Vec<SimulatedReading>>,
    pub unload: Vec<Vec<SimulatedReading>>,
}

impl Fitted {
    /// Its result: parameters by name, errors on the fitted and held-out targets, criterion.
    pub fn result(&self, id: &str, phases: &Phases, note: Option<String>) -> ModelResult {
        let (fitted, heldout) = residuals(phases, &self.load, &self.unload, self.unload_factor);
        let m = &self.material;
        let mut params = vec![
            ("k_xx".to_string(), m.k_xx),
            ("k_xy".to_string(), m.k_xy),
            ("k_yy".to_string(), m.k_yy),
            ("k_ss".to_string(), m.k_ss),
        ];
        if m.k_n1 > 0.0 || m.k_n2 > 0.0 {
            params.extend([("k_n1".to_string(), m.k_n1), ("k_n2".to_string(), m.k_n2)]);
        }
        if let Some(b) = m.stiffening {
            params.extend([
                ("stiffening_k_weft".to_string(), b.k_weft),
                ("stiffening_k_warp".to_string(), b.k_warp),
                ("stiffening_onset".to_string(), b.onset),
            ]);
        }
        if let Some(b) = m.jamming {
            params.extend([
                ("jamming_k_weft".to_string(), b.k_weft),
                ("jamming_k_warp".to_string(), b.k_warp),
                ("jamming_onset".to_string(), b.onset),
            ]);
        }
        if self.unload_factor != 1.0 {
            params.push(("hysteresis_h".to_string(), 1.0 - self.unload_factor));
        }
        ModelResult {
            id: id.into(),
            testable: true,
            note,
            params,
            parameter_count: self.parameter_count,
            error: Some(root_mean_square(fitted.iter().copied())),
            heldout_error: Some(root_mean_square(heldout.iter().copied())),
            criterion: Some(criterion(&fitted, self.parameter_count)),
        }
    }

    /// Its predictions at every target, for figures.
    pub fn prediction(&self, id: &str) -> Prediction {
        let scale = |r: &SimulatedReading| SimulatedReading { force_n: r.force_n * self.unload_factor, ..*r };
        Prediction {
            id: id.into(),
            load: self.load.iter().flatten().copied().collect(),
            unload: self.unload.iter().flatten().map(scale).collect(),
        }
    }
}

/// Fit the membrane with `terms` from `start`, simulating both phases.
pub(super) fn fit_model(
    phases: &Phases,
    terms: Terms,
    start: StvkNeoHookean,
    lm: &LmSettings,
) -> Result<Fitted, ShellFitError> {
    let fitted = fit_membrane(&phases.load, terms, Some(start), lm)?;
    let (material, parameter_count) = (fitted.material, fitted.optimizer.params.len());
    let load = phases.load.simulate(&material).ok_or(ShellFitError::Start(material))?;
    let unload = match &phases.unload {
        Some(u) => u.simulate(&material).ok_or(ShellFitError::Start(material))?,
        None => Vec::new(),
    };
    Ok(Fitted { material, unload_factor: 1.0, parameter_count, load, unload })
}

/// The unloading factor `1 - h` fitting the even unloading targets' forces by least squares.
fn hysteresis_factor(phases: &Phases, unload: &[Vec<SimulatedReading>]) -> Option<f64> {
    let u = phases.unload.as_ref()?;
    let (mut num, mut den) = (0.0, 0.0);
    for (d, r) in u.data.iter().zip(unload) {
        for ((t, reading), fitted) in d.targets.iter().zip(r).zip(&d.fitted) {
            if *fitted {
                num += reading.force_n * t.force_n;
                den += reading.force_n * reading.force_n;
            }
        }
    }
    (den > 0.0).then(|| num / den)
}

/// The noise level: the pooled RMS of the held-out targets' normalized standard errors.
pub(super) fn noise_level(phases: &Phases) -> f64 {
    let mut errors = Vec::new();
    for problem in std::iter::once(&phases.load).chain(phases.unload.as_ref()) {
        for d in &problem.data {
            let forces: Vec<f64> =
                d.targets.iter().map(|t| t.force_n + t.force_noise_n / (t.readings as f64).sqrt()).collect();
            let compressions: Vec<f64> = d
                .targets
                .iter()
                .map(|t| {
                    t.compression.unwrap_or(0.0)
                        + t.compression_noise.unwrap_or(0.0) / (t.readings as f64).sqrt()
                })
                .collect();
            errors.extend(d.residuals(&forces, &compressions, false));
        }
    }
    root_mean_square(errors)
}
