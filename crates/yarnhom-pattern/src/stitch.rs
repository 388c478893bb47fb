//! Knit tiles of a given yarn length per stitch: the fabric's own stitch.
//!
//! **Yarn length per stitch** of a periodic tile: the total centreline length of the tile's
//! yarns (the sum of all its edge lengths, the edges that close a yarn across the tile boundary
//! included: [`centreline_length_m`]) divided by the number of stitches in the tile
//! ([`GeneratorInfo::stitches_per_tile`]: 1 for stockinette, 2 for garter and rib, 4 for seed).
//! It is measured on the tile's polyline, the geometry the simulation sees.
//!
//! **The rule** ([`GeneratorInfo::generate_stitch`]). A [`StitchSpec`] gives the target length
//! `L`, the yarn radius `r`, optionally the radius of the yarn's incompressible core `r_c`, and
//! optionally the courses and wales per metre. The generator's loops are built for a *loop
//! radius* `ρ` (the `yarn_radius_m` of the [`GeneratorParams`] it runs with: crossing yarns
//! `3 ρ` apart, nowhere closer than [`MIN_CLEARANCE_R`](crate::MIN_CLEARANCE_R)` ρ`), and the tile's yarns are then given
//! the radius `r`:
//!
//! 1. The stitch size has one free parameter. With neither count given, the stitch keeps the
//!    generator's default aspect ratio (width : height of [`GeneratorParams::defaults_for`]) and
//!    is scaled as a whole; with one count, that dimension is fixed (`1 / courses_per_m` high or
//!    `1 / wales_per_m` wide) and the other is free; with both, the stitch size is fixed.
//! 2. Uncompressed first: `ρ = r` (or the largest `ρ <= r` whose smallest stitch fits the
//!    fixed dimensions), and the free dimension is found by bisection on the measured length
//!    per stitch, from the generator's smallest stitch up.
//! 3. A target shorter than the smallest stitch holds at `ρ = r` means a yarn squashed in its
//!    crossings (real yarns are fibre bundles; the authors of the stitch-by-stitch data model
//!    acrylic of radius 0.74 mm with a 0.325 mm core at 11.28 mm per stockinette stitch, half
//!    of what an incompressible 0.74 mm yarn needs): the stitch stays at the smallest size the
//!    generator allows for `ρ` (the free dimension at its minimum) and `ρ` is lowered by
//!    bisection until the length matches, down to `r_c`. The tile's centrelines then come to
//!    `1.9 ρ`, closer than `2 r`: the yarns overlap in their soft outer layer, as compressed
//!    yarns do. Without a core radius the yarn is taken as incompressible and `ρ = r` is the
//!    floor. With both counts given, only `ρ` is free (the plan view is fixed by the stitch size
//!    and `ρ` sets how far the yarns rise over each other), between `r_c` (or `r`) and the
//!    largest `ρ` the stitch size allows.
//! 4. A target outside what the rule reaches is a [`GenerateError::Stitch`]: too short for the
//!    yarn even compressed to its core (or, without a core, at its radius), too long for the
//!    fixed stitch size, or counts too dense for the core.
//!
//! The match is to a relative [`LENGTH_TOLERANCE`], far inside the 1% the calibration asks.

use yarnhom_artifacts::{Fabric, Pattern};

use crate::knit::{self, min_stitch_r};
use crate::{Chart, GENERATORS, GenerateError, GeneratorInfo, GeneratorParams};

/// Relative tolerance of the bisections on the length per stitch.
pub const LENGTH_TOLERANCE: f64 = 1e-6;

/// Bisection steps at most (each halves a bracket; 200 is far beyond `f64` resolution).
const MAX_STEPS: usize = 200;

/// Largest scale of the free stitch dimension over its minimum that the search tries.
const MAX_SCALE: f64 = 1e4;

/// The stitch of a fabric: what [`GeneratorInfo::generate_stitch`] builds a tile for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StitchSpec {
    /// Yarn length per stitch (m): the target (module docs).
    pub length_m: f64,
    /// Yarn radius (m): the tile's yarns have it.
    pub yarn_radius_m: f64,
    /// Radius of the yarn's incompressible core (m), if known: how far the yarns may be
    /// compressed to fit a short stitch (below the yarn radius).
    pub core_radius_m: Option<f64>,
    /// Courses per metre (stitch height `1 / courses_per_m`), if fixed.
    pub courses_per_m: Option<f64>,
    /// Wales per metre (stitch width `1 / wales_per_m`), if fixed.
    pub wales_per_m: Option<f64>,
}

impl std::fmt::Display for StitchSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{{length_m: {}, yarn_radius_m: {}", self.length_m, self.yarn_radius_m)?;
        for (name, value) in [
            ("core_radius_m", self.core_radius_m),
            ("courses_per_m", self.courses_per_m),
            ("wales_per_m", self.wales_per_m),
        ] {
            if let Some(v) = value {
                write!(f, ", {name}: {v}")?;
            }
        }
        write!(f, "}}")
    }
}

/// A tile generated for a stitch.
#[derive(Debug, Clone, PartialEq)]
pub struct StitchTile {
    /// The tile: yarns of radius [`StitchSpec::yarn_radius_m`].
    pub pattern: Pattern,
    /// The generator's parameters: the stitch size found, and the loop radius `ρ` as
    /// `yarn_radius_m` (module docs).
    pub params: GeneratorParams,
    /// The tile's measured yarn length per stitch (m).
    pub length_per_stitch_m: f64,
}

impl StitchTile {
    /// `ρ / r`: 1 for an uncompressed tile, less where the yarns are squashed (module docs).
    pub fn compression(&self) -> f64 {
        self.params.yarn_radius_m / self.pattern.yarns[0].radius_m
    }
}

/// Total centreline length of a tile's yarns (m): the sum of its edge lengths, the edges that
/// close a yarn across the tile boundary included.
pub fn centreline_length_m(pattern: &Pattern) -> f64 {
    pattern.edges().map(|e| pattern.edge_vector(&e).iter().map(|c| c * c).sum::<f64>().sqrt()).sum()
}

/// The built-in knit generator that made `pattern`, read from its name and origin (a generated
/// pattern's origin starts `generator NAME `); `None` for any other pattern.
pub fn knit_generator_of(pattern: &Pattern) -> Option<&'static GeneratorInfo> {
    let rest = pattern.origin.strip_prefix("generator ")?;
    GENERATORS.iter().find(|g| {
        matches!(g.chart, Chart::Knit(_))
            && g.name == pattern.name
            && rest.strip_prefix(g.name).is_some_and(|r| r.starts_with(' '))
    })
}

/// The yarn length per stitch of a tile made by a built-in knit generator (module docs);
/// `None` for a pattern of other origin (its stitch count is not known).
pub fn length_per_stitch_m(pattern: &Pattern) -> Option<f64> {
    let generator = knit_generator_of(pattern)?;
    Some(centreline_length_m(pattern) / generator.stitches_per_tile() as f64)
}

/// Run the knit generator `name` for `spec` (see [`GeneratorInfo::generate_stitch`]).
pub fn generate_stitch(name: &str, spec: &StitchSpec) -> Result<StitchTile, GenerateError> {
    crate::info(name)?.generate_stitch(spec)
}

/// The search of [`GeneratorInfo::generate_stitch`]: a knit chart, its default size and the
/// fixed dimensions.
struct Search<'a> {
    info: &'a GeneratorInfo,
    chart: &'static [&'static [knit::Stitch]],
    spec: StitchSpec,
    /// Smallest stitch, in radii.
    min_r: [f64; 2],
    /// Fixed width and height (m).
    fixed: [Option<f64>; 2],
}

impl Search<'_> {
    fn stitches(&self) -> f64 {
        (self.chart.len() * self.chart[0].len()) as f64
    }

    /// The stitch size for loop radius `rho` and free parameter `t >= 1` (a scale over the
    /// smallest size at `rho`).
    fn size(&self, rho: f64, t: f64) -> [f64; 2] {
        let d = self.info.defaults;
        match self.fixed {
            [Some(w), Some(h)] => [w, h],
            [Some(w), None] => [w, t * self.min_r[1] * rho],
            [None, Some(h)] => [t * self.min_r[0] * rho, h],
            [None, None] => {
                let s = (self.min_r[0] * rho / d.stitch_width_m).max(self.min_r[1] * rho / d.stitch_height_m);
                [t * s * d.stitch_width_m, t * s * d.stitch_height_m]
            }
        }
    }

    fn params(&self, rho: f64, t: f64) -> GeneratorParams {
        let [w, h] = self.size(rho, t);
        GeneratorParams {
            stitch_width_m: w,
            stitch_height_m: h,
            yarn_radius_m: rho,
            vertices_per_stitch: self.info.defaults.vertices_per_stitch,
        }
    }

    /// Length per stitch of the tile at `rho` and `t` (no clearance check).
    fn length(&self, rho: f64, t: f64) -> Result<f64, GenerateError> {
        let pattern = knit::knit(self.info.name, self.chart, &self.params(rho, t))?;
        Ok(centreline_length_m(&pattern) / self.stitches())
    }

    /// The value in `[lo, hi]` where the increasing `f` meets the target, by bisection.
    fn bisect(
        &self,
        mut lo: f64,
        mut hi: f64,
        f: impl Fn(f64) -> Result<f64, GenerateError>,
    ) -> Result<f64, GenerateError> {
        let target = self.spec.length_m;
        for _ in 0..MAX_STEPS {
            let mid = 0.5 * (lo + hi);
            let l = f(mid)?;
            if (l / target - 1.0).abs() <= LENGTH_TOLERANCE {
                return Ok(mid);
            }
            if l < target {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Ok(0.5 * (lo + hi))
    }

    fn error(&self, message: String) -> GenerateError {
        GenerateError::Stitch { name: self.info.name.into(), spec: Box::new(self.spec), message }
    }

    fn mm(v: f64) -> String {
        format!("{:.4} mm", v * 1e3)
    }

    /// `(rho, t)` of the stitch (module docs, steps 2-4).
    fn solve(&self) -> Result<(f64, f64), GenerateError> {
        let (r, target) = (self.spec.yarn_radius_m, self.spec.length_m);
        let floor = self.spec.core_radius_m.unwrap_or(r);
        let floor_name = if self.spec.core_radius_m.is_some() { "core radius" } else { "yarn radius" };
        // The largest loop radius the fixed dimensions leave room for.
        let mut rho_max = r;
        for (k, what) in [(0, "wale width"), (1, "course height")] {
            if let Some(size) = self.fixed[k] {
                rho_max = rho_max.min(size / self.min_r[k]);
                if size < self.min_r[k] * floor * (1.0 - 1e-9) {
                    return Err(self.error(format!(
                        "a {what} of {} is too small for the {floor_name} {}: it needs at least {}",
                        Self::mm(size),
                        Self::mm(floor),
                        Self::mm(self.min_r[k] * floor)
                    )));
                }
            }
        }
        let rho_max = rho_max.max(floor);
        let shortest = self.length(floor, 1.0)?;
        if target < shortest * (1.0 - LENGTH_TOLERANCE) {
            let how = if self.spec.core_radius_m.is_some() {
                "even with the yarn compressed to its core"
            } else {
                "at this yarn radius (no core radius given: the yarn is not compressed)"
            };
            return Err(self.error(format!(
                "a yarn length of {} per stitch is too short {how}: the shortest stitch without \
                 self-overlap takes {} per stitch at loop radius {}",
                Self::mm(target),
                Self::mm(shortest),
                Self::mm(floor)
            )));
        }
        let loosest_compressed = self.length(rho_max, 1.0)?;
        if target <= loosest_compressed * (1.0 + LENGTH_TOLERANCE) {
            // Compressed (or exactly at the smallest stitch): lower rho.
            if rho_max == floor {
                return Ok((floor, 1.0));
            }
            return Ok((self.bisect(floor, rho_max, |rho| self.length(rho, 1.0))?, 1.0));
        }
        if self.fixed.iter().all(Option::is_some) {
            return Err(self.error(format!(
                "a yarn length of {} per stitch is too long for a stitch of {} x {}: it takes at \
                 most {}; give at most one of courses_per_m and wales_per_m",
                Self::mm(target),
                Self::mm(self.fixed[0].unwrap_or_default()),
                Self::mm(self.fixed[1].unwrap_or_default()),
                Self::mm(loosest_compressed)
            )));
        }
        let mut hi = 2.0;
        while self.length(rho_max, hi)? < target {
            hi *= 2.0;
            if hi > MAX_SCALE {
                return Err(
                    self.error(format!("a yarn length of {} per stitch is too long", Self::mm(target)))
                );
            }
        }
        Ok((rho_max, self.bisect(1.0, hi, |t| self.length(rho_max, t))?))
    }
}

impl GeneratorInfo {
    /// Stitches in one tile of a knit generator (its chart's courses x wales); 0 for a weave.
    pub fn stitches_per_tile(&self) -> usize {
        match self.chart {
            Chart::Knit(chart) => chart.len() * chart[0].len(),
            Chart::Weave(_) => 0,
        }
    }

    /// A tile of this knit generator whose yarn length per stitch is `spec.length_m` (within
    /// [`LENGTH_TOLERANCE`]), yarns of radius `spec.yarn_radius_m`, by the rule of the
    /// [module docs](self), at the default resolution. The tile's clearance is checked as
    /// [`GeneratorInfo::generate`] does, against the loop radius.
    pub fn generate_stitch(&self, spec: &StitchSpec) -> Result<StitchTile, GenerateError> {
        let Chart::Knit(chart) = self.chart else {
            return Err(GenerateError::Stitch {
                name: self.name.into(),
                spec: Box::new(*spec),
                message: format!("a yarn length per stitch needs a knit generator; {} is woven", self.name),
            });
        };
        check_spec(self.name, spec)?;
        let fixed = [spec.wales_per_m.map(|n| 1.0 / n), spec.courses_per_m.map(|n| 1.0 / n)];
        let search = Search { info: self, chart, spec: *spec, min_r: min_stitch_r(chart), fixed };
        let (rho, t) = search.solve()?;
        let params = search.params(rho, t);
        let mut pattern = self.generate(&params)?;
        pattern.origin = format!("{} for stitch {spec}", pattern.origin);
        for yarn in &mut pattern.yarns {
            yarn.radius_m = spec.yarn_radius_m;
        }
        debug_assert_eq!(pattern.fabric, Fabric::Knit);
        let length_per_stitch_m = centreline_length_m(&pattern) / search.stitches();
        Ok(StitchTile { pattern, params, length_per_stitch_m })
    }
}

/// Refuse a spec whose numbers are not usable.
fn check_spec(name: &str, spec: &StitchSpec) -> Result<(), GenerateError> {
    let error = |message: String| GenerateError::Stitch { name: name.into(), spec: Box::new(*spec), message };
    let positive = |v: f64| v.is_finite() && v > 0.0;
    for (field, value) in [
        ("length_m", Some(spec.length_m)),
        ("yarn_radius_m", Some(spec.yarn_radius_m)),
        ("core_radius_m", spec.core_radius_m),
        ("courses_per_m", spec.courses_per_m),
        ("wales_per_m", spec.wales_per_m),
    ] {
        if value.is_some_and(|v| !positive(v)) {
            return Err(error(format!("{field} must be a finite number > 0")));
        }
    }
    if spec.core_radius_m.is_some_and(|c| c >= spec.yarn_radius_m) {
        return Err(error("core_radius_m must be below yarn_radius_m".into()));
    }
    Ok(())
}
