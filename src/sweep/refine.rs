//! Adaptive refinement of a two-axis grid: run a coarse grid, then only the cells whose runs
//! disagree, down to every point, and fill the rest from the cells' agreeing corners.
//!
//! Sans-IO: [`refine`] decides which points to run and hands each batch to a caller's function,
//! which runs them (a gain map's runs, a sweep's rows) and returns their classes.
//!
//! Why it keeps the full grid's answers: a map of outcomes (held, dropped, oscillating) is made of
//! regions many points wide with boundaries between them. A cell whose run points all agree lies
//! inside one region unless a region smaller than the cell sits wholly inside it, touching none of
//! its run points; the coarse stride bounds that size ([`DEFAULT_STRIDE`]). A cell stays accepted
//! only while every run point on it agrees: when a neighbour's refinement runs a point on its edge
//! that disagrees, the cell is refined too. The maps this was checked against are in the book
//! (docs/studies/stability.md, "The gain map").

use std::collections::BTreeMap;

/// A point of the grid by its indices along the two axes.
pub type Point = (usize, usize);

/// The coarse grid's stride \[points\] when the user gives none: every fourth point of each axis
/// (and its last). A choice: on the 18 × 18 gain map the smallest region (the oscillating corner
/// at Ki ≥ 5 with a weak Kp) is 5 points or more along each axis, wider than 4; a stride of 8
/// could pass over a region of 7.
pub const DEFAULT_STRIDE: usize = 4;

/// What the refinement knows of one point.
#[derive(Debug, Clone, PartialEq)]
pub struct Known<C> {
    /// The point's class.
    pub class: C,
    /// Whether the point was run (`false`: filled in from its cell's agreeing runs).
    pub ran: bool,
}

/// A refined map: every point's class, run or filled in.
#[derive(Debug, Clone)]
pub struct Map<C> {
    /// Points along the first axis.
    pub nx: usize,
    /// Points along the second axis.
    pub ny: usize,
    points: BTreeMap<Point, Known<C>>,
}

impl<C> Map<C> {
    /// The point `p`'s class and whether it ran.
    pub fn get(&self, p: Point) -> &Known<C> {
        &self.points[&p]
    }

    /// How many points were run.
    pub fn runs(&self) -> usize {
        self.points.values().filter(|k| k.ran).count()
    }
}

/// A cell of the grid: the index ranges `x0..=x1` and `y0..=y1`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Cell {
    x0: usize,
    x1: usize,
    y0: usize,
    y1: usize,
}

impl Cell {
    fn points(self) -> impl Iterator<Item = Point> {
        (self.x0..=self.x1).flat_map(move |x| (self.y0..=self.y1).map(move |y| (x, y)))
    }

    /// Whether every point of the cell is one of its corners (nothing left to refine).
    fn atomic(self) -> bool {
        self.x1 - self.x0 <= 1 && self.y1 - self.y0 <= 1
    }

    /// The cell's halves along each axis wider than one step (two or four cells).
    fn split(self) -> Vec<Cell> {
        let halves =
            |a: usize, b: usize| if b - a > 1 { vec![(a, (a + b) / 2), ((a + b) / 2, b)] } else { vec![(a, b)] };
        let mut cells = Vec::new();
        for &(x0, x1) in &halves(self.x0, self.x1) {
            for &(y0, y1) in &halves(self.y0, self.y1) {
                cells.push(Cell { x0, x1, y0, y1 });
            }
        }
        cells
    }

    fn corners(self) -> [Point; 4] {
        [(self.x0, self.y0), (self.x0, self.y1), (self.x1, self.y0), (self.x1, self.y1)]
    }
}

/// The coarse grid's indices along an axis of `n` points: every `stride`-th, and the last.
fn coarse_axis(n: usize, stride: usize) -> Vec<usize> {
    let mut v: Vec<usize> = (0..n).step_by(stride).collect();
    if v.last() != Some(&(n - 1)) {
        v.push(n - 1);
    }
    v
}

/// Refines an `nx` × `ny` grid from a coarse grid of stride `stride` (1: every point, the full
/// grid). `run` is given each batch of points to run, in order, and returns their classes in the
/// same order; a batch holds every point one level of refinement needs, so a caller can run it in
/// parallel. Errors from `run` end the refinement.
pub fn refine<C, E>(
    nx: usize,
    ny: usize,
    stride: usize,
    mut run: impl FnMut(&[Point]) -> Result<Vec<C>, E>,
) -> Result<Map<C>, E>
where
    C: Clone + PartialEq,
{
    let stride = stride.max(1);
    let mut ran: BTreeMap<Point, C> = BTreeMap::new();
    let mut run_batch = |points: Vec<Point>, ran: &mut BTreeMap<Point, C>| -> Result<(), E> {
        let points: Vec<Point> = points.into_iter().filter(|p| !ran.contains_key(p)).collect();
        if points.is_empty() {
            return Ok(());
        }
        let classes = run(&points)?;
        assert_eq!(classes.len(), points.len(), "a batch's runner returns one class per point");
        ran.extend(points.into_iter().zip(classes));
        Ok(())
    };
    if nx == 0 || ny == 0 {
        return Ok(Map { nx, ny, points: BTreeMap::new() });
    }
    let (xs, ys) = (coarse_axis(nx, stride), coarse_axis(ny, stride));
    run_batch(xs.iter().flat_map(|&x| ys.iter().map(move |&y| (x, y))).collect(), &mut ran)?;
    let mut pending: Vec<Cell> = Vec::new();
    for wx in xs.windows(2).map(|w| (w[0], w[1])).chain((xs.len() == 1).then_some((0, 0))) {
        for wy in ys.windows(2).map(|w| (w[0], w[1])).chain((ys.len() == 1).then_some((0, 0))) {
            pending.push(Cell { x0: wx.0, x1: wx.1, y0: wy.0, y1: wy.1 });
        }
    }
    // Cells whose run points all agree, with their class.
    let mut accepted: Vec<(Cell, C)> = Vec::new();
    loop {
        let mut batch = Vec::new();
        let mut next = Vec::new();
        for cell in pending.drain(..) {
            match agreeing(cell, &ran) {
                Some(class) => accepted.push((cell, class)),
                None if cell.atomic() => {}
                None => {
                    for sub in cell.split() {
                        batch.extend(sub.corners());
                        next.push(sub);
                    }
                }
            }
        }
        batch.sort_unstable();
        batch.dedup();
        run_batch(batch, &mut ran)?;
        // A point run for a neighbour may lie on an accepted cell's edge and disagree with it.
        let (keep, reopened): (Vec<_>, Vec<_>) = accepted
            .into_iter()
            .partition(|(cell, class)| cell.points().all(|p| ran.get(&p).is_none_or(|c| c == class)));
        accepted = keep;
        next.extend(reopened.into_iter().map(|(cell, _)| cell));
        if next.is_empty() {
            break;
        }
        pending = next;
    }
    let mut points: BTreeMap<Point, Known<C>> =
        ran.into_iter().map(|(p, class)| (p, Known { class, ran: true })).collect();
    for (cell, class) in accepted {
        for p in cell.points() {
            points.entry(p).or_insert_with(|| Known { class: class.clone(), ran: false });
        }
    }
    debug_assert_eq!(points.len(), nx * ny, "every point is run or lies in an accepted cell");
    Ok(Map { nx, ny, points })
}

/// The class every run point of `cell` has, when they all agree.
fn agreeing<C: Clone + PartialEq>(cell: Cell, ran: &BTreeMap<Point, C>) -> Option<C> {
    let mut classes = cell.points().filter_map(|p| ran.get(&p));
    let first = classes.next()?;
    classes.all(|c| c == first).then(|| first.clone())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Refines a grid whose classes `truth` gives, counting the runs.
    fn map_of(nx: usize, ny: usize, stride: usize, truth: impl Fn(Point) -> u8) -> Map<u8> {
        refine(nx, ny, stride, |points| Ok::<_, ()>(points.iter().map(|&p| truth(p)).collect())).unwrap()
    }

    /// The gain map's shape: a corner region (strong integral, weak proportional) and a region
    /// beyond a diagonal boundary (both gains strong).
    fn corner_and_band(p: Point) -> u8 {
        let (x, y) = p;
        if x <= 6 && y >= 13 {
            1
        } else if x + y >= 27 {
            2
        } else {
            0
        }
    }

    #[test]
    fn every_point_equals_the_full_grids_with_fewer_runs() {
        for stride in [1, 2, 3, 4] {
            let map = map_of(18, 18, stride, corner_and_band);
            for x in 0..18 {
                for y in 0..18 {
                    assert_eq!(map.get((x, y)).class, corner_and_band((x, y)), "stride {stride}, point {x},{y}");
                }
            }
            if stride == 1 {
                assert_eq!(map.runs(), 324);
            } else {
                assert!(map.runs() < 324, "stride {stride}: {} runs", map.runs());
            }
        }
    }

    #[test]
    fn a_uniform_map_runs_only_the_coarse_grid() {
        let map = map_of(18, 18, 4, |_| 0);
        assert_eq!(map.runs(), 36, "0,4,8,12,16,17 on each axis");
        assert!(!map.get((1, 1)).ran);
    }

    #[test]
    fn a_region_smaller_than_the_stride_inside_one_cell_is_missed() {
        // The limit the stride sets, stated in DEFAULT_STRIDE: one point alone inside a coarse cell.
        let map = map_of(9, 9, 4, |p| u8::from(p == (2, 2)));
        assert_eq!(map.get((2, 2)).class, 0);
        assert!(!map.get((2, 2)).ran);
    }

    #[test]
    fn a_disagreeing_edge_point_reopens_an_accepted_cell() {
        // (4, 2) lies on the edge between the cells x 0..4 and 4..8 of the 9 × 5 grid; it is run
        // when the cell x 4..8 refines (its corner (8, 4) differs), and the other cell, whose
        // corners all agree, is reopened and refined down to (2, 2)'s class.
        let truth = |p: Point| u8::from(p == (8, 4) || p == (4, 2) || p == (3, 2));
        let map = map_of(9, 5, 4, truth);
        assert_eq!(map.get((4, 2)).class, 1);
        assert_eq!(map.get((3, 2)).class, 1);
        assert!(map.get((3, 2)).ran);
    }

    #[test]
    fn single_points_and_lines_and_errors() {
        assert_eq!(map_of(1, 1, 4, |_| 7).get((0, 0)).class, 7);
        let line = map_of(1, 10, 4, |p| u8::from(p.1 >= 6));
        assert!((0..10).all(|y| line.get((0, y)).class == u8::from(y >= 6)));
        let failed: Result<Map<u8>, &str> = refine(3, 3, 2, |_| Err("no runner"));
        assert_eq!(failed.unwrap_err(), "no runner");
    }
}
