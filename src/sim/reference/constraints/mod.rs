//! The CPU twins of the solver's constraints, one file per constraint beside
//! its GLSL include (`glsl/include/constraints/NAME.glsl`), written in the
//! same order of float operations, and the CPU solve calling them in the
//! order of the constraint list (`src/gpu_types/constraints.rs`), as the step
//! kernel's generated solve does.
//!
//! A twin is a file of items (its doc is its row's in the list; a header of
//! `//` comments, no inner attributes) that defines `on(c, iteration)` (whether it acts in that iteration of
//! the sub-step), `load(c)` (what it keeps for a strand over the sub-step) and
//! `apply(loaded, set, s, c)`, which applies one of its sets to the strand's
//! positions `s` as the GPU's lanes do together.

use glam::{Mat4, Vec4};

use super::bodies::Bodies;
use super::dot;
use crate::gpu_types::SimStep;

/// One key hair in one sub-step, as the constraints see it.
pub(super) struct Strand<'a> {
    /// The sub-step's parameters.
    pub p: &'a SimStep,
    /// Where the hair's rest pose is placed: the head, or its root's frame.
    pub frame: &'a Mat4,
    /// Its rest positions (head frame; w: the particle's radius).
    pub rest: &'a [Vec4],
    /// Its rest lengths, segment i from point i to i + 1.
    pub lengths: &'a [f32],
    /// Its positions at the start of the sub-step.
    pub start: &'a [Vec4],
    /// The bodies of the sub-step.
    pub bodies: &'a Bodies<'a>,
}

/// Points i and j held at distance `rest_d` with stiffness `k`, both ends
/// moved by their inverse masses (`constraint_project_end` of
/// `glsl/include/constraints/common.glsl`, whose two invocations compute one
/// end each).
fn project(s: &mut [Vec4], i: usize, j: usize, rest_d: f32, k: f32) {
    let (a, b) = (s[i], s[j]);
    let w = a.w + b.w;
    let d = b.truncate() - a.truncate();
    let len = dot(d, d).sqrt();
    if w > 0.0 && len > 0.0 {
        let c = ((len - rest_d) / (len * w)) * k;
        let pa = a.truncate() + d * (a.w * c);
        let pb = b.truncate() - d * (b.w * c);
        s[i] = pa.extend(a.w);
        s[j] = pb.extend(b.w);
    }
}

/// Whether a kind of the list runs after the iterations rather than in them.
macro_rules! runs_after {
    (after) => {
        true
    };
    ($other:ident) => {
        false
    };
}

/// The CPU solve from the constraint list: each constraint's twin module and,
/// per strand and sub-step, its sets in the list's order.
macro_rules! sim_constraints {
    ($(
        $(#[doc = $doc:literal])*
        $name:ident : $kind:ident [ $($set:literal),* ] {
            $( $(#[doc = $kdoc:literal])* $knob:ident = $from:expr ),* $(,)?
        }
    )*) => {
        // Each twin is its file's items in a module of the constraint's name
        // (a `mod` written by a macro in an included file would be looked
        // for beside that file).
        $(
            $(#[doc = $doc])*
            mod $name {
                include!(concat!(env!("CARGO_MANIFEST_DIR"), "/src/sim/reference/constraints/", stringify!($name), ".rs"));
            }
        )*

        /// The position-based solve of one strand in one sub-step: `s` holds
        /// its predicted positions and receives its solved ones.
        pub(super) fn solve_strand(c: &Strand<'_>, s: &mut [Vec4]) {
            $( let $name = $name::load(c); )*
            for iteration in 0..c.p.iterations {
                $(
                    if !runs_after!($kind) && $name::on(c, iteration) {
                        for set in 0..[$($set),*].len() {
                            $name::apply(&$name, set, s, c);
                        }
                    }
                )*
            }
            $(
                if runs_after!($kind) && $name::on(c, c.p.iterations) {
                    $name::apply(&$name, 0, s, c);
                }
            )*
        }
    };
}

include!("../../../gpu_types/constraints.rs");
