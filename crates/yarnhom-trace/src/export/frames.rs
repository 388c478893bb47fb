//! Per-frame OBJ and PLY files.

use std::collections::HashMap;
use std::fs;
use std::io;
use std::path::{Path, PathBuf};

use super::geometry::{
    boundary_triangles, check_indices, check_tet_topology, check_vertex_count, check_yarn_frame, file_stem,
};
use yarnhom_artifacts::AtomicFile;

use super::{ExportError, ExportStats, FrameFormat, obj, ply};
use crate::{MeshFrame, MeshTopology, TetFrame, TetTopology, TraceMessage, YarnFrame};

/// What a frame of a mesh or tet mesh is drawn with: the faces and texture coordinates of its
/// topology.
struct Surface {
    vertex_count: usize,
    triangles: Vec<[u32; 3]>,
    /// Empty for tet meshes.
    texcoords: Vec<[f64; 2]>,
}

/// Writes the frames of one trace into a folder, one file per frame.
pub(super) struct FrameWriter<'a> {
    dir: &'a Path,
    format: FrameFormat,
    meshes: HashMap<String, Surface>,
    tets: HashMap<String, Surface>,
}

impl<'a> FrameWriter<'a> {
    /// A writer into `dir`, which is created if needed.
    pub(super) fn create(dir: &'a Path, format: FrameFormat) -> Result<Self, ExportError> {
        fs::create_dir_all(dir).map_err(|error| ExportError::Write { path: dir.to_path_buf(), error })?;
        Ok(Self { dir, format, meshes: HashMap::new(), tets: HashMap::new() })
    }

    /// Exports one message: topologies are remembered, frames written, anything else skipped.
    pub(super) fn write(
        &mut self,
        message: TraceMessage,
        stats: &mut ExportStats,
    ) -> Result<(), ExportError> {
        match message {
            TraceMessage::Topology(topology) => self.add_mesh(topology),
            TraceMessage::TetTopology(topology) => self.add_tet_mesh(topology),
            TraceMessage::Frame(frame) => self.write_mesh_frame(&frame, stats),
            TraceMessage::TetFrame(frame) => self.write_tet_frame(&frame, stats),
            TraceMessage::Yarns(frame) => self.write_yarn_frame(&frame, stats),
            other => {
                stats.skip(&other);
                Ok(())
            }
        }
    }

    fn add_mesh(&mut self, topology: MeshTopology) -> Result<(), ExportError> {
        let vertex_count = topology.rest_positions_m.len();
        check_indices(&topology.triangles, vertex_count, "triangle")
            .map_err(|problem| ExportError::topology(&format!("mesh {:?}", topology.name), problem))?;
        let texcoords = topology.rest_positions_m.iter().map(|&[x, y, _]| [x, y]).collect();
        let surface = Surface { vertex_count, triangles: topology.triangles, texcoords };
        self.meshes.insert(topology.name, surface);
        Ok(())
    }

    fn add_tet_mesh(&mut self, topology: TetTopology) -> Result<(), ExportError> {
        check_tet_topology(&topology)
            .map_err(|problem| ExportError::topology(&format!("tet mesh {:?}", topology.name), problem))?;
        let triangles = boundary_triangles(&topology.tets, &topology.rest_positions_m);
        let surface =
            Surface { vertex_count: topology.rest_positions_m.len(), triangles, texcoords: Vec::new() };
        self.tets.insert(topology.name, surface);
        Ok(())
    }

    fn write_mesh_frame(&self, frame: &MeshFrame, stats: &mut ExportStats) -> Result<(), ExportError> {
        let surface = self.meshes.get(&frame.mesh).ok_or_else(|| ExportError::MissingTopology {
            mesh: format!("mesh {:?}", frame.mesh),
            frame: frame.frame,
        })?;
        let stream = format!("mesh {:?}", frame.mesh);
        self.write_surface(&stream, &frame.mesh, frame.frame, &frame.positions_m, surface)?;
        stats.count_file(&format!("/mesh/{}", frame.mesh));
        Ok(())
    }

    fn write_tet_frame(&self, frame: &TetFrame, stats: &mut ExportStats) -> Result<(), ExportError> {
        let surface = self.tets.get(&frame.mesh).ok_or_else(|| ExportError::MissingTopology {
            mesh: format!("tet mesh {:?}", frame.mesh),
            frame: frame.frame,
        })?;
        let stream = format!("tet mesh {:?}", frame.mesh);
        self.write_surface(&stream, &frame.mesh, frame.frame, &frame.positions_m, surface)?;
        stats.count_file(&format!("/tet/{}", frame.mesh));
        Ok(())
    }

    /// Writes `<name>_<frame>.obj|ply` with the positions of one frame and its surface's faces.
    fn write_surface(
        &self,
        stream: &str,
        name: &str,
        frame: u64,
        positions: &[[f64; 3]],
        surface: &Surface,
    ) -> Result<(), ExportError> {
        check_vertex_count(positions, surface.vertex_count)
            .map_err(|problem| ExportError::frame(stream, frame, problem))?;
        let path = self.path_of(name, frame);
        write_atomically(&path, |out| match self.format {
            FrameFormat::Obj => obj::write_obj(out, positions, &surface.texcoords, &surface.triangles),
            FrameFormat::Ply => ply::write_ply(out, positions, &surface.triangles),
        })
    }

    fn write_yarn_frame(&self, frame: &YarnFrame, stats: &mut ExportStats) -> Result<(), ExportError> {
        check_yarn_frame(frame).map_err(|problem| {
            ExportError::frame(&format!("yarns {:?}", frame.yarns), frame.frame, problem)
        })?;
        let path = self.path_of(&frame.yarns, frame.frame);
        write_atomically(&path, |out| match self.format {
            FrameFormat::Obj => obj::write_obj_polylines(out, &frame.positions_m, &frame.yarn_ranges),
            FrameFormat::Ply => {
                ply::write_ply_polylines(out, &frame.positions_m, &frame.radii_m, &frame.yarn_ranges)
            }
        })?;
        stats.count_file(&format!("/yarns/{}", frame.yarns));
        Ok(())
    }

    /// `<dir>/<name>_<frame:06>.<ext>`.
    fn path_of(&self, name: &str, frame: u64) -> PathBuf {
        self.dir.join(format!("{}_{frame:06}.{}", file_stem(name), self.format.extension()))
    }
}

/// Writes a file atomically ([`AtomicFile`]): a failed write leaves no partial file.
fn write_atomically(
    path: &Path,
    fill: impl FnOnce(&mut AtomicFile) -> io::Result<()>,
) -> Result<(), ExportError> {
    let written = AtomicFile::create(path).and_then(|mut file| {
        fill(&mut file)?;
        file.commit()
    });
    written.map_err(|error| ExportError::Write { path: path.to_path_buf(), error })
}
