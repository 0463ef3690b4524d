//! Tours (seed ch. 5.3.2): the order in which a group visits its points, as an open path
//! over a symmetric distance matrix (shortest paths in the roadmap) from a fixed start.
//!
//! [`solve`] is exact by dynamic programming (Held–Karp) up to [`EXACT_MAX`] points and
//! otherwise [`heuristic`]: nearest neighbour, then 2-opt and Or-opt until neither
//! improves. [`nearest_neighbour`] is the baseline the bench compares against.

/// The most points [`solve`] orders exactly.
pub(crate) const EXACT_MAX: usize = 12;

/// Improvements smaller than this are noise (mm).
const EPS: f64 = 1e-9;

/// A symmetric distance matrix with the distances from a start position.
#[derive(Debug, Clone)]
pub struct Matrix {
    n: usize,
    d: Vec<f64>,
    start: Vec<f64>,
}

impl Matrix {
    /// `d(i, j)` for i, j < n; `start[i]` from the start position (zeros: a free start).
    pub fn new(n: usize, d: impl Fn(usize, usize) -> f64, start: Vec<f64>) -> Matrix {
        let mut m = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                m[i * n + j] = d(i, j);
            }
        }
        Matrix { n, d: m, start }
    }

    /// Straight-line distances between points, from `start` (`None`: a free start).
    pub fn euclidean(points: &[[f64; 3]], start: Option<[f64; 3]>) -> Matrix {
        let d = |a: &[f64; 3], b: &[f64; 3]| {
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
        };
        Matrix::new(
            points.len(),
            |i, j| d(&points[i], &points[j]),
            points
                .iter()
                .map(|p| start.map_or(0.0, |s| d(&s, p)))
                .collect(),
        )
    }

    /// The number of points.
    pub fn len(&self) -> usize {
        self.n
    }

    /// Whether there are no points.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// The distance between two points.
    pub fn d(&self, i: usize, j: usize) -> f64 {
        self.d[i * self.n + j]
    }

    /// The distance from the start to a point.
    pub fn from_start(&self, i: usize) -> f64 {
        self.start[i]
    }

    /// The length of an open path in this order, from the start.
    pub fn length(&self, order: &[usize]) -> f64 {
        match order.first() {
            None => 0.0,
            Some(&f) => self.start[f] + order.windows(2).map(|w| self.d(w[0], w[1])).sum::<f64>(),
        }
    }

    /// The cost of the edge entering position `k` of `order` (from the start for 0).
    fn into(&self, order: &[usize], k: usize) -> f64 {
        if k == 0 {
            self.start[order[0]]
        } else {
            self.d(order[k - 1], order[k])
        }
    }
}

/// The best order: exact up to [`EXACT_MAX`] points, else [`heuristic`].
pub fn solve(m: &Matrix) -> Vec<usize> {
    if m.n <= EXACT_MAX {
        exact(m)
    } else {
        heuristic(m)
    }
}

/// Nearest neighbour from the start; ties go to the lower index.
pub fn nearest_neighbour(m: &Matrix) -> Vec<usize> {
    nearest_from(m, None)
}

/// Nearest neighbour, optionally with a given first point.
fn nearest_from(m: &Matrix, first: Option<usize>) -> Vec<usize> {
    let mut left: Vec<bool> = vec![true; m.n];
    let mut order = Vec::with_capacity(m.n);
    if let Some(f) = first {
        left[f] = false;
        order.push(f);
    }
    while order.len() < m.n {
        let from = order.last().copied();
        let mut best: Option<(f64, usize)> = None;
        for (j, _) in left.iter().enumerate().filter(|(_, l)| **l) {
            let c = match from {
                None => m.start[j],
                Some(i) => m.d(i, j),
            };
            if best.is_none_or(|(b, _)| c < b - EPS) {
                best = Some((c, j));
            }
        }
        let Some((_, j)) = best else { break };
        left[j] = false;
        order.push(j);
    }
    order
}

/// How many first points the heuristic tries.
const STARTS: usize = 12;

/// Local search from several nearest-neighbour tours — each starting at one of the
/// [`STARTS`] points nearest the start — with 2-opt and Or-opt (runs of 1–3 points,
/// either way round) until neither improves; the shortest wins (ties: the first).
pub fn heuristic(m: &Matrix) -> Vec<usize> {
    let mut firsts: Vec<usize> = (0..m.n).collect();
    firsts.sort_by(|&a, &b| m.start[a].total_cmp(&m.start[b]).then(a.cmp(&b)));
    firsts.truncate(STARTS);
    let mut best: Option<(f64, Vec<usize>)> = None;
    for first in std::iter::once(None).chain(firsts.into_iter().map(Some)) {
        let mut order = nearest_from(m, first);
        while two_opt(m, &mut order) | or_opt(m, &mut order) {}
        let l = m.length(&order);
        if best.as_ref().is_none_or(|(b, _)| l < b - EPS) {
            best = Some((l, order));
        }
    }
    best.map(|(_, o)| o).unwrap_or_default()
}

/// One pass of 2-opt on an open path: reverse `order[i..=j]` when that is shorter.
fn two_opt(m: &Matrix, order: &mut [usize]) -> bool {
    let n = order.len();
    let mut improved = false;
    for i in 0..n {
        for j in i + 1..n {
            let before = m.into(order, i)
                + if j + 1 < n {
                    m.d(order[j], order[j + 1])
                } else {
                    0.0
                };
            let entry = if i == 0 {
                m.start[order[j]]
            } else {
                m.d(order[i - 1], order[j])
            };
            let after = entry
                + if j + 1 < n {
                    m.d(order[i], order[j + 1])
                } else {
                    0.0
                };
            if after < before - EPS {
                order[i..=j].reverse();
                improved = true;
            }
        }
    }
    improved
}

/// The cost of an edge of the open path: `None` on the left is the start, `None` on the
/// right the free end.
fn edge(m: &Matrix, a: Option<usize>, b: Option<usize>) -> f64 {
    match (a, b) {
        (_, None) => 0.0,
        (None, Some(j)) => m.start[j],
        (Some(i), Some(j)) => m.d(i, j),
    }
}

/// One pass of Or-opt: move a run of 1–3 points to the best other place, reversed or
/// not, when that is shorter. O(n²) per run length.
fn or_opt(m: &Matrix, order: &mut Vec<usize>) -> bool {
    let mut improved = false;
    for len in 1..=3usize {
        let mut i = 0;
        while i + len <= order.len() {
            let n = order.len();
            let prev = if i == 0 { None } else { Some(order[i - 1]) };
            let next = order.get(i + len).copied();
            let (first, last) = (order[i], order[i + len - 1]);
            let gain = edge(m, prev, Some(first)) + edge(m, Some(last), next) - edge(m, prev, next);
            // Insert between rest[a-1] and rest[a] of the path without the run.
            let mut best: Option<(f64, usize, bool)> = None;
            for a in 0..=(n - len) {
                if a == i {
                    continue;
                }
                let at = |k: usize| if k < i { order[k] } else { order[k + len] };
                let x = if a == 0 { None } else { Some(at(a - 1)) };
                let y = if a < n - len { Some(at(a)) } else { None };
                let base = edge(m, x, y);
                for rev in [false, true] {
                    let (h, t) = if rev { (last, first) } else { (first, last) };
                    let cost = edge(m, x, Some(h)) + edge(m, Some(t), y) - base;
                    if cost < gain - EPS && best.is_none_or(|(b, _, _)| cost < b - EPS) {
                        best = Some((cost, a, rev));
                    }
                }
            }
            if let Some((_, a, rev)) = best {
                let mut run: Vec<usize> = order.drain(i..i + len).collect();
                if rev {
                    run.reverse();
                }
                order.splice(a..a, run);
                improved = true;
            } else {
                i += 1;
            }
        }
    }
    improved
}

/// The optimal open path by Held–Karp: O(2ⁿ n²); `None`-free for n ≤ 20, so callers
/// keep n small.
pub fn exact(m: &Matrix) -> Vec<usize> {
    let n = m.n;
    if n == 0 {
        return vec![];
    }
    assert!(n <= 20, "Held–Karp on {n} points");
    let full = 1usize << n;
    let mut cost = vec![f64::INFINITY; full * n];
    let mut prev = vec![usize::MAX; full * n];
    for j in 0..n {
        cost[(1 << j) * n + j] = m.start[j];
    }
    for set in 1..full {
        for j in 0..n {
            let c = cost[set * n + j];
            if set & (1 << j) == 0 || !c.is_finite() {
                continue;
            }
            for k in 0..n {
                if set & (1 << k) != 0 {
                    continue;
                }
                let next = set | (1 << k);
                let v = c + m.d(j, k);
                if v < cost[next * n + k] - EPS {
                    cost[next * n + k] = v;
                    prev[next * n + k] = j;
                }
            }
        }
    }
    let last = full - 1;
    let mut end = 0;
    for j in 1..n {
        if cost[last * n + j] < cost[last * n + end] - EPS {
            end = j;
        }
    }
    let mut order = Vec::with_capacity(n);
    let (mut set, mut j) = (last, end);
    while j != usize::MAX {
        order.push(j);
        let p = prev[set * n + j];
        set &= !(1 << j);
        j = p;
    }
    order.reverse();
    order
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(xs: &[f64]) -> Matrix {
        Matrix::new(
            xs.len(),
            |i, j| (xs[i] - xs[j]).abs(),
            xs.iter().map(|x| x.abs()).collect(),
        )
    }

    #[test]
    fn points_on_a_line_are_visited_in_order() {
        let m = line(&[3.0, 1.0, 2.0, 5.0, 4.0]);
        assert_eq!(exact(&m), vec![1, 2, 0, 4, 3]);
        assert_eq!(heuristic(&m), vec![1, 2, 0, 4, 3]);
        assert!((m.length(&exact(&m)) - 5.0).abs() < 1e-12);
    }

    #[test]
    fn empty_and_single() {
        let m = line(&[]);
        assert!(solve(&m).is_empty());
        let m = line(&[7.0]);
        assert_eq!(solve(&m), vec![0]);
    }
}
