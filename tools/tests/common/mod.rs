//! Running the built `vkhair` binary as a user does, and reading what it wrote.
#![allow(dead_code)] // each test file uses its own part

use std::io::Read;
use std::path::Path;
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use glam::Vec3;
use vkhair::groom::cyhair::HairFile;
use vkhair::groom::Groom;

/// The binary, with validation on (as `tools/test.sh` sets it) so that any
/// validation message shows on stderr as `vulkan: …`.
pub fn vkhair() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_vkhair"));
    c.env("VKHAIR_VALIDATION", "1");
    c
}

/// What a run of the binary left.
pub struct Run {
    pub status: ExitStatus,
    pub stdout: String,
    pub stderr: String,
}

impl Run {
    /// The run succeeded without a panic or a validation message.
    pub fn assert_ok(&self) -> &Self {
        assert!(self.status.success(), "{:?}\n{}\n{}", self.status, self.stdout, self.stderr);
        self.assert_clean()
    }

    /// The run failed with exit status 1 and an error line that contains `text`.
    pub fn assert_error(&self, text: &str) -> &Self {
        assert_eq!(self.status.code(), Some(1), "{}\n{}", self.stdout, self.stderr);
        assert!(self.stderr.contains(text), "expected {text:?} in:\n{}", self.stderr);
        self.assert_clean()
    }

    /// No panic and no validation message on stderr.
    pub fn assert_clean(&self) -> &Self {
        assert!(!self.stderr.contains("panicked"), "{}", self.stderr);
        assert!(!self.stderr.contains("vulkan: "), "validation message:\n{}", self.stderr);
        self
    }
}

/// Runs `vkhair args…`, killing it and failing the test after `limit`.
pub fn run(args: &[&str], limit: Duration) -> Run {
    run_command(vkhair().args(args), limit)
}

/// [`run`] with the arguments given as one string, split at spaces.
pub fn run_line(args: &str, limit: Duration) -> Run {
    run(&args.split_whitespace().collect::<Vec<_>>(), limit)
}

/// Runs `command`, killing it and failing the test after `limit`.
pub fn run_command(command: &mut Command, limit: Duration) -> Run {
    let mut child = command.stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().expect("start vkhair");
    let mut stdout = child.stdout.take().expect("stdout");
    let mut stderr = child.stderr.take().expect("stderr");
    let out = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = stdout.read_to_string(&mut s);
        s
    });
    let err = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = stderr.read_to_string(&mut s);
        s
    });
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait") {
            break status;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("vkhair {:?} still ran after {limit:?}", command.get_args().collect::<Vec<_>>());
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    Run { status, stdout: out.join().expect("stdout reader"), stderr: err.join().expect("stderr reader") }
}

/// A PNG file's size and RGBA8 pixels (panics when it is not a whole PNG).
pub fn read_png(path: &Path) -> (u32, u32, Vec<u8>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).expect("open png")));
    let mut reader = decoder.read_info().unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut pixels = vec![0; reader.output_buffer_size().expect("size")];
    let info = reader.next_frame(&mut pixels).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(info.color_type, png::ColorType::Rgba, "{}", path.display());
    pixels.truncate(info.buffer_size());
    (info.width, info.height, pixels)
}

/// Share of pixels that differ from the background (the top-left pixel) by more
/// than 8 levels in a channel.
pub fn coverage(rgba: &[u8]) -> f64 {
    let bg = &rgba[..3];
    let covered = rgba.chunks_exact(4).filter(|p| p.iter().zip(bg).any(|(a, b)| a.abs_diff(*b) > 8)).count();
    covered as f64 / (rgba.len() / 4) as f64
}

/// Writes `strands` as a `.hair` file.
pub fn write_groom(path: &Path, strands: &[Vec<Vec3>]) {
    HairFile::new(Groom::from_strands(strands).expect("groom"), "test groom").save(path).expect("save");
}

/// `count` strands of `points` points hanging from a cap of a sphere of `radius`
/// (the groom's size scales with it).
pub fn cap_groom(count: usize, points: usize, radius: f32) -> Vec<Vec<Vec3>> {
    (0..count)
        .map(|i| {
            let a = i as f32 * 2.399_963; // golden angle
            let up = 0.3 + 0.6 * (i as f32 + 0.5) / count as f32;
            let root = radius * Vec3::new(a.cos() * (1.0 - up * up).sqrt(), up, a.sin() * (1.0 - up * up).sqrt());
            let out = root.normalize();
            (0..points)
                .map(|k| {
                    let t = k as f32 / (points - 1) as f32;
                    root + radius * (0.6 * t * out - Vec3::new(0.0, 1.2 * t * t, 0.0))
                })
                .collect()
        })
        .collect()
}
