//! Checks of topologies and frames before they are exported, the boundary of a tet mesh, and
//! names made safe for files and HDF5 links.

use std::collections::HashMap;

use crate::{TetTopology, YarnFrame};

/// Checks that every index of `elements` is below `vertex_count`; says which one is not.
pub(super) fn check_indices<const N: usize>(
    elements: &[[u32; N]],
    vertex_count: usize,
    what: &str,
) -> Result<(), String> {
    match elements.iter().enumerate().find(|(_, element)| element.iter().any(|&v| v as usize >= vertex_count))
    {
        Some((k, element)) => Err(format!("{what} {k} {element:?} indexes past the {vertex_count} vertices")),
        None => Ok(()),
    }
}

/// Checks a tet topology: vertex indices in range, one value per tetrahedron.
pub fn check_tet_topology(topology: &TetTopology) -> Result<(), String> {
    check_indices(&topology.tets, topology.rest_positions_m.len(), "tetrahedron")?;
    let tets = topology.tets.len();
    match topology.element_values.iter().find(|(_, values)| values.len() != tets) {
        Some((name, values)) => {
            Err(format!("element value {name:?} has {} values for {tets} tetrahedra", values.len()))
        }
        None => Ok(()),
    }
}

/// Checks that a frame has as many vertices as its topology.
pub(super) fn check_vertex_count(positions: &[[f64; 3]], vertex_count: usize) -> Result<(), String> {
    if positions.len() == vertex_count {
        Ok(())
    } else {
        Err(format!("{} vertex positions, but the topology has {vertex_count} vertices", positions.len()))
    }
}

/// Checks a yarn frame: ranges within the vertices, one radius per vertex, one twist per vertex
/// (or none).
pub(super) fn check_yarn_frame(frame: &YarnFrame) -> Result<(), String> {
    let n = frame.positions_m.len();
    if let Some((k, range)) = frame
        .yarn_ranges
        .iter()
        .enumerate()
        .find(|(_, [first, count])| u64::from(*first) + u64::from(*count) > n as u64)
    {
        return Err(format!("yarn range {k} {range:?} ends past the {n} vertices"));
    }
    if frame.radii_m.len() != n {
        return Err(format!("{} radii for {n} vertices", frame.radii_m.len()));
    }
    if !frame.edge_twist_rad.is_empty() && frame.edge_twist_rad.len() != n {
        return Err(format!("{} edge twists for {n} vertices", frame.edge_twist_rad.len()));
    }
    Ok(())
}

/// The triangles of a tet mesh that belong to one tetrahedron only, oriented so that their
/// normals (counter-clockwise) point out of the mesh, in the order of their tetrahedra.
/// Tetrahedra negatively oriented at rest are turned around first. Indices must be in range.
pub fn boundary_triangles(tets: &[[u32; 4]], rest_positions: &[[f64; 3]]) -> Vec<[u32; 3]> {
    let faces: Vec<[u32; 3]> = tets.iter().flat_map(|&tet| outward_faces(tet, rest_positions)).collect();
    let mut count: HashMap<[u32; 3], u32> = HashMap::with_capacity(faces.len());
    for face in &faces {
        *count.entry(sorted(*face)).or_default() += 1;
    }
    faces.into_iter().filter(|face| count.get(&sorted(*face)) == Some(&1)).collect()
}

/// The four faces of a tetrahedron, oriented outwards.
fn outward_faces(tet: [u32; 4], rest_positions: &[[f64; 3]]) -> [[u32; 3]; 4] {
    let [a, b, c, d] =
        if signed_volume(tet, rest_positions) < 0.0 { [tet[1], tet[0], tet[2], tet[3]] } else { tet };
    [[a, c, b], [a, b, d], [a, d, c], [b, c, d]]
}

/// Six times the signed volume of a tetrahedron: positive when `(b - a) x (c - a)` points to `d`.
fn signed_volume(tet: [u32; 4], positions: &[[f64; 3]]) -> f64 {
    let [a, b, c, d] = tet.map(|v| positions[v as usize]);
    let (u, v, w) = (sub(b, a), sub(c, a), sub(d, a));
    let cross = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
    cross[0] * w[0] + cross[1] * w[1] + cross[2] * w[2]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn sorted(mut face: [u32; 3]) -> [u32; 3] {
    face.sort_unstable();
    face
}

/// A stream name as the start of a file name: characters other than ASCII letters, digits,
/// `-`, `_` and `.` become `_`, as does a leading `.` (no hidden files); an empty name becomes
/// `_`.
pub(super) fn file_stem(name: &str) -> String {
    let mut stem: String = name
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.') { c } else { '_' })
        .collect();
    if stem.is_empty() || stem.starts_with('.') {
        stem.insert(0, '_');
    }
    stem
}

/// A stream or value name as an HDF5 link name: `/` becomes `_`; an empty name, `.` and `..`
/// get a leading `_`.
#[cfg(feature = "hdf5")]
pub(super) fn link_name(name: &str) -> String {
    let link = name.replace('/', "_");
    match link.as_str() {
        "" | "." | ".." => format!("_{link}"),
        _ => link,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_tet() -> Vec<[f64; 3]> {
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]]
    }

    /// Normal of a face, not normalized.
    fn normal(face: [u32; 3], p: &[[f64; 3]]) -> [f64; 3] {
        let [a, b, c] = face.map(|v| p[v as usize]);
        let (u, v) = (sub(b, a), sub(c, a));
        [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
    }

    fn centroid(vertices: &[u32], p: &[[f64; 3]]) -> [f64; 3] {
        let n = vertices.len() as f64;
        let sum = vertices.iter().fold([0.0; 3], |s, &v| {
            let q = p[v as usize];
            [s[0] + q[0], s[1] + q[1], s[2] + q[2]]
        });
        sum.map(|x| x / n)
    }

    #[test]
    fn two_tets_sharing_a_face_have_six_outward_boundary_triangles() {
        let p = unit_tet();
        // The second tetrahedron is negatively oriented: it must be turned around.
        let tets = [[0, 1, 2, 3], [1, 3, 2, 4]];
        assert!(signed_volume(tets[1], &p) < 0.0);
        let boundary = boundary_triangles(&tets, &p);
        assert_eq!(boundary.len(), 6);
        assert!(!boundary.iter().any(|f| sorted(*f) == [1, 2, 3]), "the shared face is inside");
        let inside = centroid(&[0, 1, 2, 3, 4], &p);
        for face in boundary {
            let (n, c) = (normal(face, &p), centroid(&face, &p));
            let outwards: f64 = (0..3).map(|k| n[k] * (c[k] - inside[k])).sum();
            assert!(outwards > 0.0, "{face:?} points inwards");
        }
    }

    #[test]
    fn names_become_safe_file_stems_and_links() {
        assert_eq!(file_stem("drape"), "drape");
        assert_eq!(file_stem("a b/c"), "a_b_c");
        assert_eq!(file_stem(".hidden"), "_.hidden");
        assert_eq!(file_stem(""), "_");
        #[cfg(feature = "hdf5")]
        {
            assert_eq!(link_name("a/b"), "a_b");
            assert_eq!(link_name(".."), "_..");
            assert_eq!(link_name("x y"), "x y");
        }
    }

    #[test]
    fn bad_indices_and_ranges_are_named() {
        assert!(check_indices(&[[0, 1, 2]], 3, "triangle").is_ok());
        let err = check_indices(&[[0, 1, 2], [0, 3, 1]], 3, "triangle").expect_err("out of range");
        assert!(err.contains("triangle 1"), "{err}");
        let frame = YarnFrame {
            positions_m: vec![[0.0; 3]; 3],
            radii_m: vec![1.0; 3],
            yarn_ranges: vec![[1, 3]],
            ..Default::default()
        };
        assert!(check_yarn_frame(&frame).expect_err("range").contains("yarn range 0"));
    }
}
