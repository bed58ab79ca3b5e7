//! Where the tool's output goes: standard output that a closed pipe or a full
//! disk cannot crash, PNG files written whole or not at all, and frames encoded
//! on a worker thread while the GPU renders the next ones.

use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::thread::JoinHandle;

use vkhair::files::write_atomic;

pub type Error = Box<dyn std::error::Error + Send + Sync>;

/// What a command returns: nothing, or the error `main` prints.
pub type CliResult = Result<(), Error>;

/// `println!` that never panics: a closed pipe ends the program as it does any
/// Unix tool (SIGPIPE, see [`restore_sigpipe`]); any other failure (a full disk)
/// is reported on stderr with exit status 1.
#[macro_export]
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let text = format!($($arg)*);
        if let Err(e) = writeln!(std::io::stdout(), "{}", $crate::output::printable(&text)) {
            $crate::output::stdout_failed(e);
        }
    }};
}

/// `eprintln!` of text that may hold names from files: control characters
/// other than line breaks and tabs are written escaped ([`printable`]).
#[macro_export]
macro_rules! say_err {
    ($($arg:tt)*) => {{
        let text = format!($($arg)*);
        eprintln!("{}", $crate::output::printable(&text));
    }};
}

/// `text` with every control character but line feeds and tabs written as an
/// escape (`\u{1b}`): a name read from a file (a USD prim, an Alembic object,
/// a path) cannot move the terminal's cursor, recolour it or retitle it.
pub fn printable(text: &str) -> std::borrow::Cow<'_, str> {
    let unsafe_char = |c: char| c.is_control() && c != '\n' && c != '\t';
    if !text.chars().any(unsafe_char) {
        return std::borrow::Cow::Borrowed(text);
    }
    text.chars()
        .map(|c| if unsafe_char(c) { c.escape_unicode().to_string() } else { c.to_string() })
        .collect::<String>()
        .into()
}

/// Ends the program after a failed write to standard output.
pub fn stdout_failed(e: std::io::Error) -> ! {
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        std::process::exit(141);
    }
    eprintln!("vkhair: standard output: {e}");
    std::process::exit(1)
}

/// Lets a write to a closed pipe end the program quietly, as with any Unix
/// tool (Rust's runtime ignores SIGPIPE and turns it into an error).
pub fn restore_sigpipe() {
    // SAFETY: setting a signal's disposition to the default has no preconditions;
    // it runs before any other thread exists.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// Keeps the process's memory flat however long a run is, without paying for
/// it every frame. Large allocations (frames, lavapipe's per-draw vertex
/// buffers) are mapped and unmapped instead of cut from the heap, where
/// glibc's growing threshold for that would leave them to fragment it a
/// little more every frame. Free memory at the top of a heap is kept up to
/// 64 MiB instead of glibc's 128 KiB: lavapipe's queue thread frees
/// tens of MB there after every frame, and handing them back only to fault
/// them in again the next frame cost up to a fifth of a frame, in some
/// processes and not others.
pub fn bound_heap_growth() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only sets the allocator's tuning; called before any
    // other thread exists.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 128 << 10);
        libc::mallopt(libc::M_TRIM_THRESHOLD, HEAP_TOP_KEPT);
    }
}

/// Free bytes at the top of a heap that glibc keeps rather than returns
/// (`M_TRIM_THRESHOLD`): above lavapipe's per-frame churn at 1280×720.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const HEAP_TOP_KEPT: i32 = 64 << 20;

/// On SIGINT or SIGTERM, removes the temporary files of the writes in progress
/// (no `.NAME.*.partial` stays behind; a file being replaced keeps its old
/// contents) and exits with the conventional status, 128 + the signal.
pub fn exit_cleanly_on_signals() {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let mut signals = match signal_hook::iterator::Signals::new([SIGINT, SIGTERM]) {
        Ok(signals) => signals,
        Err(e) => {
            say_err!("vkhair: warning: signals are not handled ({e}); an interrupted write may leave a .partial file");
            return;
        }
    };
    std::thread::spawn(move || {
        if let Some(signal) = signals.forever().next() {
            vkhair::files::remove_partial_files_then(|_| std::process::exit(128 + signal))
        }
    });
}

/// A progress bar over `len` `units` ("frames", "steps") with elapsed time and
/// ETA, on stderr (hidden when stderr is not a terminal).
pub fn progress(len: usize, units: &str) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(len as u64);
    let template = format!("{{bar:40}} {{pos}}/{{len}} {units} {{elapsed}} (eta {{eta}})");
    bar.set_style(
        indicatif::ProgressStyle::with_template(&template).unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar
}

/// Smallest image side the tool renders: below it neither the frames nor the
/// contact sheet (frames halved) would be useful images.
pub const MIN_IMAGE_SIDE: u32 = 16;
/// Largest image side the tool renders (the headless target's limit).
pub const MAX_IMAGE_SIDE: u32 = 8192;

/// An RGBA8 image as PNG bytes.
pub fn encode_png(width: u32, height: u32, rgba: &[u8]) -> Result<Vec<u8>, Error> {
    let mut bytes = Vec::new();
    let mut encoder = png::Encoder::new(&mut bytes, width, height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    encoder.write_header()?.write_image_data(rgba)?;
    Ok(bytes)
}

/// Writes an RGBA8 image as a PNG file, whole or not at all.
pub fn write_png(path: &Path, width: u32, height: u32, rgba: &[u8]) -> Result<(), Error> {
    write_atomic(path, &encode_png(width, height, rgba)?)?;
    Ok(())
}

/// Frames of the contact sheet: all of them up to 12, else 12 spread evenly.
pub fn sheet_picks(frames: usize) -> Vec<usize> {
    if frames <= 12 {
        (0..frames).collect()
    } else {
        (0..12).map(|i| i * (frames - 1) / 11).collect()
    }
}

/// An image halved in both directions (2 × 2 box filter).
fn halve(rgba: &[u8], width: u32, height: u32) -> Vec<u8> {
    let (tw, th) = (width / 2, height / 2);
    let mut out = vec![0u8; (tw * th * 4) as usize];
    for y in 0..th {
        for x in 0..tw {
            for c in 0..4 {
                let at = |dx: u32, dy: u32| u32::from(rgba[(((2 * y + dy) * width + 2 * x + dx) * 4 + c) as usize]);
                let v = (at(0, 0) + at(1, 0) + at(0, 1) + at(1, 1) + 2) / 4;
                out[((y * tw + x) * 4 + c) as usize] = v as u8;
            }
        }
    }
    out
}

/// The halved picks on a sheet of up to 4 columns.
fn sheet(thumbs: &[Vec<u8>], tw: u32, th: u32) -> (u32, u32, Vec<u8>) {
    let cols = 4u32.min(thumbs.len() as u32).max(1);
    let rows = (thumbs.len() as u32).div_ceil(cols).max(1);
    let (sw, sh) = (cols * tw, rows * th);
    let mut out = vec![0u8; (sw * sh * 4) as usize];
    for (k, thumb) in thumbs.iter().enumerate() {
        let (ox, oy) = ((k as u32 % cols) * tw, (k as u32 / cols) * th);
        for y in 0..th {
            let src = &thumb[(y * tw * 4) as usize..((y + 1) * tw * 4) as usize];
            let at = (((oy + y) * sw + ox) * 4) as usize;
            out[at..at + src.len()].copy_from_slice(src);
        }
    }
    (sw, sh, out)
}

/// Whether `name` is a file `render` writes: `frame_NNNN.png` (four digits or
/// more) or `contact_sheet.png`; the frame's index when it is a frame.
fn owned_name(name: &str) -> Option<Option<usize>> {
    if name == "contact_sheet.png" {
        return Some(None);
    }
    let digits = name.strip_prefix("frame_")?.strip_suffix(".png")?;
    (digits.len() >= 4 && digits.bytes().all(|b| b.is_ascii_digit())).then(|| digits.parse().ok())
}

/// Prepares `dir` for a run of `frames` frames: refuses when a file the run
/// writes (`frame_NNNN.png`, `contact_sheet.png`) is a symbolic link or not a
/// regular file (a folder in a frame's place is found before rendering), and
/// removes the frames of an earlier run that this one will not overwrite
/// (their index is `frames` or more), so that the folder holds one run. Only
/// those names are touched. Returns how many frames were removed.
pub fn clear_stale_frames(dir: &Path, frames: usize) -> Result<usize, Error> {
    let list = std::fs::read_dir(dir).map_err(|e| format!("cannot list {}: {e}", dir.display()))?;
    let mut stale = Vec::new();
    for entry in list {
        let entry = entry.map_err(|e| format!("cannot list {}: {e}", dir.display()))?;
        let name = entry.file_name().to_string_lossy().into_owned();
        let Some(index) = owned_name(&name) else { continue };
        let path = entry.path();
        if std::fs::symlink_metadata(&path).is_ok_and(|m| m.file_type().is_symlink()) {
            return Err(format!(
                "--out {}: {name} is a symbolic link; vkhair does not write through links (remove it)",
                dir.display()
            )
            .into());
        }
        let written = index.is_none_or(|i| i < frames);
        if written && std::fs::metadata(&path).is_ok_and(|m| !m.is_file()) {
            return Err(format!(
                "--out {}: {name} is in the place of a file this run writes but is not a file (a folder or a \
                 device); remove it or choose another folder",
                dir.display()
            )
            .into());
        }
        if !written {
            stale.push(path);
        }
    }
    for path in &stale {
        std::fs::remove_file(path).map_err(|e| format!("cannot remove {}: {e}", path.display()))?;
    }
    Ok(stale.len())
}

/// Writes frames as `frame_NNNN.png` on a worker thread and keeps only the
/// halved frames the contact sheet needs: memory does not grow with the frame
/// count. At most two frames wait for the worker; the renderer blocks beyond.
pub struct FrameSink {
    sender: Option<mpsc::SyncSender<(usize, Vec<u8>)>>,
    /// Frames' memory the worker is done with, for the next frames.
    recycled: mpsc::Receiver<Vec<u8>>,
    worker: Option<JoinHandle<Result<Vec<Vec<u8>>, Error>>>,
    width: u32,
    height: u32,
    dir: PathBuf,
}

impl FrameSink {
    /// A sink for `frames` frames of `width` × `height` into `dir`.
    pub fn new(dir: &Path, width: u32, height: u32, frames: usize) -> FrameSink {
        let (sender, receiver) = mpsc::sync_channel::<(usize, Vec<u8>)>(2);
        let (give_back, recycled) = mpsc::sync_channel::<Vec<u8>>(3);
        let picks = sheet_picks(frames);
        let out = dir.to_path_buf();
        let worker = std::thread::spawn(move || {
            let mut thumbs = Vec::new();
            for (index, rgba) in receiver {
                write_png(&out.join(format!("frame_{index:04}.png")), width, height, &rgba)?;
                if picks.contains(&index) {
                    thumbs.push(halve(&rgba, width, height));
                }
                let _ = give_back.try_send(rgba); // dropped when nobody takes it
            }
            Ok(thumbs)
        });
        FrameSink { sender: Some(sender), recycled, worker: Some(worker), width, height, dir: dir.to_path_buf() }
    }

    /// Memory for the next frame: a written frame's, or new.
    pub fn buffer(&self) -> Vec<u8> {
        self.recycled.try_recv().unwrap_or_default()
    }

    /// Hands frame `index` to the worker. A worker that has failed reports its
    /// error here or from [`FrameSink::finish`].
    pub fn push(&mut self, index: usize, rgba: Vec<u8>) -> Result<(), Error> {
        let sent = self.sender.as_ref().map(|s| s.send((index, rgba)));
        match sent {
            Some(Ok(())) => Ok(()),
            _ => self.join().map(drop),
        }
    }

    /// Waits for the worker and writes `contact_sheet.png`.
    pub fn finish(mut self) -> Result<(), Error> {
        let thumbs = self.join()?;
        let (sw, sh, pixels) = sheet(&thumbs, self.width / 2, self.height / 2);
        write_png(&self.dir.join("contact_sheet.png"), sw, sh, &pixels)
    }

    fn join(&mut self) -> Result<Vec<Vec<u8>>, Error> {
        self.sender = None;
        match self.worker.take() {
            Some(worker) => worker.join().map_err(|_| Error::from("the frame writer stopped unexpectedly"))?,
            None => Err("the frame writer already stopped".into()),
        }
    }
}
