//! `report.md`: a diagnosis for people ([`Diagnosis::markdown`]), with every number of
//! `report.json` that a reader needs to check the verdict.

use super::report::{Diagnosis, ModelResult};
use crate::yarn::confirm::{YarnConfirmation, YarnLevel};

impl Diagnosis {
    /// `report.md`: the verdict, the evidence, the candidate table, the parameters, the
    /// yarn-level confirmation, the figures.
    pub fn markdown(&self) -> String {
        let mut md = format!(
            "# Diagnosis of {}\n\n**Cause: `{}`** — {}.\n\n",
            self.fabric,
            self.cause.id.as_str(),
            self.cause.explanation
        );
        for c in self.causes.iter().skip(1) {
            md += &format!("Also **`{}`** — {}.\n\n", c.id.as_str(), c.explanation);
        }
        if let Some(remainder) = self.remainder_words() {
            md += &format!("Also **`unexplained`** — {remainder}.\n\n");
        }
        md += "## Evidence\n\n";
        for line in &self.cause.evidence {
            md += &format!("- {line}\n");
        }
        md += &format!(
            "\nHeld-out error (RMS normalized residual on targets not fitted): {} before, {} after. Noise level {}.\n\n",
            number(self.gain.heldout_error_before),
            number(self.gain.heldout_error_after),
            number(self.noise)
        );
        md += &self.candidate_table();
        md += &self.parameters();
        md += &yarn_level(self.yarn_level.as_ref());
        md += "\n## Figures\n\n![measured, base and extended](fit.svg)\n\n![residuals](residuals.svg)\n\n";
        md += &format!(
            "{} loading targets ({} fitted), {} unloading targets; {:.1} s.\n",
            self.load_targets.len(),
            self.load_fitted.iter().filter(|f| **f).count(),
            self.unload_targets.len(),
            self.wall_time_s
        );
        md
    }

    /// Every model: the stretch base, the bending base, the candidates.
    fn candidate_table(&self) -> String {
        let mut md = "## Candidates\n\n| model | testable | parameters | fitted error | held-out error | criterion (AIC) | note |\n|---|---|---|---|---|---|---|\n".to_string();
        let bending_base = self.bending.as_ref().map(|t| &t.base);
        for m in std::iter::once(&self.base).chain(bending_base).chain(&self.candidates) {
            md += &format!(
                "| {} | {} | {} | {} | {} | {} | {} |\n",
                m.id,
                if m.testable { "yes" } else { "no" },
                m.parameter_count,
                maybe(m.error),
                maybe(m.heldout_error),
                maybe(m.criterion),
                m.note.as_deref().unwrap_or("")
            );
        }
        md
    }

    /// The parameters of the bases and of the chosen extension.
    fn parameters(&self) -> String {
        let mut md = String::new();
        let sections: [(&str, Option<&ModelResult>); 3] = [
            ("Base parameters", Some(&self.base)),
            ("Bending base parameters", self.bending.as_ref().map(|t| &t.base)),
            ("Extended parameters", self.extended.as_ref()),
        ];
        for (title, model) in sections {
            let Some(model) = model else { continue };
            md += &format!("\n## {title} ({})\n\n", model.id);
            for (name, value) in &model.params {
                md += &format!("- `{name}` = {value:.6}\n");
            }
        }
        md
    }
}

fn number(x: f64) -> String {
    format!("{x:.4}")
}

fn maybe(x: Option<f64>) -> String {
    x.map_or("-".into(), number)
}

/// The yarn-level confirmation's section of `report.md` (nothing before it is run).
fn yarn_level(level: Option<&YarnLevel>) -> String {
    match level {
        None => String::new(),
        Some(YarnLevel::NotRun { reason }) => format!("\n## Yarn-level confirmation\n\nNot run: {reason}.\n"),
        Some(YarnLevel::Confirmation(c)) => confirmation(c),
    }
}

/// A confirmation: the verdict, how it was searched, the two yarn models' scores and
/// parameters.
fn confirmation(c: &YarnConfirmation) -> String {
    let mut md = format!(
        "\n## Yarn-level confirmation\n\n**{}** — {}\n\nTile `{}`; targets: the extended shell's uniform tests, {} per \
         direction fitted and as many held out between them; a swarm per model ({} evaluations in all, the \
         extension's seeded with the base's optimum), then {} local steps from their best (and the base's second \
         from the extension's optimum); {:.1} s.\n\n| yarn model | parameters | fitted error | held-out error | criterion (AIC) | local evaluations |\n|---|---|---|---|---|---|\n",
        if c.confirmed { "Confirmed" } else { "Not confirmed" },
        c.verdict,
        c.pattern,
        c.settings.local_targets,
        c.swarm_evaluations,
        serde_json::to_value(c.settings.local)
            .ok()
            .and_then(|v| v.as_str().map(String::from))
            .unwrap_or_default(),
        c.wall_time_s
    );
    for (name, m) in [("base (linear stretch, single-phase contact)", &c.base), ("extended", &c.extended)] {
        md += &format!(
            "| {name} | {} | {:.4} | {:.4} | {:.1} | {} |\n",
            m.coordinates.len(),
            m.error,
            m.heldout_error,
            m.criterion,
            m.evaluations
        );
    }
    for (name, m) in [("Base yarn parameters", &c.base), ("Extended yarn parameters", &c.extended)] {
        md += &format!("\n### {name}\n\n");
        let p = serde_json::to_value(m.params).unwrap_or_default();
        for (key, value) in p.as_object().into_iter().flatten() {
            md += &format!("- `{key}` = {value}\n");
        }
    }
    md
}
