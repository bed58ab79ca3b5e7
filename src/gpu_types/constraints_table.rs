// The table form of the constraint list (src/gpu_types/constraints.rs), for
// build.rs and tests/layers.rs: each includes this file, then the list. Plain
// items only: no `crate::` paths, no inner doc comments.

/// One constraint of the list.
#[allow(dead_code)] // each includer reads what it needs
pub struct ConstraintRow {
    /// Its name: `glsl/include/constraints/NAME.glsl`,
    /// `src/sim/reference/constraints/NAME.rs`, the GLSL functions' prefix.
    pub name: &'static str,
    /// Its doc comment, lines joined by '\n'.
    pub doc: &'static str,
    /// `pairs`, `sweep`, `point` or `after`.
    pub kind: &'static str,
    /// What each of its sets holds, in the order they run.
    pub sets: &'static [&'static str],
    /// Its knobs: name and doc comment.
    pub knobs: &'static [(&'static str, &'static str)],
}

macro_rules! sim_constraints {
    ($(
        $(#[doc = $doc:literal])*
        $name:ident : $kind:ident [ $($set:literal),* ] {
            $( $(#[doc = $kdoc:literal])* $knob:ident = $from:expr ),* $(,)?
        }
    )*) => {
        /// Every constraint, in the order the solve applies them.
        pub const SIM_CONSTRAINTS: &[ConstraintRow] = &[$(
            ConstraintRow {
                name: stringify!($name),
                doc: concat!($($doc, "\n",)*),
                kind: stringify!($kind),
                sets: &[$($set),*],
                knobs: &[$((stringify!($knob), concat!($($kdoc, "\n",)*)),)*],
            },
        )*];
    };
}
