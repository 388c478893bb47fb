//! Smooth periodic curves: B-spline sampling, arc length, resampling, and the over/under
//! undulation of a yarn through its crossings.

/// Height of yarn crossings above and below the mid-plane, in yarn radii: crossing centrelines
/// are `3 r` apart. The margin over touching (`2 r`) is what lets a yarn change sides between
/// two crossings close together (a weave's neighbouring yarns, a loop's leg between the head
/// below and the sinker above) without coming within 1.9 r of either.
pub const LEVEL_R: f64 = 1.5;
/// Fraction of each gap between crossings over which a yarn stays level.
pub const PLATEAU: f64 = 0.15;

/// Sample a uniform cubic B-spline through a periodic control polygon whose point `i + n` is
/// point `i` shifted by `shift` (one tile), `samples_per_span` points per control span.
pub fn periodic_bspline(control: &[[f64; 2]], shift: [f64; 2], samples_per_span: usize) -> Vec<[f64; 2]> {
    let n = control.len() as isize;
    let point = |i: isize| {
        let (q, k) = (i.div_euclid(n), i.rem_euclid(n) as usize);
        [control[k][0] + q as f64 * shift[0], control[k][1] + q as f64 * shift[1]]
    };
    let mut out = Vec::with_capacity(control.len() * samples_per_span);
    for i in 0..n {
        let p = [point(i - 1), point(i), point(i + 1), point(i + 2)];
        for k in 0..samples_per_span {
            let t = k as f64 / samples_per_span as f64;
            let b = [
                (1.0 - t).powi(3) / 6.0,
                (3.0 * t.powi(3) - 6.0 * t * t + 4.0) / 6.0,
                (-3.0 * t.powi(3) + 3.0 * t * t + 3.0 * t + 1.0) / 6.0,
                t.powi(3) / 6.0,
            ];
            out.push([0, 1].map(|c| (0..4).map(|j| b[j] * p[j][c]).sum()));
        }
    }
    out
}

/// Cumulative arc length at each point of a closed periodic polyline (the last point joins the
/// first shifted by `shift`), and the total length.
pub fn arc_lengths<const D: usize>(points: &[[f64; D]], shift: [f64; D]) -> (Vec<f64>, f64) {
    let mut arcs = Vec::with_capacity(points.len());
    let mut total = 0.0;
    for (k, p) in points.iter().enumerate() {
        arcs.push(total);
        let next = match points.get(k + 1) {
            Some(q) => *q,
            None => std::array::from_fn(|c| points[0][c] + shift[c]),
        };
        total += (0..D).map(|c| (next[c] - p[c]).powi(2)).sum::<f64>().sqrt();
    }
    (arcs, total)
}

/// `n` points equally spaced in arc length along a closed periodic polyline, starting at its
/// first point.
pub fn resample(points: &[[f64; 3]], shift: [f64; 3], n: usize) -> Vec<[f64; 3]> {
    let (arcs, total) = arc_lengths(points, shift);
    let at = |k: usize| -> [f64; 3] {
        if k < points.len() { points[k] } else { std::array::from_fn(|c| points[0][c] + shift[c]) }
    };
    let mut out = Vec::with_capacity(n);
    let mut seg = 0;
    for i in 0..n {
        let s = total * i as f64 / n as f64;
        while seg + 1 < points.len() && arcs[seg + 1] <= s {
            seg += 1;
        }
        let end = if seg + 1 < points.len() { arcs[seg + 1] } else { total };
        let f = if end > arcs[seg] { (s - arcs[seg]) / (end - arcs[seg]) } else { 0.0 };
        let (a, b) = (at(seg), at(seg + 1));
        out.push(std::array::from_fn(|c| a[c] + f * (b[c] - a[c])));
    }
    out
}

/// Height of a yarn at arc positions `arcs` (periodic with length `total`) that passes its
/// crossings `levels` (arc position, +1 over / -1 under, sorted by arc) at `+-amplitude`: flat
/// for a fraction `plateau` of each gap on either side of a crossing (so the yarn is level where
/// it meets another), a half cosine in between.
pub fn undulate(arcs: &[f64], total: f64, levels: &[(f64, f64)], amplitude: f64, plateau: f64) -> Vec<f64> {
    if levels.is_empty() {
        return vec![0.0; arcs.len()];
    }
    let n = levels.len();
    // One period before and after, so every arc has a crossing on each side.
    let level = |i: isize| {
        let (q, k) = (i.div_euclid(n as isize), i.rem_euclid(n as isize) as usize);
        (levels[k].0 + q as f64 * total, levels[k].1)
    };
    arcs.iter()
        .map(|&s| {
            let mut i = -1isize;
            while level(i + 1).0 <= s {
                i += 1;
            }
            let ((s0, v0), (s1, v1)) = (level(i), level(i + 1));
            let t = ((s - s0) / (s1 - s0) - plateau) / (1.0 - 2.0 * plateau);
            let t = t.clamp(0.0, 1.0);
            amplitude * ((v0 + v1) / 2.0 + (v0 - v1) / 2.0 * (std::f64::consts::PI * t).cos())
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bspline_of_a_straight_periodic_polygon_is_straight_and_periodic() {
        let control: Vec<[f64; 2]> = (0..4).map(|i| [i as f64, 1.0]).collect();
        let pts = periodic_bspline(&control, [4.0, 0.0], 5);
        assert_eq!(pts.len(), 20);
        for (k, p) in pts.iter().enumerate() {
            assert!((p[1] - 1.0).abs() < 1e-14);
            assert!((p[0] - k as f64 / 5.0).abs() < 1e-12, "uniform parameter: {p:?}");
        }
    }

    #[test]
    fn resampling_a_line_gives_equal_spacing() {
        let pts = vec![[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [3.0, 0.0, 0.0]];
        let out = resample(&pts, [4.0, 0.0, 0.0], 8);
        for (i, p) in out.iter().enumerate() {
            assert!((p[0] - 0.5 * i as f64).abs() < 1e-12, "{out:?}");
        }
    }

    #[test]
    fn undulation_is_level_at_crossings_and_bounded() {
        let levels = [(1.0, 1.0), (3.0, -1.0), (6.0, -1.0)];
        let arcs: Vec<f64> = (0..80).map(|i| i as f64 * 0.1).collect();
        let z = undulate(&arcs, 8.0, &levels, 2.0, 0.2);
        assert!((z[10] - 2.0).abs() < 1e-12 && (z[30] + 2.0).abs() < 1e-12 && (z[60] + 2.0).abs() < 1e-12);
        assert!((z[45] + 2.0).abs() < 1e-12, "between two unders the yarn stays under");
        assert!(z.iter().all(|v| v.abs() <= 2.0 + 1e-12));
        // Periodic: the gap from the last crossing to the first (across the period) is smooth.
        let wrap = undulate(&[7.5, 8.0 - 1e-9], 8.0, &levels, 2.0, 0.2);
        let start = undulate(&[0.0], 8.0, &levels, 2.0, 0.2);
        assert!((wrap[1] - start[0]).abs() < 1e-6);
    }
}
