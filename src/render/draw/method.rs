//! The one value that selects how a frame's hair reaches the target.

use crate::render::{Raster, Transparency};

/// How a frame's hair reaches the target: [`Transparency`] and, for the exact
/// mode, the resolved [`Raster`], taken together once per frame
/// (`Renderer::draw_method`). The draw pass selects its recording by it, and
/// the transparency pass its resources, pipelines and steps by what it asks
/// of them (its methods), rather than matching the two settings apart.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(in crate::render) enum DrawMethod {
    /// Opaque ribbons or lines with a depth pre-pass (`opaque.rs`).
    Opaque,
    /// Weighted blended sums through the hardware raster pipeline (`fast.rs`).
    Weighted,
    /// Per-pixel lists built by the hardware raster pipeline (`exact.rs`),
    /// walked by the composite's fragment stage.
    HardwareLists,
    /// Per-pixel lists built by the compute rasteriser (`raster.rs`), resolved
    /// by a compute dispatch before the composite.
    ComputeLists,
    /// The tiled compute rasteriser (`tiles.rs`): no per-pixel lists, its fine
    /// pass the resolve.
    Tiles,
}

impl DrawMethod {
    /// The method of `transparency` with `raster` (resolved for the device;
    /// only the exact mode has a choice of rasteriser).
    pub(in crate::render) fn of(transparency: Transparency, raster: Raster) -> DrawMethod {
        debug_assert_ne!(raster, Raster::Auto, "the raster is resolved for the device first");
        match (transparency, raster) {
            (Transparency::Off, _) => DrawMethod::Opaque,
            (Transparency::Fast, _) => DrawMethod::Weighted,
            (Transparency::Exact, Raster::Tiles) => DrawMethod::Tiles,
            (Transparency::Exact, Raster::Compute) => DrawMethod::ComputeLists,
            (Transparency::Exact, _) => DrawMethod::HardwareLists,
        }
    }

    /// The rasteriser that makes the fragments.
    pub(in crate::render) fn raster(self) -> Raster {
        match self {
            DrawMethod::ComputeLists => Raster::Compute,
            DrawMethod::Tiles => Raster::Tiles,
            _ => Raster::Hardware,
        }
    }

    /// Whether the hair is composited with exact sorting (per-pixel lists or tiles).
    pub(in crate::render) fn exact(self) -> bool {
        matches!(self, DrawMethod::HardwareLists | DrawMethod::ComputeLists | DrawMethod::Tiles)
    }

    /// Whether fragments are kept in per-pixel lists (and a pool).
    pub(in crate::render) fn lists(self) -> bool {
        matches!(self, DrawMethod::HardwareLists | DrawMethod::ComputeLists)
    }

    /// Whether a compute rasteriser makes the fragments (reading the target's
    /// depth from a copy, resolving in compute before the composite).
    pub(in crate::render) fn compute(self) -> bool {
        matches!(self, DrawMethod::ComputeLists | DrawMethod::Tiles)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each transparency mode with each resolved rasteriser that matters to it
    /// maps to the method that draws it, and each method answers for itself.
    #[test]
    fn settings_select_one_method() {
        let cases = [
            (Transparency::Off, Raster::Compute, DrawMethod::Opaque),
            (Transparency::Fast, Raster::Tiles, DrawMethod::Weighted),
            (Transparency::Exact, Raster::Hardware, DrawMethod::HardwareLists),
            (Transparency::Exact, Raster::Compute, DrawMethod::ComputeLists),
            (Transparency::Exact, Raster::Tiles, DrawMethod::Tiles),
        ];
        for (transparency, raster, method) in cases {
            assert_eq!(DrawMethod::of(transparency, raster), method, "{transparency:?} with {raster:?}");
        }
        let (lists, compute): (Vec<_>, Vec<_>) = [
            DrawMethod::Opaque,
            DrawMethod::Weighted,
            DrawMethod::HardwareLists,
            DrawMethod::ComputeLists,
            DrawMethod::Tiles,
        ]
        .iter()
        .map(|m| (m.lists(), m.compute()))
        .unzip();
        assert_eq!(lists, [false, false, true, true, false]);
        assert_eq!(compute, [false, false, false, true, true]);
        assert_eq!(DrawMethod::Tiles.raster(), Raster::Tiles);
        assert!(DrawMethod::Tiles.exact() && !DrawMethod::Weighted.exact());
    }
}
