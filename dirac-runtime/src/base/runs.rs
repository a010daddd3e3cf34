//! Work on items that each own a contiguous run of one vector (a Jacobian's blocks and their
//! rows, an interconnection's components and their unknowns) across rayon's threads: the items
//! are halved, and the vector with them at the middle item's run, while more than a grain of
//! them remain. Nothing is allocated, and each item's work is the same whatever the split.

/// Items that can be halved, each owning the run of a vector from its start to the next item's.
pub(crate) trait Runs: Send + Sized {
    /// The number of items.
    fn count(&self) -> usize;
    /// Where item `i`'s run starts in the whole vector.
    fn start(&self, i: usize) -> usize;
    /// The items before `mid`, and those from it on.
    fn halve(self, mid: usize) -> (Self, Self);
}

/// `leaf(piece, run)` on pieces of `items` of at most `grain` items each (`usize::MAX`: all of
/// them at once, on this thread), each with its run of `data` (which begins at the first item's
/// start and ends at the last item's end), the pieces' results combined by `combine`.
pub(crate) fn in_runs<R, T, F, C>(
    items: R,
    data: &mut [f64],
    grain: usize,
    leaf: &F,
    combine: &C,
) -> T
where
    R: Runs,
    T: Send,
    F: Fn(R, &mut [f64]) -> T + Sync,
    C: Fn(T, T) -> T + Sync,
{
    let count = items.count();
    if count <= grain.max(1) {
        return leaf(items, data);
    }
    let mid = count / 2;
    let (left_run, right_run) = data.split_at_mut(items.start(mid) - items.start(0));
    let (left, right) = items.halve(mid);
    let (a, b) = rayon::join(
        || in_runs(left, left_run, grain, leaf, combine),
        || in_runs(right, right_run, grain, leaf, combine),
    );
    combine(a, b)
}
