//! Binary little-endian PLY writers: triangle meshes and yarn polylines.

use std::io::{self, Write};

/// Writes a triangle mesh as binary little-endian PLY 1.0: vertices with `double` `x`, `y`,
/// `z`, faces as `list uchar uint vertex_indices` (0-based). The header is
///
/// ```text
/// ply
/// format binary_little_endian 1.0
/// element vertex V
/// property double x
/// property double y
/// property double z
/// element face T
/// property list uchar uint vertex_indices
/// end_header
/// ```
///
/// followed by `24 V + 13 T` bytes. Every triangle index must be below `positions.len()`.
pub fn write_ply<W: Write>(out: W, positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> io::Result<()> {
    let mut out = out;
    let header = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty double x\nproperty double y\n\
         property double z\nelement face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        positions.len(),
        triangles.len()
    );
    out.write_all(header.as_bytes())?;
    for position in positions {
        write_f64s(&mut out, position)?;
    }
    for triangle in triangles {
        out.write_all(&[3])?;
        write_u32s(&mut out, triangle)?;
    }
    out.flush()
}

/// Writes yarn centrelines as binary little-endian PLY 1.0: vertices with `double` `x`, `y`,
/// `z` and `radius` (metres), and one `edge` element (`uint vertex1`, `uint vertex2`, 0-based)
/// per pair of consecutive vertices of a yarn. `yarn_ranges` are `[first vertex, vertex count]`
/// ranges of `positions`, which they must lie in; yarns are written open (the last vertex is
/// not joined to the first). `radii` holds one radius per vertex. The body is
/// `32 V + 8 E` bytes.
pub fn write_ply_polylines<W: Write>(
    out: W,
    positions: &[[f64; 3]],
    radii: &[f64],
    yarn_ranges: &[[u32; 2]],
) -> io::Result<()> {
    if radii.len() != positions.len() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{} radii for {} vertices", radii.len(), positions.len()),
        ));
    }
    let mut out = out;
    let edges: u64 = yarn_ranges.iter().map(|&[_, count]| u64::from(count.saturating_sub(1))).sum();
    let header = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty double x\nproperty double y\n\
         property double z\nproperty double radius\nelement edge {edges}\nproperty uint vertex1\n\
         property uint vertex2\nend_header\n",
        positions.len()
    );
    out.write_all(header.as_bytes())?;
    for (position, radius) in positions.iter().zip(radii) {
        write_f64s(&mut out, position)?;
        write_f64s(&mut out, &[*radius])?;
    }
    for &[first, count] in yarn_ranges {
        for vertex in first..first.saturating_add(count).saturating_sub(1) {
            write_u32s(&mut out, &[vertex, vertex + 1])?;
        }
    }
    out.flush()
}

fn write_f64s<W: Write>(out: &mut W, values: &[f64]) -> io::Result<()> {
    values.iter().try_for_each(|value| out.write_all(&value.to_le_bytes()))
}

fn write_u32s<W: Write>(out: &mut W, values: &[u32]) -> io::Result<()> {
    values.iter().try_for_each(|value| out.write_all(&value.to_le_bytes()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polylines_have_one_edge_per_consecutive_pair() {
        let mut out = Vec::new();
        let positions = [[0.0; 3]; 5];
        write_ply_polylines(&mut out, &positions, &[1e-4; 5], &[[0, 3], [3, 2]]).expect("write");
        let text = String::from_utf8_lossy(&out);
        assert!(text.contains("element edge 3\n"), "{text}");
        let header_end = text.find("end_header\n").expect("header") + "end_header\n".len();
        assert_eq!(out.len() - header_end, 5 * 32 + 3 * 8);
        let edges: Vec<u32> =
            out[out.len() - 24..].chunks(4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
        assert_eq!(edges, [0, 1, 1, 2, 3, 4]);
        assert!(write_ply_polylines(Vec::new(), &positions, &[1e-4], &[]).is_err());
    }
}
