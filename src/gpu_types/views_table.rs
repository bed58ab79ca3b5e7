// The table form of the view list (src/gpu_types/views.rs), for build.rs and
// tests/layers.rs: each includes this file, then the list. The crate has its
// own `shader_views!` (gpu_types/mod.rs) that makes Rust structs of the same
// list. Plain items only: no `crate::` paths, no inner doc comments.

/// One field of one view.
#[allow(dead_code)] // each includer reads what it needs
pub struct ViewField {
    /// The Rust view's name.
    pub view: &'static str,
    /// The Rust block's name.
    pub block: &'static str,
    /// The header under glsl/include/ that declares the GLSL struct.
    pub header: &'static str,
    /// The GLSL struct's name.
    pub glsl_block: &'static str,
    /// The accessor's name: the view's prefix, `_`, the field.
    pub accessor: &'static str,
    /// The field's doc comment, lines joined by '\n'.
    pub doc: &'static str,
    /// float, uint, vec3, uvec3 or mat4.
    pub kind: &'static str,
    /// The block's member.
    pub member: &'static str,
    /// Its lanes ("" for the whole member).
    pub lanes: &'static str,
}

macro_rules! shader_views {
    ($(
        $(#[doc = $view_doc:literal])*
        $view:ident for $block:ident in $header:literal as $glsl:literal prefix $prefix:literal {
            $( $(#[doc = $doc:literal])* $field:ident : $kind:ident = $member:ident $(. $lanes:ident)? ),* $(,)?
        }
    )*) => {
        /// Every field of every view, in the list's order.
        pub const SHADER_VIEWS: &[ViewField] = &[$($(
            ViewField {
                view: stringify!($view),
                block: stringify!($block),
                header: $header,
                glsl_block: $glsl,
                accessor: concat!($prefix, "_", stringify!($field)),
                doc: concat!($($doc, "\n",)*),
                kind: stringify!($kind),
                member: stringify!($member),
                lanes: stringify!($($lanes)?),
            },
        )*)*];
    };
}
