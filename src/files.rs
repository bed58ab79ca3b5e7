//! Writing files so that they appear whole or not at all.

use std::io::Write;
use std::os::unix::fs::PermissionsExt;
use std::path::Path;

use crate::error::{Error, Result};

/// Writes `bytes` to `path` through a temporary file in the same folder that then
/// replaces `path`: a failed write, a full disk or a killed process leaves either
/// the old file or none, never a truncated one. The error names `path`.
///
/// A `path` that is a symbolic link has its target replaced (the link stays); one
/// that is not a regular file (`/dev/stdout`, a pipe, a device) is written in place,
/// since it cannot be replaced.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let io = |source| Error::Io { path: path.into(), source };
    let resolved = match std::fs::canonicalize(path) {
        Ok(target) => target,
        Err(_) => path.to_path_buf(), // not there yet (or a dangling link: replaced)
    };
    if resolved.exists() && !resolved.is_file() {
        let mut file = std::fs::OpenOptions::new().write(true).open(&resolved).map_err(io)?;
        file.write_all(bytes).map_err(io)?;
        return file.flush().map_err(io);
    }
    let path_buf = resolved;
    let path = path_buf.as_path();
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    // The new file gets the old one's permissions, or those of any new file (the
    // process's umask applied), not the temporary file's private 0600.
    let permissions = match std::fs::metadata(path) {
        Ok(old) => old.permissions(),
        Err(_) => std::fs::Permissions::from_mode(0o666),
    };
    let mut file = tempfile::Builder::new()
        .prefix(&format!(".{name}."))
        .suffix(".partial")
        .permissions(permissions)
        .tempfile_in(dir)
        .map_err(io)?;
    file.write_all(bytes).map_err(io)?;
    file.as_file().sync_all().map_err(io)?;
    file.persist(path).map_err(|e| io(e.error))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_whole_files_and_names_the_path_on_failure() {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("a.bin");
        write_atomic(&path, b"first").expect("write");
        write_atomic(&path, b"second, longer").expect("replace");
        assert_eq!(std::fs::read(&path).expect("read"), b"second, longer");
        let leftovers: Vec<_> = std::fs::read_dir(dir.path()).expect("list").collect();
        assert_eq!(leftovers.len(), 1, "no temporary file is left behind");
        let missing = dir.path().join("no such folder").join("b.bin");
        let err = write_atomic(&missing, b"x").expect_err("no folder");
        assert!(err.to_string().contains("no such folder"), "{err}");
        assert!(!missing.exists());
    }

    #[test]
    fn new_files_get_ordinary_permissions_and_old_ones_keep_theirs() {
        let dir = tempfile::tempdir().expect("temp dir");
        let plain = dir.path().join("plain.bin");
        std::fs::write(&plain, b"x").expect("write");
        let mode = |p: &Path| std::fs::metadata(p).expect("metadata").permissions().mode() & 0o777;
        let new = dir.path().join("new.bin");
        write_atomic(&new, b"x").expect("write");
        assert_eq!(mode(&new), mode(&plain), "a new file as std::fs::write makes it (umask applied)");
        std::fs::set_permissions(&new, std::fs::Permissions::from_mode(0o640)).expect("chmod");
        write_atomic(&new, b"y").expect("replace");
        assert_eq!(mode(&new), 0o640, "a replaced file keeps its permissions");
    }

    #[test]
    fn special_files_are_written_in_place_not_replaced() {
        let full = Path::new("/dev/full");
        if !full.exists() {
            eprintln!("SKIPPED: this system has no /dev/full");
            return;
        }
        let err = write_atomic(full, b"x").expect_err("a full device");
        assert!(err.to_string().contains("/dev/full"), "{err}");
        let kind = std::fs::metadata(full).expect("still there").file_type();
        assert!(!kind.is_file(), "/dev/full was replaced by a regular file");
    }

    #[test]
    fn a_link_keeps_pointing_at_the_new_contents() {
        let dir = tempfile::tempdir().expect("temp dir");
        let target = dir.path().join("target.bin");
        let link = dir.path().join("link.bin");
        std::fs::write(&target, b"old").expect("write");
        std::os::unix::fs::symlink(&target, &link).expect("link");
        write_atomic(&link, b"new").expect("write through the link");
        assert!(std::fs::symlink_metadata(&link).expect("link").file_type().is_symlink());
        assert_eq!(std::fs::read(&target).expect("read"), b"new");
    }
}
