//! The yarn-level confirmation of a diagnosed cause ([`yarnhom_calib::yarn::confirm`]) on targets
//! simulated from hidden yarn models on the generated stockinette: a yarn that is soft and then
//! stiff (biphasic stretch, (6.5)) must confirm `biphasic-stretch` (with a thorough search: a
//! reduced one, swarm 16 x 3 and Gauss-Newton 8, stays in the base's basin, where the stiff
//! linear yarn is compensated by softer contacts), and a linear yarn must not.

use yarnhom_calib::cause::CauseId;
use yarnhom_calib::data::set::Direction;
use yarnhom_calib::optimize::swarm::SwarmSettings;
use yarnhom_calib::yarn::confirm::{CONFIRM_RATIO, SearchSize, YarnConfirmation, confirm};
use yarnhom_calib::yarn::objective::COMFORT_FORCE_N;
use yarnhom_calib::yarn::params::{YarnBasis, YarnMechanisms, YarnParams};
use yarnhom_calib::yarn::problem::{RestShapeSettings, TargetSource, YarnProblem};
use yarnhom_calib::yarn::settings::YarnFitSettings;

/// The problem of recovering `truth` on the generated stockinette, weft and warp to 50%.
fn problem(truth: impl Fn(&YarnBasis) -> YarnParams) -> YarnProblem {
    let params = yarnhom_pattern::GeneratorParams::defaults_for("stockinette").expect("built in");
    let pattern = yarnhom_pattern::generate("stockinette", &params).expect("generates");
    let basis = YarnBasis::of_pattern(&pattern, Some(200.0), 1180.0);
    YarnProblem {
        source: TargetSource::Yarn(truth(&basis)),
        basis,
        pattern,
        directions: vec![(Direction::Weft, 0.5, 0.06), (Direction::Warp, 0.5, 0.06)],
        rest: RestShapeSettings { max_length_change: 0.2, max_resets: 8 },
        comfort_force_n: COMFORT_FORCE_N,
    }
}

/// A linear yarn (bending 3x its base, contact at `R_est` with its base stiffness).
fn linear(basis: &YarnBasis) -> YarnParams {
    basis.with_mechanisms(YarnMechanisms::BASE).params(&[0.5, 1.0, 0.0])
}

/// The same yarn 10x softer up to 5% yarn strain.
fn biphasic(basis: &YarnBasis) -> YarnParams {
    let p = linear(basis);
    YarnParams { k_s1_n: p.k_s2_n / 10.0, eps_bar: 0.05, ..p }
}

/// The confirmation's fit settings: `calibrate diagnose --budget thorough`'s, or a small search.
fn settings(thorough: bool) -> YarnFitSettings {
    if thorough {
        return SearchSize::Full.settings();
    }
    YarnFitSettings {
        swarm: SwarmSettings { particles: 8, generations: 2, ..SwarmSettings::default() },
        swarm_targets: 4,
        local_targets: 5,
        local_budget: 4,
        ..SearchSize::Reduced.settings()
    }
}

fn run(name: &str, truth: fn(&YarnBasis) -> YarnParams, thorough: bool) -> YarnConfirmation {
    let started = std::time::Instant::now();
    let c = confirm(&problem(truth), CauseId::BiphasicStretch, &settings(thorough), &|_| {}).expect("fits");
    eprintln!(
        "{name}: {:.1} s, {} swarm evaluations; base {:.4}/{:.4} ({} local ev.) at {:?}; extended {:.4}/{:.4} ({} local ev.) at {:?}: {}",
        started.elapsed().as_secs_f64(),
        c.swarm_evaluations,
        c.base.error,
        c.base.heldout_error,
        c.base.evaluations,
        c.base.coordinates,
        c.extended.error,
        c.extended.heldout_error,
        c.extended.evaluations,
        c.extended.coordinates,
        c.verdict
    );
    assert_eq!(c.base.mechanisms, YarnMechanisms::BASE);
    assert!(c.extended.mechanisms.biphasic_stretch);
    assert_eq!(c.base.params.k_s1_n, c.base.params.k_s2_n, "the base yarn is linear");
    assert_eq!(c.extended.coordinates.len(), c.base.coordinates.len() + 2, "k_s1 and the onset added");
    c
}

#[test]
fn a_linear_hidden_yarn_is_not_credited_to_biphasic_stretch() {
    // The base family holds the truth: whatever the search finds, the biphasic stretch must
    // not be credited with it.
    let c = run("linear", linear, false);
    assert!(!c.confirmed, "{}", c.verdict);
}

#[test]
#[ignore = "a thorough yarn-level search: 26 min on 2 cores (held-out 0.102 -> 0.0735, confirmed)"]
fn a_hidden_biphasic_yarn_is_confirmed_by_a_thorough_search() {
    let c = run("biphasic", biphasic, true);
    assert!(c.confirmed, "{}", c.verdict);
    assert!(c.extended.heldout_error < CONFIRM_RATIO * c.base.heldout_error);
}
