//! Wavefront OBJ writers: triangle meshes and yarn polylines.

use std::io::{self, Write};

/// Writes a triangle mesh as Wavefront OBJ: one `v x y z` line per vertex, then, if
/// `texcoords` is not empty, one `vt u v` line per vertex, then one `f` line per triangle
/// (`f a/a b/b c/c` with texture coordinates, `f a b c` without; OBJ indices are 1-based).
///
/// Numbers are printed with Rust's shortest round-trip formatting, so reading them back gives
/// the same `f64` bits. `texcoords` must be empty or hold one entry per vertex, and every
/// triangle index must be below `positions.len()`.
pub fn write_obj<W: Write>(
    out: W,
    positions: &[[f64; 3]],
    texcoords: &[[f64; 2]],
    triangles: &[[u32; 3]],
) -> io::Result<()> {
    if !texcoords.is_empty() && texcoords.len() != positions.len() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{} texture coordinates for {} vertices", texcoords.len(), positions.len()),
        ));
    }
    let mut out = out;
    write_vertices(&mut out, positions)?;
    for [u, v] in texcoords {
        writeln!(out, "vt {u} {v}")?;
    }
    for triangle in triangles {
        let [a, b, c] = triangle.map(|v| u64::from(v) + 1);
        if texcoords.is_empty() {
            writeln!(out, "f {a} {b} {c}")?;
        } else {
            writeln!(out, "f {a}/{a} {b}/{b} {c}/{c}")?;
        }
    }
    out.flush()
}

/// Writes yarn centrelines as Wavefront OBJ polylines: one `v x y z` line per vertex, then one
/// `l` line per yarn listing its vertices in order (1-based). `yarn_ranges` are
/// `[first vertex, vertex count]` ranges of `positions`, which they must lie in; yarns are
/// written open (the last vertex is not joined to the first), and yarns of fewer than two
/// vertices are left out (a line needs two).
pub fn write_obj_polylines<W: Write>(
    out: W,
    positions: &[[f64; 3]],
    yarn_ranges: &[[u32; 2]],
) -> io::Result<()> {
    let mut out = out;
    write_vertices(&mut out, positions)?;
    for &[first, count] in yarn_ranges.iter().filter(|range| range[1] >= 2) {
        let first = u64::from(first) + 1;
        write!(out, "l")?;
        for vertex in first..first + u64::from(count) {
            write!(out, " {vertex}")?;
        }
        writeln!(out)?;
    }
    out.flush()
}

/// The `v x y z` lines.
fn write_vertices<W: Write>(out: &mut W, positions: &[[f64; 3]]) -> io::Result<()> {
    for [x, y, z] in positions {
        writeln!(out, "v {x} {y} {z}")?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mesh_with_texture_coordinates() {
        let mut out = Vec::new();
        write_obj(
            &mut out,
            &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.5], [0.0, 0.1, 0.0]],
            &[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
            &[[0, 1, 2]],
        )
        .expect("write");
        let text = String::from_utf8(out).expect("utf-8");
        assert_eq!(text, "v 0 0 0\nv 1 0 0.5\nv 0 0.1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n");
    }

    #[test]
    fn a_mesh_without_texture_coordinates_and_a_mismatch() {
        let mut out = Vec::new();
        write_obj(&mut out, &[[0.0; 3]; 3], &[], &[[2, 1, 0]]).expect("write");
        assert!(String::from_utf8(out).expect("utf-8").ends_with("f 3 2 1\n"));
        let err = write_obj(Vec::new(), &[[0.0; 3]; 3], &[[0.0; 2]], &[]).expect_err("mismatch");
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
    }

    #[test]
    fn polylines_skip_single_vertex_yarns() {
        let mut out = Vec::new();
        write_obj_polylines(&mut out, &[[0.0; 3]; 6], &[[0, 3], [3, 1], [4, 2]]).expect("write");
        let text = String::from_utf8(out).expect("utf-8");
        assert!(text.ends_with("v 0 0 0\nl 1 2 3\nl 5 6\n"), "{text}");
    }
}
