//! Stage 7, accessibility (seed ch. 2, paper 001): for a point near the part, the
//! directions from which a probe can reach it, as cube-map cones.
//!
//! The entry point is [`point_cones`] (one fpoint, one probe) and [`cones`] (many, in
//! parallel). The pieces:
//! - [`CubeMap`]: six N × N bitmaps plus exact preferred directions, with set operations
//!   and growing;
//! - [`Scene`]: the obstacle (part, and table once a setup is known);
//! - [`ProbeShape`]: the spec's probe as tip ball plus [`Component`]s (stylus and
//!   extensions as capsules, body, head and ram as cylinders);
//! - [`Backend`]: computes one component's blocked directions; [`Cpu`] is the software
//!   rasterizer, [`Gpu`] rasterizes the same shadow polygons with wgpu, many components
//!   per submission;
//! - the seed's family: the half-line GAC, grown and truncated half-lines (any
//!   component), D1, D2 (weak GAC over dD1), D1′ for a chosen second-component
//!   direction, feature cones as intersections, approach/retract cones;
//! - [`scan`]: a laser line scanner's visibility (laser and camera rays, incidence,
//!   housing at the stand-off) on the same maps and backends.
//!
//! **Architecture Invariant:** for components of non-zero radius a direction the
//! obstacle blocks is never reported accessible; the bare half-line is exact at pixel
//! centres.

mod backend;
mod batch;
mod cones;
mod cpu;
mod cubemap;
mod errors;
mod exact;
mod gpu;
mod head;
mod heightmap;
mod options;
pub mod pose;
mod probe;
mod raster;
mod report;
pub mod scan;
mod scene;
mod swept;

pub use backend::{auto_backend, gpu, Backend, BackendKind, Cpu, Query};
pub use batch::{cones, gac_halfline_many, point_cones_many};
pub use cones::{
    approach_cone, axes, d1, d1_prime, d2, feature_cone, gac, gac_halfline, point_cones, tip_fits,
    PointCones, SecondMap,
};
pub use cpu::blocked_plain;
pub use cubemap::{ones, Cell, CubeMap, Pixel, PreferredIndex};
pub use exact::{component_hits, refine};
pub use gpu::Gpu;
pub use head::head_direction;
pub(crate) use head::orientations_in;
pub use options::{ConeOptions, D2Wanted};
pub use pose::{Blocker, Contact, Head, Pose};
pub use probe::{Component, End, ProbeShape};
pub use raster::Coverage;
pub use report::{cone_report, pgm, ConeInput, ConeReport, ConeRequest};
pub use scan::{scan_cones, ScanCones, ScannerShape};
pub use scene::{Scene, Tri};
