//! Marschner shading through lookup tables (seed 001's factorisation): the CPU
//! mirror of `glsl/include/marschner.glsl` (the test oracle), its parameters,
//! and the GPU tables built by `glsl/render/marschner_lut.comp`.

use std::f32::consts::PI;
use std::sync::Arc;

use ash::vk;
use glam::Vec4;

use super::graph::{FrameGraph, Use};
use crate::error::{Error, Result};
use crate::gpu_types::MarschnerPush;
use crate::vk::barrier::AccessKind;
use crate::vk::device::Device;
use crate::vk::image::{Image, ImageDesc, Sampler};
use crate::vk::pipeline::ComputePipeline;
use crate::vk::shaders::RENDER_MARSCHNER_LUT_COMP;

/// Side of each lookup table, texels.
pub const TABLE_SIZE: u32 = 128;

/// Marschner model parameters (angles in radians).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MarschnerParams {
    /// Index of refraction of the fiber (1.2..=2.5). Default: 1.55.
    pub eta: f32,
    /// Longitudinal shift of the R highlight (−0.3..=0.3). Default: −0.09 (−5°).
    pub alpha: f32,
    /// Longitudinal width of R (0.02..=0.5). Default: 0.14 (8°).
    pub beta: f32,
    /// Azimuthal width of TT (0.05..=1.5). Default: 0.4.
    pub gamma_tt: f32,
    /// Azimuthal width of the TRT glints (0.05..=1.5). Default: 0.35.
    pub gamma_trt: f32,
    /// Azimuth of the TRT glints (0..=π). Default: 0.6.
    pub glint: f32,
}

impl Default for MarschnerParams {
    fn default() -> Self {
        MarschnerParams { eta: 1.55, alpha: -0.09, beta: 0.14, gamma_tt: 0.4, gamma_trt: 0.35, glint: 0.6 }
    }
}

impl MarschnerParams {
    /// Checks every field; the error names the first bad one.
    pub fn validate(&self) -> Result<()> {
        let ranges = [
            ("eta", self.eta, 1.2, 2.5),
            ("alpha", self.alpha, -0.3, 0.3),
            ("beta", self.beta, 0.02, 0.5),
            ("gamma_tt", self.gamma_tt, 0.05, 1.5),
            ("gamma_trt", self.gamma_trt, 0.05, 1.5),
            ("glint", self.glint, 0.0, PI),
        ];
        for (name, v, lo, hi) in ranges {
            if !(v.is_finite() && v >= lo && v <= hi) {
                return Err(Error::param(name, v, format!("{lo}..={hi}")));
            }
        }
        Ok(())
    }

    pub(crate) fn push(&self) -> MarschnerPush {
        MarschnerPush {
            eta: self.eta,
            alpha: self.alpha,
            beta: self.beta,
            gamma_tt: self.gamma_tt,
            gamma_trt: self.gamma_trt,
            glint: self.glint,
            size: TABLE_SIZE,
            pad0: 0,
        }
    }
}

fn gauss(width: f32, x: f32) -> f32 {
    (-0.5 * x * x / (width * width)).exp() / (width * (2.0 * PI).sqrt())
}

fn fresnel(eta: f32, cos_i: f32) -> f32 {
    let sin_t2 = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin_t2 >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin_t2).sqrt();
    let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// (M_R, M_TT, M_TRT, cos θd) at sin θi, sin θo.
pub fn m_terms(p: &MarschnerParams, sin_i: f32, sin_o: f32) -> Vec4 {
    let theta_i = sin_i.clamp(-1.0, 1.0).asin();
    let theta_o = sin_o.clamp(-1.0, 1.0).asin();
    let theta_h = 0.5 * (theta_i + theta_o);
    let theta_d = 0.5 * (theta_o - theta_i);
    Vec4::new(
        gauss(p.beta, theta_h - p.alpha),
        gauss(0.5 * p.beta, theta_h + 0.5 * p.alpha),
        gauss(2.0 * p.beta, theta_h + 1.5 * p.alpha),
        theta_d.cos(),
    )
}

/// (N_R, N_TT, N_TRT, 0) at cos φ, cos θd.
pub fn n_terms(p: &MarschnerParams, cos_phi: f32, cos_theta_d: f32) -> Vec4 {
    let phi = cos_phi.clamp(-1.0, 1.0).acos();
    let cd = cos_theta_d.max(1e-3);
    let sd2 = 1.0 - cd * cd;
    let eta_p = (p.eta * p.eta - sd2).max(1e-6).sqrt() / cd;
    let half_cos = (0.5 * phi).cos();
    let f0 = fresnel(eta_p, 1.0);
    Vec4::new(
        0.25 * half_cos * fresnel(eta_p, half_cos),
        (1.0 - f0) * (1.0 - f0) * gauss(p.gamma_tt, PI - phi),
        (1.0 - f0) * (1.0 - f0) * f0 * gauss(p.gamma_trt, phi - p.glint),
        0.0,
    )
}

/// The two tables on the GPU and the pipeline that builds them.
pub(super) struct MarschnerTables {
    pub m: Image,
    pub n: Image,
    pub sampler: Sampler,
    pipeline: ComputePipeline,
    set: vk::DescriptorSet,
    /// Parameters the tables hold, or `None` until built.
    built: Option<MarschnerParams>,
}

impl MarschnerTables {
    pub(super) fn new(device: &Arc<Device>) -> Result<Self> {
        let table = |name: &str| {
            Image::new(
                device,
                &ImageDesc {
                    name,
                    extent: vk::Extent2D { width: TABLE_SIZE, height: TABLE_SIZE },
                    format: vk::Format::R16G16B16A16_SFLOAT,
                    usage: vk::ImageUsageFlags::STORAGE
                        | vk::ImageUsageFlags::SAMPLED
                        | vk::ImageUsageFlags::TRANSFER_SRC,
                    samples: vk::SampleCountFlags::TYPE_1,
                    aspect: vk::ImageAspectFlags::COLOR,
                },
            )
        };
        let (m, n) = (table("vkhair marschner M")?, table("vkhair marschner N")?);
        let pipeline = ComputePipeline::new(device, &RENDER_MARSCHNER_LUT_COMP, 1)?;
        let set = pipeline.storage_image_set(0, &[(0, m.view()), (1, n.view())])?;
        Ok(MarschnerTables {
            m,
            n,
            sampler: Sampler::new(device, "vkhair marschner tables", false)?,
            pipeline,
            set,
            built: None,
        })
    }

    /// Records a rebuild when `params` differ from what the tables hold,
    /// declaring the tables' writes to `graph` (whose later uses, or settling,
    /// return them to SHADER_READ_ONLY_OPTIMAL, their layout at rest).
    ///
    /// # Safety
    /// `cmd` is recording outside a render pass; every earlier command on the
    /// tables since `graph` was made was declared to it.
    pub(super) unsafe fn record_update(
        &mut self,
        device: &Device,
        cmd: vk::CommandBuffer,
        graph: &mut FrameGraph,
        params: &MarschnerParams,
    ) {
        if self.built.as_ref() == Some(params) {
            return;
        }
        let writes = [&self.m, &self.n].map(|t| {
            let sampled = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
            Use::image(t, &[AccessKind::ComputeWrite], vk::ImageLayout::GENERAL, sampled).discarding()
        });
        // SAFETY: guaranteed by the caller.
        unsafe {
            graph.record(device, cmd, &writes);
            self.pipeline.bind(cmd, &[self.set]);
            self.pipeline.push(cmd, &params.push());
            self.pipeline.dispatch_threads(cmd, [TABLE_SIZE, TABLE_SIZE, 1]);
        }
        self.built = Some(*params);
    }

    /// The tables as the draw samples them (fragment stages; the transparent
    /// modes' vertex shading, a compute dispatch).
    pub(super) fn sampled_uses(&self) -> [Use; 2] {
        let sampled = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
        let kinds = &[AccessKind::FragmentSampledRead, AccessKind::ComputeSampledRead];
        [&self.m, &self.n].map(|t| Use::image(t, kinds, sampled, sampled))
    }

    /// Reads a table back as RGBA f32 texels, row by row (tests; submits and waits).
    pub(super) fn read(&self, device: &Arc<Device>, which_n: bool) -> Result<Vec<Vec4>> {
        let image = if which_n { &self.n } else { &self.m };
        let bytes = device.readback_image(image, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL, 8)?;
        Ok(bytes
            .chunks_exact(8)
            .map(|c| {
                let h = |i: usize| f16_to_f32(u16::from_le_bytes([c[2 * i], c[2 * i + 1]]));
                Vec4::new(h(0), h(1), h(2), h(3))
            })
            .collect())
    }
}

/// IEEE half to single precision.
fn f16_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exponent = i32::from((h >> 10) & 0x1f);
    let mantissa = f32::from(h & 0x3ff);
    sign * match exponent {
        0 => mantissa * 2f32.powi(-24),
        31 => f32::INFINITY,
        e => (1.0 + mantissa / 1024.0) * 2f32.powi(e - 15),
    }
}
