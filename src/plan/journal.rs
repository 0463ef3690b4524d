//! Re-plans that resume where a ban first matters (issue 47: every real part in 2 s).
//!
//! The path stage sends a plan back with configurations banned ([`Ban`]) and the planner
//! searches the same input again. Generate-and-test is deterministic: until a round
//! validates a touch that a new ban covers, every round of the new search computes what
//! the last search's did (the same knowledge, clustering and validation results), so
//! its rounds up to there are the old ones. The journal keeps, per search, the state at the
//! start of each round that validated touches, with those touches; a re-plan takes up the
//! state of the first round whose touches a new ban covers (the last round's where none
//! does: then only what the search does after it settles changes) and searches on from
//! there. The plan is the one a search from the first round gives (a test compares
//! them; every NIST spec, example and MFCAD part builds byte-identical programs). CTC 02's
//! re-plans resume at round 36 of 37: its build takes 7.1 s, not 8.3 s; the imported
//! FTC 08 4.4 s, not 6.1 s; the MFCAD part with the most re-plans 16.8 s, not 27.8 s.
//!
//! **Decision: which rounds.** A state is taken before a round that follows one that
//! validated touches: the rounds before the first validation acquire most of the
//! whole-probe cones, and a state held across them would copy every domain they change.
//! The touches of a round without a state count with the state before it.
//!
//! **Decision: what a state is.** The knowledge's learnt part (`knowledge::Learnt`:
//! the domains, whose rows the states share until learning changes one, D1′, the setups
//! whose holding was asked, the table alternatives' life) and the search's own
//! ([`super::search`]: touches validated, fragile counts, faces skipped, the fallback,
//! why the last round failed). Pure results (cones, depth maps, orientations) are in the
//! memo already. A state is kept only while the search has reported nothing: a round that
//! reports faces short under `allow_unmeasured` and goes on would not report again from a
//! later state.
//!
//! **Decision: which searches.** One journal per search of an input: keyed by the turn
//! the touches are validated at and the faces left to a scanner, kept in the
//! [`super::Memo`] (which forgets them when a dense graph is renumbered), taken up only
//! where the bans it was written under begin the new search's bans. The journal knows
//! neither the state nor the touches it keeps (`S`, `C`): the memo sits below the search
//! and holds it as the search hands it over.

use super::Ban;

/// What the states of one search may hold at most (bytes, counting each state's domains
/// as if none were shared with the knowledge): 8 states on CTC 02.
const BUDGET: usize = 64 << 20;

/// The rounds of one search that validated touches: the state `S` each started from and
/// the touches `C` it validated.
pub(super) struct Journal<S, C> {
    /// The bans the search ran under.
    bans: Vec<Ban>,
    entries: Vec<Entry<S, C>>,
    /// The search reported something: no later state is kept.
    closed: bool,
    /// How many states are kept: the latest (an earlier state the journal no longer
    /// holds means a search from the first round).
    most: usize,
    /// The touches validated by the rounds whose states were let go: a ban on one of
    /// them means a search from the first round.
    lost: Vec<C>,
}

/// The state at the start of a round, and the touches the round validated.
struct Entry<S, C> {
    iteration: usize,
    state: S,
    checked: Vec<C>,
}

impl<S, C> Journal<S, C> {
    /// A journal for a search under `bans` whose states take up to `bytes` each.
    pub fn new(bans: &[Ban], bytes: usize) -> Self {
        Journal {
            bans: bans.to_vec(),
            entries: Vec::new(),
            closed: false,
            most: (BUDGET / bytes.max(1)).clamp(1, 32),
            lost: Vec::new(),
        }
    }

    /// Takes up the journal for a search under `bans`, `banned` saying whether bans
    /// cover a touch: the round to run next, the state it starts from, and the journal
    /// of the rounds before it. None where the journal ran under other bans, kept
    /// nothing, or let go of the state a new ban needs.
    pub fn resume(
        mut self,
        bans: &[Ban],
        banned: impl Fn(&C, &[Ban]) -> bool,
    ) -> Option<(usize, S, Self)> {
        let new = bans.strip_prefix(self.bans.as_slice())?;
        let hit = |c: &C| banned(c, new);
        if self.lost.iter().any(hit) {
            return None;
        }
        let at = match self.entries.iter().position(|e| e.checked.iter().any(hit)) {
            Some(i) => i,
            None => self.entries.len().checked_sub(1)?,
        };
        self.entries.truncate(at + 1);
        let from = self.entries.pop()?;
        self.bans = bans.to_vec();
        self.closed = false;
        Some((from.iteration, from.state, self))
    }

    /// Keeps the state a round started from (`state`, where the search took it), where
    /// the round validated touches and the search had reported nothing before it
    /// (`reported`). The touches of a round without its state go with the state before
    /// (a ban on them resumes there), or with the states let go.
    pub fn record(
        &mut self,
        iteration: usize,
        state: Option<S>,
        mut checked: Vec<C>,
        reported: bool,
    ) {
        if self.closed || reported {
            self.closed = true;
            return;
        }
        if checked.is_empty() {
            return;
        }
        let Some(state) = state else {
            match self.entries.last_mut() {
                Some(e) => e.checked.append(&mut checked),
                None => self.lost.append(&mut checked),
            }
            return;
        };
        if self.entries.len() == self.most {
            let gone = self.entries.remove(0);
            self.lost.extend(gone.checked);
        }
        self.entries.push(Entry {
            iteration,
            state,
            checked,
        });
    }
}
