// Flags and enumeration values shared by the Rust side and the shaders,
// defined here once.
//
// Each group below becomes a module of `u32` constants in the crate
// (`codes::sim_flags::GRAVITY`) and, through build.rs, which includes this
// file (`include!`), a macro of every shader named by the group's prefix and
// the constant's name (`-DSIM_GRAVITY=1u`). A shader that declares one of
// these names itself fails the build (`limits::redeclared_constants`), and
// `gpu_types::tests` runs a shader that writes every one of them back, so the
// two sides cannot drift. Plain items only: no `crate::` paths, no inner doc
// comments (the file is compiled in two places).

/// Declares groups of shared codes: a module of constants per group and
/// [`SHADER_CODES`], every code with the name the shaders see it by.
macro_rules! shader_codes {
    ($(
        $(#[doc = $group_doc:literal])*
        $group:ident = $prefix:literal {
            $( $(#[doc = $doc:literal])* $name:ident = $value:expr ),* $(,)?
        }
    )*) => {
        $(
            $(#[doc = $group_doc])*
            #[allow(dead_code)] // a group may have members only the shaders use
            pub mod $group {
                $( $(#[doc = $doc])* pub const $name: u32 = $value; )*
            }
        )*
        /// Every code with the name the shaders see it by (`PREFIX_NAME`).
        #[cfg_attr(not(test), allow(dead_code))] // used by build.rs and the tests
        pub const SHADER_CODES: &[(&str, u32)] = &[
            $( $( (concat!($prefix, stringify!($name)), $group::$name), )* )*
        ];
    };
}

shader_codes! {
    /// Switches of one simulation sub-step (`sim_flags(p)` of `SimStepParams`).
    sim_flags = "SIM_" {
        /// Gravity acts.
        GRAVITY = 1,
        /// Wind acts.
        WIND = 1 << 1,
        /// The rest-shape spring acts.
        SPRING = 1 << 2,
        /// Bending constraints act.
        BENDING = 1 << 3,
        /// Body collisions act (spheres, capsules, the mesh collider).
        COLLISIONS = 1 << 4,
        /// The DFTL solver replaces the PBD iterations.
        DFTL = 1 << 5,
        /// The global shape constraint acts.
        GLOBAL_SHAPE = 1 << 6,
        /// The global shape targets are raised by the static sag.
        SAG_FREE = 1 << 7,
        /// The local shape constraints act.
        LOCAL_SHAPE = 1 << 8,
        /// A mesh collider is set and collisions act.
        MESH = 1 << 9,
        /// Each key hair's root follows its bound triangle of a skinned scalp
        /// (`sim::scalp`): the rest pose is placed per hair by its root's frame.
        SCALP = 1 << 10,
        /// The mesh collider's field follows bones (`sim::MeshCollider::skinned`):
        /// each point is taken to the bind pose by the bones of its grid point.
        MESH_SKIN = 1 << 11,
    }

    /// A collider's shape (`collider_kind(c)`, stored as a float).
    collider_kind = "COLLIDER_" {
        /// The points within the radius of the centre.
        SPHERE = 0,
        /// The points within the radius of a segment.
        CAPSULE = 1,
    }

    /// What a volume cell holds (the cell labels of the FLIP stage).
    vol_cell = "VOL_" {
        /// No hair: pressure 0.
        AIR = 0,
        /// Hair: a pressure unknown.
        FLUID = 1,
        /// Inside a collider: a Neumann boundary.
        SOLID = 2,
    }

    /// The volume stage's mode (`vol_mode(p)`, stored as a float).
    vol_mode = "VOL_MODE_" {
        /// The stage is off.
        OFF = 0,
        /// FLIP with a pressure projection.
        FLIP = 1,
        /// Density friction and repulsion.
        FRICTION = 2,
    }

    /// The pressure solve's preconditioner (`vol_preconditioner(p)`).
    vol_precond = "VOL_PRECOND_" {
        /// Jacobi (the diagonal).
        JACOBI = 0,
        /// A multigrid V-cycle.
        MULTIGRID = 1,
    }

    /// How the pressure solve ended (`PcgScalars::status`).
    vol_status = "VOL_STATUS_" {
        /// Converged or stopped at the iteration cap.
        OK = 0,
        /// The conjugate-gradient recurrence broke down.
        BREAKDOWN = 1,
        /// A value was NaN or infinite.
        NONFINITE = 2,
    }

    /// The pressure matrix's stencil word per cell (`volume_ops.glsl`).
    vol_stencil = "VOL_STENCIL_" {
        /// The cell is fluid.
        FLUID = 1 << 16,
        /// Where the count of non-solid neighbours starts.
        COUNT_SHIFT = 8,
    }

    /// A light's kind (`Light::position_kind.w`, stored as a float).
    light_kind = "LIGHT_" {
        /// Parallel rays along a direction.
        DIRECTIONAL = 0,
        /// From a point, in every direction.
        POINT = 1,
        /// From a point, inside a cone.
        SPOT = 2,
    }

    /// How a shadow-casting light's shadow is made (`ShadowMap::params.z`, stored as a float).
    shadow_kind = "SHADOW_" {
        /// A deep opacity map.
        DEEP_OPACITY = 0,
        /// Transmittance through the simulation's density volume.
        DENSITY_VOLUME = 1,
    }

    /// The draw pass's shading model (`DrawParams::counts.w`).
    shading = "SHADING_" {
        /// Kajiya-Kay diffuse and two shifted highlights.
        KAJIYA_KAY = 0,
        /// Marschner through lookup tables.
        MARSCHNER = 1,
    }

    /// How the host's depth copied for the compute rasteriser is encoded
    /// (`OitCounters::scene_depth`).
    scene_depth = "SCENE_DEPTH_" {
        /// No depth to test against (no depth attachment, or one cleared by vkhair).
        NONE = 0,
        /// 32-bit floats (`D32_SFLOAT`).
        FLOAT32 = 1,
        /// 24-bit unsigned normalised in the low bits of a word (`X8_D24_UNORM_PACK32`).
        UNORM24 = 2,
        /// 16-bit unsigned normalised, two a word, the first in the low half (`D16_UNORM`).
        UNORM16 = 3,
    }

    /// Optional parts of the hair shading (`hair_shading.glsl`) that the
    /// pipelines which shade are specialised to, as the bits of their
    /// `SHADING_FEATURES` constant: a CPU device runs both sides of every branch
    /// it cannot prove uniform, so a frame without them does not pay for them.
    shading_features = "SHADE_" {
        /// Marschner shading (else Kajiya-Kay only).
        MARSCHNER = 1,
        /// A light whose shadow comes from the density volume (else deep
        /// opacity maps, or none, only).
        DENSITY_VOLUME = 1 << 1,
    }

    /// How the interpolation pass lays out its isolines.
    interpolate = "INTERPOLATE_" {
        /// Hairs (isolines) grown per patch instance (at most 64, the least
        /// `maxTessellationGenerationLevel` Vulkan allows). More hairs per key
        /// hair take more instances of the patches. Few lines per patch: a
        /// software tessellator (lavapipe) spends time in the square of a
        /// patch's output: a one-frame `vkhair render` of Sintel at 64 hairs per
        /// key hair took 1.7 s at 4 lines per patch against 10.0 s at 64.
        LINES_PER_INSTANCE = 4,
        /// Most hairs grown per key hair (or scalp triangle): 256 instances of 4.
        /// Also the stride of the random seeds of interpolated hairs
        /// (`key · MAX_HAIRS_PER_KEY + hair`): distinct for the hairs of up to
        /// 2^21 key hairs or scalp triangles (the hash takes twice the seed).
        MAX_HAIRS_PER_KEY = 1024,
    }

    /// Transparent bands (`ribbon.vert`, `render::reference::strand_band`).
    band = "BAND_" {
        /// Widest a band spreads, in multiples of the n hair widths it stands
        /// for: Sintel's and the thesis' error against a full head fell with
        /// the spread while its fragments grew (thesis 800×600: no spread 9.8
        /// steps, 1.36 M fragments; 2× 8.7, 1.99 M; 4× 7.6, 2.96 M; unbounded
        /// 6.9, 4.3 M).
        MAX_SPREAD = 2,
    }

    /// The tiled rasteriser (`render/draw/tiles.rs`, `glsl/render/tile_*.comp`).
    tile = "TILE_" {
        /// Pixels along each side of a screen tile: the fine pass's workgroup
        /// is SIZE × SIZE invocations, one a pixel.
        SIZE = 16,
        /// Fragments a tile's workgroup holds in shared memory (16 bytes
        /// each) before it sorts them into its pixels' K-buffers.
        FRAGMENTS = 1024,
        /// Invocations of the one workgroup that scans the tiles' counts.
        SCAN_GROUP = 256,
    }

    /// "None" words that buffers are cleared to.
    sentinel = "" {
        /// No node in a per-pixel list, no depth stored (transparency).
        OIT_END = 0xffff_ffff,
        /// No triangle or distance yet (mesh collider build).
        SDF_NONE = 0xffff_ffff,
    }
}
