//! Following id references between QIF elements, the one way the readers do it where
//! the file decides how far they go: a compound feature nominal naming further
//! features, each naming more.
//!
//! QIF 3 (`QIFDocument`'s `FeatureNominalIds`, `EntityInternalIds`) lets any element
//! name any id, so a file can chain 100,000 features or name one from itself. The walk
//! is iterative (a chain as long as the file costs no stack), marks the elements being
//! resolved so that a reference back to one is a `qif_cycle` error naming the circle,
//! and counts every element it enters against one budget for the whole document, so
//! that the work is proportional to the file however often elements are named.

use super::error::QifError;
use std::cell::Cell;
use std::collections::HashMap;

/// How many elements the walks of one document may enter in all: a few times its
/// elements.
pub(crate) fn budget(elements: usize) -> Cell<usize> {
    Cell::new(4 * elements + 10_000)
}

/// Every id reachable from `start` through `next` (depth first, `start` first), each
/// once; `None` when the budget ran out on the way. `line_of` gives an id's line for
/// the error.
pub(crate) fn reachable(
    start: u64,
    next: impl Fn(u64) -> Vec<u64>,
    line_of: impl Fn(u64) -> usize,
    budget: &Cell<usize>,
) -> Result<Option<Vec<u64>>, QifError> {
    let mut w = Walk {
        open: HashMap::new(),
        out: Vec::new(),
        path: Vec::new(),
        next,
        budget,
    };
    if !w.enter(start) {
        return Ok(None);
    }
    while let Some((id, rest)) = w.path.last_mut() {
        let Some(n) = rest.next() else {
            w.open.insert(*id, false);
            w.path.pop();
            continue;
        };
        match w.open.get(&n) {
            Some(false) => {}
            Some(true) => {
                let from = w.path.iter().position(|(p, _)| *p == n).unwrap_or(0);
                return Err(QifError::Cycle {
                    ids: w.path[from..].iter().map(|(p, _)| *p).collect(),
                    line: line_of(n),
                });
            }
            None => {
                if !w.enter(n) {
                    return Ok(None);
                }
            }
        }
    }
    Ok(Some(w.out))
}

/// A walk under way.
struct Walk<'b, F> {
    /// Ids entered: `true` while being resolved, `false` once done.
    open: HashMap<u64, bool>,
    out: Vec<u64>,
    /// The ids being resolved, each with the ids it names still to enter.
    path: Vec<(u64, std::vec::IntoIter<u64>)>,
    next: F,
    budget: &'b Cell<usize>,
}

impl<F: Fn(u64) -> Vec<u64>> Walk<'_, F> {
    /// Enters `id`; `false` when the budget is spent.
    fn enter(&mut self, id: u64) -> bool {
        let left = self.budget.get();
        if left == 0 {
            return false;
        }
        self.budget.set(left - 1);
        self.open.insert(id, true);
        self.out.push(id);
        self.path.push((id, (self.next)(id).into_iter()));
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_chains_read_and_circles_are_named() {
        let chain = |n: u64| if n < 100_000 { vec![n + 1] } else { vec![] };
        let all = reachable(0, chain, |_| 1, &budget(200_000))
            .unwrap()
            .unwrap();
        assert_eq!(all.len(), 100_001);
        let circle = |n: u64| vec![(n + 1) % 3];
        let e = reachable(0, circle, |n| n as usize, &budget(10)).unwrap_err();
        assert_eq!(
            e,
            QifError::Cycle {
                ids: vec![0, 1, 2],
                line: 0
            }
        );
        // A diamond is no circle.
        let diamond = |n: u64| match n {
            0 => vec![1, 2],
            1 | 2 => vec![3],
            _ => vec![],
        };
        assert_eq!(
            reachable(0, diamond, |_| 1, &budget(10))
                .unwrap()
                .unwrap()
                .len(),
            4
        );
        assert_eq!(reachable(0, chain, |_| 1, &Cell::new(5)).unwrap(), None);
    }
}
