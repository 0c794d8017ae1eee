//! One Box Pushing frame: the grid with the goal row (yellow, at the top as in the paper's figure),
//! faint waypoints, the two small boxes, the 1 x 2 big box and both robots with a heading marker,
//! for the status bar below it (`docs/BOX_PUSHING.md` §1-2 for what is where).

use super::geometry::{Cell, Heading};
use super::BoxPushing;
use crate::draw::{Canvas, Colour, Picture};

/// Status-bar labels of the two robots.
pub const LABELS: [&str; 2] = ["R0", "R1"];

/// Pixels per cell side: 32 up to a 12 x 12 grid, then whatever keeps the grid about 360 pixels
/// wide (12 on the paper's 30 x 30), never below 6.
pub fn cell_px(grid: usize) -> usize {
    if grid <= 12 {
        32
    } else {
        (360 / grid).max(6)
    }
}

/// Pixel geometry of one grid: cell borders are the 1-pixel lines at multiples of `cell`.
#[derive(Debug, Clone, Copy)]
pub struct GridPixels {
    /// Grid side in cells.
    pub n: i32,
    /// Side of one cell in pixels.
    pub cell: i64,
}

impl GridPixels {
    /// The geometry of an `grid` x `grid` grid.
    pub fn new(grid: usize) -> Self {
        Self {
            n: grid as i32,
            cell: cell_px(grid) as i64,
        }
    }

    /// Side of the square grid picture in pixels (n cells plus the closing border line).
    pub fn side(&self) -> usize {
        (i64::from(self.n) * self.cell + 1) as usize
    }

    /// Top-left pixel of `cell` (on its border lines). Row 0 is the bottom row, so it is drawn
    /// last from the top. Cells outside the grid (a robot lifted by the Q2 push) are clamped to
    /// the nearest border cell so they stay visible.
    pub fn origin(&self, cell: Cell) -> (i64, i64) {
        let col = cell.col.clamp(0, self.n - 1);
        let row = cell.row.clamp(0, self.n - 1);
        (
            i64::from(col) * self.cell,
            i64::from(self.n - 1 - row) * self.cell,
        )
    }

    /// Centre of `cell` in continuous pixel coordinates (pixel (x, y) covers [x, x+1)).
    pub fn centre(&self, cell: Cell) -> (f64, f64) {
        let (x, y) = self.origin(cell);
        let half = self.cell as f64 / 2.0 + 0.5;
        (x as f64 + half, y as f64 + half)
    }

    /// Fill the inside of a `w_cells` x 1 block starting at `cell`, `inset` pixels in from its
    /// border lines, with a 1-pixel `rim`.
    fn block(
        &self,
        canvas: &mut Canvas,
        cell: Cell,
        w_cells: i64,
        inset: i64,
        fill: Colour,
        rim: Option<Colour>,
    ) {
        let (x, y) = self.origin(cell);
        let (x, y) = (x + 1 + inset, y + 1 + inset);
        let w = w_cells * self.cell - 1 - 2 * inset;
        let h = self.cell - 1 - 2 * inset;
        canvas.fill_rect(x, y, w, h, fill);
        if let Some(rim) = rim {
            canvas.outline_rect(x, y, w, h, 1, rim);
        }
    }
}

/// Unit vector of a heading in picture coordinates (y grows downwards).
fn screen_dir(h: Heading) -> (f64, f64) {
    let (dc, dr) = h.delta();
    (f64::from(dc), -f64::from(dr))
}

/// The picture of `env`'s current state.
pub fn draw(env: &BoxPushing) -> Picture {
    let g = GridPixels::new(env.grid());
    let side = g.side();
    let mut canvas = Canvas::new(side, side, Colour::Background);
    let n = g.n;
    let layout = env.layout();

    // Goal row, then faint waypoints, then the grid lines over both.
    let (_, goal_y) = g.origin(Cell::new(0, layout.goal_row()));
    canvas.fill_rect(0, goal_y, side as i64, g.cell, Colour::Goal);
    for &w in &layout.waypoints {
        g.block(&mut canvas, w, 1, g.cell / 4, Colour::Waypoint, None);
    }
    for k in 0..=i64::from(n) {
        canvas.fill_rect(k * g.cell, 0, 1, side as i64, Colour::GridLine);
        canvas.fill_rect(0, k * g.cell, side as i64, 1, Colour::GridLine);
    }
    canvas.outline_rect(0, 0, side as i64, side as i64, 1, Colour::Dark);

    let inset = (g.cell / 7).max(1);
    let boxes = env.boxes();
    for &s in &boxes.small {
        g.block(
            &mut canvas,
            s,
            1,
            inset,
            Colour::SmallBox,
            Some(Colour::Dark),
        );
    }
    g.block(
        &mut canvas,
        boxes.big_left,
        2,
        inset,
        Colour::BigBox,
        Some(Colour::Dark),
    );

    // Robots: a disc in the robot's colour with a dark rim and a dark "hand" toward its heading.
    // Two robots on one cell (allowed, `docs/BOX_PUSHING.md` Q4) are drawn smaller, side by side.
    let shared = env.robot(0).cell == env.robot(1).cell;
    for i in 0..2 {
        let robot = env.robot(i);
        let (mut cx, mut cy) = g.centre(robot.cell);
        let mut r = 0.38 * g.cell as f64;
        if shared {
            let off = 0.2 * g.cell as f64 * if i == 0 { -1.0 } else { 1.0 };
            cx += off;
            cy += off;
            r = 0.26 * g.cell as f64;
        }
        let rim = (g.cell as f64 / 16.0).max(1.0);
        canvas.ringed_circle(cx, cy, r, rim, Colour::Dark, Colour::agent(i));
        let (dx, dy) = screen_dir(robot.heading);
        let hand = (g.cell as f64 / 8.0).max(1.5);
        canvas.line(
            cx,
            cy,
            cx + dx * (r - 0.5),
            cy + dy * (r - 0.5),
            hand,
            Colour::Dark,
        );
    }

    Picture {
        world: canvas,
        agent_labels: &LABELS,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(c: &Canvas, p: (f64, f64)) -> Option<Colour> {
        c.pixel(p.0 as usize, p.1 as usize)
    }

    #[test]
    fn ten_by_ten_cells_are_32_pixels_and_thirty_by_thirty_12() {
        assert_eq!(GridPixels::new(10).side(), 321);
        assert_eq!(GridPixels::new(30).side(), 361);
        assert_eq!(cell_px(100), 6);
    }

    #[test]
    fn start_frame_puts_each_object_on_its_cell() {
        let env = BoxPushing::new(10, 100).unwrap();
        let c = draw(&env).world;
        let g = GridPixels::new(10);
        // Robot 0 at (1,1) faces east: its disc shows green left of the centre, robot 1 at (8,1)
        // faces west: blue right of its centre.
        let (x0, y0) = g.centre(Cell::new(1, 1));
        assert_eq!(at(&c, (x0 - 5.0, y0)), Some(Colour::Agent0));
        assert_eq!(
            at(&c, (x0 + 5.0, y0)),
            Some(Colour::Dark),
            "heading hand points east"
        );
        let (x1, y1) = g.centre(Cell::new(8, 1));
        assert_eq!(at(&c, (x1 + 5.0, y1)), Some(Colour::Agent1));
        assert_eq!(
            at(&c, (x1 - 5.0, y1)),
            Some(Colour::Dark),
            "heading hand points west"
        );
        assert_eq!(at(&c, g.centre(Cell::new(1, 5))), Some(Colour::SmallBox));
        assert_eq!(at(&c, g.centre(Cell::new(8, 5))), Some(Colour::SmallBox));
        assert_eq!(at(&c, g.centre(Cell::new(4, 5))), Some(Colour::BigBox));
        assert_eq!(at(&c, g.centre(Cell::new(5, 5))), Some(Colour::BigBox));
        // The big box is one block: the border line between its two cells is covered.
        let (bx, by) = g.origin(Cell::new(5, 5));
        assert_eq!(c.pixel(bx as usize, by as usize + 16), Some(Colour::BigBox));
        assert_eq!(at(&c, g.centre(Cell::new(4, 4))), Some(Colour::Waypoint));
        assert_eq!(at(&c, g.centre(Cell::new(3, 4))), Some(Colour::Background));
        assert_eq!(at(&c, g.centre(Cell::new(7, 9))), Some(Colour::Goal));
        assert_eq!(at(&c, g.centre(Cell::new(7, 8))), Some(Colour::Background));
    }

    #[test]
    fn robots_on_one_cell_are_both_visible() {
        let mut env = BoxPushing::new(10, 100).unwrap();
        env.place_robot(1, Cell::new(1, 1), Heading::North);
        let c = draw(&env).world;
        let (x, y) = GridPixels::new(10).centre(Cell::new(1, 1));
        assert_eq!(at(&c, (x - 10.0, y - 10.0)), Some(Colour::Agent0));
        assert_eq!(at(&c, (x + 10.0, y + 10.0)), Some(Colour::Agent1));
    }
}
