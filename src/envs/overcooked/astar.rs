//! The macro-actions' navigation (`Overcooked_MA_V1._navigate`): A* on an agent's belief map,
//! returning the first primitive move of the path it finds.
//!
//! Exact parity needs the reference's tie-breaking, which comes from Python's `PriorityQueue`
//! (the `heapq` sift algorithm) ordering nodes by `AStarAgent.__lt__`: smaller f first, then
//! fewer agents passed, and the non-strict `<=` there makes equal nodes each "less" than the
//! other. [`PyHeap`] is `heapq`'s `heappush`/`heappop` with that comparison, step for step, so
//! equal-cost paths are broken exactly as the reference breaks them.

use serde::{Deserialize, Serialize};

use super::layout::{Cells, Tile, MAX_SIDE};
use super::world::{tile_of, Cell, STAY};

/// A search node (`AStarAgent`; the unused action history is left out).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Node {
    /// The node's cell.
    pub at: Cell,
    /// Steps from the start.
    pub g: i32,
    /// g + Manhattan distance to the target (the reference's `dis`).
    pub f: i32,
    /// The first move of the path to this node; `None` at the start.
    pub first: Option<u8>,
    /// Whether this node's cell shows an agent (`pass_agent`).
    pub pass_agent: bool,
}

/// `AStarAgent.__lt__`: `dis <= other.dis` when they differ, else `pass_agent <= other's`.
fn lt(a: &Node, b: &Node) -> bool {
    if a.f != b.f {
        a.f <= b.f
    } else {
        a.pass_agent <= b.pass_agent
    }
}

/// A binary heap with CPython's `heapq` algorithm and `lt` as `<`. The buffer is reused and
/// sized for the whole grid before the first search, so searching never allocates again.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct PyHeap {
    items: Vec<Node>,
}

impl PyHeap {
    /// An empty heap with room for every cell of a `side` x `side` grid, the most a search
    /// ever holds, so no search on that grid allocates.
    pub fn for_grid(side: usize) -> PyHeap {
        PyHeap {
            items: Vec::with_capacity(side * side),
        }
    }

    /// Remove every node, keeping the allocation.
    pub fn clear(&mut self) {
        self.items.clear();
    }

    /// Whether no node is left.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// `heapq.heappush`: append, then `_siftdown(heap, 0, len - 1)`.
    pub fn push(&mut self, n: Node) {
        self.items.push(n);
        let last = self.items.len() - 1;
        self.sift_down(0, last);
    }

    /// `heapq.heappop`: the last item replaces the root, then `_siftup(heap, 0)`.
    pub fn pop(&mut self) -> Option<Node> {
        let last = self.items.pop()?;
        if self.items.is_empty() {
            return Some(last);
        }
        let top = std::mem::replace(&mut self.items[0], last);
        self.sift_up(0);
        Some(top)
    }

    /// `heapq._siftdown`: move the item at `pos` up towards `start` while it is `<` its parent.
    fn sift_down(&mut self, start: usize, mut pos: usize) {
        let new = self.items[pos];
        while pos > start {
            let parent = (pos - 1) >> 1;
            if lt(&new, &self.items[parent]) {
                self.items[pos] = self.items[parent];
                pos = parent;
                continue;
            }
            break;
        }
        self.items[pos] = new;
    }

    /// `heapq._siftup`: move the smaller child up until a leaf, then sift the item down.
    fn sift_up(&mut self, mut pos: usize) {
        let end = self.items.len();
        let start = pos;
        let new = self.items[pos];
        let mut child = 2 * pos + 1;
        while child < end {
            let right = child + 1;
            if right < end && !lt(&self.items[child], &self.items[right]) {
                child = right;
            }
            self.items[pos] = self.items[child];
            pos = child;
            child = 2 * pos + 1;
        }
        self.items[pos] = new;
        self.sift_down(start, pos);
    }
}

/// The search's neighbour order (`direction`) and the primitive action of each (`actionIdx`):
/// right, left, down, up, so it "explores up and down first" as the reference's comment says.
const SEARCH: [((i32, i32), u8); 4] = [((0, 1), 0), ((0, -1), 2), ((1, 0), 1), ((-1, 0), 3)];

/// The first primitive move from `from` towards `target` on belief map `pomap` (`_navigate`),
/// or stay when the search finds no way. Paths go through cells the map shows as floor or as
/// an agent (preferring floor at equal cost); the target may be any cell, and the search ends
/// as soon as it is generated.
pub fn navigate(pomap: &Cells, side: usize, from: Cell, target: Cell, heap: &mut PyHeap) -> u8 {
    let mut visited = [[false; MAX_SIDE]; MAX_SIDE];
    let seen = |v: &[[bool; MAX_SIDE]; MAX_SIDE], c: Cell| {
        c.x < 0
            || c.y < 0
            || c.x as usize >= side
            || c.y as usize >= side
            || v[c.x as usize][c.y as usize]
    };
    heap.clear();
    // Every cell is pushed at most once (it is marked visited when pushed), so the frontier
    // never outgrows the grid. A heap made by `for_grid` already has the room; a default one
    // (a deserialized environment's) gets it at its first search.
    heap.items.reserve(side * side);
    heap.push(Node {
        at: from,
        g: 0,
        f: from.distance(target),
        first: None,
        pass_agent: false,
    });
    if !seen(&visited, from) {
        visited[from.x as usize][from.y as usize] = true;
    }
    while let Some(node) = heap.pop() {
        for &(d, action) in &SEARCH {
            let next = node.at.plus(d);
            if seen(&visited, next) {
                continue;
            }
            let first = node.first.unwrap_or(action);
            let tile = tile_of(pomap, side, next);
            if tile == Tile::Space || tile == Tile::Agent {
                let g = node.g + 1;
                heap.push(Node {
                    at: next,
                    g,
                    f: g + next.distance(target),
                    first: Some(first),
                    pass_agent: tile == Tile::Agent,
                });
                visited[next.x as usize][next.y as usize] = true;
            }
            if next == target {
                return first;
            }
        }
    }
    STAY
}

#[cfg(test)]
mod tests {
    use super::*;

    fn node(f: i32, pass_agent: bool, id: i32) -> Node {
        Node {
            at: Cell::new(id, 0),
            g: 0,
            f,
            first: None,
            pass_agent,
        }
    }

    /// Pops of CPython's heapq with `__lt__` = `AStarAgent.__lt__`, recorded by running
    /// `heappush` of (f, pass_agent, id) = (3,0,0), (3,0,1), (2,1,2), (3,0,3), (2,0,4), (3,1,5),
    /// (2,1,6) then popping everything: ids 4, 2, 6, 3, 0, 1, 5 (a strict order would give
    /// 4, 2, 6, 0, 1, 3, 5).
    #[test]
    fn equal_nodes_pop_in_heapq_order() {
        let mut h = PyHeap::default();
        for (f, p, id) in [
            (3, false, 0),
            (3, false, 1),
            (2, true, 2),
            (3, false, 3),
            (2, false, 4),
            (3, true, 5),
            (2, true, 6),
        ] {
            h.push(node(f, p, id));
        }
        let mut order = vec![];
        while let Some(n) = h.pop() {
            order.push(n.at.x);
        }
        assert_eq!(order, PY_ORDER);
    }

    const PY_ORDER: [i32; 7] = [4, 2, 6, 3, 0, 1, 5];
}
