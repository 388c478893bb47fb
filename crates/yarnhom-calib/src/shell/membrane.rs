//! The membrane fit of thesis Sec. 6.3.1 by simulation in the loop (6.2): the anisotropic
//! StVK + Neo-Hookean membrane (6.1), with the extensions the diagnosis screens (stiffening,
//! jamming), fitted to the stretch targets of each direction's clamped swatch
//! ([`crate::experiments::swatch`]) after a screening on the uniform test
//! ([`crate::experiments::uniform`]), by Levenberg-Marquardt ([`crate::optimize::lm`]).
//!
//! Errors (Sec. 6.3.1): per direction, the RMS of `f_sim - f` over the mean measured force,
//! and the RMS of `c_sim - c` over the mean measured compression (at least 0.01); (6.2)'s
//! weights `w_s`, `w_c` are these normalizations, so the fit minimizes the reported errors.
//! The shell fit and the diagnosis both fit through `fit_membrane`.

use rayon::prelude::*;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use yarnhom_geom::stats::root_mean_square;
use yarnhom_shell::{Stiffening, StvkNeoHookean};

use crate::data::set::{Direction, MeasurementSet, Specimen};
use crate::data::targets::{Target, TargetError};
use crate::experiments::swatch::{SimulatedReading, SwatchTest};
use crate::experiments::uniform::uniaxial;
use crate::optimize::lm::{LmReport, LmSettings, minimize};

/// Smallest compression scale in the normalization (compressions are often near 0).
pub(crate) const COMPRESSION_SCALE_FLOOR: f64 = 0.01;

/// Weight of the prior residuals `w (p - p_start)` on the encoded parameters: a change by a
/// factor e of a stiffness costs `w²/2`, negligible against the data (a cost of order 1), but
/// it keeps directions the data leaves flat (a vanishing area term, a saturated coupling)
/// from drifting to infinity.
const PRIOR_WEIGHT: f64 = 1e-2;

/// Which terms of (6.1) are fitted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "kebab-case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum MembraneModel {
    /// Plain anisotropic StVK (`k_n1 = k_n2 = 0`).
    Stvk,
    /// Anisotropic StVK with the Neo-Hookean area terms (6.1).
    StvkNeoHookean,
    /// (6.1) with jamming past an onset compression: the extension the diagnosis names
    /// `two-phase-contact` (beyond the thesis).
    ///
    /// See [`StvkNeoHookean::jamming`].
    StvkNeoHookeanJamming,
    /// Plain anisotropic StVK plus the extensions a diagnosis of the set confirms
    /// (`calibrate diagnose`): the area terms for `area-preservation`, stiffening for
    /// `biphasic-stretch`, jamming for `two-phase-contact`.
    ///
    /// See [`crate::auto_model`].
    Auto,
}

impl MembraneModel {
    /// The model's name in summaries.
    pub fn name(self) -> &'static str {
        match self {
            MembraneModel::Stvk => "anisotropic StVK",
            MembraneModel::StvkNeoHookean => "anisotropic StVK + Neo-Hookean (6.1)",
            MembraneModel::StvkNeoHookeanJamming => "anisotropic StVK + Neo-Hookean (6.1) + jamming",
            MembraneModel::Auto => "anisotropic StVK + the extensions the diagnosis confirms",
        }
    }
}

/// Fit errors (fractions, Sec. 6.3.1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct FitErrors {
    /// Per direction: `(direction, force error, compression error if measured)`.
    pub by_direction: Vec<(Direction, f64, Option<f64>)>,
    /// Mean force error over directions.
    pub force: f64,
    /// Mean compression error over directions with compression.
    pub compression: Option<f64>,
}

/// Why a fit failed.
#[derive(Debug, thiserror::Error)]
pub enum ShellFitError {
    /// No targets.
    #[error(transparent)]
    Targets(#[from] TargetError),
    /// The swatch could not be simulated at the start.
    #[error("the clamped swatch has no equilibrium at the starting material {0:?}")]
    Start(StvkNeoHookean),
    /// `--model auto` asked of a fit that does not diagnose.
    #[error("the auto model is chosen by a diagnosis: fit it with yarnhom_calib::auto_model::fit_shell")]
    Auto,
}

/// Which extensions of plain anisotropic StVK a fit has.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) struct Terms {
    /// The Neo-Hookean area terms of (6.1).
    pub area: bool,
    /// [`Stiffening`] past an onset strain.
    pub stiffening: bool,
    /// Jamming ([`StvkNeoHookean::jamming`]) past an onset compression.
    pub jamming: bool,
}

impl MembraneModel {
    /// The terms of a fixed model (`None` for [`MembraneModel::Auto`], whose terms a diagnosis
    /// chooses).
    pub(crate) fn terms(self) -> Option<Terms> {
        (self != MembraneModel::Auto).then(|| Terms {
            area: self != MembraneModel::Stvk,
            stiffening: false,
            jamming: self == MembraneModel::StvkNeoHookeanJamming,
        })
    }
}

/// The fitted parameters: logs of the positive stiffnesses (and of the stiffening and jamming
/// onsets) and
/// `atanh` of the coupling ratio `k_xy / √(k_xx k_yy)`, which keeps the StVK matrix positive
/// definite.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Parameterization {
    pub terms: Terms,
    pub fit_shear: bool,
    /// Values of the parameters not fitted.
    pub held: StvkNeoHookean,
}

impl Parameterization {
    pub fn encode(&self, m: &StvkNeoHookean) -> Vec<f64> {
        let mut p = vec![m.k_xx.ln(), m.k_yy.ln(), (m.k_xy / (m.k_xx * m.k_yy).sqrt()).atanh()];
        if self.fit_shear {
            p.push(m.k_ss.ln());
        }
        if self.terms.area {
            p.extend([m.k_n1.ln(), m.k_n2.ln()]);
        }
        if self.terms.stiffening {
            let b = m.stiffening.expect("a stiffening term to encode");
            p.extend([b.k_weft.ln(), b.k_warp.ln(), b.onset.ln()]);
        }
        if self.terms.jamming {
            let b = m.jamming.expect("a jamming term to encode");
            p.extend([b.k_weft.ln(), b.k_warp.ln(), b.onset.ln()]);
        }
        p
    }

    pub fn decode(&self, p: &[f64]) -> StvkNeoHookean {
        let (k_xx, k_yy) = (p[0].exp(), p[1].exp());
        let mut m = StvkNeoHookean { k_xx, k_yy, k_xy: p[2].tanh() * (k_xx * k_yy).sqrt(), ..self.held };
        let mut rest = p[3..].iter().map(|x| x.exp());
        let mut next = || rest.next().expect("encoded");
        if self.fit_shear {
            m.k_ss = next();
        }
        if self.terms.area {
            (m.k_n1, m.k_n2) = (next(), next());
        }
        if self.terms.stiffening {
            m.stiffening = Some(Stiffening { k_weft: next(), k_warp: next(), onset: next() });
        }
        if self.terms.jamming {
            m.jamming = Some(Stiffening { k_weft: next(), k_warp: next(), onset: next() });
        }
        m
    }

    pub fn unconstrained(&self) -> Vec<String> {
        if self.fit_shear { Vec::new() } else { vec!["k_ss".into()] }
    }
}

/// The measured data of one direction: its swatch, its targets and which of them are fitted
/// (the others are held out).
pub(crate) struct DirectionData {
    pub direction: Direction,
    pub specimen: Specimen,
    pub targets: Vec<Target>,
    pub fitted: Vec<bool>,
    pub force_scale: f64,
    pub compression_scale: Option<f64>,
}

impl DirectionData {
    /// Group `targets` by direction; `fitted(k)` says whether a direction's `k`-th target is
    /// fitted.
    pub fn group(
        set: &MeasurementSet,
        targets: &[Target],
        fitted: impl Fn(usize) -> bool,
    ) -> Vec<DirectionData> {
        Direction::ALL
            .into_iter()
            .filter_map(|direction| {
                let mine: Vec<Target> =
                    targets.iter().filter(|t| t.direction == direction).copied().collect();
                let n = mine.len() as f64;
                let force_scale = mine.iter().map(|t| t.force_n.abs()).sum::<f64>() / n;
                let compressions: Vec<f64> = mine.iter().filter_map(|t| t.compression).collect();
                let compression_scale = (!compressions.is_empty()).then(|| {
                    (compressions.iter().map(|c| c.abs()).sum::<f64>() / compressions.len() as f64)
                        .max(COMPRESSION_SCALE_FLOOR)
                });
                (!mine.is_empty()).then(|| DirectionData {
                    direction,
                    specimen: set.fabric.swatch.specimen(direction),
                    fitted: (0..mine.len()).map(&fitted).collect(),
                    targets: mine,
                    force_scale: force_scale.max(1e-12),
                    compression_scale,
                })
            })
            .collect()
    }

    pub fn stretches(&self) -> Vec<f64> {
        self.targets.iter().map(|t| t.stretch).collect()
    }

    /// (6.2)'s weighted residuals of the targets whose `fitted` flag is `which`, from forces and
    /// compressions at every target.
    pub fn residuals(&self, forces: &[f64], compressions: &[f64], which: bool) -> Vec<f64> {
        let mut r = Vec::with_capacity(2 * self.targets.len());
        for (k, ((t, f), c)) in self.targets.iter().zip(forces).zip(compressions).enumerate() {
            if self.fitted[k] != which {
                continue;
            }
            r.push((f - t.force_n) / self.force_scale);
            if let (Some(measured), Some(scale)) = (t.compression, self.compression_scale) {
                r.push((c - measured) / scale);
            }
        }
        r
    }

    /// Force and compression errors (Sec. 6.3.1) over the targets whose `fitted` flag is `which`.
    fn errors(&self, forces: &[f64], compressions: &[f64], which: bool) -> (f64, Option<f64>) {
        let chosen =
            || self.targets.iter().zip(&self.fitted).filter(move |(_, f)| **f == which).map(|(t, _)| t);
        let picked = |values: &[f64]| -> Vec<f64> {
            values.iter().zip(&self.fitted).filter(|(_, f)| **f == which).map(|(v, _)| *v).collect()
        };
        let force =
            root_mean_square(chosen().zip(picked(forces)).map(|(t, f)| f - t.force_n)) / self.force_scale;
        let compression = self.compression_scale.map(|scale| {
            root_mean_square(
                chosen().zip(picked(compressions)).filter_map(|(t, c)| t.compression.map(|m| c - m)),
            ) / scale
        });
        (force, compression)
    }

    /// The uniform test's forces and compressions at the targets.
    fn uniform(&self, material: &StvkNeoHookean) -> (Vec<f64>, Vec<f64>) {
        self.targets
            .iter()
            .map(|t| {
                let p = uniaxial(material, self.direction, t.stretch);
                (p.stress_n_m * self.specimen.width_m, p.compression)
            })
            .unzip()
    }
}

pub(crate) fn forces_and_compressions(readings: &[SimulatedReading]) -> (Vec<f64>, Vec<f64>) {
    readings.iter().map(|r| (r.force_n, r.compression)).unzip()
}

/// Errors per direction and their means over the targets whose `fitted` flag is `which`.
pub(crate) fn collect_errors(
    data: &[DirectionData],
    per_direction: &[Vec<SimulatedReading>],
    which: bool,
) -> FitErrors {
    let by_direction: Vec<(Direction, f64, Option<f64>)> = data
        .iter()
        .zip(per_direction)
        .map(|(d, readings)| {
            let (f, c) = forces_and_compressions(readings);
            let (force, compression) = d.errors(&f, &c, which);
            (d.direction, force, compression)
        })
        .collect();
    let force = by_direction.iter().map(|e| e.1).sum::<f64>() / by_direction.len() as f64;
    let compressions: Vec<f64> = by_direction.iter().filter_map(|e| e.2).collect();
    let compression =
        (!compressions.is_empty()).then(|| compressions.iter().sum::<f64>() / compressions.len() as f64);
    FitErrors { by_direction, force, compression }
}

/// A starting material from the last target of each direction: `k ≈ σ / ((1 + s) E)` with
/// `E = ((1 + s)² - 1) / 2`, the other axis copying a missing one; area terms at 5% of the
/// mean stiffness; stiffening as stiff as the StVK part, from half the largest Green strain;
/// jamming as stiff as the mean StVK stiffness, from a quarter of the largest compressive Green
/// strain measured across a weft or warp pull (the axes the jamming acts on; a bias swatch
/// contracts by shear), so that it acts on most targets from the start.
pub(crate) fn starting_material(data: &[DirectionData], terms: Terms) -> StvkNeoHookean {
    let stiffness = |direction: Direction| {
        data.iter().find(|d| d.direction == direction).and_then(|d| d.targets.last().map(|t| (d, t))).map(
            |(d, t)| {
                let green = 0.5 * ((1.0 + t.stretch).powi(2) - 1.0);
                (t.force_n / d.specimen.width_m / ((1.0 + t.stretch) * green)).max(1e-3)
            },
        )
    };
    let (weft, warp, bias) =
        (stiffness(Direction::Weft), stiffness(Direction::Warp), stiffness(Direction::Bias));
    let any = weft.or(warp).or(bias).unwrap_or(1.0);
    let (k_xx, k_yy) = (weft.unwrap_or(any), warp.unwrap_or(any));
    let mean = (k_xx * k_yy).sqrt();
    let area = if terms.area { 0.05 * mean } else { 0.0 };
    let largest = data.iter().flat_map(|d| d.targets.iter().map(|t| t.stretch)).fold(0.0, f64::max);
    let onset = 0.25 * ((1.0 + largest).powi(2) - 1.0);
    let most_compressed = data
        .iter()
        .filter(|d| d.direction != Direction::Bias)
        .flat_map(|d| d.targets.iter().filter_map(|t| t.compression))
        .fold(0.0, f64::max)
        .min(0.9);
    let jamming_onset = 0.125 * (1.0 - (1.0 - most_compressed).powi(2));
    StvkNeoHookean {
        k_xx,
        k_yy,
        k_xy: 0.2 * mean,
        k_ss: bias.map_or(0.4 * mean, |b| 0.5 * b),
        k_n1: area,
        k_n2: area,
        stiffening: terms.stiffening.then_some(Stiffening {
            k_weft: k_xx,
            k_warp: k_yy,
            onset: onset.max(1e-3),
        }),
        jamming: terms.jamming.then_some(Stiffening {
            k_weft: mean,
            k_warp: mean,
            onset: jamming_onset.max(1e-3),
        }),
    }
}

/// A fit problem: the data, the simulated swatches, and the prior on the encoded parameters.
pub(crate) struct Problem {
    pub data: Vec<DirectionData>,
    pub tests: Vec<SwatchTest>,
}

impl Problem {
    pub fn new(data: Vec<DirectionData>, spacing_m: f64) -> Self {
        let tests = data.iter().map(|d| SwatchTest::new(d.direction, d.specimen, spacing_m)).collect();
        Self { data, tests }
    }

    /// Every direction's swatch simulated at all its targets (`None` without equilibrium).
    pub fn simulate(&self, m: &StvkNeoHookean) -> Option<Vec<Vec<SimulatedReading>>> {
        self.tests.par_iter().zip(&self.data).map(|(test, d)| test.run(m, &d.stretches()).ok()).collect()
    }

    /// The fitted targets' residuals plus the prior `w (p - prior)`.
    fn with_prior(p: &[f64], prior: &[f64], mut r: Vec<f64>) -> Vec<f64> {
        r.extend(p.iter().zip(prior).map(|(a, b)| PRIOR_WEIGHT * (a - b)));
        r
    }

    /// (6.2) with the uniform test in place of the swatch, from `start`, the prior at `prior`:
    /// the encoded parameters.
    pub fn screen(
        &self,
        parameterization: &Parameterization,
        start: &[f64],
        prior: &[f64],
        lm: &LmSettings,
    ) -> Vec<f64> {
        let residuals = |p: &[f64]| {
            let m = parameterization.decode(p);
            let r = self.data.iter().flat_map(|d| {
                let (f, c) = d.uniform(&m);
                d.residuals(&f, &c, true)
            });
            Some(Self::with_prior(p, prior, r.collect()))
        };
        let settings = LmSettings { max_iterations: 200, difference_step: 1e-6, ..*lm };
        minimize(residuals, start, &settings).expect("the uniform test is evaluable everywhere").params
    }

    /// (6.2) with the clamped swatches simulated, from the encoded `start`, the prior at `prior`.
    pub fn refine(
        &self,
        parameterization: &Parameterization,
        start: &[f64],
        prior: &[f64],
        lm: &LmSettings,
    ) -> Option<LmReport> {
        let residuals =
            |p: &[f64]| Some(Self::with_prior(p, prior, self.fitted_residuals(&parameterization.decode(p))?));
        minimize(residuals, start, lm)
    }

    /// (6.2)'s weighted residuals of the fitted targets with the clamped swatches of `m`
    /// simulated (`None` without equilibrium).
    pub fn fitted_residuals(&self, m: &StvkNeoHookean) -> Option<Vec<f64>> {
        let per_direction = self.simulate(m)?;
        let r = self.data.iter().zip(&per_direction).flat_map(|(d, r)| {
            let (f, c) = forces_and_compressions(r);
            d.residuals(&f, &c, true)
        });
        Some(r.collect())
    }
}

/// A membrane fitted by [`fit_membrane`].
pub(crate) struct FittedMembrane {
    /// The material fitted to the uniform test (the screening).
    pub screening: StvkNeoHookean,
    /// The simulation-in-the-loop refinement.
    pub optimizer: LmReport,
    /// The fitted material.
    pub material: StvkNeoHookean,
    /// The parameters the data do not constrain (held at their start).
    pub unconstrained: Vec<String>,
}

/// Fit `terms` to the problem's fitted targets: screen on the uniform test from each of
/// `starts` (none: [`starting_material`]), then refine on the clamped swatches from the best
/// (lowest swatch cost) of the screened points and the starts, with the prior at the first
/// start. Several starts let an extension's onset leave a start where it does not act.
pub(crate) fn fit_membrane(
    problem: &Problem,
    terms: Terms,
    starts: &[StvkNeoHookean],
    lm: &LmSettings,
) -> Result<FittedMembrane, ShellFitError> {
    let default = [starting_material(&problem.data, terms)];
    let starts = if starts.is_empty() { &default[..] } else { starts };
    let parameterization = Parameterization {
        terms,
        fit_shear: problem.data.iter().any(|d| d.direction == Direction::Bias),
        held: starts[0],
    };
    let prior = parameterization.encode(&starts[0]);
    let encoded: Vec<Vec<f64>> = starts.iter().map(|m| parameterization.encode(m)).collect();
    let screened: Vec<Vec<f64>> =
        encoded.iter().map(|p| problem.screen(&parameterization, p, &prior, lm)).collect();
    let screening = parameterization.decode(&screened[0]);
    let cost = |p: &[f64]| {
        let r = problem.fitted_residuals(&parameterization.decode(p))?;
        Some(r.iter().map(|x| x * x).sum::<f64>())
    };
    let from = screened
        .into_iter()
        .chain(encoded)
        .filter_map(|p| cost(&p).map(|c| (c, p)))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, p)| p)
        .ok_or(ShellFitError::Start(starts[0]))?;
    let optimizer =
        problem.refine(&parameterization, &from, &prior, lm).ok_or(ShellFitError::Start(starts[0]))?;
    let material = parameterization.decode(&optimizer.params);
    Ok(FittedMembrane { screening, optimizer, material, unconstrained: parameterization.unconstrained() })
}
