//! The `.pyp` periodic yarn pattern format of the published HYLC patterns.
//!
//! A text file of `*section` blocks; `#` starts a comment. With `n` the number of "vertedges"
//! (a vertex plus the edge leaving it):
//!
//! | section | rows | columns |
//! |---|---|---|
//! | `*pattern` | 1 | `px py radius n` (periods and radius in m) |
//! | `*Q` | n | `x y z t`: vertex position (m) and twist of the edge leaving it (rad) |
//! | `*E` | n | `v0 v1 dx dy`: edge from `v0` to `v1` shifted by `(dx, dy)` tiles |
//! | `*RL` | n | rest length of the edge leaving the vertex (m) |
//! | `*RK` | n | rest material curvature `kappa1 kappa2` at the vertex |
//! | `*RT` | n | rest twist at the vertex (rad) |
//! | `*RefD1` | n | reference director `d1` of the edge leaving the vertex |
//! | `*RefT` | n | reference twist at the vertex (rad) |
//!
//! The five rest sections are present together or not at all. Per-edge rows (`RL`, `RefD1`, the
//! `t` column) are indexed by the edge's source vertex, which we checked on the published files
//! (rest lengths match the outgoing edges to 0.1%, reference directors are orthogonal to them);
//! the order of the `*E` rows carries no meaning, and [`write_pyp`] lists them yarn by yarn.
//! Numbers are written in the shortest form that reads back to the same `f64`, so an import of
//! an export is exact.

use std::fmt::Write as _;

use crate::error::{Error, Result};
use crate::pattern::{Fabric, Pattern, RestState, Yarn};

const FORMAT: &str = ".pyp";

fn err(line: usize, message: impl Into<String>) -> Error {
    Error::Format { format: FORMAT, line, message: message.into() }
}

/// Numeric rows of a section, each with its 1-based line number.
type Rows = [(usize, Vec<f64>)];

/// One `*section` with its numeric rows and their line numbers.
struct Section {
    name: String,
    line: usize,
    rows: Vec<(usize, Vec<f64>)>,
}

fn sections(text: &str) -> Result<Vec<Section>> {
    let mut out: Vec<Section> = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let content = raw.split('#').next().unwrap_or("").trim();
        if let Some(name) = content.strip_prefix('*') {
            let name = name.split_whitespace().next().unwrap_or("").to_string();
            if out.iter().any(|s| s.name == name) {
                return Err(err(line, format!("section *{name} appears twice")));
            }
            out.push(Section { name, line, rows: Vec::new() });
        } else if !content.is_empty() {
            let section = out.last_mut().ok_or_else(|| err(line, "data before the first *section header"))?;
            let values = content
                .split_whitespace()
                .map(|t| {
                    t.parse::<f64>()
                        .ok()
                        .filter(|v| v.is_finite())
                        .ok_or_else(|| err(line, format!("'{t}' is not a finite number")))
                })
                .collect::<Result<Vec<f64>>>()?;
            section.rows.push((line, values));
        }
    }
    Ok(out)
}

/// Rows of one section, checked for count and width.
fn table<'a>(all: &'a [Section], name: &str, rows: usize, cols: usize) -> Result<Option<&'a Rows>> {
    let Some(s) = all.iter().find(|s| s.name == name) else {
        return Ok(None);
    };
    if s.rows.len() != rows {
        return Err(err(s.line, format!("section *{name} has {} rows, expected {rows}", s.rows.len())));
    }
    if let Some((line, row)) = s.rows.iter().find(|(_, r)| r.len() != cols) {
        return Err(err(*line, format!("section *{name} needs {cols} columns, found {}", row.len())));
    }
    Ok(Some(&s.rows))
}

fn required<'a>(all: &'a [Section], name: &str, rows: usize, cols: usize) -> Result<&'a Rows> {
    table(all, name, rows, cols)?.ok_or_else(|| err(0, format!("missing section *{name}")))
}

fn integer(line: usize, v: f64, what: &str) -> Result<i64> {
    if v.fract() == 0.0 && v.abs() < 1e15 {
        Ok(v as i64)
    } else {
        Err(err(line, format!("{what} must be an integer, got {v}")))
    }
}

/// Parse a `.pyp` text into a [`Pattern`] named `name`. The fabric is inferred from the
/// geometry unless given.
pub fn parse_pyp(text: &str, name: &str, fabric: Option<Fabric>) -> Result<Pattern> {
    let all = sections(text)?;
    let head = required(&all, "pattern", 1, 4)?;
    let (head_line, h) = (&head[0].0, &head[0].1);
    let n = integer(*head_line, h[3], "num_vertedges")?;
    if n < 3 {
        return Err(err(*head_line, format!("num_vertedges must be at least 3, got {n}")));
    }
    let n = n as usize;
    let q = required(&all, "Q", n, 4)?;
    let edges = required(&all, "E", n, 4)?;
    let yarns = yarns_from_edges(edges, n, h[2])?;
    let rest = rest_state(&all, n)?;
    let mut pattern = Pattern {
        name: name.to_string(),
        fabric: fabric.unwrap_or(Fabric::Knit),
        period_m: [h[0], h[1]],
        positions_m: q.iter().map(|(_, r)| [r[0], r[1], r[2]]).collect(),
        edge_twist_rad: q.iter().map(|(_, r)| r[3]).collect(),
        yarns,
        rest,
        origin: format!("import of {name}.pyp"),
    };
    if fabric.is_none() {
        pattern.fabric = pattern.infer_fabric();
    }
    pattern.validate().map_err(|problem| Error::Invalid { kind: "pattern", problem })?;
    Ok(pattern)
}

/// Follow the `*E` rows into yarns: every vertex must have exactly one outgoing and one
/// incoming edge. Yarns start at their lowest-numbered vertex.
fn yarns_from_edges(rows: &Rows, n: usize, radius: f64) -> Result<Vec<Yarn>> {
    let mut next: Vec<Option<(u32, [i32; 2], usize)>> = vec![None; n];
    let mut incoming: Vec<Option<usize>> = vec![None; n];
    for (line, r) in rows {
        let line = *line;
        let index = |v: f64, what: &str| -> Result<usize> {
            let i = integer(line, v, what)?;
            usize::try_from(i)
                .ok()
                .filter(|&i| i < n)
                .ok_or_else(|| err(line, format!("{what} {i} is out of range 0..{n}")))
        };
        let (a, b) = (index(r[0], "v0")?, index(r[1], "v1")?);
        let offset = |v: f64, what: &str| -> Result<i32> {
            let o = integer(line, v, what)?;
            i32::try_from(o).map_err(|_| err(line, format!("{what} {o} is out of range")))
        };
        let o = [offset(r[2], "dx")?, offset(r[3], "dy")?];
        if let Some((_, _, first)) = next[a] {
            return Err(err(line, format!("vertex {a} already has an outgoing edge (line {first})")));
        }
        if let Some(first) = incoming[b] {
            return Err(err(line, format!("vertex {b} already has an incoming edge (line {first})")));
        }
        next[a] = Some((b as u32, o, line));
        incoming[b] = Some(line);
    }
    let mut seen = vec![false; n];
    let mut yarns = Vec::new();
    for start in 0..n {
        if seen[start] {
            continue;
        }
        let mut yarn = Yarn { radius_m: radius, vertices: Vec::new(), edge_offsets: Vec::new() };
        let mut v = start;
        while !seen[v] {
            seen[v] = true;
            let (to, offset, _) =
                next[v].ok_or_else(|| err(0, format!("vertex {v} has no outgoing edge")))?;
            yarn.vertices.push(v as u32);
            yarn.edge_offsets.push(offset);
            v = to as usize;
        }
        yarns.push(yarn);
    }
    Ok(yarns)
}

fn rest_state(all: &[Section], n: usize) -> Result<Option<RestState>> {
    let names = ["RL", "RK", "RT", "RefD1", "RefT"];
    let present: Vec<&str> = names.iter().copied().filter(|m| all.iter().any(|s| s.name == *m)).collect();
    if present.is_empty() {
        return Ok(None);
    }
    if present.len() < names.len() {
        let missing: Vec<&str> = names.iter().copied().filter(|m| !present.contains(m)).collect();
        return Err(err(0, format!("rest state is incomplete: missing *{}", missing.join(", *"))));
    }
    let col =
        |name, c| -> Result<Vec<f64>> { Ok(required(all, name, n, c)?.iter().map(|(_, r)| r[0]).collect()) };
    Ok(Some(RestState {
        edge_length_m: col("RL", 1)?,
        vertex_curvature: required(all, "RK", n, 2)?.iter().map(|(_, r)| [r[0], r[1]]).collect(),
        vertex_twist_rad: col("RT", 1)?,
        edge_reference_director: required(all, "RefD1", n, 3)?
            .iter()
            .map(|(_, r)| [r[0], r[1], r[2]])
            .collect(),
        vertex_reference_twist_rad: col("RefT", 1)?,
    }))
}

/// The shortest decimal that reads back to the same `f64`, in exponent form for very small or
/// very large magnitudes.
fn number(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || (1e-4..1e15).contains(&a) { format!("{v}") } else { format!("{v:e}") }
}

fn row(out: &mut String, values: &[f64]) {
    let cells: Vec<String> = values.iter().map(|&v| number(v)).collect();
    out.push_str(&cells.join(" "));
    out.push('\n');
}

/// Write a pattern as `.pyp`. The format has one radius for all yarns: patterns whose yarns
/// differ in radius cannot be exported.
pub fn write_pyp(p: &Pattern) -> Result<String> {
    let (lo, hi) = p.radius_range_m();
    if lo != hi {
        return Err(Error::Unrepresentable {
            format: FORMAT,
            message: format!("yarn radii differ ({lo} to {hi} m) but .pyp stores one radius"),
        });
    }
    let n = p.vertex_count();
    let mut out = String::new();
    out.push_str("*pattern # px py radius num_vertedges\n");
    let _ = writeln!(out, "{} {} {} {n}", number(p.period_m[0]), number(p.period_m[1]), number(lo));
    out.push_str("\n*Q # dofs: x y z t\n");
    for (x, t) in p.positions_m.iter().zip(&p.edge_twist_rad) {
        row(&mut out, &[x[0], x[1], x[2], *t]);
    }
    out.push_str("\n*E # edges [v0, v1, dx, dy]\n");
    for e in p.edges() {
        let _ = writeln!(out, "{} {} {} {}", e.from, e.to, e.offset[0], e.offset[1]);
    }
    if let Some(rest) = &p.rest {
        let mut section = |header: &str, rows: &mut dyn Iterator<Item = Vec<f64>>| {
            out.push('\n');
            out.push_str(header);
            out.push('\n');
            for r in rows {
                row(&mut out, &r);
            }
        };
        section("*RL # rest lengths", &mut rest.edge_length_m.iter().map(|&v| vec![v]));
        section("*RK # rest kappas", &mut rest.vertex_curvature.iter().map(|k| k.to_vec()));
        section("*RT # rest twists", &mut rest.vertex_twist_rad.iter().map(|&v| vec![v]));
        section("*RefD1 # reference directors", &mut rest.edge_reference_director.iter().map(|d| d.to_vec()));
        section("*RefT # reference twists", &mut rest.vertex_reference_twist_rad.iter().map(|&v| vec![v]));
    }
    Ok(out)
}
