//! How cones are computed: the cube map's resolution and preferred directions, the
//! retract distance and the backend ([`ConeOptions`]), and which second-component
//! directions D2 samples ([`D2Wanted`]).

use super::cones::d2_resolution;
use super::{axes, BackendKind, CubeMap};
use crate::geometry::V3;
use std::sync::Arc;

/// What to compute for a point.
#[derive(Debug, Clone)]
pub struct ConeOptions {
    /// Cube-map resolution N.
    pub n: u32,
    /// Preferred directions (exact axes and the like), shared by every cone.
    pub preferred: Vec<V3>,
    /// The retract distance along the normal (mm): approach cones hold at the contact
    /// and at the retract point.
    pub retract: f64,
    /// How many points of dD1 the weak GAC D2 samples.
    pub d2_samples: usize,
    /// Refine the grown components' cones with exact parry tests at their boundaries
    /// ([`super::refine`]): slower, and exact at the pixel centres it reaches.
    pub exact_boundary: bool,
    /// Which backend rasterizes the shadows.
    pub backend: BackendKind,
    /// The setups D2 is asked about, when the caller masks it by them (the planner: the
    /// realisable, unforbidden ones); D2 may then leave out other cells (see [`super::d2`]).
    pub d2_wanted: Option<Arc<D2Wanted>>,
}

/// The cells D2 is asked about ([`ConeOptions::d2_wanted`]), with their map at D2's
/// coarser resolution made once for every point that shares them (coarsening the
/// 24,600 cells of a sphere in a chuck for each point was 1.6 % of its build).
#[derive(Debug)]
pub struct D2Wanted {
    map: CubeMap,
    coarse: std::sync::OnceLock<CubeMap>,
}

impl D2Wanted {
    /// The cells of `map` (at the cones' resolution).
    pub fn new(map: CubeMap) -> D2Wanted {
        D2Wanted {
            map,
            coarse: std::sync::OnceLock::new(),
        }
    }

    /// The wanted cells at resolution `n`, a divisor of the map's.
    pub(super) fn at(&self, n: u32) -> CubeMap {
        if n == d2_resolution(self.map.n()) {
            self.coarse.get_or_init(|| self.map.coarsened(n)).clone()
        } else {
            self.map.coarsened(n)
        }
    }
}

impl Default for ConeOptions {
    fn default() -> Self {
        ConeOptions {
            n: 64,
            preferred: axes(),
            retract: 2.0,
            d2_samples: 16,
            exact_boundary: false,
            backend: BackendKind::Cpu,
            d2_wanted: None,
        }
    }
}
