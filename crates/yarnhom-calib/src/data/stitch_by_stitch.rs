//! Importer for the stitch-by-stitch uniaxial stretch data (feature `hdf5`).
//!
//! Source: `sabetta/stitch-by-stitch` (Singal et al., Nature Communications 2024); the files and
//! their notes are in `shared/data/stitch-by-stitch-acrylic/`. Each file holds up to five videos
//! `/videoN` of one swatch pulled along one direction, with per-frame pin positions
//! `/videoN/traj` (pixels), gauge forces `/videoN/forces` (N) and frame numbers `/videoN/frames`.
//!
//! # Conventions (see also `schemas/measurement-set.md`)
//!
//! - **Pins.** The acrylic files have 7 tracked points, not the 6 of the format notes. Row 4
//!   (0-based) is a *centre pin*: at the first frame it lies within 2 to 15 px of both the
//!   midpoint of the top/bottom pins and the midpoint of the left/right pins, and it moves
//!   half as far as the bottom pin. The rows are therefore right pin, left pin, bottom pin,
//!   top pin, centre pin, bottom clamp, top clamp ([`Pins::SEVEN`]). Files with the documented 6
//!   rows ([`Pins::SIX`]) are read too, and so are files with 4 rows ([`Pins::FOUR`]: right pin,
//!   left pin, bottom clamp, top clamp; the format notes' layout without top/bottom pins, as in
//!   the public pearlized-cotton rib y file).
//! - **Stretch** is `d / d_rest - 1` with `d` the distance of the video's [`StretchGauge`]: the
//!   top/bottom pins ([`StretchGauge::Pins`], 6 and 7 rows) or, where the file has no
//!   top/bottom pins, the clamps ([`StretchGauge::Clamps`], 4 rows). **Compression** is
//!   `1 - w / w_rest` with `w` the left/right pin distance, in every layout. All videos of a
//!   file must share one gauge (`swatch.stretch_gauge_m` is one distance). The rest values are
//!   those of the video's first frame: every video starts at zero gauge force (one,
//!   `garter-x` video 4, at 0.49 N) before the crosshead moves, and this is the only choice
//!   that reproduces the sanity figures of the data notes. Each video (a repeat) has its own
//!   rest frame: the pins are re-tracked in every video.
//! - **Phases.** Load is every frame up to and including the first frame of largest stretch
//!   (over all frames with finite data, saturated and glitch readings included), unload the
//!   frames after it.
//! - **Saturation.** The gauge saturates at [`SATURATION_FORCE_N`]: over all 133 262 readings
//!   of the eight acrylic files, the 0.1 N histogram bins hold 230 to 420 readings from 27 to
//!   29 N, then 332, 514, 874 and 797 readings from 29.0 to 29.4 N (the readings pile up while
//!   the swatch keeps stretching) and only 66 readings above 29.4 N (single-frame spikes).
//!   Readings at or above 29.0 N are dropped and counted.
//! - **Glitches.** A reading is a gauge glitch when its force differs from the median force `m`
//!   of its [`GLITCH_NEIGHBOURS`] preceding and [`GLITCH_NEIGHBOURS`] following frames (fewer
//!   at a video's ends) by more than the larger of [`GLITCH_FLOOR_N`] and
//!   [`GLITCH_MAD_MULTIPLE`] times the scaled median absolute deviation
//!   `1.4826 median |f - m|` of those neighbours' forces. The test runs per video in frame
//!   order over the frames with finite data, saturated readings included as neighbours (they
//!   are the pegged gauge's real readings); a saturated reading is counted as saturated, never
//!   as a glitch. Glitches are dropped and counted. In the eight acrylic files the rule drops
//!   21 of the 133 262 readings: garter-x 1 (video 1), garter-y 2 (videos 1 and 3), rib-x 6
//!   (videos 2 and 3 two each, 4 and 5 one each), rib-y 1 (video 1), seed-x 6 (videos 2, 3 and
//!   4 two each), stockinette-x 5 (video 4 three consecutive frames, video 5 two), seed-y and
//!   stockinette-y none. They lie 5.7 to 9.8 N off their neighbours' median, single frames
//!   (three frames at 20.76 N on a 28.8 N plateau in stockinette-x video 4), most like a
//!   misread digit: 7.98 N among 0.97 to 1.04 N at 7.7 % stretch (garter-y video 3), 0.08 N
//!   among 8 N, 10.00 N among 18 N. The readings kept are at most 3.1 N off: edges of the 1 to
//!   4 N steps the gauge reads above 20 N, a few dips of 1.5 to 2 N over one or two frames, and
//!   the gauge's dither of up to 1 N between consecutive frames (the data notes' sanity figures
//!   come from it: rib y at 2 N is a one-frame 1.99 N among 1.1 N). The same 21 are found for
//!   floors from 3 to 5 N with multiples up to 4, and when the saturated readings are dropped
//!   first; a multiple of 8 keeps four of them (in windows straddling a step, like 10.74 N
//!   between 17.1 to 17.9 N before and 19.8 to 20.0 N after in rib-y video 1).
//! - **Missing data.** Frames with a non-finite force or pin coordinate are dropped and counted
//!   (the acrylic files have none); frame numbers absent from `/videoN/frames` (gaps where the
//!   tracker had no data) are counted, they were never in the file.
//! - **Scale.** `/clampSize` pixels are [`CLAMP_SIZE_M`] (35.5 mm). `fabric.toml` gets the
//!   clamp-to-clamp distance at the first frame of the first video as `swatch.length_m`,
//!   `/fabricSize` (the width at the clamp) as `swatch.width_m`, and the stretch gauge and
//!   left/right pin distances of that frame as `swatch.stretch_gauge_m` and
//!   `swatch.compression_gauge_m` (where the stretch and compression were read). With
//!   [`StretchGauge::Clamps`] `swatch.stretch_gauge_m` is the clamp distance, equal to
//!   `swatch.length_m`: written rather than left out, so that a merged set's other direction
//!   cannot lend its pins' distance to this one. [`import_fabric`] merges a fabric's `-x` and
//!   `-y` files (separate swatches) into one set with per-direction `[swatch.weft]` /
//!   `[swatch.warp]` tables. Two swatches are wider between their left/right pins than
//!   `/fabricSize` at rest (garter x: 48.4 mm against 35.2 mm at the clamp; seed y: 150.4 mm
//!   against 145.1 mm): the pins sit at the free edges of a piece wider in the middle than at
//!   the clamps. The set is a rectangle, so there `swatch.width_m` is the pin distance (the
//!   larger of the two).
//! - **Directions.** Files ending in `-x` are pulled along the courses (`weft`), `-y` along the
//!   wales (`warp`). The pattern is the file name's middle part (`garter`, `rib`, `seed`,
//!   `stockinette`), all built-in generators of yarnhom.
//! - **Stitch.** The files do not say what yarn or stitch the swatches were knitted with; the
//!   authors' yarn-level simulations of the same acrylic swatches do (the repository's
//!   `code/fabric_simulations/<pattern>config.dat`: `stitch_length` in mm, `yarn_radius` and
//!   `core_radius` in mm). [`AUTHORS_ACRYLIC_STITCHES`] holds them, and a file whose name starts
//!   `acrylic-` gets its pattern's entry as `fabric.toml`'s `[stitch]` (`length_m`,
//!   `yarn_radius_m`, `core_radius_m`; no course or wale counts, the configs give none); files of
//!   other yarns get none. [`Import::report`] says so in its first line.

use std::path::{Path, PathBuf};

use ::hdf5::{File, Group};

use crate::data::set::{
    Direction, Fabric, MeasurementSet, Phase, Stitch, StretchPoint, Swatch, SwatchOverride, Yarn,
};

/// Physical size of `/clampSize` (the clamp's short dimension), in metres.
pub const CLAMP_SIZE_M: f64 = 0.0355;

/// Gauge readings at or above this force (newtons) are saturated and dropped.
pub const SATURATION_FORCE_N: f64 = 29.0;

/// A reading is compared with this many frames on each side for the glitch test.
pub const GLITCH_NEIGHBOURS: usize = 5;

/// A glitch lies more than this (newtons) from its neighbours' median force.
pub const GLITCH_FLOOR_N: f64 = 4.0;

/// A glitch lies more than this many scaled median absolute deviations of its neighbours'
/// forces from their median.
pub const GLITCH_MAD_MULTIPLE: f64 = 4.0;

/// The median absolute deviation times this estimates a normal distribution's standard
/// deviation.
const MAD_TO_STANDARD_DEVIATION: f64 = 1.4826;

/// Patterns of the stitch-by-stitch files, all built-in yarnhom generator names.
const PATTERNS: [&str; 4] = ["garter", "rib", "seed", "stockinette"];

/// Where [`AUTHORS_ACRYLIC_STITCHES`] come from.
pub const AUTHORS_STITCH_SOURCE: &str =
    "sabetta/stitch-by-stitch, code/fabric_simulations/<pattern>config.dat";

/// The stitches the authors simulated the acrylic swatches with at yarn level (Singal et al.
/// 2024; [`AUTHORS_STITCH_SOURCE`]): pattern, yarn length per stitch (`stitch_length`), yarn
/// radius (`yarn_radius`) and core radius (`core_radius`), in metres (the files give mm).
pub const AUTHORS_ACRYLIC_STITCHES: [(&str, f64, f64, f64); 4] = [
    ("garter", 10.55e-3, 0.54e-3, 0.255e-3),
    ("rib", 16.10e-3, 1.18e-3, 0.41e-3),
    ("seed", 15.67e-3, 1.20e-3, 0.285e-3),
    ("stockinette", 11.28e-3, 0.74e-3, 0.325e-3),
];

/// The authors' stitch of an acrylic swatch of `pattern` ([`AUTHORS_ACRYLIC_STITCHES`]).
pub fn authors_acrylic_stitch(pattern: &str) -> Option<Stitch> {
    AUTHORS_ACRYLIC_STITCHES.iter().find(|(p, ..)| *p == pattern).map(|&(_, length, radius, core)| Stitch {
        length_m: length,
        yarn_radius_m: radius,
        core_radius_m: Some(core),
        courses_per_m: None,
        wales_per_m: None,
    })
}

/// Why a stitch-by-stitch file could not be imported.
#[derive(Debug, thiserror::Error)]
pub enum ImportError {
    /// The HDF5 library refused to open or read something.
    #[error("{}: {what}: {message}", path.display())]
    Hdf5 {
        /// The file.
        path: PathBuf,
        /// What was being read.
        what: String,
        /// The HDF5 library's message.
        message: String,
    },
    /// The file does not have the expected layout or name.
    #[error("{}: {message}", path.display())]
    Layout {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

/// Result type of this module.
pub type Result<T> = std::result::Result<T, ImportError>;

/// Where a video's stretch is read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StretchGauge {
    /// Between the top and bottom pins (files with 6 or 7 tracked points).
    Pins,
    /// Between the clamps (files with 4 tracked points: no top/bottom pins).
    Clamps,
}

impl StretchGauge {
    /// What the stretch is read between, for reports: "the top/bottom pins" or "the clamps".
    pub fn markers(self) -> &'static str {
        match self {
            StretchGauge::Pins => "the top/bottom pins",
            StretchGauge::Clamps => "the clamps",
        }
    }
}

/// Which rows of `/videoN/traj` hold which tracked point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Pins {
    /// Number of rows.
    pub rows: usize,
    /// Right pin.
    pub right: usize,
    /// Left pin.
    pub left: usize,
    /// Bottom and top pin, where tracked (not in 4-row files).
    pub bottom_top: Option<(usize, usize)>,
    /// Bottom clamp.
    pub bottom_clamp: usize,
    /// Top clamp.
    pub top_clamp: usize,
}

impl Pins {
    /// The 7-row layout of the acrylic files: right, left, bottom, top, centre pin, bottom clamp,
    /// top clamp.
    pub const SEVEN: Pins =
        Pins { rows: 7, right: 0, left: 1, bottom_top: Some((2, 3)), bottom_clamp: 5, top_clamp: 6 };
    /// The documented 6-row layout: right, left, bottom, top, bottom clamp, top clamp.
    pub const SIX: Pins =
        Pins { rows: 6, right: 0, left: 1, bottom_top: Some((2, 3)), bottom_clamp: 4, top_clamp: 5 };
    /// The documented layout without top/bottom pins: right, left, bottom clamp, top clamp.
    pub const FOUR: Pins =
        Pins { rows: 4, right: 0, left: 1, bottom_top: None, bottom_clamp: 2, top_clamp: 3 };

    /// The layout of a `traj` dataset with `rows` rows, if known.
    pub fn for_rows(rows: usize) -> Option<Pins> {
        [Pins::SEVEN, Pins::SIX, Pins::FOUR].into_iter().find(|p| p.rows == rows)
    }

    /// Where the stretch is read: the top/bottom pins where tracked, else the clamps.
    pub fn gauge(&self) -> StretchGauge {
        match self.bottom_top {
            Some(_) => StretchGauge::Pins,
            None => StretchGauge::Clamps,
        }
    }

    /// The rows (bottom, top) whose distance is the stretch gauge.
    fn gauge_rows(&self) -> (usize, usize) {
        self.bottom_top.unwrap_or((self.bottom_clamp, self.top_clamp))
    }
}

/// What the import kept and dropped in one video.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct VideoReport {
    /// The pull direction of the video's file (`None` in a total).
    pub direction: Option<Direction>,
    /// Video number `N` of `/videoN`: the `repeat` column.
    pub repeat: u32,
    /// Where the stretch was read (`None` in a total).
    pub gauge: Option<StretchGauge>,
    /// Frames stored in the file.
    pub frames: usize,
    /// Frame numbers missing from `/videoN/frames` (tracker gaps), never in the file.
    pub missing_frames: usize,
    /// Frames dropped for a non-finite force or pin coordinate.
    pub dropped_nan: usize,
    /// Frames dropped for a saturated gauge reading (force >= [`SATURATION_FORCE_N`]).
    pub dropped_saturated: usize,
    /// Frames dropped for a gauge glitch: a reading far off its neighbours' (module docs).
    pub dropped_glitches: usize,
    /// Frames thinned out by `every`.
    pub dropped_thinning: usize,
    /// Load points written.
    pub load: usize,
    /// Unload points written.
    pub unload: usize,
}

/// A converted file: the measurement set and what happened to each video.
#[derive(Debug, Clone, PartialEq)]
pub struct Import {
    /// The measurement set (fabric and stretch points, no bending points).
    pub set: MeasurementSet,
    /// One report per video, in video order.
    pub videos: Vec<VideoReport>,
}

impl Import {
    /// A human summary: where the `[stitch]` came from (if the set has one), then kept and dropped
    /// frames, one line per video plus a total.
    pub fn report(&self) -> String {
        let stitch = self.set.fabric.stitch.iter().map(|stitch| {
            format!("stitch: from the authors' yarn-level simulations ({AUTHORS_STITCH_SOURCE}): {stitch}")
        });
        let mut lines: Vec<String> = stitch.chain(self.videos.iter().map(video_line)).collect();
        let total = self.videos.iter().fold(VideoReport::default(), add_reports);
        lines.push(format!("total: {}", report_counts(&total)));
        lines.join("\n")
    }
}

fn video_line(v: &VideoReport) -> String {
    let direction = v.direction.map_or(String::new(), |d| format!("{d} "));
    let gauge = v.gauge.map_or(String::new(), |g| format!("stretch from {}; ", g.markers()));
    format!("{direction}video{}: {gauge}{}", v.repeat, report_counts(v))
}

fn report_counts(v: &VideoReport) -> String {
    format!(
        "{} frames, {} load + {} unload points kept; dropped {} saturated (>= {SATURATION_FORCE_N} N), \
         {} glitches, {} NaN, {} thinned; {} frame numbers missing in the file",
        v.frames,
        v.load,
        v.unload,
        v.dropped_saturated,
        v.dropped_glitches,
        v.dropped_nan,
        v.dropped_thinning,
        v.missing_frames
    )
}

fn add_reports(a: VideoReport, b: &VideoReport) -> VideoReport {
    VideoReport {
        direction: None,
        repeat: 0,
        gauge: None,
        frames: a.frames + b.frames,
        missing_frames: a.missing_frames + b.missing_frames,
        dropped_nan: a.dropped_nan + b.dropped_nan,
        dropped_saturated: a.dropped_saturated + b.dropped_saturated,
        dropped_glitches: a.dropped_glitches + b.dropped_glitches,
        dropped_thinning: a.dropped_thinning + b.dropped_thinning,
        load: a.load + b.load,
        unload: a.unload + b.unload,
    }
}

/// One video's per-frame data, in file order.
struct Video {
    repeat: u32,
    frame_numbers: Vec<f64>,
    forces_n: Vec<f64>,
    /// Where the stretch is read.
    gauge: StretchGauge,
    /// Distance of the stretch gauge's markers, pixels.
    gauge_px: Vec<f64>,
    /// Left/right pin distance, pixels.
    width_px: Vec<f64>,
    /// Clamp-to-clamp distance, pixels.
    clamp_distance_px: Vec<f64>,
}

/// Import the stitch-by-stitch file `path`, keeping every `every`-th point (1: all) of each
/// video and phase after dropping saturated, glitch and non-finite frames.
pub fn import(path: &Path, every: usize) -> Result<Import> {
    let (pattern, direction) = pattern_and_direction(path)?;
    let file = File::open(path).map_err(|e| hdf5_error(path, "cannot open", &e))?;
    let scale_px_per_m = scalar(path, &file, "clampSize")? / CLAMP_SIZE_M;
    let fabric_size_px = scalar(path, &file, "fabricSize")?;
    let videos = read_videos(path, &file)?;
    let first = videos.first().ok_or_else(|| layout(path, "no /videoN groups"))?;
    check_one_gauge(path, &videos)?;
    let length_px = first
        .clamp_distance_px
        .first()
        .copied()
        .filter(|d| d.is_finite() && *d > 0.0)
        .ok_or_else(|| layout(path, "the first frame of the first video has no clamp positions"))?;
    let stretch_gauge_px = first.gauge_px.first().copied().filter(|d| d.is_finite() && *d > 0.0);
    let compression_gauge_px = first.width_px.first().copied().filter(|d| d.is_finite() && *d > 0.0);
    let fabric = Fabric {
        name: file_stem(path).to_string(),
        pattern: pattern.to_string(),
        swatch: Swatch {
            length_m: length_px / scale_px_per_m,
            width_m: fabric_size_px.max(compression_gauge_px.unwrap_or(0.0)) / scale_px_per_m,
            stretch_gauge_m: stretch_gauge_px.map(|d| d / scale_px_per_m),
            compression_gauge_m: compression_gauge_px.map(|d| d / scale_px_per_m),
            ..Swatch::default()
        },
        stitch: file_stem(path).starts_with("acrylic-").then(|| authors_acrylic_stitch(pattern)).flatten(),
        yarn: vec![Yarn {
            material: "acrylic".into(),
            linear_density_tex: None,
            stiffness_n: None,
            mass_fraction: None,
        }],
    };
    let mut stretch = Vec::new();
    let mut reports = Vec::new();
    for video in &videos {
        let (points, report) = convert_video(video, direction, every.max(1));
        stretch.extend(points);
        reports.push(report);
    }
    Ok(Import {
        set: MeasurementSet { fabric, stretch, bending: Vec::new(), cantilever: Vec::new() },
        videos: reports,
    })
}

/// Import the files of one fabric (say its `-x` and `-y` files) into one measurement set: each
/// file's swatch becomes its direction's `[swatch.<direction>]` override (the first file's is
/// also the top-level `[swatch]`), and the reports are concatenated in file order. The files
/// must share a pattern and test distinct directions.
pub fn import_fabric(paths: &[PathBuf], every: usize) -> Result<Import> {
    let (first, rest) = paths.split_first().ok_or_else(|| layout(Path::new(""), "no input files"))?;
    let mut merged = import(first, every)?;
    let (pattern, direction) = pattern_and_direction(first)?;
    if rest.is_empty() {
        return Ok(merged);
    }
    merged.set.fabric.name = merged.set.fabric.name.trim_end_matches("-x").trim_end_matches("-y").to_string();
    let mut directions = vec![direction];
    let own = merged.set.fabric.swatch.clone();
    set_override(&mut merged.set.fabric.swatch, direction, &own);
    for path in rest {
        let (other_pattern, other_direction) = pattern_and_direction(path)?;
        if other_pattern != pattern {
            return Err(layout(
                path,
                &format!("pattern '{other_pattern}' differs from '{pattern}' of {}", first.display()),
            ));
        }
        if directions.contains(&other_direction) {
            return Err(layout(path, &format!("a second file for direction '{other_direction}'")));
        }
        directions.push(other_direction);
        let other = import(path, every)?;
        set_override(&mut merged.set.fabric.swatch, other_direction, &other.set.fabric.swatch);
        merged.set.stretch.extend(other.set.stretch);
        merged.videos.extend(other.videos);
    }
    Ok(merged)
}

/// Refuse a file whose videos read the stretch between different markers.
fn check_one_gauge(path: &Path, videos: &[Video]) -> Result<()> {
    let Some(first) = videos.first() else { return Ok(()) };
    match videos.iter().find(|v| v.gauge != first.gauge) {
        Some(other) => Err(layout(
            path,
            &format!(
                "video{} reads the stretch between {}, video{} between {}: a file's videos must share one \
                 stretch gauge",
                other.repeat,
                other.gauge.markers(),
                first.repeat,
                first.gauge.markers()
            ),
        )),
        None => Ok(()),
    }
}

/// Record `swatch`'s geometry as `direction`'s override in `target`.
fn set_override(target: &mut Swatch, direction: Direction, swatch: &Swatch) {
    let o = Some(SwatchOverride {
        length_m: Some(swatch.length_m),
        width_m: Some(swatch.width_m),
        stretch_gauge_m: swatch.stretch_gauge_m,
        compression_gauge_m: swatch.compression_gauge_m,
    });
    match direction {
        Direction::Weft => target.weft = o,
        Direction::Bias => target.bias = o,
        Direction::Warp => target.warp = o,
    }
}

fn file_stem(path: &Path) -> &str {
    path.file_stem().and_then(|s| s.to_str()).unwrap_or("")
}

/// Pattern and direction from a file name `MATERIAL-PATTERN-x.h5` or `...-y.h5`.
fn pattern_and_direction(path: &Path) -> Result<(&'static str, Direction)> {
    let stem = file_stem(path);
    let direction = if stem.ends_with("-x") {
        Direction::Weft
    } else if stem.ends_with("-y") {
        Direction::Warp
    } else {
        return Err(layout(path, "file name must end in -x (course/weft) or -y (wale/warp)"));
    };
    let parts: Vec<&str> = stem.split('-').collect();
    let pattern = PATTERNS.into_iter().find(|p| parts.contains(p)).ok_or_else(|| {
        layout(path, &format!("file name names none of the patterns {}", PATTERNS.join(", ")))
    })?;
    Ok((pattern, direction))
}

fn layout(path: &Path, message: &str) -> ImportError {
    ImportError::Layout { path: path.to_path_buf(), message: message.to_string() }
}

fn hdf5_error(path: &Path, what: &str, error: &::hdf5::Error) -> ImportError {
    ImportError::Hdf5 { path: path.to_path_buf(), what: what.to_string(), message: error.to_string() }
}

/// Read a whole f64 dataset and its shape.
fn dataset(path: &Path, group: &Group, name: &str) -> Result<(Vec<f64>, Vec<usize>)> {
    let ds = group.dataset(name).map_err(|e| hdf5_error(path, &format!("no dataset {name}"), &e))?;
    let data = ds.read_raw::<f64>().map_err(|e| hdf5_error(path, &format!("cannot read {name}"), &e))?;
    Ok((data, ds.shape()))
}

fn scalar(path: &Path, group: &Group, name: &str) -> Result<f64> {
    let (data, _) = dataset(path, group, name)?;
    match data.as_slice() {
        [value] if value.is_finite() && *value > 0.0 => Ok(*value),
        _ => Err(layout(path, &format!("/{name} must hold one positive number"))),
    }
}

/// The `/videoN` groups in order of N.
fn read_videos(path: &Path, file: &File) -> Result<Vec<Video>> {
    let names = file.member_names().map_err(|e| hdf5_error(path, "cannot list groups", &e))?;
    let mut repeats: Vec<u32> = names.iter().filter_map(|n| n.strip_prefix("video")?.parse().ok()).collect();
    repeats.sort_unstable();
    repeats.iter().map(|&repeat| read_video(path, file, repeat)).collect()
}

fn read_video(path: &Path, file: &File, repeat: u32) -> Result<Video> {
    let group = format!("video{repeat}");
    let (forces_n, _) = dataset(path, file, &format!("{group}/forces"))?;
    let (frame_numbers, _) = dataset(path, file, &format!("{group}/frames"))?;
    let (traj, shape) = dataset(path, file, &format!("{group}/traj"))?;
    let n = forces_n.len();
    let pins = match shape.as_slice() {
        [rows, 2, frames] if *frames == n && frame_numbers.len() == n => Pins::for_rows(*rows),
        _ => None,
    }
    .ok_or_else(|| {
        layout(path, &format!("/{group}/traj has shape {shape:?}; expected (7, 6 or 4, 2, {n})"))
    })?;
    let distance = |a: usize, b: usize| -> Vec<f64> {
        (0..n)
            .map(|i| {
                let at = |pin: usize, axis: usize| traj[(pin * 2 + axis) * n + i];
                (at(a, 0) - at(b, 0)).hypot(at(a, 1) - at(b, 1))
            })
            .collect()
    };
    let (bottom, top) = pins.gauge_rows();
    Ok(Video {
        repeat,
        gauge: pins.gauge(),
        gauge_px: distance(top, bottom),
        width_px: distance(pins.left, pins.right),
        clamp_distance_px: distance(pins.top_clamp, pins.bottom_clamp),
        frame_numbers,
        forces_n,
    })
}

/// Frame numbers absent between the first and last stored frame.
fn missing_frame_count(frame_numbers: &[f64]) -> usize {
    frame_numbers.windows(2).map(|w| (w[1] - w[0] - 1.0).max(0.0) as usize).sum()
}

/// Whether frame `i` has a finite force and finite gauge distances.
fn is_finite_frame(video: &Video, i: usize) -> bool {
    [video.forces_n[i], video.gauge_px[i], video.width_px[i]].iter().all(|v| v.is_finite())
}

/// The index of the first finite frame of largest stretch gauge distance.
fn peak_stretch_index(video: &Video, finite: &[usize]) -> Option<usize> {
    finite.iter().copied().fold(None, |best, i| match best {
        Some(b) if video.gauge_px[b] >= video.gauge_px[i] => Some(b),
        _ => Some(i),
    })
}

/// The median of `values` (the mean of the middle two for an even count); `None` when empty.
fn median(values: &[f64]) -> Option<f64> {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    match n {
        0 => None,
        _ if n % 2 == 1 => Some(sorted[n / 2]),
        _ => Some(0.5 * (sorted[n / 2 - 1] + sorted[n / 2])),
    }
}

/// Whether the reading of frame `frames[j]` is a glitch against the forces of the
/// [`GLITCH_NEIGHBOURS`] frames of `frames` on each side of it (module docs).
fn is_glitch(forces_n: &[f64], frames: &[usize], j: usize) -> bool {
    let before = &frames[j.saturating_sub(GLITCH_NEIGHBOURS)..j];
    let after = &frames[j + 1..(j + 1 + GLITCH_NEIGHBOURS).min(frames.len())];
    let neighbours: Vec<f64> = before.iter().chain(after).map(|&i| forces_n[i]).collect();
    let Some(centre) = median(&neighbours) else { return false };
    let deviations: Vec<f64> = neighbours.iter().map(|f| (f - centre).abs()).collect();
    let spread = MAD_TO_STANDARD_DEVIATION * median(&deviations).unwrap_or(0.0);
    (forces_n[frames[j]] - centre).abs() > GLITCH_FLOOR_N.max(GLITCH_MAD_MULTIPLE * spread)
}

/// The frames of `frames` (ascending frame indices) whose readings are glitches.
fn glitch_frames(forces_n: &[f64], frames: &[usize]) -> Vec<usize> {
    (0..frames.len()).filter(|&j| is_glitch(forces_n, frames, j)).map(|j| frames[j]).collect()
}

/// The stretch points of one video and what was kept and dropped.
fn convert_video(video: &Video, direction: Direction, every: usize) -> (Vec<StretchPoint>, VideoReport) {
    let frames = video.forces_n.len();
    let finite: Vec<usize> = (0..frames).filter(|&i| is_finite_frame(video, i)).collect();
    let mut report = VideoReport {
        repeat: video.repeat,
        gauge: Some(video.gauge),
        frames,
        missing_frames: missing_frame_count(&video.frame_numbers),
        dropped_nan: frames - finite.len(),
        direction: Some(direction),
        ..VideoReport::default()
    };
    let (Some(&rest), Some(peak)) = (finite.first(), peak_stretch_index(video, &finite)) else {
        return (Vec::new(), report);
    };
    let glitches = glitch_frames(&video.forces_n, &finite);
    let unsaturated: Vec<usize> =
        finite.iter().copied().filter(|&i| video.forces_n[i] < SATURATION_FORCE_N).collect();
    report.dropped_saturated = finite.len() - unsaturated.len();
    let clean: Vec<usize> =
        unsaturated.iter().copied().filter(|i| glitches.binary_search(i).is_err()).collect();
    report.dropped_glitches = unsaturated.len() - clean.len();
    let mut points = Vec::new();
    for phase in Phase::ALL {
        let in_phase: Vec<usize> =
            clean.iter().copied().filter(|&i| (i <= peak) == (phase == Phase::Load)).collect();
        let kept: Vec<usize> = in_phase.iter().copied().step_by(every).collect();
        report.dropped_thinning += in_phase.len() - kept.len();
        match phase {
            Phase::Load => report.load = kept.len(),
            Phase::Unload => report.unload = kept.len(),
        }
        points.extend(kept.into_iter().map(|i| StretchPoint {
            direction,
            stretch: video.gauge_px[i] / video.gauge_px[rest] - 1.0,
            force_n: video.forces_n[i],
            compression: Some(1.0 - video.width_px[i] / video.width_px[rest]),
            phase,
            repeat: Some(video.repeat),
        }));
    }
    (points, report)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A video of `forces_n`, one frame each, stretching uniformly from 100 to 110 px.
    fn video(forces_n: Vec<f64>) -> Video {
        let n = forces_n.len();
        let gauge_px: Vec<f64> = (0..n).map(|i| 100.0 + 10.0 * i as f64 / n as f64).collect();
        Video {
            repeat: 1,
            frame_numbers: (0..n).map(|i| i as f64).collect(),
            forces_n,
            gauge: StretchGauge::Pins,
            clamp_distance_px: gauge_px.iter().map(|d| 2.0 * d).collect(),
            gauge_px,
            width_px: vec![50.0; n],
        }
    }

    /// A deterministic dither in [-1, 1) N, like the gauge's frame-to-frame jitter.
    fn dither(i: usize) -> f64 {
        let hashed =
            (i as u64).wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (hashed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }

    #[test]
    fn one_spike_among_small_readings_is_the_only_glitch() {
        // 8 N at frame 20 of 40 (105 of 100 px: 5 % stretch) between readings of 0.3 N, with a
        // 0.01 N jitter.
        let mut forces: Vec<f64> = (0..40).map(|i| 0.3 + 0.01 * dither(i)).collect();
        forces[20] = 8.0;
        let (points, report) = convert_video(&video(forces), Direction::Weft, 1);
        assert_eq!(report.dropped_glitches, 1);
        assert_eq!(points.len(), 39);
        assert!(points.iter().all(|p| p.force_n < 1.0));
        assert!(points.iter().all(|p| (p.stretch - 0.05).abs() > 1e-9), "the 5 % frame is the dropped one");
    }

    #[test]
    fn a_smooth_noisy_ramp_has_no_glitches() {
        // 0 to 28 N over 3000 frames, dithering by up to 1 N.
        let forces: Vec<f64> = (0..3000).map(|i| (28.0 * i as f64 / 3000.0 + dither(i)).max(0.0)).collect();
        let (points, report) = convert_video(&video(forces), Direction::Warp, 1);
        assert_eq!(report.dropped_glitches, 0);
        assert_eq!(points.len(), 3000);
    }

    #[test]
    fn the_median_of_an_even_count_is_the_mean_of_the_middle_two() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), Some(2.5));
        assert_eq!(median(&[]), None);
    }
}
