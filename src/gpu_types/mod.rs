//! Rust twins of the GLSL structs in `glsl/include/`, one definition each,
//! and the named views of the packed ones.
//!
//! Every struct is `#[repr(C)]` + `bytemuck::Pod` and implements
//! `GpuStruct`; `vk::tests` reflects the SPIR-V of every shader and checks
//! member offsets, sizes and array strides against these definitions.
//!
//! The parameter blocks pack scalars into `vec4`/`uvec4` lanes (std140
//! alignment). Which lane holds what is written once, in `views.rs`: each
//! *view* there is a plain struct of named, typed fields (generated below,
//! with `From` conversions to and from its block), and build.rs turns the same
//! list into the shaders' accessors (`#include "views.glsl"`:
//! `sim_wind_frequency(p)` reads `p.wind_noise.x`). The blocks' members are
//! private to this module, so no other Rust code can index into the packing,
//! and `tests/layers.rs` refuses a simulation shader that reads a packed
//! member but through an accessor. Flags and enumerations shared with the
//! shaders live in [`crate::codes`].

use glam::{Mat4, Vec3};

mod probe;
mod render;
mod sim;
#[cfg(test)]
mod tests;
mod volume;

#[cfg(test)]
pub(crate) use probe::{LayoutProbe, ScaleAddPush};
pub(crate) use render::{
    DrawParams, FollowerBinding, GpuLight, GpuMotion, GpuShadowMap, GpuShadowParams, InterpolatePush, MarschnerPush,
    OitCounters, SmoothPush, TileCounters,
};
pub(crate) use sim::{GpuCollider, GpuScalpRoot, MovePush, SdfPush, SimPush, SimStepParams};
pub(crate) use volume::{GpuVolumeParams, PcgScalars, VolumePush};

/// The Rust type of a view field of a given kind.
macro_rules! view_type {
    (float) => {
        f32
    };
    (uint) => {
        u32
    };
    (vec3) => {
        Vec3
    };
    (uvec3) => {
        [u32; 3]
    };
    (mat4) => {
        Mat4
    };
    (knobs) => {
        SimKnobs
    };
}

/// The index of one lane.
macro_rules! lane {
    (x) => {
        0
    };
    (y) => {
        1
    };
    (z) => {
        2
    };
    (w) => {
        3
    };
}

/// A view field's value from its block member's lanes.
macro_rules! view_get {
    (float, $m:expr, $l:ident) => {
        $m[lane!($l)]
    };
    (uint, $m:expr, $l:ident) => {
        $m[lane!($l)]
    };
    (vec3, $m:expr, xyz) => {
        Vec3::new($m[0], $m[1], $m[2])
    };
    (uvec3, $m:expr, xyz) => {
        [$m[0], $m[1], $m[2]]
    };
    (mat4, $m:expr,) => {
        Mat4::from_cols_array_2d(&$m)
    };
    (knobs, $m:expr,) => {
        SimKnobs::from_lanes(&$m)
    };
}

/// Writes a view field's value into its block member's lanes.
macro_rules! view_set {
    (float, $m:expr, $l:ident, $v:expr) => {
        $m[lane!($l)] = $v
    };
    (uint, $m:expr, $l:ident, $v:expr) => {
        $m[lane!($l)] = $v
    };
    (vec3, $m:expr, xyz, $v:expr) => {
        [$m[0], $m[1], $m[2]] = $v.to_array()
    };
    (uvec3, $m:expr, xyz, $v:expr) => {
        [$m[0], $m[1], $m[2]] = $v
    };
    (mat4, $m:expr,, $v:expr) => {
        $m = $v.to_cols_array_2d()
    };
    (knobs, $m:expr,, $v:expr) => {
        $m = $v.to_lanes()
    };
}

/// The crate's form of the view list (`views.rs`): a struct per view, with
/// `From` conversions to and from its block, and (in tests) the words the
/// probe shader must write for a block of distinct words.
macro_rules! shader_views {
    ($(
        $(#[doc = $view_doc:literal])*
        $view:ident for $block:ident in $header:literal as $glsl:literal prefix $prefix:literal {
            $( $(#[doc = $doc:literal])* $field:ident : $kind:ident = $member:ident $(. $lanes:ident)? ),* $(,)?
        }
    )*) => {
        $(
            $(#[doc = $view_doc])*
            ///
            #[doc = concat!(
                "Packed as [`", stringify!($block), "`]; shaders read its fields as `",
                $prefix, "_FIELD(b)` (`glsl/include/", $header, "` includes `views.glsl`)."
            )]
            #[derive(Debug, Clone, Copy, Default, PartialEq)]
            pub(crate) struct $view {
                $( $(#[doc = $doc])* pub $field: view_type!($kind), )*
            }

            impl From<&$view> for $block {
                fn from(v: &$view) -> Self {
                    let mut b = <$block>::default();
                    $( view_set!($kind, b.$member, $($lanes)?, v.$field); )*
                    b
                }
            }

            impl From<&$block> for $view {
                fn from(b: &$block) -> Self {
                    $view { $( $field: view_get!($kind, b.$member, $($lanes)?), )* }
                }
            }
        )*

        /// Per view, in the list's order: a block of distinct words and the
        /// words the probe shader must write for it.
        #[cfg(test)]
        pub(crate) fn probe_cases() -> Vec<tests::ProbeCase> {
            let mut cases = Vec::new();
            $({
                let block: $block = tests::distinct_words(cases.len() as u32);
                let view = $view::from(&block);
                let mut words = Vec::new();
                $( words.extend(tests::ProbeWords::probe_words(&view.$field)); )*
                cases.push(tests::ProbeCase {
                    view: stringify!($view),
                    bytes: bytemuck::bytes_of(&block).to_vec(),
                    words,
                });
            })*
            cases
        }
    };
}

/// The crate's form of the constraint list (`constraints.rs`): the knobs'
/// struct, whose fields take the lanes of `SimStepParams::knobs` in the
/// list's order (build.rs gives the shaders' accessors the same lanes).
macro_rules! sim_constraints {
    ($(
        $(#[doc = $doc:literal])*
        $name:ident : $kind:ident [ $($set:literal),* ] {
            $( $(#[doc = $kdoc:literal])* $knob:ident = $from:expr ),* $(,)?
        }
    )*) => {
        /// The solver constraints' knobs (`gpu_types/constraints.rs`), each in
        /// its own lane of `SimStepParams::knobs`; shaders read them as
        /// `sim_KNOB(params)`.
        #[derive(Debug, Clone, Copy, Default, PartialEq)]
        pub(crate) struct SimKnobs {
            $( $( $(#[doc = $kdoc])* pub $knob: f32, )* )*
        }

        /// How many knobs the list names.
        const SIM_KNOB_COUNT: usize = [$($(stringify!($knob),)*)*].len();

        /// The `vec4`s of `SimStepParams::knobs` (build.rs defines the same
        /// count for the shaders as `SIM_KNOB_VEC4S`).
        pub(crate) const SIM_KNOB_VEC4S: usize = SIM_KNOB_COUNT.div_ceil(4);

        impl SimKnobs {
            /// The knobs in their lanes, the list's order.
            fn to_lanes(self) -> [[f32; 4]; SIM_KNOB_VEC4S] {
                let flat = [$($(self.$knob,)*)*];
                let mut lanes = [[0.0; 4]; SIM_KNOB_VEC4S];
                for (i, v) in flat.into_iter().enumerate() {
                    lanes[i / 4][i % 4] = v;
                }
                lanes
            }

            /// The knobs read back from their lanes.
            fn from_lanes(lanes: &[[f32; 4]; SIM_KNOB_VEC4S]) -> Self {
                let mut flat = lanes.iter().flatten().copied();
                SimKnobs { $($( $knob: flat.next().unwrap_or_default(), )*)* }
            }

            /// Every knob's value, the list's order.
            #[cfg(test)]
            pub(crate) fn values(&self) -> Vec<f32> {
                vec![$($(self.$knob,)*)*]
            }
        }
    };
}

include!("constraints.rs");
include!("views.rs");

impl ColliderShape {
    /// Whether it is a capsule (else a sphere).
    pub(crate) fn is_capsule(&self) -> bool {
        self.kind == crate::codes::collider_kind::CAPSULE as f32
    }
}

/// Every Rust GPU struct with the shader-side name, for the layout test.
#[cfg(test)]
pub(crate) fn check_all(reflection: &crate::vk::reflect::Reflection) -> Vec<String> {
    use crate::vk::reflect::{compare, GpuStruct};
    fn check<T: GpuStruct>(r: &crate::vk::reflect::Reflection, out: &mut Vec<String>) {
        for layout in r.structs_named(T::GLSL_NAME) {
            if let Err(e) = compare::<T>(layout) {
                out.push(e);
            }
        }
    }
    let mut problems = Vec::new();
    check::<ScaleAddPush>(reflection, &mut problems);
    check::<LayoutProbe>(reflection, &mut problems);
    check::<SimStepParams>(reflection, &mut problems);
    check::<SimPush>(reflection, &mut problems);
    check::<MovePush>(reflection, &mut problems);
    check::<GpuCollider>(reflection, &mut problems);
    check::<GpuScalpRoot>(reflection, &mut problems);
    check::<SdfPush>(reflection, &mut problems);
    check::<SmoothPush>(reflection, &mut problems);
    check::<InterpolatePush>(reflection, &mut problems);
    check::<FollowerBinding>(reflection, &mut problems);
    check::<GpuLight>(reflection, &mut problems);
    check::<DrawParams>(reflection, &mut problems);
    check::<OitCounters>(reflection, &mut problems);
    check::<GpuMotion>(reflection, &mut problems);
    check::<TileCounters>(reflection, &mut problems);
    check::<MarschnerPush>(reflection, &mut problems);
    check::<GpuVolumeParams>(reflection, &mut problems);
    check::<VolumePush>(reflection, &mut problems);
    check::<PcgScalars>(reflection, &mut problems);
    check::<GpuShadowMap>(reflection, &mut problems);
    check::<GpuShadowParams>(reflection, &mut problems);
    problems
}
