//! Where a figure's legend goes: the place, among nine, that covers no drawn data (curves,
//! their bands, the optimal line); when every place covers some, the figure gets headroom above
//! its data for the legend. Pure geometry in the plotting area's pixels, so it is tested without
//! drawing.

/// Pixels kept between the legend and the plotting area's edge (as plotters' own placements).
pub const INSET_PX: i32 = 5;
/// Pixels around every curve, band and line that the legend must also keep clear of.
const CLEARANCE_PX: i32 = 3;

/// Which pixels of the plotting area something is drawn on.
#[derive(Debug, Clone)]
pub struct Occupancy {
    width: i32,
    height: i32,
    cells: Vec<bool>,
}

impl Occupancy {
    /// An empty plotting area of `width` x `height` pixels.
    pub fn new(width: i32, height: i32) -> Occupancy {
        let (width, height) = (width.max(1), height.max(1));
        Occupancy {
            width,
            height,
            cells: vec![false; width as usize * height as usize],
        }
    }

    /// Mark column `x` from row `y0` to row `y1` (either order, clipped), with clearance.
    pub fn mark_span(&mut self, x: i32, y0: i32, y1: i32) {
        let (lo, hi) = (y0.min(y1) - CLEARANCE_PX, y0.max(y1) + CLEARANCE_PX);
        for x in (x - CLEARANCE_PX).max(0)..=(x + CLEARANCE_PX).min(self.width - 1) {
            for y in lo.max(0)..=hi.min(self.height - 1) {
                self.cells[(y * self.width + x) as usize] = true;
            }
        }
    }

    /// Mark a polyline with a band: each point is `(x, line_y, band_top_y, band_bottom_y)` in
    /// pixels, in x order; every column between two points is marked by linear interpolation.
    pub fn mark_band(&mut self, points: &[(i32, i32, i32, i32)]) {
        if let [(x, y, top, bottom)] = points {
            self.mark_span(*x, (*y).min(*top), (*y).max(*bottom));
        }
        for w in points.windows(2) {
            let ((xa, ya, ta, ba), (xb, yb, tb, bb)) = (w[0], w[1]);
            let steps = (xb - xa).abs().max(1);
            for k in 0..=steps {
                let at = |a: i32, b: i32| a + ((b - a) as i64 * k as i64 / steps as i64) as i32;
                let (x, y, t, b) = (at(xa, xb), at(ya, yb), at(ta, tb), at(ba, bb));
                self.mark_span(x, y.min(t), y.max(b));
            }
        }
    }

    /// Mark row `y` across the whole width (the optimal line).
    pub fn mark_row(&mut self, y: i32) {
        for x in 0..self.width {
            self.mark_span(x, y, y);
        }
    }

    /// How many marked pixels the rectangle at `(x, y)` of `size` covers.
    pub fn covered(&self, (x, y): (i32, i32), (w, h): (i32, i32)) -> usize {
        let (x0, x1) = (x.max(0), (x + w).min(self.width));
        let (y0, y1) = (y.max(0), (y + h).min(self.height));
        (y0..y1)
            .map(|row| {
                let start = (row * self.width) as usize;
                self.cells[start + x0 as usize..start + x1.max(x0) as usize]
                    .iter()
                    .filter(|&&c| c)
                    .count()
            })
            .sum()
    }

    /// The legend's top-left corner among the nine places (corners, edge middles, centre) that
    /// covers least, preferring earlier places on a tie, and how much it covers.
    pub fn best_place(&self, size: (i32, i32)) -> ((i32, i32), usize) {
        let (w, h) = size;
        let left = INSET_PX;
        let centre_x = (self.width - w) / 2;
        let right = self.width - w - INSET_PX;
        let top = INSET_PX;
        let middle_y = (self.height - h) / 2;
        let bottom = self.height - h - INSET_PX;
        // Learning curves rise to the right: the lower right and the upper left are the usual
        // free corners.
        let places = [
            (right, bottom),
            (left, top),
            (right, middle_y),
            (right, top),
            (left, bottom),
            (centre_x, bottom),
            (centre_x, top),
            (left, middle_y),
            (centre_x, middle_y),
        ];
        places
            .iter()
            .map(|&p| (p, self.covered(p, size)))
            .min_by_key(|&(_, covered)| covered)
            .expect("nine places")
    }
}

/// The data-unit headroom to add above `y_range` so that a legend `legend_h` pixels tall (plus
/// insets) fits above everything drawn in a plotting area `area_h` pixels tall: the new top is
/// chosen so the old top maps to `legend_h + 2 * INSET_PX` pixels below it.
pub fn headroom(y_range: std::ops::Range<f64>, area_h: i32, legend_h: i32) -> f64 {
    let free = (legend_h + 2 * INSET_PX) as f64;
    let data = (area_h as f64 - free).max(area_h as f64 / 4.0);
    (y_range.end - y_range.start) * free / data
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A curve rising from the bottom left to a plateau across the top right of a 400 x 200
    /// area.
    fn rising() -> Occupancy {
        let mut o = Occupancy::new(400, 200);
        o.mark_band(&[(0, 190, 185, 195), (100, 40, 30, 50), (399, 40, 30, 50)]);
        o
    }

    #[test]
    fn a_rising_curve_leaves_the_lower_right_free() {
        let o = rising();
        let (at, covered) = o.best_place((120, 60));
        assert_eq!(
            (at, covered),
            ((400 - 120 - INSET_PX, 200 - 60 - INSET_PX), 0)
        );
    }

    #[test]
    fn the_legend_moves_to_a_free_place_and_never_over_a_line() {
        let mut o = rising();
        // A second, flat curve along the bottom covers the lower right and the lower left.
        o.mark_band(&[(0, 170, 165, 175), (399, 170, 165, 175)]);
        let ((x, y), covered) = o.best_place((120, 60));
        assert_eq!(covered, 0);
        assert_eq!(
            (x, y),
            (400 - 120 - INSET_PX, (200 - 60) / 2),
            "middle right"
        );
        // Lines between points are marked, not only the points: a steep segment between two
        // points far apart in x still blocks the middle.
        let mut steep = Occupancy::new(400, 200);
        steep.mark_band(&[(0, 195, 195, 195), (399, 5, 5, 5)]);
        assert!(steep.covered((140, 70), (120, 60)) > 0);
        // The optimal line is data too.
        let mut line = Occupancy::new(400, 200);
        line.mark_row(100);
        assert!(line.covered((0, 80), (50, 30)) > 0);
        assert_eq!(line.covered((0, 10), (50, 30)), 0);
    }

    #[test]
    fn a_full_area_reports_how_much_it_covers_and_headroom_makes_space() {
        let mut o = Occupancy::new(100, 100);
        for x in 0..100 {
            o.mark_span(x, 0, 99);
        }
        let (_, covered) = o.best_place((20, 10));
        assert_eq!(covered, 200);
        // 100 px tall, a 10 px legend: 20 px of the area become headroom, 80 hold the data.
        let extra = headroom(0.0..80.0, 100, 10);
        assert!((extra - 20.0).abs() < 1e-12, "{extra}");
        // Clipping: rectangles partly outside count only what is inside.
        assert_eq!(o.covered((-10, -10), (20, 20)), 100);
    }
}
