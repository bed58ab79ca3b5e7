//! Reading input files with a bound decided before reading, and writing files
//! so that they appear whole or not at all.
//!
//! Every file the crate reads goes through [`read_announced`] (a binary
//! format whose header says how long the file is: `.hair`, `.tfx`) or
//! [`read_capped`] (text formats: OBJ meshes, TOML parameter files), so that a
//! wrong path — a device such as `/dev/zero`, a FIFO, a huge file — gives an
//! error naming the file and the cap instead of exhausting memory.

use std::fs::File;
use std::io::{Read, Write};
use std::os::unix::fs::PermissionsExt;
use std::path::Path;

use crate::error::{Error, Result};

/// The environment variable that sets the cap (bytes) on input files with no
/// header to bound them (OBJ meshes, TOML parameter files, the tool's CSVs),
/// for a real file larger than the defaults.
pub const MAX_INPUT_ENV: &str = "VKHAIR_MAX_INPUT_BYTES";

/// The cap on a headerless input whose default cap is `default`: the value of
/// [`MAX_INPUT_ENV`] when set (a whole number of bytes), else `default`.
pub fn input_cap(default: u64) -> Result<u64> {
    match std::env::var_os(MAX_INPUT_ENV) {
        None => Ok(default),
        Some(value) => value.to_str().and_then(|v| v.trim().parse::<u64>().ok()).filter(|&v| v > 0).ok_or_else(|| {
            Error::param("VKHAIR_MAX_INPUT_BYTES", value.to_string_lossy(), "a whole number of bytes above 0")
        }),
    }
}

/// How long an input that is not a regular file (a FIFO, a device) may go
/// without giving a byte before it is refused: a FIFO whose writer holds it
/// open and writes nothing had the reader wait for as long as the writer
/// lived.
pub const INPUT_STALL: std::time::Duration = std::time::Duration::from_secs(10);

/// An input file: a regular file read as it is, or a stream (a FIFO, a
/// device) each of whose reads waits at most `stall` for data.
enum Input {
    Regular(File),
    Stream { file: File, stall: std::time::Duration },
}

impl Read for Input {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        match self {
            Input::Regular(file) => file.read(buf),
            Input::Stream { file, stall } => loop {
                // Non-blocking: data, the end (no writer, or the writer gone),
                // or nothing yet, when it waits for data at most `stall`.
                match file.read(buf) {
                    Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {}
                    other => return other,
                }
                use std::os::fd::AsRawFd;
                let mut fd = libc::pollfd { fd: file.as_raw_fd(), events: libc::POLLIN, revents: 0 };
                let ms = libc::c_int::try_from(stall.as_millis()).unwrap_or(libc::c_int::MAX);
                // SAFETY: poll on one descriptor this reader owns, for `ms`.
                let ready = unsafe { libc::poll(&mut fd, 1, ms) };
                if ready == 0 {
                    return Err(std::io::Error::new(
                        std::io::ErrorKind::TimedOut,
                        format!(
                            "not a regular file, and it gave no data for {} s (a FIFO whose writer has stopped writing)",
                            stall.as_secs_f32()
                        ),
                    ));
                }
                if ready < 0 {
                    let e = std::io::Error::last_os_error();
                    if e.kind() != std::io::ErrorKind::Interrupted {
                        return Err(e);
                    }
                }
            },
        }
    }
}

fn open_input(path: &Path) -> Result<(Input, Option<u64>)> {
    open_input_within(path, INPUT_STALL)
}

fn open_input_within(path: &Path, stall: std::time::Duration) -> Result<(Input, Option<u64>)> {
    use std::os::unix::fs::OpenOptionsExt;
    let io = |source| Error::Io { path: path.into(), source };
    // Opened without blocking: a FIFO no process writes to reads as empty
    // instead of blocking forever. A regular file's reads then block as
    // usual; a stream's stay non-blocking, each waiting for data by `poll`.
    let file = std::fs::OpenOptions::new().read(true).custom_flags(libc::O_NONBLOCK).open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    if meta.is_dir() {
        return Err(Error::Io { path: path.into(), source: std::io::Error::other("a folder, not a file") });
    }
    if !meta.is_file() {
        // Devices and FIFOs have no length to trust.
        return Ok((Input::Stream { file, stall }, None));
    }
    {
        use std::os::fd::AsRawFd;
        let fd = file.as_raw_fd();
        // SAFETY: fcntl on a descriptor this function owns; clears O_NONBLOCK.
        let cleared = unsafe {
            let flags = libc::fcntl(fd, libc::F_GETFL);
            flags >= 0 && libc::fcntl(fd, libc::F_SETFL, flags & !libc::O_NONBLOCK) == 0
        };
        if !cleared {
            return Err(io(std::io::Error::last_os_error()));
        }
    }
    Ok((Input::Regular(file), Some(meta.len())))
}

/// Reads all of `path`, a `what` of at most `cap` bytes: a regular file larger
/// than `cap` is refused before reading, and anything else (a device, a FIFO)
/// is read up to `cap` bytes and refused beyond, and refused when a read
/// waits [`INPUT_STALL`] for data.
pub fn read_capped(path: &Path, cap: u64, what: &'static str) -> Result<Vec<u8>> {
    read_capped_within(path, cap, what, INPUT_STALL)
}

/// [`read_capped`], a stream's reads each waiting at most `stall`.
fn read_capped_within(path: &Path, cap: u64, what: &'static str, stall: std::time::Duration) -> Result<Vec<u8>> {
    let too_large = || Error::InputTooLarge {
        path: path.into(),
        what,
        cap,
        hint: " (set VKHAIR_MAX_INPUT_BYTES to read a larger one)",
    };
    let (file, len) = open_input_within(path, stall)?;
    if len.is_some_and(|len| len > cap) {
        return Err(too_large());
    }
    let mut data = Vec::new();
    file.take(cap.saturating_add(1))
        .read_to_end(&mut data)
        .map_err(|source| Error::Io { path: path.into(), source })?;
    if data.len() as u64 > cap {
        return Err(too_large());
    }
    Ok(data)
}

/// Checks that `path` is a regular file, a `what` of at most `cap` bytes, for
/// a reader that opens the file itself (a USD stage): a device or a FIFO is
/// refused, since nothing bounds what such a reader would take from it.
pub fn check_regular(path: &Path, cap: u64, what: &'static str) -> Result<()> {
    let (_, len) = open_input(path)?;
    match len {
        None => Err(Error::Io {
            path: path.into(),
            source: std::io::Error::other(format!("not a regular file; {what} must be one")),
        }),
        Some(len) if len > cap => Err(Error::InputTooLarge {
            path: path.into(),
            what,
            cap,
            hint: " (set VKHAIR_MAX_INPUT_BYTES to read a larger one)",
        }),
        Some(_) => Ok(()),
    }
}

/// Reads the `header_len`-byte header of `path`, then at most the length in
/// bytes that `announced` computes from it (header included), which refuses a
/// header that is not the format's or announces more than its limits allow.
/// A file shorter than its header or its announced length is returned as it
/// is (the parser reports the truncation); bytes after the announced length
/// are not read.
pub fn read_announced(path: &Path, header_len: u64, announced: impl FnOnce(&[u8]) -> Result<u64>) -> Result<Vec<u8>> {
    let io = |source| Error::Io { path: path.into(), source };
    let (file, _) = open_input(path)?;
    let mut reader = file.take(header_len);
    let mut data = Vec::new();
    reader.read_to_end(&mut data).map_err(io)?;
    if (data.len() as u64) < header_len {
        return Ok(data);
    }
    let total = announced(&data).map_err(|e| e.in_asset(path))?;
    let mut rest = reader.into_inner().take(total.saturating_sub(header_len));
    rest.read_to_end(&mut data).map_err(io)?;
    Ok(data)
}

/// Temporary files being written by [`write_atomic`] in this process.
static IN_PROGRESS: std::sync::Mutex<Vec<std::path::PathBuf>> = std::sync::Mutex::new(Vec::new());

/// Removes the temporary files of every [`write_atomic`] in progress in this
/// process, then runs `then` with their count while no new one can start: for
/// a program about to exit on a signal (`then` exits), so that no
/// `.NAME.*.partial` file stays behind.
pub fn remove_partial_files_then<R>(then: impl FnOnce(usize) -> R) -> R {
    let mut files = IN_PROGRESS.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    let n = files.len();
    for path in files.drain(..) {
        let _ = std::fs::remove_file(path);
    }
    then(n)
}

/// Stack of the thread a third-party reader runs on ([`read_guarded`]): 256
/// MiB, reserved, not committed; deep enough for any nesting the readers'
/// own depth checks let through.
pub const READER_STACK_BYTES: usize = 256 << 20;

thread_local! {
    /// Whether this thread runs a guarded reader, whose panics are reported
    /// as errors rather than printed.
    static GUARDED: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Runs `read` — a third-party reader that may panic on a malformed file —
/// on its own thread with a [`READER_STACK_BYTES`] stack; a panic becomes
/// `Err` with its message, printed nowhere (the process's panic hook is
/// wrapped once so that it stays silent for guarded threads and prints as
/// before for every other thread).
pub fn read_guarded<T: Send>(read: impl FnOnce() -> T + Send) -> std::result::Result<T, String> {
    static HOOK: std::sync::Once = std::sync::Once::new();
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !GUARDED.with(std::cell::Cell::get) {
                previous(info);
            }
        }));
    });
    let message = |panic: Box<dyn std::any::Any + Send>| {
        panic
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "a panic without a message".into())
    };
    std::thread::scope(|scope| {
        let worker = std::thread::Builder::new()
            .name("vkhair reader".into())
            .stack_size(READER_STACK_BYTES)
            .spawn_scoped(scope, || {
                GUARDED.with(|g| g.set(true));
                read()
            })
            .map_err(|e| format!("the reader's thread could not start: {e}"))?;
        worker.join().map_err(message)
    })
}

/// Outputs opened before their write ([`hold_fifo_output`]): path and file.
static HELD: std::sync::Mutex<Vec<(std::path::PathBuf, File)>> = std::sync::Mutex::new(Vec::new());

/// The file [`hold_fifo_output`] opened for `path`, if any (taken: the write
/// closes it).
fn take_held(path: &Path) -> Option<File> {
    let mut held = HELD.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    let k = held.iter().position(|(p, _)| p == path)?;
    Some(held.swap_remove(k).1)
}

fn is_fifo(path: &Path) -> bool {
    use std::os::unix::fs::FileTypeExt;
    std::fs::metadata(path).is_ok_and(|m| m.file_type().is_fifo())
}

/// `path`, a FIFO, opened for writing without waiting for a reader: refused
/// ([`Error::OutputRefused`]) when no process reads it, which would block the
/// write forever; the file returned blocks on a full pipe as any write does.
fn open_fifo_for_writing(path: &Path) -> Result<File> {
    use std::os::fd::AsRawFd;
    use std::os::unix::fs::OpenOptionsExt;
    let file =
        std::fs::OpenOptions::new().write(true).custom_flags(libc::O_NONBLOCK).open(path).map_err(|e| {
            match e.raw_os_error() {
                Some(libc::ENXIO) => {
                    Error::OutputRefused { path: path.into(), reason: "no process reads this FIFO".into() }
                }
                _ => Error::Io { path: path.into(), source: e },
            }
        })?;
    let fd = file.as_raw_fd();
    // SAFETY: fcntl on a descriptor this function owns, reading then clearing
    // one status flag.
    let cleared = unsafe {
        let flags = libc::fcntl(fd, libc::F_GETFL);
        flags >= 0 && libc::fcntl(fd, libc::F_SETFL, flags & !libc::O_NONBLOCK) == 0
    };
    if !cleared {
        return Err(Error::Io { path: path.into(), source: std::io::Error::last_os_error() });
    }
    Ok(file)
}

/// Opens the FIFO at `path` for writing now and keeps it open until
/// [`write_atomic`] writes to it: a run checks at its start that a process
/// reads its output, and that reader, holding the other end, does not see
/// the stream end before the write (a reader that reads once would otherwise
/// take a probe's open and close for the whole output, and the real write
/// would wait for a reader forever). Refused ([`Error::OutputRefused`]) where
/// no process reads it; a `path` that is not a FIFO is left alone.
pub fn hold_fifo_output(path: &Path) -> Result<()> {
    if !is_fifo(path) {
        return Ok(());
    }
    let file = open_fifo_for_writing(path)?;
    HELD.lock().unwrap_or_else(|poisoned| poisoned.into_inner()).push((path.to_path_buf(), file));
    Ok(())
}

/// Writes `bytes` to `file` (a pipe, a device) with SIGPIPE blocked on this
/// thread: a reader that closes a pipe before the output is written makes
/// the write an error naming that, not a signal that ends the process
/// without a word (the signal the write raised is taken before SIGPIPE is
/// unblocked).
fn write_without_sigpipe(file: &mut std::fs::File, bytes: &[u8]) -> std::io::Result<()> {
    // SAFETY: plain libc calls on a local signal set; the mask is this
    // thread's and is restored before returning.
    unsafe {
        let mut pipe: libc::sigset_t = std::mem::zeroed();
        let mut old: libc::sigset_t = std::mem::zeroed();
        libc::sigemptyset(&mut pipe);
        libc::sigaddset(&mut pipe, libc::SIGPIPE);
        libc::pthread_sigmask(libc::SIG_BLOCK, &pipe, &mut old);
        let written = file.write_all(bytes).and_then(|_| file.flush());
        if written.as_ref().is_err_and(|e| e.kind() == std::io::ErrorKind::BrokenPipe) {
            let now = libc::timespec { tv_sec: 0, tv_nsec: 0 };
            libc::sigtimedwait(&pipe, std::ptr::null_mut(), &now);
        }
        libc::pthread_sigmask(libc::SIG_SETMASK, &old, std::ptr::null_mut());
        written.map_err(|e| match e.kind() {
            std::io::ErrorKind::BrokenPipe => std::io::Error::new(
                e.kind(),
                "the process reading this pipe closed it before the whole output was written",
            ),
            _ => e,
        })
    }
}

/// Writes `bytes` to `path` through a temporary file in the same folder that then
/// replaces `path`: a failed write, a full disk or a killed process leaves either
/// the old file or none, never a truncated one (a process that handles its
/// signals removes the temporary file with [`remove_partial_files_then`]). The error
/// names `path`.
///
/// A symbolic link in `path`'s place is never followed to a file: the write is
/// refused ([`Error::OutputRefused`]), since replacing the link's target
/// could clobber a file the caller never named. A `path` that is not a regular
/// file, or a link to one that is not (`/dev/stdout`, a pipe, a device), is
/// written in place, since it cannot be replaced.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let io = |source| Error::Io { path: path.into(), source };
    let special = |p: &Path| std::fs::metadata(p).is_ok_and(|m| !m.is_file() && !m.is_dir());
    match std::fs::symlink_metadata(path) {
        Ok(m) if m.file_type().is_symlink() && !special(path) => {
            let target = std::fs::read_link(path).map(|t| t.display().to_string()).unwrap_or_default();
            return Err(Error::OutputRefused {
                path: path.into(),
                reason: format!(
                    "a symbolic link (to {target}) is in its place; vkhair does not write through links to files \
                     (remove the link or choose another path)"
                ),
            });
        }
        Ok(_) if special(path) => {
            let held = take_held(path);
            let mut file = match held {
                Some(file) => file,
                None if is_fifo(path) => open_fifo_for_writing(path)?,
                None => std::fs::OpenOptions::new().write(true).open(path).map_err(io)?,
            };
            return write_without_sigpipe(&mut file, bytes).map_err(io);
        }
        _ => {}
    }
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
    // Made and registered under the lock, so that a signal's clean-up
    // (remove_partial_files_then) either removes it or runs before it exists.
    let (mut file, partial) = {
        let mut in_progress = IN_PROGRESS.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        let file = tempfile::Builder::new()
            .prefix(&format!(".{name}."))
            .suffix(".partial")
            .permissions(permissions)
            .tempfile_in(dir)
            .map_err(io)?;
        let partial = file.path().to_path_buf();
        in_progress.push(partial.clone());
        (file, partial)
    };
    let written = file
        .write_all(bytes)
        .and_then(|_| file.as_file().sync_all())
        .map_err(io)
        .and_then(|_| file.persist(path).map(drop).map_err(|e| io(e.error)));
    IN_PROGRESS.lock().unwrap_or_else(|poisoned| poisoned.into_inner()).retain(|p| *p != partial);
    written
}

#[cfg(test)]
mod tests {
    /// A reader that opens a FIFO output and closes it before the write: the
    /// write is an error naming that, and the process lives on (SIGPIPE, at
    /// its default disposition as the tool sets it, would have ended it).
    #[test]
    fn a_pipe_closed_before_the_write_is_an_error_not_a_signal() {
        use std::os::unix::fs::OpenOptionsExt;
        let dir = tempfile::tempdir().expect("tempdir");
        let fifo = dir.path().join("out.json");
        let c = std::ffi::CString::new(fifo.to_str().expect("utf-8")).expect("path");
        // SAFETY: valid NUL-terminated path; signal() with the default disposition.
        unsafe {
            assert_eq!(libc::mkfifo(c.as_ptr(), 0o600), 0, "mkfifo");
            libc::signal(libc::SIGPIPE, libc::SIG_DFL);
        }
        let reader = std::fs::OpenOptions::new().read(true).custom_flags(libc::O_NONBLOCK).open(&fifo).expect("reader");
        super::hold_fifo_output(&fifo).expect("a reader is there");
        drop(reader);
        let e = super::write_atomic(&fifo, &[7u8; 1 << 20]).expect_err("the reader is gone").to_string();
        // SAFETY: back to the disposition Rust's runtime gives tests.
        unsafe { libc::signal(libc::SIGPIPE, libc::SIG_IGN) };
        assert!(e.contains("out.json") && e.contains("closed it before the whole output"), "{e}");
    }

    /// A FIFO whose writer holds it open and writes nothing is refused once
    /// a read has waited its deadline (it had the reader wait as long as the
    /// writer lived); one whose writer writes slowly, each piece within the
    /// deadline, reads whole.
    #[test]
    fn a_stream_that_gives_no_data_is_refused_after_its_deadline() {
        let dir = tempfile::tempdir().expect("tempdir");
        let fifo = dir.path().join("in.hair");
        let c = std::ffi::CString::new(fifo.to_str().expect("utf-8")).expect("path");
        // SAFETY: valid NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0, "mkfifo");
        let stall = std::time::Duration::from_millis(300);
        let writer = |pieces: Vec<&'static [u8]>, pause: std::time::Duration| {
            let fifo = fifo.clone();
            std::thread::spawn(move || {
                let mut file = std::fs::OpenOptions::new().write(true).open(&fifo).expect("writer");
                for piece in pieces {
                    std::thread::sleep(pause);
                    file.write_all(piece).expect("write");
                }
                std::thread::sleep(pause);
            })
        };
        // Silent for 3 deadlines, then gone.
        let silent = writer(vec![], 3 * stall);
        std::thread::sleep(stall / 3);
        let start = std::time::Instant::now();
        let e = super::read_capped_within(&fifo, 1 << 20, "a groom", stall).expect_err("no data").to_string();
        assert!(e.contains("in.hair") && e.contains("gave no data for 0.3 s"), "{e}");
        assert!(start.elapsed() < 2 * stall, "refused after {:?}", start.elapsed());
        silent.join().expect("writer");
        // Three pieces, each after half a deadline.
        let slow = writer(vec![b"ab", b"cd", b"ef"], stall / 2);
        std::thread::sleep(stall / 3);
        let data = super::read_capped_within(&fifo, 1 << 20, "a groom", stall).expect("read whole");
        assert_eq!(data, b"abcdef");
        slow.join().expect("writer");
    }

    use super::*;

    /// A panic inside a guarded reader is its error (the message the panic
    /// carried), and a reader that returns is its value.
    #[test]
    fn a_guarded_readers_panic_is_its_error() {
        let stopped = read_guarded(|| -> u32 { panic!("index out of bounds: the len is 3 but the index is 7") });
        assert_eq!(stopped, Err("index out of bounds: the len is 3 but the index is 7".to_owned()));
        let message = format!("{} is {}", "a formatted", "message");
        assert_eq!(read_guarded(move || -> u32 { panic!("{message}") }), Err("a formatted is message".to_owned()));
        assert_eq!(read_guarded(|| 42u32), Ok(42));
    }

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

    /// A link planted in an output's place (`out/frame_0000.png -> ../victim`)
    /// is refused, and neither the link nor its target changes; a dangling
    /// link too. A link to a device (`/dev/stdout` is one) is written through.
    #[test]
    fn a_link_in_the_outputs_place_is_refused_not_followed() {
        let dir = tempfile::tempdir().expect("temp dir");
        let victim = dir.path().join("victim.txt");
        let link = dir.path().join("frame_0000.png");
        std::fs::write(&victim, b"precious").expect("write");
        std::os::unix::fs::symlink(&victim, &link).expect("link");
        let err = write_atomic(&link, b"png bytes").expect_err("a link to a file");
        assert!(matches!(err, Error::OutputRefused { .. }), "{err}");
        assert!(err.to_string().contains("symbolic link"), "{err}");
        assert_eq!(std::fs::read(&victim).expect("read"), b"precious");
        assert!(std::fs::symlink_metadata(&link).expect("link").file_type().is_symlink());
        let dangling = dir.path().join("dangling.json");
        std::os::unix::fs::symlink(dir.path().join("nowhere"), &dangling).expect("link");
        assert!(matches!(write_atomic(&dangling, b"{}"), Err(Error::OutputRefused { .. })));
        assert!(!dir.path().join("nowhere").exists());
        let null_link = dir.path().join("null");
        std::os::unix::fs::symlink("/dev/null", &null_link).expect("link");
        write_atomic(&null_link, b"discarded").expect("a link to a device is written through");
        let leftovers = std::fs::read_dir(dir.path()).expect("list").filter_map(|e| e.ok());
        assert!(leftovers.map(|e| e.file_name()).all(|n| !n.to_string_lossy().ends_with(".partial")));
    }

    /// Reads are bounded: a regular file over the cap is refused before reading,
    /// a device is read up to the cap, a header-bounded read stops at what the
    /// header announces.
    #[test]
    fn reads_stop_at_their_bound() {
        let dir = tempfile::tempdir().expect("temp dir");
        let big = dir.path().join("big.obj");
        std::fs::write(&big, vec![b'#'; 1000]).expect("write");
        let err = read_capped(&big, 999, "an OBJ mesh").expect_err("over the cap");
        assert!(matches!(err, Error::InputTooLarge { cap: 999, .. }), "{err}");
        assert!(err.to_string().contains("big.obj") && err.to_string().contains("VKHAIR_MAX_INPUT_BYTES"), "{err}");
        assert_eq!(read_capped(&big, 1000, "an OBJ mesh").expect("at the cap").len(), 1000);
        if Path::new("/dev/zero").exists() {
            let err = read_capped(Path::new("/dev/zero"), 4096, "an OBJ mesh").expect_err("an endless device");
            assert!(matches!(err, Error::InputTooLarge { .. }), "{err}");
            let data = read_announced(Path::new("/dev/zero"), 16, |_| Ok(100)).expect("bounded by the header");
            assert_eq!(data.len(), 100);
            let refused = read_announced(Path::new("/dev/zero"), 16, |_| Err(Error::EmptyGroom));
            assert!(refused.expect_err("refused header").to_string().contains("/dev/zero"));
        } else {
            eprintln!("SKIPPED the device half: this system has no /dev/zero");
        }
        let short = dir.path().join("short.hair");
        std::fs::write(&short, b"HAI").expect("write");
        assert_eq!(read_announced(&short, 128, |_| panic!("no header to read")).expect("short").len(), 3);
        assert!(read_capped(dir.path(), 10, "a folder").is_err());
    }
}
