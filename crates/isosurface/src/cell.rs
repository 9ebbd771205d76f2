//! The state of one grid cell on a sparse grid: its configuration when every corner's side is
//! known or can be inferred, and whether its surface can be built.
//!
//! A missing corner's side comes from the side hint when there is one. Otherwise it is inferred
//! (the paper does not say how): an edge with a missing endpoint cannot carry a vertex, so under
//! the paper's sparsification protocol it is not a crossing edge and the missing corner lies on the
//! same side as its neighbours. The side of a connected group of missing corners is therefore
//! that of the known corners next to the group, which must all agree; if they do not, the cell
//! is *unresolved*. For random dropouts without hints this is an assumption (a surface passing
//! between a missing sample and its neighbours is lost), and such cells are counted.

use crate::grid::flag;
use crate::tables::case_table;

/// What a cell contributes to the mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum CellState {
    /// No surface passes through (all sides equal, or nothing known).
    Empty,
    /// Some surface passes through but the cell cannot be triangulated: conflicting inferred
    /// sides, or a crossing edge with a missing endpoint.
    Unresolved,
    /// The cell's configuration (bit `c` set when corner `c` is inside).
    Active(u8),
}

/// Corners adjacent to corner `c` (differ in one coordinate).
#[inline]
const fn neighbours(c: usize) -> [usize; 3] {
    [c ^ 1, c ^ 2, c ^ 4]
}

/// Resolves a cell from the [`flag`] bits of its eight corners (corner order of
/// [`crate::tables`]).
#[inline]
pub(crate) fn resolve_cell(flags: &[u8; 8]) -> CellState {
    let (mut known, mut inside, mut defined) = (0u8, 0u8, 0u8);
    for (c, &f) in flags.iter().enumerate() {
        defined |= ((f & flag::DEFINED != 0) as u8) << c;
        known |= ((f & flag::KNOWN != 0) as u8) << c;
        inside |= ((f & flag::INSIDE != 0) as u8) << c;
    }
    if known == 0 {
        return CellState::Empty;
    }
    let config = if known == 0xff {
        inside
    } else {
        match infer_sides(known, inside) {
            Some(c) => c,
            None => return CellState::Unresolved,
        }
    };
    if config == 0 || config == 0xff {
        return CellState::Empty;
    }
    // Every crossing edge needs both of its samples.
    if case_table()[config as usize].endpoints & !defined != 0 {
        return CellState::Unresolved;
    }
    CellState::Active(config)
}

/// Gives every unknown corner the side of the known corners bordering its group of unknown
/// corners; `None` when those disagree.
fn infer_sides(known: u8, inside: u8) -> Option<u8> {
    let mut config = inside;
    let mut done = known;
    for start in 0..8 {
        if done >> start & 1 == 1 {
            continue;
        }
        // Flood the group of unknown corners containing `start`.
        let mut group = 1u8 << start;
        let mut stack = [0usize; 8];
        let mut top = 1;
        stack[0] = start;
        let mut side: Option<bool> = None;
        while top > 0 {
            top -= 1;
            let c = stack[top];
            for n in neighbours(c) {
                if known >> n & 1 == 1 {
                    let s = inside >> n & 1 == 1;
                    match side {
                        None => side = Some(s),
                        Some(t) if t != s => return None,
                        _ => {}
                    }
                } else if group >> n & 1 == 0 {
                    group |= 1 << n;
                    stack[top] = n;
                    top += 1;
                }
            }
        }
        // A group always borders a known corner when at least one corner is known.
        if side? {
            config |= group;
        }
        done |= group;
    }
    Some(config)
}

#[cfg(test)]
mod tests {
    use super::*;

    const IN: u8 = flag::DEFINED | flag::KNOWN | flag::INSIDE;
    const OUT: u8 = flag::DEFINED | flag::KNOWN;
    const MISSING: u8 = 0;

    #[test]
    fn full_cells() {
        let mut f = [OUT; 8];
        assert_eq!(resolve_cell(&f), CellState::Empty);
        f[0] = IN;
        assert_eq!(resolve_cell(&f), CellState::Active(1));
    }

    #[test]
    fn missing_corner_takes_its_neighbours_side() {
        // Corner 0 inside; corner 7 (far from 0) missing, its neighbours outside.
        let mut f = [OUT; 8];
        f[0] = IN;
        f[7] = MISSING;
        assert_eq!(resolve_cell(&f), CellState::Active(1));
        // A missing corner between an inside and an outside neighbour cannot be resolved.
        let mut g = [OUT; 8];
        g[0] = IN;
        g[1] = MISSING;
        assert_eq!(resolve_cell(&g), CellState::Unresolved);
        // All missing: nothing to build.
        assert_eq!(resolve_cell(&[MISSING; 8]), CellState::Empty);
    }

    #[test]
    fn hinted_side_must_not_need_a_missing_vertex() {
        // Corner 1 missing but hinted inside next to an inside corner 0: edge 0-1 does not
        // cross, the others at corner 1 do and need its value.
        let mut f = [OUT; 8];
        f[0] = IN;
        f[1] = flag::KNOWN | flag::INSIDE;
        assert_eq!(resolve_cell(&f), CellState::Unresolved);
        // Hinted outside next to outside corners: fine.
        let mut g = [OUT; 8];
        g[0] = IN;
        g[7] = flag::KNOWN;
        assert_eq!(resolve_cell(&g), CellState::Active(1));
    }
}
