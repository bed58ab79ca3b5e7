//! An offscreen colour + depth target standing in for a host's swapchain image.

use std::sync::Arc;

use ash::vk;
use glam::{Vec3, Vec4};

use crate::context::GpuContext;
use crate::error::{Error, Result};
use crate::render::RenderTarget;
use crate::vk::barrier::{self, AccessKind};
use crate::vk::buffer::Buffer;
use crate::vk::device::Device;
use crate::vk::image::{Image, ImageDesc};
use crate::vk::rendering::{self, Load};

/// Color format of [`Offscreen`] (shading is linear; the target encodes sRGB).
pub const OFFSCREEN_COLOR: vk::Format = vk::Format::R8G8B8A8_SRGB;
/// Depth format of [`Offscreen`].
pub const OFFSCREEN_DEPTH: vk::Format = vk::Format::D32_SFLOAT;
/// The colour formats [`Offscreen::with_format`] makes and reads back: 8-bit
/// sRGB (the default), half-float HDR and packed unsigned floats. The hair's
/// shading is linear in all three; the target stores it as its format does.
pub const OFFSCREEN_COLOR_FORMATS: [vk::Format; 3] =
    [vk::Format::R8G8B8A8_SRGB, vk::Format::R16G16B16A16_SFLOAT, vk::Format::B10G11R11_UFLOAT_PACK32];

/// Bytes per texel of an [`OFFSCREEN_COLOR_FORMATS`] format.
fn texel_bytes(format: vk::Format) -> u64 {
    if format == vk::Format::R16G16B16A16_SFLOAT {
        8
    } else {
        4
    }
}

/// An offscreen single-sample color + depth target.
pub struct Offscreen {
    device: Arc<Device>,
    color: Image,
    /// `color`'s format, one of [`OFFSCREEN_COLOR_FORMATS`].
    format: vk::Format,
    depth: Image,
    /// Host-visible copy target of `color`, kept between reads.
    readback: Buffer,
    /// Host-visible copy of `color` taken mid-frame ([`Offscreen::record_snapshot`]),
    /// made by [`Offscreen::keep_snapshots`].
    snapshot: Option<Buffer>,
    /// A velocity image, made by [`Offscreen::add_velocity`].
    velocity: Option<Velocity>,
}

/// An [`Offscreen`]'s velocity image, its readback buffer and what a clear writes.
struct Velocity {
    image: Image,
    format: vk::Format,
    readback: Buffer,
    clear: glam::Vec2,
}

impl Offscreen {
    /// A `width` × `height` target (1..=8192 each) of [`OFFSCREEN_COLOR`].
    pub fn new(ctx: &GpuContext, width: u32, height: u32) -> Result<Self> {
        Self::with_format(ctx, width, height, OFFSCREEN_COLOR)
    }

    /// A `width` × `height` target (1..=8192 each) whose colour image has
    /// `format`, one of [`OFFSCREEN_COLOR_FORMATS`]; refused for another
    /// format, or one the device cannot render and blend into.
    pub fn with_format(ctx: &GpuContext, width: u32, height: u32, format: vk::Format) -> Result<Self> {
        if !(1..=8192).contains(&width) || !(1..=8192).contains(&height) {
            return Err(Error::param("extent", format!("{width}×{height}"), "1..=8192 × 1..=8192"));
        }
        if !OFFSCREEN_COLOR_FORMATS.contains(&format) {
            return Err(Error::param(
                "offscreen format",
                format!("{format:?}"),
                "R8G8B8A8_SRGB, R16G16B16A16_SFLOAT or B10G11R11_UFLOAT_PACK32",
            ));
        }
        let device = ctx.device.clone();
        let needed = vk::FormatFeatureFlags::COLOR_ATTACHMENT_BLEND | vk::FormatFeatureFlags::TRANSFER_SRC;
        if !device.optimal_tiling_features(format).contains(needed) {
            return Err(Error::incompatible(
                "offscreen format",
                format!("{format:?} is not a blendable colour attachment on this device"),
            ));
        }
        let extent = vk::Extent2D { width, height };
        let color = Image::new(
            &device,
            &ImageDesc {
                name: "offscreen color",
                extent,
                format,
                usage: vk::ImageUsageFlags::COLOR_ATTACHMENT
                    | vk::ImageUsageFlags::TRANSFER_SRC
                    | vk::ImageUsageFlags::SAMPLED,
                samples: vk::SampleCountFlags::TYPE_1,
                aspect: vk::ImageAspectFlags::COLOR,
            },
        )?;
        let depth = Image::new(
            &device,
            &ImageDesc {
                name: "offscreen depth",
                extent,
                format: OFFSCREEN_DEPTH,
                // Transfer source: the compute rasteriser copies the depth out.
                usage: vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
                samples: vk::SampleCountFlags::TYPE_1,
                aspect: vk::ImageAspectFlags::DEPTH,
            },
        )?;
        let bytes = u64::from(width) * u64::from(height) * texel_bytes(format);
        let readback = device.readback_staging("offscreen readback", bytes)?;
        Ok(Offscreen { device, color, format, depth, readback, snapshot: None, velocity: None })
    }

    /// Gives the target a velocity image of `format` (one of
    /// [`crate::render::VELOCITY_FORMATS`]) for the hair's motion vectors
    /// ([`RenderTarget::velocity`]), which [`Offscreen::record_clear`] clears
    /// to `clear` (pixels, or whatever units the renderer writes).
    pub fn add_velocity(&mut self, format: vk::Format, clear: glam::Vec2) -> Result<()> {
        if !crate::render::VELOCITY_FORMATS.contains(&format) {
            return Err(Error::param("velocity format", format!("{format:?}"), "R16G16_SFLOAT or R32G32_SFLOAT"));
        }
        let needed = vk::FormatFeatureFlags::COLOR_ATTACHMENT | vk::FormatFeatureFlags::TRANSFER_SRC;
        if !self.device.optimal_tiling_features(format).contains(needed) {
            return Err(Error::incompatible("velocity format", format!("{format:?} is not a colour attachment here")));
        }
        let image = Image::new(
            &self.device,
            &ImageDesc {
                name: "offscreen velocity",
                extent: self.color.extent,
                format,
                usage: vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
                samples: vk::SampleCountFlags::TYPE_1,
                aspect: vk::ImageAspectFlags::COLOR,
            },
        )?;
        let texel = if format == vk::Format::R16G16_SFLOAT { 4 } else { 8 };
        let (w, h) = self.size();
        let bytes = u64::from(w) * u64::from(h) * texel;
        let readback = self.device.readback_staging("offscreen velocity readback", bytes)?;
        self.velocity = Some(Velocity { image, format, readback, clear });
        Ok(())
    }

    /// Reads the velocity image back, rows top to bottom (this submits and
    /// waits); refused without [`Offscreen::add_velocity`].
    pub fn read_velocity(&self) -> Result<Vec<glam::Vec2>> {
        let v = self
            .velocity
            .as_ref()
            .ok_or_else(|| Error::incompatible("offscreen velocity", "read_velocity before add_velocity"))?;
        let mut bytes = Vec::new();
        let layout = vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL;
        self.device.readback_image_via(&v.image, layout, &v.readback, &mut bytes)?;
        Ok(super::texels::decode_velocity(v.format, &bytes))
    }

    /// Makes the buffer [`Offscreen::record_snapshot`] copies into (as large
    /// as the colour image; once).
    pub fn keep_snapshots(&mut self) -> Result<()> {
        if self.snapshot.is_none() {
            let (w, h) = self.size();
            let bytes = u64::from(w) * u64::from(h) * texel_bytes(self.format);
            self.snapshot = Some(self.device.readback_staging("offscreen snapshot", bytes)?);
        }
        Ok(())
    }

    /// Records a copy of the colour image as it is at this point of the frame
    /// (after [`Offscreen::record_clear`], between passes) into the snapshot
    /// buffer, read after the submission by [`Offscreen::read_snapshot_into`];
    /// the image is left in `COLOR_ATTACHMENT_OPTIMAL`, its copy ordered before
    /// later attachment reads and writes. Refused without
    /// [`Offscreen::keep_snapshots`].
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of the context's device, outside a
    /// render pass, after this target's clear in the same frame.
    pub unsafe fn record_snapshot(&self, cmd: vk::CommandBuffer) -> Result<()> {
        let snapshot = self
            .snapshot
            .as_ref()
            .ok_or_else(|| Error::incompatible("offscreen snapshot", "record_snapshot before keep_snapshots"))?;
        let d = &self.device;
        let region = crate::vk::staging::whole_image_region(&self.color);
        let attachment = vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL;
        let source = vk::ImageLayout::TRANSFER_SRC_OPTIMAL;
        // SAFETY: guaranteed by the caller; both resources belong to this device.
        unsafe {
            d.cmd_transition(
                cmd,
                &self.color,
                barrier::COLOR_ATTACHMENT,
                &[AccessKind::TransferRead],
                (attachment, source),
            );
            d.raw.cmd_copy_image_to_buffer(cmd, self.color.raw(), source, snapshot.raw(), &[region]);
            d.cmd_barrier(
                cmd,
                &[],
                &[barrier::buffer(snapshot, &[AccessKind::TransferWrite], &[AccessKind::HostRead])],
                &[barrier::image(
                    &self.color,
                    &[AccessKind::TransferRead],
                    barrier::COLOR_ATTACHMENT,
                    source,
                    attachment,
                )],
            );
        }
        Ok(())
    }

    /// The colour image as [`Offscreen::record_snapshot`] copied it, rows top
    /// to bottom in the target's format (sRGB RGBA8 for [`Offscreen::new`]),
    /// into `out` (its memory reused). Call after the frame that recorded the
    /// snapshot has completed.
    pub fn read_snapshot_into(&self, out: &mut Vec<u8>) -> Result<()> {
        let snapshot = self
            .snapshot
            .as_ref()
            .ok_or_else(|| Error::incompatible("offscreen snapshot", "read_snapshot_into before keep_snapshots"))?;
        let bytes = snapshot
            .mapped()
            .and_then(|b| b.get(..snapshot.size() as usize))
            .ok_or_else(|| Error::device("staging memory", "the snapshot buffer could not be mapped whole"))?;
        out.clear();
        out.extend_from_slice(bytes);
        Ok(())
    }

    /// The target for [`crate::render::Renderer::record_draw`] and [`super::MeshDrawer::record`].
    pub fn target(&self) -> RenderTarget {
        RenderTarget {
            color: self.color.view(),
            color_format: self.format,
            depth: self.depth.view(),
            depth_format: OFFSCREEN_DEPTH,
            depth_image: self.depth.raw(),
            velocity: self.velocity.as_ref().map_or(vk::ImageView::null(), |v| v.image.view()),
            velocity_format: self.velocity.as_ref().map_or(vk::Format::UNDEFINED, |v| v.format),
            extent: self.color.extent,
            samples: vk::SampleCountFlags::TYPE_1,
        }
    }

    /// Records a clear of color (to `rgb`, linear) and depth (to 1), leaving both in
    /// attachment layouts. Earlier contents are discarded.
    ///
    /// # Safety
    /// `cmd` is a recording command buffer of the context's device, outside a render
    /// pass; earlier work on this target was submitted before it on the same queue.
    pub unsafe fn record_clear(&self, cmd: vk::CommandBuffer, rgb: Vec3) {
        // SAFETY: guaranteed by the caller.
        unsafe { self.record_clear_to(cmd, rgb, 1.0) }
    }

    /// As [`Offscreen::record_clear`], the depth cleared to `depth` (0 for a
    /// reversed depth buffer, whose far is 0).
    ///
    /// # Safety
    /// As [`Offscreen::record_clear`].
    pub unsafe fn record_clear_to(&self, cmd: vk::CommandBuffer, rgb: Vec3, depth: f32) {
        let d = &self.device;
        let to_color = barrier::image(
            &self.color,
            barrier::ANY,
            barrier::COLOR_ATTACHMENT,
            vk::ImageLayout::UNDEFINED,
            vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
        );
        let to_depth = barrier::image(
            &self.depth,
            barrier::ANY,
            barrier::DEPTH_ATTACHMENT,
            vk::ImageLayout::UNDEFINED,
            vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL,
        );
        let mut color = vec![rendering::color(self.color.view(), Load::color([rgb.x, rgb.y, rgb.z, 1.0]))];
        let mut images = vec![to_color, to_depth];
        if let Some(v) = &self.velocity {
            color.push(rendering::color(v.image.view(), Load::color([v.clear.x, v.clear.y, 0.0, 0.0])));
            images.push(barrier::image(
                &v.image,
                barrier::ANY,
                barrier::COLOR_ATTACHMENT,
                vk::ImageLayout::UNDEFINED,
                vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
            ));
        }
        let depth = rendering::depth(self.depth.view(), Load::depth(depth));
        let rendering = rendering::info(self.color.extent, &color, Some(&depth));
        // SAFETY: guaranteed by the caller.
        unsafe {
            d.cmd_barrier(cmd, &[], &[], &images);
            d.raw.cmd_begin_rendering(cmd, &rendering);
            d.raw.cmd_end_rendering(cmd);
        }
    }

    /// Reads the color image back as sRGB-encoded RGBA8 rows, top to bottom
    /// (this submits and waits).
    pub fn read_rgba8(&self) -> Result<Vec<u8>> {
        let mut out = Vec::new();
        self.read_rgba8_into(&mut out)?;
        Ok(out)
    }

    /// [`Offscreen::read_rgba8`] into `out`, reusing its memory (and the
    /// target's own staging buffer): reading every frame allocates nothing.
    /// Refused for a target of another format than [`OFFSCREEN_COLOR`]
    /// ([`Offscreen::read_linear`] reads every format).
    pub fn read_rgba8_into(&self, out: &mut Vec<u8>) -> Result<()> {
        if self.format != OFFSCREEN_COLOR {
            return Err(Error::incompatible(
                "offscreen readback",
                format!("read_rgba8 of a {:?} target (read_linear reads it)", self.format),
            ));
        }
        self.device.readback_image_via(&self.color, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL, &self.readback, out)
    }

    /// Reads the colour image back as linear RGBA, rows top to bottom, whatever
    /// its format: sRGB decoded, half and packed floats widened (the packed
    /// format has no alpha: 1). This submits and waits.
    pub fn read_linear(&self) -> Result<Vec<Vec4>> {
        let mut bytes = Vec::new();
        self.device.readback_image_via(
            &self.color,
            vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
            &self.readback,
            &mut bytes,
        )?;
        Ok(super::texels::decode(self.format, &bytes))
    }

    /// The colour image's format.
    pub fn format(&self) -> vk::Format {
        self.format
    }

    /// Width and height.
    pub fn size(&self) -> (u32, u32) {
        (self.color.extent.width, self.color.extent.height)
    }
}
