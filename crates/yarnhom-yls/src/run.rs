//! Running a scene of the shell simulator on a swatch (thesis Sec. 4.3.1, Table 4.2), so that a
//! yarn-level run and a homogenized run of one scene compare directly.
//!
//! The swatch takes the place of the scene's cloth: it is centred on the origin, its yarns'
//! mean height at z = 0, material x (weft, the pattern's X1) along world x. The scene's parts
//! map onto the yarns as follows:
//! - **handles**: a bar holds the yarn vertices within its fractions of the *swatch's* sides
//!   (so a bar means the same on a swatch of any size); a sphere holds the vertices inside it
//!   (or the nearest one), at the scene's absolute position; both follow the scene's motions.
//!   A handle that holds no vertex is an error;
//! - **obstacles**: spheres, planes and boxes, as barriers on the gap between a yarn's surface
//!   and the obstacle ([`RunSettings::obstacle_activation_radii`],
//!   [`RunSettings::obstacle_stiffness_n_m`]), with the scene's Coulomb friction (`obs_friction`)
//!   applied as the shell simulator applies it ([`Obstacle::apply_friction`]);
//! - **gravity**: the scene's; **air drag**: the scene's wind on the yarn segments, the
//!   swatch's area shared among them by rest length ([`YarnWind`]);
//! - **damping**: the scene's Rayleigh terms are the shell's; the yarns get Kaldor et al.
//!   (2008)'s damping of non-rigid motion at [`RunSettings::damping_rate_per_s`], as the
//!   thesis' yarn-level runs (Sec. 4.3.1);
//! - **time**: the scene's frames (`frame_time_s`, `end_time_s`), each of
//!   [`RunSettings::steps_per_frame`] backward Euler steps (yarn-level runs need far shorter
//!   steps than the shell's).

use nalgebra::Vector3;
use yarnhom_artifacts::Swatch;
use yarnhom_shell::contact::Obstacle as ShellObstacle;
use yarnhom_shell::scene::HandleSpec;

use crate::dynamics::{
    Damping, Energies, Handle, InputError, Keyframe, Obstacle, ObstacleShape, Scene, Simulation, StepError,
    StepReport, YarnWind,
};
use crate::scene::scene_of_swatch;

/// How a yarn-level run reads a scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunSettings {
    /// Backward Euler steps per output frame.
    pub steps_per_frame: u32,
    /// Rate of Kaldor's damping of non-rigid motion (1/s).
    pub damping_rate_per_s: f64,
    /// Obstacle barriers act within this many yarn radii of an obstacle.
    pub obstacle_activation_radii: f64,
    /// Stiffness of the obstacle barriers (N/m).
    pub obstacle_stiffness_n_m: f64,
}

impl Default for RunSettings {
    /// 16 steps per frame (about 1 ms at the built-ins' 60 frames per second), damping
    /// 20 /s, obstacle barriers within half a yarn radius at 1000 N/m.
    fn default() -> Self {
        RunSettings {
            steps_per_frame: 16,
            damping_rate_per_s: 20.0,
            obstacle_activation_radii: 0.5,
            obstacle_stiffness_n_m: 1e3,
        }
    }
}

/// Why a run cannot start or stopped.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The scene is not usable.
    #[error(transparent)]
    Scene(#[from] yarnhom_shell::scene::SceneError),
    /// A handle holds no yarn vertex.
    #[error(
        "scene '{scene}': handle {handle} holds no yarn vertex of the swatch (the swatch is centred on the origin)"
    )]
    NothingHeld {
        /// The scene.
        scene: String,
        /// The handle's index.
        handle: usize,
    },
    /// The settings are out of range.
    #[error("{0}")]
    Settings(String),
    /// The yarns, handles or obstacles are not a valid simulation.
    #[error(transparent)]
    Input(#[from] InputError),
    /// A time step failed (the state is that of the frame before).
    #[error("frame {frame}: {error}")]
    Step {
        /// The output frame being computed.
        frame: u64,
        /// What failed.
        error: StepError,
    },
    /// The frame callback failed.
    #[error("{0}")]
    Output(String),
}

/// The dynamics scene of `swatch` placed in `scene`'s cloth rectangle, with its handles,
/// obstacles, gravity and damping (module docs).
pub fn place(
    swatch: &Swatch,
    scene: &yarnhom_shell::Scene,
    settings: &RunSettings,
) -> Result<Scene, RunError> {
    scene.validate()?;
    check_settings(settings)?;
    let mut dynamics = scene_of_swatch(swatch);
    let offset = centring_offset(swatch);
    for yarn in &mut dynamics.yarns {
        for p in &mut yarn.positions_m {
            *p = std::array::from_fn(|k| p[k] + offset[k]);
        }
    }
    let positions: Vec<Vector3<f64>> =
        dynamics.yarns.iter().flat_map(|y| y.positions_m.iter().map(|&p| Vector3::from(p))).collect();
    dynamics.handles = handles(swatch, scene, &positions)?;
    let radius = swatch.yarns.iter().map(|y| y.radius_m).fold(0.0, f64::max);
    dynamics.obstacles =
        scene.obstacles.iter().map(|o| obstacle(o, radius, settings, scene.contact.friction)).collect();
    dynamics.gravity_m_s2 = scene.gravity;
    dynamics.wind = (!scene.wind.is_none()).then(|| wind(swatch, &scene.wind));
    dynamics.damping = Some(Damping::kaldor(settings.damping_rate_per_s));
    Ok(dynamics)
}

/// The scene's handles over the placed yarn vertices `positions`, bars as fractions of the
/// swatch's sides. The shell holds the nearest vertex where a small sphere holds none; on yarns
/// that would grip one vertex anywhere, so a sphere must hold a vertex inside it.
fn handles(
    swatch: &Swatch,
    scene: &yarnhom_shell::Scene,
    positions: &[Vector3<f64>],
) -> Result<Vec<Handle>, RunError> {
    let on_swatch = yarnhom_shell::Scene { size_m: swatch.size_m, ..scene.clone() };
    let held = on_swatch.handles_at(positions)?;
    for (k, (spec, handle)) in scene.handles.iter().zip(&held).enumerate() {
        if let HandleSpec::Sphere { center, radius, .. } = *spec {
            let inside = |&v: &usize| (positions[v] - Vector3::from(center)).norm() <= radius;
            if !handle.vertices.iter().any(inside) {
                return Err(RunError::NothingHeld { scene: scene.name.clone(), handle: k });
            }
        }
    }
    Ok(held
        .into_iter()
        .map(|h| Handle { vertices: h.vertices, keyframes: keyframes(&h.motion.keys) })
        .collect())
}

/// The scene's air drag on the swatch's yarns: the swatch's area shared by rest length.
fn wind(swatch: &Swatch, wind: &yarnhom_shell::wind::Wind) -> YarnWind {
    let length_m: f64 = swatch.rest_length_m.iter().sum();
    YarnWind {
        density_kg_m3: wind.density_kg_m3,
        velocity_m_s: wind.velocity_m_s,
        drag_kg_m2_s: wind.drag_kg_m2_s,
        area_per_length_m: swatch.size_m[0] * swatch.size_m[1] / length_m,
    }
}

/// The translation that centres the swatch's rectangle on the origin and its yarns' mean
/// height at z = 0.
fn centring_offset(swatch: &Swatch) -> [f64; 3] {
    let n = swatch.positions_m.len().max(1) as f64;
    let mean_z = swatch.positions_m.iter().map(|p| p[2]).sum::<f64>() / n;
    [-swatch.size_m[0] / 2.0, -swatch.size_m[1] / 2.0, -mean_z]
}

/// A scene motion's keyframes (the translation at rest first, if the motion starts later).
fn keyframes(keys: &[(f64, [f64; 3])]) -> Vec<Keyframe> {
    if keys.is_empty() {
        return vec![Keyframe { time_s: 0.0, translation_m: [0.0; 3] }];
    }
    keys.iter().map(|&(time_s, translation_m)| Keyframe { time_s, translation_m }).collect()
}

/// A scene obstacle as a yarn-level barrier with the scene's friction coefficient.
fn obstacle(o: &ShellObstacle, radius_m: f64, settings: &RunSettings, friction: f64) -> Obstacle {
    let shape = match *o {
        ShellObstacle::Sphere { center, radius } => {
            ObstacleShape::Sphere { centre_m: center, radius_m: radius }
        }
        ShellObstacle::Plane { point, normal } => ObstacleShape::Plane { point_m: point, normal },
        ShellObstacle::Box { min, max } => ObstacleShape::Box { min_m: min, max_m: max },
    };
    Obstacle {
        shape,
        activation_distance_m: settings.obstacle_activation_radii * radius_m,
        stiffness_n_m: settings.obstacle_stiffness_n_m,
        friction,
    }
}

fn check_settings(settings: &RunSettings) -> Result<(), RunError> {
    let positive = |name: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(RunError::Settings(format!("{name} must be positive, not {v}")))
        }
    };
    if settings.steps_per_frame == 0 {
        return Err(RunError::Settings("steps per frame must be at least 1".into()));
    }
    positive("the obstacle activation distance", settings.obstacle_activation_radii)?;
    positive("the obstacle stiffness", settings.obstacle_stiffness_n_m)?;
    if !(settings.damping_rate_per_s.is_finite() && settings.damping_rate_per_s >= 0.0) {
        return Err(RunError::Settings(format!(
            "the damping rate must be >= 0, not {}",
            settings.damping_rate_per_s
        )));
    }
    Ok(())
}

/// The output frames of a run: how many after the initial one, how far apart, and the
/// backward Euler steps between two.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frames {
    /// Frames after frame 0.
    pub count: u64,
    /// Time between frames (s).
    pub frame_time_s: f64,
    /// Steps per frame.
    pub steps_per_frame: u32,
}

/// What happened up to an output frame.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameReport {
    /// Frame number (0 is the initial state).
    pub frame: u64,
    /// Simulated time (s).
    pub time_s: f64,
    /// The steps since the previous frame.
    pub steps: Vec<StepReport>,
    /// Energies at the frame.
    pub energies: Energies,
    /// The closest centreline distance between contact candidates at the frame (yarn radii).
    pub closest_distance_radii: f64,
}

/// Run `simulation` through output `frames` of `plan` (its count aside), calling `on_frame`
/// after each: frame 0 is the current state (reported as it is);
/// frame `k > 0` is reached by stepping from frame `k - 1`, where the simulation must be.
pub fn run(
    simulation: &mut Simulation,
    frames: std::ops::RangeInclusive<u64>,
    plan: &Frames,
    mut on_frame: impl FnMut(&FrameReport, &Simulation) -> Result<(), String>,
) -> Result<(), RunError> {
    let time_step_s = plan.frame_time_s / f64::from(plan.steps_per_frame);
    for frame in frames {
        let steps = if frame == 0 {
            vec![]
        } else {
            (0..plan.steps_per_frame)
                .map(|_| simulation.step(time_step_s))
                .collect::<Result<Vec<_>, _>>()
                .map_err(|error| RunError::Step { frame, error })?
        };
        on_frame(&frame_report(simulation, frame, steps), simulation).map_err(RunError::Output)?;
    }
    Ok(())
}

/// The report of `frame`: energies and closest distance from its last step, or evaluated for
/// the initial frame.
fn frame_report(simulation: &Simulation, frame: u64, steps: Vec<StepReport>) -> FrameReport {
    let (energies, closest_distance_radii) = match steps.last() {
        Some(last) => (last.energies, last.closest_distance_radii),
        None => (simulation.energies(), simulation.closest_distance_radii()),
    };
    FrameReport { frame, time_s: simulation.time_s(), steps, energies, closest_distance_radii }
}
