//! The one way yarnhom writes a file: into a temporary file beside the destination, flushed and
//! synced, given the permissions of the file it replaces (or `0644`), then renamed over it.
//!
//! A reader never sees a half-written file, a crash or an error leaves the destination as it
//! was, and no temporary file is left behind. Every writer of yarnhom goes through here:
//! artifacts, traces, HDF5 exports, OBJ/PLY frames, JSON reports, figures.

use std::fs::File;
use std::io::{self, BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use tempfile::NamedTempFile;

/// A file being written atomically: write (and seek) into it, then [`commit`](Self::commit).
/// Dropping it without a commit removes the temporary file and leaves the destination as it was.
#[derive(Debug)]
pub struct AtomicFile {
    /// `None` once committed.
    temp: Option<BufWriter<NamedTempFile>>,
    temp_path: PathBuf,
    destination: PathBuf,
}

impl AtomicFile {
    /// Starts writing `destination`: a hidden temporary file `.NAME.XXXXXX.tmp` in its folder.
    pub fn create(destination: impl AsRef<Path>) -> io::Result<Self> {
        let destination = destination.as_ref().to_path_buf();
        let name = destination.file_name().ok_or_else(|| {
            io::Error::new(io::ErrorKind::InvalidInput, format!("{} has no file name", destination.display()))
        })?;
        let temp = tempfile::Builder::new()
            .prefix(&format!(".{}.", name.to_string_lossy()))
            .suffix(".tmp")
            .tempfile_in(folder_of(&destination))?;
        let temp_path = temp.path().to_path_buf();
        Ok(Self { temp: Some(BufWriter::new(temp)), temp_path, destination })
    }

    /// The temporary file's path, for libraries that write a file by its name (HDF5): they
    /// write there, and [`commit`](Self::commit) moves what they wrote into place.
    pub fn temp_path(&self) -> &Path {
        &self.temp_path
    }

    /// The file this becomes.
    pub fn destination(&self) -> &Path {
        &self.destination
    }

    /// Whether the file has been moved into place.
    pub fn is_committed(&self) -> bool {
        self.temp.is_none()
    }

    /// Flushes and syncs the file, gives it the mode of the file it replaces, renames it into
    /// place and (best effort: some file systems refuse) syncs the folder, so the rename is
    /// durable too. Writing after a commit is an error.
    pub fn commit(&mut self) -> io::Result<()> {
        let temp = self.temp.take().ok_or_else(already_committed)?;
        let temp = temp.into_inner().map_err(io::IntoInnerError::into_error)?;
        temp.as_file().sync_all()?;
        keep_mode(temp.as_file(), &self.destination)?;
        temp.persist(&self.destination).map_err(|e| e.error)?;
        if let Ok(folder) = File::open(folder_of(&self.destination)) {
            let _ = folder.sync_all();
        }
        Ok(())
    }

    fn temp(&mut self) -> io::Result<&mut BufWriter<NamedTempFile>> {
        self.temp.as_mut().ok_or_else(already_committed)
    }
}

fn already_committed() -> io::Error {
    io::Error::other("the file is already committed")
}

/// The folder a file is in (`.` for a bare name).
fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Gives `file` the permissions of the file at `destination` it is about to replace, or `0644`
/// (the temporary file starts as `0600`).
#[cfg(unix)]
fn keep_mode(file: &File, destination: &Path) -> io::Result<()> {
    use std::os::unix::fs::PermissionsExt;
    let mode = std::fs::metadata(destination).map_or(0o644, |m| m.permissions().mode());
    file.set_permissions(std::fs::Permissions::from_mode(mode))
}

#[cfg(not(unix))]
fn keep_mode(_: &File, _: &Path) -> io::Result<()> {
    Ok(())
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.temp()?.write(buf)
    }
    fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
        self.temp()?.write_all(buf)
    }
    fn flush(&mut self) -> io::Result<()> {
        self.temp.as_mut().map_or(Ok(()), Write::flush)
    }
}

impl Seek for AtomicFile {
    fn seek(&mut self, pos: SeekFrom) -> io::Result<u64> {
        self.temp()?.seek(pos)
    }
    fn stream_position(&mut self) -> io::Result<u64> {
        self.temp()?.stream_position()
    }
}

/// Writes `bytes` to `path` atomically.
pub fn write_atomic(path: impl AsRef<Path>, bytes: impl AsRef<[u8]>) -> io::Result<()> {
    let mut file = AtomicFile::create(path)?;
    file.write_all(bytes.as_ref())?;
    file.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .expect("list")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn a_file_appears_whole_on_commit_and_keeps_the_mode_it_replaces() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().expect("dir");
        let path = dir.path().join("out.txt");
        std::fs::write(&path, "old").expect("old");
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o640)).expect("mode");
        let mut file = AtomicFile::create(&path).expect("create");
        file.write_all(b"new contents").expect("write");
        assert_eq!(std::fs::read_to_string(&path).expect("read"), "old", "nothing visible before commit");
        file.commit().expect("commit");
        assert_eq!(std::fs::read_to_string(&path).expect("read"), "new contents");
        assert_eq!(std::fs::metadata(&path).expect("meta").permissions().mode() & 0o777, 0o640);
        assert_eq!(names(dir.path()), ["out.txt"], "no temporary file left");
        assert!(file.write_all(b"more").is_err(), "a committed file takes no more bytes");
    }

    #[test]
    fn a_dropped_file_leaves_the_destination_and_no_temporary_file() {
        let dir = tempfile::tempdir().expect("dir");
        let path = dir.path().join("kept.bin");
        write_atomic(&path, b"first").expect("write");
        let mut file = AtomicFile::create(&path).expect("create");
        file.write_all(b"abandoned").expect("write");
        drop(file);
        assert_eq!(std::fs::read(&path).expect("read"), b"first");
        assert_eq!(names(dir.path()), ["kept.bin"]);
    }

    #[test]
    fn a_new_file_gets_mode_0644() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().expect("dir");
        let path = dir.path().join("new.json");
        write_atomic(&path, "{}").expect("write");
        assert_eq!(std::fs::metadata(&path).expect("meta").permissions().mode() & 0o777, 0o644);
    }
}
