//! The decision rule of a diagnosis ([`DecisionRule`]): which candidates are causes, step by
//! step, and the evidence that says why, in the rule's own numbers.

use super::report::{ModelResult, SignatureScore};
use crate::cause::CauseId;

/// When a candidate explains a discrepancy, and when there is none to explain.
///
/// The tests compare mean squares, since independent errors add in variance: a model's
/// held-out error `h` is an RMS over the held-out residuals, and a model that is right still
/// leaves `h² ≈ σ²`, the track's noise `σ` squared. A candidate is judged against the model it
/// extends (its track's base, or on the stretch track the model of the causes confirmed so far).
/// It is *significant* when it lowers the held-out mean square by more than
/// [`noise_margin`](Self::noise_margin) noise variances, `h_model² - h² > noise_margin σ²`, and
/// its Akaike criterion on the fitted targets by more than
/// [`criterion_drop`](Self::criterion_drop). It *explains its signature* (what its cause changes
/// in the data: the paired load/unload difference for friction, the change of slope of the force
/// for biphasic stretch, the contraction curve for area preservation, the change of slope of the
/// contraction for two-phase contact, the bending readings for the bending causes; error `e`,
/// noise `σ_e`) when the signature shows an effect, `e_before² - σ_e² > noise_margin σ_e²`,
/// the candidate removes more than that, `e_before² - e_after² > noise_margin σ_e²`, and it
/// leaves at most [`signature_left`](Self::signature_left) of the signature's excess mean square,
/// `⟨e_after² - σ_e²⟩₊ ≤ signature_left (e_before² - σ_e²)`. A candidate that is significant and
/// explains its signature *passes*; of those, the one with the lowest held-out error is added,
/// and the others are tested again on top of it. Without a confirmed cause, the verdict is
/// `none` when every track's base has `h² ≤ none_noise_multiple σ²` or `h ≤ none_floor`, else
/// `unexplained`; with causes, a held-out error still above that is reported as an unexplained
/// remainder.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DecisionRule {
    /// A candidate must lower the held-out mean square by more than this many noise variances
    /// (1): what it removes must exceed what the noise alone puts there. Its signature must
    /// show, and lose, as many of its own noise variances.
    pub noise_margin: f64,
    /// The Akaike criterion `n ln(RSS/n) + 2k` on the fitted targets must drop by more than
    /// this (4): the usual threshold of considerably less support for the simpler model, so an
    /// extension's parameters must pay for themselves on the data it was fitted to.
    pub criterion_drop: f64,
    /// A candidate explains its signature only if it leaves at most this fraction of the
    /// signature's excess mean square above its noise (0.5): a cause must fix its own effect,
    /// whatever else the model still misses.
    pub signature_left: f64,
    /// Without a confirmed cause, the verdict is `none` when every base's held-out mean square
    /// is within this many noise variances (2) ...
    pub none_noise_multiple: f64,
    /// ... or its held-out error within this (0.03), whichever is larger: sets so clean that
    /// their noise is far below any model's reach still have no discrepancy worth naming.
    pub none_floor: f64,
}

impl Default for DecisionRule {
    /// The rule of `calibrate diagnose`.
    fn default() -> Self {
        Self {
            noise_margin: 1.0,
            criterion_drop: 4.0,
            signature_left: 0.5,
            none_noise_multiple: 2.0,
            none_floor: 0.03,
        }
    }
}

impl DecisionRule {
    /// The rule as a Markdown table, a row per threshold (the table `docs/methods.md` holds).
    pub fn markdown(&self) -> String {
        let rows = [
            (
                "noise_margin",
                self.noise_margin,
                "a candidate lowers the held-out mean square of the model it extends by more than this many noise variances; its signature's mean square exceeds its noise's, and drops, by as many of the signature's noise variances",
            ),
            (
                "criterion_drop",
                self.criterion_drop,
                "its Akaike criterion on the fitted targets drops by more than this",
            ),
            (
                "signature_left",
                self.signature_left,
                "it leaves at most this fraction of its signature's excess mean square above the noise",
            ),
            (
                "none_noise_multiple",
                self.none_noise_multiple,
                "no cause confirmed: `none` when every base's held-out mean square is within this many noise variances ...",
            ),
            (
                "none_floor",
                self.none_floor,
                "... or within this held-out error, whichever is larger; else `unexplained` (with causes: an unexplained remainder)",
            ),
        ];
        let mut table = "| `DecisionRule` field | default | test |\n|---|---|---|\n".to_string();
        for (field, value, test) in rows {
            table += &format!("| `{field}` | {value} | {test} |\n");
        }
        table
    }

    /// Whether `c` is significant against `model` (the model it extends) at track noise `noise`.
    pub(super) fn is_significant(&self, model: &ModelResult, noise: f64, c: &ModelResult) -> bool {
        let (_, heldout, criterion) = c.scores();
        let (_, model_heldout, model_criterion) = model.scores();
        model_heldout.powi(2) - heldout.powi(2) > self.noise_margin * noise * noise
            && criterion < model_criterion - self.criterion_drop
    }

    /// Whether `c` explains its signature.
    pub(super) fn explains_signature(&self, c: &ModelResult) -> bool {
        c.signature.as_ref().is_some_and(|s| {
            let margin = self.noise_margin * s.noise * s.noise;
            self.signature_shows_an_effect(s)
                && s.before.powi(2) - s.after.powi(2) > margin
                && self.signature_excess_left(s) <= self.signature_left
        })
    }

    /// Whether the signature's mean square before a candidate exceeds its noise's by more than
    /// `noise_margin` noise variances.
    fn signature_shows_an_effect(&self, s: &SignatureScore) -> bool {
        s.before.powi(2) - s.noise.powi(2) > self.noise_margin * s.noise.powi(2)
    }

    /// The fraction of the signature's excess mean square above its noise that a candidate
    /// leaves.
    pub(super) fn signature_excess_left(&self, s: &SignatureScore) -> f64 {
        (s.after.powi(2) - s.noise.powi(2)).max(0.0) / (s.before.powi(2) - s.noise.powi(2)).max(1e-300)
    }

    /// Whether `c` passes against `model` at `noise`.
    pub(super) fn passes(&self, model: &ModelResult, noise: f64, c: &ModelResult) -> bool {
        c.testable && self.is_significant(model, noise, c) && self.explains_signature(c)
    }

    /// The candidate to add among `candidates` (tested against `model` at `noise`): the passing
    /// one with the lowest held-out error.
    pub(super) fn best<'a>(
        &self,
        model: &ModelResult,
        noise: f64,
        candidates: &'a [ModelResult],
    ) -> Option<&'a ModelResult> {
        candidates
            .iter()
            .filter(|c| self.passes(model, noise, c))
            .min_by(|a, b| a.scores().1.total_cmp(&b.scores().1))
    }

    /// The held-out error within which a track has no discrepancy worth naming.
    pub(super) fn within_noise(&self, heldout: f64, noise: f64) -> bool {
        heldout <= self.noise_limit(noise)
    }

    /// The held-out error within which a track has no discrepancy worth naming:
    /// `max(√none_noise_multiple σ, none_floor)`.
    fn noise_limit(&self, noise: f64) -> f64 {
        (self.none_noise_multiple.sqrt() * noise).max(self.none_floor)
    }

    /// One evidence line per tested candidate of a step against `model`.
    pub(super) fn step_evidence(
        &self,
        step: usize,
        model: &ModelResult,
        noise: f64,
        candidates: &[ModelResult],
    ) -> Vec<String> {
        let (_, model_heldout, model_criterion) = model.scores();
        candidates
            .iter()
            .filter(|c| c.testable)
            .map(|c| {
                let (_, heldout, criterion) = c.scores();
                let signature = c.signature.as_ref().map_or(String::new(), |s| {
                    let left = match self.signature_shows_an_effect(s) {
                        true => format!("{:.0}% of its excess left", 100.0 * self.signature_excess_left(s)),
                        false => "no effect above its noise".into(),
                    };
                    format!("; {} {:.4} -> {:.4} (noise {:.4}, {left})", s.measure, s.before, s.after, s.noise)
                });
                let verdict = match (self.is_significant(model, noise, c), self.explains_signature(c)) {
                    (true, true) => "passes",
                    (true, false) => "significant, but does not explain its signature",
                    (false, true) => "explains its signature, but is not significant",
                    (false, false) => "fails",
                };
                format!(
                    "step {step}: {}: held-out error {heldout:.4} ({:+.1}% vs {}), criterion {:+.1}{signature}: {verdict}",
                    c.id,
                    100.0 * (heldout / model_heldout - 1.0),
                    model.id,
                    criterion - model_criterion,
                )
            })
            .collect()
    }

    /// The sentence of a verdict without a confirmed cause.
    pub(super) fn verdict(&self, cause: CauseId) -> String {
        let within = self.within_words();
        match cause {
            CauseId::None => format!(
                "no candidate passes the tests (held-out mean square lower by more than {} noise variances, \
                 criterion lower by {}, its signature's excess mean square at most {} left), and every \
                 base's held-out error is within {within}",
                self.noise_margin,
                self.criterion_drop,
                fraction_in_words(self.signature_left)
            ),
            CauseId::Unexplained => {
                format!("no candidate passes the tests, and a base's held-out error exceeds {within}")
            }
            _ => format!("confirmed: {}", cause.as_str()),
        }
    }

    /// How the verdicts word the noise limit.
    fn within_words(&self) -> String {
        format!("max(√{} x noise, {}) of its track", self.none_noise_multiple, self.none_floor)
    }

    /// The sentence on what the confirmed causes leave, at held-out error `heldout`.
    pub(super) fn remainder(&self, heldout: f64, noise: f64) -> String {
        let limit = self.noise_limit(noise);
        let within = self.within_words();
        if heldout <= limit {
            format!(
                "the confirmed causes leave a held-out error of {heldout:.4}, within {within} ({limit:.4})"
            )
        } else {
            format!(
                "the confirmed causes leave a held-out error of {heldout:.4}, above {within} ({limit:.4}): the rest is unexplained by the catalog"
            )
        }
    }
}

/// A fraction as the evidence words it: `half`, else a whole percentage.
fn fraction_in_words(fraction: f64) -> String {
    if fraction == 0.5 { "half".into() } else { format!("{:.0}%", 100.0 * fraction) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_methods_documentation_states_the_rule_the_code_applies() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/methods.md");
        let doc = std::fs::read_to_string(path).expect("docs/methods.md");
        let table = DecisionRule::default().markdown();
        assert!(
            doc.contains(&table),
            "docs/methods.md must hold DecisionRule::default().markdown():\n{table}"
        );
    }

    fn model(id: &str, heldout: f64, criterion: f64, signature: Option<(f64, f64, f64)>) -> ModelResult {
        ModelResult {
            id: id.into(),
            testable: true,
            note: None,
            params: Vec::new(),
            parameter_count: 4,
            error: Some(heldout),
            heldout_error: Some(heldout),
            criterion: Some(criterion),
            signature: signature.map(|(before, after, noise)| SignatureScore {
                measure: "the test signature".into(),
                before,
                after,
                noise,
            }),
        }
    }

    #[test]
    fn a_candidate_passes_by_its_own_signature_whatever_else_is_left() {
        let rule = DecisionRule::default();
        let base = model("base", 0.20, 0.0, None);
        // Removes a tenth of the held-out error (the rest is another misfit) but fixes its own
        // signature: it passes.
        let friction = model("friction-hysteresis", 0.18, -10.0, Some((0.15, 0.02, 0.01)));
        assert!(rule.passes(&base, 0.005, &friction));
        // Removes more, but leaves most of its signature: it does not.
        let area = model("area-preservation", 0.12, -30.0, Some((0.15, 0.13, 0.01)));
        assert!(rule.is_significant(&base, 0.005, &area) && !rule.explains_signature(&area));
        // A signature at its noise has no effect to explain.
        let faint = model("biphasic-stretch", 0.15, -30.0, Some((0.012, 0.001, 0.01)));
        assert!(!rule.explains_signature(&faint));
        // Within the noise margin (0.2² - 0.18² = 0.0076 < 0.1²), or without the criterion's
        // drop, it is not significant.
        assert!(!rule.is_significant(&base, 0.1, &friction));
        assert!(!rule.is_significant(&base, 0.005, &model("x", 0.18, -3.0, None)));
        let candidates = [area, friction.clone()];
        assert_eq!(rule.best(&base, 0.005, &candidates), Some(&friction));
    }

    #[test]
    fn the_default_rule_words_its_verdicts() {
        let rule = DecisionRule::default();
        assert_eq!(
            rule.verdict(CauseId::None),
            "no candidate passes the tests (held-out mean square lower by more than 1 noise variances, \
             criterion lower by 4, its signature's excess mean square at most half left), and every \
             base's held-out error is within max(√2 x noise, 0.03) of its track"
        );
        assert_eq!(
            rule.verdict(CauseId::Unexplained),
            "no candidate passes the tests, and a base's held-out error exceeds max(√2 x noise, 0.03) of its track"
        );
        assert!(rule.remainder(0.1, 0.01).ends_with("the rest is unexplained by the catalog"));
        assert!(rule.remainder(0.02, 0.01).contains("within"));
        // A large noise: the base's 0.27 exceeds √2 x 0.176; a candidate at 0.137 removes
        // 0.054 of mean square, more than the noise variance 0.031.
        assert!(!rule.within_noise(0.27, 0.176));
        let base = model("base", 0.27, 0.0, None);
        assert!(rule.is_significant(&base, 0.176, &model("two-phase-contact", 0.137, -16.0, None)));
    }
}
