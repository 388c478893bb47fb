//! The stretch track of a diagnosis: the targets of the stretch tests split into fitted and
//! held-out ones, the base membrane and the nested stretch-track extensions fitted by simulating
//! the clamped swatches ([`crate::shell::membrane`]), their residuals and the noise level.

use yarnhom_geom::stats::root_mean_square;
use yarnhom_shell::{Stiffening, StvkNeoHookean};

use super::report::{ModelResult, Prediction};
use super::settings::DiagnoseSettings;
use crate::cause::CauseId;
use crate::data::set::{MeasurementSet, Phase};
use crate::data::targets::{Target, TargetChoice, TargetPlan, targets};
use crate::experiments::swatch::SimulatedReading;
use crate::optimize::akaike::criterion;
use crate::optimize::lm::LmSettings;
use crate::shell::membrane::{
    DirectionData, Problem, ShellFitError, Terms, fit_membrane, forces_and_compressions, starting_material,
};

/// The stretch targets of a diagnosis and the problems they make: up to `n` loading targets per
/// direction (and unloading ones where the set has enough unloading readings), chosen from the
/// readings ([`crate::data::targets`]), the even ones of each direction fitted, the odd ones
/// held out.
pub(super) struct Phases {
    pub load_targets: Vec<Target>,
    pub unload_targets: Option<Vec<Target>>,
    pub choices: Vec<TargetChoice>,
    pub load: Problem,
    pub unload: Option<Problem>,
    /// Why there are no unloading targets, if there are none.
    unload_note: Option<String>,
}

impl Phases {
    /// The targets of `set` and their split.
    pub fn of_set(set: &MeasurementSet, settings: &DiagnoseSettings) -> Result<Self, ShellFitError> {
        let plan = TargetPlan {
            per_direction: settings.targets_per_direction,
            force_cap_n: settings.force_cap_n,
            phase: Phase::Load,
        };
        let load = targets(set, &plan)?;
        let even = |k: usize| k.is_multiple_of(2);
        let (unload_targets, unload_note, unload_choices) =
            match targets(set, &TargetPlan { phase: Phase::Unload, ..plan }) {
                Ok(t) => (Some(t.targets), None, t.choices),
                Err(e) => (None, Some(format!("no unloading targets: {e}")), Vec::new()),
            };
        let load_problem = Problem::new(DirectionData::group(set, &load.targets, even), settings.spacing_m);
        let unload = unload_targets
            .as_ref()
            .map(|t| Problem::new(DirectionData::group(set, t, even), settings.spacing_m));
        Ok(Self {
            load_targets: load.targets,
            unload_targets,
            choices: load.choices.into_iter().chain(unload_choices).collect(),
            load: load_problem,
            unload,
            unload_note,
        })
    }

    /// Why the unloading cannot be tested, if it cannot.
    pub fn unload_note(&self) -> Option<&str> {
        self.unload_note.as_deref()
    }

    /// Whether each loading target is fitted (else held out), in target order.
    pub fn load_fitted(&self) -> Vec<bool> {
        self.load.data.iter().flat_map(|d| d.fitted.iter().copied()).collect()
    }
}

/// Which extensions of the base a stretch-track model has.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(super) struct Extensions {
    /// The membrane terms.
    pub terms: Terms,
    /// Unloading force `(1 - h)` times the loading force.
    pub friction: bool,
}

impl Extensions {
    /// These extensions and the one for `id`.
    fn with(self, id: CauseId) -> Self {
        let mut e = self;
        match id {
            CauseId::AreaPreservation => e.terms.area = true,
            CauseId::BiphasicStretch => e.terms.stiffening = true,
            CauseId::TwoPhaseContact => e.terms.jamming = true,
            CauseId::FrictionHysteresis => e.friction = true,
            _ => {}
        }
        e
    }
}

/// The stretch-track causes, in catalog order.
pub(super) const STRETCH_CAUSES: [CauseId; 4] = [
    CauseId::AreaPreservation,
    CauseId::BiphasicStretch,
    CauseId::FrictionHysteresis,
    CauseId::TwoPhaseContact,
];

/// The base of the stretch track: plain anisotropic StVK from its starting material.
pub(super) fn fit_base(phases: &Phases, lm: &LmSettings) -> Result<Fitted, ShellFitError> {
    fit_model(phases, Extensions::default(), &[], lm)
}

/// The stretch-track candidate `id` fitted on top of `model` (`None` when `model` has it
/// already, without an equilibrium, or for friction without unloading targets to fit). The
/// membrane terms are fitted from several starts ([`candidate_starts`]), so that an onset can
/// leave a start where it does not act; friction's `h` is a least-squares factor on the even
/// unloading targets.
pub(super) fn fit_candidate(id: CauseId, phases: &Phases, model: &Fitted, lm: &LmSettings) -> Option<Fitted> {
    let extensions = model.extensions.with(id);
    if extensions == model.extensions {
        return None;
    }
    if id == CauseId::FrictionHysteresis {
        let hysteresis = fit_hysteresis(phases, &model.unload)?;
        return Some(Fitted {
            extensions,
            hysteresis,
            parameter_count: model.parameter_count + 2,
            ..model.clone()
        });
    }
    fit_model(phases, extensions, &candidate_starts(id, phases, &model.material), lm).ok()
}

/// The starts of candidate `id`'s fit on top of `material`: first the nested start (the new
/// term a thousandth of its usual starting size, so the extension starts where the model
/// ended; the prior's anchor), then the new term at full size: the area terms at 5%, 30% and
/// 100% of the mean stiffness; the stiffening as stiff as the StVK axes and five times that,
/// from 20%, 45% and 70% of the largest Green strain; the jamming as stiff as the mean StVK
/// stiffness and ten times that, from 10%, 30% and 60% of the largest compressive Green strain.
fn candidate_starts(id: CauseId, phases: &Phases, material: &StvkNeoHookean) -> Vec<StvkNeoHookean> {
    let terms = Extensions::default().with(id).terms;
    let seed = starting_material(&phases.load.data, terms);
    let nested = StvkNeoHookean {
        k_n1: if terms.area { 1e-3 * seed.k_n1 } else { material.k_n1 },
        k_n2: if terms.area { 1e-3 * seed.k_n2 } else { material.k_n2 },
        stiffening: material.stiffening.or(seed.stiffening.map(Stiffening::faint)),
        jamming: material.jamming.or(seed.jamming.map(Stiffening::faint)),
        ..*material
    };
    let mean = (material.k_xx * material.k_yy).sqrt();
    let grid = |onsets: [f64; 3], sizes: [f64; 2], largest: f64, k: (f64, f64)| -> Vec<Stiffening> {
        sizes
            .iter()
            .flat_map(|size| {
                onsets.map(|f| Stiffening {
                    k_weft: size * k.0,
                    k_warp: size * k.1,
                    onset: (f * largest).max(1e-3),
                })
            })
            .collect()
    };
    let full: Vec<StvkNeoHookean> = match id {
        CauseId::AreaPreservation => [0.05, 0.3, 1.0]
            .iter()
            .map(|f| StvkNeoHookean { k_n1: f * mean, k_n2: f * mean, ..nested })
            .collect(),
        CauseId::BiphasicStretch => {
            let largest = seed.stiffening.map_or(0.0, |b| 4.0 * b.onset);
            grid([0.2, 0.45, 0.7], [1.0, 5.0], largest, (material.k_xx, material.k_yy))
                .into_iter()
                .map(|b| StvkNeoHookean { stiffening: Some(b), ..nested })
                .collect()
        }
        CauseId::TwoPhaseContact => {
            let largest = seed.jamming.map_or(0.0, |b| 4.0 * b.onset);
            grid([0.1, 0.3, 0.6], [1.0, 10.0], largest, (mean, mean))
                .into_iter()
                .map(|b| StvkNeoHookean { jamming: Some(b), ..nested })
                .collect()
        }
        _ => Vec::new(),
    };
    std::iter::once(nested).chain(full).collect()
}

/// Residuals of a model's predictions: `(fitted, held out)`, pooled over both phases.
fn residuals(
    phases: &Phases,
    load: &[Vec<SimulatedReading>],
    unload: &[Vec<SimulatedReading>],
    hysteresis: Hysteresis,
) -> (Vec<f64>, Vec<f64>) {
    let mut fitted = Vec::new();
    let mut heldout = Vec::new();
    let mut add = |problem: &Problem, readings: &[Vec<SimulatedReading>], hysteresis: Hysteresis| {
        for (d, r) in problem.data.iter().zip(readings) {
            let (f, c) = forces_and_compressions(r);
            let f = hysteresis.unloading(&f);
            fitted.extend(d.residuals(&f, &c, true));
            heldout.extend(d.residuals(&f, &c, false));
        }
    };
    add(&phases.load, load, Hysteresis::NONE);
    if let Some(u) = &phases.unload {
        add(u, unload, hysteresis);
    }
    (fitted, heldout)
}

/// Friction hysteresis: the unloading force `F - h F_ref (F / F_ref)^p`, with `F` the model's
/// force at the unloading stretch and `F_ref` the direction's largest. `p = 1` takes a fixed
/// fraction `h` of the loading force; smaller `p` an offset that varies less with the force,
/// as Coulomb friction does at a normal force that grows slower than the tension.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Hysteresis {
    /// The offset at the largest force, as a fraction of it.
    pub h: f64,
    /// How the offset grows with the force.
    pub p: f64,
}

/// The exponents `p` over which the hysteresis is profiled.
const HYSTERESIS_EXPONENTS: [f64; 4] = [0.25, 0.5, 0.75, 1.0];

impl Hysteresis {
    /// No hysteresis: unloading as loading.
    pub const NONE: Hysteresis = Hysteresis { h: 0.0, p: 1.0 };

    /// The offset `h F_ref (F / F_ref)^p` per force of one direction, before `h`.
    fn shape(p: f64, forces: &[f64]) -> Vec<f64> {
        let reference = forces.iter().fold(0.0, |a: f64, f| a.max(f.abs())).max(1e-300);
        forces.iter().map(|f| reference * (f.max(0.0) / reference).powf(p)).collect()
    }

    /// The unloading forces of one direction from the model's forces at the same stretches.
    pub fn unloading(&self, forces: &[f64]) -> Vec<f64> {
        if self.h == 0.0 {
            return forces.to_vec();
        }
        forces.iter().zip(Self::shape(self.p, forces)).map(|(f, b)| f - self.h * b).collect()
    }
}

/// A fitted model: its extensions, material, unloading factor and predictions.
#[derive(Clone)]
pub(super) struct Fitted {
    pub extensions: Extensions,
    pub material: StvkNeoHookean,
    pub hysteresis: Hysteresis,
    pub parameter_count: usize,
    pub load: Vec<Vec<SimulatedReading>>,
    pub unload: Vec<Vec<SimulatedReading>>,
}

impl Fitted {
    /// Its result: parameters by name, errors on the fitted and held-out targets, criterion.
    pub fn result(&self, id: &str, phases: &Phases, note: Option<String>) -> ModelResult {
        let (fitted, heldout) = residuals(phases, &self.load, &self.unload, self.hysteresis);
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
        if self.extensions.friction {
            params.push(("hysteresis_h".to_string(), self.hysteresis.h));
            params.push(("hysteresis_p".to_string(), self.hysteresis.p));
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
            signature: None,
        }
    }

    /// Its predictions at every target, for figures.
    pub fn prediction(&self, id: &str) -> Prediction {
        let unload = self.unload.iter().flat_map(|readings| {
            let (forces, _) = forces_and_compressions(readings);
            let unloading = self.hysteresis.unloading(&forces);
            readings
                .iter()
                .zip(unloading)
                .map(|(r, force_n)| SimulatedReading { force_n, ..*r })
                .collect::<Vec<_>>()
        });
        Prediction {
            id: id.into(),
            load: self.load.iter().flatten().copied().collect(),
            unload: unload.collect(),
        }
    }
}

/// Fit the model with `extensions` from `starts` (none: the starting material), simulating
/// both phases; friction's factor is fitted on the simulated unloading.
pub(super) fn fit_model(
    phases: &Phases,
    extensions: Extensions,
    starts: &[StvkNeoHookean],
    lm: &LmSettings,
) -> Result<Fitted, ShellFitError> {
    let fitted = fit_membrane(&phases.load, extensions.terms, starts, lm)?;
    let material = fitted.material;
    let load = phases.load.simulate(&material).ok_or(ShellFitError::Start(material))?;
    let unload = match &phases.unload {
        Some(u) => u.simulate(&material).ok_or(ShellFitError::Start(material))?,
        None => Vec::new(),
    };
    let hysteresis = match extensions.friction {
        true => fit_hysteresis(phases, &unload).unwrap_or(Hysteresis::NONE),
        false => Hysteresis::NONE,
    };
    let parameter_count = fitted.optimizer.params.len() + 2 * usize::from(extensions.friction);
    Ok(Fitted { extensions, material, hysteresis, parameter_count, load, unload })
}

/// The hysteresis fitting the even unloading targets' forces: for each profiled exponent `p`,
/// `h` by least squares on (6.2)'s normalized force residuals; the `p` of the smallest cost.
fn fit_hysteresis(phases: &Phases, unload: &[Vec<SimulatedReading>]) -> Option<Hysteresis> {
    let u = phases.unload.as_ref()?;
    let fit_at = |p: f64| {
        let (mut bb, mut by, mut yy) = (0.0, 0.0, 0.0);
        for (d, r) in u.data.iter().zip(unload) {
            let (forces, _) = forces_and_compressions(r);
            let shape = Hysteresis::shape(p, &forces);
            for (((t, f), b), fitted) in d.targets.iter().zip(&forces).zip(&shape).zip(&d.fitted) {
                if *fitted {
                    // Residual (f - h b - t) / scale: least squares in h.
                    let (b, y) = (b / d.force_scale, (f - t.force_n) / d.force_scale);
                    (bb, by, yy) = (bb + b * b, by + b * y, yy + y * y);
                }
            }
        }
        (bb > 0.0).then(|| (yy - by * by / bb, Hysteresis { h: by / bb, p }))
    };
    HYSTERESIS_EXPONENTS.iter().filter_map(|&p| fit_at(p)).min_by(|a, b| a.0.total_cmp(&b.0)).map(|(_, h)| h)
}

/// The noise level: the pooled RMS of the held-out targets' normalized standard errors.
pub(super) fn noise_level(phases: &Phases) -> f64 {
    let mut errors = Vec::new();
    for problem in std::iter::once(&phases.load).chain(phases.unload.as_ref()) {
        for d in &problem.data {
            let forces: Vec<f64> = d.targets.iter().map(|t| t.force_n + t.force_standard_error_n).collect();
            let compressions: Vec<f64> = d
                .targets
                .iter()
                .map(|t| t.compression.unwrap_or(0.0) + t.compression_standard_error.unwrap_or(0.0))
                .collect();
            errors.extend(d.residuals(&forces, &compressions, false));
        }
    }
    root_mean_square(errors)
}
