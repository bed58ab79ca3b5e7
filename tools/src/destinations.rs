//! Where a command's outputs go, checked before any work: a run whose result
//! could not be written, or would clobber what it should not, stops before it
//! starts.
//!
//! - An output file is written as a file of one of the formats the flag
//!   writes (by extension), into a folder that exists and can be written, or
//!   to a pipe, a terminal or `/dev/null`; never to another device.
//! - A symbolic link in an output's place is refused (the files are written
//!   through `vkhair::files::write_atomic`, which refuses it too).
//! - No output is also an input of the run, and no two outputs share a path.
//! - An output folder the check creates is removed again, with the folders it
//!   created above it, if it is still empty when the returned [`Made`] is
//!   dropped: a run refused after the check leaves no folder it made.

use std::os::unix::fs::{FileTypeExt, MetadataExt};
use std::path::{Path, PathBuf};

use crate::output::Error;

/// What an output flag names.
pub enum Kind {
    /// A file in one of these formats (extensions, without the dot).
    File(&'static [&'static str]),
    /// A folder the command writes its files into (created when missing).
    Folder,
}

/// One output of a command: its flag, its path and what it names.
pub struct Output<'a> {
    pub flag: &'static str,
    pub path: &'a Path,
    pub kind: Kind,
}

/// The folders a [`check`] created, in the order it created them: each is
/// removed when this is dropped if it is empty then (a run that wrote into it
/// keeps it).
#[must_use = "the folders made are removed when this is dropped: hold it until the run ends"]
pub struct Made(Vec<PathBuf>);

impl Drop for Made {
    fn drop(&mut self) {
        // Deepest first; each fails, leaving the folder, when the run wrote into it.
        for folder in self.0.iter().rev() {
            let _ = std::fs::remove_dir(folder);
        }
    }
}

/// Checks `outputs` against each other, against `inputs` and against the file
/// system (see the module docs); creates a missing output folder, returning
/// what it made.
pub fn check(inputs: &[&Path], outputs: &[Output<'_>]) -> Result<Made, Error> {
    let mut made = Made(Vec::new());
    for (k, out) in outputs.iter().enumerate() {
        match out.kind {
            Kind::File(formats) => check_file(out, formats)?,
            Kind::Folder => check_folder(out, &mut made)?,
        }
        if let Some(input) = inputs.iter().find(|input| same_file(input, out.path)) {
            return Err(format!(
                "{} {}: the output is also this run's input {} (choose another path)",
                out.flag,
                out.path.display(),
                input.display()
            )
            .into());
        }
        if let Some(other) = outputs[..k].iter().find(|o| same_place(o.path, out.path)) {
            return Err(format!(
                "{} and {} both name {}: each output needs its own path",
                other.flag,
                out.flag,
                out.path.display()
            )
            .into());
        }
    }
    Ok(made)
}

fn check_file(out: &Output<'_>, formats: &[&str]) -> Result<(), Error> {
    let (flag, path) = (out.flag, out.path.display());
    let link = std::fs::symlink_metadata(out.path).is_ok_and(|m| m.file_type().is_symlink());
    match std::fs::metadata(out.path) {
        Ok(m) if m.is_dir() => return Err(format!("{flag} {path} is a folder, not a file").into()),
        Ok(m) if !m.is_file() => return writable_device(out, &m),
        _ if link => {
            let target = std::fs::read_link(out.path).map(|t| t.display().to_string()).unwrap_or_default();
            return Err(format!(
                "{flag} {path}: a symbolic link (to {target}) is in its place; vkhair does not write through \
                 links to files (remove the link or choose another path)"
            )
            .into());
        }
        _ => {}
    }
    let extension = out.path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if !extension.is_some_and(|e| formats.contains(&e.as_str())) {
        let names: Vec<String> = formats.iter().map(|f| format!(".{f}")).collect();
        return Err(format!(
            "{flag} {path}: vkhair writes {} files here (give the path that extension)",
            names.join(" or ")
        )
        .into());
    }
    let folder = match out.path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if !folder.is_dir() {
        return Err(format!("{flag} {path}: the folder {} does not exist", folder.display()).into());
    }
    probe_folder(flag, folder)
}

fn check_folder(out: &Output<'_>, made: &mut Made) -> Result<(), Error> {
    let (flag, path) = (out.flag, out.path.display());
    if std::fs::symlink_metadata(out.path).is_ok_and(|m| !m.is_dir() && !m.file_type().is_symlink()) {
        return Err(format!("{flag} {path} is a file, not a folder").into());
    }
    // Each prefix of the path in turn: only the folders this call creates are
    // recorded (one that exists, or that another process makes meanwhile, is not).
    let mut prefix = PathBuf::new();
    for part in out.path.components() {
        prefix.push(part);
        match std::fs::create_dir(&prefix) {
            Ok(()) => made.0.push(prefix.clone()),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists || prefix.is_dir() => {}
            Err(e) => return Err(format!("{flag}: cannot create {}: {e}", prefix.display()).into()),
        }
    }
    if !out.path.is_dir() {
        return Err(format!("{flag}: cannot create {path}: not a folder").into());
    }
    probe_folder(flag, out.path)
}

/// A temporary file made and removed in `folder`: it can be written.
fn probe_folder(flag: &str, folder: &Path) -> Result<(), Error> {
    tempfile::Builder::new()
        .prefix(".vkhair-probe.")
        .tempfile_in(folder)
        .map(drop)
        .map_err(|e| format!("{flag}: cannot write into {}: {e}", folder.display()).into())
}

/// A device in an output's place: a pipe with a reader, a terminal or the null
/// device are written to; anything else (`/dev/full`, a disk) is refused.
fn writable_device(out: &Output<'_>, meta: &std::fs::Metadata) -> Result<(), Error> {
    let (flag, path) = (out.flag, out.path.display());
    let kind = meta.file_type();
    if kind.is_fifo() {
        // Opened now and held until the write: a FIFO no process reads would
        // block the write forever, and opening and closing it would end a
        // reader that reads once before the output reaches it.
        return vkhair::files::hold_fifo_output(out.path)
            .map_err(|_| format!("{flag} {path}: no process reads this FIFO").into());
    }
    if kind.is_socket() {
        return Ok(());
    }
    let null = std::fs::metadata("/dev/null").is_ok_and(|n| n.rdev() == meta.rdev());
    let terminal = kind.is_char_device()
        && std::fs::OpenOptions::new().write(true).open(out.path).is_ok_and(|f| {
            use std::os::fd::AsRawFd;
            // SAFETY: isatty only reads the descriptor's state; the file is open.
            unsafe { libc::isatty(f.as_raw_fd()) == 1 }
        });
    if null || terminal {
        return Ok(());
    }
    Err(format!("{flag} {path} is a device vkhair does not write to (give a file, a pipe or a terminal)").into())
}

/// Whether `a` and `b` are the same existing file.
fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

/// Whether two outputs would land in the same place: the same file, or the
/// same absolute path for files not made yet.
fn same_place(a: &Path, b: &Path) -> bool {
    let absolute = |p: &Path| -> Option<PathBuf> { std::path::absolute(p).ok() };
    same_file(a, b) || absolute(a).is_some_and(|x| Some(x) == absolute(b))
}
