//! The status bar under each picture: step, undiscounted team return so far, and the macro-action
//! each agent executed in the last step (`docs/ALGORITHMS.md` §1.1: what `executed` reports).
//!
//! Its layout depends only on the environment (agent labels and the longest action name of each
//! agent), never on the state, so every frame of an episode has the same height.

use crate::draw::font::{draw_text, ADVANCE, GLYPH_H};
use crate::draw::{Canvas, Colour};
use crate::envs::MacroEnv;

/// Font scale: each font pixel is 2 x 2 image pixels (glyphs 6 x 10).
const SCALE: i64 = 2;
/// Padding around the bar's content.
const PAD: i64 = 6;
/// Baseline-to-baseline distance of text lines.
const LINE: i64 = GLYPH_H * SCALE + 5;
/// Space between two agents' entries, in characters.
const GAP_CHARS: i64 = 2;

/// Where each agent's entry starts: (x, line index from 1; line 0 holds step and return).
fn slots(env: &impl MacroEnv, labels: &[&str], width: usize) -> Vec<(i64, i64)> {
    let usable = width as i64 - 2 * PAD;
    let mut out = Vec::with_capacity(env.n_agents());
    let (mut x, mut line) = (0i64, 1i64);
    for (i, label) in labels.iter().enumerate().take(env.n_agents()) {
        let longest = env
            .action_names(i)
            .iter()
            .map(|n| n.chars().count())
            .max()
            .unwrap_or(1) as i64;
        let chars = label.chars().count() as i64 + 1 + longest;
        let w = chars * ADVANCE * SCALE;
        if x > 0 && x + w > usable {
            x = 0;
            line += 1;
        }
        out.push((PAD + x, line));
        x += w + GAP_CHARS * ADVANCE * SCALE;
    }
    out
}

/// Height in pixels of the bar for `env` on a picture `width` pixels wide.
pub fn hud_height(env: &impl MacroEnv, labels: &[&str], width: usize) -> usize {
    let lines = slots(env, labels, width)
        .iter()
        .map(|&(_, l)| l)
        .max()
        .unwrap_or(0)
        + 1;
    (2 * PAD + lines * LINE - (LINE - GLYPH_H * SCALE)) as usize
}

/// Draw the bar with its top edge at pixel row `top`, across the canvas's full width.
/// `labels[i]` names agent i and is drawn in that agent's colour.
pub fn draw_hud(
    canvas: &mut Canvas,
    top: usize,
    env: &impl MacroEnv,
    labels: &[&str],
    team_return: f64,
) {
    let width = canvas.width();
    let top = top as i64;
    canvas.fill_rect(
        0,
        top,
        width as i64,
        canvas.height() as i64 - top,
        Colour::HudBackground,
    );
    canvas.fill_rect(0, top, width as i64, 1, Colour::GridLine);
    let head = format!(
        "STEP {}/{}   RETURN {:+.1}",
        env.t(),
        env.horizon(),
        team_return
    );
    draw_text(canvas, PAD, top + PAD, &head, SCALE, Colour::Dark);
    for (i, (x, line)) in slots(env, labels, width).into_iter().enumerate() {
        let y = top + PAD + line * LINE;
        let action = if env.t() == 0 {
            "-"
        } else {
            env.action_names(i)
                .get(env.executed()[i])
                .copied()
                .unwrap_or("?")
        };
        let after = draw_text(canvas, x, y, labels[i], SCALE, Colour::agent(i));
        draw_text(
            canvas,
            after + ADVANCE * SCALE,
            y,
            action,
            SCALE,
            Colour::Dark,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::envs::box_pushing::BoxPushing;
    use crate::envs::warehouse::Warehouse;

    #[test]
    fn agents_share_one_line_when_they_fit_and_wrap_when_not() {
        let bp = BoxPushing::new(10, 100).unwrap();
        // "R0 GT_SB0" is 9 characters, 72 px at scale 2.
        let wide = slots(&bp, &["R0", "R1"], 281);
        assert_eq!(wide, vec![(PAD, 1), (PAD + 72 + 16, 1)]);
        let narrow = slots(&bp, &["R0", "R1"], 120);
        assert_eq!(narrow, vec![(PAD, 1), (PAD, 2)]);
        assert_eq!(
            hud_height(&bp, &["R0", "R1"], 120) - hud_height(&bp, &["R0", "R1"], 281),
            LINE as usize
        );
    }

    #[test]
    fn warehouse_labels_fit_on_one_line_at_sixty_pixels_per_metre() {
        let env = Warehouse::paper(150).unwrap();
        let s = slots(&env, &["T0", "T1", "F"], 420);
        assert!(s.iter().all(|&(_, line)| line == 1), "{s:?}");
    }
}
