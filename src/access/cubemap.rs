//! Direction cones as cube maps (seed ch. 2.3 and 4.3.4): six N × N bitmaps on the faces
//! of the cube around the origin, one bit per pixel, plus one bit per *preferred
//! direction* — an exact direction such as +z that would otherwise fall on a pixel corner
//! and could not be chosen exactly.
//!
//! Cube face `f` has major axis `a = f / 2` and sign `s = +1` for even `f`; its pixel
//! (i, j) covers u ∈ [2i/N − 1, 2(i+1)/N − 1] and likewise v for j, where the direction is
//! `s·e_a + u·e_(a+1) + v·e_(a+2)` (axes modulo 3). So face 4 is +z with u along x and
//! v along y.

use crate::geometry::V3;
use std::sync::Arc;

/// A set of directions: pixels of a cube map, and preferred directions.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CubeMap {
    n: u32,
    /// The preferred directions every map of a computation shares.
    extra: Arc<[[u64; 3]]>,
    /// 6·N² pixel bits, then one bit per preferred direction.
    bits: Vec<u64>,
}

/// The preferred directions of maps of one shape sorted by x, for
/// [`CubeMap::cell_of_indexed`]: a plan has up to 48 and looks up millions of directions.
#[derive(Debug, Clone)]
pub struct PreferredIndex {
    /// (x, preferred index), by x then index.
    by_x: Vec<(f64, usize)>,
}

impl PreferredIndex {
    /// The index of `like`'s preferred directions.
    pub fn new(like: &CubeMap) -> PreferredIndex {
        let mut by_x: Vec<(f64, usize)> = (0..like.preferred_len())
            .map(|k| (like.preferred(k).x, k))
            .collect();
        by_x.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        PreferredIndex { by_x }
    }
}

/// A pixel: cube face (0..6), column i and row j.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Pixel {
    /// Cube face: 0 +x, 1 −x, 2 +y, 3 −y, 4 +z, 5 −z.
    pub face: u8,
    /// Column (along u).
    pub i: u32,
    /// Row (along v).
    pub j: u32,
}

/// An element of a cube map: a pixel or the k-th preferred direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Cell {
    /// A pixel.
    Pixel(Pixel),
    /// A preferred direction, by index.
    Preferred(usize),
}

fn key(d: &V3) -> [u64; 3] {
    let n = d.normalize();
    [n.x, n.y, n.z].map(|c| (c + 0.0).to_bits())
}

/// The major axis and sign of a direction, and its (u, v) on that cube face.
pub(crate) fn face_uv(d: &V3) -> (u8, f64, f64) {
    let a = d.iamax();
    let s = d[a];
    let face = (2 * a + usize::from(s < 0.0)) as u8;
    let w = s.abs();
    (face, d[(a + 1) % 3] / w, d[(a + 2) % 3] / w)
}

/// The direction through (u, v) of a cube face (not normalised).
pub(crate) fn face_dir(face: u8, u: f64, v: f64) -> V3 {
    let a = (face / 2) as usize;
    let s = if face.is_multiple_of(2) { 1.0 } else { -1.0 };
    let mut d = V3::zeros();
    d[a] = s;
    d[(a + 1) % 3] = u;
    d[(a + 2) % 3] = v;
    d
}

/// The indices of the set bits of a word slice (64 to a word), ascending.
pub fn ones(words: &[u64]) -> impl Iterator<Item = usize> + '_ {
    words.iter().enumerate().flat_map(|(w, &word)| {
        let mut rest = word;
        std::iter::from_fn(move || {
            if rest == 0 {
                return None;
            }
            let b = rest.trailing_zeros() as usize;
            rest &= rest - 1;
            Some(w * 64 + b)
        })
    })
}

impl CubeMap {
    /// The empty cone at resolution `n` with the given preferred directions.
    pub fn empty(n: u32, preferred: &[V3]) -> CubeMap {
        let extra: Arc<[[u64; 3]]> = preferred.iter().map(key).collect();
        let len = 6 * (n as usize) * (n as usize) + extra.len();
        CubeMap {
            n,
            extra,
            bits: vec![0; len.div_ceil(64)],
        }
    }

    /// The full cone (every direction) at resolution `n`.
    pub fn full(n: u32, preferred: &[V3]) -> CubeMap {
        let mut c = CubeMap::empty(n, preferred);
        c.bits.iter_mut().for_each(|w| *w = !0);
        c.trim();
        c
    }

    /// A map with no bits set and the same resolution and preferred directions.
    pub fn empty_like(&self) -> CubeMap {
        CubeMap {
            n: self.n,
            extra: self.extra.clone(),
            bits: vec![0; self.bits.len()],
        }
    }

    /// Resolution N (pixels per cube-face side).
    pub fn n(&self) -> u32 {
        self.n
    }

    /// The number of preferred directions.
    pub fn preferred_len(&self) -> usize {
        self.extra.len()
    }

    /// The k-th preferred direction (unit).
    pub fn preferred(&self, k: usize) -> V3 {
        let [x, y, z] = self.extra[k].map(f64::from_bits);
        V3::new(x, y, z)
    }

    fn len(&self) -> usize {
        6 * (self.n as usize) * (self.n as usize) + self.extra.len()
    }

    /// Clears the unused bits past the end, so counts and equality are exact.
    fn trim(&mut self) {
        let len = self.len();
        if !len.is_multiple_of(64) {
            if let Some(last) = self.bits.last_mut() {
                *last &= (1u64 << (len % 64)) - 1;
            }
        }
    }

    /// The bit index of a cell.
    pub fn index(&self, c: Cell) -> usize {
        let n = self.n as usize;
        match c {
            Cell::Pixel(p) => (p.face as usize * n + p.j as usize) * n + p.i as usize,
            Cell::Preferred(k) => 6 * n * n + k,
        }
    }

    /// The cell of a bit index.
    pub fn cell(&self, index: usize) -> Cell {
        let n = self.n as usize;
        if index >= 6 * n * n {
            return Cell::Preferred(index - 6 * n * n);
        }
        Cell::Pixel(Pixel {
            face: (index / (n * n)) as u8,
            j: ((index / n) % n) as u32,
            i: (index % n) as u32,
        })
    }

    /// Whether a cell is in the cone.
    pub fn get(&self, c: Cell) -> bool {
        self.has_index(self.index(c))
    }

    /// Whether the cell with bit index `k` (see [`CubeMap::index`]) is in the cone.
    pub fn has_index(&self, k: usize) -> bool {
        self.bits[k / 64] >> (k % 64) & 1 == 1
    }

    /// Adds or removes a cell.
    pub fn set(&mut self, c: Cell, on: bool) {
        let k = self.index(c);
        if on {
            self.bits[k / 64] |= 1 << (k % 64);
        } else {
            self.bits[k / 64] &= !(1 << (k % 64));
        }
    }

    /// The pixel a direction falls in.
    pub(crate) fn pixel_of(&self, d: &V3) -> Pixel {
        let (face, u, v) = face_uv(d);
        let at =
            |x: f64| floor_i((x + 1.0) / 2.0 * self.n as f64).clamp(0, self.n as i64 - 1) as u32;
        Pixel {
            face,
            i: at(u),
            j: at(v),
        }
    }

    /// The cell of a direction: its preferred-direction bit if it is one (to within
    /// 1e-9 rad, so a head's A = 90°, B = 0° is +x despite rounding), else its pixel.
    pub fn cell_of(&self, d: &V3) -> Cell {
        let u = d.normalize();
        match (0..self.extra.len()).find(|&k| self.is_preferred(k, &u)) {
            Some(i) => Cell::Preferred(i),
            None => Cell::Pixel(self.pixel_of(d)),
        }
    }

    /// Whether unit `u` is preferred direction `k` (to within 1e-9 rad). A component more
    /// than 2e-9 off rules it out before the norm (the norm is at least as large): the
    /// same answer, without a square root each.
    fn is_preferred(&self, k: usize, u: &V3) -> bool {
        let p = self.preferred(k);
        (p.x - u.x).abs() < 2e-9
            && (p.y - u.y).abs() < 2e-9
            && (p.z - u.z).abs() < 2e-9
            && (p - u).norm() < 1e-9
    }

    /// [`CubeMap::cell_of`] with the preferred directions looked up in `index` (built
    /// from a map of this shape): the same cell, without testing every preferred
    /// direction.
    pub fn cell_of_indexed(&self, index: &PreferredIndex, d: &V3) -> Cell {
        let u = d.normalize();
        let from = index.by_x.partition_point(|&(x, _)| x < u.x - 3e-9);
        let near = index.by_x[from..]
            .iter()
            .take_while(|&&(x, _)| x <= u.x + 3e-9)
            .map(|&(_, k)| k)
            .filter(|&k| self.is_preferred(k, &u))
            .min();
        match near {
            Some(k) => Cell::Preferred(k),
            None => Cell::Pixel(self.pixel_of(d)),
        }
    }

    /// Whether a direction is in the cone (sampled at its cell).
    pub fn contains(&self, d: &V3) -> bool {
        self.get(self.cell_of(d))
    }

    /// The unit direction of a cell: the pixel centre, or the preferred direction.
    pub fn direction(&self, c: Cell) -> V3 {
        match c {
            Cell::Pixel(p) => {
                let at = |k: u32| (2.0 * (k as f64 + 0.5)) / self.n as f64 - 1.0;
                face_dir(p.face, at(p.i), at(p.j)).normalize()
            }
            Cell::Preferred(k) => self.preferred(k),
        }
    }

    /// The cells whose direction makes at least `cos` with unit `axis` (less 1e-12):
    /// a cap of directions, from a table of pixel directions built once per resolution.
    pub fn cap(&self, axis: &V3, cos: f64) -> CubeMap {
        let mut out = self.empty_like();
        let pixels = pixel_directions(self);
        for (k, d) in pixels.iter().enumerate() {
            if d.dot(axis) >= cos - 1e-12 {
                out.bits[k / 64] |= 1 << (k % 64);
            }
        }
        for k in 0..self.extra.len() {
            if self.preferred(k).dot(axis) >= cos - 1e-12 {
                let i = pixels.len() + k;
                out.bits[i / 64] |= 1 << (i % 64);
            }
        }
        out
    }

    /// The raw bits: 6·N² pixels then the preferred directions, 64 to a word, in
    /// [`CubeMap::index`] order. For set algorithms that work on any bitset.
    pub fn words(&self) -> &[u64] {
        &self.bits
    }

    /// The cells' centres' mean direction and the widest angle (radians) from it to a
    /// centre: `None` for an empty cone, `Some(None)` when the centres cancel out.
    pub fn spread(&self) -> Option<Option<(V3, f64)>> {
        let dirs = self.centres();
        if dirs.is_empty() {
            return None;
        }
        let sum: V3 = dirs.iter().sum();
        if sum.norm() < 1e-9 {
            return Some(None);
        }
        let m = sum.normalize();
        // The widest angle is the arccosine of the least cosine (one arccosine, not one
        // per cell).
        let least = dirs.iter().map(|d| d.dot(&m)).fold(1.0, f64::min);
        Some(Some((m, least.clamp(-1.0, 1.0).acos())))
    }

    /// A cap that holds every direction of the cone's cells, as (unit axis, angle in
    /// radians), or `None` for an empty cone: the [`CubeMap::spread`] plus 2/N (a
    /// pixel's half diagonal is √2/N on a face at distance 1 or more, so it subtends
    /// less than 2/N radians, and a preferred cell holds only directions within 1e-9 of
    /// its own), or the whole sphere when the centres have no mean direction.
    pub fn bounding_cap(&self) -> Option<(V3, f64)> {
        Some(match self.spread()? {
            Some((axis, rho)) => (axis, rho + 2.0 / self.n as f64),
            None => (V3::z(), std::f64::consts::PI),
        })
    }

    /// The directions of the cone's cells in cell order, as [`CubeMap::direction`] gives
    /// them (the pixels' from a table built once per resolution).
    pub fn centres(&self) -> Vec<V3> {
        let pixels = pixel_directions(self);
        ones(&self.bits)
            .map(|k| match pixels.get(k) {
                Some(d) => *d,
                None => self.direction(self.cell(k)),
            })
            .collect()
    }

    /// Whether no direction is in the cone.
    pub fn is_empty(&self) -> bool {
        self.bits.iter().all(|&w| w == 0)
    }

    /// Whether every direction is in the cone.
    pub(crate) fn is_full(&self) -> bool {
        self.count() == self.len()
    }

    /// The number of cells in the cone.
    pub fn count(&self) -> usize {
        self.bits.iter().map(|w| w.count_ones() as usize).sum()
    }

    /// The cells in the cone, in index order (faces, rows, columns, then preferred).
    pub fn cells(&self) -> impl Iterator<Item = Cell> + '_ {
        ones(&self.bits).map(move |k| self.cell(k))
    }

    fn same_shape(&self, o: &CubeMap) {
        assert!(
            self.n == o.n && (Arc::ptr_eq(&self.extra, &o.extra) || self.extra == o.extra),
            "cube maps of different resolution or preferred directions"
        );
    }

    /// The union of `maps`, within `inside` and outside `outside`, shaped like `like`: in
    /// one pass over the words.
    pub fn union_within<'m>(
        like: &CubeMap,
        maps: impl Iterator<Item = &'m CubeMap>,
        inside: &CubeMap,
        outside: &CubeMap,
    ) -> CubeMap {
        like.same_shape(inside);
        like.same_shape(outside);
        let mut out = like.empty_like();
        for m in maps {
            like.same_shape(m);
            out.bits.iter_mut().zip(&m.bits).for_each(|(a, b)| *a |= b);
        }
        out.bits
            .iter_mut()
            .zip(inside.bits.iter().zip(&outside.bits))
            .for_each(|(a, (i, o))| *a &= i & !o);
        out
    }

    /// In place: keep only directions also in `o`.
    pub fn and_assign(&mut self, o: &CubeMap) {
        self.same_shape(o);
        self.bits.iter_mut().zip(&o.bits).for_each(|(a, b)| *a &= b);
    }

    /// In place: add the directions of `o`.
    pub fn or_assign(&mut self, o: &CubeMap) {
        self.same_shape(o);
        self.bits.iter_mut().zip(&o.bits).for_each(|(a, b)| *a |= b);
    }

    /// In place: remove the directions of `o`.
    pub fn and_not_assign(&mut self, o: &CubeMap) {
        self.same_shape(o);
        self.bits
            .iter_mut()
            .zip(&o.bits)
            .for_each(|(a, b)| *a &= !b);
    }

    /// The intersection.
    pub fn and(&self, o: &CubeMap) -> CubeMap {
        let mut c = self.clone();
        c.and_assign(o);
        c
    }

    /// The union.
    pub fn or(&self, o: &CubeMap) -> CubeMap {
        let mut c = self.clone();
        c.or_assign(o);
        c
    }

    /// The complement.
    pub fn not(&self) -> CubeMap {
        let mut c = self.clone();
        c.bits.iter_mut().for_each(|w| *w = !*w);
        c.trim();
        c
    }

    /// The pixels next to a pixel (8-neighbourhood), across cube edges too.
    pub fn neighbours(&self, p: Pixel) -> Vec<Pixel> {
        let n = self.n as f64;
        let mut out = Vec::with_capacity(8);
        for dj in -1i32..=1 {
            for di in -1i32..=1 {
                if (di, dj) == (0, 0) {
                    continue;
                }
                let (i, j) = (p.i as i64 + di as i64, p.j as i64 + dj as i64);
                let q = if (0..self.n as i64).contains(&i) && (0..self.n as i64).contains(&j) {
                    Pixel {
                        face: p.face,
                        i: i as u32,
                        j: j as u32,
                    }
                } else {
                    // Off the face: the pixel the neighbour's centre direction falls in.
                    let at = |k: i64| (2.0 * (k as f64 + 0.5)) / n - 1.0;
                    self.pixel_of(&face_dir(p.face, at(i), at(j)))
                };
                if q != p && !out.contains(&q) {
                    out.push(q);
                }
            }
        }
        out
    }

    /// The cone grown by one pixel: every pixel next to one in the cone joins it (the
    /// pessimistic step of ch. 4.3.4 when the cone is a set of blocked directions).
    /// Preferred directions join when their pixel is in the grown cone.
    pub fn grow(&self) -> CubeMap {
        let mut out = self.grow_pixels();
        out.settle_preferred();
        out
    }

    /// [`CubeMap::grow`] of the pixels alone: the preferred bits are kept as they are, for
    /// callers that decide them afterwards (each settling looks up every preferred
    /// direction's pixel).
    pub(crate) fn grow_pixels(&self) -> CubeMap {
        self.grow_pixels_after(None)
    }

    /// [`CubeMap::grow_pixels`] of a map that holds `before` grown once (as each step of
    /// a growth chain holds the step before it, grown): the pixels of `before` reach
    /// across cube edges into this map already, so only the others' edge neighbours are
    /// looked up.
    pub(crate) fn grow_pixels_after(&self, before: Option<&CubeMap>) -> CubeMap {
        let n = self.n as usize;
        if n > 64 {
            return self.grow_slow();
        }
        let mut out = self.clone();
        let mask = row_mask(n);
        let table = EdgeTable::of(self.n);
        let (mut rows, mut wide) = ([0u64; 64], [0u64; 64]);
        for face in 0..6u8 {
            for j in 0..n {
                let r = self.row(face, j);
                rows[j] = r;
                wide[j] = (r | r << 1 | r >> 1) & mask;
            }
            for j in 0..n {
                let mut g = wide[j];
                if j > 0 {
                    g |= wide[j - 1];
                }
                if j + 1 < n {
                    g |= wide[j + 1];
                }
                out.or_row(face, j, g);
            }
            // Pixels on the face's border reach across cube edges.
            for (j, &r) in rows[..n].iter().enumerate() {
                let r = match before {
                    Some(b) => r & !b.row(face, j),
                    None => r,
                };
                let border = if j == 0 || j == n - 1 {
                    r
                } else {
                    r & (1 | 1 << (n - 1))
                };
                let mut rest = border;
                while rest != 0 {
                    let i = rest.trailing_zeros() as usize;
                    rest &= rest - 1;
                    let pixel = (face as usize * n + j) * n + i;
                    for &q in table.across(pixel) {
                        out.bits[q as usize / 64] |= 1 << (q % 64);
                    }
                }
            }
        }
        out
    }

    /// [`CubeMap::grow`] `k` times.
    pub fn grown(&self, k: u32) -> CubeMap {
        let mut c = self.clone();
        for _ in 0..k {
            c = c.grow();
        }
        c
    }

    fn grow_slow(&self) -> CubeMap {
        let mut out = self.clone();
        for c in self.cells() {
            if let Cell::Pixel(p) = c {
                for q in self.neighbours(p) {
                    out.set(Cell::Pixel(q), true);
                }
            }
        }
        out
    }

    /// Preferred directions whose pixel is in the cone join it.
    fn settle_preferred(&mut self) {
        for k in 0..self.extra.len() {
            let p = self.pixel_of(&self.preferred(k));
            if self.get(Cell::Pixel(p)) {
                self.set(Cell::Preferred(k), true);
            }
        }
    }

    /// Row `j` of a face as bits (bit i = column i); N ≤ 64.
    pub(crate) fn row(&self, face: u8, j: usize) -> u64 {
        let n = self.n as usize;
        let start = (face as usize * n + j) * n;
        let (w, b) = (start / 64, start % 64);
        let mut r = self.bits[w] >> b;
        if b + n > 64 {
            r |= self.bits[w + 1] << (64 - b);
        }
        r & row_mask(n)
    }

    /// Adds the bits of `r` to row `j` of a face; N ≤ 64.
    pub(crate) fn or_row(&mut self, face: u8, j: usize, r: u64) {
        let n = self.n as usize;
        let r = r & row_mask(n);
        let start = (face as usize * n + j) * n;
        let (w, b) = (start / 64, start % 64);
        self.bits[w] |= r << b;
        if b + n > 64 {
            self.bits[w + 1] |= r >> (64 - b);
        }
    }

    /// A map shaped like this one whose pixels are the bits of `words` (32 to a word, in
    /// pixel order: see [`CubeMap::words`]) and whose preferred directions are clear.
    pub(crate) fn with_pixel_words(&self, words: &[u32]) -> CubeMap {
        let mut out = self.empty_like();
        let pixels = 6 * (self.n as usize) * (self.n as usize);
        for (k, w) in out.bits.iter_mut().enumerate() {
            let lo = words.get(2 * k).copied().unwrap_or(0) as u64;
            let hi = words.get(2 * k + 1).copied().unwrap_or(0) as u64;
            let first = 64 * k;
            let keep = if first + 64 <= pixels {
                u64::MAX
            } else if first >= pixels {
                0
            } else {
                row_mask(pixels - first)
            };
            *w = (lo | hi << 32) & keep;
        }
        out
    }

    /// Adds pixels i0..=i1 of row `j` of a face.
    pub(crate) fn set_span(&mut self, face: u8, j: u32, i0: u32, i1: u32) {
        if i0 > i1 {
            return;
        }
        for (w, mask) in self.span_words(face, j, i0, i1) {
            self.bits[w] |= mask;
        }
    }

    /// The words and masks of pixels i0..=i1 (i0 ≤ i1) of row j of a face.
    fn span_words(&self, face: u8, j: u32, i0: u32, i1: u32) -> impl Iterator<Item = (usize, u64)> {
        let n = self.n as usize;
        let start = (face as usize * n + j as usize) * n;
        let (mut k, end) = (start + i0 as usize, start + i1 as usize + 1);
        std::iter::from_fn(move || {
            (k < end).then(|| {
                let (w, b) = (k / 64, k % 64);
                let len = (64 - b).min(end - k);
                k += len;
                (w, row_mask(len) << b)
            })
        })
    }

    /// Whether pixels i0..=i1 of rows j0..=j1 of a face are all in the map (true for an
    /// empty range).
    pub(crate) fn spans_set(&self, face: u8, j0: u32, j1: u32, i0: u32, i1: u32) -> bool {
        if i0 > i1 {
            return true;
        }
        (j0..=j1).all(|j| {
            self.span_words(face, j, i0, i1)
                .all(|(w, mask)| self.bits[w] & mask == mask)
        })
    }

    /// Whether some pixel i0..=i1 of rows j0..=j1 of a face is in the map (false for an
    /// empty range).
    pub(crate) fn spans_meet(&self, face: u8, j0: u32, j1: u32, i0: u32, i1: u32) -> bool {
        if i0 > i1 {
            return false;
        }
        (j0..=j1).any(|j| {
            self.span_words(face, j, i0, i1)
                .any(|(w, mask)| self.bits[w] & mask != 0)
        })
    }

    /// The pixels of the map's cells: its pixels and those holding its preferred
    /// directions (preferred bits clear).
    pub(crate) fn pixels_of_cells(&self) -> CubeMap {
        let mut out = self.clone();
        for k in 0..self.extra.len() {
            if self.get(Cell::Preferred(k)) {
                out.set(Cell::Preferred(k), false);
                for p in self.pixels_holding(&self.preferred(k)) {
                    out.set(Cell::Pixel(p), true);
                }
            }
        }
        out
    }

    /// Whether every pixel i0..=i1 of rows j0..=j1 of a face is in at least one of
    /// `maps` (maps of one resolution; false when there is none).
    pub(crate) fn spans_set_any(
        maps: &[Option<CubeMap>],
        face: u8,
        j0: u32,
        j1: u32,
        i0: u32,
        i1: u32,
    ) -> bool {
        let Some(first) = maps.iter().flatten().next() else {
            return false;
        };
        (j0..=j1).all(|j| {
            first.span_words(face, j, i0, i1).all(|(w, mask)| {
                maps.iter().flatten().fold(0, |acc, m| acc | m.bits[w]) & mask == mask
            })
        })
    }

    /// Whether the map's pixels meet those of `disc` (one of [`CubeMap::discs`]).
    pub(crate) fn meets(&self, disc: &Disc) -> bool {
        self.bits[disc.start..]
            .iter()
            .zip(&disc.words)
            .any(|(a, b)| a & b != 0)
    }

    /// The pixels within k growth steps of pixel `index` at resolution `n`, for k = 0
    /// up to 2n: pixel c is in `B` grown k times exactly when `B` meets c's disc k, the
    /// neighbour relation being symmetric (tested). Kept once computed, for up to 1,024
    /// pixels (`DISCS_KEPT`).
    pub(crate) fn discs(n: u32, index: usize) -> Arc<[Disc]> {
        use std::collections::HashMap;
        use std::sync::{Mutex, OnceLock};
        type Discs = HashMap<(u32, usize), Arc<[Disc]>>;
        static DISCS: OnceLock<Mutex<Discs>> = OnceLock::new();
        let discs = DISCS.get_or_init(|| Mutex::new(HashMap::new()));
        if let Some(d) = discs
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .get(&(n, index))
        {
            return d.clone();
        }
        let out = Self::discs_by_steps(n, index);
        let mut kept = discs.lock().unwrap_or_else(|e| e.into_inner());
        // A long-running process (the language server) plans many specs: the cache is
        // emptied rather than let grow past a few tens of megabytes.
        if kept.len() >= DISCS_KEPT {
            kept.clear();
        }
        kept.insert((n, index), out.clone());
        out
    }

    /// [`CubeMap::discs`] by a breadth-first walk from the pixel over the neighbours
    /// [`CubeMap::grow`] adds (the eight around it on its face, and those across the
    /// cube's edges): disc k holds the pixels at most k steps away. One walk instead of
    /// 2n growths of the whole map.
    fn discs_by_steps(n: u32, index: usize) -> Arc<[Disc]> {
        let nu = n as usize;
        let table = EdgeTable::of(n);
        let mut steps = vec![u32::MAX; 6 * nu * nu];
        let mut order = vec![index];
        steps[index] = 0;
        let mut next = 0;
        while next < order.len() {
            let p = order[next];
            next += 1;
            let s = steps[p] + 1;
            if s > 2 * n {
                continue;
            }
            let (face, j, i) = (p / (nu * nu), (p / nu) % nu, p % nu);
            let inside = (j.saturating_sub(1)..=(j + 1).min(nu - 1)).flat_map(|jj| {
                (i.saturating_sub(1)..=(i + 1).min(nu - 1))
                    .map(move |ii| (face * nu + jj) * nu + ii)
            });
            let across = table.across(p).iter().map(|&q| q as usize);
            for q in inside.chain(across) {
                if steps[q] == u32::MAX {
                    steps[q] = s;
                    order.push(q);
                }
            }
        }
        let mut bits = vec![0u64; (6 * nu * nu).div_ceil(64)];
        let mut out = Vec::with_capacity(2 * nu + 1);
        let mut at = 0;
        for k in 0..=2 * n {
            while at < order.len() && steps[order[at]] <= k {
                bits[order[at] / 64] |= 1 << (order[at] % 64);
                at += 1;
            }
            out.push(Disc::of(&bits));
        }
        out.into()
    }

    /// This map at resolution `n`, a multiple of its own: each fine pixel takes the bit
    /// of the coarse pixel holding it, each preferred direction its own bit. A cone whose
    /// free pixels are free in every direction they hold (cells, not centres) stays so.
    pub fn refined(&self, n: u32) -> CubeMap {
        debug_assert!(n >= self.n && n.is_multiple_of(self.n));
        if n == self.n {
            return self.clone();
        }
        let mut out = CubeMap {
            n,
            extra: self.extra.clone(),
            bits: vec![0; (6 * (n as usize) * (n as usize) + self.extra.len()).div_ceil(64)],
        };
        let k = n / self.n;
        for face in 0..6u8 {
            for j in 0..n {
                let mut i = 0;
                while i < n {
                    let coarse = Cell::Pixel(Pixel {
                        face,
                        i: i / k,
                        j: j / k,
                    });
                    if self.get(coarse) {
                        out.set_span(face, j, i, i + k - 1);
                    }
                    i += k;
                }
            }
        }
        for p in 0..self.extra.len() {
            if self.get(Cell::Preferred(p)) {
                out.set(Cell::Preferred(p), true);
            }
        }
        out
    }

    /// This map at resolution `n`, a divisor of its own: a coarse pixel is in it when
    /// any fine pixel it holds is; each preferred direction keeps its bit.
    pub fn coarsened(&self, n: u32) -> CubeMap {
        debug_assert!(n <= self.n && self.n.is_multiple_of(n));
        if n == self.n {
            return self.clone();
        }
        let mut out = CubeMap {
            n,
            extra: self.extra.clone(),
            bits: vec![0; (6 * (n as usize) * (n as usize) + self.extra.len()).div_ceil(64)],
        };
        let k = self.n / n;
        for cell in self.cells() {
            let c = match cell {
                Cell::Pixel(p) => Cell::Pixel(Pixel {
                    face: p.face,
                    i: p.i / k,
                    j: p.j / k,
                }),
                preferred => preferred,
            };
            out.set(c, true);
        }
        out
    }

    /// Whether every cell of `o` is in this map.
    pub fn covers(&self, o: &CubeMap) -> bool {
        debug_assert_eq!(self.n, o.n);
        self.bits.iter().zip(&o.bits).all(|(a, b)| b & !a == 0)
    }

    /// Adds every preferred direction.
    pub(crate) fn fill_preferred(&mut self) {
        for k in 0..self.extra.len() {
            self.set(Cell::Preferred(k), true);
        }
    }

    /// Every pixel whose closed cell holds the direction: one inside a pixel, up to four
    /// on pixel edges and corners, across cube edges too.
    pub fn pixels_holding(&self, d: &V3) -> Vec<Pixel> {
        let n = self.n as f64;
        let mut out = Vec::new();
        for face in 0..6u8 {
            let a = (face / 2) as usize;
            let s = if face.is_multiple_of(2) { 1.0 } else { -1.0 };
            let w = s * d[a];
            if w <= 0.0 {
                continue;
            }
            let (u, v) = (d[(a + 1) % 3] / w, d[(a + 2) % 3] / w);
            let tol = 1e-9;
            if u.abs() > 1.0 + tol || v.abs() > 1.0 + tol {
                continue;
            }
            let range = |x: f64| {
                let y = (x + 1.0) / 2.0 * n;
                let lo = ((y - tol).floor().max(0.0) as u32).min(self.n - 1);
                let hi = ((y + tol).floor().max(0.0) as u32).min(self.n - 1);
                lo..=hi
            };
            for j in range(v) {
                for i in range(u) {
                    let p = Pixel { face, i, j };
                    if !out.contains(&p) {
                        out.push(p);
                    }
                }
            }
        }
        out
    }

    /// Adds every pixel.
    pub(crate) fn fill_pixels(&mut self) {
        for f in 0..6 {
            for j in 0..self.n {
                self.set_span(f, j, 0, self.n - 1);
            }
        }
    }
}

/// How many pixels' discs [`CubeMap::discs`] keeps at most.
const DISCS_KEPT: usize = 1024;

/// Pixels around one pixel ([`CubeMap::discs`]): the pixel words from the first that
/// holds one to the last.
#[derive(Debug)]
pub(crate) struct Disc {
    start: usize,
    words: Vec<u64>,
}

impl Disc {
    fn of(bits: &[u64]) -> Disc {
        let start = bits.iter().position(|&w| w != 0).unwrap_or(0);
        let end = bits.iter().rposition(|&w| w != 0).map_or(start, |e| e + 1);
        Disc {
            start,
            words: bits[start..end].to_vec(),
        }
    }

    /// How many words a look at it reads.
    pub(crate) fn words(&self) -> usize {
        self.words.len()
    }
}

/// Per border pixel, its neighbours on other cube faces (bit indices), computed once per
/// resolution.
struct EdgeTable {
    /// Pixel index → range in `list` (empty inside a face).
    start: Vec<(u32, u32)>,
    list: Vec<u32>,
}

impl EdgeTable {
    /// The table of resolution `n` (at most 64), built once.
    fn of(n: u32) -> &'static EdgeTable {
        use std::sync::OnceLock;
        static TABLES: [OnceLock<EdgeTable>; 65] = [const { OnceLock::new() }; 65];
        TABLES[n as usize].get_or_init(|| EdgeTable::build(n))
    }

    fn build(n: u32) -> EdgeTable {
        let map = CubeMap::empty(n, &[]);
        let (mut start, mut list) = (vec![(0, 0); 6 * (n as usize) * (n as usize)], Vec::new());
        for face in 0..6u8 {
            for j in 0..n {
                for i in 0..n {
                    if i != 0 && j != 0 && i != n - 1 && j != n - 1 {
                        continue;
                    }
                    let p = Pixel { face, i, j };
                    let from = list.len() as u32;
                    for q in map.neighbours(p).into_iter().filter(|q| q.face != face) {
                        list.push(map.index(Cell::Pixel(q)) as u32);
                    }
                    start[map.index(Cell::Pixel(p))] = (from, list.len() as u32);
                }
            }
        }
        EdgeTable { start, list }
    }

    fn across(&self, pixel: usize) -> &[u32] {
        let (a, b) = self.start[pixel];
        &self.list[a as usize..b as usize]
    }
}

fn row_mask(n: usize) -> u64 {
    if n >= 64 {
        !0
    } else {
        (1u64 << n) - 1
    }
}

/// The unit directions of the pixels of a map of `like`'s resolution, in bit-index order
/// (exactly what [`CubeMap::direction`] gives), built once per resolution.
fn pixel_directions(like: &CubeMap) -> Arc<[V3]> {
    use std::collections::BTreeMap;
    use std::sync::{Mutex, OnceLock};
    static TABLES: OnceLock<Mutex<BTreeMap<u32, Arc<[V3]>>>> = OnceLock::new();
    let tables = TABLES.get_or_init(|| Mutex::new(BTreeMap::new()));
    let mut t = tables.lock().unwrap_or_else(|e| e.into_inner());
    t.entry(like.n)
        .or_insert_with(|| {
            let n = 6 * (like.n as usize).pow(2);
            (0..n).map(|k| like.direction(like.cell(k))).collect()
        })
        .clone()
}

/// `x.floor() as i64` without the libm call the baseline x86-64 target makes of
/// `floor` (no SSE4.1 rounding): the same integer for every `x`, NaN and infinities
/// saturating as the cast does. The rasterizer calls it for every span.
#[inline]
pub(super) fn floor_i(x: f64) -> i64 {
    let i = x as i64;
    if (i as f64) > x {
        i.saturating_sub(1)
    } else {
        i
    }
}

#[cfg(test)]
mod tests {

    /// Every direction of every cell, corners of pixels included, lies in the bounding
    /// cap: the planner passes over grid directions outside it unlooked.
    #[test]
    fn the_bounding_cap_holds_every_direction_of_every_cell() {
        use super::*;
        let pref = [V3::new(0.0, 0.6, 0.8), V3::new(-1.0, 0.0, 0.0)];
        for n in [4, 7, 32] {
            let empty = CubeMap::empty(n, &pref);
            assert!(empty.bounding_cap().is_none());
            let mut scattered = empty.clone();
            for k in (0..6 * (n as usize).pow(2)).filter(|k| k % 13 == 5) {
                scattered.set(scattered.cell(k), true);
            }
            scattered.set(Cell::Preferred(1), true);
            let cap = empty.cap(&V3::new(0.3, -0.2, 0.9).normalize(), 0.8);
            let mut across = empty.cap(&V3::new(1.0, 1.0, 1.0).normalize(), 0.97);
            across.set(Cell::Preferred(0), true);
            for map in [scattered, cap, across, empty.not()] {
                let (axis, angle) = map.bounding_cap().expect("not empty");
                for cell in map.cells() {
                    let corners: Vec<V3> = match cell {
                        Cell::Pixel(p) => {
                            let at = |k: u32| 2.0 * k as f64 / n as f64 - 1.0;
                            [(0, 0), (0, 1), (1, 0), (1, 1)]
                                .map(|(di, dj)| face_dir(p.face, at(p.i + di), at(p.j + dj)))
                                .to_vec()
                        }
                        Cell::Preferred(k) => vec![map.preferred(k)],
                    };
                    for d in corners {
                        let a = d.normalize().dot(&axis).clamp(-1.0, 1.0).acos();
                        assert!(a <= angle, "n = {n}: {cell:?} at {a} outside {angle}");
                    }
                }
            }
        }
    }

    /// [`CubeMap::discs`] relies on it: q is a neighbour of p exactly when p is one of q.
    #[test]
    fn growing_is_symmetric_and_discs_are_grown_pixels() {
        for n in [4, 7, 16, 32] {
            let empty = CubeMap::empty(n, &[]);
            let grown: Vec<Vec<usize>> = (0..6 * (n as usize).pow(2))
                .map(|p| {
                    let mut m = empty.clone();
                    m.bits[p / 64] |= 1 << (p % 64);
                    let g = m.grow();
                    (0..6 * (n as usize).pow(2))
                        .filter(|&q| g.has_index(q))
                        .collect()
                })
                .collect();
            for (p, near) in grown.iter().enumerate() {
                for &q in near {
                    assert!(
                        grown[q].contains(&p),
                        "n = {n}: {q} grows from {p}, not back"
                    );
                }
            }
            let d = CubeMap::discs(n, 5);
            assert_eq!(d.len(), 2 * n as usize + 1);
            // The walk's discs are the growths', ring by ring, from a face's inside,
            // edge and corner.
            let last = 6 * (n as usize).pow(2) - 1;
            for p in [0, 5, n as usize * (n as usize / 2) + 1, last] {
                let walked = CubeMap::discs_by_steps(n, p);
                let mut m = empty.clone();
                m.bits[p / 64] |= 1 << (p % 64);
                for (k, disc) in walked.iter().enumerate() {
                    let grown = Disc::of(&m.bits);
                    assert_eq!(
                        (disc.start, &disc.words),
                        (grown.start, &grown.words),
                        "n = {n}, pixel {p}, ring {k}"
                    );
                    m = m.grow();
                }
            }
            let mut m = empty.clone();
            m.bits[0] |= 1 << 5;
            let g = m.grown(3);
            assert_eq!(
                g.bits[d[3].start..d[3].start + d[3].words()],
                d[3].words[..]
            );
            assert_eq!(
                g.count(),
                d[3].words
                    .iter()
                    .map(|w| w.count_ones() as usize)
                    .sum::<usize>()
            );
        }
    }

    #[test]
    fn a_refined_map_gives_each_fine_pixel_its_coarse_pixels_bit() {
        let pref = [V3::z()];
        let mut coarse = CubeMap::empty(4, &pref);
        coarse.set(
            Cell::Pixel(Pixel {
                face: 2,
                i: 1,
                j: 3,
            }),
            true,
        );
        coarse.set(Cell::Preferred(0), true);
        let fine = coarse.refined(8);
        assert_eq!(fine.n(), 8);
        assert_eq!(fine.count(), 4 + 1);
        for (i, j) in [(2, 6), (3, 6), (2, 7), (3, 7)] {
            assert!(fine.get(Cell::Pixel(Pixel { face: 2, i, j })));
        }
        assert!(fine.get(Cell::Preferred(0)));
        assert_eq!(coarse.refined(4), coarse);
    }

    use super::*;

    #[test]
    fn directions_round_trip_through_their_pixels() {
        let c = CubeMap::empty(16, &[]);
        for k in 0..c.len() {
            let cell = c.cell(k);
            assert_eq!(c.index(cell), k);
            assert_eq!(c.cell_of(&c.direction(cell)), cell);
        }
    }

    #[test]
    fn full_empty_not_and_count() {
        let prefs = [V3::z(), -V3::x()];
        let full = CubeMap::full(8, &prefs);
        assert_eq!(full.count(), 6 * 64 + 2);
        assert!(full.not().is_empty());
        let mut half = CubeMap::empty(8, &prefs);
        for cell in full
            .cells()
            .filter(|c| matches!(c, Cell::Pixel(p) if p.face % 2 == 0))
        {
            half.set(cell, true);
        }
        assert_eq!(half.count(), 3 * 64);
        assert_eq!(half.or(&half.not()), full);
        assert!(half.and(&half.not()).is_empty());
        assert!(half.contains(&V3::new(1.0, 0.2, 0.1)) && !half.contains(&V3::new(-1.0, 0.2, 0.1)));
    }

    #[test]
    fn preferred_directions_are_exact() {
        let mut c = CubeMap::empty(4, &[V3::z()]);
        assert_eq!(c.cell_of(&V3::new(0.0, 0.0, 2.0)), Cell::Preferred(0));
        c.set(Cell::Preferred(0), true);
        assert!(c.contains(&V3::z()));
        // +z is a pixel corner; the pixels around it are not in the cone.
        assert!(!c.contains(&V3::new(1e-3, 1e-3, 1.0)));
    }

    #[test]
    fn growing_crosses_cube_edges() {
        let mut c = CubeMap::empty(8, &[]);
        // The +z pixel at the +x edge.
        let p = Pixel {
            face: 4,
            i: 7,
            j: 3,
        };
        c.set(Cell::Pixel(p), true);
        let g = c.grow();
        assert_eq!(g.count(), 9);
        assert!(
            g.cells()
                .any(|c| matches!(c, Cell::Pixel(q) if q.face == 0)),
            "no +x pixel after growing"
        );
    }

    #[test]
    fn fast_growth_matches_the_neighbour_definition() {
        for n in [5u32, 8, 32, 64] {
            let mut c = CubeMap::empty(n, &[V3::z()]);
            let mut k = 7usize;
            for idx in 0..6 * (n as usize) * (n as usize) {
                k = k
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                if k >> 60 == 0 {
                    c.set(c.cell(idx), true);
                }
            }
            assert_eq!(c.grow_pixels(), c.grow_slow(), "n = {n}");
        }
    }

    /// A growth chain's step grown after the step before it is the step grown whole:
    /// sparse and dense maps, pixels joined to each step as `finish` joins bands.
    #[test]
    fn growing_after_the_step_before_is_growing_whole() {
        for n in [5u32, 8, 16, 32, 64] {
            for density in [60, 62] {
                let mut k = 11usize;
                let mut random = |c: &mut CubeMap| {
                    for idx in 0..6 * (n as usize) * (n as usize) {
                        k = k
                            .wrapping_mul(6364136223846793005)
                            .wrapping_add(1442695040888963407);
                        if k >> density == 0 {
                            c.set(c.cell(idx), true);
                        }
                    }
                };
                let mut before = CubeMap::empty(n, &[]);
                random(&mut before);
                for _ in 0..4 {
                    let mut step = before.grow_pixels();
                    random(&mut step);
                    assert_eq!(
                        step.grow_pixels_after(Some(&before)),
                        step.grow_pixels(),
                        "n = {n}"
                    );
                    before = step;
                }
            }
        }
    }

    #[test]
    fn spans_set_exactly_their_pixels() {
        for n in [5u32, 32, 64] {
            let mut c = CubeMap::empty(n, &[]);
            c.set_span(3, 2, 1, n - 2);
            assert_eq!(c.count(), n as usize - 2);
            assert!(c.get(Cell::Pixel(Pixel {
                face: 3,
                i: 1,
                j: 2
            })));
            assert!(!c.get(Cell::Pixel(Pixel {
                face: 3,
                i: 0,
                j: 2
            })));
            assert_eq!(c.row(3, 2), ((1u64 << (n - 1)) - 1) & !1);
        }
    }
}
