//! Which children the walk of rays from one origin (`wide/shared_origin.rs`) visits first, learnt
//! as a thread renders.
//!
//! "Is anything in the way" has the same answer in any order, but not the same cost. Nearest to the
//! origin first suits a lone object: the probes that are blocked are blocked close by, in its
//! folds, and the others escape whatever the order. Farthest first suits an interior: every probe
//! ends on the room's walls, floor or ceiling, large boxes beyond the furniture around the origin,
//! which nearest first searches in vain before reaching them. Measured with `--mode ao --samples
//! 16` at 1 thread: the staircase 581 -> 348 ms farthest first, the 1.1M-triangle bunny 964 -> 1,112
//! ms.
//!
//! Neither order can be told from the scene, so each thread tries both: in every epoch of
//! [`EPOCH`] walks, the first [`TRIALS`] alternate the two orders and are timed, and farthest first
//! is used for the rest if its trials took less than [`FARTHEST_IF_BELOW`] of the others' time.
//! Time, not the nodes and blocks visited: on the bunny, farthest first visits 5% fewer of them
//! but takes 16% longer (its walks jump across a 76 MB tree, where nearest first stays with the
//! nodes the previous pixel fetched). The trials are noisy: on the bunny, the epochs' ratios of
//! farthest-first to nearest-first time ranged from 0.44 to 2.7, a quarter of them below 1; on the
//! staircase from 0.20 to 0.96, a median of 0.48. The image never depends on the choice: every
//! order gives every ray's own answer.

use std::cell::Cell;
use std::time::Instant;

/// The order of a walk's visits among the children its rays enter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VisitOrder {
    /// Children nearer the origin first.
    NearestFirst,
    /// Children farther from the origin first.
    FarthestFirst,
}

impl VisitOrder {
    /// Sort keys of children at `distances` from the origin (or entry distances along a ray): the
    /// child of the least key is visited first.
    #[inline(always)]
    pub(super) fn keys<const W: usize>(self, distances: [f32; W]) -> [f32; W] {
        match self {
            VisitOrder::NearestFirst => distances,
            VisitOrder::FarthestFirst => distances.map(|d| -d),
        }
    }
}

/// Walks per epoch (a walk per pixel and pass: sixteen tiles of 16x16 pixels): a fresh choice this
/// often follows the parts of the scene a thread moves across.
const EPOCH: u32 = 4096;
/// Walks per epoch that try the orders in turn: half of them, 0.4% of all, pay for the worse one.
const TRIALS: u32 = 32;
/// Farthest first is chosen when its trials took less than this fraction of nearest first's.
const FARTHEST_IF_BELOW: f64 = 0.7;

thread_local! {
    /// This thread's choice, learnt from its walks tile after tile (a tile of 16x16 pixels is too
    /// few walks to learn from: trials were an eighth of them).
    static CHOOSER: Cell<OrderChooser> = Cell::new(OrderChooser::default());
}

/// `walk(order)` in the order this thread's walks take next, timed when it is one of the trials
/// that choose it. `walk` is called from one place, so that it is inlined into the caller's ISA
/// (an intrinsic out of line becomes a call).
#[inline(always)]
pub fn in_learnt_order<R>(walk: impl FnOnce(VisitOrder) -> R) -> R {
    let mut chooser = CHOOSER.get();
    let order = chooser.next();
    let start = chooser.is_trial().then(Instant::now);
    let result = walk(order);
    chooser.record(order, start.map_or(0, |start| start.elapsed().as_nanos() as u64));
    CHOOSER.set(chooser);
    result
}

/// A thread's choice of [`VisitOrder`]: what it tries or uses next, and what its trials cost.
#[derive(Clone, Copy, Debug)]
struct OrderChooser {
    /// Walks so far.
    walks: u32,
    /// The time the trials of this epoch took, per order (any unit).
    trial_costs: [u64; 2],
    chosen: VisitOrder,
}

impl Default for OrderChooser {
    fn default() -> Self {
        OrderChooser { walks: 0, trial_costs: [0; 2], chosen: VisitOrder::NearestFirst }
    }
}

impl OrderChooser {
    /// The order of the next walk.
    #[inline]
    fn next(&self) -> VisitOrder {
        let k = self.walks % EPOCH;
        if k >= TRIALS {
            self.chosen
        } else if k.is_multiple_of(2) {
            VisitOrder::NearestFirst
        } else {
            VisitOrder::FarthestFirst
        }
    }

    /// Whether the next walk is a trial, whose time [`OrderChooser::record`] needs.
    #[inline]
    fn is_trial(&self) -> bool {
        self.walks % EPOCH < TRIALS
    }

    /// Records the walk [`OrderChooser::next`] ordered, and the time it took if it was a trial
    /// (ignored otherwise).
    #[inline]
    fn record(&mut self, order: VisitOrder, cost: u64) {
        let k = self.walks % EPOCH;
        if k < TRIALS {
            self.trial_costs[order as usize] += cost;
            if k == TRIALS - 1 {
                let [nearest, farthest] = self.trial_costs;
                let faster = (farthest as f64) < FARTHEST_IF_BELOW * nearest as f64;
                self.chosen = if faster { VisitOrder::FarthestFirst } else { VisitOrder::NearestFirst };
                self.trial_costs = [0; 2];
            }
        }
        self.walks = self.walks.wrapping_add(1);
    }
}

#[cfg(test)]
mod tests {
    use super::{EPOCH, OrderChooser, TRIALS, VisitOrder};

    /// Runs `walks` walks whose times `cost` gives per order; the orders used, in turn.
    fn run(chooser: &mut OrderChooser, walks: u32, cost: impl Fn(VisitOrder) -> u64) -> Vec<VisitOrder> {
        (0..walks)
            .map(|_| {
                let order = chooser.next();
                let trial = chooser.is_trial();
                chooser.record(order, if trial { cost(order) } else { 0 });
                order
            })
            .collect()
    }

    #[test]
    fn the_cheaper_order_is_used_after_the_trials_of_each_epoch() {
        let mut chooser = OrderChooser::default();
        let interior = |order| if order == VisitOrder::FarthestFirst { 30 } else { 50 };
        let orders = run(&mut chooser, EPOCH, interior);
        let tried = &orders[..TRIALS as usize];
        assert_eq!(tried.iter().filter(|&&o| o == VisitOrder::FarthestFirst).count(), TRIALS as usize / 2);
        assert!(orders[TRIALS as usize..].iter().all(|&o| o == VisitOrder::FarthestFirst));
        // The next epoch tries again, and follows a scene that changed.
        let lone_object = |order| if order == VisitOrder::FarthestFirst { 60 } else { 40 };
        let orders = run(&mut chooser, EPOCH, lone_object);
        assert!(orders[TRIALS as usize..].iter().all(|&o| o == VisitOrder::NearestFirst));
    }

    #[test]
    fn ties_and_the_first_trials_keep_nearest_first() {
        let mut chooser = OrderChooser::default();
        assert_eq!(chooser.next(), VisitOrder::NearestFirst);
        let orders = run(&mut chooser, EPOCH, |_| 7);
        assert!(orders[TRIALS as usize..].iter().all(|&o| o == VisitOrder::NearestFirst));
    }
}
