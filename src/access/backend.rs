//! Who computes a component's blocked directions: the [`Backend`] trait over a batch of
//! [`Query`]s, the software rasterizer [`Cpu`], and the choice between it and the wgpu
//! backend ([`BackendKind`]; `auto` takes the GPU where wgpu finds an adapter).

use super::{cpu, Component, CubeMap, Gpu, Scene};
use crate::geometry::{P3, V3};

/// One component placed at one point: a question for [`Backend::blocked_many`].
#[derive(Debug, Clone, Copy)]
pub struct Query<'a> {
    /// Where the component's axis starts (the tip centre, or an articulation point).
    pub from: P3,
    /// The component.
    pub comp: &'a Component,
}

/// Computes the directions one probe component is blocked in. The CPU rasterizer
/// implements it; the GPU backend rasterizes the same shadows.
pub trait Backend: Sync {
    /// The directions in which `comp`, with its axis starting at `from`, meets the scene.
    fn blocked(
        &self,
        scene: &Scene,
        from: &P3,
        comp: &Component,
        n: u32,
        preferred: &[V3],
    ) -> CubeMap;

    /// [`Backend::blocked`], right on the cells of `stop`; elsewhere it may hold fewer
    /// blocked cells (the CPU stops drawing once every cell of `stop` is blocked, and
    /// decides only those; others may draw the whole map).
    fn blocked_until(
        &self,
        scene: &Scene,
        from: &P3,
        comp: &Component,
        n: u32,
        preferred: &[V3],
        stop: &CubeMap,
    ) -> CubeMap {
        let _ = stop;
        self.blocked(scene, from, comp, n, preferred)
    }

    /// [`Backend::blocked`], right on the cells of `within` (and the pixels holding its
    /// preferred directions); elsewhere it may hold fewer blocked cells (the CPU passes
    /// over shadows that cannot reach them; others may draw the whole map).
    fn blocked_within(
        &self,
        scene: &Scene,
        from: &P3,
        comp: &Component,
        n: u32,
        preferred: &[V3],
        within: &CubeMap,
    ) -> CubeMap {
        let _ = within;
        self.blocked(scene, from, comp, n, preferred)
    }

    /// [`Backend::blocked`] for many queries, in their order.
    fn blocked_many(
        &self,
        scene: &Scene,
        queries: &[Query],
        n: u32,
        preferred: &[V3],
    ) -> Vec<CubeMap> {
        queries
            .iter()
            .map(|q| self.blocked(scene, &q.from, q.comp, n, preferred))
            .collect()
    }

    /// Whether [`Backend::blocked_many`] pays over one query at a time, so callers
    /// should gather their queries (the CPU stops early instead, once a cone is empty).
    fn batches(&self) -> bool {
        false
    }
}

/// The software backend.
#[derive(Debug, Clone, Copy, Default)]
pub struct Cpu;

impl Backend for Cpu {
    fn blocked(
        &self,
        scene: &Scene,
        from: &P3,
        comp: &Component,
        n: u32,
        preferred: &[V3],
    ) -> CubeMap {
        cpu::blocked(scene, from, comp, n, preferred)
    }

    fn blocked_until(
        &self,
        scene: &Scene,
        from: &P3,
        comp: &Component,
        n: u32,
        preferred: &[V3],
        stop: &CubeMap,
    ) -> CubeMap {
        cpu::blocked_until(scene, from, comp, n, preferred, stop)
    }

    fn blocked_within(
        &self,
        scene: &Scene,
        from: &P3,
        comp: &Component,
        n: u32,
        preferred: &[V3],
        within: &CubeMap,
    ) -> CubeMap {
        cpu::blocked_within(scene, from, comp, n, preferred, within)
    }
}

/// Which backend computes the cones.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BackendKind {
    /// The software rasterizer: the reference, byte-identical on every machine.
    #[default]
    Cpu,
    /// wgpu ([`Gpu`]), found once per process.
    Gpu,
}

static GPU: std::sync::OnceLock<Result<Gpu, String>> = std::sync::OnceLock::new();

/// The process's GPU backend, set up on first use, or why there is none.
pub fn gpu() -> Result<&'static Gpu, String> {
    GPU.get_or_init(Gpu::new).as_ref().map_err(Clone::clone)
}

/// The backend `--backend auto` picks: the GPU when wgpu finds a hardware adapter; a
/// software one (lavapipe) is slower than the CPU backend it would replace, so there the
/// CPU. Also says why, for the summary.
pub fn auto_backend() -> (BackendKind, String) {
    match gpu() {
        Ok(g) if !g.is_software() => (
            BackendKind::Gpu,
            format!("cones on the GPU: {}", g.adapter()),
        ),
        Ok(g) => (
            BackendKind::Cpu,
            format!(
                "cones on the CPU: the only adapter is a software one ({})",
                g.adapter()
            ),
        ),
        Err(why) => (
            BackendKind::Cpu,
            format!("cones on the CPU: no GPU adapter ({why})"),
        ),
    }
}

impl BackendKind {
    /// The backend itself; the GPU's when one was found, else the CPU's.
    pub fn get(self) -> &'static dyn Backend {
        match self {
            BackendKind::Cpu => &Cpu,
            BackendKind::Gpu => match gpu() {
                Ok(g) => g,
                Err(_) => &Cpu,
            },
        }
    }
}
