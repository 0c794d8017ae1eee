//! Push by a single robot (`docs/BOX_PUSHING.md` §5.2). The joint big-box push is in `step.rs`.

use super::geometry::Heading;
use super::state::{Boxes, Robot};

/// Whether the robot stands on a boundary cell facing out of an `n` x `n` grid: facing north in
/// row n-1, east in column n-1, south in row 0 or west in column 0 (`docs/BOX_PUSHING.md` §5.2 (a), (c)). Exact
/// equality as in the reference: a robot lifted above the grid by Q2 is not "on the edge".
/// The reference uses xlen for (a) and ylen for (c) east tests (Q9); on square grids both are n.
#[inline]
pub fn facing_out_from_edge(robot: &Robot, n: i32) -> bool {
    match robot.heading {
        Heading::North => robot.cell.row == n - 1,
        Heading::East => robot.cell.col == n - 1,
        Heading::South => robot.cell.row == 0,
        Heading::West => robot.cell.col == 0,
    }
}

/// One primitive step of Push by one robot on an `n` x `n` grid with goal row `n - 1`, where a hit
/// costs `hit` ([`super::Rules::penalty`]: -5 in the ICRA paper, `docs/BOX_PUSHING.md` §7). Returns the robot's penalty, summed from 0.0
/// in box order as the reference does (0.0 or one `hit`; two would need a robot standing inside
/// a box).
#[inline]
pub fn push_step(robot: &mut Robot, boxes: &mut Boxes, n: i32, hit: f64) -> f64 {
    let mut penalty = 0.0;
    // (a) Facing out from an edge: -5, finished, no movement (quirk Q5).
    if facing_out_from_edge(robot, n) {
        robot.finished = true;
        return penalty + hit;
    }
    // (b) Step forward, then test the boxes in the order small 0, small 1, big, each against the
    // robot's cell at that moment (a bounce moves the robot back before the next test).
    robot.cell = robot.cell.step(robot.heading);
    let mut pushing_small_box = false;
    for k in 0..3 {
        if !boxes.box_covers(k, robot.cell) {
            continue;
        }
        if k < 2 && robot.heading == Heading::North {
            pushing_small_box = true;
            boxes.small[k].row += 1;
            if boxes.small[k].row == n - 1 {
                robot.finished = true;
            }
        } else {
            // The big box alone, or a small box sideways or downwards (quirk Q11).
            robot.cell = robot.cell.step_back(robot.heading);
            robot.finished = true;
            penalty += hit;
        }
    }
    // (c) Reaching the last cell before the wall ends the Push without a penalty.
    if !pushing_small_box && facing_out_from_edge(robot, n) {
        robot.finished = true;
    }
    penalty
}

#[cfg(test)]
mod tests {
    use super::super::geometry::Cell;
    use super::super::layout::GridLayout;
    use super::super::Rules;
    use super::*;

    fn setup(cell: Cell, heading: Heading) -> (Robot, Boxes) {
        let l = GridLayout::new(10);
        let mut r = Robot::at_start(cell, heading);
        r.finished = false;
        (
            r,
            Boxes {
                small: l.small_boxes,
                big_left: l.big_box_left,
            },
        )
    }

    #[test]
    fn facing_out_from_an_edge_costs_five_and_does_not_move() {
        let (mut r, mut b) = setup(Cell::new(1, 0), Heading::South);
        assert_eq!(push_step(&mut r, &mut b, 10, Rules::ICRA.penalty), -5.0);
        assert!(r.finished);
        assert_eq!(r.cell, Cell::new(1, 0));
    }

    #[test]
    fn walking_into_the_last_cell_finishes_without_penalty() {
        let (mut r, mut b) = setup(Cell::new(1, 1), Heading::South);
        assert_eq!(push_step(&mut r, &mut b, 10, Rules::ICRA.penalty), 0.0);
        assert!(r.finished);
        assert_eq!(r.cell, Cell::new(1, 0));
    }

    #[test]
    fn free_space_push_keeps_running() {
        let (mut r, mut b) = setup(Cell::new(1, 1), Heading::East);
        assert_eq!(push_step(&mut r, &mut b, 10, Rules::ICRA.penalty), 0.0);
        assert!(!r.finished);
        assert_eq!(r.cell, Cell::new(2, 1));
    }

    #[test]
    fn big_box_alone_bounces_with_penalty() {
        let (mut r, mut b) = setup(Cell::new(5, 4), Heading::North);
        assert_eq!(push_step(&mut r, &mut b, 10, Rules::ICRA.penalty), -5.0);
        assert!(r.finished);
        assert_eq!(r.cell, Cell::new(5, 4));
        assert_eq!(b.big_left, Cell::new(4, 5));
    }

    #[test]
    fn small_box_sideways_bounces_with_penalty() {
        // Quirk Q11: from (0,5) facing east into small box 0 at (1,5).
        let (mut r, mut b) = setup(Cell::new(0, 5), Heading::East);
        assert_eq!(push_step(&mut r, &mut b, 10, Rules::ICRA.penalty), -5.0);
        assert_eq!(r.cell, Cell::new(0, 5));
        assert_eq!(b.small[0], Cell::new(1, 5));
    }

    #[test]
    fn small_box_north_moves_with_the_robot_until_the_goal_row() {
        let (mut r, mut b) = setup(Cell::new(1, 4), Heading::North);
        for row in 6..9 {
            assert_eq!(push_step(&mut r, &mut b, 10, Rules::ICRA.penalty), 0.0);
            assert_eq!(b.small[0], Cell::new(1, row));
            assert!(!r.finished);
        }
        assert_eq!(push_step(&mut r, &mut b, 10, Rules::ICRA.penalty), 0.0);
        assert_eq!(b.small[0], Cell::new(1, 9));
        assert_eq!(r.cell, Cell::new(1, 8));
        assert!(r.finished);
    }
}
