//! Measurement sets: what was measured on a real fabric swatch, as a directory of plain files.
//!
//! ```text
//! DIR/fabric.toml    name, pattern, [swatch], [stitch], [[yarn]]
//! DIR/stretch.csv    direction,stretch,force_n,compression,phase,repeat
//! DIR/bending.csv    direction,clamp_distance_m,aspect_ratio      (optional)
//! DIR/cantilever.csv direction,face,overhang_m,tip_drop_m         (optional)
//! ```
//!
//! The full format, units, defaults and validation rules are in `schemas/measurement-set.md`.
//! [`MeasurementSet::read`] validates everything it reads and names the file, the 1-based line
//! and the column of every bad value ([`MeasureError::Value`]); [`MeasurementSet::write`] writes
//! numbers with Rust's shortest round-tripping `Display`, so write-then-read gives back the
//! same set bit for bit.

use std::fmt;
use std::path::{Path, PathBuf};

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use yarnhom_artifacts::container::content_hash;
use yarnhom_artifacts::{InputRef, Pattern};
use yarnhom_pattern::{GenerateError, GeneratorParams, StitchSpec};

/// File name of the fabric description in a measurement set.
pub const FABRIC_FILE: &str = "fabric.toml";
/// File name of the uniaxial stretch tests in a measurement set.
pub const STRETCH_FILE: &str = "stretch.csv";
/// File name of the (optional) pear-loop bending tests in a measurement set.
pub const BENDING_FILE: &str = "bending.csv";
/// File name of the (optional) cantilever bending tests in a measurement set.
pub const CANTILEVER_FILE: &str = "cantilever.csv";

/// Absolute part of the negative-force noise floor, in newtons: a force below
/// `-max(NEGATIVE_FORCE_FLOOR_N, NEGATIVE_FORCE_FRACTION * largest |force|)` at positive stretch
/// is refused as a sign error rather than gauge noise.
pub const NEGATIVE_FORCE_FLOOR_N: f64 = 0.05;
/// Relative part of the negative-force noise floor: a fraction of the set's largest |force|.
pub const NEGATIVE_FORCE_FRACTION: f64 = 0.02;

/// Default free length between the clamps (thesis Sec. 6.2.3), in metres.
pub const DEFAULT_SWATCH_LENGTH_M: f64 = 0.10;
/// Default swatch width (thesis Sec. 6.2.3), in metres.
pub const DEFAULT_SWATCH_WIDTH_M: f64 = 0.06;

const STRETCH_COLUMNS: [&str; 6] = ["direction", "stretch", "force_n", "compression", "phase", "repeat"];
const STRETCH_REQUIRED: [&str; 3] = ["direction", "stretch", "force_n"];
const BENDING_COLUMNS: [&str; 3] = ["direction", "clamp_distance_m", "aspect_ratio"];
const CANTILEVER_COLUMNS: [&str; 4] = ["direction", "face", "overhang_m", "tip_drop_m"];

/// Why a measurement set could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum MeasureError {
    /// A file could not be read or written.
    #[error("{}: {error}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        error: std::io::Error,
    },
    /// `fabric.toml` is not valid TOML or does not have the expected fields.
    #[error("{}: {message}", path.display())]
    Toml {
        /// The file.
        path: PathBuf,
        /// The parser's message (with line and column).
        message: String,
    },
    /// A field of `fabric.toml` has a value out of its range.
    #[error("{}: field `{field}`: {message}", path.display())]
    Field {
        /// The file.
        path: PathBuf,
        /// The field, as a TOML path (`swatch.length_m`, `yarn[1].mass_fraction`).
        field: String,
        /// What is wrong with it.
        message: String,
    },
    /// A bad value, header or row in a CSV file.
    #[error("{}:{line}: column `{column}`: {message}", path.display())]
    Value {
        /// The file.
        path: PathBuf,
        /// 1-based line number (1 is the header).
        line: usize,
        /// The column's name.
        column: String,
        /// What is wrong.
        message: String,
    },
    /// A CSV file with a header but no data rows, or with no header at all.
    #[error("{}: no data rows", path.display())]
    Empty {
        /// The file.
        path: PathBuf,
    },
    /// `fabric.toml`'s `pattern` names neither a file nor a built-in generator.
    #[error("pattern '{spec}' of {}: neither a file nor a generator", dir.display())]
    Pattern {
        /// The measurement set's directory.
        dir: PathBuf,
        /// The `pattern` field.
        spec: String,
        /// Why it is not a generator.
        #[source]
        source: GenerateError,
    },
}

/// Result type of this module.
pub type Result<T> = std::result::Result<T, MeasureError>;

/// In-plane direction of a test, relative to the fabric.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum Direction {
    /// Along the courses (knits) or the weft (wovens): `weft`.
    Weft,
    /// At 45 degrees: `bias`.
    Bias,
    /// Along the wales (knits) or the warp (wovens): `warp`.
    Warp,
}

impl Direction {
    /// Every direction, in file order.
    pub const ALL: [Direction; 3] = [Direction::Weft, Direction::Bias, Direction::Warp];

    /// The name used in the CSV files.
    pub fn as_str(self) -> &'static str {
        match self {
            Direction::Weft => "weft",
            Direction::Bias => "bias",
            Direction::Warp => "warp",
        }
    }

    /// The direction named `name` (`weft`, `bias` or `warp`), if any.
    pub fn parse(name: &str) -> Option<Direction> {
        Direction::ALL.into_iter().find(|d| d.as_str() == name)
    }

    /// Per-direction values, in [`Direction::ALL`] order, given as one value for every direction
    /// or as three (weft, bias, warp); `None` for any other count.
    pub fn per_direction(values: &[f64]) -> Option<[f64; 3]> {
        match *values {
            [v] => Some([v; 3]),
            [weft, bias, warp] => Some([weft, bias, warp]),
            _ => None,
        }
    }
}

impl fmt::Display for Direction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Whether a stretch point was taken while loading or unloading the swatch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Phase {
    /// Stretch increasing: `load`.
    Load,
    /// Stretch decreasing after the maximum: `unload`.
    Unload,
}

impl Phase {
    /// Both phases, in file order.
    pub const ALL: [Phase; 2] = [Phase::Load, Phase::Unload];

    /// The name used in the CSV files.
    pub fn as_str(self) -> &'static str {
        match self {
            Phase::Load => "load",
            Phase::Unload => "unload",
        }
    }

    /// The phase named `name` (`load` or `unload`), if any.
    pub fn parse(name: &str) -> Option<Phase> {
        Phase::ALL.into_iter().find(|p| p.as_str() == name)
    }
}

impl fmt::Display for Phase {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Which face of the fabric is up in a cantilever test.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Face {
    /// The reference face up (the technical face of a knit; the material frame's normal): `up`.
    Up,
    /// Turned over: `down`.
    Down,
}

impl Face {
    /// Both faces, in file order.
    pub const ALL: [Face; 2] = [Face::Up, Face::Down];

    /// The name used in the CSV files.
    pub fn as_str(self) -> &'static str {
        match self {
            Face::Up => "up",
            Face::Down => "down",
        }
    }

    /// The face named `name` (`up` or `down`), if any.
    pub fn parse(name: &str) -> Option<Face> {
        Face::ALL.into_iter().find(|f| f.as_str() == name)
    }
}

impl fmt::Display for Face {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// `fabric.toml`: what was measured.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fabric {
    /// Free-form name of the fabric.
    pub name: String,
    /// The yarn pattern: a built-in generator name (`yarnhom pattern list`), a `.pattern.yh` or a
    /// `.pyp` path (relative paths are relative to the measurement set's directory).
    pub pattern: String,
    /// Swatch dimensions (defaults of thesis Sec. 6.2.3 when the table is absent).
    #[serde(default)]
    pub swatch: Swatch,
    /// The fabric's own stitch, if known: a generated `pattern` is built for it, and its core
    /// radius holds the yarn model's inner contact radius (absent: the generator's default
    /// stitch and the thesis' `R_2`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stitch: Option<Stitch>,
    /// The yarns the fabric is made of, if known.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub yarn: Vec<Yarn>,
}

/// Where a set's input yarn geometry comes from: [`Fabric::pattern`] resolved.
#[derive(Debug, Clone, PartialEq)]
pub enum PatternSource {
    /// A pattern file (`.pattern.yh`, a JSON document, an HDF5 export or a `.pyp`).
    File(PathBuf),
    /// A built-in generator.
    Generator(Generator),
}

/// A built-in generator as a set uses it: at its default stitch size, or for the set's
/// `[stitch]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Generator {
    /// The generator's name.
    pub name: String,
    /// Its default parameters.
    pub params: GeneratorParams,
    /// The set's stitch, if it gives one: the tile is generated for it
    /// ([`yarnhom_pattern::generate_stitch`]) instead of at the default parameters.
    pub stitch: Option<StitchSpec>,
}

impl Generator {
    /// The generated tile: [`yarnhom_pattern::generate_stitch`] for the set's stitch (yarn length
    /// per stitch within 1%, the stitch's yarn radius), else the generator at its defaults.
    pub fn generate(&self) -> std::result::Result<Pattern, GenerateError> {
        match &self.stitch {
            Some(spec) => Ok(yarnhom_pattern::generate_stitch(&self.name, spec)?.pattern),
            None => yarnhom_pattern::generate(&self.name, &self.params),
        }
    }
}

impl Fabric {
    /// The input geometry of the set in `set_dir`: the file `pattern` names (relative to the
    /// set's directory, or as given), else the built-in generator of that name, for the set's
    /// `[stitch]` if it has one. A pattern file is used as it is: `[stitch]` does not change
    /// its geometry.
    pub fn pattern_source(&self, set_dir: &Path) -> Result<PatternSource> {
        let spec = &self.pattern;
        let candidates = [set_dir.join(spec), PathBuf::from(spec)];
        if let Some(path) = candidates.into_iter().find(|p| p.is_file()) {
            return Ok(PatternSource::File(path));
        }
        let params = GeneratorParams::defaults_for(spec).map_err(|source| MeasureError::Pattern {
            dir: set_dir.to_path_buf(),
            spec: spec.clone(),
            source,
        })?;
        let stitch = self.stitch.as_ref().map(Stitch::spec);
        Ok(PatternSource::Generator(Generator { name: spec.clone(), params, stitch }))
    }
}

/// `[stitch]`: the fabric's own stitch.
///
/// The yarn length per stitch is the centreline length of yarn in one stitch (for a periodic
/// tile: the total centreline length of its yarns over its stitches); the core radius is the
/// radius of the yarn's incompressible part, to which a yarn squashed in its crossings can give.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Stitch {
    /// Yarn length per stitch, in metres (required in the table).
    pub length_m: f64,
    /// Yarn radius, in metres (required in the table).
    pub yarn_radius_m: f64,
    /// Radius of the yarn's incompressible core, in metres (below the yarn radius), if known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub core_radius_m: Option<f64>,
    /// Courses per metre, if known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub courses_per_m: Option<f64>,
    /// Wales per metre, if known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wales_per_m: Option<f64>,
}

impl Stitch {
    /// The stitch as the knit generators take it.
    pub fn spec(&self) -> StitchSpec {
        StitchSpec {
            length_m: self.length_m,
            yarn_radius_m: self.yarn_radius_m,
            core_radius_m: self.core_radius_m,
            courses_per_m: self.courses_per_m,
            wales_per_m: self.wales_per_m,
        }
    }
}

/// A length in millimetres to 0.1 µm, without trailing zeros (`11.28`, `0.325`).
fn mm(metres: f64) -> String {
    let text = format!("{:.4}", metres * 1e3);
    text.trim_end_matches('0').trim_end_matches('.').to_string()
}

impl fmt::Display for Stitch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} mm of yarn per stitch, yarn radius {} mm", mm(self.length_m), mm(self.yarn_radius_m))?;
        if let Some(c) = self.core_radius_m {
            write!(f, ", core radius {} mm", mm(c))?;
        }
        if let Some(n) = self.courses_per_m {
            write!(f, ", {n} courses/m")?;
        }
        if let Some(n) = self.wales_per_m {
            write!(f, ", {n} wales/m")?;
        }
        Ok(())
    }
}

/// `[swatch]`: the tested piece of fabric, and where its deformation was read.
///
/// The top-level keys describe every direction's swatch; a `[swatch.weft]`, `[swatch.bias]` or
/// `[swatch.warp]` table overrides them for that direction's test (real tests often use a
/// separate piece per direction). [`Swatch::specimen`] resolves one direction's geometry.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Swatch {
    /// Free length between the clamps at rest, in metres (default 0.10).
    #[serde(default = "default_length_m")]
    pub length_m: f64,
    /// Width at rest, in metres (default 0.06).
    #[serde(default = "default_width_m")]
    pub width_m: f64,
    /// Rest distance between two stretch markers centred on the swatch along the pull, in
    /// metres; absent: stretch is read between the clamps.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stretch_gauge_m: Option<f64>,
    /// Rest distance between two compression markers across the swatch at mid-length, in
    /// metres; absent: compression is read between the free edges.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compression_gauge_m: Option<f64>,
    /// Mass per unit area, in kg/m², if measured.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub areal_density_kg_m2: Option<f64>,
    /// Overrides for the weft test's swatch.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weft: Option<SwatchOverride>,
    /// Overrides for the bias test's swatch.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bias: Option<SwatchOverride>,
    /// Overrides for the warp test's swatch.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub warp: Option<SwatchOverride>,
}

/// `[swatch.<direction>]`: one direction's swatch, where it differs from `[swatch]`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SwatchOverride {
    /// Free length between the clamps, in metres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub length_m: Option<f64>,
    /// Width, in metres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub width_m: Option<f64>,
    /// Stretch marker distance, in metres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stretch_gauge_m: Option<f64>,
    /// Compression marker distance, in metres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compression_gauge_m: Option<f64>,
}

/// One direction's tested swatch, resolved from `[swatch]` and its override.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Specimen {
    /// Free length between the clamps (m).
    pub length_m: f64,
    /// Width (m).
    pub width_m: f64,
    /// Stretch marker distance (m); the clamps when absent.
    pub stretch_gauge_m: Option<f64>,
    /// Compression marker distance (m); the free edges when absent.
    pub compression_gauge_m: Option<f64>,
}

impl fmt::Display for Specimen {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} m long x {} m wide", self.length_m, self.width_m)?;
        if let Some(g) = self.stretch_gauge_m {
            write!(f, ", stretch read over {g} m")?;
        }
        if let Some(g) = self.compression_gauge_m {
            write!(f, ", compression read over {g} m")?;
        }
        Ok(())
    }
}

impl Default for Swatch {
    fn default() -> Self {
        Swatch {
            length_m: DEFAULT_SWATCH_LENGTH_M,
            width_m: DEFAULT_SWATCH_WIDTH_M,
            stretch_gauge_m: None,
            compression_gauge_m: None,
            areal_density_kg_m2: None,
            weft: None,
            bias: None,
            warp: None,
        }
    }
}

impl Swatch {
    /// The override table of `direction`, if any.
    pub fn override_for(&self, direction: Direction) -> Option<&SwatchOverride> {
        match direction {
            Direction::Weft => self.weft.as_ref(),
            Direction::Bias => self.bias.as_ref(),
            Direction::Warp => self.warp.as_ref(),
        }
    }

    /// The swatch tested along `direction`.
    pub fn specimen(&self, direction: Direction) -> Specimen {
        let o = self.override_for(direction).cloned().unwrap_or_default();
        Specimen {
            length_m: o.length_m.unwrap_or(self.length_m),
            width_m: o.width_m.unwrap_or(self.width_m),
            stretch_gauge_m: o.stretch_gauge_m.or(self.stretch_gauge_m),
            compression_gauge_m: o.compression_gauge_m.or(self.compression_gauge_m),
        }
    }
}

fn default_length_m() -> f64 {
    DEFAULT_SWATCH_LENGTH_M
}

fn default_width_m() -> f64 {
    DEFAULT_SWATCH_WIDTH_M
}

/// `[[yarn]]`: one yarn of the fabric.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Yarn {
    /// Fibre material, free-form (`acrylic`, `cotton`, ...).
    pub material: String,
    /// Linear density in tex (g/km), if known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub linear_density_tex: Option<f64>,
    /// Tensile stiffness: force per unit yarn strain, in newtons, if known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness_n: Option<f64>,
    /// Fraction of the fabric's mass made of this yarn, in (0, 1], if known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass_fraction: Option<f64>,
}

/// One row of `stretch.csv`: a uniaxial stretch test reading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StretchPoint {
    /// Pull direction.
    pub direction: Direction,
    /// Engineering stretch along the pull, `l / l_rest - 1` (dimensionless, > -1).
    pub stretch: f64,
    /// Total clamp force in newtons.
    pub force_n: f64,
    /// Transverse compression `1 - w / w_rest` (dimensionless, < 1), if measured.
    pub compression: Option<f64>,
    /// Loading or unloading.
    pub phase: Phase,
    /// Which repeat of the test (e.g. the video number) the point belongs to, if known.
    pub repeat: Option<u32>,
}

/// One row of `bending.csv`: a pear-loop bending test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BendingPoint {
    /// Direction of the strip's long axis.
    pub direction: Direction,
    /// Distance between the clamped ends of the loop, in metres (> 0).
    pub clamp_distance_m: f64,
    /// Height over width of the loop (dimensionless, > 0).
    pub aspect_ratio: f64,
}

/// One row of `cantilever.csv`: a cantilever bending test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CantileverPoint {
    /// Direction of the strip's long axis.
    pub direction: Direction,
    /// Which face was up.
    pub face: Face,
    /// Free length beyond the clamp, in metres (> 0).
    pub overhang_m: f64,
    /// Drop of the free end below the clamp, in metres (negative when it curls up; at most the
    /// overhang in size).
    pub tip_drop_m: f64,
}

/// A measurement set: the fabric, its stretch tests and its bending tests.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasurementSet {
    /// `fabric.toml`.
    pub fabric: Fabric,
    /// `stretch.csv`, in file order.
    pub stretch: Vec<StretchPoint>,
    /// `bending.csv`, in file order (empty when the file is absent).
    pub bending: Vec<BendingPoint>,
    /// `cantilever.csv`, in file order (empty when the file is absent).
    pub cantilever: Vec<CantileverPoint>,
}

impl MeasurementSet {
    /// Read and validate the measurement set in directory `dir`.
    pub fn read(dir: &Path) -> Result<MeasurementSet> {
        let fabric = read_fabric(&dir.join(FABRIC_FILE))?;
        let stretch = read_stretch(&dir.join(STRETCH_FILE))?;
        let bending_path = dir.join(BENDING_FILE);
        let bending = if bending_path.exists() { read_bending(&bending_path)? } else { Vec::new() };
        let cantilever_path = dir.join(CANTILEVER_FILE);
        let cantilever =
            if cantilever_path.exists() { read_cantilever(&cantilever_path)? } else { Vec::new() };
        Ok(MeasurementSet { fabric, stretch, bending, cantilever })
    }

    /// Write the set into directory `dir` (created if missing; files of the same names are
    /// replaced, and a stale `bending.csv` or `cantilever.csv` is removed when the set has no
    /// such points).
    pub fn write(&self, dir: &Path) -> Result<()> {
        std::fs::create_dir_all(dir).map_err(|error| MeasureError::Io { path: dir.to_path_buf(), error })?;
        let fabric_path = dir.join(FABRIC_FILE);
        let fabric = toml::to_string(&self.fabric)
            .map_err(|e| MeasureError::Toml { path: fabric_path.clone(), message: e.to_string() })?;
        write_file(&fabric_path, &fabric)?;
        write_file(&dir.join(STRETCH_FILE), &stretch_csv(&self.stretch))?;
        write_optional_file(
            &dir.join(BENDING_FILE),
            (!self.bending.is_empty()).then(|| bending_csv(&self.bending)),
        )?;
        write_optional_file(
            &dir.join(CANTILEVER_FILE),
            (!self.cantilever.is_empty()).then(|| cantilever_csv(&self.cantilever)),
        )
    }

    /// The set in directory `dir` as a provenance input: kind `measurement-set`, the content
    /// hash of its `fabric.toml` and `stretch.csv` bytes, in that order.
    pub fn input_ref(dir: &Path) -> Result<InputRef> {
        let mut bytes = Vec::new();
        for name in [FABRIC_FILE, STRETCH_FILE] {
            let path = dir.join(name);
            bytes.extend(std::fs::read(&path).map_err(|error| MeasureError::Io { path, error })?);
        }
        Ok(InputRef {
            kind: "measurement-set".into(),
            content_hash: content_hash(&bytes),
            path: dir.display().to_string(),
        })
    }

    /// A human summary: the fabric, then points per direction and phase with their stretch and
    /// force ranges, then the bending points per direction.
    pub fn summary(&self) -> String {
        let mut lines = vec![format!("fabric: {} (pattern {})", self.fabric.name, self.fabric.pattern)];
        if let Some(stitch) = &self.fabric.stitch {
            lines.push(format!("stitch: {stitch}"));
        }
        for direction in Direction::ALL.into_iter().filter(|&d| self.stretch.iter().any(|p| p.direction == d))
        {
            lines.push(format!("swatch ({direction}): {}", self.fabric.swatch.specimen(direction)));
        }
        lines.push(format!("stretch points: {}", self.stretch.len()));
        for direction in Direction::ALL {
            for phase in Phase::ALL {
                let points: Vec<&StretchPoint> =
                    self.stretch.iter().filter(|p| p.direction == direction && p.phase == phase).collect();
                if let Some(line) = stretch_group_summary(direction, phase, &points) {
                    lines.push(line);
                }
            }
        }
        lines.push(format!("bending points: {}", self.bending.len()));
        for direction in Direction::ALL {
            let n = self.bending.iter().filter(|p| p.direction == direction).count();
            if n > 0 {
                lines.push(format!("  {direction}: {n}"));
            }
        }
        lines.push(format!("cantilever points: {}", self.cantilever.len()));
        for direction in Direction::ALL {
            for face in Face::ALL {
                let n = self.cantilever.iter().filter(|p| p.direction == direction && p.face == face).count();
                if n > 0 {
                    lines.push(format!("  {direction} face {face}: {n}"));
                }
            }
        }
        lines.join("\n")
    }
}

/// One summary line for the stretch points of a direction and phase; `None` when there are none.
fn stretch_group_summary(direction: Direction, phase: Phase, points: &[&StretchPoint]) -> Option<String> {
    let (stretch_min, stretch_max) = range(points.iter().map(|p| p.stretch))?;
    let (force_min, force_max) = range(points.iter().map(|p| p.force_n))?;
    let mut repeats: Vec<u32> = points.iter().filter_map(|p| p.repeat).collect();
    repeats.sort_unstable();
    repeats.dedup();
    Some(format!(
        "  {direction} {phase}: {} points, {} repeats, stretch {stretch_min:.4} .. {stretch_max:.4}, \
         force {force_min:.3} .. {force_max:.3} N",
        points.len(),
        repeats.len()
    ))
}

/// Smallest and largest value; `None` for no values.
fn range(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    values.fold(None, |acc, v| match acc {
        None => Some((v, v)),
        Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
    })
}

fn write_file(path: &Path, text: &str) -> Result<()> {
    std::fs::write(path, text).map_err(|error| MeasureError::Io { path: path.to_path_buf(), error })
}

/// Write `text` to `path`, or remove a stale `path` when there is nothing to write.
fn write_optional_file(path: &Path, text: Option<String>) -> Result<()> {
    match text {
        Some(text) => write_file(path, &text),
        None if path.exists() => {
            std::fs::remove_file(path).map_err(|error| MeasureError::Io { path: path.to_path_buf(), error })
        }
        None => Ok(()),
    }
}

fn read_text(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).map_err(|error| MeasureError::Io { path: path.to_path_buf(), error })
}

/// The text of `stretch.csv` for `points`: every column, empty cells for absent values.
fn stretch_csv(points: &[StretchPoint]) -> String {
    let mut text = STRETCH_COLUMNS.join(",");
    text.push('\n');
    for p in points {
        text.push_str(&format!(
            "{},{},{},{},{},{}\n",
            p.direction,
            p.stretch,
            p.force_n,
            optional_cell(p.compression),
            p.phase,
            optional_cell(p.repeat)
        ));
    }
    text
}

/// The text of `bending.csv` for `points`.
fn bending_csv(points: &[BendingPoint]) -> String {
    let mut text = BENDING_COLUMNS.join(",");
    text.push('\n');
    for p in points {
        text.push_str(&format!("{},{},{}\n", p.direction, p.clamp_distance_m, p.aspect_ratio));
    }
    text
}

/// The text of `cantilever.csv` for `points`.
fn cantilever_csv(points: &[CantileverPoint]) -> String {
    let mut text = CANTILEVER_COLUMNS.join(",");
    text.push('\n');
    for p in points {
        text.push_str(&format!("{},{},{},{}\n", p.direction, p.face, p.overhang_m, p.tip_drop_m));
    }
    text
}

fn optional_cell<T: fmt::Display>(value: Option<T>) -> String {
    value.map_or(String::new(), |v| v.to_string())
}

/// Read and validate `fabric.toml`.
pub fn read_fabric(path: &Path) -> Result<Fabric> {
    let text = read_text(path)?;
    let fabric: Fabric = toml::from_str(&text)
        .map_err(|e| MeasureError::Toml { path: path.to_path_buf(), message: e.to_string() })?;
    validate_fabric(path, &fabric)?;
    Ok(fabric)
}

fn validate_fabric(path: &Path, fabric: &Fabric) -> Result<()> {
    let field_error = |field: String, message: &str| MeasureError::Field {
        path: path.to_path_buf(),
        field,
        message: message.to_string(),
    };
    if fabric.name.trim().is_empty() {
        return Err(field_error("name".into(), "must not be empty"));
    }
    if fabric.pattern.trim().is_empty() {
        return Err(field_error("pattern".into(), "must not be empty"));
    }
    for (field, value) in positive_fields(fabric) {
        if value.is_some_and(|v| !(v.is_finite() && v > 0.0)) {
            return Err(field_error(field, "must be a finite number > 0"));
        }
    }
    if let Some((field, message)) = gauge_problem(&fabric.swatch) {
        return Err(field_error(field, message));
    }
    if let Some(stitch) = &fabric.stitch
        && stitch.core_radius_m.is_some_and(|c| c >= stitch.yarn_radius_m)
    {
        return Err(field_error("stitch.core_radius_m".into(), "must be below stitch.yarn_radius_m"));
    }
    for (i, yarn) in fabric.yarn.iter().enumerate() {
        if yarn.mass_fraction.is_some_and(|m| m > 1.0) {
            return Err(field_error(format!("yarn[{i}].mass_fraction"), "must be at most 1"));
        }
    }
    Ok(())
}

/// The fields of `fabric` that must be finite numbers > 0 where given, by TOML path, in the
/// order they are checked.
fn positive_fields(fabric: &Fabric) -> Vec<(String, Option<f64>)> {
    let swatch = &fabric.swatch;
    let mut positive = vec![
        ("swatch.length_m".to_string(), Some(swatch.length_m)),
        ("swatch.width_m".to_string(), Some(swatch.width_m)),
        ("swatch.stretch_gauge_m".to_string(), swatch.stretch_gauge_m),
        ("swatch.compression_gauge_m".to_string(), swatch.compression_gauge_m),
        ("swatch.areal_density_kg_m2".to_string(), swatch.areal_density_kg_m2),
    ];
    for direction in Direction::ALL {
        if let Some(o) = swatch.override_for(direction) {
            let key = |k: &str| format!("swatch.{direction}.{k}");
            positive.push((key("length_m"), o.length_m));
            positive.push((key("width_m"), o.width_m));
            positive.push((key("stretch_gauge_m"), o.stretch_gauge_m));
            positive.push((key("compression_gauge_m"), o.compression_gauge_m));
        }
    }
    if let Some(stitch) = &fabric.stitch {
        positive.push(("stitch.length_m".to_string(), Some(stitch.length_m)));
        positive.push(("stitch.yarn_radius_m".to_string(), Some(stitch.yarn_radius_m)));
        positive.push(("stitch.core_radius_m".to_string(), stitch.core_radius_m));
        positive.push(("stitch.courses_per_m".to_string(), stitch.courses_per_m));
        positive.push(("stitch.wales_per_m".to_string(), stitch.wales_per_m));
    }
    for (i, yarn) in fabric.yarn.iter().enumerate() {
        positive.push((format!("yarn[{i}].linear_density_tex"), yarn.linear_density_tex));
        positive.push((format!("yarn[{i}].stiffness_n"), yarn.stiffness_n));
        positive.push((format!("yarn[{i}].mass_fraction"), yarn.mass_fraction));
    }
    positive
}

/// The first marker gauge longer than its direction's swatch: the field and what is wrong.
fn gauge_problem(swatch: &Swatch) -> Option<(String, &'static str)> {
    for direction in Direction::ALL {
        let specimen = swatch.specimen(direction);
        let prefix = if swatch.override_for(direction).is_some() {
            format!("swatch.{direction}")
        } else {
            "swatch".into()
        };
        if specimen.stretch_gauge_m.is_some_and(|g| g > specimen.length_m) {
            return Some((format!("{prefix}.stretch_gauge_m"), "must be at most the swatch length"));
        }
        if specimen.compression_gauge_m.is_some_and(|g| g > specimen.width_m) {
            return Some((format!("{prefix}.compression_gauge_m"), "must be at most the swatch width"));
        }
    }
    None
}

/// A CSV file split into a header and rows of fields (no quoting: the format needs none).
struct Table {
    path: PathBuf,
    columns: Vec<String>,
    rows: Vec<Row>,
}

/// A data row and its 1-based line number.
struct Row {
    line: usize,
    fields: Vec<String>,
}

impl Table {
    /// Read `path`, check its header against the `known` columns and the `required` ones, and
    /// check every row has one field per column. Blank lines are skipped.
    fn read(path: &Path, known: &[&str], required: &[&str]) -> Result<Table> {
        let text = read_text(path)?;
        let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l.trim_end_matches('\r')));
        let Some((_, header)) = lines.next() else {
            return Err(MeasureError::Empty { path: path.to_path_buf() });
        };
        let columns: Vec<String> = header.split(',').map(|c| c.trim().to_string()).collect();
        let table = Table { path: path.to_path_buf(), columns, rows: Vec::new() };
        table.check_header(known, required)?;
        let mut rows = Vec::new();
        for (line, content) in lines.filter(|(_, l)| !l.trim().is_empty()) {
            let fields: Vec<String> = content.split(',').map(|f| f.trim().to_string()).collect();
            table.check_field_count(line, &fields)?;
            rows.push(Row { line, fields });
        }
        if rows.is_empty() {
            return Err(MeasureError::Empty { path: path.to_path_buf() });
        }
        Ok(Table { rows, ..table })
    }

    fn check_header(&self, known: &[&str], required: &[&str]) -> Result<()> {
        for (i, column) in self.columns.iter().enumerate() {
            if !known.contains(&column.as_str()) {
                let expected = known.join(", ");
                return Err(self.error(1, column, &format!("unknown column (expected some of {expected})")));
            }
            if self.columns[..i].contains(column) {
                return Err(self.error(1, column, "column appears twice"));
            }
        }
        match required.iter().find(|r| !self.columns.iter().any(|c| c == *r)) {
            Some(missing) => Err(self.error(1, missing, "missing required column")),
            None => Ok(()),
        }
    }

    fn check_field_count(&self, line: usize, fields: &[String]) -> Result<()> {
        if fields.len() < self.columns.len() {
            let missing = &self.columns[fields.len()];
            return Err(self.error(line, missing, "missing value (fewer fields than the header)"));
        }
        if fields.len() > self.columns.len() {
            let message =
                format!("{} fields but the header has {} columns", fields.len(), self.columns.len());
            return Err(self.error(line, self.columns.last().map_or("", String::as_str), &message));
        }
        Ok(())
    }

    fn error(&self, line: usize, column: &str, message: &str) -> MeasureError {
        MeasureError::Value {
            path: self.path.clone(),
            line,
            column: column.to_string(),
            message: message.to_string(),
        }
    }

    /// The cell of `row` in `column`; `None` when the file has no such column.
    fn cell<'a>(&self, row: &'a Row, column: &str) -> Option<&'a str> {
        let index = self.columns.iter().position(|c| c == column)?;
        row.fields.get(index).map(String::as_str)
    }

    /// The cell of `row` in `column` as a finite number; `None` when the column is absent or
    /// the cell empty.
    fn optional_number(&self, row: &Row, column: &str) -> Result<Option<f64>> {
        match self.cell(row, column) {
            None | Some("") => Ok(None),
            Some(text) => match text.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(Some(v)),
                Ok(_) => Err(self.error(row.line, column, &format!("`{text}` is not a finite number"))),
                Err(_) => Err(self.error(row.line, column, &format!("`{text}` is not a number"))),
            },
        }
    }

    /// The cell of `row` in a required numeric `column`.
    fn number(&self, row: &Row, column: &str) -> Result<f64> {
        self.optional_number(row, column)?.ok_or_else(|| self.error(row.line, column, "missing value"))
    }

    fn direction(&self, row: &Row) -> Result<Direction> {
        let text = self.cell(row, "direction").unwrap_or("");
        Direction::parse(text).ok_or_else(|| {
            self.error(
                row.line,
                "direction",
                &format!("unknown direction `{text}` (expected weft, bias or warp)"),
            )
        })
    }

    fn phase(&self, row: &Row) -> Result<Phase> {
        match self.cell(row, "phase") {
            None | Some("") => Ok(Phase::Load),
            Some(text) => Phase::parse(text).ok_or_else(|| {
                self.error(row.line, "phase", &format!("unknown phase `{text}` (expected load or unload)"))
            }),
        }
    }

    fn face(&self, row: &Row) -> Result<Face> {
        let text = self.cell(row, "face").unwrap_or("");
        Face::parse(text).ok_or_else(|| {
            self.error(row.line, "face", &format!("unknown face `{text}` (expected up or down)"))
        })
    }

    fn repeat(&self, row: &Row) -> Result<Option<u32>> {
        match self.cell(row, "repeat") {
            None | Some("") => Ok(None),
            Some(text) => text.parse::<u32>().map(Some).map_err(|_| {
                self.error(row.line, "repeat", &format!("`{text}` is not a non-negative integer"))
            }),
        }
    }
}

/// Read and validate `stretch.csv`.
pub fn read_stretch(path: &Path) -> Result<Vec<StretchPoint>> {
    let table = Table::read(path, &STRETCH_COLUMNS, &STRETCH_REQUIRED)?;
    let points = table.rows.iter().map(|row| stretch_point(&table, row)).collect::<Result<Vec<_>>>()?;
    check_negative_forces(&table, &points)?;
    Ok(points)
}

fn stretch_point(table: &Table, row: &Row) -> Result<StretchPoint> {
    let direction = table.direction(row)?;
    let stretch = table.number(row, "stretch")?;
    if stretch <= -1.0 {
        return Err(table.error(row.line, "stretch", "must be > -1 (a positive length)"));
    }
    let force_n = table.number(row, "force_n")?;
    let compression = table.optional_number(row, "compression")?;
    if compression.is_some_and(|c| c >= 1.0) {
        return Err(table.error(row.line, "compression", "must be < 1 (a positive width)"));
    }
    let phase = table.phase(row)?;
    let repeat = table.repeat(row)?;
    Ok(StretchPoint { direction, stretch, force_n, compression, phase, repeat })
}

/// The negative-force noise floor of a set of points, in newtons (a positive number).
pub fn negative_force_floor_n(points: &[StretchPoint]) -> f64 {
    let largest = points.iter().map(|p| p.force_n.abs()).fold(0.0, f64::max);
    NEGATIVE_FORCE_FLOOR_N.max(NEGATIVE_FORCE_FRACTION * largest)
}

/// Refuse a force below minus the noise floor at positive stretch (points are in row order).
fn check_negative_forces(table: &Table, points: &[StretchPoint]) -> Result<()> {
    let floor = negative_force_floor_n(points);
    for (row, p) in table.rows.iter().zip(points) {
        if p.stretch > 0.0 && p.force_n < -floor {
            let message = format!(
                "force {} N at positive stretch {} is below the noise floor -{floor} N",
                p.force_n, p.stretch
            );
            return Err(table.error(row.line, "force_n", &message));
        }
    }
    Ok(())
}

/// Read and validate `bending.csv`.
pub fn read_bending(path: &Path) -> Result<Vec<BendingPoint>> {
    let table = Table::read(path, &BENDING_COLUMNS, &BENDING_COLUMNS)?;
    let points = table.rows.iter().map(|row| bending_point(&table, row)).collect::<Result<Vec<_>>>()?;
    check_monotone_clamp_distance(&table, &points)?;
    Ok(points)
}

fn bending_point(table: &Table, row: &Row) -> Result<BendingPoint> {
    let direction = table.direction(row)?;
    let clamp_distance_m = table.number(row, "clamp_distance_m")?;
    if clamp_distance_m <= 0.0 {
        return Err(table.error(row.line, "clamp_distance_m", "must be > 0"));
    }
    let aspect_ratio = table.number(row, "aspect_ratio")?;
    if aspect_ratio <= 0.0 {
        return Err(table.error(row.line, "aspect_ratio", "must be > 0"));
    }
    Ok(BendingPoint { direction, clamp_distance_m, aspect_ratio })
}

/// Read and validate `cantilever.csv`.
pub fn read_cantilever(path: &Path) -> Result<Vec<CantileverPoint>> {
    let table = Table::read(path, &CANTILEVER_COLUMNS, &CANTILEVER_COLUMNS)?;
    table.rows.iter().map(|row| cantilever_point(&table, row)).collect()
}

fn cantilever_point(table: &Table, row: &Row) -> Result<CantileverPoint> {
    let direction = table.direction(row)?;
    let face = table.face(row)?;
    let overhang_m = table.number(row, "overhang_m")?;
    if overhang_m <= 0.0 {
        return Err(table.error(row.line, "overhang_m", "must be > 0"));
    }
    let tip_drop_m = table.number(row, "tip_drop_m")?;
    if tip_drop_m.abs() > overhang_m {
        let message = format!("a drop of {tip_drop_m} m is longer than the overhang {overhang_m} m");
        return Err(table.error(row.line, "tip_drop_m", &message));
    }
    Ok(CantileverPoint { direction, face, overhang_m, tip_drop_m })
}

/// Within each direction, the clamp distance must be strictly monotone in row order (increasing
/// or decreasing, as set by the direction's first two rows).
fn check_monotone_clamp_distance(table: &Table, points: &[BendingPoint]) -> Result<()> {
    for direction in Direction::ALL {
        let rows: Vec<(&Row, f64)> = table
            .rows
            .iter()
            .zip(points)
            .filter(|(_, p)| p.direction == direction)
            .map(|(row, p)| (row, p.clamp_distance_m))
            .collect();
        let mut trend = 0.0;
        for pair in rows.windows(2) {
            let (row, distance) = pair[1];
            let step = distance - pair[0].1;
            if step == 0.0 || step * trend < 0.0 {
                let message = format!(
                    "clamp distance {distance} after {} breaks the monotone order of direction {direction}",
                    pair[0].1
                );
                return Err(table.error(row.line, "clamp_distance_m", &message));
            }
            trend = step;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn example() -> MeasurementSet {
        MeasurementSet {
            fabric: Fabric {
                name: "test knit".into(),
                pattern: "stockinette".into(),
                swatch: Swatch {
                    length_m: 0.1,
                    width_m: 0.06,
                    stretch_gauge_m: Some(0.05),
                    areal_density_kg_m2: Some(0.3),
                    warp: Some(SwatchOverride { length_m: Some(0.12), ..Default::default() }),
                    ..Swatch::default()
                },
                stitch: Some(Stitch {
                    length_m: 11.28e-3,
                    yarn_radius_m: 0.74e-3,
                    core_radius_m: Some(0.74e-3 / 3.0),
                    courses_per_m: None,
                    wales_per_m: Some(1.0 / 3.0e-3),
                }),
                yarn: vec![Yarn {
                    material: "acrylic".into(),
                    linear_density_tex: Some(50.0),
                    stiffness_n: Some(123.456),
                    mass_fraction: Some(1.0),
                }],
            },
            stretch: vec![
                StretchPoint {
                    direction: Direction::Weft,
                    stretch: 0.1 + 0.2,
                    force_n: 1.0 / 3.0,
                    compression: Some(1e-17),
                    phase: Phase::Load,
                    repeat: Some(1),
                },
                StretchPoint {
                    direction: Direction::Bias,
                    stretch: -0.001,
                    force_n: 0.0,
                    compression: None,
                    phase: Phase::Unload,
                    repeat: None,
                },
            ],
            bending: vec![
                BendingPoint { direction: Direction::Warp, clamp_distance_m: 0.05, aspect_ratio: 1.2 },
                BendingPoint { direction: Direction::Warp, clamp_distance_m: 0.04, aspect_ratio: 1.4 },
            ],
            cantilever: vec![
                CantileverPoint {
                    direction: Direction::Weft,
                    face: Face::Up,
                    overhang_m: 0.05,
                    tip_drop_m: 0.01,
                },
                CantileverPoint {
                    direction: Direction::Weft,
                    face: Face::Down,
                    overhang_m: 0.05,
                    tip_drop_m: -1.0 / 3.0 * 1e-3,
                },
            ],
        }
    }

    #[test]
    fn cantilever_errors_name_line_and_column() {
        let cases = [
            (
                "direction,face,overhang_m,tip_drop_m
weft,sideways,0.05,0.01
",
                ":2: column `face`: unknown face",
            ),
            (
                "direction,face,overhang_m,tip_drop_m
weft,up,0,0
",
                ":2: column `overhang_m`: must be > 0",
            ),
            (
                "direction,face,overhang_m,tip_drop_m
weft,up,0.05,0.06
",
                ":2: column `tip_drop_m`: a drop of 0.06",
            ),
            (
                "direction,face,overhang_m
weft,up,0.05
",
                ":1: column `tip_drop_m`: missing required column",
            ),
        ];
        for (csv, expected) in cases {
            let dir = tempfile::tempdir().expect("tempdir");
            example().write(dir.path()).expect("write");
            std::fs::write(dir.path().join(CANTILEVER_FILE), csv).expect("write");
            let error = MeasurementSet::read(dir.path()).expect_err("must fail").to_string();
            assert!(error.contains("cantilever.csv") && error.contains(expected), "{error} lacks {expected}");
        }
    }

    #[test]
    fn writing_a_set_without_bending_tests_removes_stale_files() {
        let dir = tempfile::tempdir().expect("tempdir");
        example().write(dir.path()).expect("write");
        let stretch_only = MeasurementSet { bending: vec![], cantilever: vec![], ..example() };
        stretch_only.write(dir.path()).expect("write");
        assert!(!dir.path().join(BENDING_FILE).exists() && !dir.path().join(CANTILEVER_FILE).exists());
        assert_eq!(MeasurementSet::read(dir.path()).expect("read"), stretch_only);
    }

    /// Write `stretch` as stretch.csv (and a valid fabric.toml) and return the read error.
    fn stretch_error(stretch: &str) -> (tempfile::TempDir, String) {
        let dir = tempfile::tempdir().expect("tempdir");
        std::fs::write(dir.path().join(FABRIC_FILE), "name = \"x\"\npattern = \"rib\"\n").expect("write");
        std::fs::write(dir.path().join(STRETCH_FILE), stretch).expect("write");
        let error = MeasurementSet::read(dir.path()).expect_err("must fail").to_string();
        (dir, error)
    }

    fn bending_error(bending: &str) -> String {
        let dir = tempfile::tempdir().expect("tempdir");
        example().write(dir.path()).expect("write");
        std::fs::write(dir.path().join(BENDING_FILE), bending).expect("write");
        MeasurementSet::read(dir.path()).expect_err("must fail").to_string()
    }

    #[test]
    fn write_then_read_is_exact() {
        let dir = tempfile::tempdir().expect("tempdir");
        let set = example();
        set.write(dir.path()).expect("write");
        assert_eq!(MeasurementSet::read(dir.path()).expect("read"), set);
    }

    #[test]
    fn defaults_apply_to_a_minimal_set() {
        let dir = tempfile::tempdir().expect("tempdir");
        std::fs::write(dir.path().join(FABRIC_FILE), "name = \"x\"\npattern = \"rib\"\n").expect("write");
        std::fs::write(dir.path().join(STRETCH_FILE), "direction,stretch,force_n\nwarp,0.1,2\n")
            .expect("write");
        let set = MeasurementSet::read(dir.path()).expect("read");
        assert_eq!(set.fabric.swatch, Swatch::default());
        assert_eq!(set.stretch[0].phase, Phase::Load);
        assert_eq!(set.stretch[0].compression, None);
        assert!(set.bending.is_empty());
    }

    #[test]
    fn errors_name_file_line_and_column() {
        let cases = [
            (
                "direction,stretch,force_n\nweft,0.1,1\nsideways,0.2,2\n",
                ":3: column `direction`: unknown direction",
            ),
            ("direction,stretch,force_n,phase\nweft,0.1,1,reload\n", ":2: column `phase`: unknown phase"),
            ("direction,stretch,force_n\nweft,NaN,1\n", ":2: column `stretch`: `NaN` is not a finite number"),
            (
                "direction,stretch,force_n\nweft,0.1,inf\n",
                ":2: column `force_n`: `inf` is not a finite number",
            ),
            ("direction,stretch,force_n\nweft,0.1,abc\n", ":2: column `force_n`: `abc` is not a number"),
            ("direction,force_n\nweft,1\n", ":1: column `stretch`: missing required column"),
            ("direction,stretch,force_n,colour\nweft,0.1,1,red\n", ":1: column `colour`: unknown column"),
            ("direction,stretch,force_n\nweft,0.1\n", ":2: column `force_n`: missing value"),
            ("direction,stretch,force_n\nweft,0.1,\n", ":2: column `force_n`: missing value"),
            ("direction,stretch,force_n\nweft,0.1,10\nweft,0.2,-1\n", ":3: column `force_n`: force -1 N"),
            (
                "direction,stretch,force_n,compression\nweft,0.1,1,1.5\n",
                ":2: column `compression`: must be < 1",
            ),
            ("direction,stretch,force_n,repeat\nweft,0.1,1,-2\n", ":2: column `repeat`"),
        ];
        for (csv, expected) in cases {
            let (_dir, error) = stretch_error(csv);
            assert!(error.contains("stretch.csv"), "no file in: {error}");
            assert!(error.contains(expected), "expected '{expected}' in: {error}");
        }
    }

    #[test]
    fn small_negative_forces_are_noise() {
        let dir = tempfile::tempdir().expect("tempdir");
        std::fs::write(dir.path().join(FABRIC_FILE), "name = \"x\"\npattern = \"rib\"\n").expect("write");
        let csv = "direction,stretch,force_n\nweft,0.01,-0.04\nweft,0.5,10\nweft,0.02,-0.19\n";
        std::fs::write(dir.path().join(STRETCH_FILE), csv).expect("write");
        let set = MeasurementSet::read(dir.path()).expect("within 2% of 10 N");
        assert_eq!(negative_force_floor_n(&set.stretch), 0.2);
    }

    #[test]
    fn empty_files_are_refused() {
        let (_dir, error) = stretch_error("");
        assert!(error.ends_with("stretch.csv: no data rows"), "{error}");
        let (_dir, error) = stretch_error("direction,stretch,force_n\n\n");
        assert!(error.ends_with("stretch.csv: no data rows"), "{error}");
        let error = bending_error("direction,clamp_distance_m,aspect_ratio\n");
        assert!(error.ends_with("bending.csv: no data rows"), "{error}");
    }

    #[test]
    fn bending_clamp_distance_must_be_monotone_per_direction() {
        let ok =
            "direction,clamp_distance_m,aspect_ratio\nweft,0.05,1\nwarp,0.01,1\nweft,0.04,1.1\nwarp,0.02,1\n";
        let dir = tempfile::tempdir().expect("tempdir");
        example().write(dir.path()).expect("write");
        std::fs::write(dir.path().join(BENDING_FILE), ok).expect("write");
        assert_eq!(MeasurementSet::read(dir.path()).expect("read").bending.len(), 4);

        let bad = "direction,clamp_distance_m,aspect_ratio\nweft,0.05,1\nweft,0.04,1\nweft,0.045,1\n";
        let error = bending_error(bad);
        assert!(error.contains("bending.csv:4: column `clamp_distance_m`: clamp distance 0.045"), "{error}");
        let repeated = "direction,clamp_distance_m,aspect_ratio\nbias,0.05,1\nbias,0.05,1\n";
        assert!(bending_error(repeated).contains("bending.csv:3: column `clamp_distance_m`"));
        let missing = "direction,clamp_distance_m\nbias,0.05\n";
        assert!(
            bending_error(missing).contains("bending.csv:1: column `aspect_ratio`: missing required column")
        );
    }

    #[test]
    fn fabric_errors_name_the_field() {
        let dir = tempfile::tempdir().expect("tempdir");
        example().write(dir.path()).expect("write");
        let fabric = dir.path().join(FABRIC_FILE);
        std::fs::write(&fabric, "name = \"x\"\npattern = \"rib\"\n[swatch]\nlength_m = -0.1\n")
            .expect("write");
        let error = MeasurementSet::read(dir.path()).expect_err("must fail").to_string();
        assert!(
            error.contains("fabric.toml: field `swatch.length_m`: must be a finite number > 0"),
            "{error}"
        );
        std::fs::write(&fabric, "name = \"x\"\n").expect("write");
        let error = MeasurementSet::read(dir.path()).expect_err("must fail").to_string();
        assert!(error.contains("fabric.toml") && error.contains("pattern"), "{error}");
    }

    /// Write a fabric.toml of `text` beside a valid stretch.csv and return the read result.
    fn read_fabric_text(text: &str) -> (tempfile::TempDir, Result<MeasurementSet>) {
        let dir = tempfile::tempdir().expect("tempdir");
        example().write(dir.path()).expect("write");
        std::fs::write(dir.path().join(FABRIC_FILE), text).expect("write");
        let read = MeasurementSet::read(dir.path());
        (dir, read)
    }

    #[test]
    fn a_stitch_table_reads_validates_and_round_trips() {
        let text = "name = \"x\"\npattern = \"rib\"\n[stitch]\nlength_m = 0.0161\nyarn_radius_m = 0.00118\n";
        let (_dir, set) = read_fabric_text(text);
        let stitch = set.expect("read").fabric.stitch.expect("a stitch");
        assert_eq!((stitch.length_m, stitch.yarn_radius_m, stitch.core_radius_m), (0.0161, 0.00118, None));
        let cases = [
            (
                "length_m = -0.01\nyarn_radius_m = 0.001",
                "field `stitch.length_m`: must be a finite number > 0",
            ),
            (
                "length_m = 0.01\nyarn_radius_m = 0",
                "field `stitch.yarn_radius_m`: must be a finite number > 0",
            ),
            ("length_m = 0.01\nyarn_radius_m = 0.001\ncore_radius_m = nan", "field `stitch.core_radius_m`"),
            (
                "length_m = 0.01\nyarn_radius_m = 0.001\ncore_radius_m = 0.001",
                "field `stitch.core_radius_m`: must be below stitch.yarn_radius_m",
            ),
            ("length_m = 0.01\nyarn_radius_m = 0.001\ncourses_per_m = inf", "field `stitch.courses_per_m`"),
            ("length_m = 0.01\nyarn_radius_m = 0.001\nwales_per_m = -5", "field `stitch.wales_per_m`"),
            ("yarn_radius_m = 0.001", "length_m"),
            ("length_m = 0.01", "yarn_radius_m"),
            ("length_m = 0.01\nyarn_radius_m = 0.001\nloop_m = 1", "loop_m"),
        ];
        for (table, expected) in cases {
            let (_dir, read) =
                read_fabric_text(&format!("name = \"x\"\npattern = \"rib\"\n[stitch]\n{table}\n"));
            let error = read.expect_err("must fail").to_string();
            assert!(error.contains("fabric.toml") && error.contains(expected), "{error} lacks {expected}");
        }
    }

    #[test]
    fn a_set_without_a_stitch_uses_the_generator_defaults_and_with_one_its_stitch() {
        let dir = tempfile::tempdir().expect("tempdir");
        let without = MeasurementSet { fabric: Fabric { stitch: None, ..example().fabric }, ..example() };
        without.write(dir.path()).expect("write");
        let text = std::fs::read_to_string(dir.path().join(FABRIC_FILE)).expect("read");
        assert!(!text.contains("stitch"), "{text}");
        let PatternSource::Generator(g) = without.fabric.pattern_source(dir.path()).expect("generator")
        else {
            panic!("a generator")
        };
        assert_eq!(g.stitch, None);
        let defaults = GeneratorParams::defaults_for("stockinette").expect("known");
        assert_eq!(
            g.generate().expect("generates"),
            yarnhom_pattern::generate("stockinette", &defaults).expect("generates")
        );
        // With the stitch (wales fixed at 3 mm): the stitch's radius and length per stitch.
        let with = example().fabric;
        let PatternSource::Generator(g) = with.pattern_source(dir.path()).expect("generator") else {
            panic!("a generator")
        };
        let pattern = g.generate().expect("generates");
        assert!(pattern.yarns.iter().all(|y| y.radius_m == 0.74e-3));
        let length = yarnhom_pattern::length_per_stitch_m(&pattern).expect("generated");
        assert!((length / 11.28e-3 - 1.0).abs() < 0.01, "{length}");
        assert!((pattern.period_m[0] - 3.0e-3).abs() < 1e-12, "one wale of 3 mm: {:?}", pattern.period_m);
        assert!(example().summary().contains("stitch: 11.28 mm of yarn per stitch, yarn radius 0.74 mm"));
    }
}
