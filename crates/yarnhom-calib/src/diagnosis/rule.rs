//! The decision rule of a diagnosis ([`DecisionRule`]): which candidate, if any, is the cause,
//! and the evidence that says why, in the rule's own numbers.

use super::report::{BendingTrack, Gain, ModelResult};
use crate::cause::CauseId;

/// When a candidate explains a discrepancy, and when there is none to explain.
///
/// A candidate is judged against its track's base and noise (the bending base for the bending
/// causes, else the stretch base). It is *significant* when its held-out error is below
/// [`heldout_ratio`](Self::heldout_ratio) of the base's and below it by more than
/// [`noise_margin`](Self::noise_margin) times the noise, and its Akaike criterion on the fitted
/// targets is lower by more than [`criterion_drop`](Self::criterion_drop); it *passes* when it
/// also leaves at most [`max_excess_left`](Self::max_excess_left) of the base's held-out error
/// above the noise (a significant candidate that leaves more is a partial explanation, not the
/// cause). Of the passing candidates, the one with the lowest held-out error relative to its
/// base is the cause. Without one, the cause is `none` when every track's base held-out error
/// is within `max(none_noise_multiple x noise, none_floor)`, else `unexplained`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DecisionRule {
    /// A candidate's held-out error must be below this fraction of its base's (0.75): an
    /// extension must remove a quarter of the error on targets it was not fitted to, not a
    /// sliver that any extra parameter would buy.
    pub heldout_ratio: f64,
    /// ... and below the base's by more than this many times the track's noise (2): a gain
    /// within twice the noise could be the held-out targets' own scatter.
    pub noise_margin: f64,
    /// The Akaike criterion `n ln(RSS/n) + 2k` on the fitted targets must drop by more than
    /// this (4): the usual threshold of considerably less support for the simpler model, so an
    /// extension's parameters must pay for themselves on the data it was fitted to.
    pub criterion_drop: f64,
    /// A significant candidate fixes its track's discrepancy only if it leaves at most this
    /// fraction of the base's held-out error above the noise (0.5); else it is reported as a
    /// partial explanation.
    pub max_excess_left: f64,
    /// Without an accepted candidate, the cause is `none` when every base's held-out error is
    /// within this many times its track's noise (3) ...
    pub none_noise_multiple: f64,
    /// ... or within this held-out error (0.03), whichever is larger: sets so clean that
    /// their noise is far below any model's reach still have no discrepancy worth naming.
    pub none_floor: f64,
}

impl Default for DecisionRule {
    /// The rule of `calibrate diagnose`.
    fn default() -> Self {
        Self {
            heldout_ratio: 0.75,
            noise_margin: 2.0,
            criterion_drop: 4.0,
            max_excess_left: 0.5,
            none_noise_multiple: 3.0,
            none_floor: 0.03,
        }
    }
}

impl DecisionRule {
    /// The rule as a Markdown table, a row per threshold (the table `docs/methods.md` holds).
    pub fn markdown(&self) -> String {
        let rows = [
            (
                "heldout_ratio",
                self.heldout_ratio,
                "a candidate's held-out error is below this fraction of its track base's",
            ),
            (
                "noise_margin",
                self.noise_margin,
                "... and below it by more than this many times the track's noise",
            ),
            (
                "criterion_drop",
                self.criterion_drop,
                "its Akaike criterion on the fitted targets drops by more than this",
            ),
            (
                "max_excess_left",
                self.max_excess_left,
                "it leaves at most this fraction of the base's held-out error above the noise (else: a partial explanation)",
            ),
            (
                "none_noise_multiple",
                self.none_noise_multiple,
                "no candidate passing: `none` when every base's held-out error is within this many times its noise ...",
            ),
            (
                "none_floor",
                self.none_floor,
                "... or within this held-out error, whichever is larger; else `unexplained`",
            ),
        ];
        let mut table = "| `DecisionRule` field | default | test |\n|---|---|---|\n".to_string();
        for (field, value, test) in rows {
            table += &format!("| `{field}` | {value} | {test} |\n");
        }
        table
    }
}

/// What a candidate is judged against: the stretch track's base and noise, and the bending
/// track when the set has one.
pub(super) struct Tracks<'a> {
    pub base: &'a ModelResult,
    pub noise: f64,
    pub bending: Option<&'a BendingTrack>,
}

impl Tracks<'_> {
    /// The base and noise of candidate `c`'s track.
    fn of(&self, c: &ModelResult) -> (&ModelResult, f64) {
        let is_bending =
            c.id == CauseId::AnisotropicBending.as_str() || c.id == CauseId::RestCurvature.as_str();
        match (self.bending, is_bending) {
            (Some(t), true) => (&t.base, t.noise),
            _ => (self.base, self.noise),
        }
    }

    /// Candidate `c`'s held-out error over its base's.
    fn relative(&self, c: &ModelResult) -> f64 {
        c.scores().1 / self.of(c).0.scores().1
    }

    /// Every track's base held-out error and noise.
    fn bases(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        std::iter::once((self.base.scores().1, self.noise))
            .chain(self.bending.iter().map(|t| (t.base.scores().1, t.noise)))
    }
}

/// The rule applied to the candidates.
pub(super) struct Choice<'a> {
    /// The candidates that pass the held-out and Akaike tests.
    pub significant: Vec<&'a ModelResult>,
    /// Those that also fix their track's discrepancy.
    pub passing: Vec<&'a ModelResult>,
    /// The cause.
    pub cause: CauseId,
    /// The accepted candidate, if one is.
    pub extended: Option<&'a ModelResult>,
}

impl Choice<'_> {
    /// The held-out errors before (the accepted candidate's base's, else the stretch base's) and
    /// after (the accepted candidate's, else the stretch base's).
    pub(super) fn gain(&self, tracks: &Tracks<'_>) -> Gain {
        let base_heldout = tracks.base.scores().1;
        Gain {
            heldout_error_before: self.extended.map_or(base_heldout, |c| tracks.of(c).0.scores().1),
            heldout_error_after: self.extended.map_or(base_heldout, |e| e.scores().1),
        }
    }
}

impl DecisionRule {
    /// The cause among `candidates`.
    pub(super) fn choose<'a>(&self, tracks: &Tracks<'_>, candidates: &'a [ModelResult]) -> Choice<'a> {
        let significant: Vec<&ModelResult> =
            candidates.iter().filter(|c| c.testable).filter(|c| self.is_significant(tracks, c)).collect();
        let passing: Vec<&ModelResult> = significant
            .iter()
            .copied()
            .filter(|c| self.excess_left(tracks, c) <= self.max_excess_left)
            .collect();
        let accepted =
            passing.iter().min_by(|a, b| tracks.relative(a).total_cmp(&tracks.relative(b))).copied();
        let cause = match accepted {
            Some(c) => CauseId::CANDIDATES.into_iter().find(|i| i.as_str() == c.id).expect("a catalog id"),
            None if self.bases_within_noise(tracks) => CauseId::None,
            None => CauseId::Unexplained,
        };
        Choice { significant, passing, cause, extended: accepted }
    }

    /// The held-out and Akaike tests against `c`'s track.
    fn is_significant(&self, tracks: &Tracks<'_>, c: &ModelResult) -> bool {
        let (track_base, track_noise) = tracks.of(c);
        let (_, heldout, criterion) = c.scores();
        let (_, base_heldout, base_criterion) = track_base.scores();
        heldout < self.heldout_ratio * base_heldout
            && heldout < base_heldout - self.noise_margin * track_noise
            && criterion < base_criterion - self.criterion_drop
    }

    /// The fraction of its base's held-out error above the noise that `c` leaves (0: down to
    /// the noise; 1: nothing removed).
    fn excess_left(&self, tracks: &Tracks<'_>, c: &ModelResult) -> f64 {
        let (track_base, noise) = tracks.of(c);
        (c.scores().1 - noise).max(0.0) / (track_base.scores().1 - noise).max(1e-300)
    }

    /// Whether every track's base is within `max(none_noise_multiple x noise, none_floor)`.
    fn bases_within_noise(&self, tracks: &Tracks<'_>) -> bool {
        tracks
            .bases()
            .all(|(heldout, noise)| heldout <= (self.none_noise_multiple * noise).max(self.none_floor))
    }

    /// The numbers behind `choice`: the bases, every tested candidate against its base, the
    /// partial explanations, the verdict and the other passing candidates.
    pub(super) fn evidence(
        &self,
        tracks: &Tracks<'_>,
        candidates: &[ModelResult],
        choice: &Choice<'_>,
    ) -> Vec<String> {
        let mut evidence = base_evidence(tracks);
        for c in candidates.iter().filter(|c| c.testable) {
            let (_, heldout, criterion) = c.scores();
            let (track_base, _) = tracks.of(c);
            evidence.push(format!(
                "{}: held-out error {heldout:.4} ({:+.1}% vs {}), criterion {:+.1} vs {}",
                c.id,
                100.0 * (tracks.relative(c) - 1.0),
                track_base.id,
                criterion - track_base.scores().2,
                track_base.id
            ));
        }
        for c in choice.significant.iter().filter(|c| self.excess_left(tracks, c) > self.max_excess_left) {
            evidence.push(format!(
                "{}: significant, but it leaves {:.0}% of its base's held-out error above the noise (more than {:.0}%): a partial explanation",
                c.id,
                100.0 * self.excess_left(tracks, c),
                100.0 * self.max_excess_left
            ));
        }
        evidence.push(self.verdict(choice.cause));
        let also: Vec<&str> =
            choice.passing.iter().map(|c| c.id.as_str()).filter(|c| *c != choice.cause.as_str()).collect();
        if !also.is_empty() {
            evidence.push(format!(
                "also passing: {} (a combination may explain more; only single causes are screened)",
                also.join(", ")
            ));
        }
        evidence
    }

    /// The sentence naming `cause` and the rule behind it.
    fn verdict(&self, cause: CauseId) -> String {
        let within = format!("max({} x noise, {})", self.none_noise_multiple, self.none_floor);
        match cause {
            CauseId::None => format!(
                "no candidate passes the tests (held-out error below {:.0}% of its base's, by more than {} x noise, \
                 criterion lower by {}, at most {} of the base's held-out error above the noise left), and every \
                 base's held-out error is within {within} of its track",
                100.0 * self.heldout_ratio,
                self.noise_margin,
                self.criterion_drop,
                fraction_in_words(self.max_excess_left)
            ),
            CauseId::Unexplained => {
                format!(
                    "no candidate passes the tests, and a base's held-out error exceeds {within} of its track"
                )
            }
            _ => format!(
                "chosen: {} (lowest held-out error relative to its base among the candidates that pass the tests)",
                cause.as_str()
            ),
        }
    }
}

/// The bases' lines of the evidence.
fn base_evidence(tracks: &Tracks<'_>) -> Vec<String> {
    let (base_error, base_heldout, _) = tracks.base.scores();
    let mut evidence = vec![format!(
        "base (anisotropic StVK): fitted error {base_error:.4}, held-out error {base_heldout:.4}, noise {:.4}",
        tracks.noise
    )];
    if let Some(t) = tracks.bending {
        let (e, h, _) = t.base.scores();
        evidence.push(format!(
            "bending base (isotropic flat hinges, {} bending readings): fitted error {e:.4}, held-out error {h:.4}, noise {:.4}",
            t.tests.len(),
            t.noise
        ));
    }
    evidence
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

    #[test]
    fn the_default_rule_words_its_tests_as_the_reports_always_have() {
        let rule = DecisionRule::default();
        assert_eq!(
            rule.verdict(CauseId::None),
            "no candidate passes the tests (held-out error below 75% of its base's, by more than 2 x noise, \
             criterion lower by 4, at most half of the base's held-out error above the noise left), and every \
             base's held-out error is within max(3 x noise, 0.03) of its track"
        );
        assert_eq!(
            rule.verdict(CauseId::Unexplained),
            "no candidate passes the tests, and a base's held-out error exceeds max(3 x noise, 0.03) of its track"
        );
        let strict = DecisionRule { heldout_ratio: 0.5, max_excess_left: 0.25, none_floor: 0.01, ..rule };
        let text = strict.verdict(CauseId::None);
        assert!(
            text.contains("below 50% of") && text.contains("at most 25% of") && text.contains(", 0.01)"),
            "{text}"
        );
    }
}
