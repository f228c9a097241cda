//! The previous frame of a coherent re-synthesis and the bounds of what
//! changed since it: restricted re-synthesis corrects only the window those
//! bounds, widened by how far subpasses carry a change, can reach.

use crate::level::fixed::Coord;
use crate::level::state::State;

/// Subpass reads reach two pixels (DESIGN §5), so within one level a change
/// spreads at most this far per subpass.
pub(super) const REACH_PER_SUBPASS: usize = 2;

/// Every corrected level's state after every pass (index = level, then
/// pass): the previous frame a coherent re-synthesis reads. A pass writes
/// each pixel once, in its parity class's subpass, so the state after the
/// pass holds every subpass's result (paper §5.3: "the results for all
/// sub-passes are needed").
///
/// Equality and clones compare and copy the recorded results; the kept
/// `states` are a cache of them and are neither compared nor
/// cloned.
#[derive(Default)]
pub struct Frames {
    /// Per level, per pass (read with [`Frames::levels`]: crate code that
    /// changes them also clears [`Frames::states`] or writes the same into
    /// them, which outside code could not).
    pub(crate) levels: Vec<Vec<PassResult>>,
    /// Level 0's fixed-point heights (stage `reconstruct`'s output), which
    /// an edit's re-synthesis recomputes only where S and V can change;
    /// empty where not recorded.
    pub heights: Vec<i32>,
    /// Each level's final state, where the backend keeps states on the
    /// host (index = level; `None` where not kept): the same S and V as
    /// the level's last [`PassResult`]. A restricted re-synthesis writes
    /// its window into it instead of building the level's state afresh
    /// from that result (at 1024² a 12 MB copy into new pages per edit,
    /// ~14 % of an edit's CPU time). Code that changes [`Frames::levels`]
    /// clears it or writes the same into it.
    pub(crate) states: Vec<Option<State>>,
}

impl Clone for Frames {
    fn clone(&self) -> Frames {
        Frames {
            levels: self.levels.clone(),
            heights: self.heights.clone(),
            states: Vec::new(),
        }
    }

    /// Into `self`'s buffers where they are large enough (an editor's
    /// recycled [`crate::synth::session::Snapshot`]): a copy without
    /// allocating or faulting in new pages.
    fn clone_from(&mut self, source: &Frames) {
        self.levels.clone_from(&source.levels);
        self.heights.clone_from(&source.heights);
        self.states.clear();
    }
}

impl PartialEq for Frames {
    fn eq(&self, other: &Frames) -> bool {
        self.levels == other.levels && self.heights == other.heights
    }
}

impl std::fmt::Debug for Frames {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Frames")
            .field("levels", &self.levels)
            .field("heights", &self.heights)
            .field(
                "states",
                &self.states.iter().map(Option::is_some).collect::<Vec<_>>(),
            )
            .finish()
    }
}

impl Frames {
    /// Every corrected level's results after each pass (index = level,
    /// then pass).
    pub fn levels(&self) -> &[Vec<PassResult>] {
        &self.levels
    }

    /// Keeps `st` as level `level`'s final state (a level the frame
    /// records).
    pub(super) fn keep_state(&mut self, level: usize, st: Option<State>) {
        if level < self.levels.len() {
            self.states.resize_with(self.levels.len(), || None);
            self.states[level] = st;
        }
    }
}

/// One level's S and V after one pass.
#[derive(Debug, Default, PartialEq)]
pub struct PassResult {
    pub coords: Vec<Coord>,
    pub offsets: Vec<i32>,
}

impl Clone for PassResult {
    fn clone(&self) -> PassResult {
        PassResult {
            coords: self.coords.clone(),
            offsets: self.offsets.clone(),
        }
    }

    /// Into `self`'s buffers (see [`Frames`]' `clone_from`).
    fn clone_from(&mut self, source: &PassResult) {
        self.coords.clone_from(&source.coords);
        self.offsets.clone_from(&source.offsets);
    }
}

/// The union of two optional bounds.
pub(crate) fn union(a: Option<[usize; 4]>, b: Option<[usize; 4]>) -> Option<[usize; 4]> {
    match (a, b) {
        (Some(a), Some(b)) => Some([
            a[0].min(b[0]),
            a[1].min(b[1]),
            a[2].max(b[2]),
            a[3].max(b[3]),
        ]),
        (a, None) => a,
        (None, b) => b,
    }
}

/// Bounds of the set entries of one row: `row` holds, for columns
/// `x0, x0 + 1, …` of row `y`, whether the pixel is in the set. The one
/// rule behind every "where did this change" of the engine and sessions.
pub(crate) fn row_bounds(
    y: usize,
    x0: usize,
    row: impl IntoIterator<Item = bool>,
) -> Option<[usize; 4]> {
    let mut span: Option<(usize, usize)> = None;
    for (i, set) in row.into_iter().enumerate() {
        if set {
            span = Some(span.map_or((i, i), |(a, _)| (a, i)));
        }
    }
    span.map(|(a, b)| [x0 + a, y, x0 + b + 1, y + 1])
}

/// The children of a parent level's bounds.
pub(super) fn double(b: [usize; 4]) -> [usize; 4] {
    b.map(|v| 2 * v)
}

/// Bounds grown by `by` on every side, clipped to `w × h`.
pub(super) fn widen(b: [usize; 4], by: usize, w: usize, h: usize) -> [usize; 4] {
    [
        b[0].saturating_sub(by),
        b[1].saturating_sub(by),
        (b[2] + by).min(w),
        (b[3] + by).min(h),
    ]
}

/// Bounds of the pixels in `[x0, y0, x1, y1)` whose S or V (row-major,
/// `width` wide) differ from `r`; None if none do. Outside the window a
/// restricted re-synthesis keeps `r` as it is, so only the window is read.
pub(super) fn changed_bounds(
    coords: &[Coord],
    offsets: &[i32],
    width: usize,
    r: &PassResult,
    [x0, y0, x1, y1]: [usize; 4],
) -> Option<[usize; 4]> {
    (y0..y1)
        .map(|y| {
            let k = y * width + x0..y * width + x1;
            let differs = |i: usize| coords[i] != r.coords[i] || offsets[i] != r.offsets[i];
            row_bounds(y, x0, k.map(differs))
        })
        .fold(None, union)
}

#[cfg(test)]
mod row_bounds_tests {
    use super::row_bounds;

    #[test]
    fn row_bounds_span_the_first_and_last_set_entries() {
        let row = |bits: &str| bits.chars().map(|c| c == '1').collect::<Vec<_>>();
        assert_eq!(row_bounds(3, 10, row("0000")), None);
        assert_eq!(row_bounds(3, 10, row("0100")), Some([11, 3, 12, 4]));
        assert_eq!(row_bounds(0, 0, row("1001")), Some([0, 0, 4, 1]));
        assert_eq!(row_bounds(7, 2, row("0110100")), Some([3, 7, 7, 8]));
    }
}
