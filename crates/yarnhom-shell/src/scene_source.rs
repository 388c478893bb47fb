//! Where a scene comes from: a built-in name, a yarnhom scene file or a published ARCSim-HYLC
//! scene file, told apart by content.

use crate::scene::{BUILTINS, Scene, SceneError};

impl Scene {
    /// A built-in name, an ARCSim-HYLC scene (`*.json` with a `cloths` key) or a yarnhom scene
    /// file.
    pub fn load(spec: &str) -> Result<Self, SceneError> {
        if BUILTINS.contains(&spec) {
            return Self::builtin(spec);
        }
        let text = std::fs::read_to_string(spec).map_err(|e| {
            SceneError::Parse(format!(
                "'{spec}' is neither a built-in scene ({}) nor a readable scene file: {e}",
                BUILTINS.join(", ")
            ))
        })?;
        let name = std::path::Path::new(spec).file_stem().and_then(|s| s.to_str()).unwrap_or("scene");
        let stripped = yarnhom_artifacts::arcsim::strip_comments(&text);
        let value: serde_json::Value =
            serde_json::from_str(&stripped).map_err(|e| SceneError::Parse(format!("{spec}: {e}")))?;
        if value.get("cloths").is_some() {
            crate::arcsim_scene::import(&value, name)
        } else {
            Self::from_json(&stripped)
        }
    }
}
