//! An indexed raster and the few shapes the frames need: rectangles, discs, thick lines.
//!
//! Everything clips at the borders, so a drawing routine never has to check bounds (a Box Pushing
//! robot the Q2 push lifts past the top row, say, is simply cut off).

use super::palette::Colour;

/// A `width` x `height` image of palette indices, row-major, top row first.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Canvas {
    width: usize,
    height: usize,
    pixels: Vec<u8>,
}

impl Canvas {
    /// A canvas filled with `fill`.
    pub fn new(width: usize, height: usize, fill: Colour) -> Self {
        Self {
            width,
            height,
            pixels: vec![fill as u8; width * height],
        }
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// Palette indices, row-major: pixel (x, y) is at `y * width + x`.
    pub fn pixels(&self) -> &[u8] {
        &self.pixels
    }

    /// The colour at (x, y), or None outside the canvas.
    pub fn pixel(&self, x: usize, y: usize) -> Option<Colour> {
        if x >= self.width || y >= self.height {
            return None;
        }
        Colour::from_index(self.pixels[y * self.width + x])
    }

    /// Copy `other` onto this canvas with its top-left pixel at (x, y), clipped at the borders.
    pub fn paste(&mut self, other: &Canvas, x: usize, y: usize) {
        for row in 0..other.height.min(self.height.saturating_sub(y)) {
            let n = other.width.min(self.width.saturating_sub(x));
            let from = row * other.width;
            let to = (y + row) * self.width + x;
            self.pixels[to..to + n].copy_from_slice(&other.pixels[from..from + n]);
        }
    }

    /// Set one pixel; ignored outside the canvas.
    #[inline]
    pub fn set(&mut self, x: i64, y: i64, c: Colour) {
        if x >= 0 && y >= 0 && (x as usize) < self.width && (y as usize) < self.height {
            self.pixels[y as usize * self.width + x as usize] = c as u8;
        }
    }

    /// Fill the `w` x `h` rectangle whose top-left pixel is (x, y).
    pub fn fill_rect(&mut self, x: i64, y: i64, w: i64, h: i64, c: Colour) {
        let x0 = x.clamp(0, self.width as i64) as usize;
        let x1 = (x + w).clamp(0, self.width as i64) as usize;
        let y0 = y.clamp(0, self.height as i64) as usize;
        let y1 = (y + h).clamp(0, self.height as i64) as usize;
        for row in y0..y1 {
            self.pixels[row * self.width + x0..row * self.width + x1].fill(c as u8);
        }
    }

    /// A `thickness`-pixel frame just inside the `w` x `h` rectangle at (x, y).
    pub fn outline_rect(&mut self, x: i64, y: i64, w: i64, h: i64, thickness: i64, c: Colour) {
        let t = thickness.min(w).min(h);
        self.fill_rect(x, y, w, t, c);
        self.fill_rect(x, y + h - t, w, t, c);
        self.fill_rect(x, y, t, h, c);
        self.fill_rect(x + w - t, y, t, h, c);
    }

    /// A `side`-pixel square centred on pixel point (cx, cy), filled with `fill`, with a
    /// 1-pixel `rim`.
    pub fn centred_square(&mut self, cx: f64, cy: f64, side: i64, fill: Colour, rim: Colour) {
        let (x, y) = (
            (cx - side as f64 / 2.0).round() as i64,
            (cy - side as f64 / 2.0).round() as i64,
        );
        self.fill_rect(x, y, side, side, fill);
        self.outline_rect(x, y, side, side, 1, rim);
    }

    /// Fill every pixel whose centre lies within `r` of (cx, cy) (pixel coordinates, pixel
    /// (x, y) has its centre at (x + 0.5, y + 0.5)).
    pub fn fill_circle(&mut self, cx: f64, cy: f64, r: f64, c: Colour) {
        let y0 = (cy - r).floor() as i64;
        let y1 = (cy + r).ceil() as i64;
        let x0 = (cx - r).floor() as i64;
        let x1 = (cx + r).ceil() as i64;
        for y in y0..=y1 {
            let dy = y as f64 + 0.5 - cy;
            for x in x0..=x1 {
                let dx = x as f64 + 0.5 - cx;
                if dx * dx + dy * dy <= r * r {
                    self.set(x, y, c);
                }
            }
        }
    }

    /// A disc of `fill` with a `border`-pixel rim of `rim` (an outlined robot).
    pub fn ringed_circle(
        &mut self,
        cx: f64,
        cy: f64,
        r: f64,
        border: f64,
        rim: Colour,
        fill: Colour,
    ) {
        self.fill_circle(cx, cy, r, rim);
        self.fill_circle(cx, cy, (r - border).max(0.0), fill);
    }

    /// A line from (x0, y0) to (x1, y1) about `width` pixels wide (discs stamped every half
    /// pixel along it).
    pub fn line(&mut self, x0: f64, y0: f64, x1: f64, y1: f64, width: f64, c: Colour) {
        self.dashed_line(x0, y0, x1, y1, width, f64::INFINITY, 0.0, c);
    }

    /// A dashed line: `dash` pixels drawn, `gap` pixels skipped, starting with a dash.
    #[allow(clippy::too_many_arguments)]
    pub fn dashed_line(
        &mut self,
        x0: f64,
        y0: f64,
        x1: f64,
        y1: f64,
        width: f64,
        dash: f64,
        gap: f64,
        c: Colour,
    ) {
        let len = ((x1 - x0).powi(2) + (y1 - y0).powi(2)).sqrt();
        let n = (len * 2.0).ceil().max(1.0) as usize;
        let r = (width / 2.0).max(0.5);
        for k in 0..=n {
            let s = k as f64 / n as f64;
            let along = s * len;
            if gap > 0.0 && along % (dash + gap) >= dash {
                continue;
            }
            self.fill_circle(x0 + s * (x1 - x0), y0 + s * (y1 - y0), r, c);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rect_clips_at_the_border_and_counts_its_pixels() {
        let mut c = Canvas::new(10, 8, Colour::Background);
        c.fill_rect(-2, 6, 5, 5, Colour::Dark);
        let dark = c
            .pixels()
            .iter()
            .filter(|&&p| p == Colour::Dark as u8)
            .count();
        assert_eq!(dark, 3 * 2);
        assert_eq!(c.pixel(2, 7), Some(Colour::Dark));
        assert_eq!(c.pixel(3, 7), Some(Colour::Background));
        assert_eq!(c.pixel(10, 0), None);
    }

    #[test]
    fn circle_is_symmetric_and_about_pi_r_squared() {
        let mut c = Canvas::new(40, 40, Colour::Background);
        c.fill_circle(20.0, 20.0, 10.0, Colour::Agent0);
        let n = c.pixels().iter().filter(|&&p| p != 0).count() as f64;
        assert!((n - std::f64::consts::PI * 100.0).abs() < 20.0, "{n}");
        for (x, y) in [(10, 20), (29, 20), (20, 10), (20, 29)] {
            assert_eq!(c.pixel(x, y), Some(Colour::Agent0), "({x},{y})");
        }
        assert_eq!(c.pixel(9, 20), Some(Colour::Background));
        assert_eq!(c.pixel(30, 20), Some(Colour::Background));
    }

    #[test]
    fn outline_leaves_the_inside_alone() {
        let mut c = Canvas::new(10, 10, Colour::Background);
        c.outline_rect(1, 1, 8, 8, 2, Colour::Dark);
        assert_eq!(c.pixel(1, 1), Some(Colour::Dark));
        assert_eq!(c.pixel(2, 5), Some(Colour::Dark));
        assert_eq!(c.pixel(3, 3), Some(Colour::Background));
        assert_eq!(c.pixel(8, 8), Some(Colour::Dark));
        assert_eq!(c.pixel(9, 9), Some(Colour::Background));
    }

    #[test]
    fn dashed_line_has_gaps_where_a_solid_one_has_none() {
        let mut solid = Canvas::new(40, 3, Colour::Background);
        solid.line(0.5, 1.5, 39.5, 1.5, 1.0, Colour::Dark);
        let mut dashed = Canvas::new(40, 3, Colour::Background);
        dashed.dashed_line(0.5, 1.5, 39.5, 1.5, 1.0, 4.0, 4.0, Colour::Dark);
        let row = |c: &Canvas| {
            (0..40)
                .filter(|&x| c.pixel(x, 1) == Some(Colour::Dark))
                .count()
        };
        assert_eq!(row(&solid), 40);
        let d = row(&dashed);
        assert!((16..=28).contains(&d), "{d}");
        assert_eq!(dashed.pixel(1, 1), Some(Colour::Dark));
        assert_eq!(dashed.pixel(6, 1), Some(Colour::Background));
    }
}
