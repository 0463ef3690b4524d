//! What one planning of an input computes that a later planning of the same input
//! reuses: the pure results only — each (fpoint, probe)'s first domain ([`Dom`]), the
//! whole probe's cones, depth maps of a setup, the scanners' face cones and coverages —
//! never what learning changed. The knowledge base ([`super::knowledge`]) reads and fills
//! it; the re-plans after the path stage's bans start from it and give byte-identical
//! knowledge without computing it again.

use super::cluster::Bits;
use crate::access::scan::{FaceCones, FaceCoverage};
use crate::access::{self, CubeMap, Scene, SecondMap};
use crate::geometry::{FaceId, V3};
use std::any::Any;
use std::collections::{BTreeMap, BTreeSet};

/// What is known about one fpoint, per probe: shared until learning changes it.
pub(crate) type DomRow = std::sync::Arc<Vec<Dom>>;

/// How much is known about one (fpoint, probe).
#[derive(Debug, Clone)]
pub(crate) struct Dom {
    /// The tip fits at the contact and at the retract point.
    pub tip: bool,
    /// Setups: the straight probe's cone, or D2 for a bent probe.
    pub setup: CubeMap,
    /// D1, for a bent probe.
    pub d1: Option<CubeMap>,
    /// Whether the whole probe's cones replaced the half-line approximation.
    pub full: bool,
}

/// What one planning of an input computes that a later planning of the same input (a
/// re-plan after the path stage bans a configuration) can reuse: the pure results only —
/// cones of a point and probe, depth maps of a setup — never what learning changed —
/// and whether a plan validated with the part turned was found at all. A memo belongs
/// to one [`super::Input`]; the re-plan gives byte-identical knowledge without
/// computing it again.
#[derive(Default)]
pub struct Memo {
    /// The initial knowledge of every (graph point, probe).
    pub(super) initial: Option<Vec<DomRow>>,
    /// The whole probe's cones per (point, probe).
    pub(super) cones: BTreeMap<(usize, usize), access::PointCones>,
    /// The second component's depth map per setup cell.
    pub(super) second: BTreeMap<usize, SecondMap>,
    /// [`super::knowledge::Knowledge::orientations`] as first computed, per (point, probe, setup cell,
    /// whether the whole probe's cones were acquired): D1 is a function of those.
    pub(super) orientations: BTreeMap<(usize, usize, usize, bool), Bits>,
    /// The scanners' face cones and coverages.
    pub(crate) scans: ScanMemo,
    /// D2's cap over a bent probe's D1 once acquired, per (point, probe): D1 is then
    /// the first D1 and the whole probe's approach cone, both kept here.
    pub(super) caps: BTreeMap<(usize, usize), CubeMap>,
    /// The part as obstacle.
    pub(super) scene: Option<Scene>,
    /// A plan validated with the part turned was sought and not found: the re-plans of
    /// the same input (which only add bans) do not seek it again.
    pub(crate) unturnable: bool,
    /// Points of a dense face the search plans besides its representatives, by index in
    /// the full graph ([`super::dense`]): those no representative's configuration
    /// reached, and those the path stage banned.
    pub(super) promoted: std::collections::BTreeSet<usize>,
    /// Per search of the input (the turn's bits, the faces left to a scanner), the
    /// states its rounds started from: a [`super::journal::Journal`], as the search
    /// hands it over.
    pub(super) journals: BTreeMap<(u64, BTreeSet<FaceId>), Box<dyn Any + Send + Sync>>,
    /// The full graph's indices of the points the knowledge above is numbered by, when
    /// the search planned a thinned graph.
    thinned: Option<Vec<usize>>,
}

impl Memo {
    /// Numbers the per-point knowledge by the thinned graph of `full` (indices in the
    /// full graph): what was kept for another numbering is forgotten.
    pub(super) fn retarget(&mut self, full: &[usize]) {
        if self.thinned.as_deref() == Some(full) {
            return;
        }
        self.thinned = Some(full.to_vec());
        self.initial = None;
        self.cones.clear();
        self.orientations.clear();
        self.caps.clear();
        self.journals.clear();
    }

    /// Later plannings of this input validate at the nominal pose only.
    pub fn give_up_turned(&mut self) {
        self.unturnable = true;
    }

    /// Whether the last planning of this input found a plan validated with the part
    /// turned (none has given it up).
    pub fn turned(&self) -> bool {
        !self.unturnable
    }

    /// The part as obstacle, built on first use (a memo belongs to one input, so to one
    /// part): re-plans and the path stage share it instead of building its hierarchy
    /// again.
    pub fn scene(&mut self, geometry: &crate::geometry::PartGeometry) -> Scene {
        self.scene
            .get_or_insert_with(|| Scene::of_part(geometry))
            .clone()
    }
}

/// The coverages computed, by scanner, face and setup direction (to a nanometre), for
/// the plan made again after features went back to touch (its setups are mostly the
/// same), and the faces' cones, which every setup's coverage shares.
#[derive(Default)]
pub(crate) struct ScanMemo {
    coverages: std::collections::BTreeMap<(usize, usize, [i64; 3]), FaceCoverage>,
    cones: std::collections::BTreeMap<(usize, usize), FaceCones>,
}

impl ScanMemo {
    /// The coverage of `face` by scanner `scanner` in setup `up`, computed by `cover`
    /// the first time, on the face's cones drawn by `cones` the first time it is asked
    /// in any setup.
    pub(super) fn get(
        &mut self,
        (scanner, face): (usize, FaceId),
        up: &V3,
        cones: &dyn Fn() -> FaceCones,
        cover: &dyn Fn(&FaceCones, &V3) -> FaceCoverage,
    ) -> FaceCoverage {
        let key = (
            scanner,
            face.0,
            [up.x, up.y, up.z].map(|c| (c * 1e9).round() as i64),
        );
        if let Some(c) = self.coverages.get(&key) {
            return c.clone();
        }
        let cones = self.cones.entry((scanner, face.0)).or_insert_with(cones);
        let c = cover(cones, up);
        self.coverages.insert(key, c.clone());
        c
    }
}
