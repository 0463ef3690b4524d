//! Following references between instances, the one way the readers do it.
//!
//! ISO 10303-21 lets any instance refer to any other, so a file can make a shell of
//! itself, a trimmed curve of itself or a datum reference of itself, directly or round
//! a longer circle. Every reader that follows a reference whose depth the file decides
//! (a shell wrapping a shell, a curve wrapping a curve, a datum reference listing
//! others) goes through [`Trail::follow`]: the instances being resolved are on the
//! trail, a reference back to one of them is a `step_cycle` error naming the circle,
//! and a chain deeper than [`MAX_DEPTH`] is malformed. Results are memoised by the
//! callers ([`Memo`]), so an instance is resolved once however often it is named.

use super::error::StepError;
use std::cell::RefCell;
use std::collections::HashMap;

/// How many wrapped references may be followed from one instance: far more than any
/// schema nests (an oriented shell of a shell, a trimmed curve of a surface curve).
pub(crate) const MAX_DEPTH: usize = 64;

/// The instances being resolved, innermost last.
#[derive(Debug, Default)]
pub(crate) struct Trail {
    path: RefCell<Vec<u64>>,
}

impl Trail {
    /// Runs `resolve` for instance `id` (at `line`) with `id` on the trail: an error if
    /// it is already there (a circle) or the trail is [`MAX_DEPTH`] long.
    pub fn follow<T>(
        &self,
        id: u64,
        line: usize,
        resolve: impl FnOnce() -> Result<T, StepError>,
    ) -> Result<T, StepError> {
        self.enter(id, line)?;
        let out = resolve();
        self.leave();
        out
    }

    /// Puts `id` on the trail (for a caller that cannot pass a closure); [`Trail::leave`]
    /// takes it off.
    pub fn enter(&self, id: u64, line: usize) -> Result<(), StepError> {
        let mut path = self.path.borrow_mut();
        if let Some(k) = path.iter().position(|p| *p == id) {
            return Err(StepError::Cycle {
                ids: path[k..].to_vec(),
                line,
            });
        }
        if path.len() >= MAX_DEPTH {
            return Err(StepError::Malformed {
                id,
                line,
                message: format!("it is reached through more than {MAX_DEPTH} references"),
            });
        }
        path.push(id);
        Ok(())
    }

    /// Takes the innermost instance off the trail.
    pub fn leave(&self) {
        self.path.borrow_mut().pop();
    }
}

/// Results by instance: what is resolved once is cloned after (cheaply: heavy results
/// are shared).
#[derive(Debug)]
pub(crate) struct Memo<T>(RefCell<HashMap<u64, T>>);

impl<T> Default for Memo<T> {
    fn default() -> Self {
        Memo(RefCell::new(HashMap::new()))
    }
}

impl<T: Clone> Memo<T> {
    /// The result for `id`, resolved by `resolve` the first time.
    pub fn get_or(
        &self,
        id: u64,
        resolve: impl FnOnce() -> Result<T, StepError>,
    ) -> Result<T, StepError> {
        if let Some(v) = self.0.borrow().get(&id) {
            return Ok(v.clone());
        }
        let v = resolve()?;
        self.0.borrow_mut().insert(id, v.clone());
        Ok(v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_circle_is_named_and_depth_is_bounded() {
        let t = Trail::default();
        let e = t
            .follow(1, 3, || t.follow(2, 4, || t.follow(1, 3, || Ok(()))))
            .unwrap_err();
        assert_eq!(
            e,
            StepError::Cycle {
                ids: vec![1, 2],
                line: 3
            }
        );
        fn chain(t: &Trail, id: u64) -> Result<(), StepError> {
            t.follow(id, 1, || chain(t, id + 1))
        }
        assert!(matches!(chain(&t, 0), Err(StepError::Malformed { .. })));
    }
}
