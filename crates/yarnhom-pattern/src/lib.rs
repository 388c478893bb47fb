#![doc = include_str!("../README.md")]

mod curve;
pub mod knit;
pub mod min_distance;
pub mod mirror;
pub mod stitch;
pub mod weave;

use yarnhom_artifacts::{Fabric, Pattern, Yarn};

use knit::Stitch::{self, Knit as K, Purl as P};
pub use min_distance::{
    EdgeRef, MinDistance, YarnNeighbours, closest_yarns, edge_clearances, min_inter_yarn_distance,
};
pub use mirror::{Mirror, MirrorAxis, MirrorError, find_mirror, mirrored};
pub use stitch::{
    StitchSpec, StitchTile, centreline_length_m, generate_stitch, knit_generator_of, length_per_stitch_m,
};

/// The smallest centreline distance between yarn pieces that a generated pattern keeps, in yarn
/// radii (touching yarns are 2 radii apart; the published relaxed tiles come to 1.87-1.98).
pub const MIN_CLEARANCE_R: f64 = 1.9;

/// A generator's size and resolution parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeneratorParams {
    /// Stitch width (m): wale spacing for knits, warp yarn spacing for weaves.
    pub stitch_width_m: f64,
    /// Stitch height (m): course spacing for knits, weft yarn spacing for weaves.
    pub stitch_height_m: f64,
    /// Yarn radius (m).
    pub yarn_radius_m: f64,
    /// Centreline vertices per stitch (knits) or per yarn spacing (weaves).
    pub vertices_per_stitch: usize,
}

impl std::fmt::Display for GeneratorParams {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{{stitch_width_m: {}, stitch_height_m: {}, yarn_radius_m: {}, vertices_per_stitch: {}}}",
            self.stitch_width_m, self.stitch_height_m, self.yarn_radius_m, self.vertices_per_stitch
        )
    }
}

/// Most vertices per stitch a generator accepts: far beyond any useful resolution, it keeps
/// vertex indices and memory bounded.
pub const MAX_VERTICES_PER_STITCH: usize = 4096;

/// Why a pattern cannot be generated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GenerateError {
    /// No generator of that name.
    #[error("unknown pattern generator '{0}' (known: {known})", known = GENERATORS.iter().map(|g| g.name).collect::<Vec<_>>().join(", "))]
    UnknownGenerator(String),
    /// A parameter is out of range.
    #[error("{0}")]
    BadParameter(String),
    /// The parameters are in range but the tile's yarns come closer than [`MIN_CLEARANCE_R`].
    #[error(
        "{name} {params}: yarn centrelines come {distance_r:.3} radii apart, closer than {MIN_CLEARANCE_R}; use larger stitches or more vertices per stitch"
    )]
    TooClose {
        /// Generator name.
        name: String,
        /// The parameters used.
        params: GeneratorParams,
        /// Closest centreline distance, in yarn radii.
        distance_r: f64,
    },
    /// No tile of the generator has the stitch asked for ([`GeneratorInfo::generate_stitch`]).
    #[error("{name} for stitch {spec}: {message}")]
    Stitch {
        /// Generator name.
        name: String,
        /// The stitch asked for.
        spec: Box<StitchSpec>,
        /// What is wrong.
        message: String,
    },
}

/// A built-in generator.
#[derive(Debug, Clone, Copy)]
pub struct GeneratorInfo {
    /// Name used on the command line.
    pub name: &'static str,
    /// Knit or woven.
    pub fabric: Fabric,
    /// One line on what it makes.
    pub description: &'static str,
    /// What the tile is made of.
    chart: Chart,
    /// Sizes in proportion to the published tiles (see [`GeneratorParams::defaults_for`]).
    defaults: GeneratorParams,
}

/// The repeat of a generator.
#[derive(Debug, Clone, Copy)]
enum Chart {
    /// Stitches, `[course][wale]`, course 0 at the bottom.
    Knit(&'static [&'static [Stitch]]),
    /// Interlacing, `[weft][warp]`: true where the warp passes over the weft.
    Weave(&'static [&'static [bool]]),
}

/// Warp over weft.
const O: bool = true;
/// Warp under weft.
const U: bool = false;

/// Default knit parameters for a stitch of `width x height` mm: 1 mm yarn radius, 32 vertices
/// per stitch (the published stockinette has 25).
const fn knit_defaults(width_mm: f64, height_mm: f64) -> GeneratorParams {
    GeneratorParams {
        stitch_width_m: width_mm * 1e-3,
        stitch_height_m: height_mm * 1e-3,
        yarn_radius_m: 1e-3,
        vertices_per_stitch: 32,
    }
}

/// Default weave parameters for yarn spacings of `width x height` mm: 1 mm yarn radius, 4
/// vertices per spacing (the published basket has 2.5).
const fn weave_defaults(width_mm: f64, height_mm: f64) -> GeneratorParams {
    GeneratorParams {
        stitch_width_m: width_mm * 1e-3,
        stitch_height_m: height_mm * 1e-3,
        yarn_radius_m: 1e-3,
        vertices_per_stitch: 4,
    }
}

/// Every built-in generator.
///
/// Default sizes: the published relaxed HYLC tiles scaled up about 10% (a looser start that
/// relaxation tightens), where the loops fit. The published stockinette tile (15.05 x 7.93 mm,
/// 1 mm radius) holds 2 x 2 stitches of 7.5 x 4.0 mm: stockinette 8.4 x 4.4 mm. The published
/// rib has 8.7 mm wales: rib 9.6 x 4.4 mm (knit and purl wales side by side need more room, see
/// [`knit`]). Garter and seed, with knit and purl courses, need 5.6 radii of course height: 6.0
/// mm. The published basket has yarns 2.68 x 2.58 mm apart: 3.1 x 3.0 mm; plain and satin
/// (published satin 2.22 x 2.20 mm, jammed tighter than circular centrelines allow): 3.0 x 3.0
/// mm.
pub const GENERATORS: &[GeneratorInfo] = &[
    GeneratorInfo {
        name: "stockinette",
        fabric: Fabric::Knit,
        description: "jersey: knit stitches only; 1 wale x 1 course tile",
        chart: Chart::Knit(&[&[K]]),
        defaults: knit_defaults(8.4, 4.4),
    },
    GeneratorInfo {
        name: "garter",
        fabric: Fabric::Knit,
        description: "knit and purl courses alternating; 1 x 2 tile",
        chart: Chart::Knit(&[&[K], &[P]]),
        defaults: knit_defaults(8.4, 6.0),
    },
    GeneratorInfo {
        name: "rib",
        fabric: Fabric::Knit,
        description: "1x1 rib: knit and purl wales alternating; 2 x 1 tile",
        chart: Chart::Knit(&[&[K, P]]),
        defaults: knit_defaults(9.6, 4.4),
    },
    GeneratorInfo {
        name: "seed",
        fabric: Fabric::Knit,
        description: "knit/purl checkerboard; 2 x 2 tile",
        chart: Chart::Knit(&[&[K, P], &[P, K]]),
        defaults: knit_defaults(9.6, 6.0),
    },
    GeneratorInfo {
        name: "plain",
        fabric: Fabric::Woven,
        description: "plain (tabby) weave, 1/1; 2 warps x 2 wefts",
        chart: Chart::Weave(&[&[O, U], &[U, O]]),
        defaults: weave_defaults(3.0, 3.0),
    },
    GeneratorInfo {
        name: "basket",
        fabric: Fabric::Woven,
        description: "2x2 basket weave; 4 warps x 4 wefts",
        chart: Chart::Weave(&[&[O, O, U, U], &[O, O, U, U], &[U, U, O, O], &[U, U, O, O]]),
        defaults: weave_defaults(3.1, 3.0),
    },
    GeneratorInfo {
        name: "satin",
        fabric: Fabric::Woven,
        description: "5-harness satin (warp floats over 4, step 2); 5 x 5",
        chart: Chart::Weave(&[
            &[U, O, O, O, O],
            &[O, O, O, U, O],
            &[O, U, O, O, O],
            &[O, O, O, O, U],
            &[O, O, U, O, O],
        ]),
        defaults: weave_defaults(3.0, 3.0),
    },
];

impl GeneratorInfo {
    /// The smallest stitch (width, height) this generator accepts for yarn radius `r` (m);
    /// stitches at least this large keep [`MIN_CLEARANCE_R`] at the default resolution.
    pub fn min_stitch_m(&self, yarn_radius_m: f64) -> [f64; 2] {
        let r = match self.chart {
            Chart::Knit(chart) => knit::min_stitch_r(chart),
            Chart::Weave(_) => [weave::MIN_SPACING_R; 2],
        };
        r.map(|v| v * yarn_radius_m)
    }

    /// Run the generator, checking the result's clearance.
    pub fn generate(&self, params: &GeneratorParams) -> Result<Pattern, GenerateError> {
        let pattern = match self.chart {
            Chart::Knit(chart) => knit::knit(self.name, chart, params)?,
            Chart::Weave(chart) => weave::weave(self.name, chart, params)?,
        };
        pattern
            .validate()
            .map_err(|e| GenerateError::BadParameter(format!("generated pattern is invalid: {e}")))?;
        let closest = min_inter_yarn_distance(&pattern).map_or(f64::INFINITY, |m| m.distance_m);
        let distance_r = closest / params.yarn_radius_m;
        if distance_r < MIN_CLEARANCE_R {
            return Err(GenerateError::TooClose { name: self.name.into(), params: *params, distance_r });
        }
        Ok(pattern)
    }
}

impl GeneratorParams {
    /// Default parameters of a generator (see [`GENERATORS`] for how they were chosen).
    pub fn defaults_for(name: &str) -> Result<GeneratorParams, GenerateError> {
        Ok(info(name)?.defaults)
    }

    /// Check that the values are usable, the stitch holds at least `min_width x min_height` and
    /// has at least `min_vertices` vertices.
    fn require_stitch(
        &self,
        min_width: f64,
        min_height: f64,
        min_vertices: usize,
    ) -> Result<(), GenerateError> {
        let bad = |m: String| Err(GenerateError::BadParameter(m));
        for (name, v) in [
            ("stitch width", self.stitch_width_m),
            ("stitch height", self.stitch_height_m),
            ("yarn radius", self.yarn_radius_m),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return bad(format!("{name} must be a finite length > 0 m, got {v}"));
            }
        }
        if self.vertices_per_stitch < min_vertices {
            return bad(format!(
                "need at least {min_vertices} vertices per stitch, got {}",
                self.vertices_per_stitch
            ));
        }
        if self.vertices_per_stitch > MAX_VERTICES_PER_STITCH {
            return bad(format!(
                "at most {MAX_VERTICES_PER_STITCH} vertices per stitch, got {}",
                self.vertices_per_stitch
            ));
        }
        // Round-off slack: a stitch of exactly the documented minimum is accepted.
        let at_least = |v: f64, min: f64| v >= min * (1.0 - 1e-9);
        if !(at_least(self.stitch_width_m, min_width) && at_least(self.stitch_height_m, min_height)) {
            return bad(format!(
                "a stitch of {} x {} m is too small for yarn radius {} m: it needs at least {min_width:.3e} x {min_height:.3e} m",
                self.stitch_width_m, self.stitch_height_m, self.yarn_radius_m
            ));
        }
        Ok(())
    }
}

fn info(name: &str) -> Result<&'static GeneratorInfo, GenerateError> {
    GENERATORS.iter().find(|g| g.name == name).ok_or_else(|| GenerateError::UnknownGenerator(name.into()))
}

/// Run the generator `name` (see [`GeneratorInfo::generate`]).
pub fn generate(name: &str, params: &GeneratorParams) -> Result<Pattern, GenerateError> {
    info(name)?.generate(params)
}

/// A generated pattern: untwisted, without rest state, its origin naming generator and parameters.
fn generated(
    name: &str,
    fabric: Fabric,
    period_m: [f64; 2],
    positions_m: Vec<[f64; 3]>,
    yarns: Vec<Yarn>,
    params: &GeneratorParams,
) -> Pattern {
    Pattern {
        name: name.into(),
        fabric,
        period_m,
        edge_twist_rad: vec![0.0; positions_m.len()],
        positions_m,
        yarns,
        rest: None,
        origin: format!("generator {name} {params}"),
    }
}

/// Append a yarn through `points` (closing with tile offset `closure`) to `positions`.
fn add_yarn(
    positions: &mut Vec<[f64; 3]>,
    points: impl Iterator<Item = [f64; 3]>,
    closure: [i32; 2],
    r: f64,
) -> Yarn {
    let start = positions.len() as u32;
    positions.extend(points);
    let n = positions.len() - start as usize;
    let mut edge_offsets = vec![[0, 0]; n];
    edge_offsets[n - 1] = closure;
    Yarn { radius_m: r, vertices: (start..start + n as u32).collect(), edge_offsets }
}
