//! The GPU backend: the CPU decides, per triangle, which shadow polygons a component casts
//! and into which map (culling, splitting, dilation bands, prisms: `cpu::draw`), and the
//! GPU rasterizes the polygons of many components at once (`shadow.wgsl`, one thread per
//! polygon, atomic ORs into the maps' words); the CPU then grows the bands and tests the
//! preferred directions (`cpu::finish`). The maps are the same bit sets the CPU draws, up
//! to f32 rounding, which the shader absorbs by marking pixels within a hair of a shadow:
//! the GPU errs on the blocked side only.
//!
//! [`Gpu::new`] finds a headless adapter (Vulkan: a real GPU, or Mesa's lavapipe on a
//! machine without one).
//!
//! **Decision: rasterize the CPU's polygons, not rays.** An exact per-pixel test on the
//! GPU would call free what the CPU's rounded-up dilations block, so the two would
//! disagree on whole bands of pixels; rasterizing the CPU's own polygons agrees on
//! 99.99 % of cells (the rest blocked on the GPU only). The per-triangle decisions
//! (culling, splitting, bands, prisms) stay on the CPU: they are branchy, cheap, and
//! shared by both backends, so their conservativeness is proved once.
//!
//! **Decision: `--backend cpu` is the default.** f32 rounding on the GPU can block a
//! few more pixels and so change a plan's choices; "same input, same bytes on any
//! machine" holds for the default, and `auto`/`gpu` trade it for speed where there is a
//! GPU. `auto` takes hardware adapters only: on lavapipe the shader runs several times
//! slower than the CPU backend (one thread per polygon, whose loops diverge on
//! llvmpipe's SIMD lanes). Vulkan only (wgpu's `vulkan` feature): it is what lavapipe
//! offers and what Linux CMM workstations have; each further wgpu backend is one
//! feature flag.

use super::cpu::{self, Canvas, Drawn};
use super::cubemap::CubeMap;
use super::probe::Component;
use super::raster::Coverage;
use super::scene::Scene;
use super::{Backend, Query};
use crate::geometry::{P3, V3};
use rayon::prelude::*;
use wgpu::util::DeviceExt;

/// Words per draw record (see `shadow.wgsl`).
const DRAW_WORDS: usize = 40;
/// The most draws one dispatch takes (6.4 MB of records).
const MAX_DRAWS: usize = 40_000;
/// Queries drawn on the CPU before their polygons are submitted together.
const CHUNK: usize = 32;
/// The most bytes of maps one submission writes (far under wgpu's least binding limit,
/// 128 MiB); a query whose maps alone exceed it is computed on the CPU.
const MAP_BUDGET: usize = 32 << 20;

/// A wgpu device with the shadow pipeline.
pub struct Gpu {
    software: bool,
    /// Set by wgpu's error handler (out of memory, a lost device): the maps of the
    /// submission in flight are not trusted, and the CPU computes them instead.
    failed: std::sync::Arc<std::sync::atomic::AtomicBool>,
    device: wgpu::Device,
    queue: wgpu::Queue,
    pipeline: wgpu::ComputePipeline,
    adapter: String,
}

impl std::fmt::Debug for Gpu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Gpu")
            .field("adapter", &self.adapter)
            .finish()
    }
}

impl Gpu {
    /// A headless device on the first adapter wgpu finds, or why there is none.
    pub fn new() -> Result<Gpu, String> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends: wgpu::Backends::VULKAN,
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        });
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
            apply_limit_buckets: false,
        }))
        .map_err(|e| e.to_string())?;
        let info = adapter.get_info();
        let name = format!("{} ({:?})", info.name, info.device_type);
        let software = info.device_type == wgpu::DeviceType::Cpu;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("inspc"),
            required_features: wgpu::Features::empty(),
            required_limits: wgpu::Limits::downlevel_defaults(),
            ..Default::default()
        }))
        .map_err(|e| e.to_string())?;
        let failed = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        let flag = failed.clone();
        device.on_uncaptured_error(std::sync::Arc::new(move |_e: wgpu::Error| {
            flag.store(true, std::sync::atomic::Ordering::SeqCst);
        }));
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("shadow"),
            source: wgpu::ShaderSource::Wgsl(include_str!("shadow.wgsl").into()),
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("shadow"),
            layout: None,
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
        if failed.load(std::sync::atomic::Ordering::SeqCst) {
            return Err("the shadow shader did not compile on this adapter".into());
        }
        Ok(Gpu {
            software,
            failed,
            device,
            queue,
            pipeline,
            adapter: name,
        })
    }

    /// Whether the adapter runs on the CPU (Mesa's lavapipe, say).
    pub(crate) fn is_software(&self) -> bool {
        self.software
    }

    /// The adapter's name and kind, for the summary.
    pub fn adapter(&self) -> &str {
        &self.adapter
    }

    /// Rasterizes `draws` (records of [`DRAW_WORDS`] words) into `maps` cube maps of
    /// resolution `n`: their pixel words, `words_per_map` each.
    fn raster(&self, draws: &[u32], maps: usize, n: u32, words_per_map: usize) -> Vec<u32> {
        let out_size = (maps * words_per_map * 4).max(4) as u64;
        let out = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("maps"),
            size: out_size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("read back"),
            size: out_size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let layout = self.pipeline.get_bind_group_layout(0);
        let mut encoder = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
        for piece in draws.chunks(MAX_DRAWS * DRAW_WORDS) {
            let count = (piece.len() / DRAW_WORDS) as u32;
            let params = [n, words_per_map as u32, count, 0];
            let params = self
                .device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("params"),
                    contents: bytemuck::cast_slice(&params),
                    usage: wgpu::BufferUsages::UNIFORM,
                });
            let records = self
                .device
                .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("draws"),
                    contents: bytemuck::cast_slice(piece),
                    usage: wgpu::BufferUsages::STORAGE,
                });
            let bind = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout: &layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: params.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: records.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: out.as_entire_binding(),
                    },
                ],
            });
            let groups = count.div_ceil(64);
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor::default());
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups(groups.min(65_535), groups.div_ceil(65_535), 1);
        }
        encoder.copy_buffer_to_buffer(&out, 0, &staging, 0, out_size);
        self.queue.submit([encoder.finish()]);
        let slice = staging.slice(..);
        slice.map_async(wgpu::MapMode::Read, |_| {});
        // A lost device leaves the maps empty; the caller falls back to the CPU.
        if self
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .is_err()
        {
            return Vec::new();
        }
        let Ok(view) = slice.get_mapped_range() else {
            return Vec::new();
        };
        let words = bytemuck::cast_slice::<u8, u32>(&view).to_vec();
        drop(view);
        staging.unmap();
        if self.failed.load(std::sync::atomic::Ordering::SeqCst) {
            return Vec::new();
        }
        words
    }

    /// Rasterizes the recorded polygons of `queries` in one submission and finishes their
    /// maps; the CPU computes them when the GPU fails.
    fn submit(
        &self,
        scene: &Scene,
        queries: &[Query],
        recorded: &[(Record, Drawn)],
        (n, preferred, words_per_map): (u32, &[V3], usize),
    ) -> Vec<CubeMap> {
        let like = CubeMap::empty(n, preferred);
        // Map indices: each query's targets, one after another.
        let mut first = Vec::with_capacity(queries.len());
        let mut maps = 0usize;
        let mut draws = Vec::new();
        for (rec, drawn) in recorded {
            first.push(maps);
            if drawn.full {
                continue;
            }
            for d in rec.draws.chunks(DRAW_WORDS) {
                draws.push(d[0] + maps as u32);
                draws.extend_from_slice(&d[1..]);
            }
            maps += rec.targets as usize + 1;
        }
        let words = if draws.is_empty() {
            vec![0; maps * words_per_map]
        } else {
            self.raster(&draws, maps, n, words_per_map)
        };
        let lost = words.len() < maps * words_per_map;
        queries
            .par_iter()
            .zip(recorded)
            .zip(&first)
            .map(|((q, (rec, drawn)), &m)| {
                if lost {
                    return cpu::blocked(scene, &q.from, q.comp, n, preferred);
                }
                let map = |t: usize| {
                    let at = (m + t) * words_per_map;
                    like.with_pixel_words(&words[at..at + words_per_map])
                };
                let (base, bands) = if drawn.full {
                    (like.clone(), Vec::new())
                } else {
                    let bands = (1..=rec.targets as usize).map(|t| Some(map(t))).collect();
                    (map(0), bands)
                };
                cpu::finish(scene, &q.from, q.comp, base, bands, drawn)
            })
            .collect()
    }
}

/// A query's polygons, recorded for the GPU.
struct Record {
    draws: Vec<u32>,
    /// The highest target drawn into (0: the base map only).
    targets: u32,
}

impl Canvas for Record {
    fn draw(&mut self, target: u32, q: &[V3], cov: Coverage) {
        let len = q.len().min(12);
        self.draws
            .extend_from_slice(&[target, u32::from(cov == Coverage::Cells), len as u32, 0]);
        for k in 0..12 {
            let p = q.get(k).copied().unwrap_or_default();
            self.draws.extend(p.iter().map(|&c| (c as f32).to_bits()));
        }
        self.targets = self.targets.max(target);
    }
}

impl Backend for Gpu {
    fn blocked(
        &self,
        scene: &Scene,
        from: &P3,
        comp: &Component,
        n: u32,
        preferred: &[V3],
    ) -> CubeMap {
        self.blocked_many(scene, &[Query { from: *from, comp }], n, preferred)
            .pop()
            .unwrap_or_else(|| cpu::blocked(scene, from, comp, n, preferred))
    }

    fn blocked_many(
        &self,
        scene: &Scene,
        queries: &[Query],
        n: u32,
        preferred: &[V3],
    ) -> Vec<CubeMap> {
        let pixels = 6 * (n as usize) * (n as usize);
        let words_per_map = pixels.div_ceil(32);
        let mut out = Vec::with_capacity(queries.len());
        for chunk in queries.chunks(CHUNK) {
            let recorded: Vec<(Record, Drawn)> = chunk
                .par_iter()
                .map(|q| {
                    let mut rec = Record {
                        draws: Vec::new(),
                        targets: 0,
                    };
                    let drawn = cpu::draw(scene, &q.from, q.comp, n, &mut rec);
                    (rec, drawn)
                })
                .collect();
            // Submissions: queries in order, as many as the map budget takes.
            let bytes = |(rec, drawn): &(Record, Drawn)| {
                if drawn.full {
                    0
                } else {
                    (rec.targets as usize + 1) * words_per_map * 4
                }
            };
            let mut start = 0;
            while start < chunk.len() {
                let mut end = start;
                let mut total = 0;
                while end < chunk.len() && total + bytes(&recorded[end]) <= MAP_BUDGET {
                    total += bytes(&recorded[end]);
                    end += 1;
                }
                if end == start {
                    // Too large for one submission: the CPU draws it.
                    let q = &chunk[start];
                    out.push(cpu::blocked(scene, &q.from, q.comp, n, preferred));
                    start += 1;
                    continue;
                }
                out.extend(self.submit(
                    scene,
                    &chunk[start..end],
                    &recorded[start..end],
                    (n, preferred, words_per_map),
                ));
                start = end;
            }
        }
        out
    }

    fn batches(&self) -> bool {
        true
    }
}
