// Constants shared by the Rust side and the shaders, defined here once.
//
// build.rs includes this file (`include!`) and injects every entry of
// `SHADER_CONSTANTS` into every shader as a macro of the same name, an
// unsigned literal (`-DSIM_MAX_COLLIDERS=64u`); the build fails when a shader
// declares one of these names itself. The crate uses the same constants, so
// the two sides cannot drift. Plain items only: no `crate::` paths, no inner
// doc comments (the file is compiled in two places).

/// Most colliders (spheres and capsules) a simulation takes.
pub const SIM_MAX_COLLIDERS: u32 = 64;
/// Most bones a skinned mesh collider's field follows (`sim::MeshCollider::skinned`).
pub const SIM_MESH_MAX_BONES: u32 = 32;
/// Invocations of a simulation workgroup (predict, solve, integrate); the
/// constraint solver holds one strand point per invocation, so this is also the
/// most points a simulated strand can have.
pub const SIM_WORKGROUP: u32 = 64;
/// Most lights the draw pass shades with.
pub const MAX_LIGHTS: u32 = 8;
/// Most shadow-casting lights.
pub const MAX_SHADOW_MAPS: u32 = 4;
/// Invocations of a volume-stage workgroup (a power of two: the shared-memory
/// reduction halves it).
pub const VOL_GROUP: u32 = 256;
const _: () = assert!(VOL_GROUP.is_power_of_two());
/// uint words per cell of the volume transfer's fixed-point sums: weight and
/// weighted velocity (x, y, z), two words each (`volume_fixed.glsl`).
pub const VOL_CELL_WORDS: u32 = 8;
/// uint words per face of the same sums: weight and weighted velocity.
pub const VOL_FACE_WORDS: u32 = 4;
/// Damped Jacobi sweeps of the multigrid preconditioner on its coarsest level
/// (an even number).
pub const VOL_COARSEST_SWEEPS: u32 = 16;
const _: () = assert!(VOL_COARSEST_SWEEPS.is_multiple_of(2));
/// Invocations of the per-item compute kernels of the renderer and the tests.
#[cfg_attr(not(test), allow(dead_code))] // the pipelines read it back from the SPIR-V
pub const ITEM_GROUP: u32 = 64;

/// How near its closest triangle's face, in cells, a mesh collider's grid
/// point takes its sign from the side of that face (farther, and where the
/// closest point is on an edge or a corner: from the axis rays' vote).
pub const SDF_FACE_BAND_CELLS: u32 = 2;

/// Most grid points per axis of a mesh collider's distance field.
pub const SDF_MAX_RESOLUTION: u32 = 256;

/// Most fragments per pixel the exact transparency mode sorts (its K).
pub const OIT_MAX_SORTED: u32 = 32;

/// Ribbon segments per instance of the indexed ribbon draw
/// (`render/draw/ribbons.rs`): their four corners each are numbered within
/// 16-bit indices.
pub const RIBBON_CHUNK: u32 = 16_384;

/// The constants above that shaders use, with the name they see each by
/// ([`SDF_MAX_RESOLUTION`] is the host's alone: the mesh collider's kernels
/// size a line's marks from the grid they are given).
#[cfg_attr(not(test), allow(dead_code))] // used by build.rs and the tests
pub const SHADER_CONSTANTS: &[(&str, u32)] = &[
    ("SIM_MAX_COLLIDERS", SIM_MAX_COLLIDERS),
    ("SIM_WORKGROUP", SIM_WORKGROUP),
    ("SIM_MESH_MAX_BONES", SIM_MESH_MAX_BONES),
    ("SDF_FACE_BAND_CELLS", SDF_FACE_BAND_CELLS),
    ("MAX_LIGHTS", MAX_LIGHTS),
    ("MAX_SHADOW_MAPS", MAX_SHADOW_MAPS),
    ("VOL_GROUP", VOL_GROUP),
    ("VOL_CELL_WORDS", VOL_CELL_WORDS),
    ("VOL_FACE_WORDS", VOL_FACE_WORDS),
    ("VOL_COARSEST_SWEEPS", VOL_COARSEST_SWEEPS),
    ("ITEM_GROUP", ITEM_GROUP),
    ("OIT_MAX_SORTED", OIT_MAX_SORTED),
    ("RIBBON_CHUNK", RIBBON_CHUNK),
];

/// The lines (1-based) of a shader source that declare a name of `table`
/// ([`SHADER_CONSTANTS`], or the shared codes of src/codes.rs) themselves
/// (`#define NAME` or `const … NAME`), with the name: build.rs refuses such a
/// shader, so each constant has one definition.
#[cfg_attr(not(test), allow(dead_code))] // used by build.rs and the tests
pub fn redeclared_constants(source: &str, table: &[(&'static str, u32)]) -> Vec<(usize, &'static str)> {
    let mut found = Vec::new();
    for (number, line) in source.lines().enumerate() {
        let code = line.split("//").next().unwrap_or_default();
        let words: Vec<&str> = code
            .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '#'))
            .filter(|w| !w.is_empty())
            .collect();
        let declares = |name: &str| {
            words.windows(2).any(|w| w[0] == "#define" && w[1] == name)
                || (words.first() == Some(&"const") && words.iter().skip(1).take(3).any(|w| *w == name))
        };
        for (name, _) in table {
            if declares(name) {
                found.push((number + 1, *name));
            }
        }
    }
    found
}
