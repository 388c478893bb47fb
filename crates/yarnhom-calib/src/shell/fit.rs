//! The shell fit of thesis Sec. 6.3: the anisotropic StVK + Neo-Hookean membrane (6.1) fitted
//! to a fabric's stretch tests by simulation in the loop (6.2), then turned into uniform
//! targets `{s, c, σ_s}` per direction (6.3) for the yarn-level fit.
//!
//! 1. Targets: the readings reduced to 6 stretches per direction ([`crate::data::targets`]).
//! 2. Screening: (6.2) with the uniform uniaxial test ([`crate::experiments::uniform`]) in place
//!    of the swatch, force = `σ_s` times the rest width. Cheap (no simulation), and the start
//!    of 3.
//! 3. Fit: (6.2) with the clamped swatch simulated to equilibrium at every target
//!    ([`crate::experiments::swatch`]), by Levenberg-Marquardt ([`super::membrane`]).
//! 4. Check: the fitted material re-simulated on a mesh twice as fine; the largest change of a
//!    simulated reading is reported (the thesis found 2% on twice-subdivided meshes).
//!
//! 5. Bending, when the set has bending tests: the thesis' anisotropic hinge bending fitted to
//!    them with the fitted membrane ([`super::bending`]), and its uniform targets `{κ, σ_κ}`.
//!
//! The errors are those of [`super::membrane`]: per direction, force and compression errors
//! over their measured scales.

use std::time::Instant;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use yarnhom_artifacts::report::Report;
use yarnhom_shell::{Stiffening, StvkNeoHookean};

use super::bending::{BendingFit, BendingModel, fit_bending};
use super::membrane::{
    COMPRESSION_SCALE_FLOOR, DirectionData, FitErrors, FittedMembrane, MembraneModel, Problem, ShellFitError,
    Terms, collect_errors, fit_membrane, starting_material,
};
use crate::cause::CauseId;
use crate::data::set::{Direction, MeasurementSet};
use crate::data::targets::{Target, TargetChoice, TargetPlan, targets};
use crate::experiments::bending_tests::{BendingTarget, BendingTest, BendingTests, BendingTestsError};
use crate::experiments::swatch::{SimulatedReading, SwatchTest};
use crate::experiments::uniform::{UniaxialPoint, uniaxial};
use crate::optimize::lm::{LmReport, LmSettings};

/// How to fit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct ShellFitSettings {
    /// Which targets.
    pub plan: TargetPlan,
    /// The membrane model.
    pub model: MembraneModel,
    /// Mesh edge length of the simulated swatch (m).
    pub spacing_m: f64,
    /// The simulation-in-the-loop iterations.
    pub lm: LmSettings,
}

impl Default for ShellFitSettings {
    fn default() -> Self {
        Self {
            plan: TargetPlan::default(),
            model: MembraneModel::StvkNeoHookean,
            spacing_m: 0.004,
            // Stop once an accepted step gains less than 0.01% of the cost: the errors have
            // settled to three digits by then (the tail of a flat valley costs minutes).
            lm: LmSettings { max_iterations: 80, cost_tolerance: 1e-4, ..LmSettings::default() },
        }
    }
}

/// What `--model auto` chose: the causes a diagnosis of the set confirmed, which of them the
/// membrane fits, and why the others are not.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct AutoModel {
    /// Every confirmed cause, in the diagnosis' order.
    pub confirmed: Vec<CauseId>,
    /// Those whose extension the membrane fits.
    pub fitted: Vec<CauseId>,
    /// The others, each with the reason.
    pub not_fitted: Vec<(CauseId, String)>,
    /// The diagnosis' held-out errors of the base and of the extended model.
    pub heldout_error: (f64, f64),
    /// The diagnosis' wall time (s).
    pub diagnosis_wall_time_s: f64,
}

/// A uniform target of the yarn-level fit (6.3).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct UniformTarget {
    /// Direction.
    pub direction: Direction,
    /// Whether the fabric was tested along it (else the state extrapolates the fit).
    pub measured: bool,
    /// `{s, c, σ_s}`.
    pub point: UniaxialPoint,
}

/// The result of a shell fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct ShellFit {
    /// Format tag of the JSON file.
    pub format: String,
    /// Layout version of the JSON file.
    pub version: u32,
    /// The fabric's name.
    pub fabric: String,
    /// The settings used.
    pub settings: ShellFitSettings,
    /// The targets.
    pub targets: Vec<Target>,
    /// How the targets were chosen, per direction (v2).
    #[serde(default)]
    pub target_choices: Vec<TargetChoice>,
    /// What `--model auto` chose (v2; absent for a fixed model).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub auto: Option<AutoModel>,
    /// The screening (uniform-test) fit.
    pub screening: StvkNeoHookean,
    /// Its errors against the clamped-swatch simulation.
    pub screening_errors: FitErrors,
    /// The fitted membrane (6.1).
    pub material: StvkNeoHookean,
    /// Parameters the data does not constrain (held at their starting value).
    pub unconstrained: Vec<String>,
    /// The simulated readings at the targets, in target order.
    pub simulated: Vec<SimulatedReading>,
    /// The fit's errors.
    pub errors: FitErrors,
    /// The largest relative change of a simulated force or compression on a mesh twice as fine
    /// (absent if the finer swatch found no equilibrium).
    pub mesh_refinement_change: Option<f64>,
    /// The optimizer's run.
    pub optimizer: LmReport,
    /// Vertices of the simulated swatch per direction.
    pub vertices: usize,
    /// Wall time (s).
    pub wall_time_s: f64,
    /// The uniform targets (6.3): every direction over the tested stretch range.
    pub uniform_targets: Vec<UniformTarget>,
    /// The bending fit (Sec. 6.3.2), when the set has bending tests.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bending: Option<ShellBending>,
}

/// The bending part of a shell fit (Sec. 6.3.2): the thesis' anisotropic hinge bending
/// `{k_weft, k_bias, k_warp}` fitted to the bending tests with the fitted membrane, and the
/// uniform bending targets `{κ, σ_κ}` per direction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct ShellBending {
    /// The fit (absent when it could not run; see `note`).
    pub fit: Option<BendingFit>,
    /// Why there is no fit.
    pub note: Option<String>,
    /// The uniform bending targets, 7 per direction.
    pub uniform_targets: Vec<BendingTarget>,
    /// The tests, in file order (pear loops, then cantilevers).
    pub tests: Vec<BendingTest>,
    /// Their measured readings.
    pub measured: Vec<f64>,
}

/// Uniform bending targets per direction.
const BENDING_TARGETS_PER_DIRECTION: usize = 7;

/// The bending fit of `set` with `membrane`, if the set has bending tests.
fn shell_bending(set: &MeasurementSet, membrane: &StvkNeoHookean, lm: &LmSettings) -> Option<ShellBending> {
    let tests = match BendingTests::of_set(set, |_| true) {
        Ok(tests) => tests,
        Err(BendingTestsError::NoTests) => return None,
        Err(e) => {
            return Some(ShellBending {
                fit: None,
                note: Some(e.to_string()),
                uniform_targets: Vec::new(),
                tests: Vec::new(),
                measured: Vec::new(),
            });
        }
    };
    let unfitted = |note: String| ShellBending {
        fit: None,
        note: Some(note),
        uniform_targets: Vec::new(),
        tests: tests.tests.clone(),
        measured: tests.measured.clone(),
    };
    Some(match fit_bending(&tests, membrane, BendingModel::Anisotropic, None, lm) {
        Ok(fit) => ShellBending {
            uniform_targets: tests
                .uniform_targets(membrane, &fit.bending, BENDING_TARGETS_PER_DIRECTION)
                .unwrap_or_default(),
            fit: Some(fit),
            note: None,
            tests: tests.tests.clone(),
            measured: tests.measured.clone(),
        },
        Err(e) => unfitted(e.to_string()),
    })
}

/// Format tag of [`ShellFit`] files.
pub const SHELL_FIT_FORMAT: &str = "yarnhom.shell-fit";

/// Layout version of [`ShellFit`] files (`schemas/shell-fit.v2.schema.json`; v2 adds
/// `target_choices` and the targets' standard errors).
pub const SHELL_FIT_VERSION: u32 = 2;

/// The JSON Schema of `shell-fit.json`.
pub fn shell_fit_schema() -> schemars::Schema {
    schemars::schema_for!(ShellFit)
}

impl Report for ShellFit {
    const FORMAT: &'static str = SHELL_FIT_FORMAT;
    const VERSION: u32 = SHELL_FIT_VERSION;

    /// Version 1 was written before the targets said how they were chosen: it reads with no
    /// `target_choices` and zero standard errors.
    fn migrate(version: u32, document: serde_json::Value) -> Result<Self, yarnhom_artifacts::Error> {
        if version != 1 {
            return Err(yarnhom_artifacts::Error::NoMigration {
                kind: SHELL_FIT_FORMAT.into(),
                found: version,
                supported: SHELL_FIT_VERSION,
            });
        }
        let fit: ShellFit = serde_json::from_value(document)
            .map_err(|e| yarnhom_artifacts::Error::Decode { what: "shell fit v1", message: e.to_string() })?;
        Ok(ShellFit { version: SHELL_FIT_VERSION, ..fit })
    }

    /// The material, the errors per direction (fitted and screening), the optimizer and the
    /// mesh check, then the bending fit.
    fn summary(&self) -> String {
        let m = &self.material;
        let mut lines = vec![
            format!("fabric {}: {}", self.fabric, self.settings.model.name()),
            format!(
                "  k_xx {:.4} k_xy {:.4} k_yy {:.4} k_ss {:.4} k_n1 {:.4} k_n2 {:.4} (J/m²)",
                m.k_xx, m.k_xy, m.k_yy, m.k_ss, m.k_n1, m.k_n2
            ),
        ];
        if let Some(j) = m.jamming {
            lines.push(format!(
                "  jamming past compressive Green strain {:.4}: k_weft {:.4} k_warp {:.4} (J/m²)",
                j.onset, j.k_weft, j.k_warp
            ));
        }
        lines.extend(self.target_choices.iter().map(|c| format!("  targets: {c}")));
        lines.extend(self.auto.as_ref().map(AutoModel::summary));
        if !self.unconstrained.is_empty() {
            lines.push(format!("  not constrained by the data (held): {}", self.unconstrained.join(", ")));
        }
        lines.extend(self.error_lines());
        let refinement = self.mesh_refinement_change.map_or("no equilibrium on the finer mesh".into(), |c| {
            format!("a mesh twice as fine changes a reading by {:.1}%", 100.0 * c)
        });
        lines.push(format!(
            "  {} Levenberg-Marquardt iterations, {} swatch simulations, {:.1} s; {} vertices per swatch; {refinement}",
            self.optimizer.iterations, self.optimizer.evaluations, self.wall_time_s, self.vertices,
        ));
        lines.extend(ShellBending::summary_lines(self.bending.as_ref()));
        lines.join("\n")
    }
}

impl AutoModel {
    /// The summary line of the choice.
    fn summary(&self) -> String {
        let names = |ids: &mut dyn Iterator<Item = &CauseId>| {
            let v: Vec<&str> = ids.map(|c| c.as_str()).collect();
            if v.is_empty() { "none".to_string() } else { v.join(", ") }
        };
        let mut line = format!(
            "  auto: the diagnosis confirmed {} (held-out error {:.4} -> {:.4}, {:.0} s); fitted: {}",
            names(&mut self.confirmed.iter()),
            self.heldout_error.0,
            self.heldout_error.1,
            self.diagnosis_wall_time_s,
            names(&mut self.fitted.iter())
        );
        for (id, why) in &self.not_fitted {
            line += &format!("; not fitted: {} ({why})", id.as_str());
        }
        line
    }
}

impl ShellFit {
    /// The errors table of the summary: per direction and their means, the screening
    /// material's in brackets.
    fn error_lines(&self) -> Vec<String> {
        let mut lines = vec![
            "  direction  force error  compression error  (the screening material, fitted to the uniform test)"
                .to_string(),
        ];
        for ((d, f, c), (_, sf, sc)) in
            self.errors.by_direction.iter().zip(&self.screening_errors.by_direction)
        {
            lines.push(format!(
                "  {:<9}  {:>11}  {:>17}  ({} / {})",
                d.as_str(),
                percent(Some(*f)),
                percent(*c),
                percent(Some(*sf)),
                percent(*sc)
            ));
        }
        lines.push(format!(
            "  mean       {:>11}  {:>17}  (thesis Sec. 6.3.1 average over 33 fabrics: 17.6% / 16.8%)",
            percent(Some(self.errors.force)),
            percent(self.errors.compression)
        ));
        lines
    }
}

impl ShellBending {
    /// The bending lines of a shell fit's summary: stiffnesses and errors per direction, or
    /// why there are none.
    fn summary_lines(bending: Option<&ShellBending>) -> Vec<String> {
        let Some(bending) = bending else { return vec!["bending: no bending tests in the set".into()] };
        let Some(fit) = &bending.fit else {
            return vec![format!(
                "bending: not fitted: {}",
                bending.note.as_deref().unwrap_or("unknown reason")
            )];
        };
        let b = &fit.bending;
        let mut lines = vec![
            format!(
                "bending (6.4): k_weft {:.3e} k_bias {:.3e} k_warp {:.3e} J ({} simulations of the {} tests)",
                b.k_weft,
                b.k_bias,
                b.k_warp,
                fit.evaluations,
                bending.tests.len()
            ),
            "  direction  pear-loop error  cantilever error".into(),
        ];
        for e in &fit.by_direction {
            lines.push(format!(
                "  {:<9}  {:>15}  {:>16}",
                e.direction.as_str(),
                percent(e.pear_loop),
                percent(e.cantilever)
            ));
        }
        lines.push(format!(
            "  all        {:>15}  (thesis Sec. 6.3.2 pear-loop average: 5.61%)",
            percent(Some(fit.error))
        ));
        lines
    }
}

/// A fraction as a percentage with one decimal, `-` when absent.
fn percent(x: Option<f64>) -> String {
    x.map_or("-".into(), |x| format!("{:.1}%", 100.0 * x))
}

/// Fit the membrane of `settings.model`, a fixed model, to `set`'s stretch tests
/// ([`crate::auto_model::fit_shell`] fits any model, `auto` included).
pub fn fit_shell(set: &MeasurementSet, settings: &ShellFitSettings) -> Result<ShellFit, ShellFitError> {
    let terms = settings.model.terms().ok_or(ShellFitError::Auto)?;
    fit_shell_with(set, settings, terms, &[], None)
}

/// Fit the membrane with `terms` from `starts` (none: the starting material, nested for the
/// jamming), recording `auto`'s choice.
pub(crate) fn fit_shell_with(
    set: &MeasurementSet,
    settings: &ShellFitSettings,
    terms: Terms,
    starts: &[StvkNeoHookean],
    auto: Option<AutoModel>,
) -> Result<ShellFit, ShellFitError> {
    let started = Instant::now();
    let chosen = targets(set, &settings.plan)?;
    let targets = chosen.targets;
    let problem = Problem::new(DirectionData::group(set, &targets, |_| true), settings.spacing_m);
    let start = if !starts.is_empty() {
        starts.to_vec()
    } else if terms.jamming {
        // Nested: from the (6.1) fit, with the jamming a thousandth of its starting size.
        let plain = fit_membrane(&problem, Terms { jamming: false, ..terms }, &[], &settings.lm)?.material;
        let seed = starting_material(&problem.data, terms);
        vec![StvkNeoHookean { jamming: seed.jamming.map(Stiffening::faint), ..plain }]
    } else {
        Vec::new()
    };
    let FittedMembrane { screening, optimizer, material, unconstrained } =
        fit_membrane(&problem, terms, &start, &settings.lm)?;
    let screening_simulated = problem.simulate(&screening).ok_or(ShellFitError::Start(screening))?;
    let fitted = problem.simulate(&material).ok_or(ShellFitError::Start(material))?;
    let finer = Problem::new(DirectionData::group(set, &targets, |_| true), 0.5 * settings.spacing_m);
    let refined = finer.simulate(&material);
    let data = &problem.data;
    Ok(ShellFit {
        format: SHELL_FIT_FORMAT.into(),
        version: SHELL_FIT_VERSION,
        fabric: set.fabric.name.clone(),
        settings: *settings,
        screening,
        screening_errors: collect_errors(data, &screening_simulated, true),
        material,
        unconstrained,
        errors: collect_errors(data, &fitted, true),
        mesh_refinement_change: refined.map(|r| largest_relative_change(&fitted, &r)),
        optimizer,
        vertices: problem.tests.iter().map(SwatchTest::vertex_count).max().unwrap_or(0),
        wall_time_s: started.elapsed().as_secs_f64(),
        uniform_targets: uniform_targets(&material, data, settings.plan.per_direction),
        bending: shell_bending(set, &material, &settings.lm),
        simulated: fitted.into_iter().flatten().collect(),
        targets,
        target_choices: chosen.choices,
        auto,
    })
}

fn largest_relative_change(a: &[Vec<SimulatedReading>], b: &[Vec<SimulatedReading>]) -> f64 {
    let mut largest: f64 = 0.0;
    for (ra, rb) in a.iter().zip(b) {
        let force_scale = ra.iter().fold(0.0_f64, |m, r| m.max(r.force_n.abs())).max(1e-12);
        let compression_scale = ra.iter().fold(COMPRESSION_SCALE_FLOOR, |m, r| m.max(r.compression.abs()));
        for (x, y) in ra.iter().zip(rb) {
            largest = largest.max((x.force_n - y.force_n).abs() / force_scale);
            largest = largest.max((x.compression - y.compression).abs() / compression_scale);
        }
    }
    largest
}

/// (6.3) along every direction at `n` stretches up to the largest tested stretch of that
/// direction (directions not tested: up to the largest stretch of any).
fn uniform_targets(material: &StvkNeoHookean, data: &[DirectionData], n: usize) -> Vec<UniformTarget> {
    let largest_of = |d: &DirectionData| d.targets.iter().map(|t| t.stretch).fold(0.0, f64::max);
    let overall = data.iter().map(largest_of).fold(0.0, f64::max);
    Direction::ALL
        .into_iter()
        .flat_map(|direction| {
            let tested = data.iter().find(|d| d.direction == direction);
            let s_max = tested.map_or(overall, largest_of);
            (1..=n).map(move |i| UniformTarget {
                direction,
                measured: tested.is_some(),
                point: uniaxial(material, direction, s_max * i as f64 / n as f64),
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiments::synth::{GroundTruth, SynthPlan, synthesize};

    fn truth() -> StvkNeoHookean {
        StvkNeoHookean {
            k_xx: 60.0,
            k_xy: 12.0,
            k_yy: 25.0,
            k_ss: 9.0,
            k_n1: 4.0,
            k_n2: 1.5,
            stiffening: None,
            jamming: None,
        }
    }

    fn settings() -> ShellFitSettings {
        ShellFitSettings {
            plan: TargetPlan { per_direction: 5, ..TargetPlan::default() },
            spacing_m: 0.01,
            ..ShellFitSettings::default()
        }
    }

    #[test]
    fn the_fit_recovers_the_membrane_behind_clean_clamped_swatch_data() {
        let plan = SynthPlan { spacing_m: 0.01, ..SynthPlan::new("truth", 0.3) };
        let set = synthesize(&GroundTruth::of_membrane(truth()), &plan).expect("simulates");
        let fit = fit_shell(&set, &settings()).expect("fits");
        assert!(
            fit.errors.force < 0.01 && fit.errors.compression.expect("measured") < 0.02,
            "{:?}",
            fit.errors
        );
        // The data stops at 5 N or 30% stretch; the stiffnesses that dominate it come back.
        for (got, want, name) in [(fit.material.k_xx, 60.0, "k_xx"), (fit.material.k_yy, 25.0, "k_yy")] {
            assert!((got / want - 1.0).abs() < 0.05, "{name}: {got} vs {want} ({:?})", fit.material);
        }
        assert!(fit.unconstrained.is_empty());
        // The uniform targets cover every direction; the screening fit of the uniform test is
        // worse on the clamped swatch than the simulation-in-the-loop fit.
        assert_eq!(fit.uniform_targets.len(), 3 * 5);
        assert!(fit.screening_errors.force >= fit.errors.force);
    }

    #[test]
    fn without_bias_data_the_shear_stiffness_is_held_and_reported() {
        let plan = SynthPlan {
            directions: vec![Direction::Weft, Direction::Warp],
            max_stretch: vec![0.3, 0.3],
            spacing_m: 0.01,
            ..SynthPlan::new("no bias", 0.3)
        };
        let set = synthesize(&GroundTruth::of_membrane(truth()), &plan).expect("simulates");
        let fit =
            fit_shell(&set, &ShellFitSettings { model: MembraneModel::Stvk, ..settings() }).expect("fits");
        assert_eq!(fit.unconstrained, vec!["k_ss".to_string()]);
        assert_eq!((fit.material.k_n1, fit.material.k_n2), (0.0, 0.0));
        assert!(fit.uniform_targets.iter().any(|u| u.direction == Direction::Bias && !u.measured));
    }
}
