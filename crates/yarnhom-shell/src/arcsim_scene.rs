//! ARCSim-HYLC scene files (`../shared/data/hylc-scenes/*.json`) read into a [`Scene`]: the
//! cloth square (`hylc_square.obj`, a unit square, scaled), handlebars, handlespheres, their
//! keyframed translations, sphere obstacles (`sphere.obj`, a unit sphere, scaled), gravity,
//! obstacle friction, the repulsion thickness, the material's stiffness damping and the air
//! drag (`wind`, [`crate::wind`], with ARCSim's defaults: density 1 kg/m³ when a scene sets
//! none).
//!
//! Damping as in ARCSim: its implicit integrator damps by the material's `damping` (our
//! Rayleigh stiffness damping `β`) and the wind only, so imported scenes have no Rayleigh mass
//! damping (`α = 0`; the published scenes leave `explicit_massdamping`, used only by ARCSim's
//! explicit integrator, commented out).
//!
//! Not carried over: ARCSim's adaptive remeshing (we use a fixed mesh of the built-in
//! resolution) and its 80 substeps per frame (we take [`Scene::steps_per_frame`] implicit
//! steps).

use serde_json::Value;

use crate::contact::Obstacle;
use crate::scene::{HandleSpec, Scene, SceneError};
use crate::wind::Wind;

fn number(v: &Value, key: &str) -> Option<f64> {
    v.get(key).and_then(Value::as_f64)
}

fn triple(v: Option<&Value>) -> Option<[f64; 3]> {
    let a = v?.as_array()?;
    Some([a.first()?.as_f64()?, a.get(1)?.as_f64()?, a.get(2)?.as_f64()?])
}

fn invalid(name: &str, problem: impl Into<String>) -> SceneError {
    SceneError::Invalid { scene: name.into(), problem: problem.into() }
}

/// The scene of a parsed ARCSim JSON document named `name`.
pub fn import(doc: &Value, name: &str) -> Result<Scene, SceneError> {
    let mut scene = Scene::builtin("stretch-x")?;
    scene.name = name.into();
    scene.handles.clear();
    scene.motions.clear();
    let cloth = doc.get("cloths").and_then(|c| c.get(0)).ok_or_else(|| invalid(name, "no cloth"))?;
    let scale = cloth.pointer("/transform/scale").and_then(Value::as_f64).unwrap_or(1.0);
    scene.size_m = [scale, scale];
    if let Some(d) = cloth.pointer("/materials/0/damping").and_then(Value::as_f64) {
        scene.stiffness_damping = d;
    }
    scene.end_time_s = number(doc, "end_time").unwrap_or(scene.end_time_s);
    scene.frame_time_s = number(doc, "frame_time").unwrap_or(scene.frame_time_s);
    scene.gravity = triple(doc.get("gravity")).unwrap_or(scene.gravity);
    scene.wind = wind(doc.get("wind"));
    scene.mass_damping = 0.0;
    scene.contact.friction = number(doc, "obs_friction").unwrap_or(0.0);
    if let Some(t) = doc.pointer("/magic/repulsion_thickness").and_then(Value::as_f64) {
        scene.contact.thickness_m = t;
    }
    scene.motions = motions(doc, name)?;
    scene.handles = handles(doc, name)?;
    scene.obstacles = obstacles(doc, name)?;
    if !scene.obstacles.is_empty() {
        scene.contact.self_thickness_m = 6e-3;
        scene.contact.self_stiffness_n_m = 10.0;
    }
    scene.validate()?;
    Ok(scene)
}

/// ARCSim's `wind` with its parser's defaults (`conf.cpp`, `parse(Wind&, ...)`): density 1,
/// velocity 0, drag 0, also when the scene has no `wind`.
fn wind(w: Option<&Value>) -> Wind {
    let get = |key: &str| w.and_then(|w| number(w, key));
    Wind {
        density_kg_m3: get("density").unwrap_or(1.0),
        velocity_m_s: triple(w.and_then(|w| w.get("velocity"))).unwrap_or([0.0; 3]),
        drag_kg_m2_s: get("drag").unwrap_or(0.0),
    }
}

/// Keyframes `(time_s, translation_m)` of one motion.
type Keyframes = Vec<(f64, [f64; 3])>;

fn motions(doc: &Value, name: &str) -> Result<Vec<Keyframes>, SceneError> {
    let Some(list) = doc.get("motions").and_then(Value::as_array) else { return Ok(Vec::new()) };
    list.iter()
        .map(|motion| {
            motion
                .as_array()
                .ok_or_else(|| invalid(name, "a motion is not a list of keyframes"))?
                .iter()
                .map(|key| {
                    let time = number(key, "time").ok_or_else(|| invalid(name, "a keyframe has no time"))?;
                    let shift = triple(key.pointer("/transform/translate")).unwrap_or([0.0; 3]);
                    Ok((time, shift))
                })
                .collect()
        })
        .collect()
}

fn handles(doc: &Value, name: &str) -> Result<Vec<HandleSpec>, SceneError> {
    let motion = |h: &Value| h.get("motion").and_then(Value::as_u64).map(|m| m as usize);
    let mut out = Vec::new();
    for h in doc.get("handlebars").and_then(Value::as_array).into_iter().flatten() {
        out.push(HandleSpec::Bar {
            side: h
                .get("side")
                .and_then(Value::as_u64)
                .ok_or_else(|| invalid(name, "handlebar without side"))? as u8,
            length: number(h, "lengthp").unwrap_or(1.0),
            width: number(h, "widthp").unwrap_or(0.05),
            inset: number(h, "insetp").unwrap_or(0.0),
            motion: motion(h),
        });
    }
    for h in doc.get("handlespheres").and_then(Value::as_array).into_iter().flatten() {
        out.push(HandleSpec::Sphere {
            center: triple(h.get("center")).ok_or_else(|| invalid(name, "handlesphere without center"))?,
            radius: number(h, "radius").ok_or_else(|| invalid(name, "handlesphere without radius"))?,
            motion: motion(h),
        });
    }
    Ok(out)
}

fn obstacles(doc: &Value, name: &str) -> Result<Vec<Obstacle>, SceneError> {
    let mut out = Vec::new();
    for o in doc.get("obstacles").and_then(Value::as_array).into_iter().flatten() {
        let mesh = o.get("mesh").and_then(Value::as_str).unwrap_or("");
        if !mesh.ends_with("sphere.obj") {
            return Err(invalid(name, format!("obstacle mesh '{mesh}' is not supported (only sphere.obj)")));
        }
        out.push(Obstacle::Sphere {
            center: triple(o.pointer("/transform/translate")).unwrap_or([0.0; 3]),
            radius: o.pointer("/transform/scale").and_then(Value::as_f64).unwrap_or(1.0),
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn published(file: &str) -> Scene {
        let path = format!("{}/../../../shared/data/hylc-scenes/{file}", env!("CARGO_MANIFEST_DIR"));
        Scene::load(&path).expect("published scene imports")
    }

    #[test]
    fn the_builtins_equal_the_published_stockinette_scenes() {
        // Same handles, motions, obstacles, times and contact thickness as the files.
        for (file, builtin) in [
            ("stock_stretchX.json", "stretch-x"),
            ("stock_stretchY.json", "stretch-y"),
            ("stock_drapeX.json", "drape"),
        ] {
            let (a, b) = (published(file), Scene::builtin(builtin).expect("builtin"));
            assert_eq!(a.handles, b.handles, "{file}");
            assert_eq!(a.motions, b.motions, "{file}");
            assert_eq!(a.obstacles, b.obstacles, "{file}");
            assert_eq!(
                (a.end_time_s, a.frame_time_s, a.size_m),
                (b.end_time_s, b.frame_time_s, b.size_m),
                "{file}"
            );
            assert_eq!(a.contact.thickness_m, b.contact.thickness_m, "{file}");
            assert_eq!(
                (a.wind, a.mass_damping, a.stiffness_damping),
                (b.wind, b.mass_damping, b.stiffness_damping),
                "{file}"
            );
        }
    }

    #[test]
    fn the_air_drag_is_read_with_arcsims_defaults() {
        let drape = published("stock_drapeX.json");
        assert_eq!(drape.wind, Wind { density_kg_m3: 7.5, velocity_m_s: [0.0; 3], drag_kg_m2_s: 0.0 });
        assert_eq!(drape.mass_damping, 0.0);
        let doc = |wind: &str| -> Value {
            serde_json::from_str(&format!(
                r#"{{"cloths": [{{}}], "handlespheres": [{{"center": [0, 0, 0], "radius": 0.01}}]{wind}}}"#
            ))
            .expect("json")
        };
        let full = import(&doc(r#", "wind": {"density": 2, "velocity": [1, 0, 0.5], "drag": 0.3}"#), "t")
            .expect("scene");
        assert_eq!(full.wind, Wind { density_kg_m3: 2.0, velocity_m_s: [1.0, 0.0, 0.5], drag_kg_m2_s: 0.3 });
        let none = import(&doc(""), "t").expect("scene");
        assert_eq!(none.wind, Wind { density_kg_m3: 1.0, ..Wind::default() });
    }

    #[test]
    fn every_published_scene_imports() {
        let dir = format!("{}/../../../shared/data/hylc-scenes", env!("CARGO_MANIFEST_DIR"));
        let mut count = 0;
        for entry in std::fs::read_dir(dir).expect("published scenes").flatten() {
            let name = entry.file_name().to_string_lossy().into_owned();
            if name.ends_with(".json") {
                let scene = published(&name);
                assert!(!scene.handles.is_empty(), "{name}");
                assert!(scene.handles(&scene.mesh()).is_ok(), "{name}");
                count += 1;
            }
        }
        assert_eq!(count, 20);
    }
}
