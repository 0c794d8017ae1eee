//! A built-in 3 x 5 pixel font (upper case, digits, a few signs) for the status bar, so frames
//! need no font files. Lower case is drawn as upper case; other characters leave a blank.

use super::canvas::Canvas;
use super::palette::Colour;

/// Glyph width and height in font pixels.
pub const GLYPH_W: i64 = 3;
/// Glyph height in font pixels.
pub const GLYPH_H: i64 = 5;

/// Horizontal advance per character in font pixels (glyph plus one column of space).
pub const ADVANCE: i64 = GLYPH_W + 1;

/// Rows of `c`, top first; bit 2 is the left column.
fn glyph(c: char) -> Option<[u8; 5]> {
    Some(match c.to_ascii_uppercase() {
        'A' => [0b010, 0b101, 0b111, 0b101, 0b101],
        'B' => [0b110, 0b101, 0b110, 0b101, 0b110],
        'C' => [0b011, 0b100, 0b100, 0b100, 0b011],
        'D' => [0b110, 0b101, 0b101, 0b101, 0b110],
        'E' => [0b111, 0b100, 0b110, 0b100, 0b111],
        'F' => [0b111, 0b100, 0b110, 0b100, 0b100],
        'G' => [0b011, 0b100, 0b101, 0b101, 0b011],
        'H' => [0b101, 0b101, 0b111, 0b101, 0b101],
        'I' => [0b111, 0b010, 0b010, 0b010, 0b111],
        'J' => [0b001, 0b001, 0b001, 0b101, 0b010],
        'K' => [0b101, 0b101, 0b110, 0b101, 0b101],
        'L' => [0b100, 0b100, 0b100, 0b100, 0b111],
        'M' => [0b101, 0b111, 0b111, 0b101, 0b101],
        'N' => [0b110, 0b101, 0b101, 0b101, 0b101],
        'O' => [0b010, 0b101, 0b101, 0b101, 0b010],
        'P' => [0b110, 0b101, 0b110, 0b100, 0b100],
        'Q' => [0b010, 0b101, 0b101, 0b110, 0b011],
        'R' => [0b110, 0b101, 0b110, 0b101, 0b101],
        'S' => [0b011, 0b100, 0b010, 0b001, 0b110],
        'T' => [0b111, 0b010, 0b010, 0b010, 0b010],
        'U' => [0b101, 0b101, 0b101, 0b101, 0b111],
        'V' => [0b101, 0b101, 0b101, 0b101, 0b010],
        'W' => [0b101, 0b101, 0b111, 0b111, 0b101],
        'X' => [0b101, 0b101, 0b010, 0b101, 0b101],
        'Y' => [0b101, 0b101, 0b010, 0b010, 0b010],
        'Z' => [0b111, 0b001, 0b010, 0b100, 0b111],
        '0' => [0b111, 0b101, 0b101, 0b101, 0b111],
        '1' => [0b010, 0b110, 0b010, 0b010, 0b111],
        '2' => [0b110, 0b001, 0b010, 0b100, 0b111],
        '3' => [0b110, 0b001, 0b010, 0b001, 0b110],
        '4' => [0b101, 0b101, 0b111, 0b001, 0b001],
        '5' => [0b111, 0b100, 0b110, 0b001, 0b110],
        '6' => [0b011, 0b100, 0b111, 0b101, 0b111],
        '7' => [0b111, 0b001, 0b010, 0b010, 0b010],
        '8' => [0b111, 0b101, 0b111, 0b101, 0b111],
        '9' => [0b111, 0b101, 0b111, 0b001, 0b110],
        '-' => [0b000, 0b000, 0b111, 0b000, 0b000],
        '+' => [0b000, 0b010, 0b111, 0b010, 0b000],
        '=' => [0b000, 0b111, 0b000, 0b111, 0b000],
        '.' => [0b000, 0b000, 0b000, 0b000, 0b010],
        ',' => [0b000, 0b000, 0b000, 0b010, 0b100],
        '_' => [0b000, 0b000, 0b000, 0b000, 0b111],
        '(' => [0b001, 0b010, 0b010, 0b010, 0b001],
        ')' => [0b100, 0b010, 0b010, 0b010, 0b100],
        ':' => [0b000, 0b010, 0b000, 0b010, 0b000],
        '/' => [0b001, 0b001, 0b010, 0b100, 0b100],
        _ => return None,
    })
}

/// Width in pixels of `text` drawn at `scale` (no trailing space).
pub fn text_width(text: &str, scale: i64) -> i64 {
    let n = text.chars().count() as i64;
    if n == 0 {
        0
    } else {
        (n * ADVANCE - 1) * scale
    }
}

/// `text` at `scale` centred on pixel point (cx, cy).
pub fn draw_text_centred(canvas: &mut Canvas, cx: f64, cy: f64, text: &str, scale: i64, c: Colour) {
    let x = (cx - text_width(text, scale) as f64 / 2.0).round() as i64;
    let y = (cy - (GLYPH_H * scale) as f64 / 2.0).round() as i64;
    draw_text(canvas, x, y, text, scale, c);
}

/// Draw `text` with its top-left corner at (x, y), each font pixel a `scale` x `scale` square.
/// Returns the x just after the text (where the next character would start).
pub fn draw_text(canvas: &mut Canvas, x: i64, y: i64, text: &str, scale: i64, c: Colour) -> i64 {
    let mut at = x;
    for ch in text.chars() {
        if let Some(rows) = glyph(ch) {
            for (r, bits) in rows.iter().enumerate() {
                for col in 0..GLYPH_W {
                    if bits & (0b100 >> col) != 0 {
                        canvas.fill_rect(at + col * scale, y + r as i64 * scale, scale, scale, c);
                    }
                }
            }
        }
        at += ADVANCE * scale;
    }
    at
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_character_of_the_action_names_has_a_glyph() {
        let names = crate::envs::box_pushing::actions::ACTION_NAMES.join("")
            + "Go-to-WS Go-to-TR Get-Tool Wait-M Pass-to-M(0) Search-Tool(1)T=/R+.,:";
        for ch in names.chars().filter(|c| *c != ' ') {
            assert!(glyph(ch).is_some(), "no glyph for {ch:?}");
        }
    }

    #[test]
    fn glyphs_are_distinct() {
        let chars: Vec<char> = ('A'..='Z')
            .chain('0'..='9')
            .chain("-+=.,_():/".chars())
            .collect();
        for (i, a) in chars.iter().enumerate() {
            for b in &chars[i + 1..] {
                assert_ne!(glyph(*a), glyph(*b), "{a} and {b} look the same");
            }
        }
    }

    #[test]
    fn t_is_drawn_as_a_bar_and_a_stem_at_scale_two() {
        let mut c = Canvas::new(8, 12, Colour::Background);
        let end = draw_text(&mut c, 1, 1, "t", 2, Colour::Dark);
        assert_eq!(end, 1 + ADVANCE * 2);
        for x in 1..7 {
            assert_eq!(c.pixel(x, 1), Some(Colour::Dark), "bar at x={x}");
        }
        assert_eq!(c.pixel(3, 10), Some(Colour::Dark));
        assert_eq!(c.pixel(1, 10), Some(Colour::Background));
        assert_eq!(text_width("t=1", 2), (3 * ADVANCE - 1) * 2);
    }
}
