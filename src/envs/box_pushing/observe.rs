//! Macro-observations: what a robot sees in its front cell (`docs/BOX_PUSHING.md` §6).

use super::state::{Boxes, Robot};

/// Values per robot observation.
pub const OBS_SIZE: usize = 5;

/// Element names in layout order (`docs/BOX_PUSHING.md` §6).
pub const OBS_NAMES: [&str; OBS_SIZE] = ["small_box", "big_box", "empty", "wall", "teammate"];

/// The observation every robot gets at reset, whatever is in front (quirk Q8).
pub const RESET_OBS: [f32; OBS_SIZE] = [0.0, 0.0, 1.0, 0.0, 0.0];

/// A fresh observation of `robot`'s front cell on an `n` x `n` grid. Bits are set independently,
/// so rare coincidences set two (quirk Q13); "empty" is set only when no other bit is.
#[inline]
pub fn observe(robot: &Robot, teammate: &Robot, boxes: &Boxes, n: i32) -> [f32; OBS_SIZE] {
    let front = robot.cell.step(robot.heading);
    let small = boxes.small[0] == front || boxes.small[1] == front;
    let big = boxes.big_covers(front);
    let wall = front.is_outside(n);
    let mate = teammate.cell == front;
    let empty = !(small || big || wall || mate);
    [
        f32::from(u8::from(small)),
        f32::from(u8::from(big)),
        f32::from(u8::from(empty)),
        f32::from(u8::from(wall)),
        f32::from(u8::from(mate)),
    ]
}

#[cfg(test)]
mod tests {
    use super::super::geometry::{Cell, Heading};
    use super::super::layout::GridLayout;
    use super::*;

    fn at(col: i32, row: i32, h: Heading) -> Robot {
        Robot::at_start(Cell::new(col, row), h)
    }

    fn start_boxes() -> Boxes {
        let l = GridLayout::new(10);
        Boxes {
            small: l.small_boxes,
            big_left: l.big_box_left,
        }
    }

    #[test]
    fn spec_examples_are_one_hot() {
        // `docs/BOX_PUSHING.md` §6 examples on 10x10; the teammate is parked far away.
        let b = start_boxes();
        let away = at(0, 0, Heading::North);
        let n = Heading::North;
        assert_eq!(
            observe(&at(1, 4, n), &away, &b, 10),
            [1.0, 0.0, 0.0, 0.0, 0.0]
        );
        assert_eq!(
            observe(&at(8, 4, n), &away, &b, 10),
            [1.0, 0.0, 0.0, 0.0, 0.0]
        );
        assert_eq!(
            observe(&at(4, 4, n), &away, &b, 10),
            [0.0, 1.0, 0.0, 0.0, 0.0]
        );
        assert_eq!(
            observe(&at(5, 4, n), &away, &b, 10),
            [0.0, 1.0, 0.0, 0.0, 0.0]
        );
        assert_eq!(
            observe(&at(3, 9, n), &away, &b, 10),
            [0.0, 0.0, 0.0, 1.0, 0.0]
        );
        assert_eq!(
            observe(&at(9, 2, Heading::East), &away, &b, 10),
            [0.0, 0.0, 0.0, 1.0, 0.0]
        );
        let mate = at(3, 2, n);
        assert_eq!(
            observe(&at(2, 2, Heading::East), &mate, &b, 10),
            [0.0, 0.0, 0.0, 0.0, 1.0]
        );
        assert_eq!(observe(&at(2, 2, n), &away, &b, 10), RESET_OBS);
    }

    #[test]
    fn small_box_and_teammate_together_set_two_bits() {
        // Quirk Q13.
        let b = start_boxes();
        let mate = at(1, 5, Heading::North);
        assert_eq!(
            observe(&at(1, 4, Heading::North), &mate, &b, 10),
            [1.0, 0.0, 0.0, 0.0, 1.0]
        );
    }

    #[test]
    fn a_robot_above_the_grid_sees_a_wall() {
        // After a Q2 teleport push a robot may stand in row n or higher.
        let b = start_boxes();
        let away = at(0, 0, Heading::North);
        assert_eq!(
            observe(&at(9, 11, Heading::West), &away, &b, 10),
            [0.0, 0.0, 0.0, 1.0, 0.0]
        );
    }
}
