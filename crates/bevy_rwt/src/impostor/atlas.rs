//! The atlas a bake fills: its texels before encoding, one level of it (both halves), the
//! mip chain that keeps a cut-out's coverage, and the sRGB image with its sampler.

use super::frames::ImpostorFrames;
use bevy::asset::RenderAssetUsages;
use bevy::image::{ImageAddressMode, ImageFilterMode, ImageSampler, ImageSamplerDescriptor};
use bevy::prelude::*;
use bevy::render::render_resource::{Extent3d, TextureDimension, TextureFormat};

/// One texel of the atlas before encoding: linear albedo, coverage, normal.
#[derive(Clone, Copy, Default)]
pub(super) struct Texel {
    pub albedo: Vec3,
    pub coverage: f32,
    pub normal: Vec3,
}

/// One mip level of the whole atlas: albedo texels on the left, normals on the right (each
/// with the coverage of its view's texel).
pub(super) struct Level {
    size: UVec2,
    texels: Vec<Texel>,
}

impl Level {
    pub fn new(size: UVec2) -> Self {
        Self {
            size,
            texels: vec![Texel::default(); (size.x * size.y) as usize],
        }
    }

    pub fn set(&mut self, x: u32, y: u32, texel: Texel) {
        self.texels[(y * self.size.x + x) as usize] = texel;
    }

    /// A normal texel: the normal stored as the albedo's place holds colour.
    pub fn set_normal(&mut self, x: u32, y: u32, texel: Texel) {
        self.set(
            x,
            y,
            Texel {
                albedo: texel.normal * 0.5 + Vec3::splat(0.5),
                ..texel
            },
        );
    }

    /// Spreads colour into uncovered texels next to covered ones, `steps` times, so that
    /// filtering at an outline blends with the outline's colour, not black.
    pub fn dilate(&mut self, steps: u32) {
        let (w, h) = (self.size.x as i64, self.size.y as i64);
        let mut filled: Vec<bool> = self.texels.iter().map(|t| t.coverage > 0.0).collect();
        for _ in 0..steps {
            let mut next = self.texels.clone();
            let mut now = filled.clone();
            for y in 0..h {
                for x in 0..w {
                    let k = (y * w + x) as usize;
                    if filled[k] {
                        continue;
                    }
                    let (mut sum, mut count) = (Vec3::ZERO, 0.0);
                    for (dx, dy) in [(-1, 0), (1, 0), (0, -1), (0, 1)] {
                        let (nx, ny) = (x + dx, y + dy);
                        if nx >= 0 && ny >= 0 && nx < w && ny < h && filled[(ny * w + nx) as usize]
                        {
                            sum += self.texels[(ny * w + nx) as usize].albedo;
                            count += 1.0;
                        }
                    }
                    if count > 0.0 {
                        next[k].albedo = sum / count;
                        now[k] = true;
                    }
                }
            }
            self.texels = next;
            filled = now;
        }
    }

    /// The next level down: 2x2 boxes, colour weighted by coverage (uncovered texels keep
    /// their dilated colour).
    fn half(&self) -> Self {
        let size = (self.size / 2).max(UVec2::ONE);
        let mut out = Self::new(size);
        for y in 0..size.y {
            for x in 0..size.x {
                let mut sum = Texel::default();
                let mut plain = Vec3::ZERO;
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let (sx, sy) = (
                        (2 * x + dx).min(self.size.x - 1),
                        (2 * y + dy).min(self.size.y - 1),
                    );
                    let t = self.texels[(sy * self.size.x + sx) as usize];
                    sum.albedo += t.albedo * t.coverage;
                    sum.coverage += t.coverage;
                    plain += t.albedo;
                }
                out.set(
                    x,
                    y,
                    Texel {
                        albedo: if sum.coverage > 0.0 {
                            sum.albedo / sum.coverage
                        } else {
                            plain / 4.0
                        },
                        coverage: sum.coverage / 4.0,
                        normal: Vec3::ZERO,
                    },
                );
            }
        }
        out
    }

    /// The share of texels whose coverage, times `gain`, reaches `cutoff`.
    pub fn kept(&self, cutoff: f32, gain: f32) -> f32 {
        let kept = self
            .texels
            .iter()
            .filter(|t| (t.coverage * gain).min(1.0) >= cutoff)
            .count();
        kept as f32 / self.texels.len() as f32
    }

    /// The gain on coverage that keeps the share `target` of texels at the cut-off (alpha
    /// averaged down a mip chain thins a cut-out; this keeps it as dense).
    fn gain_for(&self, cutoff: f32, target: f32) -> f32 {
        let (mut lo, mut hi) = (1.0f32, 16.0f32);
        if self.kept(cutoff, lo) >= target {
            return lo;
        }
        for _ in 0..24 {
            let mid = 0.5 * (lo + hi);
            if self.kept(cutoff, mid) < target {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        hi
    }

    /// The level as sRGB bytes, coverage times `gain` in alpha.
    fn encode(&self, gain: f32, out: &mut Vec<u8>) {
        for t in &self.texels {
            let c = Srgba::from(LinearRgba::rgb(t.albedo.x, t.albedo.y, t.albedo.z))
                .to_u8_array_no_alpha();
            out.extend_from_slice(&c);
            out.push(((t.coverage * gain).clamp(0.0, 1.0) * 255.0).round() as u8);
        }
    }
}

/// The atlas image: every level down to 4 texels a view, sampled linearly and clamped.
pub(super) fn atlas_image(frames: &ImpostorFrames, base: Level, cutoff: f32) -> Image {
    let levels = frames.texels.trailing_zeros().saturating_sub(1).max(1);
    let target = base.kept(cutoff, 1.0);
    let mut data = Vec::new();
    base.encode(1.0, &mut data);
    let mut level = base;
    for _ in 1..levels {
        level = level.half();
        let gain = level.gain_for(cutoff, target);
        level.encode(gain, &mut data);
    }
    let size = frames.size();
    let mut image = Image::new_uninit(
        Extent3d {
            width: size.x,
            height: size.y,
            depth_or_array_layers: 1,
        },
        TextureDimension::D2,
        TextureFormat::Rgba8UnormSrgb,
        RenderAssetUsages::RENDER_WORLD | RenderAssetUsages::MAIN_WORLD,
    );
    image.data = Some(data);
    image.texture_descriptor.mip_level_count = levels;
    image.sampler = ImageSampler::Descriptor(ImageSamplerDescriptor {
        address_mode_u: ImageAddressMode::ClampToEdge,
        address_mode_v: ImageAddressMode::ClampToEdge,
        mag_filter: ImageFilterMode::Linear,
        min_filter: ImageFilterMode::Linear,
        mipmap_filter: ImageFilterMode::Linear,
        ..default()
    });
    image
}
