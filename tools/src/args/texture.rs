//! `--scalp-texture`: a PNG sampled at each strand's root UV for its colour.

use std::path::Path;

use glam::{Vec2, Vec3};

use crate::output::Error;

/// The largest scalp texture read (64 MiB of file).
const MAX_TEXTURE_BYTES: u64 = 64 << 20;
/// The most texels a scalp texture may declare (8192 × 8192), checked before
/// decoding.
const MAX_TEXELS: u64 = 8192 * 8192;

/// A decoded texture: linear RGB texels, rows from the top.
pub struct Texture {
    width: usize,
    height: usize,
    texels: Vec<Vec3>,
}

/// sRGB-encoded `c` (0..=1) as linear.
fn linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

impl Texture {
    /// Reads the PNG at `path` (any bit depth and colour type; taken as sRGB).
    pub fn open(path: &Path) -> Result<Texture, Error> {
        let cap = vkhair::files::input_cap(MAX_TEXTURE_BYTES)?;
        let bytes = vkhair::files::read_capped(path, cap, "a scalp texture")?;
        let bad = |e: png::DecodingError| -> Error { format!("{}: not a PNG image: {e}", path.display()).into() };
        let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
        decoder.set_transformations(png::Transformations::normalize_to_color8());
        let mut reader = decoder.read_info().map_err(bad)?;
        let (w, h) = (reader.info().width, reader.info().height);
        if u64::from(w) * u64::from(h) > MAX_TEXELS {
            return Err(format!(
                "{}: a {w}×{h} image; a scalp texture has at most {MAX_TEXELS} texels",
                path.display()
            )
            .into());
        }
        let size = reader.output_buffer_size().ok_or_else(|| format!("{}: the image is too large", path.display()))?;
        let mut buf = vec![0u8; size];
        let info = reader.next_frame(&mut buf).map_err(bad)?;
        let channels = info.color_type.samples();
        let (width, height) = (info.width as usize, info.height as usize);
        let texels = buf[..info.buffer_size()]
            .chunks_exact(channels)
            .map(|p| {
                let c = |i: usize| linear(f32::from(p[i.min(channels - 1)]) / 255.0);
                // Gray (and gray with alpha) repeats its one channel.
                if channels < 3 {
                    Vec3::splat(c(0))
                } else {
                    Vec3::new(c(0), c(1), c(2))
                }
            })
            .collect();
        Ok(Texture { width, height, texels })
    }

    /// The colour at `uv` (v up, as curve files store root UVs; the texture
    /// repeats), bilinearly filtered.
    pub fn sample(&self, uv: Vec2) -> Vec3 {
        let (w, h) = (self.width as f32, self.height as f32);
        let x = uv.x.rem_euclid(1.0) * w - 0.5;
        let y = (1.0 - uv.y.rem_euclid(1.0)) * h - 0.5;
        let at = |i: f32, j: f32| {
            let i = (i as isize).rem_euclid(self.width as isize) as usize;
            let j = (j as isize).clamp(0, self.height as isize - 1) as usize;
            self.texels[j * self.width + i]
        };
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let top = at(x0, y0).lerp(at(x0 + 1.0, y0), fx);
        let bottom = at(x0, y0 + 1.0).lerp(at(x0 + 1.0, y0 + 1.0), fx);
        top.lerp(bottom, fy)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A file past 64 MiB is refused by its size, unread; an image declaring
    /// more than 8192 × 8192 texels by its header, before decoding.
    #[test]
    fn a_texture_is_bounded_by_its_file_and_its_texels() {
        let dir = tempfile::tempdir().expect("temp dir");
        let big = dir.path().join("big.png");
        let file = std::fs::File::create(&big).expect("create");
        // Sparse: no 65 MiB written.
        file.set_len((64 << 20) + 1).expect("length");
        let err = Texture::open(&big).err().expect("refused").to_string();
        assert!(err.contains("big.png") && err.contains("67108864"), "{err}");
        let wide = dir.path().join("wide.png");
        let mut bytes = Vec::new();
        {
            let encoder = png::Encoder::new(&mut bytes, 9000, 9000);
            let mut writer = encoder.write_header().expect("header");
            // The header of an image of 81 M texels, then the start of its data.
            writer.write_chunk(png::chunk::IDAT, &[0u8; 16]).expect("a data chunk");
        }
        std::fs::write(&wide, &bytes).expect("write");
        let err = Texture::open(&wide).err().expect("refused").to_string();
        assert!(err.contains("wide.png") && err.contains("9000×9000") && err.contains("67108864 texels"), "{err}");
    }
}
