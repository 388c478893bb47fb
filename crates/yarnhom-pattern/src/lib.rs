//! Built-in yarn pattern generators and pattern geometry queries.
//!
//! Generators produce plausible, non-self-intersecting starting states for relaxation: smooth
//! centrelines, near-uniform edges, and crossing yarns at least `2 * 1.05` radii apart at the
//! crossings (checked by [`min_inter_yarn_distance`] in the tests: at least 1.9 radii anywhere).
//! Knits (see [`knit`]): `stockinette`, `garter`, `rib` (1x1), `seed`. Weaves (see [`weave`]):
//! `plain`, `basket` (2x2), `satin` (5-harness).

mod curve;
pub mod knit;
pub mod min_distance;
pub mod weave;

use yarnhom_artifacts::{Fabric, Pattern, Yarn};

use knit::Stitch::{Knit as K, Purl as P};
pub use min_distance::{EdgeRef, MinDistance, YarnNeighbours, min_inter_yarn_distance};

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

/// Why a pattern cannot be generated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GenerateError {
    /// No generator of that name.
    #[error("unknown pattern generator '{0}' (known: {known})", known = GENERATORS.iter().map(|g| g.name).collect::<Vec<_>>().join(", "))]
    UnknownGenerator(String),
    /// A parameter is out of range.
    #[error("{0}")]
    BadParameter(String),
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
    /// Builds the pattern.
    build: fn(&str, &GeneratorParams) -> Result<Pattern, GenerateError>,
}

/// Every built-in generator.
pub const GENERATORS: &[GeneratorInfo] = &[
    GeneratorInfo {
        name: "stockinette",
        fabric: Fabric::Knit,
        description: "jersey: knit stitches only; 1 wale x 1 course tile",
        build: |n, p| knit::knit(n, &[vec![K]], p),
    },
    GeneratorInfo {
        name: "garter",
        fabric: Fabric::Knit,
        description: "knit and purl courses alternating; 1 x 2 tile",
        build: |n, p| knit::knit(n, &[vec![K], vec![P]], p),
    },
    GeneratorInfo {
        name: "rib",
        fabric: Fabric::Knit,
        description: "1x1 rib: knit and purl wales alternating; 2 x 1 tile",
        build: |n, p| knit::knit(n, &[vec![K, P]], p),
    },
    GeneratorInfo {
        name: "seed",
        fabric: Fabric::Knit,
        description: "knit/purl checkerboard; 2 x 2 tile",
        build: |n, p| knit::knit(n, &[vec![K, P], vec![P, K]], p),
    },
    GeneratorInfo {
        name: "plain",
        fabric: Fabric::Woven,
        description: "plain (tabby) weave, 1/1; 2 warps x 2 wefts",
        build: |n, p| weave::weave(n, &interlacing(2, |i, j| (i + j) % 2 == 0), p),
    },
    GeneratorInfo {
        name: "basket",
        fabric: Fabric::Woven,
        description: "2x2 basket weave; 4 warps x 4 wefts",
        build: |n, p| weave::weave(n, &interlacing(4, |i, j| (i / 2 + j / 2) % 2 == 0), p),
    },
    GeneratorInfo {
        name: "satin",
        fabric: Fabric::Woven,
        description: "5-harness satin (warp floats over 4, step 2); 5 x 5",
        build: |n, p| weave::weave(n, &interlacing(5, |i, j| (2 * i + 5 - j % 5) % 5 != 0), p),
    },
];

impl GeneratorParams {
    /// Default parameters of a generator: 1 mm yarn radius; knit stitches of 15 x 8 mm, in
    /// proportion to the published HYLC stockinette (15.1 x 7.9 mm); woven yarns 4 mm apart, a
    /// looser start than the published jammed tiles (about 2.7 mm), which circular yarn
    /// centrelines cannot reach without flattening.
    pub fn defaults_for(name: &str) -> Result<GeneratorParams, GenerateError> {
        let info = info(name)?;
        Ok(match info.fabric {
            Fabric::Knit => GeneratorParams {
                stitch_width_m: 0.015,
                stitch_height_m: 0.008,
                yarn_radius_m: 0.001,
                vertices_per_stitch: 40,
            },
            Fabric::Woven => GeneratorParams {
                stitch_width_m: 0.004,
                stitch_height_m: 0.004,
                yarn_radius_m: 0.001,
                vertices_per_stitch: 8,
            },
        })
    }

    /// Check that the values are usable and the stitch holds at least `min_width x min_height`.
    fn require_stitch(&self, min_width: f64, min_height: f64) -> Result<(), GenerateError> {
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
        if self.vertices_per_stitch < 4 {
            return bad(format!("need at least 4 vertices per stitch, got {}", self.vertices_per_stitch));
        }
        if self.stitch_width_m < min_width || self.stitch_height_m < min_height {
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

/// Run the generator `name`.
pub fn generate(name: &str, params: &GeneratorParams) -> Result<Pattern, GenerateError> {
    let pattern = (info(name)?.build)(name, params)?;
    pattern
        .validate()
        .map_err(|e| GenerateError::BadParameter(format!("generated pattern is invalid: {e}")))?;
    Ok(pattern)
}

/// An `n x n` interlacing chart: `over(warp, weft)` is true where the warp is on top.
fn interlacing(n: usize, over: impl Fn(usize, usize) -> bool) -> Vec<Vec<bool>> {
    (0..n).map(|weft| (0..n).map(|warp| over(warp, weft)).collect()).collect()
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
