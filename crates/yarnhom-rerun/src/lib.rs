#![doc = include_str!("../README.md")]

use std::collections::HashMap;
use std::io::Read;

pub use rerun;
use rerun::{LineStrips3D, Mesh3D, Points3D, RecordingStream, Scalars};

use yarnhom_trace::export::{boundary_triangles, check_tet_topology};
use yarnhom_trace::{
    MeshFrame, MeshTopology, RveSample, SolverIteration, SolverStep, TetFrame, TetTopology, TraceError,
    TraceMessage, TraceReader, Truncation, YarnFrame, YarnNodes,
};

/// Errors of the rerun logger.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RerunLogError {
    /// The trace could not be read.
    #[error(transparent)]
    Trace(#[from] TraceError),
    /// rerun refused a log call.
    #[error("rerun: {0}")]
    Rerun(#[from] rerun::RecordingStreamError),
    /// A frame refers to a mesh whose topology was not logged first.
    #[error("{topic}: frame {frame} of mesh '{mesh}' comes before the mesh's topology")]
    MissingTopology {
        /// Topic of the frame.
        topic: &'static str,
        /// Mesh name.
        mesh: String,
        /// Frame number.
        frame: u64,
    },
    /// A tet mesh's topology indexes past its vertices.
    #[error("/tet/topology: tet mesh '{mesh}': {problem}")]
    InvalidTopology {
        /// Mesh name.
        mesh: String,
        /// What is wrong.
        problem: String,
    },
}

/// What [`log_trace`] logged.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LogStats {
    /// Messages logged.
    pub logged: u64,
    /// Messages on topics the logger does not draw (skipped).
    pub skipped: u64,
    /// Set if the trace ended early (everything before the cut was logged).
    pub truncation: Option<Truncation>,
}

/// Logs trace messages into a rerun recording, keeping the topologies it needs to draw frames.
pub struct RerunLogger<'a> {
    rec: &'a RecordingStream,
    /// Triangle count of each surface mesh, to check frames against.
    meshes: HashMap<String, usize>,
    /// Triangles of each mesh (surface meshes and tet boundaries), for normals.
    triangles: HashMap<String, Vec<[u32; 3]>>,
    /// The vertices handles hold, per yarn set (from `/yarn/nodes`).
    held: HashMap<String, Vec<usize>>,
}

impl<'a> RerunLogger<'a> {
    /// A logger writing into `rec`.
    pub fn new(rec: &'a RecordingStream) -> Self {
        Self { rec, meshes: HashMap::new(), triangles: HashMap::new(), held: HashMap::new() }
    }

    /// Logs one message; returns `false` if its topic is not drawn.
    pub fn log(&mut self, message: &TraceMessage) -> Result<bool, RerunLogError> {
        match message {
            TraceMessage::Topology(m) => self.log_mesh_topology(m)?,
            TraceMessage::Frame(m) => self.log_mesh_frame(m)?,
            TraceMessage::YarnNodes(m) => {
                self.held.insert(m.yarns.clone(), held_vertices(m));
            }
            TraceMessage::Yarns(m) => self.log_yarns(m)?,
            TraceMessage::TetTopology(m) => self.log_tet_topology(m)?,
            TraceMessage::TetFrame(m) => self.log_tet_frame(m)?,
            TraceMessage::Scalars(m) => {
                self.set_time(m.frame, m.time_s);
                for (name, value) in &m.values {
                    self.rec.log(format!("metrics/{name}"), &Scalars::single(*value))?;
                }
            }
            TraceMessage::Solver(m) => self.log_solver_step(m)?,
            TraceMessage::SolverIteration(m) => self.log_solver_iteration(m)?,
            TraceMessage::RveSample(m) => self.log_rve_sample(m)?,
            _ => return Ok(false),
        }
        Ok(true)
    }

    fn set_time(&self, frame: u64, time_s: f64) {
        self.rec.set_time_sequence("frame", i64::try_from(frame).unwrap_or(i64::MAX));
        self.rec.set_duration_secs("sim_time", time_s);
    }

    fn log_mesh_topology(&mut self, m: &MeshTopology) -> Result<(), RerunLogError> {
        self.rec.log_static(
            format!("mesh/{}", m.name),
            &Mesh3D::update_fields().with_triangle_indices(m.triangles.clone()),
        )?;
        self.meshes.insert(m.name.clone(), m.rest_positions_m.len());
        self.triangles.insert(m.name.clone(), m.triangles.clone());
        Ok(())
    }

    fn log_mesh_frame(&mut self, m: &MeshFrame) -> Result<(), RerunLogError> {
        self.log_positions("/mesh/frame", "mesh", &m.mesh, m.frame, m.time_s, &m.positions_m)
    }

    fn log_tet_topology(&mut self, m: &TetTopology) -> Result<(), RerunLogError> {
        check_tet_topology(m)
            .map_err(|problem| RerunLogError::InvalidTopology { mesh: m.name.clone(), problem })?;
        let boundary = boundary_triangles(&m.tets, &m.rest_positions_m);
        self.rec.log_static(
            format!("tet/{}", m.name),
            &Mesh3D::update_fields().with_triangle_indices(boundary.clone()),
        )?;
        self.meshes.insert(m.name.clone(), m.rest_positions_m.len());
        self.triangles.insert(m.name.clone(), boundary);
        Ok(())
    }

    fn log_tet_frame(&mut self, m: &TetFrame) -> Result<(), RerunLogError> {
        self.log_positions("/tet/frame", "tet", &m.mesh, m.frame, m.time_s, &m.positions_m)
    }

    /// Logs new vertex positions (and normals) of a mesh whose topology was logged.
    fn log_positions(
        &self,
        topic: &'static str,
        prefix: &str,
        mesh: &str,
        frame: u64,
        time_s: f64,
        positions_m: &[[f64; 3]],
    ) -> Result<(), RerunLogError> {
        let Some(triangles) = self.triangles.get(mesh) else {
            return Err(RerunLogError::MissingTopology { topic, mesh: mesh.to_owned(), frame });
        };
        self.set_time(frame, time_s);
        let positions: Vec<[f32; 3]> = positions_m.iter().map(|p| p.map(|x| x as f32)).collect();
        let normals = vertex_normals(positions_m, triangles);
        self.rec.log(
            format!("{prefix}/{mesh}"),
            &Mesh3D::update_fields().with_vertex_positions(positions).with_vertex_normals(normals),
        )?;
        Ok(())
    }

    fn log_yarns(&self, m: &YarnFrame) -> Result<(), RerunLogError> {
        self.set_time(m.frame, m.time_s);
        let mut strips = Vec::with_capacity(m.yarn_ranges.len());
        let mut radii = Vec::with_capacity(m.yarn_ranges.len());
        for &[start, count] in &m.yarn_ranges {
            let range = start as usize..(start as usize + count as usize).min(m.positions_m.len());
            strips.push(m.positions_m[range.clone()].iter().map(|p| p.map(|x| x as f32)).collect::<Vec<_>>());
            let yarn_radii = m.radii_m.get(range).unwrap_or(&[]);
            radii.push((yarn_radii.iter().sum::<f64>() / yarn_radii.len().max(1) as f64) as f32);
        }
        self.rec.log(format!("yarns/{}", m.yarns), &LineStrips3D::new(strips).with_radii(radii))?;
        if let Some(held) = self.held.get(&m.yarns).filter(|h| !h.is_empty()) {
            let (points, radii): (Vec<[f32; 3]>, Vec<f32>) = held
                .iter()
                .filter_map(|&v| {
                    Some((m.positions_m.get(v)?.map(|x| x as f32), 1.5 * *m.radii_m.get(v)? as f32))
                })
                .unzip();
            let handles = Points3D::new(points).with_radii(radii).with_colors([HANDLE_COLOUR]);
            self.rec.log(format!("yarns/{}/handles", m.yarns), &handles)?;
        }
        Ok(())
    }

    fn log_solver_step(&self, m: &SolverStep) -> Result<(), RerunLogError> {
        self.set_time(m.frame, m.time_s);
        for (name, value) in [
            ("newton_iterations", f64::from(m.newton_iterations)),
            ("residual", m.residual),
            ("line_search_steps", f64::from(m.line_search_steps)),
            ("wall_time_s", m.wall_time_s),
        ] {
            self.rec.log(format!("solver/{name}"), &Scalars::single(value))?;
        }
        Ok(())
    }

    fn log_solver_iteration(&self, m: &SolverIteration) -> Result<(), RerunLogError> {
        self.set_time(m.frame, m.time_s);
        for (name, value) in
            [("energy_j", m.energy_j), ("residual", m.residual), ("step_length", m.step_length)]
        {
            self.rec.log(format!("solver/iteration/{name}"), &Scalars::single(value))?;
        }
        Ok(())
    }

    fn log_rve_sample(&self, m: &RveSample) -> Result<(), RerunLogError> {
        if let Some(energy) = m.energy_density_j_m2 {
            self.set_time(m.frame, m.time_s);
            self.rec.log(
                format!("rve/{}/energy_density_j_m2", m.term.replace(',', "_")),
                &Scalars::single(energy),
            )?;
        }
        Ok(())
    }
}

/// Colour of the vertices handles hold (orange).
const HANDLE_COLOUR: [u8; 3] = [255, 140, 0];

/// The vertices of a yarn set that handles hold (node type `HANDLE`).
fn held_vertices(nodes: &YarnNodes) -> Vec<usize> {
    nodes.node_type.iter().enumerate().filter(|&(_, &t)| t == YarnNodes::HANDLE).map(|(v, _)| v).collect()
}

/// Logs every message of a trace into `rec`. A truncated trace is logged up to the cut, and
/// the truncation is reported in the statistics.
pub fn log_trace<R: Read>(reader: TraceReader<R>, rec: &RecordingStream) -> Result<LogStats, RerunLogError> {
    let mut logger = RerunLogger::new(rec);
    let mut stats = LogStats::default();
    for message in reader {
        let message = match message {
            Err(TraceError::Truncated(truncation)) => {
                stats.truncation = Some(truncation);
                break;
            }
            other => other?,
        };
        if logger.log(&message)? {
            stats.logged += 1;
        } else {
            stats.skipped += 1;
        }
    }
    Ok(stats)
}

/// Area-weighted vertex normals of a triangle mesh (unit length; zero for unused vertices).
fn vertex_normals(positions_m: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<[f32; 3]> {
    let mut normals = vec![[0.0f64; 3]; positions_m.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| positions_m.get(i as usize).copied().unwrap_or_default());
        let (u, v) = ([b[0] - a[0], b[1] - a[1], b[2] - a[2]], [c[0] - a[0], c[1] - a[1], c[2] - a[2]]);
        let n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
        for &i in t {
            if let Some(normal) = normals.get_mut(i as usize) {
                for k in 0..3 {
                    normal[k] += n[k];
                }
            }
        }
    }
    normals
        .into_iter()
        .map(|n| {
            let length = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if length > 0.0 { n.map(|x| (x / length) as f32) } else { [0.0; 3] }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_held_vertices_are_drawn_as_handles() {
        let nodes = YarnNodes {
            yarns: "stock".into(),
            rest_positions_m: vec![[0.0; 3]; 5],
            node_type: vec![YarnNodes::HANDLE, 0, 0, YarnNodes::HANDLE, 0],
            edges: vec![[0, 1], [1, 2], [3, 4]],
        };
        assert_eq!(held_vertices(&nodes), vec![0, 3]);
        let (rec, _storage) = rerun::RecordingStreamBuilder::new("test").memory().expect("a recording");
        let mut logger = RerunLogger::new(&rec);
        assert!(logger.log(&TraceMessage::YarnNodes(nodes)).expect("logs"));
        let frame = YarnFrame {
            yarns: "stock".into(),
            frame: 0,
            time_s: 0.0,
            positions_m: vec![[0.0; 3]; 5],
            edge_twist_rad: vec![0.0; 5],
            radii_m: vec![1e-3; 5],
            yarn_ranges: vec![[0, 3], [3, 2]],
        };
        assert!(logger.log(&TraceMessage::Yarns(frame)).expect("logs"));
        assert_eq!(logger.held["stock"], vec![0, 3]);
    }

    #[test]
    fn two_tets_sharing_a_face_have_six_boundary_faces_facing_out() {
        let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
        let tets = [[0, 1, 2, 3], [1, 2, 3, 4]];
        let boundary = boundary_triangles(&tets, &positions);
        assert_eq!(boundary.len(), 6);
        let centroid = |ids: &[u32]| {
            let mut c = [0.0; 3];
            for &i in ids {
                for k in 0..3 {
                    c[k] += positions[i as usize][k] / ids.len() as f64;
                }
            }
            c
        };
        for face in boundary {
            let tet = tets.iter().find(|t| face.iter().all(|v| t.contains(v))).expect("owner");
            let normal = vertex_normals(&positions, &[face]);
            let n = normal[face[0] as usize];
            let (fc, tc) = (centroid(&face), centroid(tet));
            let outward: f64 = (0..3).map(|k| f64::from(n[k]) * (fc[k] - tc[k])).sum();
            assert!(outward > 0.0, "face {face:?} points inwards");
        }
    }
}
