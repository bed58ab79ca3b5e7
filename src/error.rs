//! The crate's one error type.

use std::path::PathBuf;

use ash::vk;

/// Result alias used throughout the crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Hair file formats the crate reads or writes, named in errors.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileFormat {
    /// Cem Yuksel's binary `.hair`.
    CyHair,
    /// AMD TressFX binary `.tfx` (3.x/4.x layout).
    TressFx,
    /// Wavefront OBJ mesh.
    Obj,
    /// glTF 2.0 (`.gltf`, `.glb`).
    Gltf,
    /// Universal Scene Description (`.usd`, `.usda`, `.usdc`).
    Usd,
    /// Alembic (`.abc`, the Ogawa container).
    Alembic,
}

impl std::fmt::Display for FileFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            FileFormat::CyHair => ".hair",
            FileFormat::TressFx => ".tfx",
            FileFormat::Obj => ".obj",
            FileFormat::Gltf => "glTF",
            FileFormat::Usd => "USD",
            FileFormat::Alembic => "Alembic",
        })
    }
}

/// Everything that can go wrong in `vkhair`, each case naming the problem.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    // ---- Vulkan and devices -------------------------------------------
    /// The Vulkan loader library could not be loaded.
    #[error("the Vulkan loader could not be loaded: {0}")]
    Loader(String),
    /// A Vulkan call returned an error code.
    #[error("{call} failed: {result}")]
    Vulkan {
        /// The Vulkan entry point that failed.
        call: &'static str,
        /// The code it returned.
        result: vk::Result,
    },
    /// An instance layer that was asked for is not installed.
    #[error("Vulkan layer {0} is not installed (Debian: vulkan-validationlayers)")]
    LayerMissing(String),
    /// No physical device offers what vkhair needs.
    #[error("no suitable Vulkan device: {0}")]
    NoSuitableDevice(String),
    /// The device named by `VKHAIR_DEVICE` (or the options) does not exist or lacks features.
    #[error("device {name:?} was asked for but {reason}")]
    DeviceNotUsable {
        /// The requested name (substring match).
        name: String,
        /// Why it cannot be used.
        reason: String,
    },
    /// A host-provided device lacks a feature, extension or version vkhair requires.
    #[error("the device does not meet vkhair's requirements: missing {0}")]
    MissingRequirement(String),
    /// GPU memory allocation failed.
    #[error("GPU memory allocation for {name:?} failed: {source}")]
    Allocation {
        /// Debug name of the resource.
        name: String,
        /// The allocator's error.
        source: gpu_allocator::AllocationError,
    },
    /// A SPIR-V module could not be reflected, or its interface does not match the Rust side.
    #[error("shader {shader}: {reason}")]
    Shader {
        /// Shader path under `glsl/`.
        shader: String,
        /// What is wrong.
        reason: String,
    },
    /// An argument is outside its documented range.
    #[error("invalid parameter {name}: {value} (allowed: {allowed})")]
    InvalidParameter {
        /// The parameter.
        name: &'static str,
        /// The value given, as text.
        value: String,
        /// What the parameter accepts.
        allowed: String,
    },
    /// A call does not fit the object it was made on: key hairs of another device
    /// or simulation, a frame index that went backwards, a size the object was not
    /// created for, a state of the wrong size.
    #[error("{what}: {reason}")]
    Incompatible {
        /// What was passed or asked for.
        what: &'static str,
        /// Why it does not fit.
        reason: String,
    },
    /// The device cannot do what was asked within its limits (buffer ranges, image
    /// sizes, mappable memory).
    #[error("the device cannot hold {what}: {reason}")]
    Device {
        /// The resource or operation.
        what: &'static str,
        /// The limit it ran into.
        reason: String,
    },
    /// A feature combination vkhair does not implement (point lights with deep
    /// opacity maps, barycentric interpolation without a scalp triangle).
    #[error("{what} is not supported: {reason}")]
    UnsupportedFeature {
        /// The feature.
        what: &'static str,
        /// Why, and what to use instead.
        reason: String,
    },
    /// A buffer access would run past the end of the buffer.
    #[error("{what} of {len} bytes at offset {offset} exceeds buffer {name:?} of {size} bytes")]
    OutOfBounds {
        /// `upload` or `readback`.
        what: &'static str,
        /// Buffer debug name.
        name: String,
        /// Byte offset asked for.
        offset: u64,
        /// Byte count asked for.
        len: u64,
        /// Buffer size.
        size: u64,
    },

    // ---- Files ------------------------------------------------------------
    /// A file could not be read as the asset it should be: the file, and what
    /// was wrong with its contents ([`Error::BadMagic`], [`Error::Truncated`],
    /// [`Error::Malformed`], [`Error::Unsupported`] or a groom check).
    #[error("{}: {source}", path.display())]
    Asset {
        /// The file.
        path: PathBuf,
        /// What was wrong with it.
        source: Box<Error>,
    },
    /// A curve object of a USD or Alembic file (a prim or object path) could
    /// not be read: the object, and what was wrong with it (its strand and
    /// point indices count within the object).
    #[error("{object}: {source}")]
    CurveObject {
        /// The prim or object path.
        object: String,
        /// What was wrong.
        source: Box<Error>,
    },
    /// An input file is larger than what vkhair reads of such a file: its
    /// format's limits, or [`crate::files::MAX_INPUT_ENV`]'s cap on files with
    /// no header to bound them (set it to read larger ones).
    #[error("{}: more than {cap} bytes, the most vkhair reads of {what}{hint}", path.display())]
    InputTooLarge {
        /// The file.
        path: PathBuf,
        /// What kind of file it is.
        what: &'static str,
        /// The cap, bytes.
        cap: u64,
        /// How to raise the cap, when it can be raised.
        hint: &'static str,
    },
    /// An output was not written because writing it would clobber what it
    /// should not: a symbolic link in the output's place, an input of the same
    /// run, another output of the same run.
    #[error("{}: not written: {reason}", path.display())]
    OutputRefused {
        /// The output path.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// A parameter file has an unknown key, a value of the wrong type or one outside
    /// its range: the file, the line (1-based, when known) and the key.
    #[error("{}{}: {key}: {reason}", path.display(), line.map(|l| format!(":{l}")).unwrap_or_default())]
    Config {
        /// The file.
        path: PathBuf,
        /// The line of the key, counting from 1.
        line: Option<usize>,
        /// The key, with its section (`sim.volume.resolution`).
        key: String,
        /// What is wrong.
        reason: String,
    },
    /// The file does not start with the format's signature.
    #[error("not a {format} file: {reason}")]
    BadMagic {
        /// Expected format.
        format: FileFormat,
        /// What was found.
        reason: String,
    },
    /// The file ends before the data its header announces.
    #[error("truncated {format} file: {what} needs {needed} bytes but only {available} remain")]
    Truncated {
        /// Format being read.
        format: FileFormat,
        /// Which part was being read.
        what: &'static str,
        /// Bytes required.
        needed: u64,
        /// Bytes present.
        available: u64,
    },
    /// Header fields contradict each other or the file.
    #[error("malformed {format} file: {reason}")]
    Malformed {
        /// Format being read.
        format: FileFormat,
        /// What is inconsistent.
        reason: String,
    },
    /// A file uses a format version or feature that is not supported.
    #[error("unsupported {format} file: {reason}")]
    Unsupported {
        /// Format being read.
        format: FileFormat,
        /// What is unsupported.
        reason: String,
    },

    // ---- Groom validation --------------------------------------------------
    /// A groom has no strands.
    #[error("the groom has no strands")]
    EmptyGroom,
    /// Repairing a groom dropped every strand: what was dropped and why.
    #[error("no strand remains after repairing the groom: {repairs}")]
    NothingLeft {
        /// What the repair dropped ([`crate::groom::Repairs`] as text).
        repairs: String,
    },
    /// More strands than [`crate::groom::MAX_STRANDS`].
    #[error("{count} strands exceed the limit of {max}")]
    TooManyStrands {
        /// Strands asked for.
        count: u64,
        /// The limit.
        max: u64,
    },
    /// More points in total than [`crate::groom::MAX_POINTS`].
    #[error("{count} points exceed the limit of {max}")]
    TooManyPoints {
        /// Points asked for.
        count: u64,
        /// The limit.
        max: u64,
    },
    /// A strand has fewer than 2 or more than [`crate::groom::MAX_POINTS_PER_STRAND`] points.
    #[error("strand {strand} has {points} points; a strand needs 2..={max}")]
    StrandPointCount {
        /// Strand index.
        strand: usize,
        /// Its point count.
        points: u64,
        /// The upper limit.
        max: u64,
    },
    /// A position, thickness, transparency or color is NaN or infinite.
    #[error("strand {strand} point {point}: {what} is not finite")]
    NonFinite {
        /// Strand index.
        strand: usize,
        /// Point index within the strand.
        point: usize,
        /// Which attribute.
        what: &'static str,
    },
    /// The groom's bounding box is so large that its diagonal overflows f32.
    #[error(
        "the groom's bounding box spans {extent:e} along its longest axis: its diagonal overflows f32 \
         (scale the groom down)"
    )]
    GroomExtent {
        /// Largest extent of the bounding box along an axis, in the groom's units.
        extent: f64,
    },
    /// The groom lies so far from the origin, for the size of its strands,
    /// that f32 positions cannot hold their shape: its farthest point is over
    /// [`crate::groom::MAX_DISTANCE_IN_STRANDS`] times its median strand.
    #[error(
        "the groom lies {distance:e} from the origin, over 100000 times its median strand ({median:e} across): f32 \
         positions there would round its strands' points by over a hundredth of a strand (move it nearer the origin; or, if \
         most of its strands are tiny, drop them: they make the median)"
    )]
    GroomFarAway {
        /// The distance of its farthest point from the origin, in the groom's units.
        distance: f64,
        /// Its median strand's bounding-box diagonal, in the groom's units.
        median: f32,
    },
    /// Two consecutive points of a strand coincide.
    #[error("strand {strand} segment {segment} has zero length")]
    ZeroLengthSegment {
        /// Strand index.
        strand: usize,
        /// Segment index within the strand.
        segment: usize,
    },
    /// A strand is a point, not a hair: its bounding box is under
    /// [`crate::groom::MIN_STRAND_FRACTION`] of the groom's median strand's.
    #[error(
        "strand {strand} is {size:e} across, under a millionth of the groom's median strand ({median:e}): a \
         point, not a hair"
    )]
    DegenerateStrand {
        /// Strand index.
        strand: usize,
        /// Its bounding-box diagonal, in the groom's units.
        size: f32,
        /// The groom's median strand bounding-box diagonal, in the groom's units.
        median: f32,
    },
    /// A point's thickness is not a diameter its strand could have: below
    /// zero, or more than [`crate::groom::MAX_THICKNESS_IN_SIZES`] times the
    /// strand's bounding-box diagonal.
    #[error(
        "strand {strand} point {point} has a thickness of {value:e}, not a diameter of a strand {size:e} across \
         (at least 0, at most 10 times that)"
    )]
    BadThickness {
        /// Strand index.
        strand: usize,
        /// Point index within the strand.
        point: usize,
        /// The thickness, in the groom's units.
        value: f32,
        /// The strand's bounding-box diagonal, in the groom's units.
        size: f32,
    },
    /// A point lies far from where its strand runs: a segment to it is over
    /// [`crate::groom::OUTLIER_SEGMENT_RATIO`] times the strand's median.
    #[error(
        "strand {strand} point {point} at ({}, {}, {}) is an outlier: a segment to it is over 10,000 times its \
         strand's median segment",
        position[0],
        position[1],
        position[2]
    )]
    OutlierPoint {
        /// Strand index.
        strand: usize,
        /// Point index within the strand.
        point: usize,
        /// Its position, in the groom's units.
        position: [f32; 3],
    },
    /// A per-point or per-strand attribute array has the wrong length.
    #[error("{what} has {actual} entries but the groom needs {expected}")]
    AttributeLength {
        /// Which attribute array.
        what: &'static str,
        /// Entries needed.
        expected: usize,
        /// Entries given.
        actual: usize,
    },
    /// A strand index is out of range.
    #[error("strand index {index} is out of range for {count} strands")]
    StrandIndex {
        /// The index.
        index: usize,
        /// Strand count.
        count: usize,
    },
    /// A mesh cannot serve as a scalp (no triangles, or none selected).
    #[error("mesh cannot be used as a scalp: {0}")]
    BadScalp(String),

    // ---- Frame scheduling ---------------------------------------------------
    /// A scheduling mode was asked for that the device(s) cannot run.
    #[error("schedule mode {mode} is not available: {reason}")]
    ModeUnavailable {
        /// The mode asked for.
        mode: &'static str,
        /// Why it cannot run.
        reason: String,
    },
    /// The simulation side stopped (dropped, failed or timed out) while the host
    /// still asked for frames.
    #[error("the simulation side stopped: {0}")]
    SimulationStopped(String),
    /// Handing the simulation state over to the rendering side failed or timed out.
    #[error("simulation hand-off failed: {0}")]
    HandOff(String),
}

impl Error {
    /// Builds a [`Error::Vulkan`] for `call`; used with `map_err`.
    pub(crate) fn vk(call: &'static str) -> impl FnOnce(vk::Result) -> Error {
        move |result| Error::Vulkan { call, result }
    }

    /// Builds an [`Error::InvalidParameter`]: `value` of `name` is not in `allowed`.
    pub(crate) fn param(name: &'static str, value: impl std::fmt::Display, allowed: impl Into<String>) -> Error {
        Error::InvalidParameter { name, value: value.to_string(), allowed: allowed.into() }
    }

    /// Builds an [`Error::Incompatible`].
    pub(crate) fn incompatible(what: &'static str, reason: impl Into<String>) -> Error {
        Error::Incompatible { what, reason: reason.into() }
    }

    /// Builds an [`Error::Device`].
    pub(crate) fn device(what: &'static str, reason: impl Into<String>) -> Error {
        Error::Device { what, reason: reason.into() }
    }

    /// Builds an [`Error::UnsupportedFeature`].
    pub(crate) fn unsupported(what: &'static str, reason: impl Into<String>) -> Error {
        Error::UnsupportedFeature { what, reason: reason.into() }
    }

    /// This error as the reason the file at `path` could not be read.
    pub(crate) fn in_asset(self, path: &std::path::Path) -> Error {
        match self {
            e @ (Error::Io { .. } | Error::Asset { .. } | Error::InputTooLarge { .. }) => e,
            e => Error::Asset { path: path.to_path_buf(), source: Box::new(e) },
        }
    }
}
