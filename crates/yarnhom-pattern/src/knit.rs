//! Weft-knitted tiles: every course is one yarn running along X1 through a row of loops; the
//! loops of a course are pulled through the loops of the course below (from the back for a
//! knit stitch, from the front for a purl stitch).
//!
//! Construction, per course:
//! 1. the plan view (X1, X2) of the course is a periodic cubic B-spline through a control polygon
//!    of ten points per stitch: sinker loop at the bottom, legs rising at `+-a` from the stitch
//!    centre, a head that bulges out to `+-c > a` (so that the legs of the loop above, also at
//!    `+-a`, pass through it) and closes at the top;
//! 2. the plan views of neighbouring courses cross four times per stitch: the upper loop's two
//!    legs cross the lower loop's head, and the upper sinker crosses the lower head's two sides;
//! 3. at each crossing one yarn passes over (+Z) and the other under (-Z), as the stitch type of
//!    the upper loop says (knit: upper legs in front of the lower head, upper sinker behind its
//!    sides; purl: the mirror image);
//! 4. the height along each yarn follows `curve::undulate` through its crossings, and the curve is
//!    resampled to equal edge lengths.
//!
//! The control polygon's proportions are set in units of the yarn radius and scaled (separately
//! along X1 and X2) to the requested stitch size, so the plan view of every stitch size is an
//! affine image of the smallest one and crosses its neighbours at the same curve parameters.
//! Where knit and purl loops meet, a yarn changes sides between two nearby crossings and the
//! loops get more room: wider head gaps between knit and purl wales, taller necks between knit
//! and purl courses. The smallest stitch is [`min_stitch_r`]: 8.4 x 4.4 radii for stockinette,
//! 8.4 x 5.6 for garter, 9.4 x 4.4 for rib, 9.4 x 5.6 for seed (the published relaxed
//! stockinette has 7.5 x 4.0 radii per stitch).

use nalgebra::Vector2;
use yarnhom_artifacts::{Fabric, Pattern};
use yarnhom_geom::segment_crossing_2d;

use crate::curve::{LEVEL_R, PLATEAU, arc_lengths, periodic_bspline, resample, undulate};
use crate::{GenerateError, GeneratorParams, add_yarn, generated};

/// Knit or purl, as seen from the front (+X3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stitch {
    /// The loop is pulled through the loop below from back to front.
    Knit,
    /// The loop is pulled through from front to back (a knit seen from the back).
    Purl,
}

/// Inner width of a loop's neck between its legs, in radii.
const NECK_R: f64 = 1.8;
/// How far a head bulges out beyond its legs on each side, in radii.
const BULGE_R: f64 = 2.4;
/// Gap between the heads of neighbouring loops of the same kind, in radii.
const GAP_R: f64 = 1.8;
/// Gap between the heads of a knit and a purl loop side by side, in radii: the sinker above
/// passes behind one head's leg and in front of the other's, and needs room to change sides.
const GAP_SWITCH_R: f64 = 2.8;
/// How far a head reaches into the course above, in radii.
const OVERLAP_R: f64 = 2.6;
/// Height of the neck region (sinker-to-head transition) between the crossings with the head
/// below and the sinker above, in radii. It is also the plan-view gap between a head and the
/// sinker two courses up, which lie on the same side of the fabric beside the leg between them.
const NECK_HEIGHT_R: f64 = 1.8;
/// Neck height of a loop whose legs change sides (a knit under a purl or vice versa): in front
/// of the head below and behind the sinker above, or the reverse.
const NECK_HEIGHT_SWITCH_R: f64 = 3.0;

/// The proportions of a chart's loops, in radii before scaling to the stitch size.
#[derive(Debug, Clone, Copy)]
struct Shape {
    /// Gap between neighbouring heads.
    gap_r: f64,
    /// Height of the neck region.
    neck_height_r: f64,
}

impl Shape {
    /// Room for the switches a chart needs: knit next to purl in a course, or knit above purl
    /// in a wale.
    fn of(chart: &[&[Stitch]]) -> Shape {
        let cyclic_next = |k: usize, n: usize| (k + 1) % n;
        let along_course =
            chart.iter().any(|row| (0..row.len()).any(|j| row[j] != row[cyclic_next(j, row.len())]));
        let along_wale = (0..chart.len()).any(|n| chart[n] != chart[cyclic_next(n, chart.len())]);
        Shape {
            gap_r: if along_course { GAP_SWITCH_R } else { GAP_R },
            neck_height_r: if along_wale { NECK_HEIGHT_SWITCH_R } else { NECK_HEIGHT_R },
        }
    }

    fn width_r(&self) -> f64 {
        NECK_R + 2.0 * BULGE_R + self.gap_r
    }

    fn height_r(&self) -> f64 {
        OVERLAP_R + self.neck_height_r
    }
}

/// The smallest stitch (width, height) of a chart, in yarn radii: the loop proportions at which
/// neighbouring yarns keep 1.9 r apart at 32 vertices per stitch.
pub fn min_stitch_r(chart: &[&[Stitch]]) -> [f64; 2] {
    let shape = Shape::of(chart);
    [shape.width_r(), shape.height_r()]
}

/// B-spline samples per control span (the plan view used to find crossings).
const SAMPLES_PER_SPAN: usize = 40;
/// Control points per stitch.
const CONTROL_PER_STITCH: usize = 10;
/// Fewest vertices per stitch: two for each of a stitch's eight crossings (four with the
/// course below, four with the course above).
pub const MIN_VERTICES_PER_STITCH: usize = 16;

/// Build a knitted tile from its stitch chart: `chart[course][wale]`, course 0 at the bottom.
pub(crate) fn knit(name: &str, chart: &[&[Stitch]], p: &GeneratorParams) -> Result<Pattern, GenerateError> {
    let r = p.yarn_radius_m;
    let shape = Shape::of(chart);
    p.require_stitch(shape.width_r() * r, shape.height_r() * r, MIN_VERTICES_PER_STITCH)?;
    let (courses, wales) = (chart.len(), chart[0].len());
    let period = [wales as f64 * p.stitch_width_m, courses as f64 * p.stitch_height_m];
    let plan = course_plan(wales, shape, p);
    let (arcs, length) = arc_lengths(&plan, [period[0], 0.0]);
    let levels = crossing_levels(chart, &plan, &arcs, length, period[0], p.stitch_height_m);
    let vertices_per_course = p.vertices_per_stitch * wales;
    let mut positions = Vec::with_capacity(courses * vertices_per_course);
    let mut yarns = Vec::with_capacity(courses);
    for (course, course_levels) in levels.iter().enumerate() {
        let z = undulate(&arcs, length, course_levels, LEVEL_R * r, PLATEAU);
        let base = course as f64 * p.stitch_height_m - period[1] / 2.0;
        let curve: Vec<[f64; 3]> =
            plan.iter().zip(&z).map(|(xy, &z)| [xy[0] - period[0] / 2.0, xy[1] + base, z]).collect();
        let points = resample(&curve, [period[0], 0.0, 0.0], vertices_per_course);
        yarns.push(add_yarn(&mut positions, points.into_iter(), [1, 0], r));
    }
    Ok(generated(name, Fabric::Knit, period, positions, yarns, p))
}

/// Plan view of one course (relative to its base line), sampled along a periodic B-spline.
fn course_plan(wales: usize, shape: Shape, p: &GeneratorParams) -> Vec<[f64; 2]> {
    let (w, h) = (p.stitch_width_m, p.stitch_height_m);
    let sx = w / shape.width_r();
    let sy = h / shape.height_r();
    let a = NECK_R / 2.0 * sx;
    let c = a + BULGE_R * sx;
    let m = shape.neck_height_r * sy / 2.0;
    let b = (h + OVERLAP_R * sy) / 2.0;
    let mut control = Vec::with_capacity(wales * CONTROL_PER_STITCH);
    for j in 0..wales {
        let x0 = (j as f64 + 0.5) * w;
        control.extend([
            [x0 - w / 2.0, -b],
            [x0 - a, -b],
            [x0 - a, -m],
            [x0 - c, m],
            [x0 - c, b],
            [x0, b],
            [x0 + c, b],
            [x0 + c, m],
            [x0 + a, -m],
            [x0 + a, -b],
        ]);
    }
    periodic_bspline(&control, [wales as f64 * w, 0.0], SAMPLES_PER_SPAN)
}

/// A point on the plan view of a course: sample segment and fraction.
#[derive(Clone, Copy)]
struct PlanPoint {
    segment: usize,
    fraction: f64,
}

impl PlanPoint {
    fn arc(&self, arcs: &[f64], length: f64) -> f64 {
        let next = arcs.get(self.segment + 1).copied().unwrap_or(length);
        arcs[self.segment] + self.fraction * (next - arcs[self.segment])
    }

    fn y(&self, plan: &[[f64; 2]]) -> f64 {
        let a = plan[self.segment][1];
        let b = plan[(self.segment + 1) % plan.len()][1];
        a + self.fraction * (b - a)
    }

    fn wale(&self, wales: usize) -> usize {
        (self.segment / (SAMPLES_PER_SPAN * CONTROL_PER_STITCH)) % wales
    }
}

/// For every course, its crossings with the courses above and below: (arc, +1 over / -1 under).
fn crossing_levels(
    chart: &[&[Stitch]],
    plan: &[[f64; 2]],
    arcs: &[f64],
    length: f64,
    period_x: f64,
    course_height: f64,
) -> Vec<Vec<(f64, f64)>> {
    let (courses, wales) = (chart.len(), chart[0].len());
    let mut levels = vec![Vec::new(); courses];
    for (lower, upper) in plan_crossings(plan, period_x, course_height) {
        for course in 0..courses {
            let above = (course + 1) % courses;
            // Legs of the upper loop crossing the lower head lie high on the lower course and low
            // on the upper one; the upper sinker crossing the head's sides lies lower on both.
            let legs_through_head = lower.y(plan) + upper.y(plan) > 0.0;
            let (wale, upper_in_front_if_knit) =
                if legs_through_head { (upper.wale(wales), true) } else { (lower.wale(wales), false) };
            let knit = chart[above][wale] == Stitch::Knit;
            let upper_over = if knit { upper_in_front_if_knit } else { !upper_in_front_if_knit };
            let sign = if upper_over { 1.0 } else { -1.0 };
            levels[course].push((lower.arc(arcs, length), -sign));
            levels[above].push((upper.arc(arcs, length), sign));
        }
    }
    for l in &mut levels {
        l.sort_by(|a, b| a.0.total_cmp(&b.0));
    }
    levels
}

/// Crossings of a course's plan view with the plan view of the course above (shifted up by one
/// course height, in the three X1-images that can reach it).
fn plan_crossings(plan: &[[f64; 2]], period_x: f64, course_height: f64) -> Vec<(PlanPoint, PlanPoint)> {
    let n = plan.len();
    let point = |k: usize, dx: f64, dy: f64| {
        let wrap = (k / n) as f64 * period_x;
        Vector2::new(plan[k % n][0] + wrap + dx, plan[k % n][1] + dy)
    };
    let mut out = Vec::new();
    for i in 0..n {
        let (p0, p1) = (point(i, 0.0, 0.0), point(i + 1, 0.0, 0.0));
        for image in [-1.0, 0.0, 1.0] {
            for k in 0..n {
                let q0 = point(k, image * period_x, course_height);
                let q1 = point(k + 1, image * period_x, course_height);
                if let Some((s, t)) = segment_crossing_2d(&p0, &p1, &q0, &q1) {
                    out.push((PlanPoint { segment: i, fraction: s }, PlanPoint { segment: k, fraction: t }));
                }
            }
        }
    }
    out
}
