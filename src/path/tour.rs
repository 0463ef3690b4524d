//! Tours (seed ch. 5.3.2): the order in which a group visits its points, as an open path
//! over a symmetric distance matrix (shortest paths in the roadmap) from a fixed start.
//!
//! [`solve`] is exact by dynamic programming (Held–Karp) up to [`EXACT_MAX`] points and
//! otherwise [`heuristic`]: nearest neighbour, then 2-opt and Or-opt until neither
//! improves. [`nearest_neighbour`] is the baseline the bench compares against.

/// The most points [`solve`] orders exactly.
pub const EXACT_MAX: usize = 12;

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
    let mut left: Vec<bool> = vec![true; m.n];
    let mut order = Vec::with_capacity(m.n);
    for _ in 0..m.n {
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

/// Nearest neighbour improved by 2-opt and Or-opt (segments of 1–3 points, either way
/// round) until a pass finds nothing better.
pub fn heuristic(m: &Matrix) -> Vec<usize> {
    let mut order = nearest_neighbour(m);
    loop {
        let a = two_opt(m, &mut order);
        let b = or_opt(m, &mut order);
        if !a && !b {
            return order;
        }
    }
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

/// One pass of Or-opt: move a run of 1–3 points elsewhere, reversed or not.
fn or_opt(m: &Matrix, order: &mut Vec<usize>) -> bool {
    let mut improved = false;
    for len in 1..=3usize {
        let mut i = 0;
        while i + len <= order.len() {
            let base = m.length(order);
            let run: Vec<usize> = order[i..i + len].to_vec();
            let mut rest = order.clone();
            rest.drain(i..i + len);
            let mut best: Option<(f64, Vec<usize>)> = None;
            for at in 0..=rest.len() {
                if at == i {
                    continue;
                }
                for rev in [false, true] {
                    let mut cand = rest.clone();
                    let mut r = run.clone();
                    if rev {
                        r.reverse();
                    }
                    cand.splice(at..at, r);
                    let l = m.length(&cand);
                    if l < base - EPS && best.as_ref().is_none_or(|(b, _)| l < b - EPS) {
                        best = Some((l, cand));
                    }
                }
            }
            if let Some((_, cand)) = best {
                *order = cand;
                improved = true;
            }
            i += 1;
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
